//! The measuring instrument: an upper bound, exact in the planar case, of the two-sided
//! Hausdorff distance between a piece as written (line, arc or helix) and the input polyline it
//! replaces.
//!
//! Input → output: every vertex and every chord is measured against the piece in closed form.
//! Output → input: the polyline starts next to the piece's start and ends next to its end, so
//! its projection onto the piece's parameter (distance along a line, angle about an arc's centre)
//! covers the piece; the polyline point with the same parameter is no farther than the largest
//! offset measured on the chords. The two small gaps between a written end point and the input
//! end point are added explicitly. A piece that fails these premises measures as infinite.

use camkit::geom::{Arc2, P2, P3, Plane, V2, arc::angle_between, cross2, dist};
use std::f64::consts::PI;

/// Deviation bound of a line from `a` to `b` (as written) against the polyline `pts`.
pub fn line(pts: &[P3], a: &P3, b: &P3) -> f64 {
    let (first, last) = (&pts[0], &pts[pts.len() - 1]);
    let d = b - a;
    let len2 = d.norm_squared();
    if len2 > 0.0 && (first - a).dot(&d) > (last - a).dot(&d) {
        // The polyline runs against the line's direction: not a replacement of it.
        return f64::INFINITY;
    }
    // Distance to a segment is convex along a chord: vertices bound the chords.
    let inner = pts.iter().map(|p| dist::point_segment(p, a, b)).fold(0.0, f64::max);
    inner.max((first - a).norm()).max((last - b).norm())
}

/// An arc or helix as written: start and end (3D), centre in plane coordinates, sense.
#[derive(Clone, Copy, Debug)]
pub struct Helix {
    /// Plane of the arc.
    pub plane: Plane,
    /// Start as written.
    pub start: P3,
    /// End as written.
    pub end: P3,
    /// Centre (plane coordinates) as written.
    pub centre: P2,
    /// Counter-clockwise in its plane.
    pub ccw: bool,
}

impl Helix {
    /// The arc in its plane (radius: mean of the two end radii) and the normal coordinate at
    /// start and end.
    pub fn arc(&self) -> (Arc2, f64, f64) {
        let (s, ws) = self.plane.split(&self.start);
        let (e, we) = self.plane.split(&self.end);
        (Arc2::from_centre(self.centre, &s, &e, self.ccw, false), ws, we)
    }
}

/// Deviation bound of a helical arc against the polyline `pts`; infinite when the polyline does
/// not wind about the centre the way the arc does.
pub fn helix(pts: &[P3], h: &Helix) -> f64 {
    let (arc, w0, w1) = h.arc();
    let (s, _) = h.plane.split(&h.start);
    let (e, _) = h.plane.split(&h.end);
    // A controller moves from the start radius to the end radius (a spiral or a final jog);
    // every point of that path lies within half the difference of the mean-radius circle.
    let spiral = 0.5 * ((e - arc.c).norm() - (s - arc.c).norm()).abs();
    let span = arc.sweep.abs();
    if span == 0.0 || arc.r == 0.0 {
        return f64::INFINITY;
    }
    let sense = if h.ccw { 1.0 } else { -1.0 };
    // Normal coordinate per radian of progress along the sweep.
    let slope = (w1 - w0) / span;
    let helix_at = |theta: f64| -> P3 { h.plane.join(&arc.point_at(arc.start + sense * theta), w0 + slope * theta) };
    let start_dir = arc.start_point() - arc.c;

    let (q0, wq0) = h.plane.split(&pts[0]);
    let mut theta = sense * angle_between(&start_dir, &(q0 - arc.c));
    if theta.abs() > 0.5 * PI {
        return f64::INFINITY;
    }
    let theta_first = theta;
    let mut worst: f64 = 0.0;
    let (mut q, mut wq) = (q0, wq0);
    for p in &pts[1..] {
        let (qn, wn) = h.plane.split(p);
        let u0 = q - arc.c;
        let u1 = qn - arc.c;
        let delta = sense * angle_between(&u0, &u1);
        let theta_next = theta + delta;
        let bound = chord_bound(&arc, &q, &qn, wq, wn, theta, delta, w0, slope, sense);
        if !bound.is_finite() {
            return f64::INFINITY;
        }
        let mut b = bound;
        // Parts of the chord beside the arc are measured against the nearer arc end.
        for (th, v) in [(theta, h.plane.join(&q, wq)), (theta_next, *p)] {
            if th < 0.0 {
                b = b.max((v - helix_at(0.0)).norm());
            } else if th > span {
                b = b.max((v - helix_at(span)).norm());
            }
        }
        worst = worst.max(b);
        theta = theta_next;
        q = qn;
        wq = wn;
    }
    if (theta - span).abs() > 0.5 * PI {
        return f64::INFINITY;
    }
    // Gaps between the written ends and the input ends, along the helix.
    let helix_speed = (arc.r * arc.r + slope * slope).sqrt();
    let gap_start = theta_first.max(0.0) * helix_speed + (pts[0] - helix_at(theta_first.clamp(0.0, span))).norm();
    let gap_end =
        (span - theta).max(0.0) * helix_speed + (pts[pts.len() - 1] - helix_at(theta.clamp(0.0, span))).norm();
    worst.max(gap_start).max(gap_end) + spiral
}

/// Largest distance from points of the chord `q → qn` to the helix point at the same angle:
/// radial part exactly (ends and the foot of the perpendicular from the centre), normal part
/// exactly (ends and the roots of a quadratic), combined as √(R² + W²).
#[allow(clippy::too_many_arguments)]
fn chord_bound(
    arc: &Arc2,
    q: &P2,
    qn: &P2,
    wq: f64,
    wn: f64,
    theta: f64,
    delta: f64,
    w0: f64,
    slope: f64,
    sense: f64,
) -> f64 {
    let d = qn - q;
    let u0 = q - arc.c;
    let rho0 = u0.norm();
    let rho1 = (qn - arc.c).norm();
    let len2 = d.norm_squared();
    let rho_min = if len2 > 0.0 {
        let t = (-u0.dot(&d) / len2).clamp(0.0, 1.0);
        (u0 + d * t).norm()
    } else {
        rho0
    };
    if rho_min <= 0.5 * arc.r {
        // Too close to the centre for the angle to be a parameter of the polyline.
        return f64::INFINITY;
    }
    let radial = (rho0 - arc.r).abs().max((rho1 - arc.r).abs()).max(arc.r - rho_min);
    let gap = |t: f64, th: f64| (wq + t * (wn - wq)) - (w0 + slope * th);
    let mut normal = gap(0.0, theta).abs().max(gap(1.0, theta + delta).abs());
    let dw = wn - wq;
    if slope != 0.0 && dw != 0.0 && len2 > 0.0 {
        // g'(t) = dw − slope·sense·C/ρ(t)², C = u0 × d: critical where ρ(t)² = slope·sense·C/dw.
        let c = cross2(&u0, &d);
        let target = slope * sense * c / dw;
        if target > 0.0 {
            // |u0 + t d|² = target → len2 t² + 2 (u0·d) t + (|u0|² − target) = 0.
            let (a2, b2, c2) = (len2, 2.0 * u0.dot(&d), rho0 * rho0 - target);
            let disc = b2 * b2 - 4.0 * a2 * c2;
            if disc >= 0.0 {
                let sq = disc.sqrt();
                for t in [(-b2 - sq) / (2.0 * a2), (-b2 + sq) / (2.0 * a2)] {
                    if t > 0.0 && t < 1.0 {
                        let th = theta + sense * angle_between(&u0, &(u0 + d * t));
                        normal = normal.max(gap(t, th).abs());
                    }
                }
            }
        }
    }
    (radial * radial + normal * normal).sqrt()
}

/// The arc's start tangent (unit, direction of travel).
pub fn start_tangent(h: &Helix) -> V2 {
    let (arc, _, _) = h.arc();
    arc.tangent_at(arc.start)
}

/// The arc's end tangent (unit, direction of travel).
pub fn end_tangent(h: &Helix) -> V2 {
    let (arc, _, _) = h.arc();
    arc.tangent_at(arc.start + arc.sweep)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Independent check: dense samples of both paths, exact point-to-polyline distances.
    fn sampled_hausdorff(pts: &[P3], h: &Helix) -> f64 {
        let (arc, w0, w1) = h.arc();
        let helix: Vec<P3> = (0..=2000)
            .map(|i| {
                let t = i as f64 / 2000.0;
                h.plane.join(&arc.point_at_fraction(t), w0 + t * (w1 - w0))
            })
            .collect();
        let dense: Vec<P3> = pts
            .windows(2)
            .flat_map(|w| (0..50).map(move |i| w[0] + (w[1] - w[0]) * (i as f64 / 50.0)))
            .chain(std::iter::once(pts[pts.len() - 1]))
            .collect();
        let a = dense.iter().map(|p| dist::point_polyline(p, &helix)).fold(0.0, f64::max);
        let b = helix.iter().map(|p| dist::point_polyline(p, pts)).fold(0.0, f64::max);
        a.max(b)
    }

    #[test]
    fn exact_arc_chords_measure_their_sagitta() {
        let pts: Vec<P3> = (0..=8)
            .map(|i| {
                let phi = i as f64 * PI / 16.0;
                P3::new(10.0 * phi.cos(), 10.0 * phi.sin(), 0.0)
            })
            .collect();
        let h = Helix { plane: Plane::Xy, start: pts[0], end: pts[8], centre: P2::origin(), ccw: true };
        let sagitta = 10.0 * (1.0 - (PI / 32.0).cos());
        assert!((helix(&pts, &h) - sagitta).abs() < 1e-12);
        // Clockwise is the wrong winding.
        assert!(helix(&pts, &Helix { ccw: false, ..h }).is_infinite());
    }

    #[test]
    fn collinear_points_measure_zero_against_their_line() {
        let pts: Vec<P3> = (0..5).map(|i| P3::new(i as f64, 2.0 * i as f64, 0.5)).collect();
        assert!(line(&pts, &pts[0], &pts[4]) < 1e-15);
        assert!(line(&pts, &pts[4], &pts[0]).is_infinite());
    }

    proptest! {
        /// The bound is never below the true (sampled) Hausdorff distance, and not far above it
        /// for planar arcs, where it is exact.
        #[test]
        fn bound_holds_against_sampling(
            r in 2.0..50.0f64, start in -PI..PI, sweep in 0.2..5.5f64, ccw: bool, n in 3usize..30,
            noise in proptest::collection::vec(-0.05..0.05f64, 60), dz in -3.0..3.0f64, planar: bool,
        ) {
            let sense = if ccw { 1.0 } else { -1.0 };
            let dz = if planar { 0.0 } else { dz };
            let pts: Vec<P3> = (0..=n).map(|i| {
                let t = i as f64 / n as f64;
                let phi = start + sense * sweep * t;
                let (e, ez) = if i == 0 || i == n { (0.0, 0.0) } else { (noise[i], noise[i + 30] * if planar { 0.0 } else { 1.0 }) };
                P3::new((r + e) * phi.cos(), (r + e) * phi.sin(), dz * t + ez)
            }).collect();
            let h = Helix { plane: Plane::Xy, start: pts[0], end: pts[n], centre: P2::origin(), ccw };
            let bound = helix(&pts, &h);
            let sampled = sampled_hausdorff(&pts, &h);
            prop_assert!(bound.is_finite());
            prop_assert!(sampled <= bound + 1e-9, "sampled {sampled} > bound {bound}");
            if planar {
                prop_assert!(bound - sampled < 1e-3 * r.max(1.0) * 0.01 + 1e-4, "bound {bound} sampled {sampled}");
            }
        }
    }
}
