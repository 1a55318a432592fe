//! Circles from points: the circle through three points, and the least-squares circle through
//! two fixed end points (the family of centres on their perpendicular bisector).

use super::{P2, V2, cross2};
use crate::tol;

/// Centre of the circle through three points, or `None` if they are (nearly) collinear.
pub fn circumcentre(a: &P2, b: &P2, c: &P2) -> Option<P2> {
    let ab = b - a;
    let ac = c - a;
    let d = 2.0 * cross2(&ab, &ac);
    let scale = ab.norm_squared().max(ac.norm_squared());
    if d.abs() <= tol::ANGLE_EPS * scale || scale == 0.0 {
        return None;
    }
    let (ab2, ac2) = (ab.norm_squared(), ac.norm_squared());
    let ux = (ac.y * ab2 - ab.y * ac2) / d;
    let uy = (ab.x * ac2 - ac.x * ab2) / d;
    Some(a + V2::new(ux, uy))
}

/// Signed curvature (1/mm, positive turning left) of the circle through three consecutive
/// points; zero when they are collinear.
pub fn curvature(a: &P2, b: &P2, c: &P2) -> f64 {
    let ab = b - a;
    let bc = c - b;
    let ca = a - c;
    let denom = ab.norm() * bc.norm() * ca.norm();
    if denom <= tol::LENGTH_EPS {
        return 0.0;
    }
    2.0 * cross2(&ab, &bc) / denom
}

/// A circle through the two end points `a`, `b` of a run, fitted to the points between.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChordCircle {
    /// Centre.
    pub c: P2,
    /// Radius.
    pub r: f64,
}

/// Least-squares circle through `a` and `b` fitted to `inner` (the points between them).
///
/// Centres through both ends lie on the perpendicular bisector, `c(s) = m + s·n`; the algebraic
/// residual `|p−c|² − |a−c|²` is linear in `s`, so the least-squares `s` has a closed form. The
/// algebraic residual is about `2r` times the geometric one, so equal weights fit geometry.
/// `None` when all points lie on the chord's line (no circle) or `a == b`.
pub fn fit_through_ends<'a>(a: &P2, b: &P2, inner: impl IntoIterator<Item = &'a P2>) -> Option<ChordCircle> {
    let chord = b - a;
    let len = chord.norm();
    if len <= tol::LENGTH_EPS {
        return None;
    }
    let m = P2::from((a.coords + b.coords) * 0.5);
    let n = V2::new(-chord.y, chord.x) / len;
    let h2 = 0.25 * len * len;
    let (mut sab, mut sbb) = (0.0, 0.0);
    for p in inner {
        let d = p - m;
        let av = d.norm_squared() - h2;
        let bv = n.dot(&d);
        sab += av * bv;
        sbb += bv * bv;
    }
    if sbb <= tol::LENGTH_EPS * tol::LENGTH_EPS * h2.max(1.0) {
        return None;
    }
    let s = sab / (2.0 * sbb);
    let c = m + s * n;
    Some(ChordCircle { c, r: (h2 + s * s).sqrt() })
}

/// The circle through `a` and `b` whose tangent at `a` is `t` (unit); `None` if `b` lies on the
/// tangent line.
pub fn tangent_through(a: &P2, t: &V2, b: &P2) -> Option<ChordCircle> {
    let n = V2::new(-t.y, t.x);
    let d = b - a;
    let dn = n.dot(&d);
    if dn.abs() <= tol::LENGTH_EPS * d.norm().max(1.0) {
        return None;
    }
    let s = d.norm_squared() / (2.0 * dn);
    Some(ChordCircle { c: a + s * n, r: s.abs() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circumcentre_of_right_triangle() {
        let c = circumcentre(&P2::new(0.0, 0.0), &P2::new(2.0, 0.0), &P2::new(0.0, 2.0)).unwrap();
        assert!((c - P2::new(1.0, 1.0)).norm() < 1e-15);
        assert!(circumcentre(&P2::new(0.0, 0.0), &P2::new(1.0, 0.0), &P2::new(2.0, 0.0)).is_none());
    }

    #[test]
    fn curvature_sign_and_size() {
        let k = curvature(&P2::new(1.0, 0.0), &P2::new(0.0, 1.0), &P2::new(-1.0, 0.0));
        assert!((k - 1.0).abs() < 1e-15);
        let k = curvature(&P2::new(-1.0, 0.0), &P2::new(0.0, 1.0), &P2::new(1.0, 0.0));
        assert!((k + 1.0).abs() < 1e-15);
    }

    #[test]
    fn exact_arc_samples_give_exact_circle() {
        let (c, r) = (P2::new(3.0, -2.0), 7.5);
        let pts: Vec<P2> = (0..=20)
            .map(|i| {
                let phi = 0.3 + 1.7 * i as f64 / 20.0;
                c + r * V2::new(phi.cos(), phi.sin())
            })
            .collect();
        let fit = fit_through_ends(&pts[0], &pts[20], &pts[1..20]).unwrap();
        assert!((fit.c - c).norm() < 1e-12);
        assert!((fit.r - r).abs() < 1e-12);
        let t = V2::new(-(0.3f64).sin(), 0.3f64.cos());
        let tan = tangent_through(&pts[0], &t, &pts[20]).unwrap();
        assert!((tan.c - c).norm() < 1e-12);
    }

    #[test]
    fn collinear_points_have_no_circle() {
        let pts = [P2::new(1.0, 1.0), P2::new(2.0, 2.0)];
        assert!(fit_through_ends(&P2::new(0.0, 0.0), &P2::new(3.0, 3.0), &pts).is_none());
    }
}
