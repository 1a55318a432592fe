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

/// Angles at which the circle `(c, r)` meets the infinite line through `p` with direction `u`
/// (any length): none, one (tangent) or two.
fn circle_line_angles(c: &P2, r: f64, p: &P2, u: &V2) -> ([f64; 2], usize) {
    let len = u.norm();
    if len == 0.0 {
        return ([0.0; 2], 0);
    }
    let u = u / len;
    let n = V2::new(-u.y, u.x);
    // Signed distance of the centre from the line, and the foot of the centre on it.
    let h = n.dot(&(c - p));
    if h.abs() > r {
        return ([0.0; 2], 0);
    }
    let foot = c - n * h;
    let half = (r * r - h * h).max(0.0).sqrt();
    let a = angle_of(&(foot + u * half - c));
    let b = angle_of(&(foot - u * half - c));
    ([a, b], if half == 0.0 { 1 } else { 2 })
}

/// Largest distance from a point of `arc` to the segment `[a, b]` (one-sided Hausdorff distance
/// from the arc to the segment), exactly: the distance along the arc is smooth between the
/// angles where the arc crosses the perpendiculars at `a` and `b`, and on each piece its
/// extremes lie where the arc is parallel to the segment or points at `a` or `b`.
pub fn arc_segment_max(arc: &Arc2, a: &P2, b: &P2) -> f64 {
    let d = b - a;
    let mut angles: Vec<f64> = vec![arc.start, arc.start + arc.sweep];
    if d.norm_squared() > 0.0 {
        let n = V2::new(-d.y, d.x);
        angles.push(angle_of(&n));
        angles.push(angle_of(&-n));
        for e in [a, b] {
            let (hits, k) = circle_line_angles(&arc.c, arc.r, e, &n);
            angles.extend_from_slice(&hits[..k]);
        }
    }
    for e in [a, b] {
        if (e - arc.c).norm_squared() > 0.0 {
            angles.push(angle_of(&(e - arc.c)));
            angles.push(angle_of(&(arc.c - e)));
        }
    }
    angles
        .into_iter()
        .filter(|&phi| arc.spans(phi) || phi == arc.start + arc.sweep)
        .map(|phi| point_segment(&arc.point_at(phi), a, b))
        .fold(0.0, f64::max)
}

/// Largest distance from a point of arc `from` to arc `to` (one-sided Hausdorff distance),
/// exactly: candidates are the ends of `from`, its crossings of the rays through the ends of
/// `to` and of the bisector of those ends, and the stationary points of the distance to the
/// centre and to each end of `to`.
pub fn arc_arc_max(from: &Arc2, to: &Arc2) -> f64 {
    let e0 = to.start_point();
    let e1 = to.end_point();
    let mut angles: Vec<f64> = vec![from.start, from.start + from.sweep];
    let dc = to.c - from.c;
    if dc.norm_squared() > 0.0 {
        angles.push(angle_of(&dc));
        angles.push(angle_of(&-dc));
    }
    for e in [&e0, &e1] {
        let v = e - from.c;
        if v.norm_squared() > 0.0 {
            angles.push(angle_of(&v));
            angles.push(angle_of(&-v));
        }
        let (hits, k) = circle_line_angles(&from.c, from.r, &to.c, &(e - to.c));
        angles.extend_from_slice(&hits[..k]);
    }
    let g = e1 - e0;
    if g.norm_squared() > 0.0 {
        let m = P2::from((e0.coords + e1.coords) * 0.5);
        let (hits, k) = circle_line_angles(&from.c, from.r, &m, &V2::new(-g.y, g.x));
        angles.extend_from_slice(&hits[..k]);
    }
    angles
        .into_iter()
        .filter(|&phi| from.spans(phi) || phi == from.start + from.sweep)
        .map(|phi| point_arc(&from.point_at(phi), to))
        .fold(0.0, f64::max)
}

/// Smallest distance between the segments `[a, b]` and `[c, d]` (0 if they meet).
pub fn segment_segment_min(a: &P2, b: &P2, c: &P2, d: &P2) -> f64 {
    if segments_meet(a, b, c, d) {
        return 0.0;
    }
    point_segment(a, c, d).min(point_segment(b, c, d)).min(point_segment(c, a, b)).min(point_segment(d, a, b))
}

/// True if the segments `[a, b]` and `[c, d]` share a point, decided exactly for the given
/// coordinates by adaptive orientation predicates (Shewchuk's, the `robust` crate): for nearly
/// parallel segments the floating crossing parameters are noise, which made two consecutive
/// pieces of a straight run, a few nanometres apart, "meet".
pub fn segments_meet(a: &P2, b: &P2, c: &P2, d: &P2) -> bool {
    // Boxes apart (exact comparisons): the usual case, decided without the predicates.
    if a.x.max(b.x) < c.x.min(d.x)
        || c.x.max(d.x) < a.x.min(b.x)
        || a.y.max(b.y) < c.y.min(d.y)
        || c.y.max(d.y) < a.y.min(b.y)
    {
        return false;
    }
    let at = |p: &P2| robust::Coord { x: p.x, y: p.y };
    let orient = |p: &P2, q: &P2, r: &P2| robust::orient2d(at(p), at(q), at(r));
    let (d1, d2, d3, d4) = (orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b));
    let apart = |x: f64, y: f64| (x > 0.0 && y < 0.0) || (x < 0.0 && y > 0.0);
    if apart(d1, d2) && apart(d3, d4) {
        return true;
    }
    // A point on the other segment's line meets it where it lies within that segment's box.
    let within = |p: &P2, q: &P2, r: &P2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    (d1 == 0.0 && within(a, b, c))
        || (d2 == 0.0 && within(a, b, d))
        || (d3 == 0.0 && within(c, d, a))
        || (d4 == 0.0 && within(c, d, b))
}

/// Smallest distance between the segment `[a, b]` and `arc` (0 if they meet): crossings, the
/// ends of each against the other, and the arc points where the arc is parallel to the segment.
pub fn segment_arc_min(a: &P2, b: &P2, arc: &Arc2) -> f64 {
    let d = b - a;
    let len2 = d.norm_squared();
    if len2 > 0.0 {
        let (hits, k) = circle_line_angles(&arc.c, arc.r, a, &d);
        for &phi in &hits[..k] {
            let t = (arc.point_at(phi) - a).dot(&d) / len2;
            if (0.0..=1.0).contains(&t) && arc.spans(phi) {
                return 0.0;
            }
        }
    }
    let mut best = point_arc(a, arc).min(point_arc(b, arc));
    best = best.min(point_segment(&arc.start_point(), a, b)).min(point_segment(&arc.end_point(), a, b));
    if len2 > 0.0 {
        let n = V2::new(-d.y, d.x);
        for phi in [angle_of(&n), angle_of(&-n)] {
            if arc.spans(phi) {
                best = best.min(point_segment(&arc.point_at(phi), a, b));
            }
        }
    }
    best
}

/// Smallest distance between two arcs (0 if they meet): crossings, the ends of each against the
/// other, and the pairs of points on the line through both centres.
pub fn arc_arc_min(p: &Arc2, q: &Arc2) -> f64 {
    let dc = q.c - p.c;
    let dist = dc.norm();
    if dist > 0.0 {
        // Circle-circle crossings.
        let a = (p.r * p.r - q.r * q.r + dist * dist) / (2.0 * dist);
        let h2 = p.r * p.r - a * a;
        if h2 >= 0.0 {
            let u = dc / dist;
            let n = V2::new(-u.y, u.x);
            let base = p.c + u * a;
            let h = h2.sqrt();
            for x in [base + n * h, base - n * h] {
                if p.spans(angle_of(&(x - p.c))) && q.spans(angle_of(&(x - q.c))) {
                    return 0.0;
                }
            }
        }
    }
    let mut best = point_arc(&p.start_point(), q).min(point_arc(&p.end_point(), q));
    best = best.min(point_arc(&q.start_point(), p)).min(point_arc(&q.end_point(), p));
    if dist > 0.0 {
        let u = dc / dist;
        for sp in [1.0, -1.0] {
            let phi = angle_of(&(u * sp));
            if !p.spans(phi) {
                continue;
            }
            for sq in [1.0, -1.0] {
                let psi = angle_of(&(u * sq));
                if q.spans(psi) {
                    best = best.min((p.point_at(phi) - q.point_at(psi)).norm());
                }
            }
        }
    } else if p.spans(q.start) || q.spans(p.start) {
        best = best.min((p.r - q.r).abs());
    }
    best
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
    fn consecutive_pieces_of_a_straight_run_do_not_meet() {
        // Two pieces of a nearly straight run (joints printed to 1e-9 mm, so a kink of a few
        // nanoradians), each cut 1e-9 mm short of their joint, as the self-crossing test of a
        // contour measures them: 2e-9 mm apart. The floating crossing parameters said 0.
        let p = |x: f64, y: f64| P2::new(x, y);
        let (a, b, c) = (p(26.74897854, 46.120090744), p(25.689794481, 44.730928318), p(24.630610432, 43.341765886));
        let (k1, k2) = (1e-9 / (b - a).norm(), 1e-9 / (c - b).norm());
        let (s0, s1) = (a + (b - a) * k1, a + (b - a) * (1.0 - k1));
        let (t0, t1) = (b + (c - b) * k2, b + (c - b) * (1.0 - k2));
        let m = segment_segment_min(&s0, &s1, &t0, &t1);
        assert!((m - 2e-9).abs() < 1e-12, "{m:e}");
        assert!(!segments_meet(&s0, &s1, &t0, &t1));
        // Collinear: overlapping pieces meet, pieces with a gap are the gap apart.
        assert_eq!(segment_segment_min(&p(0.0, 0.0), &p(2.0, 2.0), &p(1.0, 1.0), &p(3.0, 3.0)), 0.0);
        let gap = segment_segment_min(&p(0.0, 0.0), &p(1.0, 1.0), &p(2.0, 2.0), &p(3.0, 3.0));
        assert!((gap - 2f64.sqrt()).abs() < 1e-15);
        // A point on a segment's end, and a degenerate segment (a point) inside another.
        assert_eq!(segment_segment_min(&p(0.0, 0.0), &p(1.0, 0.0), &p(1.0, 0.0), &p(1.0, 5.0)), 0.0);
        assert_eq!(segment_segment_min(&p(0.5, 0.0), &p(0.5, 0.0), &p(0.0, 0.0), &p(1.0, 0.0)), 0.0);
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

    /// Brute force for the new pair distances: dense samples of both pieces.
    fn samples_arc(arc: &Arc2, n: usize) -> Vec<P2> {
        (0..=n).map(|i| arc.point_at_fraction(i as f64 / n as f64)).collect()
    }

    fn samples_seg(a: &P2, b: &P2, n: usize) -> Vec<P2> {
        (0..=n).map(|i| a + (b - a) * (i as f64 / n as f64)).collect()
    }

    proptest! {
        #[test]
        fn pair_distances_match_brute_force(
            ax in -3.0..3.0f64, ay in -3.0..3.0f64, bx in -3.0..3.0f64, by in -3.0..3.0f64,
            cx in -1.0..1.0f64, cy in -1.0..1.0f64,
            s1 in -PI..PI, w1 in -6.0..6.0f64, r1 in 0.5..2.0f64,
            s2 in -PI..PI, w2 in -6.0..6.0f64, r2 in 0.5..2.0f64,
        ) {
            prop_assume!(w1.abs() > 0.05 && w2.abs() > 0.05);
            let p = Arc2 { c: P2::origin(), r: r1, start: s1, sweep: w1 };
            let q = Arc2 { c: P2::new(cx, cy), r: r2, start: s2, sweep: w2 };
            let (a, b) = (P2::new(ax, ay), P2::new(bx, by));
            let (pa, qa, sa) = (samples_arc(&p, 3000), samples_arc(&q, 3000), samples_seg(&a, &b, 3000));
            // Sampling overestimates a minimum by at most half a sample spacing plus a sagitta.
            let slack = 0.01;
            let m = arc_arc_min(&p, &q);
            let bm = pa.iter().map(|u| point_arc(u, &q)).chain(qa.iter().map(|u| point_arc(u, &p))).fold(f64::INFINITY, f64::min);
            prop_assert!(m <= bm + 1e-9 && bm - m < slack, "arc_arc_min {m} brute {bm}");
            let m = segment_arc_min(&a, &b, &p);
            let bm = sa.iter().map(|u| point_arc(u, &p)).fold(f64::INFINITY, f64::min);
            prop_assert!(m <= bm + 1e-9 && bm - m < slack, "segment_arc_min {m} brute {bm}");
            // One-sided maxima: sampled points of `from`, exact distance to `to`.
            let mx = arc_arc_max(&p, &q);
            let bx = pa.iter().map(|u| point_arc(u, &q)).fold(0.0, f64::max);
            prop_assert!(mx >= bx - 1e-9 && mx - bx < slack, "arc_arc_max {mx} brute {bx}");
            let mx = arc_segment_max(&p, &a, &b);
            let bx = pa.iter().map(|u| point_segment(u, &a, &b)).fold(0.0, f64::max);
            prop_assert!(mx >= bx - 1e-9 && mx - bx < slack, "arc_segment_max {mx} brute {bx}");
        }

        #[test]
        fn crossing_segments_meet_whatever_the_angle(
            (x, y) in (-50.0..50.0f64, -50.0..50.0f64), (u, v) in (-1.0..1.0f64, -1.0..1.0f64),
            len in 0.5..80.0f64, angle in prop_oneof![Just(1e-9), 1e-7..1e-3f64, 0.01..3.1f64],
            (t, s) in (0.05..0.95f64, 0.05..0.95f64),
        ) {
            // Two segments through one point at any angle down to 1e-9 rad (the rounding of their
            // ends moves the crossing by at most 1e-5 mm along them): they meet. Cut one 1e-6 mm
            // before the point, where that leaves it far more than the round-off away, and they
            // are that far apart.
            prop_assume!(u.hypot(v) > 0.1);
            let dir = V2::new(u, v).normalize();
            let rot = V2::new(dir.x * angle.cos() - dir.y * angle.sin(), dir.x * angle.sin() + dir.y * angle.cos());
            let x0 = P2::new(x, y);
            let (a, b) = (x0 - dir * (t * len), x0 + dir * ((1.0 - t) * len));
            let (c, d) = (x0 - rot * (s * len), x0 + rot * ((1.0 - s) * len));
            prop_assert_eq!(segment_segment_min(&a, &b, &c, &d), 0.0);
            if angle >= 1e-3 {
                let short = x0 - dir * 1e-6;
                let m = segment_segment_min(&a, &short, &c, &d);
                let gap = 1e-6 * angle.sin();
                prop_assert!((m - gap).abs() <= 1e-3 * gap + 1e-13, "{m} vs {gap}");
            }
        }

        #[test]
        fn segment_segment_min_matches_brute_force(
            ax in -3.0..3.0f64, ay in -3.0..3.0f64, bx in -3.0..3.0f64, by in -3.0..3.0f64,
            cx in -3.0..3.0f64, cy in -3.0..3.0f64, dx in -3.0..3.0f64, dy in -3.0..3.0f64,
        ) {
            let (a, b, c, d) = (P2::new(ax, ay), P2::new(bx, by), P2::new(cx, cy), P2::new(dx, dy));
            let m = segment_segment_min(&a, &b, &c, &d);
            let bm = samples_seg(&a, &b, 3000).iter().map(|u| point_segment(u, &c, &d)).fold(f64::INFINITY, f64::min);
            prop_assert!(m <= bm + 1e-9 && bm - m < 0.01, "{m} vs {bm}");
        }
    }
}
