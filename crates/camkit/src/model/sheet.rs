//! The drop-cutter on smooth surfaces given as rational Bézier patches: B-spline patches split at
//! their knots, analytic surfaces of revolution written exactly (a profile of lines or circle
//! arcs swept by rational quadratic arcs), and the carriers of trimmed faces.
//!
//! The tip at (u, v) is the largest g = p.z − f(ρ) over points p of the surface with
//! ρ = |p.xy − (u, v)| ≤ R (f the cutter's profile). It is found by a best-first
//! branch-and-bound over pieces of the patches, halved by de Casteljau where their control net is
//! longest. A piece's tips are bounded from above (rational pieces with positive weights lie in
//! the hull of their control points) by its control points' box (its top less f at the box's
//! distance from the axis) and by the cutter resting on the plane through its highest control
//! point along its middle normal, the contact kept to the box's shadow (the plane's g is concave
//! over the box and the disc: the free maximum, else the largest on the region's edges); on a
//! smooth piece that plane is within O(h²) of the surface, so few pieces of each size survive.
//! Points of the surface give the lower bounds: each piece's middle, and where the segments from
//! it to its corners and edges' middles leave the cutter's shadow (or a trimmed face, by
//! bisection on its inside test). A trimmed face's boundary curves are dropped onto first, and a
//! piece of the face on which g has no stationary point (`monotone`) is searched no further:
//! what it holds in the face is on the boundary or on the pieces beside it (the piece across the
//! boundary, bounded by the carrier beyond it, would otherwise be halved down along it). The
//! search stops when no piece can give a tip more than [`TOL`] above the best point found, so the
//! tip found is exact to [`TOL`] below (and a point of the surface, with its normal).

use super::analytic::Analytic;
use super::bvh::Aabb;
use super::cutter::{Cutter, Plane, Touch};
use super::face::{Carrier, Curve, Face, SplineCurve};
use super::patch::{bezier_knots, bezier_spans};
use crate::geom::{P3, V3};
use crate::num::golden_arg;
use nalgebra::Isometry3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::f64::consts::{FRAC_PI_2, PI};

/// How far (mm) the tip found may be below the exact one.
pub const TOL: f64 = 1e-9;

/// What a bound by a plane is raised by (mm) for the rounding of its 1D searches.
const MARGIN: f64 = 1e-11;

/// Pieces searched per drop at most (never reached on the tests' surfaces; a guard).
const MAX_NODES: usize = 200_000;

/// Size (mm) below which a piece is left to its points: g changes by less than TOL across it
/// (slopes below 10) except beside the rim of a ball or bull-nose, where f′ is unbounded and a
/// rounding of ρ by 1e-15 mm already moves f by up to 1e-7 mm.
const MIN_PIECE: f64 = 1e-10;

/// Relative rounding (a few units in the last place) a box's distance from the axis is taken
/// nearer by: beside the rim of a ball, where f′ is unbounded, a larger margin would keep pieces
/// whose bound stands far above what they hold.
const RHO_ROUND: f64 = 4e-15;

/// Smallest n.z of a piece's middle normal for its plane alone to bound it (steeper, the plane
/// capped at the piece's top does).
const SLAB_NZ: f64 = 0.02;

/// Golden-section steps of the plane bound's searches along the shadow's edges.
const GOLDEN: usize = 64;

/// Bisection steps locating where a segment leaves the shadow or the face.
const BISECT: usize = 48;

/// How a piece's own parameter in [0, 1] maps to its source's (a patch's knots, an angle, a
/// height): monotone increasing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Map {
    /// Linearly onto [a, b].
    Linear(f64, f64),
    /// A rational quadratic arc (weights 1, cos(θ/2), 1) from angle a over θ ≤ π.
    Arc(f64, f64),
}

impl Map {
    /// The source's parameter at `s`.
    pub fn at(&self, s: f64) -> f64 {
        match *self {
            Map::Linear(a, b) => a + (b - a) * s,
            Map::Arc(a, th) => a + 0.5 * th + 2.0 * ((2.0 * s - 1.0) * (0.25 * th).tan()).atan(),
        }
    }
}

/// A rational Bézier patch: degrees, homogeneous control points (w·x, w·y, w·z, w) at
/// `i * (q + 1) + j` (i along s), all weights positive, and the maps of its parameters.
#[derive(Clone, Debug)]
pub struct Bezier {
    deg: [usize; 2],
    pts: Vec<[f64; 4]>,
    map: [Map; 2],
}

/// Bernstein polynomials of degree `p` at `s` and their derivatives.
fn bernstein(p: usize, s: f64) -> ([f64; 8], [f64; 8]) {
    let mut b = [0.0; 8];
    let mut prev = [0.0; 8];
    b[0] = 1.0;
    for k in 1..=p {
        prev = b;
        for i in 0..=k {
            let left = if i > 0 { s * prev[i - 1] } else { 0.0 };
            let right = if i < k { (1.0 - s) * prev[i] } else { 0.0 };
            b[i] = left + right;
        }
    }
    let mut d = [0.0; 8];
    if p > 0 {
        for (i, di) in d.iter_mut().enumerate().take(p + 1) {
            let a = if i > 0 { prev[i - 1] } else { 0.0 };
            let c = if i < p { prev[i] } else { 0.0 };
            *di = p as f64 * (a - c);
        }
    }
    (b, d)
}

/// A homogeneous point's Cartesian one.
fn cart(h: &[f64; 4]) -> P3 {
    P3::new(h[0] / h[3], h[1] / h[3], h[2] / h[3])
}

/// De Casteljau at ½: the two halves of a control polygon.
fn halve(c: &[[f64; 4]]) -> (Vec<[f64; 4]>, Vec<[f64; 4]>) {
    let n = c.len();
    let mut work = c.to_vec();
    let mut left = vec![work[0]; n];
    let mut right = vec![work[n - 1]; n];
    for k in 1..n {
        for i in 0..n - k {
            work[i] = std::array::from_fn(|m| 0.5 * (work[i][m] + work[i + 1][m]));
        }
        left[k] = work[0];
        right[n - 1 - k] = work[n - 1 - k];
    }
    (left, right)
}

impl Bezier {
    /// A patch of degrees `deg` from homogeneous points (`(deg[0] + 1) * (deg[1] + 1)` of them,
    /// positive weights) and its parameters' maps.
    pub fn new(deg: [usize; 2], pts: Vec<[f64; 4]>, map: [Map; 2]) -> Bezier {
        debug_assert_eq!(pts.len(), (deg[0] + 1) * (deg[1] + 1));
        Bezier { deg, pts, map }
    }

    /// The patch moved rigidly.
    pub fn moved(&self, iso: &Isometry3<f64>) -> Bezier {
        let pts = self
            .pts
            .iter()
            .map(|h| {
                let p = iso * cart(h);
                [p.x * h[3], p.y * h[3], p.z * h[3], h[3]]
            })
            .collect();
        Bezier { deg: self.deg, pts, map: self.map }
    }

    /// The Cartesian control points.
    fn points(&self) -> impl Iterator<Item = P3> + '_ {
        self.pts.iter().map(cart)
    }

    /// A box holding the patch (its control points').
    pub fn bounds(&self) -> Aabb {
        self.points().fold(Aabb::empty(), |b, p| b.with(&p))
    }

    /// Point and first partials at (s, t) of [0, 1]².
    pub fn eval(&self, s: f64, t: f64) -> (P3, V3, V3) {
        let [p, q] = self.deg;
        let (bs, ds) = bernstein(p, s);
        let (bt, dt) = bernstein(q, t);
        let (mut a, mut a_s, mut a_t) = ([0.0; 4], [0.0; 4], [0.0; 4]);
        for i in 0..=p {
            for j in 0..=q {
                let h = &self.pts[i * (q + 1) + j];
                let (w0, ws, wt) = (bs[i] * bt[j], ds[i] * bt[j], bs[i] * dt[j]);
                for m in 0..4 {
                    a[m] += w0 * h[m];
                    a_s[m] += ws * h[m];
                    a_t[m] += wt * h[m];
                }
            }
        }
        let s3 = V3::new(a[0], a[1], a[2]) / a[3];
        let d = |x: [f64; 4]| (V3::new(x[0], x[1], x[2]) - s3 * x[3]) / a[3];
        (P3::from(s3), d(a_s), d(a_t))
    }

    /// The two halves across parameter `dir` (0: s, 1: t).
    fn split(&self, dir: usize) -> (Bezier, Bezier) {
        let [p, q] = self.deg;
        let mut lo = self.pts.clone();
        let mut hi = self.pts.clone();
        if dir == 0 {
            for j in 0..=q {
                let col: Vec<[f64; 4]> = (0..=p).map(|i| self.pts[i * (q + 1) + j]).collect();
                let (l, r) = halve(&col);
                for i in 0..=p {
                    lo[i * (q + 1) + j] = l[i];
                    hi[i * (q + 1) + j] = r[i];
                }
            }
        } else {
            for i in 0..=p {
                let (l, r) = halve(&self.pts[i * (q + 1)..(i + 1) * (q + 1)]);
                lo[i * (q + 1)..(i + 1) * (q + 1)].copy_from_slice(&l);
                hi[i * (q + 1)..(i + 1) * (q + 1)].copy_from_slice(&r);
            }
        }
        (Bezier { deg: self.deg, pts: lo, map: self.map }, Bezier { deg: self.deg, pts: hi, map: self.map })
    }

    /// The longest way of the control net: 0 along s, 1 along t.
    fn longest(&self) -> usize {
        let [p, q] = self.deg;
        let at = |i: usize, j: usize| cart(&self.pts[i * (q + 1) + j]);
        let along_s =
            (0..=q).map(|j| (0..p).map(|i| (at(i + 1, j) - at(i, j)).norm()).sum::<f64>()).fold(0.0, f64::max);
        let along_t =
            (0..=p).map(|i| (0..q).map(|j| (at(i, j + 1) - at(i, j)).norm()).sum::<f64>()).fold(0.0, f64::max);
        usize::from(along_t > along_s)
    }
}

/// Smooth surface pieces ready for drops (axis frame), with the face trimming them if any (the
/// pieces' maps then give the face's (u, v)).
#[derive(Clone, Debug)]
pub struct Sheet {
    pieces: Vec<(Bezier, Aabb)>,
    face: Option<Trim>,
    bounds: Aabb,
}

/// A face trimming a sheet: the face, its boundary curves (axis frame) and the motion from the
/// face's frame to the axis frame.
#[derive(Clone, Debug)]
pub struct Trim {
    face: Box<Face>,
    edges: Vec<(Edge, Aabb)>,
    place: Isometry3<f64>,
}

/// A boundary curve in the axis frame.
#[derive(Clone, Debug)]
enum Edge {
    /// A segment.
    Line(P3, P3),
    /// A rational Bézier curve (degree [p, 0]) over [s0, s1] of its [0, 1].
    Piece(Bezier, f64, f64),
}

/// Samples of a curve piece whose local maxima of g start golden-section searches.
const CURVE_SAMPLES: usize = 32;

impl Trim {
    /// `face` placed by `place` (its frame to the axis frame).
    pub fn new(face: &Face, place: &Isometry3<f64>) -> Trim {
        let mut edges = Vec::new();
        for curve in face.edges() {
            match curve {
                Curve::Line { a, b } => edges.push(Edge::Line(place * a, place * b)),
                Curve::Arc { centre, x, y, radius, t0, t1 } => {
                    for (h, m) in arcs(*t0, *t1) {
                        let pts = h
                            .iter()
                            .map(|c| {
                                let p = centre.coords * c[2] + (x * c[0] + y * c[1]) * *radius;
                                [p.x, p.y, p.z, c[2]]
                            })
                            .collect();
                        edges.push(Edge::Piece(
                            Bezier::new([2, 0], pts, [m, Map::Linear(0.0, 0.0)]).moved(place),
                            0.0,
                            1.0,
                        ));
                    }
                }
                Curve::Spline { curve, t0, t1, .. } => {
                    let p = curve.degree;
                    let rows = (0..curve.ctrl.len())
                        .map(|k| {
                            let w = curve.weights.as_ref().map_or(1.0, |ws| ws[k]);
                            let c = curve.ctrl[k] * w;
                            vec![c.x, c.y, c.z, w]
                        })
                        .collect();
                    let (knots, rows) = super::patch::bezier_knots(&curve.knots, rows, p);
                    for (k, a, b) in super::patch::bezier_spans(&knots, p) {
                        let (lo, hi) = (((t0 - a) / (b - a)).max(0.0), ((t1 - a) / (b - a)).min(1.0));
                        if lo >= hi {
                            continue;
                        }
                        let pts = rows[k - p..=k].iter().map(|r| [r[0], r[1], r[2], r[3]]).collect();
                        let net = Bezier::new([p, 0], pts, [Map::Linear(a, b), Map::Linear(0.0, 0.0)]);
                        edges.push(Edge::Piece(net.moved(place), lo, hi));
                    }
                }
            }
        }
        let edges = edges
            .into_iter()
            .map(|e| {
                let b = match &e {
                    Edge::Line(a, b) => Aabb::of(&[*a, *b]),
                    Edge::Piece(net, ..) => net.bounds(),
                };
                (e, b)
            })
            .collect();
        Trim { face: Box::new(face.clone()), edges, place: *place }
    }
}

/// The largest g along a curve piece `at` over [lo, hi] above `best`: samples, a golden-section
/// search about each local maximum, and bisection where the curve leaves the shadow.
fn drop_curve(c: &Cutter, q: [f64; 2], at: impl Fn(f64) -> P3, lo: f64, hi: f64) -> Option<(f64, P3)> {
    let big_r = c.radius();
    let g = |s: f64| {
        let p = at(s);
        let rho = (p.x - q[0]).hypot(p.y - q[1]);
        (rho <= big_r).then(|| (p.z - c.height(rho), p))
    };
    let n = CURVE_SAMPLES;
    let ss: Vec<f64> = (0..=n).map(|k| lo + (hi - lo) * k as f64 / n as f64).collect();
    let gs: Vec<Option<(f64, P3)>> = ss.iter().map(|&s| g(s)).collect();
    let mut best: Option<(f64, P3)> = None;
    let mut take = |x: Option<(f64, P3)>| {
        if let Some(x) = x {
            if best.is_none_or(|b| x.0 > b.0) {
                best = Some(x);
            }
        }
    };
    // The feasible end of each sample interval the shadow's rim crosses.
    let mut ends = ss.clone();
    for k in 0..n {
        if gs[k].is_some() != gs[k + 1].is_some() {
            let (mut good, mut bad) = if gs[k].is_some() { (ss[k], ss[k + 1]) } else { (ss[k + 1], ss[k]) };
            let mut found = gs[k].or(gs[k + 1]);
            for _ in 0..64 {
                let m = 0.5 * (good + bad);
                match g(m) {
                    Some(x) => {
                        good = m;
                        found = Some(x);
                    }
                    None => bad = m,
                }
            }
            take(found);
            if gs[k].is_some() { ends[k + 1] = good } else { ends[k] = good }
        }
    }
    for k in 0..=n {
        let Some((gk, _)) = gs[k] else { continue };
        take(gs[k]);
        let lower = |j: Option<usize>| j.is_none_or(|j| gs[j].is_none_or(|x| x.0 <= gk));
        if !(lower(k.checked_sub(1)) && lower((k < n).then_some(k + 1))) {
            continue;
        }
        // Out to the neighbours, or to the rim between them and this one.
        let a = if k > 0 { if gs[k - 1].is_some() { ss[k - 1] } else { ends[k - 1] } } else { ss[k] };
        let b = if k < n { if gs[k + 1].is_some() { ss[k + 1] } else { ends[k + 1] } } else { ss[k] };
        let f = |s: f64| g(s).map_or(f64::NEG_INFINITY, |x| x.0);
        let s = golden_arg(f, a, b, GOLDEN);
        take(g(s));
    }
    best
}

/// Where a piece lies against a trimmed face.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Side {
    /// Wholly inside (or no trimming).
    In,
    /// Possibly across the boundary.
    Across,
}

/// A piece in the search: bound, piece, its part of the piece (net and [s0, s1, t0, t1] of the
/// piece's [0, 1]²), whether the bound is the full one, and its side.
struct Node {
    bound: f64,
    piece: usize,
    net: Bezier,
    rect: [f64; 4],
    full: bool,
    side: Side,
}

impl PartialEq for Node {
    fn eq(&self, o: &Node) -> bool {
        self.bound == o.bound
    }
}
impl Eq for Node {}
impl PartialOrd for Node {
    fn partial_cmp(&self, o: &Node) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Node {
    fn cmp(&self, o: &Node) -> Ordering {
        self.bound.total_cmp(&o.bound)
    }
}

/// The largest of a concave `f` on [a, b] (golden section, the ends included).
fn golden_max(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    f(golden_arg(&f, a, b, GOLDEN)).max(f(a)).max(f(b))
}

/// The largest tip over points below the plane (through `a`, unit normal `n`, n.z > 0) whose
/// shadow lies in the box's: g = plane − f(ρ) is concave over the box's and the disc's common
/// part, so it is the plane's drop if its contact is there, else the largest on that part's
/// edges (the box's sides within the disc, the disc's arc at its highest point).
fn clipped_plane(c: &Cutter, q: [f64; 2], a: &P3, n: &V3, b: &Aabb) -> f64 {
    let big_r = c.radius();
    let touch = c.drop_on(q, &Plane::new(c, *a, *n));
    let inbox = |x: f64, y: f64| x >= b.min.x && x <= b.max.x && y >= b.min.y && y <= b.max.y;
    if inbox(touch.contact.x, touch.contact.y) {
        return touch.tip;
    }
    let z = |x: f64, y: f64| a.z - (n.x * (x - a.x) + n.y * (y - a.y)) / n.z;
    let g = |x: f64, y: f64| z(x, y) - c.height((x - q[0]).hypot(y - q[1]).min(big_r));
    let mut best = f64::NEG_INFINITY;
    // The arc's highest point (uphill, against the normal's horizontal part).
    let h = n.x.hypot(n.y);
    if h > 0.0 {
        let (x, y) = (q[0] - big_r * n.x / h, q[1] - big_r * n.y / h);
        if inbox(x, y) {
            best = best.max(g(x, y));
        }
    }
    best = best.max(edges_max(b, q, big_r, &g));
    best
}

/// As [`clipped_plane`], for a plane too steep to bound a piece alone (n.z ≥ 0, a vertical one
/// too): the piece lies below both the plane and its box's top, so g = min(plane, top) − f(ρ),
/// concave over the box's and the disc's common part D, bounds it. Its largest is at the plane's
/// own drop, at D's nearest point to the axis (where the top holds), at the crease where plane
/// and top meet (its nearest point to the axis in D, g = top − f(ρ) there), or on D's edges (the
/// box's sides within the disc, the arc at its uphill point). On a steep wall the box alone
/// bounds a piece of width w only to its slope times w, and halving never ends.
fn capped_plane(c: &Cutter, q: [f64; 2], a: &P3, n: &V3, b: &Aabb) -> f64 {
    let big_r = c.radius();
    let top = b.max.z;
    let inbox = |x: f64, y: f64| x >= b.min.x && x <= b.max.x && y >= b.min.y && y <= b.max.y;
    let rho = |x: f64, y: f64| (x - q[0]).hypot(y - q[1]);
    // The plane's height capped at the top: behind a vertical plane the top, in front of it −∞.
    let z = |x: f64, y: f64| {
        let num = n.x * (x - a.x) + n.y * (y - a.y);
        let plane = if n.z > 0.0 {
            a.z - num / n.z
        } else if num <= 0.0 {
            f64::INFINITY
        } else {
            f64::NEG_INFINITY
        };
        plane.min(top)
    };
    let g = |x: f64, y: f64| z(x, y) - c.height(rho(x, y).min(big_r));
    let mut best = f64::NEG_INFINITY;
    if n.z > 0.0 {
        let touch = c.drop_on(q, &Plane::new(c, *a, *n));
        if inbox(touch.contact.x, touch.contact.y) && rho(touch.contact.x, touch.contact.y) <= big_r {
            best = best.max(if touch.contact.z <= top { touch.tip } else { g(touch.contact.x, touch.contact.y) });
        }
    }
    let (x, y) = (q[0].clamp(b.min.x, b.max.x), q[1].clamp(b.min.y, b.max.y));
    if rho(x, y) <= big_r {
        best = best.max(g(x, y));
    }
    let h = n.x.hypot(n.y);
    if h > 0.0 {
        // The crease n_xy·p = k through the box: p = foot + τ·d, τ clipped by the box's slabs.
        let k = n.x * a.x + n.y * a.y + n.z * (a.z - top);
        let (ux, uy) = (n.x / h, n.y / h);
        let off = (k / h) - (ux * q[0] + uy * q[1]);
        let foot = (q[0] + ux * off, q[1] + uy * off);
        let d = (-uy, ux);
        let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
        for (p, dd, lo, hi) in [(foot.0, d.0, b.min.x, b.max.x), (foot.1, d.1, b.min.y, b.max.y)] {
            if dd == 0.0 {
                if p < lo || p > hi {
                    t0 = f64::INFINITY;
                }
            } else {
                let (ta, tb) = ((lo - p) / dd, (hi - p) / dd);
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            }
        }
        if t0 <= t1 {
            let t = 0.0f64.clamp(t0, t1);
            let (x, y) = (foot.0 + t * d.0, foot.1 + t * d.1);
            if rho(x, y) <= big_r {
                best = best.max(top - c.height(rho(x, y)));
            }
        }
        let (x, y) = (q[0] - big_r * ux, q[1] - big_r * uy);
        if inbox(x, y) {
            best = best.max(g(x, y));
        }
    }
    best = best.max(edges_max(b, q, big_r, &g));
    best
}

/// The part [t0, t1] of the segment from `p0` to `p1` within the disc of radius `r` about `q`.
fn in_disc(q: [f64; 2], r: f64, p0: (f64, f64), p1: (f64, f64)) -> Option<(f64, f64)> {
    let (dx, dy) = (p1.0 - p0.0, p1.1 - p0.1);
    let (ex, ey) = (p0.0 - q[0], p0.1 - q[1]);
    // |e + τ d|² ≤ R²: τ between the roots.
    let aa = dx * dx + dy * dy;
    let bb = ex * dx + ey * dy;
    let cc = ex * ex + ey * ey - r * r;
    let (t0, t1) = if aa == 0.0 {
        if cc <= 0.0 { (0.0, 0.0) } else { return None }
    } else {
        let disc = bb * bb - aa * cc;
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        (((-bb - s) / aa).max(0.0), ((-bb + s) / aa).min(1.0))
    };
    (t0 <= t1).then_some((t0, t1))
}

/// The largest of `g` along the box's four edges where they lie in the disc of radius `big_r`
/// round `q` (golden-section search on each piece; −∞ where none does).
fn edges_max(b: &Aabb, q: [f64; 2], big_r: f64, g: &impl Fn(f64, f64) -> f64) -> f64 {
    let corners = [(b.min.x, b.min.y), (b.max.x, b.min.y), (b.max.x, b.max.y), (b.min.x, b.max.y)];
    let mut best = f64::NEG_INFINITY;
    for k in 0..4 {
        let (p0, p1) = (corners[k], corners[(k + 1) % 4]);
        if let Some((t0, t1)) = in_disc(q, big_r, p0, p1) {
            let (dx, dy) = (p1.0 - p0.0, p1.1 - p0.1);
            best = best.max(golden_max(|t| g(p0.0 + t * dx, p0.1 + t * dy), t0, t1));
        }
    }
    best
}

/// True when the piece's control points (whose hull holds it) lie beyond the shadow's tangent
/// across the direction from the axis to the box's middle: nearer than the box's own distance
/// where the piece runs along the shadow's rim (a box there reaches in while the piece does not).
fn beyond(c: &Cutter, q: [f64; 2], net: &Bezier, b: &Aabb) -> bool {
    let (dx, dy) = (0.5 * (b.min.x + b.max.x) - q[0], 0.5 * (b.min.y + b.max.y) - q[1]);
    let len = dx.hypot(dy);
    len > 0.0 && net.points().all(|p| ((p.x - q[0]) * dx + (p.y - q[1]) * dy) / len > c.radius())
}

/// True when g = z − f(ρ) has no stationary point on the piece `net` (box `b`), so that its largest
/// value on the piece's part in a face lies on the face's boundary or on the piece's sides. Needs
/// the piece's box in the open shadow (off the cone's tip, where f has no slope), and along s or
/// along t the derivative of g of one sign all over it: ∂g/∂s = m·S_s with m = (−f′(ρ) d̂, 1), d̂
/// the direction from the axis, and S_s of a rational piece with positive weights is a positive
/// combination of differences of control points of consecutive rows, any columns (the hodograph of
/// a rational Bézier curve lies in the cone of its control points' differences, Floater 1992); so
/// the sign holds when m·D has it for every such D and every m over the box.
fn monotone(c: &Cutter, q: [f64; 2], net: &Bezier, b: &Aabb) -> bool {
    let corners = [(b.min.x, b.min.y), (b.max.x, b.min.y), (b.max.x, b.max.y), (b.min.x, b.max.y)];
    let far = corners.iter().map(|p| (p.0 - q[0]).hypot(p.1 - q[1])).fold(0.0, f64::max);
    let near = b.dist_xy(q);
    if far >= c.radius() || (near == 0.0 && matches!(c, Cutter::Cone { .. })) {
        return false;
    }
    let (lo, hi) = (c.slope(near), c.slope(far));
    // The directions d̂ from the axis to the box: a sector (edges, middle, cosine of its
    // half-width), or the whole circle when the axis passes through the box.
    let sector = (near > 0.0).then(|| {
        let (mx, my) = (0.5 * (b.min.x + b.max.x) - q[0], 0.5 * (b.min.y + b.max.y) - q[1]);
        let len = mx.hypot(my);
        let (cx, cy) = (mx / len, my / len);
        let turn = corners.map(|p| {
            let (x, y) = (p.0 - q[0], p.1 - q[1]);
            (cx * y - cy * x).atan2(cx * x + cy * y)
        });
        let (a0, a1) = turn.iter().fold((0.0f64, 0.0f64), |(l, h), &a| (l.min(a), h.max(a)));
        let rot = |a: f64| (cx * a.cos() - cy * a.sin(), cx * a.sin() + cy * a.cos());
        (rot(a0), rot(a1), rot(0.5 * (a0 + a1)), (0.5 * (a1 - a0)).cos())
    });
    // The largest d̂·v over the directions.
    let reach = |vx: f64, vy: f64| -> f64 {
        let len = vx.hypot(vy);
        match sector {
            None => len,
            Some((e0, e1, m, cosw)) if m.0 * vx + m.1 * vy < cosw * len => {
                (e0.0 * vx + e0.1 * vy).max(e1.0 * vx + e1.1 * vy)
            }
            Some(_) => len,
        }
    };
    // One sign of m·D for every difference D of `diffs` and every m.
    let one_sign = |diffs: &mut dyn Iterator<Item = V3>| -> bool {
        let (mut up, mut down, mut any) = (true, true, false);
        for d in diffs {
            any = true;
            let (xhi, xlo) = (reach(d.x, d.y), -reach(-d.x, -d.y));
            let least = d.z - if xhi >= 0.0 { hi * xhi } else { lo * xhi };
            let most = d.z - if xlo <= 0.0 { hi * xlo } else { lo * xlo };
            let eps = 1e-12 * d.norm() * (1.0 + hi);
            up &= least > eps;
            down &= most < -eps;
            if !(up || down) {
                return false;
            }
        }
        any
    };
    let [p, r] = net.deg;
    let pts: Vec<P3> = net.points().collect();
    let at = |i: usize, j: usize| pts[i * (r + 1) + j];
    let rows = (0..p).flat_map(|i| (0..=r).flat_map(move |j| (0..=r).map(move |l| (i, j, l))));
    if one_sign(&mut rows.map(|(i, j, l)| at(i + 1, j) - at(i, l))) {
        return true;
    }
    let cols = (0..r).flat_map(|j| (0..=p).flat_map(move |i| (0..=p).map(move |k| (j, i, k))));
    one_sign(&mut cols.map(|(j, i, k)| at(i, j + 1) - at(k, j)))
}

impl Sheet {
    /// Pieces (axis frame) trimmed by `face` if given.
    pub fn new(pieces: Vec<Bezier>, face: Option<Trim>) -> Sheet {
        let pieces: Vec<(Bezier, Aabb)> = pieces.into_iter().map(|b| (b.bounds(), b)).map(|(a, b)| (b, a)).collect();
        let bounds = pieces.iter().fold(Aabb::empty(), |a, (_, b)| a.union(b));
        Sheet { pieces, face, bounds }
    }

    /// A box holding the sheet.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The face's (u, v) at (s, t) of piece `k`.
    fn uv(&self, k: usize, s: f64, t: f64) -> [f64; 2] {
        let m = self.pieces[k].0.map;
        [m[0].at(s), m[1].at(t)]
    }

    /// A bound of the tips of a piece's part: its box's, and its plane's where the middle normal
    /// is steep enough to give one; −∞ where it is out of the shadow.
    fn bound(&self, c: &Cutter, q: [f64; 2], net: &Bezier, full: bool) -> f64 {
        let b = net.bounds();
        let rho = b.dist_xy(q);
        if rho > c.radius() || beyond(c, q, net, &b) {
            return f64::NEG_INFINITY;
        }
        let top = b.max.z - c.height(rho * (1.0 - RHO_ROUND));
        if !full {
            return top;
        }
        let (_, su, sv) = net.eval(0.5, 0.5);
        let Some(mut n) = su.cross(&sv).try_normalize(1e-300) else { return top };
        if n.z < 0.0 {
            n = -n;
        }
        let a = net.points().max_by(|x, y| n.dot(&x.coords).total_cmp(&n.dot(&y.coords))).expect("control points");
        if n.z < SLAB_NZ {
            return top.min(capped_plane(c, q, &a, &n, &b) + MARGIN);
        }
        top.min(clipped_plane(c, q, &a, &n, &b) + MARGIN)
    }

    /// Whether the part [s0, s1, t0, t1] of piece `k` lies in the face: `None` when outside.
    fn side(&self, k: usize, rect: &[f64; 4]) -> Option<Side> {
        let Some(Trim { face, .. }) = &self.face else { return Some(Side::In) };
        let lo = self.uv(k, rect[0], rect[2]);
        let hi = self.uv(k, rect[1], rect[3]);
        if face.crosses(lo, hi) {
            return Some(Side::Across);
        }
        let mid = self.uv(k, 0.5 * (rect[0] + rect[1]), 0.5 * (rect[2] + rect[3]));
        face.inside(mid).then_some(Side::In)
    }

    /// The drop at `q` above `floor`: the touch and the surface's unit normal there (n.z ≥ 0,
    /// towards the axis on a wall), or `None` when no point gives a tip more than [`TOL`] above
    /// `floor`.
    pub fn drop(&self, c: &Cutter, q: [f64; 2], floor: f64) -> Option<(Touch, V3)> {
        let big_r = c.radius();
        let mut heap = BinaryHeap::new();
        let mut best: Option<(f64, P3, V3)> = None;
        let level = |best: &Option<(f64, P3, V3)>| best.map_or(floor, |b| b.0.max(floor));
        for (k, (net, b)) in self.pieces.iter().enumerate() {
            let bound = self.bound(c, q, net, false);
            if bound > floor && b.max.z > f64::NEG_INFINITY {
                if let Some(side) = self.side(k, &[0.0, 1.0, 0.0, 1.0]) {
                    heap.push(Node {
                        bound,
                        piece: k,
                        net: net.clone(),
                        rect: [0.0, 1.0, 0.0, 1.0],
                        full: false,
                        side,
                    });
                }
            }
        }
        // g at (s, t) of the node's net where the point is in the shadow (and the face).
        let feasible = |node: &Node, s: f64, t: f64| -> Option<(f64, P3, V3, V3)> {
            let (p, su, sv) = node.net.eval(s, t);
            let rho = (p.x - q[0]).hypot(p.y - q[1]);
            if rho > big_r {
                return None;
            }
            if node.side == Side::Across {
                let r = &node.rect;
                let uv = self.uv(node.piece, r[0] + (r[1] - r[0]) * s, r[2] + (r[3] - r[2]) * t);
                if !self.face.as_ref().is_some_and(|f| f.face.inside(uv)) {
                    return None;
                }
            }
            Some((p.z - c.height(rho), p, su, sv))
        };
        // The face's boundary first: its exact drop is a good start and what pieces across it
        // leave out.
        if let Some(trim) = &self.face {
            for (e, b) in &trim.edges {
                let rho = b.dist_xy(q);
                if rho > big_r || b.max.z - c.height(rho * (1.0 - RHO_ROUND)) <= level(&best) {
                    continue;
                }
                let found = match e {
                    Edge::Line(a, b) => c.drop_edge(q, a, b, level(&best)).map(|t| (t.tip, t.contact)),
                    Edge::Piece(net, lo, hi) => drop_curve(c, q, |s| net.eval(s, 0.0).0, *lo, *hi),
                };
                if let Some((g, p)) = found.filter(|f| f.0 > level(&best)) {
                    let n =
                        trim.place.rotation * trim.face.carrier().normal_at(&trim.place.inverse_transform_point(&p));
                    let n =
                        if n.z < 0.0 || (n.z == 0.0 && n.x * (q[0] - p.x) + n.y * (q[1] - p.y) < 0.0) { -n } else { n };
                    best = Some((g, p, n));
                }
            }
        }
        let mut count = 0;
        while let Some(node) = heap.pop() {
            let floor_now = level(&best);
            if node.bound <= floor_now + TOL {
                break;
            }
            if !node.full {
                let bound = self.bound(c, q, &node.net, true);
                if bound > floor_now {
                    heap.push(Node { bound, full: true, ..node });
                }
                continue;
            }
            count += 1;
            if count > MAX_NODES {
                break;
            }
            // Lower bounds: the middle, and where the segments to the edge points leave the
            // shadow or the face.
            let mut take = |found: Option<(f64, P3, V3, V3)>| {
                if let Some((g, p, su, sv)) = found {
                    if g > level(&best) {
                        let mut n = su.cross(&sv).try_normalize(1e-300).unwrap_or(V3::z());
                        if n.z < 0.0 || (n.z == 0.0 && n.x * (q[0] - p.x) + n.y * (q[1] - p.y) < 0.0) {
                            n = -n;
                        }
                        best = Some((g, p, n));
                    }
                }
            };
            let mid = feasible(&node, 0.5, 0.5);
            take(mid);
            let edges =
                [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.5, 0.0), (1.0, 0.5), (0.5, 1.0), (0.0, 0.5)];
            for (s, t) in edges {
                let at = feasible(&node, s, t);
                if at.is_some() == mid.is_some() {
                    take(at);
                    continue;
                }
                // Bisect between the feasible end and the other.
                let (mut good, mut bad) = if mid.is_some() { ((0.5, 0.5), (s, t)) } else { ((s, t), (0.5, 0.5)) };
                let mut found = if mid.is_some() { mid } else { at };
                for _ in 0..BISECT {
                    let m = (0.5 * (good.0 + bad.0), 0.5 * (good.1 + bad.1));
                    match feasible(&node, m.0, m.1) {
                        Some(f) => {
                            good = m;
                            found = Some(f);
                        }
                        None => bad = m,
                    }
                }
                take(found);
            }
            let floor_now = level(&best);
            let limit = floor_now + TOL;
            if node.bound <= limit {
                continue;
            }
            let r = node.rect;
            let dir = node.net.longest();
            let b = node.net.bounds();
            if (r[2 * dir + 1] - r[2 * dir]) < 1e-15 || (b.max - b.min).norm() < MIN_PIECE {
                continue;
            }
            // In a face, a piece where g has no stationary point gives nothing above what its
            // sides (held by the pieces beside it) and the face's boundary (dropped onto first)
            // give: the bound of a piece across the boundary holds the carrier beyond it, which
            // would otherwise be halved down to nothing along the whole boundary.
            if self.face.is_some() && monotone(c, q, &node.net, &b) {
                continue;
            }
            let (a, b) = node.net.split(dir);
            let midp = 0.5 * (r[2 * dir] + r[2 * dir + 1]);
            let mut ra = r;
            let mut rb = r;
            ra[2 * dir + 1] = midp;
            rb[2 * dir] = midp;
            for (net, rect) in [(a, ra), (b, rb)] {
                let side = match node.side {
                    Side::In => Some(Side::In),
                    Side::Across => self.side(node.piece, &rect),
                };
                let Some(side) = side else { continue };
                let bound = self.bound(c, q, &net, true);
                if bound > limit {
                    heap.push(Node { bound, piece: node.piece, net, rect, full: true, side });
                }
            }
        }
        let (tip, contact, n) = best?;
        Some((Touch { tip, contact }, n))
    }
}

/// Rational quadratic arcs of the unit circle from angle `a0` to `a1` (a quarter turn each at
/// most): homogeneous (w x, w y, w) and the map of each one's parameter to the angle.
fn arcs(a0: f64, a1: f64) -> Vec<([[f64; 3]; 3], Map)> {
    let n = ((a1 - a0) / FRAC_PI_2 - 1e-9).ceil().max(1.0) as usize;
    let th = (a1 - a0) / n as f64;
    (0..n)
        .map(|k| {
            let a = a0 + th * k as f64;
            let (m, b) = (a + 0.5 * th, a + th);
            ([[a.cos(), a.sin(), 1.0], [m.cos(), m.sin(), (0.5 * th).cos()], [b.cos(), b.sin(), 1.0]], Map::Arc(a, th))
        })
        .collect()
}

/// A section of a surface of revolution about z: pieces of (w ρ, w z, w) and their maps.
type Profile = Vec<(Vec<[f64; 3]>, Map)>;

/// The straight section from (ρ0, z0) to (ρ1, z1), its parameter running from `v0` to `v1`.
fn line(a: [f64; 2], b: [f64; 2], v0: f64, v1: f64) -> Profile {
    vec![(vec![[a[0], a[1], 1.0], [b[0], b[1], 1.0]], Map::Linear(v0, v1))]
}

/// The circle of radius `r` about (ρ, z) = (`c`, 0) from angle `v0` to `v1` as a section.
fn circle(c: f64, r: f64, v0: f64, v1: f64) -> Profile {
    arcs(v0, v1)
        .into_iter()
        .map(|(p, m)| (p.iter().map(|h| [c * h[2] + r * h[0], r * h[1], h[2]]).collect(), m))
        .collect()
}

/// The surface sweeping `profile` about z from angle `u0` to `u1`, as exact rational patches
/// (s along the angle, t along the section).
fn revolve(profile: &Profile, u0: f64, u1: f64) -> Vec<Bezier> {
    let mut out = Vec::new();
    for (c, cm) in arcs(u0, u1) {
        for (sec, sm) in profile {
            let pts = c
                .iter()
                .flat_map(|a| sec.iter().map(move |s| [a[0] * s[0], a[1] * s[0], a[2] * s[1], a[2] * s[2]]))
                .collect();
            out.push(Bezier::new([2, sec.len() - 1], pts, [cm, *sm]));
        }
    }
    out
}

/// The carrier of a face over the (u, v) box of its loops, as exact rational patches in the
/// face's frame whose maps give the face's (u, v).
pub fn face_pieces(face: &Face) -> Vec<Bezier> {
    let [u0, u1, v0, v1] = face.uv_box();
    match face.carrier() {
        Carrier::Patch(s) => s.bezier_pieces(),
        Carrier::Analytic(Analytic::Plane { .. }) => {
            let pts = vec![[u0, v0, 0.0, 1.0], [u0, v1, 0.0, 1.0], [u1, v0, 0.0, 1.0], [u1, v1, 0.0, 1.0]];
            vec![Bezier::new([1, 1], pts, [Map::Linear(u0, u1), Map::Linear(v0, v1)])]
        }
        Carrier::Analytic(Analytic::Cylinder { radius, .. }) => {
            revolve(&line([*radius, v0], [*radius, v1], v0, v1), u0, u1)
        }
        Carrier::Analytic(Analytic::Cone { apex, half_angle, .. }) => {
            let rho = |v: f64| (v - apex.z) * half_angle.tan();
            revolve(&line([rho(v0), v0], [rho(v1), v1], v0, v1), u0, u1)
        }
        Carrier::Analytic(Analytic::Sphere { radius, .. }) => revolve(&circle(0.0, *radius, v0, v1), u0, u1),
        Carrier::Analytic(Analytic::Torus { major, minor, .. }) => revolve(&circle(*major, *minor, v0, v1), u0, u1),
        Carrier::Revolution(r) => revolve(&spline_section(r.profile()), u0, u1),
    }
}

/// A profile curve in the half-plane y = 0 (x the distance from the axis) as a section: its
/// rational Bézier pieces between knots, mapped linearly onto the curve's own parameter.
fn spline_section(c: &SplineCurve) -> Profile {
    let p = c.degree;
    let w = |i: usize| c.weights.as_ref().map_or(1.0, |ws| ws[i]);
    let rows = c.ctrl.iter().enumerate().map(|(i, q)| vec![q.x * w(i), q.z * w(i), w(i)]).collect();
    let (knots, pts) = bezier_knots(&c.knots, rows, p);
    bezier_spans(&knots, p)
        .into_iter()
        .map(|(k, a, b)| ((k - p..=k).map(|i| [pts[i][0], pts[i][1], pts[i][2]]).collect(), Map::Linear(a, b)))
        .collect()
}

/// A finite cylinder or cone, or a torus, as exact rational patches (its own frame); `None` for
/// what has no finite extent.
pub fn analytic_pieces(a: &Analytic) -> Option<Vec<Bezier>> {
    let (origin, axis, profile) = match *a {
        Analytic::Cylinder { point, axis, radius, from, to } if from.is_finite() && to.is_finite() => {
            (point, axis, line([radius, from], [radius, to], from, to))
        }
        Analytic::Cone { apex, axis, half_angle, from, to } if from.is_finite() && to.is_finite() => {
            let k = half_angle.tan();
            (apex, axis, line([from * k, from], [to * k, to], from, to))
        }
        Analytic::Torus { centre, axis, major, minor } => (centre, axis, circle(major, minor, -PI, PI)),
        _ => return None,
    };
    let turn = nalgebra::UnitQuaternion::rotation_between(&V3::z(), &axis)
        .unwrap_or_else(|| nalgebra::UnitQuaternion::from_axis_angle(&V3::x_axis(), PI));
    let iso = Isometry3::from_parts(nalgebra::Translation3::from(origin.coords), turn);
    Some(revolve(&profile, -PI, PI).iter().map(|b| b.moved(&iso)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::drop::DropCutter;
    use crate::model::patch::BSpline;
    use crate::model::{Geometry, Model, Surface};
    use proptest::prelude::*;
    use std::f64::consts::TAU;

    fn cutters() -> impl Strategy<Value = Cutter> {
        prop_oneof![
            (0.3..4.0f64).prop_map(|radius| Cutter::Flat { radius }),
            (0.3..4.0f64).prop_map(|radius| Cutter::Ball { radius }),
            (0.3..4.0f64, 0.1..1.0f64).prop_map(|(radius, k)| Cutter::Bull { radius, corner: radius * k }),
            (0.3..4.0f64, 0.3..1.3f64).prop_map(|(radius, half_angle)| Cutter::Cone { radius, half_angle }),
        ]
    }

    fn one(g: Geometry) -> Model {
        Model { surfaces: vec![Surface::new("s".into(), g, None, false)] }
    }

    #[test]
    fn arcs_map_to_their_angles() {
        for (h, m) in arcs(-0.3, 5.0) {
            let net =
                Bezier::new([2, 0], h.iter().map(|p| [p[0], p[1], 0.0, p[2]]).collect(), [m, Map::Linear(0.0, 1.0)]);
            for k in 0..=10 {
                let s = k as f64 / 10.0;
                let (p, _, _) = net.eval(s, 0.0);
                assert!((p.coords.norm() - 1.0).abs() < 1e-15);
                let a = m.at(s);
                assert!((p.x - a.cos()).abs() < 1e-14 && (p.y - a.sin()).abs() < 1e-14, "{s}: {p} vs {a}");
            }
        }
    }

    #[test]
    fn bezier_pieces_are_the_spline() {
        // A rational, unevenly knotted bicubic-by-quadratic net.
        let net: Vec<Vec<P3>> = (0..6)
            .map(|i| {
                (0..5)
                    .map(|j| P3::new(i as f64 * 3.0, j as f64 * 2.0 + (i * j) as f64 * 0.1, ((i + 2 * j) % 5) as f64))
                    .collect()
            })
            .collect();
        let w: Vec<Vec<f64>> =
            (0..6).map(|i| (0..5).map(|j| 0.5 + ((i * 7 + j * 3) % 5) as f64 * 0.3).collect()).collect();
        let ku = vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.3, 1.0, 1.0, 1.0, 1.0];
        let kv = vec![0.0, 0.0, 0.0, 0.2, 0.7, 1.0, 1.0, 1.0];
        let s = BSpline::with_weights(&net, Some(&w), [3, 2], Some(ku), Some(kv));
        let pieces = s.bezier_pieces();
        assert_eq!(pieces.len(), 2 * 3);
        for b in &pieces {
            for (a, c) in [(0.0, 0.0), (0.3, 0.8), (1.0, 0.5), (0.77, 1.0)] {
                let (p, su, sv) = b.eval(a, c);
                let (u, v) = (b.map[0].at(a), b.map[1].at(c));
                let d = s.eval(u, v);
                let (Map::Linear(u0, u1), Map::Linear(v0, v1)) = (b.map[0], b.map[1]) else { panic!() };
                assert!((p - d.s).norm() < 1e-12, "{p} vs {}", d.s);
                assert!((su - d.su * (u1 - u0)).norm() < 1e-9 && (sv - d.sv * (v1 - v0)).norm() < 1e-9);
            }
        }
    }

    /// A sphere, a torus along the axis and an endless cylinder across it as exact rational
    /// patches against the closed forms of [`DropCutter`].
    fn against_closed_form(c: Cutter, g: Geometry, pieces: Vec<Bezier>, q: [f64; 2]) -> Result<(), TestCaseError> {
        let want = DropCutter::new(&one(g), c, V3::z()).unwrap().drop(q[0], q[1]);
        let got = Sheet::new(pieces, None).drop(&c, q, f64::NEG_INFINITY);
        match (got, want) {
            (None, None) => {}
            (Some((t, n)), Some(w)) => {
                prop_assert!((t.tip - w.tip.z).abs() <= 1e-9, "sheet {} closed form {}", t.tip, w.tip.z);
                prop_assert!((n.norm() - 1.0).abs() < 1e-9);
            }
            (g, w) => prop_assert!(false, "{g:?} vs {w:?}"),
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn sphere_patches_drop_as_the_closed_form(c in cutters(), r in 0.5..5.0f64, q in prop::array::uniform2(-8.0..8.0f64)) {
            let centre = P3::new(0.3, -0.2, 1.0);
            let iso = Isometry3::translation(centre.x, centre.y, centre.z);
            let pieces = revolve(&circle(0.0, r, -FRAC_PI_2, FRAC_PI_2), -PI, PI).iter().map(|b| b.moved(&iso)).collect();
            against_closed_form(c, Geometry::Analytic(Analytic::Sphere { centre, radius: r }), pieces, q)?;
        }

        #[test]
        fn torus_patches_drop_as_the_closed_form(
            c in cutters().prop_filter("closed forms for flat, ball, bull", |c| !matches!(c, Cutter::Cone { .. })),
            major in 2.0..6.0f64, minor in 0.3..1.5f64, q in prop::array::uniform2(-8.0..8.0f64),
        ) {
            let torus = Analytic::Torus { centre: P3::new(0.5, -0.5, 1.0), axis: V3::z(), major, minor };
            let pieces = analytic_pieces(&torus).unwrap();
            against_closed_form(c, Geometry::Analytic(torus), pieces, q)?;
        }

        #[test]
        fn cylinder_patches_drop_as_the_closed_form(c in cutters(), r in 0.5..4.0f64, turn in 0.0..3.0f64, q in prop::array::uniform2(-6.0..6.0f64)) {
            // Across the axis, long enough that its ends are out of reach of the drops tried.
            let axis = V3::new(turn.cos(), turn.sin(), 0.0);
            let point = P3::new(0.2, 0.1, -1.0);
            let long = Analytic::Cylinder { point, axis, radius: r, from: -30.0, to: 30.0 };
            let endless = Analytic::Cylinder { point, axis, radius: r, from: f64::NEG_INFINITY, to: f64::INFINITY };
            against_closed_form(c, Geometry::Analytic(endless), analytic_pieces(&long).unwrap(), q)?;
        }
    }

    /// A spherical cap (R5 about the origin, above a rim circle) under each cutter, its rim put
    /// 10 µm beside the whole sphere's contact: with the contact just inside, the drop is the
    /// closed form's to 1e-9 mm; just outside, it is the rim's highest tip (the rim sampled every
    /// 1e-5 rad, then golden section about the best), and no sample of the cap (every 1e-3 rad
    /// each way) stands above it. The pieces across the rim are what the search cannot halve
    /// down to nothing: it must see that the cap gives nothing more than its rim there.
    #[test]
    fn contacts_beside_a_face_edge_are_exact() {
        let rs = 5.0f64;
        let sphere = Analytic::Sphere { centre: P3::origin(), radius: rs };
        let cutters = [
            Cutter::Flat { radius: 2.0 },
            Cutter::Ball { radius: 2.0 },
            Cutter::Bull { radius: 2.0, corner: 0.7 },
            Cutter::Cone { radius: 2.0, half_angle: 1.0 },
        ];
        for c in cutters {
            for q in [[2.6, 0.9], [-2.1, 1.7], [0.2, -3.3]] {
                let whole = DropCutter::new(&one(Geometry::Analytic(sphere.clone())), c, V3::z())
                    .unwrap()
                    .drop(q[0], q[1])
                    .unwrap();
                let lat = whole.contact.z.atan2(whole.contact.coords.xy().norm());
                for (side, d) in [("inside", -1e-5 / rs), ("outside", 1e-5 / rs)] {
                    let rim_lat = lat + d;
                    let (zc, rr) = (rs * rim_lat.sin(), rs * rim_lat.cos());
                    let rim = Curve::Arc {
                        centre: P3::new(0.0, 0.0, zc),
                        x: V3::x(),
                        y: V3::y(),
                        radius: rr,
                        t0: 0.0,
                        t1: TAU,
                    };
                    // Its seam up to the pole, walked both ways (as CAD systems write a cap).
                    let seam = Curve::Arc {
                        centre: P3::origin(),
                        x: V3::x(),
                        y: V3::z(),
                        radius: rs,
                        t0: rim_lat,
                        t1: FRAC_PI_2,
                    };
                    let lp = vec![(rim, true), (seam.clone(), true), (seam, false)];
                    let face = Face::new(Carrier::Analytic(sphere.clone()), vec![lp], true);
                    let place = Isometry3::identity();
                    let sheet = Sheet::new(face_pieces(&face), Some(Trim::new(&face, &place)));
                    let got = sheet.drop(&c, q, f64::NEG_INFINITY).map(|(t, _)| t.tip);
                    let g = |p: P3| {
                        let rho = (p.x - q[0]).hypot(p.y - q[1]);
                        if rho <= c.radius() { p.z - c.height(rho) } else { f64::NEG_INFINITY }
                    };
                    if side == "inside" {
                        let tip = got.unwrap();
                        assert!((tip - whole.tip.z).abs() <= 1e-9, "{c:?} {q:?}: {tip} vs {}", whole.tip.z);
                        continue;
                    }
                    let at = |a: f64| P3::new(rr * a.cos(), rr * a.sin(), zc);
                    let n = 628_319;
                    let k = (0..n).max_by(|&i, &j| g(at(i as f64 * 1e-5)).total_cmp(&g(at(j as f64 * 1e-5)))).unwrap();
                    let a = golden_arg(|a| g(at(a)), (k as f64 - 1.0) * 1e-5, (k as f64 + 1.0) * 1e-5, 80);
                    let edge = g(at(a));
                    // The flat's contact is on its rim: just beyond it the cap is out of reach.
                    let tip = got.unwrap_or(f64::NEG_INFINITY);
                    assert!(tip == edge || (tip - edge).abs() <= 1e-9, "{c:?} {q:?}: {tip} vs the rim's {edge}");
                    // The cap within 0.6 rad of the contact's longitude (the shadow is narrower).
                    let mut cap = f64::NEG_INFINITY;
                    let lon = whole.contact.y.atan2(whole.contact.x);
                    for i in 0..=((FRAC_PI_2 - rim_lat) / 1e-3) as usize {
                        let b = rim_lat + i as f64 * 1e-3;
                        for j in 0..=1200 {
                            let a = lon - 0.6 + j as f64 * 1e-3;
                            cap = cap.max(g(P3::new(rs * b.cos() * a.cos(), rs * b.cos() * a.sin(), rs * b.sin())));
                        }
                    }
                    assert!(cap <= tip + 1e-12, "{c:?} {q:?}: a sample of the cap {} above", cap - tip);
                }
            }
        }
    }

    /// A ball beside a plane rising at slope 20 towards its rim, the box's top far above: the
    /// largest is the plane's own drop, 0.05 mm (R/2s) above the rim's uphill point, inside the
    /// box; the bound is it to 1e-9 (golden section along the uphill line, where it lies).
    #[test]
    fn capped_plane_holds_a_steep_planes_own_drop() {
        let c = Cutter::Ball { radius: 2.0 };
        let nz = 0.05f64;
        let n = V3::new((1.0 - nz * nz).sqrt(), 0.0, nz);
        let a = P3::new(-2.0, 0.0, 0.0);
        let b = Aabb { min: P3::new(-2.2, -0.5, -10.0), max: P3::new(-1.5, 0.5, 10.0) };
        let g = |x: f64| a.z - n.x * (x - a.x) / n.z - c.height(x.abs().min(2.0));
        let x = golden_arg(g, -2.0, -1.5, 200);
        let bound = capped_plane(&c, [0.0, 0.0], &a, &n, &b);
        assert!((bound - g(x)).abs() < 1e-9 && g(x) - g(-2.0) > 0.049, "{bound} vs {} (rim {})", g(x), g(-2.0));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        /// The steep plane's bound against a dense sampling of what it bounds: min(plane, top)
        /// − f(ρ) over the box within the disc (a 401² grid, its edges too): never below the
        /// largest sample, never above the box's own bound.
        #[test]
        fn capped_plane_bounds_the_dense_maximum(
            c in cutters(),
            lo in prop::array::uniform3(-3.0..3.0f64),
            size in prop::array::uniform3(0.01..4.0f64),
            q in prop::array::uniform2(-5.0..5.0f64),
            nz in prop_oneof![Just(0.0), 0.0..0.05f64],
            turn in 0.0..TAU,
            at in prop::array::uniform3(0.0..1.0f64),
        ) {
            let b = Aabb { min: P3::new(lo[0], lo[1], lo[2]), max: P3::new(lo[0] + size[0], lo[1] + size[1], lo[2] + size[2]) };
            let h = (1.0 - nz * nz).sqrt();
            let n = V3::new(h * turn.cos(), h * turn.sin(), nz);
            let a = P3::new(b.min.x + at[0] * size[0], b.min.y + at[1] * size[1], b.min.z + at[2] * size[2]);
            let bound = capped_plane(&c, q, &a, &n, &b);
            let g = |x: f64, y: f64| {
                let num = n.x * (x - a.x) + n.y * (y - a.y);
                let plane = if nz > 0.0 { a.z - num / nz } else if num <= 0.0 { f64::INFINITY } else { f64::NEG_INFINITY };
                let rho = (x - q[0]).hypot(y - q[1]);
                if rho > c.radius() { f64::NEG_INFINITY } else { plane.min(b.max.z) - c.height(rho) }
            };
            let m = 400;
            let mut dense = f64::NEG_INFINITY;
            for i in 0..=m {
                for j in 0..=m {
                    dense = dense.max(g(b.min.x + size[0] * i as f64 / m as f64, b.min.y + size[1] * j as f64 / m as f64));
                }
            }
            let rho = b.dist_xy(q);
            let boxed = if rho > c.radius() { f64::NEG_INFINITY } else { b.max.z - c.height(rho) };
            prop_assert!(bound + 1e-9 >= dense, "bound {bound} below a sample {dense}");
            prop_assert!(bound <= boxed + 1e-12, "bound {bound} above the box's {boxed}");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// A rational bicubic patch along a random axis: no dense sample of the surface gives a
        /// tip more than 1e-9 above the drop, the contact is on the surface with the tip's g, and
        /// the drop onto a fine tessellation differs by at most its chord error over the slope.
        #[test]
        fn patch_drop_is_the_dense_maximum(
            c in cutters(),
            heights in prop::collection::vec(-3.0..3.0f64, 25),
            weights in prop::collection::vec(0.5..2.0f64, 25),
            axis in prop::array::uniform2(-0.3..0.3f64),
            q in prop::array::uniform2(-2.0..22.0f64),
        ) {
            let net: Vec<Vec<P3>> =
                (0..5).map(|i| (0..5).map(|j| P3::new(5.0 * i as f64, 5.0 * j as f64 + i as f64, heights[5 * i + j])).collect()).collect();
            let w: Vec<Vec<f64>> = (0..5).map(|i| weights[5 * i..5 * i + 5].to_vec()).collect();
            let s = BSpline::with_weights(&net, Some(&w), [3, 3], None, None);
            let axis = V3::new(axis[0], axis[1], 1.0).normalize();
            let dc = DropCutter::new(&one(Geometry::Patch(s.clone())), c, axis).unwrap();
            let got = dc.drop(q[0], q[1]);
            let frame = dc.frame;
            let n = 300;
            let at = |i: usize, j: usize| frame.to_frame(&s.eval(i as f64 / n as f64, j as f64 / n as f64).s);
            let mut brute = f64::NEG_INFINITY;
            let mut tris = Vec::new();
            for i in 0..=n {
                for j in 0..=n {
                    let p = at(i, j);
                    let rho = (p.x - q[0]).hypot(p.y - q[1]);
                    if rho <= c.radius() {
                        brute = brute.max(p.z - c.height(rho));
                    }
                    if i < n && j < n {
                        let m = |a: usize, b: usize| s.eval(a as f64 / n as f64, b as f64 / n as f64).s;
                        tris.push([m(i, j), m(i + 1, j), m(i + 1, j + 1)]);
                        tris.push([m(i, j), m(i + 1, j + 1), m(i, j + 1)]);
                    }
                }
            }
            let Some(g) = got else {
                prop_assert!(brute == f64::NEG_INFINITY, "no drop but a sample gives {brute}");
                return Ok(());
            };
            let tip = frame.to_frame(&g.tip).z;
            prop_assert!(brute <= tip + 1e-9, "a sample is {} above", brute - tip);
            let (foot, _, _) = s.nearest(&g.contact, f64::INFINITY).unwrap();
            prop_assert!((foot.point - g.contact).norm() < 1e-9, "contact off the surface");
            let p = frame.to_frame(&g.contact);
            let rho = (p.x - q[0]).hypot(p.y - q[1]);
            prop_assert!(rho <= c.radius() + 1e-12 && (p.z - c.height(rho.min(c.radius())) - tip).abs() < 1e-9);
            // The tessellation: its chord error is below the surface's second derivatives times
            // the cell's size² / 8.
            let mesh = super::super::mesh::Mesh::new(&tris).unwrap();
            let m = DropCutter::new(&one(Geometry::Mesh(mesh)), c, axis).unwrap().drop(q[0], q[1]);
            let mut curv = 0.0f64;
            for i in 0..=20 {
                for j in 0..=20 {
                    let d = s.eval(i as f64 / 20.0, j as f64 / 20.0);
                    curv = curv.max(d.suu.norm()).max(d.svv.norm()).max(d.suv.norm());
                }
            }
            let chord = curv * 2.0 / (n * n) as f64 / 8.0 * 2.0;
            if let Some(m) = m {
                let nz = g.normal.dot(&axis).max(0.05);
                prop_assert!((frame.to_frame(&m.tip).z - tip).abs() <= chord / nz + 1e-9, "mesh {} exact {tip} chord {chord}", frame.to_frame(&m.tip).z);
            }
        }
    }
}
