//! Trimmed faces, what a CAD B-rep (a STEP file) is made of: a carrier surface (an analytic
//! surface in its canonical frame, or a B-spline patch) bounded by loops of edges (lines, circle
//! arcs, B-spline curves).
//!
//! The nearest point of a face is the carrier's nearest point when that lies inside the face, else
//! the nearest point of its boundary edges (lines and arcs exact, B-spline edges by a bracketed
//! Newton iteration to [`EDGE_TOL`]). Inside is decided in the carrier's parameter space: each
//! loop is sampled, mapped to (u, v) (angles unwrapped across the seam of periodic surfaces) and
//! the signed winding number of the foot's (u, v) is summed, the loops oriented as STEP orients
//! them (the face on their left seen from the face's normal). A loop that winds once round a
//! periodic surface (a cylinder's rim, a sphere's rim whose pole is inside) is closed through
//! v = +∞, and the region below all such loops counts as inside when they wind the other way.
//! Feet within [`UV_TOL`] (relative) of a loop count as inside. The loops are polygons through
//! points [`ARC_STEP`] radians apart on arcs, so a foot nearer to a curved edge than its sagitta
//! (R·1.9e-5: 0.5 µm on R26) may be classed on the wrong side; the distance found then differs by
//! less than sagitta²/(2·distance). The triangles of a face ([`Face::triangles`]) have their
//! boundary through points of the edges within the chord asked instead.

use super::analytic::{Analytic, Foot};
use super::bvh::Aabb;
use super::patch::{BSpline, FOOT_TOL, basis, basis_derivs, find_span};
use super::revolution::Revolution;
use crate::geom::{P3, V3};
use std::f64::consts::{PI, TAU};

/// Largest tangential residual (mm) of a converged nearest point on a B-spline edge.
pub const EDGE_TOL: f64 = FOOT_TOL;

/// Angle (radians) between the points a loop's arcs are sampled at.
pub const ARC_STEP: f64 = PI / 256.0;

/// Distance (relative to the loops' extent in (u, v)) within which a foot is on a loop.
pub const UV_TOL: f64 = 1e-9;

/// Samples per knot span of a B-spline edge (loops and the start of its nearest-point search).
const SPLINE_SAMPLES: usize = 32;

/// The surface a face lies on, in the face's frame.
#[derive(Clone, Debug)]
pub enum Carrier {
    /// Plane z = 0, cylinder, cone or torus around the z axis, or sphere, centred at the origin
    /// (the cone's apex on the z axis); (u, v) is (x, y) on the plane, (angle about z, z) on
    /// cylinders and cones, (longitude, latitude) on the sphere, the two angles on the torus.
    Analytic(Analytic),
    /// A B-spline patch and its own parameters.
    Patch(BSpline),
    /// A profile swept about the z axis; (u, v) is (angle about z, the profile's parameter).
    Revolution(Revolution),
}

/// A B-spline (or NURBS) curve.
#[derive(Clone, Debug)]
pub struct SplineCurve {
    /// Degree, 1 to [`crate::doc::model::MAX_DEGREE`].
    pub degree: usize,
    /// Control points.
    pub ctrl: Vec<P3>,
    /// Weights (None: polynomial).
    pub weights: Option<Vec<f64>>,
    /// Knots, `ctrl.len() + degree + 1` of them.
    pub knots: Vec<f64>,
}

/// Points of a B-spline curve at evenly spaced parameters, where a nearest-point search starts.
#[derive(Clone, Debug)]
pub struct Samples {
    ts: Vec<f64>,
    pts: Vec<P3>,
}

impl SplineCurve {
    /// Parameter domain.
    pub fn domain(&self) -> [f64; 2] {
        [self.knots[self.degree], self.knots[self.ctrl.len()]]
    }

    /// Point, first and second derivative at `t`.
    pub fn eval(&self, t: f64) -> (P3, V3, V3) {
        let (p, n) = (self.degree, self.ctrl.len());
        let s = find_span(&self.knots, n, p, t);
        let b = basis_derivs(&self.knots, s, p, t);
        let (mut a, mut w) = ([V3::zeros(); 3], [0.0; 3]);
        for k in s - p..=s {
            let wk = self.weights.as_ref().map_or(1.0, |ws| ws[k]);
            for ((ad, wd), bd) in a.iter_mut().zip(w.iter_mut()).zip(&b) {
                let basis = wk * bd[k + p - s];
                *ad += self.ctrl[k].coords * basis;
                *wd += basis;
            }
        }
        let c = a[0] / w[0];
        let c1 = (a[1] - c * w[1]) / w[0];
        let c2 = (a[2] - c1 * (2.0 * w[1]) - c * w[2]) / w[0];
        (P3::from(c), c1, c2)
    }

    /// Point at `t`: bit for bit `eval(t).0`, without the derivatives (the nearest-point
    /// search's samples and the outlines' points need none).
    pub fn point(&self, t: f64) -> P3 {
        let (p, n) = (self.degree, self.ctrl.len());
        let s = find_span(&self.knots, n, p, t);
        let b = basis(&self.knots, s, p, t);
        let (mut a, mut w) = (V3::zeros(), 0.0);
        for k in s - p..=s {
            let wk = self.weights.as_ref().map_or(1.0, |ws| ws[k]);
            let basis = wk * b[k + p - s];
            a += self.ctrl[k].coords * basis;
            w += basis;
        }
        P3::from(a / w)
    }

    /// Number of non-empty knot spans in [t0, t1].
    fn spans(&self, t0: f64, t1: f64) -> usize {
        let k = &self.knots[self.degree..=self.ctrl.len()];
        k.windows(2).filter(|w| w[1] > w[0] && w[1] > t0 && w[0] < t1).count().max(1)
    }

    /// The nearest-point search's samples over [t0, t1]: [`SPLINE_SAMPLES`] a span.
    pub fn samples(&self, t0: f64, t1: f64) -> Samples {
        let m = SPLINE_SAMPLES * self.spans(t0, t1);
        let ts: Vec<f64> = (0..=m).map(|i| t0 + (t1 - t0) * i as f64 / m as f64).collect();
        let pts = ts.iter().map(|&t| self.point(t)).collect();
        Samples { ts, pts }
    }

    /// The parameter in [t0, t1] of the nearest point to `q`, and whether it converged.
    pub fn nearest(&self, q: &P3, t0: f64, t1: f64) -> (f64, bool) {
        self.nearest_in(q, &self.samples(t0, t1))
    }

    /// [`SplineCurve::nearest`] over the span of `samples` (made by [`SplineCurve::samples`] and
    /// kept by whoever asks often): the nearest sample, then Newton's method beside it.
    pub fn nearest_in(&self, q: &P3, samples: &Samples) -> (f64, bool) {
        let Samples { ts, pts } = samples;
        let m = ts.len() - 1;
        let d2 = pts.iter().map(|p| (p - q).norm_squared()).enumerate();
        let (i, _) = d2.min_by(|a, b| a.1.total_cmp(&b.1)).expect("samples");
        // g(t) = (C − q)·C' is the derivative of |C − q|²/2; its sign says which way is down.
        let g = |t: f64| {
            let (c, c1, c2) = self.eval(t);
            let r = c - q;
            (r.dot(&c1), c1.dot(&c1) + r.dot(&c2), c1.norm())
        };
        let (gi, _, _) = g(ts[i]);
        if gi == 0.0 {
            return (ts[i], true);
        }
        let (mut lo, mut hi) = if gi > 0.0 {
            if i == 0 {
                return (ts[0], true);
            }
            (ts[i - 1], ts[i])
        } else {
            if i == m {
                return (ts[m], true);
            }
            (ts[i], ts[i + 1])
        };
        if (g(lo).0 > 0.0) || (g(hi).0 < 0.0) {
            // No sign change: the sampled minimum is the best there is.
            return (ts[i], false);
        }
        let mut t = ts[i];
        for _ in 0..200 {
            let (gt, gp, st) = g(t);
            if gt == 0.0 {
                return (t, true);
            }
            if gt < 0.0 {
                lo = t
            } else {
                hi = t
            }
            let newton = t - gt / gp;
            let next = if gp > 0.0 && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
            // Newton's steps shrink quadratically: one below a thousandth of the tolerance ends it.
            if (next - t).abs() * st <= 1e-3 * EDGE_TOL || hi - lo <= f64::EPSILON * (lo.abs() + hi.abs()) {
                let (gn, _, sn) = g(next);
                return (next, gn.abs() <= EDGE_TOL * sn);
            }
            t = next;
        }
        (t, false)
    }
}

/// A boundary curve of a face, in the face's frame, over its own parameter order.
#[derive(Clone, Debug)]
pub enum Curve {
    /// Segment from `a` to `b`.
    Line {
        /// Start.
        a: P3,
        /// End.
        b: P3,
    },
    /// Arc of the circle `centre + radius (x cos t + y sin t)` for t in [t0, t1] (t1 > t0).
    Arc {
        /// Centre.
        centre: P3,
        /// Unit direction of t = 0.
        x: V3,
        /// Unit direction of t = π/2.
        y: V3,
        /// Radius.
        radius: f64,
        /// Start angle.
        t0: f64,
        /// End angle.
        t1: f64,
    },
    /// A B-spline curve over [t0, t1] (made by [`Curve::spline`]).
    Spline {
        /// The curve.
        curve: SplineCurve,
        /// Start parameter.
        t0: f64,
        /// End parameter.
        t1: f64,
        /// The nearest-point search's samples over [t0, t1], made once.
        samples: Samples,
    },
}

impl Curve {
    /// The B-spline edge of `curve` over [t0, t1], with its search samples.
    pub fn spline(curve: SplineCurve, t0: f64, t1: f64) -> Curve {
        let samples = curve.samples(t0, t1);
        Curve::Spline { curve, t0, t1, samples }
    }

    /// The curve's first and last point, in its own parameter order.
    pub fn ends(&self) -> (P3, P3) {
        match self {
            Curve::Line { a, b } => (*a, *b),
            Curve::Arc { centre, x, y, radius, t0, t1 } => {
                let at = |t: f64| centre + (x * t.cos() + y * t.sin()) * *radius;
                (at(*t0), at(*t1))
            }
            Curve::Spline { curve, t0, t1, .. } => (curve.point(*t0), curve.point(*t1)),
        }
    }

    /// The exact (lines, arcs) or converged nearest point to `q`.
    pub fn nearest(&self, q: &P3) -> (P3, bool) {
        match self {
            Curve::Line { a, b } => {
                let d = b - a;
                let t = ((q - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
                (a + d * t, true)
            }
            Curve::Arc { centre, x, y, radius, t0, t1 } => {
                let d = q - centre;
                let (cx, cy) = (d.dot(x), d.dot(y));
                let at = |t: f64| centre + (x * t.cos() + y * t.sin()) * *radius;
                if cx.hypot(cy) > crate::tol::LENGTH_EPS {
                    let t = t0 + (cy.atan2(cx) - t0).rem_euclid(TAU);
                    if t <= *t1 {
                        return (at(t), true);
                    }
                }
                let (a, b) = (at(*t0), at(*t1));
                (if (a - q).norm_squared() <= (b - q).norm_squared() { a } else { b }, true)
            }
            Curve::Spline { curve, samples, .. } => {
                let (t, converged) = curve.nearest_in(q, samples);
                (curve.point(t), converged)
            }
        }
    }

    /// Points along the curve from its start to its end (both included), dense enough for a loop
    /// and with every chord between them within `chord` of the curve (arcs at most [`ARC_STEP`]
    /// apart, B-spline curves [`SPLINE_SAMPLES`] a span, each gap halved until its middle is
    /// within `chord` of it, at most 2¹² times).
    fn samples(&self, straight: bool, chord: f64) -> Vec<P3> {
        match self {
            Curve::Line { a, b } => {
                let n = if straight { 1 } else { 16 };
                (0..=n).map(|i| a + (b - a) * (i as f64 / n as f64)).collect()
            }
            Curve::Arc { centre, x, y, radius, t0, t1 } => {
                // The sagitta of an arc of angle θ is r (1 − cos(θ/2)).
                let step = if chord < *radius { 2.0 * (1.0 - chord / radius).acos() } else { ARC_STEP };
                let n = ((t1 - t0) / step.min(ARC_STEP)).ceil().max(1.0) as usize;
                (0..=n)
                    .map(|i| {
                        let t = t0 + (t1 - t0) * i as f64 / n as f64;
                        centre + (x * t.cos() + y * t.sin()) * *radius
                    })
                    .collect()
            }
            Curve::Spline { curve, t0, t1, .. } => {
                let n = SPLINE_SAMPLES * curve.spans(*t0, *t1);
                let ts: Vec<f64> = (0..=n).map(|i| t0 + (t1 - t0) * i as f64 / n as f64).collect();
                let mut out = vec![curve.point(ts[0])];
                for w in ts.windows(2) {
                    let b = curve.point(w[1]);
                    let mut k = 1usize;
                    while k < 1 << 12 {
                        let sag = (0..k)
                            .map(|i| {
                                let at = |j: f64| w[0] + (w[1] - w[0]) * j / k as f64;
                                let (p, q) = (curve.point(at(i as f64)), curve.point(at(i as f64 + 1.0)));
                                (curve.point(at(i as f64 + 0.5)) - (p + q.coords) / 2.0).norm()
                            })
                            .fold(0.0, f64::max);
                        if sag <= chord {
                            break;
                        }
                        k *= 2;
                    }
                    out.extend((1..k).map(|i| curve.point(w[0] + (w[1] - w[0]) * i as f64 / k as f64)));
                    out.push(b);
                }
                out
            }
        }
    }

    /// A box holding the curve.
    pub fn bounds(&self) -> Aabb {
        match self {
            Curve::Line { a, b } => Aabb::of(&[*a, *b]),
            Curve::Arc { centre, x, y, radius, .. } => {
                let n = x.cross(y);
                let ext = V3::from_fn(|i, _| radius * (1.0 - n[i] * n[i]).max(0.0).sqrt());
                Aabb { min: centre - ext, max: centre + ext }
            }
            Curve::Spline { curve, .. } => Aabb::of(&curve.ctrl),
        }
    }
}

/// One loop in (u, v): its segments (the closing one too unless the loop winds round a periodic
/// u), how many times it winds, its lowest u and v, the segments by column of u (the only ones
/// a ray from a point towards +v can cross: its winding number) and by cell of a grid (the only
/// ones near a point).
#[derive(Clone, Debug)]
struct Loop {
    segs: Vec<([f64; 2], [f64; 2])>,
    wraps: i32,
    /// Period of u (used when the loop winds).
    period: f64,
    min: [f64; 2],
    /// First and last point (a winding loop is closed through v = +∞ from the last to the first).
    ends: [[f64; 2]; 2],
    /// Lowest corner of the grid and the size of a cell.
    origin: [f64; 2],
    cell: [f64; 2],
    columns: Vec<Vec<u32>>,
    cells: Vec<Vec<u32>>,
}

/// A vertex of a face's triangulation: its (u, v) scaled to lengths, and the surface's point there.
#[derive(Clone, Copy, Debug)]
struct Node {
    at: spade::Point2<f64>,
    p: P3,
}

impl spade::HasPosition for Node {
    type Scalar = f64;
    fn position(&self) -> spade::Point2<f64> {
        self.at
    }
}

/// A face's constrained Delaunay triangulation, located through spade's hierarchy (the
/// refinement's probes come in face order, far from the last vertex, and on a long thin face
/// walking from it made the insertions quadratic); a triangle's data is the largest distance its
/// probes found, once none needed refining, or that it is left out.
type Cdt = spade::ConstrainedDelaunayTriangulation<Node, (), (), Option<Verdict>, spade::HierarchyHintGenerator<f64>>;

/// What a refinement round found of a triangle, kept while no insertion touches it: measured
/// again each round over every triangle (its middle tested against a finely outlined face walks
/// every side of its loops), a 0.25 µm check of revolve.step took 22 s, 4.6 s now.
#[derive(Clone, Copy, Debug)]
enum Verdict {
    /// Outside the face, a sliver, or collapsed: not one of the face's triangles.
    Left,
    /// One of the face's triangles: the largest distance its probes found.
    Kept(f64),
}

/// Most vertices of one face's triangulation, and of a model's faces' start grids in all (some
/// 200 bytes each while a face is built, 760 MB and 11 s of CPU for a face of a million).
pub const MAX_VERTICES: usize = 2_000_000;

/// Columns of u, and cells each way, per loop.
const GRID: usize = 64;

impl Loop {
    fn new(uv: Vec<[f64; 2]>, wraps: i32, period: f64, tol: f64) -> Loop {
        let n = uv.len();
        let count = if wraps == 0 { n } else { n - 1 };
        let segs: Vec<_> = (0..count).map(|k| (uv[k], uv[(k + 1) % n])).collect();
        let lo = |c: usize| uv.iter().map(|p| p[c]).fold(f64::INFINITY, f64::min);
        let hi = |c: usize| uv.iter().map(|p| p[c]).fold(f64::NEG_INFINITY, f64::max);
        let min = [lo(0), lo(1)];
        let origin = [min[0] - tol, min[1] - tol];
        let cell = [0, 1].map(|c| ((hi(c) - min[c] + 2.0 * tol) / GRID as f64).max(f64::MIN_POSITIVE));
        let index = |c: usize, x: f64| (((x - origin[c]) / cell[c]).floor().max(0.0) as usize).min(GRID - 1);
        let mut columns = vec![Vec::new(); GRID];
        let mut cells = vec![Vec::new(); GRID * GRID];
        for (k, (a, b)) in segs.iter().enumerate() {
            let (u0, u1) = (index(0, a[0].min(b[0]) - tol), index(0, a[0].max(b[0]) + tol));
            let (v0, v1) = (index(1, a[1].min(b[1]) - tol), index(1, a[1].max(b[1]) + tol));
            for i in u0..=u1 {
                columns[i].push(k as u32);
                for j in v0..=v1 {
                    cells[j * GRID + i].push(k as u32);
                }
            }
        }
        Loop { segs, wraps, period, min, ends: [uv[0], uv[n - 1]], origin, cell, columns, cells }
    }

    /// Index of `x` along coordinate `c` of the grid, if inside it.
    fn slot(&self, c: usize, x: f64) -> Option<usize> {
        let k = ((x - self.origin[c]) / self.cell[c]).floor();
        (k >= 0.0 && k < GRID as f64).then_some(k as usize)
    }

    /// The segments whose column of u holds `u` (none outside the loop's range).
    fn column(&self, u: f64) -> impl Iterator<Item = &([f64; 2], [f64; 2])> {
        let list = self.slot(0, u).map_or(&[][..], |k| self.columns[k].as_slice());
        list.iter().map(|&i| &self.segs[i as usize])
    }

    /// True when `q` is within `tol` of the loop.
    fn touches(&self, q: [f64; 2], tol: f64) -> bool {
        let (Some(i), Some(j)) = (self.slot(0, q[0]), self.slot(1, q[1])) else { return false };
        self.cells[j * GRID + i].iter().any(|&k| {
            let (a, b) = self.segs[k as usize];
            segment_distance(q, a, b) <= tol
        })
    }

    /// Signed winding number about `p` (a winding loop closed through v = +∞), counted on the
    /// ray from `p` towards +v: in coordinates turned a quarter (u, v) → (v, −u), where that ray
    /// runs towards +u, by Sunday's crossing rule.
    fn winding(&self, p: [f64; 2]) -> i32 {
        let turn = |q: [f64; 2]| [q[1], -q[0]];
        let [first, last] = self.ends;
        let mut p = p;
        if self.wraps > 0 {
            // The rule counts a vertex of the ray's line at a segment's end for segments running
            // towards +u, at its start for those running towards −u: the loop's first point is
            // taken as its last.
            let t = self.period;
            p[0] = first[0] + t - (first[0] + t - p[0]).rem_euclid(t);
        } else if self.wraps < 0 {
            p[0] = first[0] - (first[0] - p[0]).rem_euclid(self.period);
        }
        let mut w = 0;
        for (a, b) in self.column(p[0]) {
            w += crossing(turn(*a), turn(*b), turn(p));
        }
        if self.wraps != 0 {
            // Closed through a top above everything, from the last point up, across and down to
            // the first: the ray crosses the top once, whatever its u.
            let top = self.origin[1] + self.cell[1] * GRID as f64 + p[1].abs() + 1.0;
            let mid = [0.5 * (first[0] + last[0]), p[1]];
            w += crossing(turn([last[0], top]), turn([first[0], top]), turn(mid));
        }
        w
    }
}

/// The winding number's count for segment a → b about `p` (Sunday's crossing rule).
fn crossing(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> i32 {
    if (a[1] <= p[1]) == (b[1] <= p[1]) {
        return 0;
    }
    let left = (b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1]);
    if a[1] <= p[1] { i32::from(b[1] > p[1] && left > 0.0) } else { -i32::from(b[1] <= p[1] && left < 0.0) }
}

/// A trimmed face: carrier, boundary loops and the sense of its normal.
#[derive(Clone, Debug)]
pub struct Face {
    carrier: Carrier,
    edges: Vec<(Curve, Aabb)>,
    /// Each loop's edges (indices into `edges`) and the way each is walked (true: forward).
    walks: Vec<Vec<(usize, bool)>>,
    loops: Vec<Loop>,
    /// +1 when the face's normal is the carrier's, −1 when reversed (the loops turn the other
    /// way in (u, v)).
    sense: f64,
    /// Distance in (u, v) within which a foot is on a loop.
    tol: f64,
    bounds: Aabb,
}

impl Carrier {
    /// The periods of (u, v) that are periodic: angles, and the parameters of B-spline patches
    /// and profiles that close on themselves.
    pub fn period(&self) -> [Option<f64>; 2] {
        match self {
            Carrier::Analytic(Analytic::Plane { .. }) => [None, None],
            Carrier::Analytic(Analytic::Torus { .. }) => [Some(TAU), Some(TAU)],
            Carrier::Analytic(_) => [Some(TAU), None],
            Carrier::Patch(s) => {
                let [u0, u1, v0, v1] = s.domain();
                let c = s.closed();
                [c[0].then_some(u1 - u0), c[1].then_some(v1 - v0)]
            }
            Carrier::Revolution(r) => {
                let [_, _, v0, v1] = r.domain();
                [Some(TAU), r.closed().then_some(v1 - v0)]
            }
        }
    }

    /// (u, v) of a point on the carrier; u is None on the axis of a surface of revolution.
    fn param(&self, p: &P3) -> (Option<f64>, f64) {
        let rho = p.x.hypot(p.y);
        let u = (rho > 1e-12 * (1.0 + p.coords.norm())).then(|| p.y.atan2(p.x));
        match self {
            Carrier::Analytic(Analytic::Plane { .. }) => (Some(p.x), p.y),
            Carrier::Analytic(Analytic::Sphere { .. }) => (u, p.z.atan2(rho)),
            Carrier::Analytic(Analytic::Torus { major, .. }) => (u, p.z.atan2(rho - major)),
            Carrier::Analytic(_) => (u, p.z),
            Carrier::Patch(s) => {
                let (_, uv, _) = s.nearest(p, f64::INFINITY).expect("an unbounded query finds a point");
                (Some(uv[0]), uv[1])
            }
            Carrier::Revolution(r) => {
                let (_, uv, _) = r.nearest(p, f64::INFINITY).expect("an unbounded query finds a point");
                (u, uv[1])
            }
        }
    }

    /// The nearest point no farther than `bound`: foot, its (u, v) and whether it converged.
    fn foot(&self, q: &P3, bound: f64) -> Option<(Foot, [f64; 2], bool)> {
        match self {
            Carrier::Analytic(a) => {
                let f = a.foot(q);
                if (f.point - q).norm() > bound {
                    return None;
                }
                let (u, v) = self.param(&f.point);
                Some((f, [u.unwrap_or(0.0), v], true))
            }
            Carrier::Patch(s) => s.nearest(q, bound),
            Carrier::Revolution(r) => r.nearest(q, bound),
        }
    }

    /// The point at (u, v).
    fn point(&self, [u, v]: [f64; 2]) -> P3 {
        match self {
            Carrier::Analytic(Analytic::Plane { .. }) => P3::new(u, v, 0.0),
            Carrier::Analytic(Analytic::Cylinder { radius, .. }) => P3::new(radius * u.cos(), radius * u.sin(), v),
            Carrier::Analytic(Analytic::Cone { apex, half_angle, .. }) => {
                let rho = (v - apex.z) * half_angle.tan();
                P3::new(rho * u.cos(), rho * u.sin(), v)
            }
            Carrier::Analytic(Analytic::Sphere { radius, .. }) => {
                P3::new(radius * v.cos() * u.cos(), radius * v.cos() * u.sin(), radius * v.sin())
            }
            Carrier::Analytic(Analytic::Torus { major, minor, .. }) => {
                let rho = major + minor * v.cos();
                P3::new(rho * u.cos(), rho * u.sin(), minor * v.sin())
            }
            Carrier::Patch(s) => s.point(u, v),
            Carrier::Revolution(r) => r.point(u, v),
        }
    }

    /// The carrier's normal at a point on it.
    pub fn normal_at(&self, p: &P3) -> V3 {
        match self {
            Carrier::Analytic(a) => a.foot(p).normal,
            Carrier::Patch(s) => s.nearest(p, f64::INFINITY).expect("an unbounded query finds a point").0.normal,
            Carrier::Revolution(r) => r.nearest(p, f64::INFINITY).expect("an unbounded query finds a point").0.normal,
        }
    }
}

/// True when the segment from `a` to `b` meets the rectangle [lo, hi].
fn segment_meets_rect(a: [f64; 2], b: [f64; 2], lo: [f64; 2], hi: [f64; 2]) -> bool {
    if a[0].max(b[0]) < lo[0] || a[0].min(b[0]) > hi[0] || a[1].max(b[1]) < lo[1] || a[1].min(b[1]) > hi[1] {
        return false;
    }
    let side = |x: f64, y: f64| (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
    let s = [side(lo[0], lo[1]), side(hi[0], lo[1]), side(hi[0], hi[1]), side(lo[0], hi[1])];
    !(s.iter().all(|&v| v > 0.0) || s.iter().all(|&v| v < 0.0))
}

/// Distance from `p` to the segment from `a` to `b`.
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    let t = if len2 > 0.0 { (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (p[0] - a[0] - t * d[0]).hypot(p[1] - a[1] - t * d[1])
}

/// One loop (edges by index and the way each is walked) as a polygon in (u, v) through points of
/// its edges within `chord` of them (angles unwrapped across seams), and how many times it winds
/// round a periodic u; `None` for a loop of no points.
fn polygon(
    carrier: &Carrier,
    edges: &[(Curve, Aabb)],
    walk: &[(usize, bool)],
    chord: f64,
) -> Option<(Vec<[f64; 2]>, i32)> {
    let period = carrier.period();
    let straight = matches!(carrier, Carrier::Analytic(Analytic::Plane { .. } | Analytic::Cylinder { .. }));
    let mut pts: Vec<(Option<f64>, f64)> = Vec::new();
    for &(k, forward) in walk {
        let mut s = edges[k].0.samples(straight, chord);
        if !forward {
            s.reverse();
        }
        s.pop();
        pts.extend(s.iter().map(|p| carrier.param(p)));
    }
    if pts.is_empty() {
        return None;
    }
    // A point on the axis takes the angle of its neighbour along the loop.
    if let Some(k) = pts.iter().position(|p| p.0.is_some()) {
        let n = pts.len();
        for i in 1..n {
            let (j, prev) = ((k + i) % n, (k + i - 1) % n);
            if pts[j].0.is_none() {
                pts[j].0 = pts[prev].0;
            }
        }
    }
    let mut uv: Vec<[f64; 2]> = pts.iter().map(|p| [p.0.unwrap_or(0.0), p.1]).collect();
    for i in 1..uv.len() {
        for c in 0..2 {
            if let Some(t) = period[c] {
                let prev = uv[i - 1][c];
                uv[i][c] = prev + (uv[i][c] - prev + t / 2.0).rem_euclid(t) - t / 2.0;
            }
        }
    }
    // Closing the loop: how far it has wound round u.
    let last = uv[uv.len() - 1];
    let wraps = if let Some(t) = period[0] {
        let closed = last[0] + (uv[0][0] - last[0] + t / 2.0).rem_euclid(t) - t / 2.0;
        ((closed - uv[0][0]) / t).round() as i32
    } else {
        0
    };
    Some((uv, wraps))
}

impl Face {
    /// A face on `carrier` bounded by `loops`, each a list of curves with the direction they are
    /// walked in (true: from the curve's start to its end), oriented as STEP orients them for a
    /// face whose normal is the carrier's when `same_sense`.
    pub fn new(carrier: Carrier, loops: Vec<Vec<(Curve, bool)>>, same_sense: bool) -> Face {
        let period = carrier.period();
        let mut edges = Vec::new();
        let mut walks = Vec::new();
        let mut extent = Aabb::empty();
        for lp in loops {
            let mut walk = Vec::new();
            for (curve, forward) in lp {
                let b = curve.bounds();
                extent = extent.union(&b);
                walk.push((edges.len(), forward));
                edges.push((curve, b));
            }
            walks.push(walk);
        }
        let polys: Vec<_> = walks.iter().filter_map(|w| polygon(&carrier, &edges, w, f64::INFINITY)).collect();
        let span = polys.iter().flat_map(|(uv, _)| uv.iter()).fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()));
        let tol = UV_TOL * (1.0 + span);
        let polys = polys.into_iter().map(|(uv, wraps)| Loop::new(uv, wraps, period[0].unwrap_or(TAU), tol)).collect();
        let bounds = match &carrier {
            Carrier::Analytic(Analytic::Plane { .. }) => extent,
            Carrier::Analytic(a) => a.bounds(),
            Carrier::Patch(s) => s.bounds(),
            Carrier::Revolution(r) => r.bounds(),
        };
        Face { carrier, edges, walks, loops: polys, sense: if same_sense { 1.0 } else { -1.0 }, tol, bounds }
    }

    /// The face with its loops' polygons through points of its edges within `chord` of them.
    fn outlined(&self, chord: f64) -> Face {
        let period = self.carrier.period();
        let loops = self
            .walks
            .iter()
            .filter_map(|w| polygon(&self.carrier, &self.edges, w, chord))
            .map(|(uv, wraps)| Loop::new(uv, wraps, period[0].unwrap_or(TAU), self.tol))
            .collect();
        Face { loops, ..self.clone() }
    }

    /// A box holding the face (its carrier's when curved, its boundary's when planar).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The (u, v) box [u0, u1, v0, v1] the face spans (its loops', a full turn where one winds round,
    /// out to a pole it holds; a vertex-bounded face's whole carrier).
    pub fn uv_box(&self) -> [f64; 4] {
        let (lo, hi) = self.span();
        [lo[0], hi[0], lo[1], hi[1]]
    }

    /// The carrier.
    pub fn carrier(&self) -> &Carrier {
        &self.carrier
    }

    /// True when `p`, a point of the carrier (face frame), is inside the face or on its boundary.
    pub fn contains(&self, p: &P3) -> bool {
        let (u, v) = self.carrier.param(p);
        self.inside([u.unwrap_or(0.0), v])
    }

    /// The boundary curves of every loop.
    pub fn edges(&self) -> impl Iterator<Item = &Curve> {
        self.edges.iter().map(|(c, _)| c)
    }

    /// False when no loop passes within the tolerance of the rectangle [lo, hi] of (u, v) (moved
    /// by whole turns along periodic parameters), so that it lies wholly inside or wholly outside
    /// the face; true when one may.
    pub fn crosses(&self, lo: [f64; 2], hi: [f64; 2]) -> bool {
        let period = self.carrier.period();
        let (lo, hi) = ([lo[0] - self.tol, lo[1] - self.tol], [hi[0] + self.tol, hi[1] + self.tol]);
        for l in &self.loops {
            let top = [0, 1].map(|c| l.origin[c] + l.cell[c] * GRID as f64);
            let turns = |c: usize| -> Vec<f64> {
                let Some(t) = period[c] else { return vec![0.0] };
                let first = ((l.origin[c] - hi[c]) / t).floor() as i64;
                let last = ((top[c] - lo[c]) / t).ceil() as i64;
                (first..=last).map(|k| k as f64 * t).collect()
            };
            for du in turns(0) {
                for dv in turns(1) {
                    let (a, b) = ([lo[0] + du, lo[1] + dv], [hi[0] + du, hi[1] + dv]);
                    if a[0] > top[0] || a[1] > top[1] || b[0] < l.origin[0] || b[1] < l.origin[1] {
                        continue;
                    }
                    if l.segs.iter().any(|(p, q)| segment_meets_rect(*p, *q, a, b)) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// True when (u, v) is inside the face or on its boundary.
    pub fn inside(&self, uv: [f64; 2]) -> bool {
        if self.loops.is_empty() {
            return true; // bounded by vertex loops alone: the whole carrier (a sphere)
        }
        let period = self.carrier.period();
        let shifts = |c: usize| match period[c] {
            Some(t) => ([0.0, -t, t], 3),
            None => ([0.0; 3], 1),
        };
        let ((su, nu), (sv, nv)) = (shifts(0), shifts(1));
        let (mut w, mut wraps) = (0i32, 0i32);
        for l in &self.loops {
            let mut p = uv;
            for c in 0..2 {
                if let Some(t) = period[c] {
                    p[c] = l.min[c] + (p[c] - l.min[c]).rem_euclid(t);
                }
            }
            for du in &su[..nu] {
                for dv in &sv[..nv] {
                    let q = [p[0] + du, p[1] + dv];
                    if l.touches(q, self.tol) {
                        return true;
                    }
                }
            }
            w += l.winding(p);
            wraps += l.wraps;
        }
        let below = (-(self.sense as i32) * wraps).max(0);
        self.sense as i32 * w + below >= 1
    }

    /// The parameter rectangle the face spans: its loops' (a full turn where one winds round, out
    /// to a pole the face holds), or the carrier's whole domain for a face bounded by vertex
    /// loops alone (a whole sphere).
    fn span(&self) -> ([f64; 2], [f64; 2]) {
        let period = self.carrier.period();
        if self.loops.is_empty() {
            let [u0, u1, v0, v1] = match &self.carrier {
                Carrier::Analytic(Analytic::Sphere { .. }) => [-PI, PI, -PI / 2.0, PI / 2.0],
                Carrier::Analytic(Analytic::Torus { .. }) => [-PI, PI, -PI, PI],
                Carrier::Patch(s) => s.domain(),
                Carrier::Revolution(r) => r.domain(),
                _ => [0.0; 4], // unbounded carriers always have loops
            };
            return ([u0, v0], [u1, v1]);
        }
        let pts = || self.loops.iter().flat_map(|l| l.segs.iter().flat_map(|(a, b)| [*a, *b]));
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in pts() {
            for c in 0..2 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        if self.loops.iter().any(|l| l.wraps != 0) {
            hi[0] = hi[0].max(lo[0] + period[0].unwrap_or(TAU));
            if let Carrier::Analytic(Analytic::Sphere { .. }) = self.carrier {
                // Out to the pole the face holds.
                if self.inside([lo[0], -PI / 2.0]) {
                    lo[1] = -PI / 2.0;
                }
                if self.inside([lo[0], PI / 2.0]) {
                    hi[1] = PI / 2.0;
                }
            }
        }
        if let Some(t) = period[1] {
            hi[1] = hi[1].min(lo[1] + t);
        }
        (lo, hi)
    }

    /// The steps each way of a face's start grid within `chord`: as fine each way as the surface
    /// bends that way (a cylinder's straight lines need no points along them), halved from 1/16
    /// of the span until the surface midway between two grid points of nine lines across is
    /// within 3/4 of the chord of their chord (at most 2¹² each way).
    fn grid(&self, chord: f64) -> (usize, usize) {
        let target = 0.75 * chord;
        let (lo, hi) = self.span();
        let at = |q: [f64; 2]| self.carrier.point(q);
        let steps = |c: usize| {
            let mut n = 16usize;
            while n < 1 << 12 {
                let bends = (0..=8).any(|j| {
                    let across = lo[1 - c] + (hi[1 - c] - lo[1 - c]) * j as f64 / 8.0;
                    let p = |i: f64| {
                        let along = lo[c] + (hi[c] - lo[c]) * i / n as f64;
                        at(if c == 0 { [along, across] } else { [across, along] })
                    };
                    (0..n).any(|i| (p(i as f64 + 0.5) - (p(i as f64) + p(i as f64 + 1.0).coords) / 2.0).norm() > target)
                });
                if !bends {
                    break;
                }
                n *= 2;
            }
            n
        };
        (steps(0), steps(1))
    }

    /// The fewest vertices [`Face::triangles`] makes within `chord`: its start grid's (a cheap
    /// estimate to refuse a model by before tessellating any face).
    pub fn least_vertices(&self, chord: f64) -> usize {
        let (nu, nv) = self.grid(chord);
        (nu + 1) * (nv + 1)
    }

    /// Lengths on the surface per unit of u and of v (the mean over a 9 × 9 grid of the span),
    /// each rounded to a power of two (1 where the surface does not move that way).
    fn uv_scale(&self, lo: [f64; 2], hi: [f64; 2]) -> [f64; 2] {
        let at = |i: usize, j: usize| {
            self.carrier.point([lo[0] + (hi[0] - lo[0]) * i as f64 / 8.0, lo[1] + (hi[1] - lo[1]) * j as f64 / 8.0])
        };
        let (mut du, mut dv) = (0.0, 0.0);
        for i in 0..=8 {
            for j in 0..8 {
                du += (at(j + 1, i) - at(j, i)).norm();
                dv += (at(i, j + 1) - at(i, j)).norm();
            }
        }
        let pow2 = |len: f64, span: f64| {
            let speed = len / span;
            if speed.is_finite() && speed > 0.0 {
                2f64.powi(speed.log2().round().clamp(-900.0, 900.0) as i32)
            } else {
                1.0
            }
        };
        [pow2(du / 9.0, hi[0] - lo[0]), pow2(dv / 9.0, hi[1] - lo[1])]
    }

    /// Triangles covering the face (face frame, turned so that their right-hand normals follow
    /// the carrier's) and the largest distance found between them and the surface: a constrained
    /// Delaunay triangulation (`spade`) in (u, v) of the loops (as constraints, each segment
    /// halved until the surface at its middle is within `chord` of its chord) and a grid as fine
    /// each way as the surface bends that way, refined where the surface bends: every kept triangle whose plane is farther than 3/4 of `chord`
    /// from the surface at its edges' middles or its centroid gets a vertex at the worst of them,
    /// until none does or [`MAX_VERTICES`] are reached; the distance returned is 4/3 of the largest
    /// measured (to second order a triangle's distance is at most 4/3 of its edges' middles'). The triangles whose middle is inside the
    /// face are kept; the boundary is a polygon through points of the edges, each of its sides
    /// within 3/4 of `chord` of its edge. Refused (the reason) where the start grid alone would
    /// exceed [`MAX_VERTICES`].
    pub fn triangles(&self, chord: f64) -> Result<(Vec<[P3; 3]>, f64), String> {
        use spade::{Point2, Triangulation};
        // A triangle's distance from a smooth surface is, to second order, a quadratic vanishing at
        // its corners: 4 Σ m_ij λi λj over the edges' middles m_ij, at most 4/3 of the largest
        // middle. Refining to 3/4 of the chord keeps the triangles within the chord.
        let target = 0.75 * chord;
        // The loops through points of the edges within the target of them.
        let fine = self.outlined(target);
        let (lo, hi) = self.span();
        let extent = (hi[0] - lo[0]) * (hi[1] - lo[1]);
        let at = |q: [f64; 2]| self.carrier.point(q);
        let middle = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        // Triangulated in (u, v) scaled to the surface's lengths: a Delaunay triangulation is not
        // invariant under stretching one axis, and a knot vector over (0, 1e9) or an angle
        // beside a length makes its triangles needles that refinement never ends. Powers of two,
        // so that the mapping is exact both ways.
        let scale = self.uv_scale(lo, hi);
        // spade refuses coordinates under 2^-142 but 0: those are 0 (far below any length here).
        let flush = |x: f64| if x.abs() < spade::MIN_ALLOWED_VALUE { 0.0 } else { x };
        let to = |q: [f64; 2]| Point2::new(flush(q[0] * scale[0]), flush(q[1] * scale[1]));
        let back = |p: Point2<f64>| [p.x / scale[0], p.y / scale[1]];
        let (nu, nv) = self.grid(chord);
        // The start grid is the least the triangulation holds: past the bound, refuse before
        // building it (a face bent that finely over its span: a 12 km spike on a patch).
        let least = (nu + 1) * (nv + 1);
        if least > MAX_VERTICES {
            return Err(format!(
                "within {chord} mm its triangles need at least {least} vertices ({} × {} along its (u, v) directions), more than the {MAX_VERTICES} a face may have: the face is too large or too finely bent for the check",
                nu + 1,
                nv + 1
            ));
        }
        // The grid and the loops' points (constraint edges between neighbours), bulk-loaded: a
        // grid's points are cocircular, and inserted one by one each legalised its neighbourhood.
        let mut nodes: Vec<Node> = Vec::with_capacity(least);
        let mut edges: Vec<[usize; 2]> = Vec::new();
        let node = |q: [f64; 2]| Node { at: to(q), p: at(q) };
        for i in 0..=nu {
            for j in 0..=nv {
                let f = [i as f64 / nu as f64, j as f64 / nv as f64];
                nodes.push(node([lo[0] + (hi[0] - lo[0]) * f[0], lo[1] + (hi[1] - lo[1]) * f[1]]));
            }
        }
        for l in &fine.loops {
            for &(a, b) in &l.segs {
                // Halved until every piece's middle is within the chord of the piece.
                let mut k = 1usize;
                while k < 1 << 12 {
                    let piece = |i: usize| {
                        let f = |t: f64| [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
                        (f(i as f64 / k as f64), f((i + 1) as f64 / k as f64))
                    };
                    let sag = (0..k)
                        .map(|i| {
                            let (p, q) = piece(i);
                            (at(middle(p, q)) - (at(p) + at(q).coords) / 2.0).norm()
                        })
                        .fold(0.0, f64::max);
                    if sag <= target {
                        break;
                    }
                    k *= 2;
                }
                nodes.push(node(a));
                for i in 1..=k {
                    let t = i as f64 / k as f64;
                    nodes.push(node([a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]));
                    let (p, q) = (nodes.len() - 2, nodes.len() - 1);
                    if nodes[p].at != nodes[q].at {
                        edges.push([p, q]);
                    }
                }
            }
        }
        // Points spade cannot take (not finite) are left out, as an insertion's error would leave them.
        let mut keep = vec![usize::MAX; nodes.len()];
        let mut kept = Vec::with_capacity(nodes.len());
        for (k, n) in nodes.into_iter().enumerate() {
            if spade::validate_vertex(&n).is_ok() && n.p.coords.iter().all(|c| c.is_finite()) {
                keep[k] = kept.len();
                kept.push(n);
            }
        }
        let edges = edges
            .into_iter()
            .filter(|&[p, q]| keep[p] != usize::MAX && keep[q] != usize::MAX)
            .map(|[p, q]| [keep[p], keep[q]])
            .collect();
        // A constraint crossing one already in is left out, as `try_add_constraint` leaves it.
        let mut cdt =
            Cdt::try_bulk_load_cdt(kept, edges, |_| {}).map_err(|e| format!("its triangulation failed: {e:?}"))?;
        // Each round measures the triangles made since the last (at first every one): every face
        // an insertion makes holds the new vertex, so the others keep their verdict.
        let judge = |cdt: &Cdt, h: spade::handles::FixedFaceHandle<spade::handles::InnerTag>| {
            let f = cdt.face(h);
            let t = f.vertices().map(|v| v.data().p);
            let uv = f.vertices().map(|v| back(v.position()));
            let mid = [(uv[0][0] + uv[1][0] + uv[2][0]) / 3.0, (uv[0][1] + uv[1][1] + uv[2][1]) / 3.0];
            let area = (uv[1][0] - uv[0][0]) * (uv[2][1] - uv[0][1]) - (uv[2][0] - uv[0][0]) * (uv[1][1] - uv[0][1]);
            let nrm = (t[1] - t[0]).cross(&(t[2] - t[0]));
            let len = nrm.norm();
            // Outside, a sliver of a loop's nearly collinear points (turned either way in space),
            // or collapsed at a pole or an apex.
            if area <= 1e-14 * extent || len <= 1e-12 || !fine.inside(mid) {
                return (Verdict::Left, None);
            }
            let edges = f.adjacent_edges();
            let mut bad: Option<([f64; 2], f64)> = None;
            let mut largest = 0.0f64;
            let mut probe = |q: [f64; 2], movable: bool| {
                let d = ((at(q) - t[0]).dot(&nrm) / len).abs();
                largest = largest.max(d);
                if movable && d > target && bad.is_none_or(|(_, b)| d > b) {
                    bad = Some((q, d));
                }
            };
            probe(mid, true);
            for k in 0..3 {
                let e = middle(uv[k], uv[(k + 1) % 3]);
                // Constraint edges were split to the chord beforehand: their middles stay.
                let fixed = edges.iter().any(|h| {
                    let [p, q] = h.positions().map(back);
                    let m = middle(p, q);
                    m == e && cdt.is_constraint_edge(h.as_undirected().fix())
                });
                probe(e, !fixed);
            }
            (Verdict::Kept(largest), bad.map(|(q, _)| q))
        };
        let mut fresh: Vec<_> = cdt.fixed_inner_faces().collect();
        loop {
            // Probes needing a vertex, in face order (the order of insertion shapes a grid's
            // cocircular points' triangles).
            let mut refine = Vec::new();
            let verdicts: Vec<_> = fresh
                .iter()
                .map(|&h| {
                    let (verdict, q) = judge(&cdt, h);
                    refine.extend(q);
                    (h, verdict)
                })
                .collect();
            for (h, verdict) in verdicts {
                *cdt.face_data_mut(h) = Some(verdict);
            }
            if refine.is_empty() || cdt.num_vertices() >= MAX_VERTICES {
                break;
            }
            let first_new = cdt.num_vertices();
            for q in refine {
                cdt.insert(node(q)).ok();
            }
            if cdt.num_vertices() == first_new {
                break; // nothing new: the probes are vertices already
            }
            fresh = (first_new..cdt.num_vertices())
                .flat_map(|i| cdt.vertex(spade::handles::FixedVertexHandle::from_index(i)).out_edges())
                .filter_map(|e| e.face().as_inner().map(|f| f.fix()))
                .collect();
            fresh.sort_unstable_by_key(|h| h.index());
            fresh.dedup();
        }
        let mut tris = Vec::new();
        let mut worst = 0.0f64;
        for f in cdt.inner_faces() {
            if let Verdict::Kept(d) = f.data().unwrap_or_else(|| judge(&cdt, f.fix()).0) {
                worst = worst.max(d);
                tris.push(f.vertices().map(|v| v.data().p));
            }
        }
        Ok((tris, worst * 4.0 / 3.0))
    }

    /// The farthest any point of the face's edges (at their loop samples) lies from its carrier,
    /// with the edge's index (in loop order): a CAD file's edges lie on their faces within its
    /// tolerance.
    pub fn edges_off(&self) -> (f64, usize) {
        let straight = matches!(self.carrier, Carrier::Analytic(Analytic::Plane { .. } | Analytic::Cylinder { .. }));
        let mut worst = (0.0, 0);
        for (k, (curve, _)) in self.edges.iter().enumerate() {
            for p in curve.samples(straight, f64::INFINITY) {
                let d = self.carrier.foot(&p, f64::INFINITY).map_or(f64::INFINITY, |(f, _, _)| (f.point - p).norm());
                if d > worst.0 || d.is_nan() {
                    worst = (d, k);
                }
            }
        }
        worst
    }

    /// The nearest point of the face to `q` no farther than `bound`, the carrier's normal there
    /// and whether the iterations converged.
    pub fn nearest(&self, q: &P3, bound: f64) -> Option<(Foot, bool)> {
        let (foot, uv, converged) = self.carrier.foot(q, bound)?;
        if self.inside(uv) {
            return Some((foot, converged));
        }
        let mut best: Option<(P3, bool, f64)> = None;
        let mut limit = bound;
        if let Carrier::Patch(s) = &self.carrier {
            // A nearer local minimum inside the face than its edges (a B-spline bends back).
            if let Some((f, _, c)) = s.nearest_where(q, bound, |uv| self.inside(uv)) {
                let d = (f.point - q).norm();
                limit = d;
                best = Some((f.point, c, d));
            }
        }
        for (curve, b) in &self.edges {
            if b.dist2(q).sqrt() > limit {
                continue;
            }
            let (p, c) = curve.nearest(q);
            let d = (p - q).norm();
            if d <= limit && best.is_none_or(|(_, _, bd)| d < bd) {
                limit = d;
                best = Some((p, c, d));
            }
        }
        let (p, c, _) = best?;
        Some((Foot { point: p, normal: self.carrier.normal_at(&p) }, c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(centre: P3, radius: f64) -> Curve {
        Curve::Arc { centre, x: V3::x(), y: V3::y(), radius, t0: 0.0, t1: TAU }
    }

    fn square(a: f64) -> Vec<(Curve, bool)> {
        let c = [P3::new(-a, -a, 0.0), P3::new(a, -a, 0.0), P3::new(a, a, 0.0), P3::new(-a, a, 0.0)];
        (0..4).map(|k| (Curve::Line { a: c[k], b: c[(k + 1) % 4] }, true)).collect()
    }

    /// A 100 × 100 plane with a hole of radius 10 at the origin: over the hole the nearest point
    /// is on the rim, at the closed-form distance.
    #[test]
    fn plane_with_a_hole_gives_the_rim_over_the_hole() {
        let plane = Carrier::Analytic(Analytic::Plane { point: P3::origin(), normal: V3::z() });
        let face = Face::new(plane, vec![square(50.0), vec![(circle(P3::origin(), 10.0), false)]], true);
        for (x, y, z) in [(3.0, 4.0, 2.0), (0.0, 0.0, 5.0), (-7.0, 1.0, -3.0), (9.9, 0.0, 1.0)] {
            let q = P3::new(x, y, z);
            let (f, ok) = face.nearest(&q, f64::INFINITY).unwrap();
            let rho: f64 = x.hypot(y);
            let want = (10.0 - rho).hypot(z);
            assert!(ok && ((f.point - q).norm() - want).abs() < 1e-12, "{q}: {} vs {want}", (f.point - q).norm());
            assert!((f.point.coords.xy().norm() - 10.0).abs() < 1e-12 && f.normal == V3::z());
        }
        // On the solid part: the foot on the plane; beyond the outer edge: the edge.
        let (f, _) = face.nearest(&P3::new(20.0, -30.0, 4.0), f64::INFINITY).unwrap();
        assert_eq!(f.point, P3::new(20.0, -30.0, 0.0));
        let (f, _) = face.nearest(&P3::new(60.0, 10.0, 4.0), f64::INFINITY).unwrap();
        assert!((f.point - P3::new(50.0, 10.0, 0.0)).norm() < 1e-12);
        assert!(face.nearest(&P3::new(60.0, 10.0, 4.0), 10.0).is_none());
        // The same face with its normal reversed (loops turn the other way): the same answers.
        let plane = Carrier::Analytic(Analytic::Plane { point: P3::origin(), normal: V3::z() });
        let rev = |l: Vec<(Curve, bool)>| l.into_iter().rev().map(|(c, f)| (c, !f)).collect::<Vec<_>>();
        let back = Face::new(plane, vec![rev(square(50.0)), rev(vec![(circle(P3::origin(), 10.0), false)])], false);
        for uv in [[3.0, 4.0], [20.0, -30.0], [60.0, 0.0], [0.0, 0.0]] {
            assert_eq!(back.inside(uv), face.inside(uv), "{uv:?}");
        }
    }

    /// A spherical dish (R40 centred 30 above its rim plane, the cap below the rim, normal
    /// reversed) bounded by its rim and a seam down to the pole, as a CAD system writes it: points
    /// over the dish get the sphere's foot, points beside it the rim.
    #[test]
    fn sphere_dish_is_bounded_by_its_rim() {
        let (r, h) = (40.0f64, 30.0f64);
        let rim_r = (r * r - h * h).sqrt();
        let sphere = Carrier::Analytic(Analytic::Sphere { centre: P3::origin(), radius: r });
        let rim = circle(P3::new(0.0, 0.0, -h), rim_r);
        let seam =
            Curve::Arc { centre: P3::origin(), x: V3::x(), y: -V3::z(), radius: r, t0: (h / r).asin(), t1: PI / 2.0 };
        let face = Face::new(sphere, vec![vec![(rim, true), (seam.clone(), true), (seam, false)]], false);
        for (x, y, z) in [(0.0, 0.0, 0.0), (5.0, -3.0, -10.0), (10.0, 10.0, -35.0), (0.0, 0.0, -45.0)] {
            let q = P3::new(x, y, z);
            let (f, _) = face.nearest(&q, f64::INFINITY).unwrap();
            assert!(((f.point - q).norm() - (r - q.coords.norm()).abs()).abs() < 1e-12, "{q}");
        }
        let q = P3::new(40.0, 0.0, -25.0);
        let (f, _) = face.nearest(&q, f64::INFINITY).unwrap();
        assert!((f.point - P3::new(rim_r, 0.0, -h)).norm() < 1e-12, "{}", f.point);
    }

    /// A quarter-round fillet: the cylinder x² + y² = 25 for x, y ≥ 0, 0 ≤ z ≤ 50, and the
    /// matching quarter of a torus (major 20, minor 5) round the z axis.
    #[test]
    fn cylinder_and_torus_fillets_against_closed_forms() {
        let cyl = Carrier::Analytic(Analytic::Cylinder {
            point: P3::origin(),
            axis: V3::z(),
            radius: 5.0,
            from: 0.0,
            to: 50.0,
        });
        let arc = |z: f64, t0: f64, t1: f64| Curve::Arc {
            centre: P3::new(0.0, 0.0, z),
            x: V3::x(),
            y: V3::y(),
            radius: 5.0,
            t0,
            t1,
        };
        let (a, b) = (P3::new(5.0, 0.0, 0.0), P3::new(0.0, 5.0, 0.0));
        let l = vec![
            (arc(0.0, 0.0, PI / 2.0), true),
            (Curve::Line { a: b, b: b + V3::z() * 50.0 }, true),
            (arc(50.0, 0.0, PI / 2.0), false),
            (Curve::Line { a, b: a + V3::z() * 50.0 }, false),
        ];
        let face = Face::new(cyl, vec![l], true);
        for (x, y, z) in [(8.0, 6.0, 20.0), (1.0, 1.0, 3.0), (4.0, 30.0, 49.0)] {
            let q = P3::new(x, y, z);
            let (f, _) = face.nearest(&q, f64::INFINITY).unwrap();
            assert!(((f.point - q).norm() - (x.hypot(y) - 5.0).abs()).abs() < 1e-12, "{q}");
        }
        // Outside the quarter: the nearest straight edge.
        let q = P3::new(-3.0, 8.0, 10.0);
        let (f, _) = face.nearest(&q, f64::INFINITY).unwrap();
        assert!((f.point - P3::new(0.0, 5.0, 10.0)).norm() < 1e-12, "{}", f.point);

        let torus = Carrier::Analytic(Analytic::Torus { centre: P3::origin(), axis: V3::z(), major: 20.0, minor: 5.0 });
        let ring = |z: f64, r: f64| Curve::Arc {
            centre: P3::new(0.0, 0.0, z),
            x: V3::x(),
            y: V3::y(),
            radius: r,
            t0: 0.0,
            t1: TAU,
        };
        let seam =
            Curve::Arc { centre: P3::new(20.0, 0.0, 0.0), x: V3::x(), y: V3::z(), radius: 5.0, t0: 0.0, t1: PI / 2.0 };
        // The outer upper quarter of the tube: from the equator (ρ = 25) up to the top (z = 5).
        let l = vec![(ring(0.0, 25.0), true), (seam.clone(), true), (ring(5.0, 20.0), false), (seam, false)];
        let face = Face::new(torus, vec![l], true);
        for (x, y, z) in [(30.0, 4.0, 3.0), (-15.0, 18.0, 7.0), (0.0, -28.0, 0.5)] {
            let q = P3::new(x, y, z);
            let (f, _) = face.nearest(&q, f64::INFINITY).unwrap();
            let want = (x.hypot(y) - 20.0).hypot(z) - 5.0;
            assert!(((f.point - q).norm() - want).abs() < 1e-12, "{q}");
        }
        // Below the equator the rim circle ρ = 25, z = 0 is nearest.
        let q = P3::new(0.0, 30.0, -4.0);
        let (f, _) = face.nearest(&q, f64::INFINITY).unwrap();
        assert!((f.point - P3::new(0.0, 25.0, 0.0)).norm() < 1e-12, "{}", f.point);
    }

    /// The triangles of a plane with a hole cover its area less the hole's (the hole's polygon),
    /// face up; those of the dish lie on the sphere below the rim, within the chord.
    #[test]
    fn triangles_cover_the_face() {
        let plane = Carrier::Analytic(Analytic::Plane { point: P3::origin(), normal: V3::z() });
        let face = Face::new(plane, vec![square(50.0), vec![(circle(P3::origin(), 10.0), false)]], true);
        let (tris, dev) = face.triangles(1e-6).unwrap();
        let area: f64 = tris.iter().map(|t| 0.5 * (t[1] - t[0]).cross(&(t[2] - t[0])).z).sum();
        // The hole's polygon is inscribed within 3/4 of the chord of its circle: its area falls
        // short of the disc's by less than the perimeter times that.
        let hole = PI * 100.0;
        assert!(
            area > 1e4 - hole && area - (1e4 - hole) < TAU * 10.0 * 0.75e-6 && dev < 1e-9,
            "{area} vs {}",
            1e4 - hole
        );
        assert!(tris.iter().all(|t| (t[0] + t[1].coords + t[2].coords).coords.xy().norm() / 3.0 > 9.9));
        let (r, h) = (40.0f64, 30.0f64);
        let sphere = Carrier::Analytic(Analytic::Sphere { centre: P3::origin(), radius: r });
        let rim = circle(P3::new(0.0, 0.0, -h), (r * r - h * h).sqrt());
        let seam =
            Curve::Arc { centre: P3::origin(), x: V3::x(), y: -V3::z(), radius: r, t0: (h / r).asin(), t1: PI / 2.0 };
        let dish = Face::new(sphere, vec![vec![(rim, true), (seam.clone(), true), (seam, false)]], false);
        let (tris, dev) = dish.triangles(1e-3).unwrap();
        assert!(dev <= 1e-3 && tris.len() > 100, "{dev}");
        for t in &tris {
            for p in t {
                assert!((p.coords.norm() - r).abs() < 1e-9 && p.z <= -h + 1e-9, "{p}");
            }
            // Turned with the carrier's normal (outward from the centre).
            let c = (t[0].coords + t[1].coords + t[2].coords) / 3.0;
            assert!(
                (t[1] - t[0]).cross(&(t[2] - t[0])).dot(&c) > 0.0,
                "{t:?} {}",
                (t[1] - t[0]).cross(&(t[2] - t[0])).norm()
            );
        }
        // Together they cover the cap: 2πR(R − h) less the chord's shortfall.
        let area: f64 = tris.iter().map(|t| 0.5 * (t[1] - t[0]).cross(&(t[2] - t[0])).norm()).sum();
        let cap = TAU * r * (r - h);
        assert!(area < cap && area > cap * 0.999, "{area} vs {cap}");
    }

    #[test]
    fn spline_edge_nearest_converges() {
        // A quarter circle as a rational quadratic: the nearest point is radial.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let curve = SplineCurve {
            degree: 2,
            ctrl: vec![P3::new(10.0, 0.0, 0.0), P3::new(10.0, 10.0, 0.0), P3::new(0.0, 10.0, 0.0)],
            weights: Some(vec![1.0, h, 1.0]),
            knots: vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        };
        let edge = Curve::spline(curve, 0.0, 1.0);
        for (x, y, z) in [(20.0, 3.0, 1.0), (1.0, 2.0, -4.0), (7.0, 7.0, 0.0)] {
            let (p, ok) = edge.nearest(&P3::new(x, y, z));
            let e = V3::new(x, y, 0.0).normalize() * 10.0;
            assert!(ok && (p.coords - e).norm() < 1e-9, "{p}");
        }
        let (p, ok) = edge.nearest(&P3::new(5.0, -9.0, 0.0));
        assert!(ok && (p - P3::new(10.0, 0.0, 0.0)).norm() < 1e-12, "{p}");
    }

    /// A square face on the plane z = 0 with one edge lifted to z = h (and a spline edge, a
    /// quarter circle, left on it): its edges lie exactly h off the surface, at the lifted edge.
    #[test]
    fn edges_off_is_the_lifted_edges_height() {
        let plane = || Carrier::Analytic(Analytic::Plane { point: P3::origin(), normal: V3::z() });
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let quarter = SplineCurve {
            degree: 2,
            ctrl: vec![P3::new(10.0, 0.0, 0.0), P3::new(10.0, 10.0, 0.0), P3::new(0.0, 10.0, 0.0)],
            weights: Some(vec![1.0, h, 1.0]),
            knots: vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        };
        for lift in [0.0, 0.02, 3.5] {
            let a = P3::new(0.0, 10.0, lift);
            let edges = vec![
                (Curve::Line { a: P3::origin(), b: P3::new(10.0, 0.0, 0.0) }, true),
                (Curve::spline(quarter.clone(), 0.0, 1.0), true),
                (Curve::Line { a: P3::new(0.0, 10.0, 0.0), b: a }, true),
                (Curve::Line { a, b: P3::new(0.0, 0.0, lift) }, true),
            ];
            let (off, edge) = Face::new(plane(), vec![edges], true).edges_off();
            assert!((off - lift).abs() < 1e-15, "{off} vs {lift}");
            assert!(lift == 0.0 || edge >= 2, "{edge}");
        }
    }

    /// The point-only evaluation the nearest-point search samples with is the full evaluation's
    /// point to the bit (a rational cubic of three spans, at knots, inside spans and at the ends),
    /// so the search's samples and the outlines are what they were with the derivatives.
    #[test]
    fn spline_point_is_the_evaluations_point_to_the_bit() {
        let curve = SplineCurve {
            degree: 3,
            ctrl: (0..6).map(|i| P3::new(i as f64 * 3.1, (i as f64 * 1.7).sin() * 5.0, 0.3 * i as f64)).collect(),
            weights: Some(vec![1.0, 0.7, 1.3, 0.9, 1.1, 1.0]),
            knots: vec![0.0, 0.0, 0.0, 0.0, 0.4, 0.75, 1.0, 1.0, 1.0, 1.0],
        };
        for i in 0..=1000 {
            let t = i as f64 / 1000.0;
            assert_eq!(curve.point(t), curve.eval(t).0, "t = {t}");
        }
    }
}
