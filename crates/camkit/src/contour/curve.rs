//! Smooth curves of drawings (SVG Béziers, DXF ellipses and splines) as lines and arcs within a
//! proven tolerance: every curve is cut into rational Bézier pieces and each piece into biarcs.
//!
//! The bound: a piece is subdivided (de Casteljau) until each part's control polygon lies within
//! ε = tol/4 of its chord, so the part lies in that polygon's hull, within ε of the chord, and
//! every chord point is within ε of the part (its projection onto the chord covers the chord).
//! The chords are measured against the biarc with the exact segment-to-arc distances of
//! [`crate::geom::dist`]; `ε` plus their largest distance bounds the distance of every curve
//! point from the biarc. The other way, each arc is kept under a quarter turn and its radius over
//! twice the bound, so the nearest-point map from the curve onto the biarc is continuous and, the
//! ends being shared, onto: every biarc point is within the same bound of the curve.

use super::Seg;
use crate::geom::dist::segment_arc_max;
use crate::geom::{Arc2, P2, V2, arc::angle_between, cross2};
use std::f64::consts::FRAC_PI_2;

/// A rational Bézier piece: control points and their (positive) weights.
#[derive(Clone, Debug, PartialEq)]
pub struct Bezier {
    /// Control points (two or more).
    pub p: Vec<P2>,
    /// Weights, one per control point (all 1 for a polynomial piece).
    pub w: Vec<f64>,
}

/// An ellipse `c + u cos θ + v sin θ` (u, v conjugate semi-diameters; a circle when they are
/// perpendicular and of one length).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipse {
    /// Centre.
    pub c: P2,
    /// Point at θ = 0, from the centre.
    pub u: V2,
    /// Point at θ = π/2, from the centre.
    pub v: V2,
}

impl Bezier {
    /// A polynomial piece through `p` (weights 1).
    pub fn polynomial(p: Vec<P2>) -> Bezier {
        let w = vec![1.0; p.len()];
        Bezier { p, w }
    }

    /// The point at parameter `t` ∈ [0, 1] (de Casteljau in homogeneous coordinates).
    pub fn point(&self, t: f64) -> P2 {
        let mut h: Vec<(V2, f64)> = self.p.iter().zip(&self.w).map(|(p, w)| (p.coords * *w, *w)).collect();
        for k in 1..h.len() {
            for i in 0..h.len() - k {
                h[i] = (h[i].0 * (1.0 - t) + h[i + 1].0 * t, h[i].1 * (1.0 - t) + h[i + 1].1 * t);
            }
        }
        P2::from(h[0].0 / h[0].1)
    }

    /// The two halves at `t` (de Casteljau in homogeneous coordinates).
    pub fn split(&self, t: f64) -> (Bezier, Bezier) {
        let n = self.p.len();
        let mut h: Vec<(V2, f64)> = self.p.iter().zip(&self.w).map(|(p, w)| (p.coords * *w, *w)).collect();
        let (mut left, mut right) = (vec![h[0]], vec![h[n - 1]]);
        for k in 1..n {
            for i in 0..n - k {
                h[i] = (h[i].0 * (1.0 - t) + h[i + 1].0 * t, h[i].1 * (1.0 - t) + h[i + 1].1 * t);
            }
            left.push(h[0]);
            right.push(h[n - 1 - k]);
        }
        right.reverse();
        let back = |v: Vec<(V2, f64)>| Bezier {
            p: v.iter().map(|(q, w)| P2::from(q / *w)).collect(),
            w: v.iter().map(|(_, w)| *w).collect(),
        };
        (back(left), back(right))
    }

    /// Largest distance of a control point from the chord (first to last point).
    fn flatness(&self) -> f64 {
        let (a, b) = (self.p[0], self.p[self.p.len() - 1]);
        self.p.iter().map(|q| crate::geom::dist::point_segment(q, &a, &b)).fold(0.0, f64::max)
    }

    /// Unit tangent at the start (the first control point apart from the start), if any.
    fn start_tangent(&self) -> Option<V2> {
        self.p.iter().skip(1).find_map(|q| (q - self.p[0]).try_normalize(1e-12 * scale(&self.p)))
    }

    /// Unit tangent at the end.
    fn end_tangent(&self) -> Option<V2> {
        let last = self.p[self.p.len() - 1];
        self.p.iter().rev().skip(1).find_map(|q| (last - q).try_normalize(1e-12 * scale(&self.p)))
    }
}

/// The size of a point set (largest coordinate magnitude, at least 1), for relative epsilons.
fn scale(p: &[P2]) -> f64 {
    p.iter().map(|q| q.x.abs().max(q.y.abs())).fold(1.0, f64::max)
}

impl Ellipse {
    /// The point at angle `t`.
    pub fn point(&self, t: f64) -> P2 {
        self.c + self.u * t.cos() + self.v * t.sin()
    }

    /// The circle's radius if the ellipse is one (to 1e-12 relative), else `None`.
    pub fn radius(&self) -> Option<f64> {
        let (a, b) = (self.u.norm(), self.v.norm());
        let tight = 1e-12 * a.max(b);
        ((a - b).abs() <= tight && self.u.dot(&self.v).abs() <= tight * a.max(b)).then_some(0.5 * (a + b))
    }

    /// The arc from angle `t0` to `t1` (either way): one exact arc for a circle, otherwise
    /// rational quadratic Bézier pieces of at most a quarter turn each (exact conics).
    pub fn arc(&self, t0: f64, t1: f64) -> Result<Seg, Vec<Bezier>> {
        if let Some(r) = self.radius() {
            // In the (u, v) frame the angle runs counter-clockwise when (u, v) is.
            let turn = if cross2(&self.u, &self.v) > 0.0 { t1 - t0 } else { t0 - t1 };
            let start = crate::geom::arc::angle_of(&(self.point(t0) - self.c));
            return Ok(Seg::Arc(Arc2 { c: self.c, r, start, sweep: turn }));
        }
        let n = ((t1 - t0).abs() / FRAC_PI_2).ceil().max(1.0) as usize;
        let d = (t1 - t0) / n as f64;
        Err((0..n)
            .map(|k| {
                let (a, b) = (t0 + k as f64 * d, t0 + (k + 1) as f64 * d);
                let m = 0.5 * (a + b);
                let half = (0.5 * d).cos();
                let mid = self.c + (self.u * m.cos() + self.v * m.sin()) / half;
                Bezier { p: vec![self.point(a), mid, self.point(b)], w: vec![1.0, half, 1.0] }
            })
            .collect())
    }
}

/// The bulge `tan(sweep / 4)` of an arc, exactly ±1 for a half turn (so that a half circle read
/// from a drawing has the centre a table or a DXF bulge of 1 gives it).
pub fn bulge_of(sweep: f64) -> f64 {
    let b = (sweep / 4.0).tan();
    if (b.abs() - 1.0).abs() < 1e-12 { b.signum() } else { b }
}

/// A NURBS curve (`degree`, `knots`, control `points` and their `weights`) as rational Bézier
/// pieces, one per knot span of its domain [knots[degree], knots[n]] (n control points), by
/// inserting every knot of the domain until it has multiplicity `degree` (Boehm).
pub fn nurbs_beziers(degree: usize, knots: &[f64], points: &[P2], weights: &[f64]) -> Result<Vec<Bezier>, String> {
    let (p, n) = (degree, points.len());
    if p == 0 || n <= p {
        return Err(format!("degree {p} needs more than {p} control points, got {n}"));
    }
    if knots.len() != n + p + 1 {
        return Err(format!("{n} control points of degree {p} need {} knots, got {}", n + p + 1, knots.len()));
    }
    if weights.len() != n || weights.iter().any(|w| w.is_nan() || *w <= 0.0) {
        return Err(format!("needs {n} positive weights, got {:?}", weights));
    }
    if knots.windows(2).any(|w| w[1] < w[0]) || knots[p] >= knots[n] {
        return Err("knots must not decrease and the domain must not be empty".into());
    }
    let mut u = knots.to_vec();
    let mut h: Vec<(V2, f64)> = points.iter().zip(weights).map(|(q, w)| (q.coords * *w, *w)).collect();
    let (lo, hi) = (knots[p], knots[n]);
    let mut distinct: Vec<f64> = knots.iter().copied().filter(|k| *k >= lo && *k <= hi).collect();
    distinct.dedup();
    for &x in &distinct {
        while u.iter().filter(|k| **k == x).count() < p {
            // The span holding x: the last k with u[k] ≤ x (below the top of the domain).
            let k = u.iter().rposition(|kn| *kn <= x).unwrap_or(0).min(u.len() - p - 2);
            let mut q = Vec::with_capacity(h.len() + 1);
            for i in 0..=h.len() {
                q.push(if i + p <= k {
                    h[i]
                } else if i > k {
                    h[i - 1]
                } else {
                    let a = (x - u[i]) / (u[i + p] - u[i]);
                    (h[i - 1].0 * (1.0 - a) + h[i].0 * a, h[i - 1].1 * (1.0 - a) + h[i].1 * a)
                });
            }
            h = q;
            u.insert(k + 1, x);
        }
    }
    let mut out = Vec::new();
    for k in p..h.len() {
        if u[k] < u[k + 1] && u[k] >= lo && u[k + 1] <= hi {
            let part = &h[k - p..=k];
            out.push(Bezier {
                p: part.iter().map(|(q, w)| P2::from(q / *w)).collect(),
                w: part.iter().map(|(_, w)| *w).collect(),
            });
        }
    }
    Ok(out)
}

/// Why a curve could not be approximated.
#[derive(Clone, Debug, PartialEq)]
pub struct Unfit {
    /// Where the piece that would not fit starts.
    pub at: P2,
}

/// Lines and arcs within `tol` (mm) of the piece `b`, both ways, from its first to its last
/// point exactly; the largest proven deviation is folded into `worst`.
pub fn biarcs(b: &Bezier, tol: f64, worst: &mut f64) -> Result<Vec<Seg>, Unfit> {
    let mut out = Vec::new();
    fit(b, tol, 0, &mut out, worst)?;
    Ok(out)
}

/// Deepest halving of a piece before it is refused (2^-40 of its parameter range).
const MAX_DEPTH: u32 = 40;

fn fit(b: &Bezier, tol: f64, depth: u32, out: &mut Vec<Seg>, worst: &mut f64) -> Result<(), Unfit> {
    let (p0, p1) = (b.p[0], b.p[b.p.len() - 1]);
    if (p1 - p0).norm() <= crate::tol::POINT_EPS && b.flatness() <= crate::tol::POINT_EPS {
        return Ok(());
    }
    if b.flatness() <= tol {
        // Within tol of its chord (the hull argument above): a line, both ways.
        *worst = worst.max(b.flatness());
        out.push(Seg::Line(p0, p1));
        return Ok(());
    }
    if let (Some(t0), Some(t1)) = (b.start_tangent(), b.end_tangent())
        && let Some(pair) = biarc(p0, t0, p1, t1)
        && let Some(dev) = deviation(b, &pair, tol)
    {
        *worst = worst.max(dev);
        out.extend(pair.into_iter().filter(|s| s.length() > crate::tol::POINT_EPS));
        return Ok(());
    }
    if depth >= MAX_DEPTH {
        return Err(Unfit { at: p0 });
    }
    let (l, r) = b.split(0.5);
    fit(&l, tol, depth + 1, out, worst)?;
    fit(&r, tol, depth + 1, out, worst)
}

/// The equal-tangent-length biarc from `p0` leaving along `t0` to `p1` arriving along `t1`.
fn biarc(p0: P2, t0: V2, p1: P2, t1: V2) -> Option<[Seg; 2]> {
    let v = p1 - p0;
    let t = t0 + t1;
    let denom = 2.0 * (1.0 - t0.dot(&t1));
    let d = if denom.abs() < 1e-12 {
        let vt = v.dot(&t1);
        if vt.abs() < 1e-12 * v.norm() {
            return None;
        }
        v.norm_squared() / (4.0 * vt)
    } else {
        let vt = v.dot(&t);
        (-vt + (vt * vt + denom * v.norm_squared()).sqrt()) / denom
    };
    if !(d.is_finite() && d > 0.0) {
        return None;
    }
    let j = P2::from((p0.coords + t0 * d + p1.coords - t1 * d) * 0.5);
    // Chord and tangent make half the sweep at either end of an arc.
    let first = 2.0 * angle_between(&t0, &(j - p0));
    let second = 2.0 * angle_between(&(p1 - j), &t1);
    Some([Seg::from_bulge(p0, j, (first / 4.0).tan()), Seg::from_bulge(j, p1, (second / 4.0).tan())])
}

/// A proven bound on the distance between the piece and the biarc (both ways), or `None` when
/// it is over `tol` or the biarc breaks the conditions of the bound (an arc over a quarter turn,
/// or of radius under twice the bound).
fn deviation(b: &Bezier, pair: &[Seg; 2], tol: f64) -> Option<f64> {
    let eps = 0.25 * tol;
    for s in pair {
        if let Seg::Arc(a) = s
            && a.sweep.abs() > FRAC_PI_2
        {
            return None;
        }
    }
    let mut chords = Vec::new();
    flat_chords(b, eps, 0, &mut chords)?;
    let joint = pair[0].end();
    let mut far = 0.0f64;
    for (a, c) in chords {
        let whole = seg_max(&a, &c, &pair[0]).min(seg_max(&a, &c, &pair[1]));
        let d = if whole <= tol - eps {
            whole
        } else {
            // A chord across the joint: split where the joint projects onto it.
            let dir = c - a;
            let t = ((joint - a).dot(&dir) / dir.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
            let s = a + dir * t;
            whole.min(seg_max(&a, &s, &pair[0]).max(seg_max(&s, &c, &pair[1])))
        };
        far = far.max(d);
        if eps + far > tol {
            return None;
        }
    }
    let bound = eps + far;
    for s in pair {
        if let Seg::Arc(a) = s
            && a.r <= 2.0 * bound
        {
            return None;
        }
    }
    Some(bound)
}

/// Largest distance from the segment `a`–`b` to the piece `s`, exactly.
fn seg_max(a: &P2, b: &P2, s: &Seg) -> f64 {
    match s {
        Seg::Line(p, q) => crate::geom::dist::point_segment(a, p, q).max(crate::geom::dist::point_segment(b, p, q)),
        Seg::Arc(arc) => segment_arc_max(a, b, arc),
    }
}

/// The chords of parts of `b` each within `eps` of its part (control polygon within `eps` of the
/// chord); `None` if that takes too many halvings.
fn flat_chords(b: &Bezier, eps: f64, depth: u32, out: &mut Vec<(P2, P2)>) -> Option<()> {
    if b.flatness() <= eps {
        out.push((b.p[0], b.p[b.p.len() - 1]));
        return Some(());
    }
    if depth >= MAX_DEPTH {
        return None;
    }
    let (l, r) = b.split(0.5);
    flat_chords(&l, eps, depth + 1, out)?;
    flat_chords(&r, eps, depth + 1, out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::Contour;

    /// Dense two-way distance between a curve (sampled at `n` parameters) and the pieces, by
    /// exact point-to-piece distances and the pieces sampled against the curve's polyline.
    fn measured(curve: impl Fn(f64) -> P2, segs: &[Seg], n: usize) -> f64 {
        let (there, back) = both_ways(curve, segs, n);
        there.max(back)
    }

    /// Largest distance of the curve's samples from the pieces (exact per sample), and of the
    /// pieces' samples from the curve's polyline.
    fn both_ways(curve: impl Fn(f64) -> P2, segs: &[Seg], n: usize) -> (f64, f64) {
        let pts: Vec<P2> = (0..=n).map(|k| curve(k as f64 / n as f64)).collect();
        let to_segs = pts.iter().map(|p| segs.iter().map(|s| s.distance_to(p)).fold(f64::MAX, f64::min));
        let there = to_segs.fold(0.0, f64::max);
        let mut back = 0.0f64;
        for s in segs {
            for k in 0..=50 {
                let q = s.point_at(k as f64 / 50.0);
                back = back.max(crate::geom::dist::point_polyline(&q, &pts));
            }
        }
        (there, back)
    }

    fn chained(segs: &[Seg], from: P2, to: P2) {
        assert!((segs[0].start() - from).norm() < 1e-12);
        assert!((segs[segs.len() - 1].end() - to).norm() < 1e-12);
        for w in segs.windows(2) {
            assert!((w[0].end() - w[1].start()).norm() < 1e-9, "{w:?}");
        }
    }

    #[test]
    fn cubic_within_tolerance_of_the_exact_curve() {
        let b =
            Bezier::polynomial(vec![P2::new(0.0, 0.0), P2::new(10.0, 25.0), P2::new(30.0, -15.0), P2::new(40.0, 10.0)]);
        for tol in [1e-2, 1e-3, 1e-6] {
            let mut worst = 0.0;
            let segs = biarcs(&b, tol, &mut worst).unwrap();
            chained(&segs, b.p[0], b.p[3]);
            assert!(worst <= tol, "{worst}");
            // The exact curve sampled at 20 000 parameters: its polyline is within 1e-6 mm of it
            // (chord sagitta at these curvatures), so measured ≤ tol + that.
            let m = measured(|t| b.point(t), &segs, 20_000);
            assert!(m <= tol + 1e-6, "tol {tol}: measured {m}, {} pieces", segs.len());
            // The proven bound is no smaller than what is measured.
            assert!(worst + 1e-6 >= m, "bound {worst} < measured {m}");
        }
    }

    #[test]
    fn ellipse_arcs_are_exact_conics_and_fit_within_tolerance() {
        let e = Ellipse { c: P2::new(3.0, -1.0), u: V2::new(20.0, 5.0), v: V2::new(-1.25, 5.0) };
        let (t0, t1) = (0.3, 5.1);
        let pieces = e.arc(t0, t1).unwrap_err();
        // Each rational quadratic piece lies on the ellipse (exact conic).
        let inv = nalgebra::Matrix2::from_columns(&[e.u, e.v]).try_inverse().unwrap();
        for p in &pieces {
            for k in 0..=20 {
                let q = inv * (p.point(k as f64 / 20.0) - e.c);
                assert!((q.norm() - 1.0).abs() < 1e-12, "{}", q.norm());
            }
        }
        let tol = 1e-6;
        let mut worst = 0.0;
        let segs: Vec<Seg> = pieces.iter().flat_map(|p| biarcs(p, tol, &mut worst).unwrap()).collect();
        chained(&segs, e.point(t0), e.point(t1));
        let m = measured(|s| e.point(t0 + s * (t1 - t0)), &segs, 40_000);
        assert!(worst <= tol && m <= tol + 1e-6, "bound {worst}, measured {m}, {} pieces", segs.len());
    }

    #[test]
    fn circles_stay_exact_arcs() {
        let e = Ellipse { c: P2::new(1.0, 2.0), u: V2::new(0.0, 5.0), v: V2::new(-5.0, 0.0) };
        let Ok(Seg::Arc(a)) = e.arc(0.0, std::f64::consts::PI) else { panic!("not an arc") };
        assert_eq!((a.c, a.r), (P2::new(1.0, 2.0), 5.0));
        assert!((a.sweep - std::f64::consts::PI).abs() < 1e-15 && (a.start - FRAC_PI_2).abs() < 1e-15);
        let c = Contour::from_segs(&[Seg::Arc(a), Seg::Arc(Arc2 { start: a.start + a.sweep, ..a })], true);
        assert!((c.area() - 25.0 * std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(bulge_of(-std::f64::consts::PI), -1.0);
    }

    #[test]
    fn straight_cubics_are_lines() {
        let b = Bezier::polynomial(vec![P2::new(0.0, 0.0), P2::new(1.0, 1.0), P2::new(2.0, 2.0), P2::new(3.0, 3.0)]);
        let mut worst = 0.0;
        let segs = biarcs(&b, 1e-6, &mut worst).unwrap();
        assert_eq!(segs, vec![Seg::Line(b.p[0], b.p[3])]);
    }

    /// A NURBS point by the Cox–de Boor basis functions (independent of the knot insertion).
    fn nurbs_point(p: usize, u: &[f64], pts: &[P2], w: &[f64], x: f64) -> P2 {
        let n = pts.len();
        let mut basis: Vec<f64> = (0..u.len() - 1)
            .map(|i| if u[i] <= x && x < u[i + 1] || (x == u[n] && u[i] < x && x <= u[i + 1]) { 1.0 } else { 0.0 })
            .collect();
        for d in 1..=p {
            for i in 0..u.len() - 1 - d {
                let a = if u[i + d] > u[i] { (x - u[i]) / (u[i + d] - u[i]) * basis[i] } else { 0.0 };
                let b = if u[i + d + 1] > u[i + 1] {
                    (u[i + d + 1] - x) / (u[i + d + 1] - u[i + 1]) * basis[i + 1]
                } else {
                    0.0
                };
                basis[i] = a + b;
            }
        }
        let (mut s, mut ws) = (V2::zeros(), 0.0);
        for i in 0..n {
            s += pts[i].coords * (w[i] * basis[i]);
            ws += w[i] * basis[i];
        }
        P2::from(s / ws)
    }

    #[test]
    fn nurbs_pieces_are_the_curve_and_fit_within_tolerance() {
        let pts: Vec<P2> =
            [(0.0, 0.0), (10.0, 20.0), (25.0, -5.0), (40.0, 15.0), (50.0, 0.0), (45.0, -20.0), (20.0, -25.0)]
                .iter()
                .map(|&(x, y)| P2::new(x, y))
                .collect();
        let w = [1.0, 0.7, 1.5, 1.0, 2.0, 0.8, 1.0];
        // Clamped cubic with a double interior knot, and an unclamped quadratic.
        for (p, u) in [
            (3usize, vec![0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 3.0, 3.0, 3.0, 3.0]),
            (2, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]),
        ] {
            let pieces = nurbs_beziers(p, &u, &pts, &w).unwrap();
            let (lo, hi) = (u[p], u[pts.len()]);
            let spans: Vec<(f64, f64)> =
                u.windows(2).filter(|s| s[0] < s[1] && s[0] >= lo && s[1] <= hi).map(|s| (s[0], s[1])).collect();
            assert_eq!(pieces.len(), spans.len());
            for (b, (a, c)) in pieces.iter().zip(&spans) {
                for k in 0..=10 {
                    let t = k as f64 / 10.0;
                    let exact = nurbs_point(p, &u, &pts, &w, a + t * (c - a));
                    assert!((b.point(t) - exact).norm() < 1e-9, "degree {p}: {:?} vs {exact:?}", b.point(t));
                }
            }
            let tol = 1e-3;
            let mut worst = 0.0;
            let segs: Vec<Seg> = pieces.iter().flat_map(|b| biarcs(b, tol, &mut worst).unwrap()).collect();
            chained(&segs, pieces[0].p[0], *pieces.last().unwrap().p.last().unwrap());
            let m = measured(|s| nurbs_point(p, &u, &pts, &w, (lo + s * (hi - lo)).min(hi)), &segs, 40_000);
            assert!(worst <= tol && m <= tol + 1e-5, "bound {worst}, measured {m}");
        }
        assert!(nurbs_beziers(3, &[0.0; 5], &pts, &w).is_err());
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]

        /// Any cubic (also with loops and cusps nearby) fits within the tolerance, measured densely.
        #[test]
        fn random_cubics_fit(c in proptest::collection::vec(-20.0f64..20.0, 8), tol in 1e-5f64..1e-2) {
            let b = Bezier::polynomial(c.chunks(2).map(|q| P2::new(q[0], q[1])).collect());
            let mut worst = 0.0;
            if let Ok(segs) = biarcs(&b, tol, &mut worst) {
                proptest::prop_assert!(worst <= tol);
                if !segs.is_empty() {
                    let (there, _) = both_ways(|t| b.point(t), &segs, 20_000);
                    proptest::prop_assert!(there <= tol * (1.0 + 1e-9), "measured {} tol {}", there, tol);
                }
            }
        }
    }
}
