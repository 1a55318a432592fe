//! The resources a run will need, estimated from its inputs before any work starts, and the
//! bounds they are held to: `--max-memory` (bytes held) and `--max-work` (exact edge
//! evaluations, one [`crate::kinematics::Track`] query of one pass at one node, about a
//! microsecond each). A run past either is refused as bad input naming the option and the
//! estimate, rather than aborting on an allocation or running for days.

use crate::patch::{Conditions, Grid, periods};
use camkit::error::{Error, Result};

/// Default work bound (edge evaluations): about a quarter of an hour on two cores.
pub const DEFAULT_WORK: f64 = 1e9;
/// Largest tool radius simulated (mm): heights are differences of numbers of the radius's
/// size, so their round-off (≈1e-16·r times the few hundred operations of a node) stays
/// far below the stated 0.1 µm error up to here.
pub const MAX_RADIUS: f64 = 1e4;
/// Bytes a pass's track holds while its column is computed (pieces and their tables).
const TRACK_BYTES: f64 = 16_384.0;
/// Heights are 8-byte floats.
const HEIGHT_BYTES: f64 = 8.0;
/// Evaluations of the peak refinement after a patch ([`crate::study::refine_peak`]).
const REFINE_NODES: f64 = 4.0 * 121.0;

/// The bounds of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Bytes (`--max-memory`).
    pub memory: f64,
    /// Edge evaluations (`--max-work`).
    pub work: f64,
}

/// What a run (or part of one) is estimated to need.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Need {
    /// Bytes held at once.
    pub memory: f64,
    /// Edge evaluations.
    pub work: f64,
}

impl Need {
    /// Two parts run one after the other: the work adds, the memory is the larger.
    pub fn then(self, other: Need) -> Need {
        Need { memory: self.memory.max(other.memory), work: self.work + other.work }
    }

    /// Refuses a need beyond the budget; `what` names the run and the inputs that drive it.
    pub fn check(&self, budget: &Budget, what: &str) -> Result<()> {
        if !camkit::budget::fits(self.memory, budget.memory) {
            return Err(Error::input(format!(
                "{what} needs an estimated {:.0} MB, more than the bound of {:.0} MB (--max-memory): coarsen --step, shrink the area or raise --max-memory",
                self.memory / 1e6,
                budget.memory / 1e6
            )));
        }
        if !camkit::budget::fits(self.work, budget.work) {
            return Err(Error::input(format!(
                "{what} needs an estimated {:.3e} edge evaluations, more than the bound of {:.3e} (--max-work): coarsen --step, shrink the area or raise --max-work",
                self.work, budget.work
            )));
        }
        Ok(())
    }
}

/// Checks a tool radius against [`MAX_RADIUS`] (`what` names the option or file).
pub fn check_radius(radius: f64, what: &str) -> Result<()> {
    if radius > MAX_RADIUS {
        return Err(Error::input(format!(
            "{what}: tool radius {radius} mm is above the {MAX_RADIUS} mm simulated (round-off would exceed the stated 0.1 µm)"
        )));
    }
    Ok(())
}

/// Passes a node of `cond` evaluates, at most: those whose ball can cut lower than the nearest
/// pass surely does. The nearest pass (at most f/2 across) has a flute over the node within
/// Z·fz along the feed (in one turn's feed G turns by more than a pitch), so a pass farther
/// than √(f²/4 + (Z·fz)²) across cannot be lower, and none beyond the radius reaches.
pub fn passes_per_node(cond: &Conditions) -> f64 {
    let (r, f) = (cond.cutter.radius, cond.pick);
    let reach = (0.25 * f * f + (cond.cutter.flutes as f64 * cond.feed_per_tooth).powi(2)).sqrt().min(r);
    2.0 * (reach / f).ceil() + 2.0
}

/// The patch of `cond` on `grid`: its heights, the tracks of one column per thread, and its
/// nodes (one period when it repeats) times the passes each evaluates, plus the peak's
/// refinement.
pub fn patch(cond: &Conditions, grid: &Grid) -> Need {
    let nodes = grid.nx as f64 * grid.ny as f64;
    let computed = match periods(cond, grid) {
        Some((m, p, _)) if nodes > (m * p) as f64 => (m * p) as f64,
        _ => nodes,
    };
    let passes = passes_per_node(cond);
    let threads = rayon::current_num_threads() as f64;
    Need { memory: nodes * HEIGHT_BYTES + threads * passes * TRACK_BYTES, work: (computed + REFINE_NODES) * passes }
}

/// One periodic cell of `cond` at `step` ([`crate::study::cell`]).
pub fn cell(cond: &Conditions, step: f64) -> Need {
    patch(cond, &crate::study::cell_grid(cond, step))
}

/// The brute-force check of a patch ([`crate::brute::worst_below`]) over `area`: every sampled
/// edge point, each checked against the passes of its node.
pub fn verify(cond: &Conditions, area: (f64, f64, f64, f64), dtheta: f64, spacing: f64, max_radial: f64) -> Need {
    let (x0, x1, y0, y1) = area;
    let passes = (x1 - x0 + 2.0 * max_radial) / cond.pick + 3.0;
    let turns = (y1 - y0 + 2.0 * max_radial) / cond.feed_per_radian() / dtheta + 1.0;
    let samples = passes * turns * cond.cutter.flutes as f64 * (max_radial / spacing + 1.0);
    Need { memory: 0.0, work: samples * (1.0 + passes_per_node(cond)) }
}

/// Cells of the bisection for the simulated flat radius ([`crate::flat::simulated_r0`]).
pub fn flat_cells(radius: f64, resolution: f64) -> f64 {
    1.0 + (radius / 2.0 / resolution).log2().ceil().max(0.0)
}

/// Work of a z-map, in the units of [`DEFAULT_WORK`]: for every move, the nodes its ball can
/// reach (its centres' bounding box grown by the radius, within the grid) times the flute passes
/// over each (a node is cut by the teeth that pass within the radius: 2R over the feed per tooth,
/// at most the move's own teeth), at [`ZMAP_PASSES_PER_UNIT`] passes a unit; `moves` are the
/// moves, the memory the heights and the moves.
pub fn zmap(grid: &Grid, moves: &[crate::kinematics::Move], cutter: &crate::cutter::Cutter) -> Need {
    let (gx1, gy1) = (grid.x(grid.nx.saturating_sub(1)), grid.y(grid.ny.saturating_sub(1)));
    let span = |lo: f64, hi: f64, g0: f64, g1: f64| ((hi.min(g1) - lo.max(g0)) / grid.step + 1.0).max(0.0);
    let (radius, flutes) = (cutter.radius, f64::from(cutter.flutes.max(1)));
    let passes: f64 = moves
        .iter()
        .map(|m| {
            let (a, b) = (m.c0, m.centre(m.span));
            let nodes = span(a.x.min(b.x) - radius, a.x.max(b.x) + radius, grid.x0, gx1)
                * span(a.y.min(b.y) - radius, a.y.max(b.y) + radius, grid.y0, gy1);
            let per_tooth = m.feed_per_radian() * std::f64::consts::TAU / flutes;
            let teeth = m.span * flutes / std::f64::consts::TAU + 1.0;
            let over_node = if per_tooth > 0.0 { (2.0 * radius / per_tooth + 1.0).min(teeth) } else { 1.0 };
            nodes * over_node.max(1.0)
        })
        .sum();
    let memory = grid.nx as f64 * grid.ny as f64 * HEIGHT_BYTES + moves.len() as f64 * MOVE_BYTES;
    Need { memory, work: passes / ZMAP_PASSES_PER_UNIT }
}

/// Flute passes over a z-map node that cost about one unit of work (1 µs): 22 ns a pass measured
/// on a 12 km move over 4.2 M nodes (15 s of CPU for 6.7e8 passes).
pub const ZMAP_PASSES_PER_UNIT: f64 = 45.0;

/// Bytes of one simulated move.
pub const MOVE_BYTES: f64 = std::mem::size_of::<crate::kinematics::Move>() as f64;
