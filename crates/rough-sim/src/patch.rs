//! The paper's machining case as a height map: straight passes fed in +y, picked by f in x,
//! the tool axis tilted by ζ toward +x (eq. 3–5), every node's height the exact lowest cut of
//! the passes that reach it. Columns (constant x) run in parallel; each shares one [`Track`]
//! per pass, so the output does not depend on the thread count.

use crate::cutter::Cutter;
use crate::kinematics::{Cut, Frame, Move, Track, Zone, lower, lowest_flat};
use camkit::error::{Error, Result};
use camkit::geom::{P3, V3};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Cutting conditions of a patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conditions {
    /// The tool.
    pub cutter: Cutter,
    /// Pick feed f (mm).
    pub pick: f64,
    /// Feed per tooth F/(N·Z) (mm).
    pub feed_per_tooth: f64,
    /// Tilt ζ of the axis from the vertical (rad), in [0, π/2).
    pub tilt: f64,
    /// Side the shank leans to: +1 toward +x (eq. 3 as printed: the tip's trace moves to −x),
    /// −1 toward −x.
    pub lean: f64,
    /// Spindle angle of flute 1 at y = 0 on pass k is k times this (rad).
    pub pass_phase: f64,
}

/// Memory bound of a height map unless the caller says otherwise (bytes).
pub const DEFAULT_MEMORY: u64 = 2 << 30;

impl Conditions {
    /// Checks the conditions (bad input: exit status 2).
    pub fn validate(&self) -> Result<()> {
        self.cutter.validate()?;
        let r = self.cutter.radius;
        if !(self.pick.is_finite() && self.pick > 0.0 && self.pick < 2.0 * r) {
            return Err(Error::input(format!(
                "pick feed must be positive and below the tool diameter 2r = {} mm, got {} mm",
                2.0 * r,
                self.pick
            )));
        }
        if !(self.feed_per_tooth.is_finite() && self.feed_per_tooth > 0.0) {
            return Err(Error::input(format!(
                "feed per tooth must be positive (feed and spindle speed positive), got {} mm",
                self.feed_per_tooth
            )));
        }
        if !(self.tilt.is_finite() && self.tilt >= 0.0 && self.tilt < PI / 2.0) {
            return Err(Error::input(format!("tilt must be in [0°, 90°), got {}°", self.tilt.to_degrees())));
        }
        if self.lean.abs() != 1.0 {
            return Err(Error::input("the tilt leans toward +x (+1) or −x (−1)"));
        }
        if !self.pass_phase.is_finite() {
            return Err(Error::input("pass phase must be a finite angle"));
        }
        Ok(())
    }

    /// Feed per radian of spindle rotation, F/(2πN) (mm/rad).
    pub fn feed_per_radian(&self) -> f64 {
        self.feed_per_tooth * self.cutter.flutes as f64 / (2.0 * PI)
    }

    /// Height of the tool's lowest point: heights are measured from it (the nominal surface).
    pub fn reference(&self) -> f64 {
        self.cutter.radius - self.cutter.lowest_below_centre(self.tilt)
    }

    /// The move of pass k covering y ∈ [y_lo, y_hi] with a margin of the tool radius.
    pub fn pass(&self, k: i64, y_lo: f64, y_hi: f64) -> Move {
        let r = self.cutter.radius;
        let a = self.feed_per_radian();
        let y_start = y_lo - r - 1.0;
        let sigma = self.cutter.rotation.sign();
        Move {
            c0: P3::new(k as f64 * self.pick, y_start, r),
            dc: V3::new(0.0, a, 0.0),
            span: (y_hi + r + 1.0 - y_start) / a,
            // Flute 1 at angle k·pass_phase when the centre is at y = 0.
            phase: k as f64 * self.pass_phase + sigma * y_start / a,
            frame: Frame::tilted(self.lean * self.tilt),
        }
    }

    /// Passes whose ball reaches x, nearest first (ties: the lower index first), generated one
    /// at a time: the callers stop once a pass's lowest possible cut is above the surface found,
    /// so a large radius over a small pick feed never lists every pass the ball reaches.
    pub fn passes_near(&self, x: f64) -> impl Iterator<Item = i64> + use<> {
        let (r, pick) = (self.cutter.radius, self.pick);
        let below = (x / pick).floor() as i64;
        let (mut left, mut right) = (below, below.saturating_add(1));
        std::iter::from_fn(move || {
            let (dl, dr) = (x - left as f64 * pick, right as f64 * pick - x);
            let (k, d) = if dl <= dr { (left, dl) } else { (right, dr) };
            if d.abs() >= r {
                return None;
            }
            if dl <= dr {
                left = left.saturating_sub(1);
            } else {
                right = right.saturating_add(1);
            }
            Some(k)
        })
    }
}

/// A rectangular grid of nodes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// First node's x, y (mm).
    pub x0: f64,
    /// First node's y (mm).
    pub y0: f64,
    /// Node spacing (mm).
    pub step: f64,
    /// Nodes along x.
    pub nx: usize,
    /// Nodes along y.
    pub ny: usize,
}

impl Grid {
    /// Nodes covering [x0, x1] × [y0, y1] at `step` (both ends included when they fall on it).
    pub fn covering(x0: f64, x1: f64, y0: f64, y1: f64, step: f64) -> Grid {
        // Saturating: a patch too large to hold is counted, not wrapped, and the budget refuses it.
        let n = |len: f64| (((len / step) * (1.0 + 1e-12)).floor() as usize).saturating_add(1);
        Grid { x0, y0, step, nx: n(x1 - x0), ny: n(y1 - y0) }
    }

    /// x of column i.
    pub fn x(&self, i: usize) -> f64 {
        self.x0 + i as f64 * self.step
    }

    /// y of row j.
    pub fn y(&self, j: usize) -> f64 {
        self.y0 + j as f64 * self.step
    }
}

/// Heights on a grid, column-major (`h[i * ny + j]` at x_i, y_j), mm above the nominal surface;
/// NaN where no edge passed.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightMap {
    /// The nodes.
    pub grid: Grid,
    /// Heights (mm).
    pub h: Vec<f64>,
}

impl HeightMap {
    /// Height at column i, row j.
    pub fn at(&self, i: usize, j: usize) -> f64 {
        self.h[i * self.grid.ny + j]
    }

    /// Column i.
    pub fn column(&self, i: usize) -> &[f64] {
        &self.h[i * self.grid.ny..(i + 1) * self.grid.ny]
    }
}

/// The lowest cut over (x, y) of the patch's passes, with the pass that made it.
pub fn node_cut(cond: &Conditions, x: f64, y: f64) -> Option<(i64, Cut)> {
    let mut best: Option<(i64, Cut)> = None;
    for k in cond.passes_near(x) {
        let mv = cond.pass(k, y, y);
        if best.is_some_and(|(_, b)| mv.lower_bound(&cond.cutter, x, y).is_none_or(|lb| lb >= b.z)) {
            break;
        }
        let ball = Track::new(&cond.cutter, &mv, x, y).lowest(x, y);
        let flat = if cond.cutter.flat_radius > 0.0 { lowest_flat(&cond.cutter, &mv, x, y) } else { None };
        if let Some(c) = lower(ball, flat) {
            if best.is_none_or(|(_, b)| c.z < b.z) {
                best = Some((k, c));
            }
        }
    }
    best
}

/// Heights of one column of the grid.
fn column(cond: &Conditions, grid: &Grid, i: usize, out: &mut [f64]) {
    let x = grid.x(i);
    let (y_lo, y_hi) = (grid.y(0), grid.y(grid.ny.saturating_sub(1)));
    let reference = cond.reference();
    let r = cond.cutter.radius;
    // Passes nearest first, each with its move, the lowest the ball can cut at its offset (a
    // horizontal pass) and its lazily built track; taken from `order` only when needed.
    let mut order = cond.passes_near(x);
    let mut passes: Vec<(Move, f64, Option<Track>)> = Vec::new();
    for (j, slot) in out.iter_mut().enumerate() {
        let y = grid.y(j);
        let mut best = f64::INFINITY;
        for p in 0.. {
            if p == passes.len() {
                let Some(k) = order.next() else { break };
                let mv = cond.pass(k, y_lo, y_hi);
                let d = (x - mv.c0.x).abs();
                passes.push((mv, mv.c0.z - (r * r - d * d).max(0.0).sqrt(), None));
            }
            let (mv, bound, track) = &mut passes[p];
            if *bound >= best {
                break;
            }
            let track = track.get_or_insert_with(|| Track::new(&cond.cutter, mv, x, y));
            let mut cut = track.lowest(x, y);
            if cond.cutter.flat_radius > 0.0 {
                cut = lower(cut, lowest_flat(&cond.cutter, mv, x, y));
            }
            if let Some(c) = cut {
                best = best.min(c.z);
            }
        }
        *slot = if best.is_finite() { best - reference } else { f64::NAN };
    }
}

/// The height map of the patch on `grid`: one period computed node by node and repeated
/// ([`periods`]) when the grid fits the periods, else every node.
pub fn simulate(cond: &Conditions, grid: &Grid) -> HeightMap {
    match periods(cond, grid) {
        Some((m, p, d)) if grid.nx * grid.ny > m * p => {
            tile(&simulate_nodes(cond, &Grid { nx: m, ny: p, ..*grid }), (m, p, d), grid)
        }
        _ => simulate_nodes(cond, grid),
    }
}

/// The map on `grid` (same origin and step as `base`) repeating the first `m` columns and `p`
/// rows of `base` with the periods `(m, p, d)` of [`periods`].
pub fn tile(base: &HeightMap, (m, p, d): (usize, usize, usize), grid: &Grid) -> HeightMap {
    let mut h = vec![0.0; grid.nx * grid.ny];
    h.par_chunks_mut(grid.ny.max(1)).enumerate().for_each(|(i, col)| {
        let (src, shift) = (base.column(i % m), (i / m) * d);
        for (j, v) in col.iter_mut().enumerate() {
            *v = src[(j + shift) % p];
        }
    });
    HeightMap { grid: *grid, h }
}

/// The height map with every node computed (no use of the periods).
pub fn simulate_nodes(cond: &Conditions, grid: &Grid) -> HeightMap {
    let mut h = vec![0.0; grid.nx * grid.ny];
    h.par_chunks_mut(grid.ny.max(1)).enumerate().for_each(|(i, col)| column(cond, grid, i, col));
    HeightMap { grid: *grid, h }
}

/// The surface's periods in grid steps, when all are whole: it repeats every feed per tooth in
/// y (the flutes are alike) and every pick feed in x shifted by σ·(pass phase)·F/(2πN) in y
/// (pass k + 1 is pass k moved by f and that much along the feed; the passes are endless).
/// `(m, p, d)`: columns per pick, rows per tooth, rows of shift per pass.
pub fn periods(cond: &Conditions, grid: &Grid) -> Option<(usize, usize, usize)> {
    let whole = |v: f64| {
        let n = v.round();
        ((v - n).abs() < PERIOD_TOL * v.abs().max(1.0) && n >= 0.0).then_some(n as usize)
    };
    let fz = cond.feed_per_tooth;
    let shift = cond.cutter.rotation.sign() * cond.pass_phase * cond.feed_per_radian();
    let (m, p, d) = (whole(cond.pick / grid.step)?, whole(fz / grid.step)?, whole(shift.rem_euclid(fz) / grid.step)?);
    // Lazily: with a feed per tooth below the step p is 0 and d % p would divide by zero.
    (m >= 1 && p >= 1).then(|| (m, p, d % p))
}

/// A period is a whole number of grid steps when within this fraction of one (the position
/// error it makes over a 10 mm patch stays below 1e-10 mm).
const PERIOD_TOL: f64 = 1e-9;

/// Which part of the tool and which pass cut each node: for the figures' classification.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeSource {
    /// Pass index.
    pub pass: i64,
    /// Zone of the flute.
    pub zone: Zone,
    /// Distance of the cutting point from the axis (mm).
    pub radial: f64,
}

/// The cut at one node with its source (slow path, for inspection and tests).
pub fn node_source(cond: &Conditions, x: f64, y: f64) -> Option<(f64, NodeSource)> {
    node_cut(cond, x, y).map(|(pass, c)| (c.z - cond.reference(), NodeSource { pass, zone: c.zone, radial: c.radial }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cutter::Rotation;

    fn paper(fz: f64, flutes: u32, tilt_deg: f64) -> Conditions {
        Conditions {
            cutter: Cutter::ball(5.0, flutes),
            pick: 0.5,
            feed_per_tooth: fz,
            tilt: tilt_deg.to_radians(),
            lean: 1.0,
            pass_phase: 0.0,
        }
    }

    #[test]
    fn repeated_periods_equal_every_node_computed() {
        for (phase, rotation) in [(90.0f64, Rotation::Ccw), (90.0, Rotation::Cw), (37.5, Rotation::Ccw)] {
            let mut cond = paper(0.4, 2, 3.0);
            cond.pass_phase = phase.to_radians();
            cond.cutter.rotation = rotation;
            // 37.5° per pass shifts by 0.4·2/(2π)·37.5° = 1/12 mm: not a whole number of steps.
            let grid = Grid::covering(-0.6, 0.9, -0.2, 0.9, 0.02);
            let tiled = simulate(&cond, &grid);
            let every = simulate_nodes(&cond, &grid);
            assert_eq!(periods(&cond, &grid).is_some(), phase == 90.0);
            let worst = tiled.h.iter().zip(&every.h).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(worst < 1e-10, "phase {phase}: {worst} mm");
        }
    }

    /// A feed per tooth below the grid step has no whole period in y (it used to divide by
    /// zero: `sweep --values 1e-12 --step 0.02`, exit 101).
    #[test]
    fn no_period_below_one_step() {
        let cond = paper(1e-12, 2, 0.0);
        let grid = Grid::covering(-0.25, 0.25, 0.0, cond.feed_per_tooth, 0.02);
        assert_eq!(periods(&cond, &grid), None);
        let map = simulate(&cond, &grid);
        assert_eq!(map.h.len(), 26);
        assert!(map.h.iter().all(|v| v.is_finite()));
    }

    /// The passes come nearest first, exactly those the ball reaches, and a huge number of
    /// reachable passes is not listed up front.
    #[test]
    fn passes_nearest_first() {
        let cond = paper(0.5, 2, 0.0);
        let ks: Vec<i64> = cond.passes_near(0.3).collect();
        let mut want: Vec<i64> = (-20..=20).filter(|&k| (0.3 - k as f64 * 0.5).abs() < 5.0).collect();
        want.sort_by(|a, b| (0.3 - *a as f64 * 0.5).abs().total_cmp(&(0.3 - *b as f64 * 0.5).abs()).then(a.cmp(b)));
        assert_eq!(ks, want);
        let wide = Conditions { pick: 1e-9, ..cond };
        assert_eq!(wide.passes_near(0.0).take(3).collect::<Vec<_>>(), vec![0, -1, 1]);
    }

    #[test]
    fn columns_agree_with_single_nodes() {
        let cond = paper(0.5, 2, 3.0);
        let grid = Grid::covering(-0.25, 0.25, 0.0, 0.5, 0.05);
        let map = simulate(&cond, &grid);
        for i in 0..grid.nx {
            for j in 0..grid.ny {
                let (h, _) = node_source(&cond, grid.x(i), grid.y(j)).unwrap();
                assert!((h - map.at(i, j)).abs() < 1e-12, "{i} {j}");
            }
        }
    }
}
