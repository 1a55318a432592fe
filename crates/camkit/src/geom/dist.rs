//! Exact distances between points, segments and arcs. These are the measuring instruments of
//! every tolerance the toolkit promises, so each is closed-form, never sampled.

use super::{Arc2, P2, P3, V2, arc::angle_of, cross2};
use nalgebra::{Const, OPoint};

/// Distance from `p` to the segment `[a, b]`, in any dimension.
pub fn point_segment<const D: usize>(
    p: &OPoint<f64, Const<D>>,
    a: &OPoint<f64, Const<D>>,
    b: &OPoint<f64, Const<D>>,
) -> f64 {
    let d = b - a;
    let len2 = d.norm_squared();
    let ap = p - a;
    if len2 == 0.0 {
        return ap.norm();
    }
    let t = (ap.dot(&d) / len2).clamp(0.0, 1.0);
    (ap - d * t).norm()
}

/// Distance from `p` to the closest point of `arc`.
pub fn point_arc(p: &P2, arc: &Arc2) -> f64 {
    let v = p - arc.c;
    let rho = v.norm();
    if rho == 0.0 || arc.spans(angle_of(&v)) {
        (rho - arc.r).abs()
    } else {
        (p - arc.start_point()).norm().min((p - arc.end_point()).norm())
    }
}

/// Largest distance from a point of the segment `[a, b]` to the arc (the one-sided Hausdorff
/// distance from the segment to the arc), exactly.
///
/// The segment is cut where it crosses the rays through the arc's ends; on a piece facing the
/// arc the distance is `| |q−c| − r |`, whose maximum lies at the piece's ends or at the foot of
/// the perpendicular from the centre; on a piece beside the arc it is the distance to the nearer
/// arc end, whose maximum lies at the piece's ends or on the bisector of the two arc ends.
pub fn segment_arc_max(a: &P2, b: &P2, arc: &Arc2) -> f64 {
    let d = b - a;
    let e0 = arc.start_point();
    let e1 = arc.end_point();
    let mut cuts = [0.0, 1.0, 1.0, 1.0];
    let mut n = 1;
    if arc.sweep.abs() < std::f64::consts::TAU {
        for e in [&e0, &e1] {
            let u = e - arc.c;
            let den = cross2(&d, &u);
            if den != 0.0 {
                let ca = arc.c - a;
                let t = cross2(&ca, &u) / den;
                let lambda = cross2(&ca, &d) / den;
                if t > 0.0 && t < 1.0 && lambda > 0.0 {
                    cuts[n] = t;
                    n += 1;
                }
            }
        }
    }
    cuts[n] = 1.0;
    n += 1;
    let cuts = &mut cuts[..n];
    cuts.sort_by(f64::total_cmp);
    let at = |t: f64| a + d * t;
    let mut worst: f64 = 0.0;
    for w in cuts.windows(2) {
        let (t0, t1) = (w[0], w[1]);
        let mid = at(0.5 * (t0 + t1));
        let facing = (mid - arc.c).norm() == 0.0 || arc.spans(angle_of(&(mid - arc.c)));
        if facing {
            let radial = |q: P2| ((q - arc.c).norm() - arc.r).abs();
            worst = worst.max(radial(at(t0))).max(radial(at(t1)));
            let len2 = d.norm_squared();
            if len2 > 0.0 {
                let tf = ((arc.c - a).dot(&d) / len2).clamp(t0, t1);
                worst = worst.max(radial(at(tf)));
            }
        } else {
            let ends = |q: P2| (q - e0).norm().min((q - e1).norm());
            worst = worst.max(ends(at(t0))).max(ends(at(t1)));
            // Crossing of the bisector of e0, e1: (q − m)·(e1 − e0) = 0.
            let m = P2::from((e0.coords + e1.coords) * 0.5);
            let g = e1 - e0;
            let den = d.dot(&g);
            if den != 0.0 {
                let t = (m - a).dot(&g) / den;
                if t > t0 && t < t1 {
                    worst = worst.max(ends(at(t)));
                }
            }
        }
    }
    worst
}

/// Distance from `p` to a polyline (the minimum over its segments); a single point is a polyline.
pub fn point_polyline<const D: usize>(p: &OPoint<f64, Const<D>>, line: &[OPoint<f64, Const<D>>]) -> f64 {
    match line {
        [] => f64::INFINITY,
        [q] => (p - q).norm(),
        _ => line.windows(2).map(|w| point_segment(p, &w[0], &w[1])).fold(f64::INFINITY, f64::min),
    }
}

/// Distance from a point to the infinite line through `a` with unit direction `u` (3D).
pub fn point_line3(p: &P3, a: &P3, u: &nalgebra::Vector3<f64>) -> f64 {
    let ap = p - a;
    (ap - u * ap.dot(u)).norm()
}

/// Unit vector of `v`, or `None` if it has no length.
pub fn unit2(v: &V2) -> Option<V2> {
    let n = v.norm();
    (n > 0.0).then(|| v / n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    fn quarter() -> Arc2 {
        Arc2::from_centre(P2::origin(), &P2::new(1.0, 0.0), &P2::new(0.0, 1.0), true, false)
    }

    #[test]
    fn point_distances() {
        let a = quarter();
        assert!((point_arc(&P2::new(2.0, 2.0), &a) - (8f64.sqrt() - 1.0)).abs() < 1e-15);
        assert!((point_arc(&P2::new(1.0, -1.0), &a) - 1.0).abs() < 1e-15);
        assert!((point_arc(&P2::origin(), &a) - 1.0).abs() < 1e-15);
        let d = point_segment(&P3::new(0.0, 1.0, 0.0), &P3::new(-1.0, 0.0, 0.0), &P3::new(1.0, 0.0, 0.0));
        assert!((d - 1.0).abs() < 1e-15);
    }

    #[test]
    fn chord_sagitta() {
        let a = quarter();
        let worst = segment_arc_max(&P2::new(1.0, 0.0), &P2::new(0.0, 1.0), &a);
        assert!((worst - (1.0 - 0.5f64.sqrt())).abs() < 1e-15);
    }

    /// Brute force: dense samples of the segment against a dense polyline of the arc.
    fn brute(a: &P2, b: &P2, arc: &Arc2) -> f64 {
        let arc_pts: Vec<P2> = (0..=4000).map(|i| arc.point_at_fraction(i as f64 / 4000.0)).collect();
        (0..=400)
            .map(|i| {
                let q = a + (b - a) * (i as f64 / 400.0);
                point_polyline(&q, &arc_pts)
            })
            .fold(0.0, f64::max)
    }

    proptest! {
        #[test]
        fn segment_arc_max_matches_brute_force(
            ax in -3.0..3.0f64, ay in -3.0..3.0f64, bx in -3.0..3.0f64, by in -3.0..3.0f64,
            start in -PI..PI, sweep in -6.0..6.0f64, r in 0.5..2.0f64,
        ) {
            prop_assume!(sweep.abs() > 0.05);
            let arc = Arc2 { c: P2::origin(), r, start, sweep };
            let (a, b) = (P2::new(ax, ay), P2::new(bx, by));
            let exact = segment_arc_max(&a, &b, &arc);
            let sampled = brute(&a, &b, &arc);
            // Sampling only underestimates the maximum; the polyline of the arc overestimates
            // distance by at most its sagitta (< 1e-6 here).
            prop_assert!(sampled <= exact + 1e-6, "sampled {sampled} > exact {exact}");
            prop_assert!(exact - sampled < 0.02 * (b - a).norm() + 1e-6, "exact {exact} sampled {sampled}");
        }
    }
}
