//! The stock a program has not cut yet, as a height map: nodes on a square grid over the stock's
//! outline, each standing for its cell (the square of the spacing round it) and holding a height
//! no material in the cell rises above (none outside the outline). A cut by a vertical tool lowers
//! a node only as far as it is sure of over the whole cell: to the lowest height the tool's bottom
//! passes at over the node, with the bottom raised as if every point were half a cell's diagonal
//! further from the axis. A footprint sees every cell within half a diagonal of it.
//!
//! So the map is conservative everywhere: it never shows less material than there is, and a
//! footprint never misses material in a cell it touches, however thin (a crescent of stock left
//! between two passes, narrower than the spacing, is in the cells it lies in). The price is half a
//! cell's diagonal at every cut's edge, where the map keeps material the tool has removed. The map
//! therefore also keeps every cut (the history): a footprint wholly inside one cut's swept region
//! has nothing above that cut's bottom, exactly, which is what a tool coming down where it cut
//! before (a slot of its own width, the next layer of a pass) needs.

use crate::contour::Seg;
use crate::doc::setup::Stock;
use crate::doc::tool::{Tool, ToolKind};
use crate::geom::P2;
use crate::geom::arc::PreparedArc;

/// The bottom of a rotating tool seen along a vertical axis: a flat of radius `radius − corner`
/// and a torus of radius `corner` round it (flat end mill: corner 0; ball: corner = radius).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cutter {
    /// Radius R (mm).
    pub radius: f64,
    /// Corner radius (mm), 0 ≤ corner ≤ radius.
    pub corner: f64,
}

impl Cutter {
    /// The cutter of a tool document (non-rotating tools as flat cylinders of their radius).
    pub fn of(tool: &Tool) -> Cutter {
        let corner = match tool.kind {
            ToolKind::Ball => tool.radius,
            ToolKind::Bull => tool.corner_radius,
            _ => 0.0,
        };
        Cutter { radius: tool.radius, corner }
    }

    /// Height of the tool's bottom above its tip at horizontal distance `rho` from the axis
    /// (+∞ beyond the radius).
    pub fn lift(&self, rho: f64) -> f64 {
        let flat = self.radius - self.corner;
        if rho <= flat {
            0.0
        } else if rho <= self.radius {
            let d = rho - flat;
            self.corner - (self.corner * self.corner - d * d).max(0.0).sqrt()
        } else {
            f64::INFINITY
        }
    }
}

/// One cut of the history: the cutter, the XY piece, the tip's heights at its ends.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cut {
    cutter: Cutter,
    piece: Seg,
    z0: f64,
    z1: f64,
}

/// Cuts per block of a [`History`].
const HISTORY_BLOCK: usize = 4096;

/// Every cut, in order, kept in blocks of [`HISTORY_BLOCK`]: the history grows a block at a time
/// and is never copied into a larger one (a doubling vector holds both copies while it grows: a
/// third of a long program's history, transiently, at every doubling).
#[derive(Clone, Debug, Default, PartialEq)]
struct History {
    blocks: Vec<Vec<Cut>>,
    len: usize,
}

impl History {
    fn len(&self) -> usize {
        self.len
    }

    fn push(&mut self, cut: Cut) {
        if self.blocks.last().is_none_or(|b| b.len() == HISTORY_BLOCK) {
            self.blocks.push(Vec::with_capacity(HISTORY_BLOCK));
        }
        self.blocks.last_mut().expect("a block with room").push(cut);
        self.len += 1;
    }
}

impl std::ops::Index<usize> for History {
    type Output = Cut;

    fn index(&self, k: usize) -> &Cut {
        &self.blocks[k / HISTORY_BLOCK][k % HISTORY_BLOCK]
    }
}

/// The remaining stock.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    origin: P2,
    step: f64,
    nx: usize,
    ny: usize,
    /// Top of the material at each node (row-major in y); −∞ where there is none.
    top: Vec<f64>,
    bottom: f64,
    /// Every cut, in order.
    cuts: History,
    /// The cuts whose reach meets each bucket (squares of `bucket` mm from `origin`).
    buckets: std::collections::HashMap<(i64, i64), Vec<u32>>,
    bucket: f64,
}

/// Half the diagonal of a cell of spacing `step`.
fn half_diagonal(step: f64) -> f64 {
    step * std::f64::consts::FRAC_1_SQRT_2
}

/// Golden-section steps of a ramp's lowest passage over a node.
const GOLDEN_STEPS: usize = 40;

impl Material {
    /// The uncut stock on a grid of `step` mm; `Err` with the node count if it would exceed
    /// `max_nodes`.
    pub fn new(stock: &Stock, step: f64, max_nodes: usize) -> Result<Material, usize> {
        if !step.is_finite() || step <= 0.0 {
            return Err(usize::MAX);
        }
        let (lo, hi) = stock.extent();
        let nx = ((hi[0] - lo[0]) / step).floor() as usize + 1;
        let ny = ((hi[1] - lo[1]) / step).floor() as usize + 1;
        let n = nx.saturating_mul(ny);
        if n > max_nodes {
            return Err(n);
        }
        let origin = P2::new(lo[0], lo[1]);
        let top = (0..n)
            .map(|k| {
                let p = origin + nalgebra::Vector2::new((k % nx) as f64 * step, (k / nx) as f64 * step);
                if stock.covers(p.x, p.y) { stock.top() } else { f64::NEG_INFINITY }
            })
            .collect();
        let bucket = (8.0 * step).max(1.0);
        Ok(Material {
            origin,
            step,
            nx,
            ny,
            top,
            bottom: stock.bottom(),
            cuts: History::default(),
            buckets: Default::default(),
            bucket,
        })
    }

    /// Node spacing (mm).
    pub fn step(&self) -> f64 {
        self.step
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.top.len()
    }

    /// Bottom of the stock.
    pub fn bottom(&self) -> f64 {
        self.bottom
    }

    fn node(&self, i: usize, j: usize) -> P2 {
        self.origin + nalgebra::Vector2::new(i as f64 * self.step, j as f64 * self.step)
    }

    /// Index ranges of the nodes inside the box `lo`..`hi` (empty ranges when it misses the map).
    fn span(&self, lo: P2, hi: P2) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
        let range = |a: f64, b: f64, o: f64, n: usize| {
            let i0 = ((a - o) / self.step).ceil().max(0.0);
            let i1 = ((b - o) / self.step).floor();
            if i1.is_nan() || i1 < 0.0 || i0 > i1 || i0 >= n as f64 {
                return 0..0;
            }
            i0 as usize..(i1 as usize).min(n - 1) + 1
        };
        (range(lo.x, hi.x, self.origin.x, self.nx), range(lo.y, hi.y, self.origin.y, self.ny))
    }

    /// Nodes within `reach` of the piece's bounds.
    fn near(&self, piece: &Seg, reach: f64) -> impl Iterator<Item = (usize, P2)> + '_ {
        let (lo, hi) = piece.bounds();
        let (xs, ys) = self.span(P2::new(lo.x - reach, lo.y - reach), P2::new(hi.x + reach, hi.y + reach));
        ys.flat_map(move |j| xs.clone().map(move |i| (j * self.nx + i, self.node(i, j))))
    }

    /// The radius a footprint query covers: every cell the footprint touches.
    fn footprint(&self, radius: f64) -> f64 {
        radius.max(0.0) + half_diagonal(self.step)
    }

    /// Top of the material at the node nearest `p` (−∞ where there is none).
    pub fn top_near(&self, p: &P2) -> f64 {
        let i = ((p.x - self.origin.x) / self.step).round();
        let j = ((p.y - self.origin.y) / self.step).round();
        if i < 0.0 || j < 0.0 || i >= self.nx as f64 || j >= self.ny as f64 {
            return f64::NEG_INFINITY;
        }
        self.top[j as usize * self.nx + i as usize]
    }

    /// The tool with its tip going from height `z0` to `z1` (linearly along the piece) over the
    /// XY piece cuts the material under its bottom.
    pub fn cut(&mut self, cutter: &Cutter, piece: &Seg, z0: f64, z1: f64) {
        let (lo, hi) = piece.bounds();
        let (b0, b1) = (self.bucket_of(&lo, -cutter.radius), self.bucket_of(&hi, cutter.radius));
        let index = self.cuts.len() as u32;
        self.cuts.push(Cut { cutter: *cutter, piece: *piece, z0, z1 });
        for i in b0.0..=b1.0 {
            for j in b0.1..=b1.1 {
                self.buckets.entry((i, j)).or_default().push(index);
            }
        }
        let d = half_diagonal(self.step);
        let r = cutter.radius - d;
        if r < 0.0 {
            return;
        }
        let nodes: Vec<(usize, P2)> = self.near(piece, r).collect();
        let prepared = Prepared::of(piece);
        for (k, p) in nodes {
            if self.top[k] == f64::NEG_INFINITY {
                continue;
            }
            let low = lowest_pass(cutter, d, &prepared, z0, z1, &p);
            if low < self.top[k] {
                self.top[k] = low;
            }
        }
    }

    /// Smallest height of a flat-bottomed footprint of `radius` above the material, the
    /// footprint's bottom going from `z0` to `z1` (linearly) over the XY piece: over every node
    /// within `radius` of the piece, the lowest the bottom is while the node is under it, less the
    /// node's top. `None` if no material lies under the footprint. Also returns the node.
    pub fn clearance(&self, piece: &Seg, z0: f64, z1: f64, radius: f64) -> Option<(f64, P2)> {
        if let Seg::Line(a, b) = piece
            && a == b
        {
            // A move straight up or down: the footprint stands still.
            let top = self.highest_within(a, radius);
            return (top > f64::NEG_INFINITY).then_some((z0.min(z1) - top, *a));
        }
        let r = radius.max(0.0);
        let radius = self.footprint(radius);
        let mut best: Option<(f64, P2)> = None;
        for (k, p) in self.near(piece, radius) {
            let top = self.top[k];
            if top == f64::NEG_INFINITY {
                continue;
            }
            let Some((t0, t1)) = under(piece, &p, radius) else { continue };
            let z = (z0 + (z1 - z0) * t0).min(z0 + (z1 - z0) * t1);
            let c = z - top;
            if best.is_none_or(|(b, _)| c < b) {
                best = Some((c, p));
            }
        }
        // The whole footprint inside one cut's swept region: that cut bounds the material.
        let (lo, hi) = piece.bounds();
        let (b0, b1) = (self.bucket_of(&lo, 0.0), self.bucket_of(&hi, 0.0));
        let mut bound = f64::INFINITY;
        for i in b0.0..=b1.0 {
            for j in b0.1..=b1.1 {
                for &k in self.buckets.get(&(i, j)).map_or(&[][..], Vec::as_slice) {
                    let c = &self.cuts[k as usize];
                    let far = piece.max_distance_to(&c.piece);
                    if far + r <= c.cutter.radius {
                        bound = bound.min(c.z0.max(c.z1) + c.cutter.lift(far + r));
                    }
                }
            }
        }
        best.map(|(c, p)| (c.max(z0.min(z1) - bound), p))
    }

    /// The bucket holding `p` moved by `grow` in both coordinates.
    fn bucket_of(&self, p: &P2, grow: f64) -> (i64, i64) {
        (
            ((p.x + grow - self.origin.x) / self.bucket).floor() as i64,
            ((p.y + grow - self.origin.y) / self.bucket).floor() as i64,
        )
    }

    /// Highest material within `radius` of the XY point `p` (−∞ if none): the cells' heights, or
    /// less where the footprint lies wholly inside one cut's swept region (that cut's bottom
    /// bounds the material there).
    pub fn highest_within(&self, p: &P2, radius: f64) -> f64 {
        let cells = self.highest_along(&Seg::Line(*p, *p), radius);
        if cells == f64::NEG_INFINITY {
            return cells;
        }
        let r = radius.max(0.0);
        let mut best = cells;
        if let Some(list) = self.buckets.get(&self.bucket_of(p, 0.0)) {
            for &k in list {
                let c = &self.cuts[k as usize];
                let t = nearest_fraction(&c.piece, p);
                let d = (c.piece.point_at(t) - p).norm();
                if d + r <= c.cutter.radius {
                    // Every point of the footprint is within the cutter's reach of the piece's
                    // point at `t`: the bottom there is at most this high over it.
                    best = best.min(c.z0 + (c.z1 - c.z0) * t + c.cutter.lift(d + r));
                }
            }
        }
        best
    }

    /// Highest material within `radius` of the XY piece (−∞ if none).
    pub fn highest_along(&self, piece: &Seg, radius: f64) -> f64 {
        let radius = self.footprint(radius);
        self.near(piece, radius)
            .filter(|(_, q)| piece.distance_to(q) <= radius)
            .map(|(k, _)| self.top[k])
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// The range of fractions of `piece` during which `p` lies within `radius` of the point of the
/// piece at that fraction (one interval: exact for a line, the hull of the arcs' interval for an
/// arc, which only widens it).
fn under(piece: &Seg, p: &P2, radius: f64) -> Option<(f64, f64)> {
    match piece {
        Seg::Line(a, b) => {
            let d = b - a;
            let l2 = d.norm_squared();
            if l2 == 0.0 {
                return ((p - a).norm() <= radius).then_some((0.0, 1.0));
            }
            // |a + t d − p|² ≤ r²: a quadratic in t.
            let w = a - p;
            let (qa, qb, qc) = (l2, 2.0 * w.dot(&d), w.norm_squared() - radius * radius);
            let disc = qb * qb - 4.0 * qa * qc;
            if disc < 0.0 {
                return None;
            }
            let s = disc.sqrt();
            let (t0, t1) = ((-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa));
            let (t0, t1) = (t0.max(0.0), t1.min(1.0));
            (t0 <= t1).then_some((t0, t1))
        }
        Seg::Arc(arc) => {
            let prepared = PreparedArc::new(arc);
            if prepared.distance(p) > radius {
                return None;
            }
            // The directions from the centre whose circle point is within reach of `p`: a window
            // of half-width acos((d² + r² − R²) / 2rd) about the direction of `p`.
            let v = p - arc.c;
            let d = v.norm();
            let k = if d > 0.0 { (d * d + arc.r * arc.r - radius * radius) / (2.0 * arc.r * d) } else { -1.0 };
            let sweep = arc.sweep.abs();
            if k <= -1.0 || sweep == 0.0 {
                return Some((0.0, 1.0));
            }
            let half = k.min(1.0).acos();
            let mid = arc.progress(crate::geom::arc::angle_of(&v));
            // The window in progress along the sweep, its copies a turn either side, cut to it.
            let mut hull: Option<(f64, f64)> = None;
            for shift in [-std::f64::consts::TAU, 0.0, std::f64::consts::TAU] {
                let (lo, hi) = ((mid - half + shift).max(0.0), (mid + half + shift).min(sweep));
                if lo <= hi {
                    hull = Some(hull.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
                }
            }
            hull.map(|(lo, hi)| (lo / sweep, hi / sweep))
        }
    }
}

/// A piece made ready for the distances of many nodes.
enum Prepared<'a> {
    Line(&'a Seg),
    Arc(&'a Seg, PreparedArc),
}

impl<'a> Prepared<'a> {
    fn of(piece: &'a Seg) -> Prepared<'a> {
        match piece {
            Seg::Line(..) => Prepared::Line(piece),
            Seg::Arc(arc) => Prepared::Arc(piece, PreparedArc::new(arc)),
        }
    }

    fn seg(&self) -> &'a Seg {
        match self {
            Prepared::Line(s) | Prepared::Arc(s, _) => s,
        }
    }

    fn distance(&self, p: &P2) -> f64 {
        match self {
            Prepared::Line(s) => s.distance_to(p),
            Prepared::Arc(_, a) => a.distance(p),
        }
    }
}

/// The lowest height the cutter's bottom reaches over `p` while its tip runs over the piece from
/// `z0` to `z1`, the bottom taken `d` further from the axis than `p` is (so the height holds for
/// every point within `d` of `p`); +∞ if it never covers `p` so. A value of the function evaluated
/// at some fractions: never below the true minimum.
fn lowest_pass(cutter: &Cutter, d: f64, prepared: &Prepared, z0: f64, z1: f64, p: &P2) -> f64 {
    let nearest = prepared.distance(p);
    if nearest + d > cutter.radius {
        return f64::INFINITY;
    }
    if z0 == z1 {
        return z0 + cutter.lift(nearest + d);
    }
    let piece = prepared.seg();
    let at = |t: f64| {
        let q = piece.point_at(t);
        z0 + (z1 - z0) * t + cutter.lift((q - p).norm() + d)
    };
    let best = at(nearest_fraction(piece, p));
    let Some((t0, t1)) = under(piece, p, cutter.radius - d) else { return f64::INFINITY };
    match prepared {
        // Over the fractions where a line's tool covers `p` the height is a linear term plus a
        // convex function of a convex distance: unimodal, so golden-section search finds it.
        Prepared::Line(_) => {
            let g = 0.5 * (5f64.sqrt() - 1.0);
            let (mut a, mut b) = (t0, t1);
            let (mut c, mut dd) = (b - g * (b - a), a + g * (b - a));
            let (mut fc, mut fd) = (at(c), at(dd));
            for _ in 0..GOLDEN_STEPS {
                if fc <= fd {
                    b = dd;
                    dd = c;
                    fd = fc;
                    c = b - g * (b - a);
                    fc = at(c);
                } else {
                    a = c;
                    c = dd;
                    fc = fd;
                    dd = a + g * (b - a);
                    fd = at(dd);
                }
            }
            best.min(fc).min(fd).min(at(t0)).min(at(t1))
        }
        // A helix: samples over the fractions that may cover `p`, one per 1/64 of a half turn.
        Prepared::Arc(..) => {
            let turn = match piece {
                Seg::Arc(arc) => arc.sweep.abs() * (t1 - t0),
                Seg::Line(..) => 0.0,
            };
            let n = ((turn / (std::f64::consts::PI / ARC_SAMPLES as f64)).ceil() as usize).clamp(2, ARC_SAMPLES);
            (0..=n).map(|k| at(t0 + (t1 - t0) * k as f64 / n as f64)).fold(best, f64::min)
        }
    }
}

/// Samples of a helical cut over a node per half turn of the window it may cover it in.
const ARC_SAMPLES: usize = 64;

/// Fraction of the piece's point nearest `p`.
fn nearest_fraction(piece: &Seg, p: &P2) -> f64 {
    match piece {
        Seg::Line(a, b) => {
            let d = b - a;
            let l2 = d.norm_squared();
            if l2 > 0.0 { ((p - a).dot(&d) / l2).clamp(0.0, 1.0) } else { 0.0 }
        }
        Seg::Arc(arc) => {
            let phi = crate::geom::arc::angle_of(&(p - arc.c));
            if arc.spans(phi) && (p - arc.c).norm() > 0.0 {
                arc.progress(phi) / arc.sweep.abs()
            } else if (arc.start_point() - p).norm() <= (arc.end_point() - p).norm() {
                0.0
            } else {
                1.0
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Arc2, P3};
    use proptest::prelude::*;

    fn block() -> Stock {
        Stock::Box { min: P3::new(0.0, 0.0, -20.0), max: P3::new(40.0, 30.0, 0.0) }
    }

    /// Spacing 0.5: half a diagonal is 0.3536. A flat slot R4 lowers the nodes whose cells it
    /// covers (within 3.6464 of its path); a footprint sees the cells it touches.
    #[test]
    fn a_flat_slot_lowers_the_cells_it_covers() {
        let mut m = Material::new(&block(), 0.5, 1 << 20).unwrap();
        let flat = Cutter { radius: 4.0, corner: 0.0 };
        m.cut(&flat, &Seg::Line(P2::new(10.0, 15.0), P2::new(30.0, 15.0)), -5.0, -5.0);
        assert_eq!(m.top_near(&P2::new(20.0, 18.5)), -5.0);
        assert_eq!(m.top_near(&P2::new(20.0, 19.0)), 0.0);
        assert_eq!(m.top_near(&P2::new(6.5, 15.0)), -5.0);
        assert_eq!(m.top_near(&P2::new(6.0, 15.0)), 0.0);
        // A footprint deep in the slot sees its floor; one off the path reaching a cell on the
        // slot's edge sees the stock top.
        assert_eq!(m.highest_within(&P2::new(20.0, 15.0), 3.0), -5.0);
        assert_eq!(m.highest_within(&P2::new(20.0, 15.5), 3.6), 0.0);
        // A footprint as wide as the slot, on its path, lies inside its swept region: it sees
        // the floor, exactly; moved off the path it sees the stock beside the slot.
        assert_eq!(m.highest_within(&P2::new(20.0, 15.0), 3.999), -5.0);
        assert_eq!(m.highest_within(&P2::new(20.0, 15.002), 3.999), 0.0);
        // A rapid coming down at (20, 15) over a footprint of 3 clears the floor by 3; a rapid
        // across at −2 runs into the stock beside the slot.
        let (c, _) = m.clearance(&Seg::Line(P2::new(20.0, 15.0), P2::new(20.0, 15.0)), 1.0, -2.0, 3.0).unwrap();
        assert_eq!(c, 3.0);
        let (c, at) = m.clearance(&Seg::Line(P2::new(12.0, 15.0), P2::new(12.0, 25.0)), -2.0, -2.0, 4.0).unwrap();
        assert_eq!(c, -2.0);
        assert_eq!(m.top_near(&at), 0.0, "{at:?}");
        // Along the slot's own path at −2 with a footprint of its width: 3 over its floor (the
        // cells alone see its edges at the stock top); 0.1 off the path, the edges again.
        let along = Seg::Line(P2::new(25.0, 15.0), P2::new(12.0, 15.0));
        assert_eq!(m.clearance(&along, -2.0, -2.0, 3.99).unwrap().0, 3.0);
        let beside = Seg::Line(P2::new(25.0, 15.1), P2::new(12.0, 15.1));
        assert_eq!(m.clearance(&beside, -2.0, -2.0, 3.99).unwrap().0, -2.0);
        // A footprint smaller than the spacing sees the cells round it.
        assert_eq!(m.highest_within(&P2::new(20.2, 19.7), 0.01), 0.0);
        assert_eq!(m.highest_within(&P2::new(20.2, 15.2), 0.01), -5.0);
        // Outside the stock there is nothing.
        assert!(m.clearance(&Seg::Line(P2::new(50.0, 15.0), P2::new(60.0, 15.0)), -10.0, -10.0, 4.0).is_none());
    }

    #[test]
    fn a_ball_leaves_its_own_section() {
        let mut m = Material::new(&block(), 0.25, 1 << 20).unwrap();
        let ball = Cutter { radius: 3.0, corner: 3.0 };
        m.cut(&ball, &Seg::Line(P2::new(5.0, 15.0), P2::new(35.0, 15.0)), -3.0, -3.0);
        let d = half_diagonal(0.25);
        for dy in [0.0, 1.0, 2.0, 2.5] {
            let want = -3.0 + 3.0 - (9.0f64 - (dy + d) * (dy + d)).sqrt();
            assert!((m.top_near(&P2::new(20.0, 15.0 + dy)) - want).abs() < 1e-12, "{dy}");
        }
    }

    #[test]
    fn a_helix_lowers_no_node_below_its_path() {
        // A flat end mill ramping round a circle: a node on the circle at fraction t is cut to
        // z(t) exactly (the tip passes over it); none lower than the ramp's lowest height.
        let mut m = Material::new(&block(), 0.5, 1 << 20).unwrap();
        let flat = Cutter { radius: 2.5, corner: 0.0 };
        let arc = Seg::Arc(Arc2 { c: P2::new(20.0, 15.0), r: 5.0, start: 0.0, sweep: std::f64::consts::TAU });
        m.cut(&flat, &arc, 0.0, -4.0);
        let centre = m.top_near(&P2::new(20.0, 15.0));
        assert_eq!(centre, 0.0, "the circle's centre is 5 from the path, beyond R");
        let low = (0..m.nodes()).map(|k| m.top[k]).fold(f64::INFINITY, f64::min);
        assert!(low >= -4.0 - 1e-12, "{low}");
        // The node at angle 0 is under the tip at the start and at the end: the end is lower.
        assert!((m.top_near(&P2::new(25.0, 15.0)) + 4.0).abs() < 1e-9, "{}", m.top_near(&P2::new(25.0, 15.0)));
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

        /// A straight ramp's cut is conservative over each node's cell: no point of the cell is
        /// cut lower (by brute force over 2 000 positions of the tool along the move, at the
        /// node and its cell's corners and edge midpoints), and the node's height is no higher
        /// than the brute force's lowest pass with the cell's reach.
        #[test]
        fn ramp_cuts_are_conservative_over_each_cell(
            ax in 5.0f64..35.0, ay in 5.0f64..25.0, bx in 5.0f64..35.0, by in 5.0f64..25.0,
            z0 in -10.0f64..0.0, z1 in -10.0f64..0.0, corner in 0.0f64..1.0,
        ) {
            let cutter = Cutter { radius: 3.0, corner: 3.0 * corner };
            let piece = Seg::Line(P2::new(ax, ay), P2::new(bx, by));
            let mut m = Material::new(&block(), 0.5, 1 << 20).unwrap();
            m.cut(&cutter, &piece, z0, z1);
            let n = 2_000;
            let slack = (z1 - z0).abs() / n as f64 + 1e-6;
            let brute = |q: &P2, grow: f64| {
                (0..=n)
                    .map(|i| {
                        let t = i as f64 / n as f64;
                        z0 + (z1 - z0) * t + cutter.lift((piece.point_at(t) - q).norm() + grow)
                    })
                    .fold(0.0f64, f64::min)
            };
            let d = half_diagonal(0.5);
            for (k, p) in m.near(&piece, 3.0).collect::<Vec<_>>() {
                // A node whose cell the rim only grazes is under it at one fraction, which samples miss.
                if (piece.distance_to(&p) + d - 3.0).abs() < 1e-6 {
                    continue;
                }
                // The node and its cell's corners and edge midpoints.
                for (u, v) in [(0, 0), (1, 1), (1, -1), (-1, 1), (-1, -1), (1, 0), (-1, 0), (0, 1), (0, -1)] {
                    let q = p + nalgebra::Vector2::new(0.25 * u as f64, 0.25 * v as f64);
                    prop_assert!(m.top[k] >= brute(&q, 0.0) - slack, "node {p:?}: {} below the cut at {q:?}", m.top[k]);
                }
                // Accurate: no higher than the lowest sampled pass with the cell's reach (the samples
                // can only miss the minimum, which near a ball's steep rim may be by more than
                // the slack, so this side alone is exact).
                prop_assert!(m.top[k] <= brute(&p, d) + slack, "node {p:?}: {} vs {}", m.top[k], brute(&p, d));
            }
        }
    }
}
