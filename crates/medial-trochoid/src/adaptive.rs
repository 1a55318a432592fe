//! Adaptive clearing held at an engagement target by the exact simulation: a helical entry at
//! the largest inscribed circle, then passes that step the tool forward by a short line whose
//! heading is chosen at each step (bisection on the angle) so that the engagement against
//! everything cut before is the target, material always on the right (climb), the tool centre
//! kept R + allowance from the walls. A pass ends where no material is within reach; the next
//! starts at a cleared position next to the nearest material left, linked through cleared
//! ground (a retract where the straight link is not).

use crate::engagement::Cut;
use crate::program::{Move, Program, Tag, clearance, point_clearance};
use crate::{PlanError, Settings};
use camkit::contour::region::Region;
use camkit::contour::{Contour, Seg};
use camkit::geom::{P2, V2};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// An adaptive program of one layer and what making it decided.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Adaptive {
    /// The moves (entry circles, passes tagged contour, links).
    pub program: Program,
    /// Number of passes.
    pub passes: usize,
    /// Chains started by a retract (entries included).
    pub retracts: usize,
    /// Material grid points left uncut (mm): reachable by the tool but not cleared under the
    /// target (e.g. the walls' sharp inside corners the turn limit rounds).
    pub uncut: Vec<P2>,
    /// Area of the uncut grid points (mm², each a grid cell).
    pub uncut_area: f64,
}

/// Heading limits of the walk.
#[derive(Clone, Copy, Debug)]
struct Walk {
    /// Grid of written positions (mm), if rounded.
    unit: Option<f64>,
    /// Step length (mm).
    step: f64,
    /// Largest turn per step (radians).
    turn: f64,
    /// Target engagement (radians).
    target: f64,
    /// Tool radius (mm).
    r: f64,
    /// Wall distance R + allowance (mm).
    wall: f64,
}

impl Walk {
    /// Spacing (mm) of a link's engagement checks: with the disks at two checks d apart
    /// cleared, a circle a and b from them (a + b = d) meets material only outside both, within
    /// asin(a/2R) + asin(b/2R) ≤ asin(d/2R) on each side of the travel; at d = 2R·sin(target/8)
    /// that is a quarter of the target in all (and never over a step: the walk's own spacing).
    fn link_spacing(&self) -> f64 {
        self.step.min(2.0 * self.r * (0.125 * self.target).sin())
    }

    /// `p` on the grid of written positions.
    fn snap(&self, p: P2) -> P2 {
        self.unit.map_or(p, |u| P2::new((p.x / u).round() * u, (p.y / u).round() * u))
    }
}

/// Engagement (radians) under which a step counts as in air.
const AIR: f64 = 1e-4;

/// Smallest helix radius (mm): an entry needs the tool centre this much farther from the walls.
const ENTRY_ROOM: f64 = 1e-3;

/// Most entries (helices) in one region.
const MOST_ENTRIES: usize = 64;

/// Air (as a fraction of R) after which a pass ends: shorter runs end passes too early (box-die
/// at 0.1 R: 8.14 min), longer ones circle in cleared ground (1 R: 8.21 min; 2.5 R: 11.2 min);
/// 0.4 R gave 7.10 min (but islands2 9.30 → 9.46, dumbbell 5.47 → 5.83: the choice is rough).
const AIR_RUN: f64 = 0.4;

/// Turn (radians) into the material a fresh pass's first step may take (the later steps: 0.5):
/// a pass enters the front nearly head-on at the target instead of ramping in over several
/// steps. Swept 0.8–1.5 (four pockets at FreeCAD's targets, at 40° and 44 fuzz pockets at 60°):
/// every value shortens the first and third sums (5–7 % and 2–4 %), the 40° sum scatters
/// (−8 % to +11 %); 1.2 is the best of the sweep on all three, 0.5 (the old value) the worst.
const FRESH_TURN: f64 = 1.2;

/// Tool circumferences a pass may run without clearing a grid point of material.
const IDLE_TURNS: f64 = 2.0;

/// Most steps of one pass.
const MOST_STEPS: usize = 1_000_000;

/// How close (radians) under the target a step's engagement is taken as reached.
const ROOT_TOL: f64 = 0.003;

/// Root-finding rounds on a step's heading.
const BISECTIONS: usize = 8;

/// Fractions along a step, besides its end, where its engagement must hold the target: the
/// engagement is not monotone along a step (the tool circle sweeps over envelope arcs of its
/// own radius), and a 0.25 mm re-simulation of box-die found 80° between the end and middle
/// of a 67° step when only those two were held.
const HELD_AT: [f64; 3] = [0.5, 0.25, 0.75];

/// The cut so far, indexed piece by piece.
struct Cutting {
    cut: Cut,
}

impl Cutting {
    fn new(r: f64) -> Cutting {
        Cutting { cut: Cut::new(r, Vec::new()) }
    }

    /// Largest engagement (radians) along `seg` (at most `h` mm apart, both ends).
    fn along(&self, seg: Seg, h: f64) -> f64 {
        let n = (seg.length() / h).ceil().max(1.0) as usize;
        (0..=n).map(|k| self.cut.engagement_after(&[seg], 0, k as f64 / n as f64)).fold(0.0, f64::max)
    }

    /// Engagement (radians) of the tool standing at `p` after everything so far.
    fn standing(&self, p: P2) -> f64 {
        self.cut.engagement_at(&p, self.cut.pieces.len())
    }

    /// True if the point `q` is removed by what is cut so far.
    fn removes(&self, q: &P2) -> bool {
        self.cut.removes(q)
    }

    fn push(&mut self, seg: Seg) {
        self.cut.push(seg);
    }

    fn pop(&mut self) {
        self.cut.pop();
    }
}

/// Grid of material points: inside the region, within R of a tool position that keeps the wall
/// distance, not yet within R of a cut piece.
struct Material {
    h: f64,
    lo: P2,
    nx: usize,
    ny: usize,
    /// Material left at each grid point.
    left: Vec<bool>,
    /// Tool positions (grid points) that keep the wall distance.
    centres: Vec<bool>,
    /// Distance of each tool position to the walls (mm; 0 elsewhere).
    gap: Vec<f64>,
    /// Material cleared at each grid point.
    cleared: Vec<bool>,
    /// Material given up at each grid point (no start found next to it, or a pass from there
    /// cleared nothing).
    given_up: Vec<bool>,
}

impl Material {
    fn new(region: &Region, w: &Walk, h: f64) -> Material {
        let (lo, hi) = region.outer.bounds().expect("a region's boundary has pieces");
        let nx = ((hi.x - lo.x) / h).ceil() as usize + 1;
        let ny = ((hi.y - lo.y) / h).ceil() as usize + 1;
        let at = |i: usize, j: usize| P2::new(lo.x + i as f64 * h, lo.y + j as f64 * h);
        let mut centres = vec![false; nx * ny];
        let mut gap = vec![0.0; nx * ny];
        let mut inside = vec![false; nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                let p = at(i, j);
                if region.contains(&p) {
                    inside[j * nx + i] = true;
                    let g = point_clearance(&p, region);
                    centres[j * nx + i] = g >= w.wall;
                    gap[j * nx + i] = g;
                }
            }
        }
        let n = nx * ny;
        let mut m = Material {
            h,
            lo,
            nx,
            ny,
            left: vec![false; n],
            centres,
            gap,
            cleared: vec![false; n],
            given_up: vec![false; n],
        };
        let reach = w.r - h;
        for j in 0..ny {
            for i in 0..nx {
                if m.centres[j * nx + i] {
                    m.each_within(&at(i, j), reach, |k, _| if inside[k] { Some(k) } else { None })
                        .into_iter()
                        .for_each(|k| m.left[k] = true);
                }
            }
        }
        m
    }

    /// Number of grid points with material left.
    fn count(&self) -> usize {
        self.left.iter().filter(|&&l| l).count()
    }

    fn point(&self, k: usize) -> P2 {
        P2::new(self.lo.x + (k % self.nx) as f64 * self.h, self.lo.y + (k / self.nx) as f64 * self.h)
    }

    /// `f` of the grid points within `d` of `p` (index, point), the results kept.
    fn each_within<T>(&self, p: &P2, d: f64, mut f: impl FnMut(usize, P2) -> Option<T>) -> Vec<T> {
        let i0 = (((p.x - d - self.lo.x) / self.h).floor().max(0.0)) as usize;
        let j0 = (((p.y - d - self.lo.y) / self.h).floor().max(0.0)) as usize;
        let i1 = (((p.x + d - self.lo.x) / self.h).ceil().max(0.0) as usize).min(self.nx - 1);
        let j1 = (((p.y + d - self.lo.y) / self.h).ceil().max(0.0) as usize).min(self.ny - 1);
        let mut out = Vec::new();
        for j in j0..=j1 {
            for i in i0..=i1 {
                let k = j * self.nx + i;
                let q = self.point(k);
                if (q - p).norm() <= d
                    && let Some(t) = f(k, q)
                {
                    out.push(t);
                }
            }
        }
        out
    }

    /// Gives up the material at grid point `k` (left uncut): returns the point.
    fn give_up(&mut self, k: usize) -> P2 {
        self.left[k] = false;
        self.given_up[k] = true;
        self.point(k)
    }

    /// Unit direction from grid point `k` towards its cleared neighbours (the front's normal).
    fn cleared_side(&self, k: usize) -> Option<V2> {
        let (i, j) = ((k % self.nx) as i64, (k / self.nx) as i64);
        let mut sum = V2::zeros();
        for dj in -2..=2i64 {
            for di in -2..=2i64 {
                let (x, y) = (i + di, j + dj);
                if x >= 0
                    && y >= 0
                    && (x as usize) < self.nx
                    && (y as usize) < self.ny
                    && self.cleared[y as usize * self.nx + x as usize]
                {
                    sum += V2::new(di as f64, dj as f64);
                }
            }
        }
        (sum.norm() > 1e-9).then(|| sum.normalize())
    }

    /// True if grid point `k` has material left next to a cleared grid point (a front).
    fn on_front(&self, k: usize) -> bool {
        let (i, j) = ((k % self.nx) as i64, (k / self.nx) as i64);
        self.left[k]
            && (-1..=1).any(|dj: i64| {
                (-1..=1).any(|di: i64| {
                    let (x, y) = (i + di, j + dj);
                    x >= 0
                        && y >= 0
                        && (x as usize) < self.nx
                        && (y as usize) < self.ny
                        && self.cleared[y as usize * self.nx + x as usize]
                })
            })
    }

    /// Clears the material within `d` of `seg`.
    /// Returns how many grid points it cleared.
    fn clear(&mut self, seg: &Seg, d: f64) -> usize {
        let (a, b) = (seg.start(), seg.end());
        let mid = P2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y));
        let reach = d + 0.5 * seg.length();
        let hits = self.each_within(&mid, reach, |k, q| (seg.distance_to(&q) < d).then_some(k));
        let mut n = 0;
        for k in hits {
            if self.left[k] {
                self.left[k] = false;
                self.cleared[k] = true;
                n += 1;
            }
        }
        n
    }
}

/// The adaptive program of `regions` (one layer) at the target `s.threshold`.
/// With `unit` (mm), every position of the program is a multiple of it (as the rows are
/// written to that many decimals), so that the program planned is the one written.
pub fn plan_adaptive(regions: &[Region], s: &Settings, unit: Option<f64>) -> Result<Adaptive, PlanError> {
    let w = Walk {
        unit,
        // Under the sample spacing, so that each step is one row and one sample.
        step: 0.99 * s.sample.min(0.25 * s.radius),
        turn: 0.5,
        target: s.threshold.to_radians(),
        r: s.radius,
        wall: s.radius + s.allowance,
    };
    let h = (0.1 * s.radius).clamp(0.05, 0.5);
    let mut cutting = Cutting::new(s.radius);
    let mut out = Adaptive::default();
    for region in regions {
        let mut m = Material::new(region, &w, h);
        let unit = w.unit.unwrap_or(0.0);
        let mut given_up: Vec<P2> = Vec::new();
        // An entry where material is left and the tool stands farthest from the walls (the
        // largest inscribed circle at first), a spiral from it, passes along the fronts it
        // leaves; again while material is left that no front reaches under the target.
        for _ in 0..MOST_ENTRIES {
            let best = (0..m.centres.len())
                .filter(|&k| m.centres[k] && m.left[k] && m.gap[k] >= w.wall + ENTRY_ROOM + 2.0 * unit)
                .map(|k| (k, m.gap[k]))
                .max_by(|a, b| a.1.total_cmp(&b.1));
            let Some((k0, cl)) = best else { break };
            let c0 = w.snap(m.point(k0));
            // The helix keeps the wall distance after its centre is snapped to the written grid
            // (its radius rounded down onto it).
            let room = (0.5 * s.radius).min(cl - w.wall - 2.0 * unit);
            let rh = w.unit.map_or(room, |u| (room / u).floor() * u);
            let helix = Contour::circle(c0, rh, 0.0, true);
            out.program.push_entry(&helix, &s.entry);
            for seg in helix.segs() {
                cutting.push(seg);
                m.clear(&seg, w.r);
            }
            clear_from(&mut cutting, &mut m, region, &w, (c0 + V2::new(rh, 0.0), FRAC_PI_2), &mut given_up, &mut out);
        }
        let left: Vec<P2> = (0..m.left.len()).filter(|&k| m.left[k]).map(|k| m.point(k)).collect();
        out.uncut_area += (left.len() + given_up.len()) as f64 * h * h;
        out.uncut.extend(left);
        out.uncut.extend(given_up);
    }
    // Counted where written: a retract planned before a pass that then cuts nothing, or before
    // no pass at all, is none.
    out.retracts = out.program.moves.iter().filter(|m| m.retract_before).count();
    // Entries alone (no pass holds the target anywhere) are no program: the tool is too large.
    if out.passes == 0 {
        return Err(PlanError::NoPasses);
    }
    Ok(out)
}

/// The passes from `start` (position, heading: the end of an entry) until no front is left:
/// each pass linked to the next through cleared ground or by a retract.
fn clear_from(
    cutting: &mut Cutting,
    m: &mut Material,
    region: &Region,
    w: &Walk,
    start: (P2, f64),
    given_up: &mut Vec<P2>,
    out: &mut Adaptive,
) {
    let (mut at, mut heading) = start;
    let mut fresh = false;
    let mut retract_next = false;
    let mut target: Option<usize> = None;
    let mut first = true;
    loop {
        let before = m.count();
        let (moves, cut_any) = walk_pass(cutting, m, region, w, at, heading, fresh);
        // Where the next pass is looked for: near this one's start, so that passes sweep a
        // front one after another from the same end (climb passes cannot turn back at a wall);
        // after the spiral, near its end.
        let mut near = at;
        if cut_any {
            out.passes += 1;
            near = if first { moves[moves.len() - 1].end() } else { moves[0].start() };
            at = moves[moves.len() - 1].end();
            for (k, seg) in moves.into_iter().enumerate() {
                let retract = k == 0 && retract_next;
                out.program.moves.push(Move { seg, tag: Tag::Contour, retract_before: retract });
            }
            retract_next = false;
        }
        first = false;
        if let Some(t) = target.filter(|_| m.count() == before) {
            // Nothing cleared from this start: the material it was for is given up.
            given_up.push(m.give_up(t));
        }
        let Some((next, dir, t)) = next_start(cutting, m, region, w, near, given_up) else {
            return;
        };
        target = Some(t);
        // A link only through cleared ground: its engagement checked every `link_spacing` (the
        // whole-program check samples it at other places).
        let link = Seg::Line(at, next);
        if link.length() > camkit::tol::POINT_EPS {
            if clearance(&link, region) >= w.wall && cutting.along(link, w.link_spacing()) <= AIR {
                out.program.moves.push(Move { seg: link, tag: Tag::Link, retract_before: retract_next });
                cutting.push(link);
                retract_next = false;
            } else {
                retract_next = true;
            }
        }
        at = next;
        heading = dir;
        fresh = true;
    }
}

/// One pass from `at` heading `heading`: the steps taken and whether any cut material. `fresh`
/// starts the pass by turning freely from straight into the material to straight away from it.
fn walk_pass(
    cutting: &mut Cutting,
    m: &mut Material,
    region: &Region,
    w: &Walk,
    at: P2,
    heading: f64,
    fresh: bool,
) -> (Vec<Seg>, bool) {
    let mut out: Vec<Seg> = Vec::new();
    let mut p = at;
    let mut h = heading;
    let mut air = 0.0;
    let mut cut_any = false;
    let mut since_cut = 0usize;
    let mut idle = 0.0;
    for k in 0..MOST_STEPS {
        let (left, right) = if k == 0 && fresh {
            // From straight away from the material (on the right) to well into it.
            (h + FRAC_PI_2, h - FRESH_TURN)
        } else {
            (h + w.turn, h - w.turn)
        };
        let Some((theta, e)) = choose(cutting, region, w, p, left, right) else { break };
        let q = w.snap(p + V2::new(theta.cos(), theta.sin()) * w.step);
        let seg = Seg::Line(p, q);
        cutting.push(seg);
        if m.clear(&seg, w.r) > 0 {
            idle = 0.0;
        } else {
            idle += w.step;
        }
        out.push(seg);
        p = q;
        h = theta;
        // Cutting slivers finer than the grid round and round: the pass ends after a few tool
        // circumferences without clearing a grid point.
        if idle >= IDLE_TURNS * TAU * w.r {
            break;
        }
        if e <= AIR {
            air += w.step;
            if air >= AIR_RUN * w.r {
                break;
            }
        } else {
            air = 0.0;
            cut_any = true;
            since_cut = out.len();
        }
    }
    // Trailing air beyond the first step out of the material is dropped (it was cut in the
    // simulation but removes nothing: the pieces stay, harmless).
    let keep = if cut_any { (since_cut + 1).min(out.len()) } else { 0 };
    let dropped = out.len() - keep;
    out.truncate(keep);
    for _ in 0..dropped {
        cutting.pop();
    }
    (out, cut_any)
}

/// The heading between `left` (least engagement) and `right` (most) that turns furthest right
/// while the step keeps the wall distance and its end's engagement holds the target, with that
/// engagement (radians); `None` if even `left` does not. The heading is searched holding the
/// end and middle, then checked at [`HELD_AT`]'s quarters, and searched again holding those
/// too where they do not hold (rarely: a third of the search's cost saved).
fn choose(cutting: &Cutting, region: &Region, w: &Walk, p: P2, left: f64, right: f64) -> Option<(f64, f64)> {
    let (theta, e) = choose_holding(cutting, region, w, p, left, right, &HELD_AT[..1])?;
    let seg = Seg::Line(p, w.snap(p + V2::new(theta.cos(), theta.sin()) * w.step));
    if HELD_AT[1..].iter().all(|&t| cutting.cut.engagement_after(&[seg], 0, t) <= w.target) {
        return Some((theta, e));
    }
    choose_holding(cutting, region, w, p, left, right, &HELD_AT)
}

/// [`choose`] with the engagement held at the step's end and at the fractions `held` of it.
fn choose_holding(
    cutting: &Cutting,
    region: &Region,
    w: &Walk,
    p: P2,
    left: f64,
    right: f64,
    held: &[f64],
) -> Option<(f64, f64)> {
    let step = |theta: f64| Seg::Line(p, w.snap(p + V2::new(theta.cos(), theta.sin()) * w.step));
    // The end's engagement less the target (radians); a step that breaks the wall distance
    // counts as a full turn over.
    let over = |theta: f64| -> f64 {
        let seg = step(theta);
        if clearance(&seg, region) < w.wall {
            return TAU;
        }
        cutting.cut.engagement_after(&[seg], 0, 1.0) - w.target
    };
    // The step holds the target at its end and at `held` (the whole-program check samples the
    // end and middle).
    let holds = |theta: f64, f: f64| {
        f <= 0.0 && held.iter().all(|&t| cutting.cut.engagement_after(&[step(theta)], 0, t) <= w.target)
    };
    let fr = over(right);
    if holds(right, fr) {
        return Some((right, fr + w.target));
    }
    // Where even the leftmost heading does not hold, turning further left (up to a half turn
    // back), the first that does.
    let span = left - right;
    let (mut lo, mut flo) =
        (1..=8).map(|k| left + f64::from(k - 1) * (PI - span / 2.0).max(0.0) / 7.0).find_map(|a| {
            let f = over(a);
            holds(a, f).then_some((a, f))
        })?;
    // Regula falsi (Illinois) on the end's engagement between `lo` (holds) and `right` (does
    // not), `lo` kept on the holding side.
    let (mut hi, mut fhi) = (right, fr);
    // `wlo`: the holding side's value as weighted by the Illinois rule.
    let mut wlo = flo;
    let mut side = 0i8;
    for _ in 0..BISECTIONS {
        if flo > -ROOT_TOL {
            break;
        }
        let t = if fhi >= 1.0 { 0.5 } else { (wlo / (wlo - fhi)).clamp(0.05, 0.95) };
        let mid = lo + (hi - lo) * t;
        let f = over(mid);
        if holds(mid, f) {
            (lo, flo, wlo) = (mid, f, f);
            if side == 1 {
                fhi *= 0.5;
            }
            side = 1;
        } else {
            (hi, fhi) = (mid, f.max(1e-12));
            if side == -1 {
                wlo *= 0.5;
            }
            side = -1;
        }
    }
    Some((lo, flo + w.target))
}

/// A cleared tool position next to the material front nearest to `from` (its grid index
/// returned too), with the heading that has that material on its right; front points with no
/// such position near them are given up (added to `given_up`). `None` when no front is left.
fn next_start(
    cutting: &Cutting,
    m: &mut Material,
    region: &Region,
    w: &Walk,
    from: P2,
    given_up: &mut Vec<P2>,
) -> Option<(P2, f64, usize)> {
    loop {
        let mut front: Vec<(f64, usize)> =
            (0..m.left.len()).filter(|&k| m.on_front(k)).map(|k| ((m.point(k) - from).norm(), k)).collect();
        if front.is_empty() {
            return None;
        }
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        if let Some(found) = front_start(cutting, m, region, w, from, given_up, &front) {
            return Some(found);
        }
    }
}

/// [`next_start`] over the points of `front` (distance from `from`, grid index; nearest first):
/// those found removed are marked cleared, those with no start next to them given up.
fn front_start(
    cutting: &Cutting,
    m: &mut Material,
    region: &Region,
    w: &Walk,
    from: P2,
    given_up: &mut Vec<P2>,
    front: &[(f64, usize)],
) -> Option<(P2, f64, usize)> {
    for &(_, k) in front {
        let target = m.point(k);
        if cutting.removes(&target) {
            m.left[k] = false;
            m.cleared[k] = true;
            continue;
        }
        // Tool positions R + a little from it (or a few steps more), nearest to `from` first,
        // that stand clear.
        let normal = m.cleared_side(k).unwrap_or_else(|| (from - target).normalize());
        let mut around: Vec<P2> = [0.5, 1.0, 2.0, 4.0]
            .iter()
            .flat_map(|f| {
                let ring = w.r + f * w.step;
                (0..48).map(move |j| {
                    let a = f64::from(j) * PI / 24.0;
                    target + V2::new(a.cos(), a.sin()) * ring
                })
            })
            .collect();
        // Along the front's normal first, then turning away from it.
        around.sort_by(|a, b| {
            let key = |c: &P2| ((c - target).normalize().dot(&normal) * 8.0).round();
            key(b).total_cmp(&key(a)).then((a - target).norm().total_cmp(&(b - target).norm()))
        });
        let found = around
            .into_iter()
            .map(|c| w.snap(c))
            .find(|c| region.contains(c) && point_clearance(c, region) >= w.wall && cutting.standing(*c) <= AIR);
        if let Some(c) = found {
            let d = target - c;
            // Material on the right: heading a quarter turn left of the direction to it.
            return Some((c, d.y.atan2(d.x) + FRAC_PI_2, k));
        }
        given_up.push(m.give_up(k));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use camkit::geom::arc::angle_of;

    /// An L-shaped pocket (a 40 × 20 and a 20 × 40 leg) with a square island.
    fn l_pocket() -> Vec<Region> {
        let pts = |v: &[(f64, f64)]| v.iter().map(|&(x, y)| P2::new(x, y)).collect::<Vec<_>>();
        let outer = Contour::polygon(
            &pts(&[(0.0, 0.0), (40.0, 0.0), (40.0, 20.0), (20.0, 20.0), (20.0, 40.0), (0.0, 40.0)]),
            true,
        );
        let island = Contour::polygon(&pts(&[(6.0, 6.0), (6.0, 10.0), (10.0, 10.0), (10.0, 6.0)]), true);
        let (regions, _) = camkit::contour::region::regions(&[outer, island]).expect("a region");
        regions
    }

    #[test]
    fn every_cut_holds_the_target_with_the_material_on_the_right() {
        // The exact engagement of every cutting move's samples (the whole-program check's) is at
        // most the target, and wherever the tool is in material, the material arcs lie on the
        // right of travel (climb with a clockwise spindle): their middle within a half turn
        // clockwise of the heading.
        let r = 3.0;
        let s = Settings::for_tests(r);
        let regions = l_pocket();
        let plan = plan_adaptive(&regions, &s, None).expect("a plan");
        let a = crate::analyse(plan.program.clone(), &s, &regions);
        assert!(a.max_cutting <= 40.0 + crate::ENGAGEMENT_ROUNDOFF_DEG, "{}", a.max_cutting);
        assert_eq!(a.over + a.over_links, 0);
        assert!(a.wall_clearance >= r - 1e-9, "{}", a.wall_clearance);
        let cut = Cut::new(r, plan.program.moves.iter().map(|m| m.seg).collect());
        let mut checked = 0;
        for (&(i, t), &e) in a.samples.iter().zip(&a.engagement) {
            if plan.program.moves[i].tag != Tag::Contour || e < 1.0 {
                continue;
            }
            let heading = angle_of(&plan.program.moves[i].seg.tangent_at(t));
            for (a0, a1) in cut.material(i, t) {
                let rel = (0.5 * (a0 + a1) - heading + PI).rem_euclid(TAU) - PI;
                assert!(rel <= 0.05 && rel > -PI, "move {i}: material at {rel} rad from the heading");
            }
            checked += 1;
        }
        assert!(checked > 100, "{checked}");
        // Each pass's steps are short lines (the engagement is held at their ends and middles).
        assert!(plan.program.moves.iter().filter(|m| m.tag == Tag::Contour).all(|m| m.seg.length() <= s.sample + 1e-9));
        // What is left is named and smaller than the pocket.
        assert!(plan.uncut_area < 0.05 * (40.0 * 20.0 + 20.0 * 20.0), "{}", plan.uncut_area);
    }

    #[test]
    fn the_target_holds_between_the_samples_the_plan_checks() {
        // Re-simulated every quarter step (the planner holds ends, middles and quarters), at
        // targets where a check of ends and middles alone lets a step run over between them.
        let regions = l_pocket();
        for target in [40.0, 55.0, 67.0] {
            let s = Settings { threshold: target, ..Settings::for_tests(3.0) };
            let plan = plan_adaptive(&regions, &s, None).expect("a plan");
            let fine = Settings { sample: s.sample / 4.0, ..s };
            let a = crate::analyse(plan.program.clone(), &fine, &regions);
            assert!(a.max_cutting <= target + crate::ENGAGEMENT_ROUNDOFF_DEG, "{target}: {}", a.max_cutting);
        }
    }
}
