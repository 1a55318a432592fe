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

/// Deviation bound of a line from `a` to `b` (as written) against the polyline `pts`. Stops
/// early (returning a value above `limit`) once the bound exceeds `limit`.
pub fn line(pts: &[P3], a: &P3, b: &P3, limit: f64) -> f64 {
    let (first, last) = (&pts[0], &pts[pts.len() - 1]);
    let d = b - a;
    let len2 = d.norm_squared();
    if len2 > 0.0 && (first - a).dot(&d) > (last - a).dot(&d) {
        // The polyline runs against the line's direction: not a replacement of it.
        return f64::INFINITY;
    }
    // Distance to a segment is convex along a chord: vertices bound the chords.
    let mut worst = (first - a).norm().max((last - b).norm());
    for p in pts {
        worst = worst.max(dist::point_segment(p, a, b));
        if worst > limit {
            return worst;
        }
    }
    worst
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

/// A monotone stand-in for the angle of `v` (no trigonometry): 0, 1, 2, 3 at 0°, 90°, 180°,
/// 270°, strictly increasing in between, and exactly 2 more for the opposite direction.
pub fn pseudo_angle(v: &V2) -> f64 {
    let s = v.x.abs() + v.y.abs();
    if s == 0.0 {
        return 0.0;
    }
    let r = v.y / s;
    if v.x >= 0.0 { if v.y >= 0.0 { r } else { 4.0 + r } } else { 2.0 - r }
}

/// A difference of pseudo-angles as a turn of less than half a circle: in (−2, 2].
fn wrap_turn(d: f64) -> f64 {
    if d > 2.0 {
        d - 4.0
    } else if d <= -2.0 {
        d + 4.0
    } else {
        d
    }
}

/// The pseudo-angle span of a counter-clockwise turn from direction `a` to direction `b`, in
/// (0, 4] (a full turn when they coincide).
fn pseudo_span(a: &V2, b: &V2) -> f64 {
    let d = pseudo_angle(b) - pseudo_angle(a);
    if d <= 0.0 { d + 4.0 } else { d }
}

/// True if the arc sweeps no more than the angle whose unit direction (relative to a start
/// along +x, counter-clockwise) is `(cos, sin)`; no trigonometry per arc.
pub fn sweep_within(h: &Helix, limit: &V2) -> bool {
    let flip = if h.ccw { 1.0 } else { -1.0 };
    let (s, _) = h.plane.split(&h.start);
    let (e, _) = h.plane.split(&h.end);
    let u = s - h.centre;
    let v = e - h.centre;
    let (u, v) = (V2::new(u.x, flip * u.y), V2::new(v.x, flip * v.y));
    // The limit direction rotated onto the start direction.
    let l = V2::new(u.x * limit.x - u.y * limit.y, u.x * limit.y + u.y * limit.x);
    pseudo_span(&u, &v) <= pseudo_span(&u, &l)
}

/// Deviation bound of a helical arc against the polyline `pts`; infinite when the polyline does
/// not wind about the centre the way the arc does. Stops early (returning a value above `limit`)
/// once the bound exceeds `limit`. A planar arc is measured without trigonometry.
pub fn helix(pts: &[P3], h: &Helix, limit: f64) -> f64 {
    let (s, w0) = h.plane.split(&h.start);
    let (e, w1) = h.plane.split(&h.end);
    let c = h.centre;
    let (rs, re) = ((s - c).norm(), (e - c).norm());
    let r = 0.5 * (rs + re);
    if r == 0.0 || rs == 0.0 || re == 0.0 {
        return f64::INFINITY;
    }
    // A controller moves from the start radius to the end radius (a spiral or a final jog);
    // every point of that path lies within half the difference of the mean-radius circle.
    let spiral = 0.5 * (re - rs).abs();
    let limit = limit - spiral;
    // Work counter-clockwise: mirror clockwise arcs.
    let flip = if h.ccw { 1.0 } else { -1.0 };
    let mirror = |v: V2| V2::new(v.x, flip * v.y);
    let start_dir = mirror(s - c);
    let end_dir = mirror(e - c);
    // The ends on the mean circle, with their normal coordinates.
    let first_end = h.plane.join(&(c + (s - c) * (r / rs)), w0);
    let last_end = h.plane.join(&(c + (e - c) * (r / re)), w1);
    // The span in pseudo-angle, measured from the start direction.
    let p_start = pseudo_angle(&start_dir);
    let pspan = pseudo_span(&start_dir, &end_dir);
    let helical = w1 != w0;
    // Radians and the normal coordinate per radian, for helices only.
    let (span, slope) = if helical {
        let mut span = angle_between(&start_dir, &end_dir);
        if span <= 0.0 {
            span += std::f64::consts::TAU;
        }
        (span, (w1 - w0) / span)
    } else {
        (0.0, 0.0)
    };

    let (q0, wq0) = h.plane.split(&pts[0]);
    let u0 = mirror(q0 - c);
    let mut p_u = pseudo_angle(&u0);
    let mut pa = wrap_turn(p_u - p_start);
    if pa.abs() > 1.0 {
        return f64::INFINITY;
    }
    // A vertex beside the arc is measured against the nearer arc end.
    let beside = |pv: f64, v: &P3| -> f64 { if pv < 0.0 { (v - first_end).norm() } else { (v - last_end).norm() } };
    let theta_first = if helical { angle_between(&start_dir, &u0) } else { 0.0 };
    let mut theta = theta_first;
    let mut worst = if (0.0..=pspan).contains(&pa) { 0.0 } else { beside(pa, &pts[0]) };
    let (mut wq, mut u) = (wq0, u0);
    let mut rho = u.norm();
    let inner = 0.5 * r;
    for p in &pts[1..] {
        let (qn, wn) = h.plane.split(p);
        let un = mirror(qn - c);
        let rho_n = un.norm();
        let p_un = pseudo_angle(&un);
        let pa_next = pa + wrap_turn(p_un - p_u);
        // Radial deviation along the chord: ends, and the foot of the perpendicular.
        let mut radial = (rho - r).abs().max((rho_n - r).abs());
        let d = un - u;
        let len2 = d.norm_squared();
        let t = -u.dot(&d);
        let rho_min = if t > 0.0 && t < len2 { (u + d * (t / len2)).norm() } else { rho.min(rho_n) };
        if rho_min <= inner {
            // Too close to the centre for the angle to be a parameter of the polyline.
            return f64::INFINITY;
        }
        radial = radial.max(r - rho_min);
        let b = if helical {
            let delta = angle_between(&u, &un);
            let normal = normal_gap(&u, &d, wq, wn, theta, delta, w0, slope);
            theta += delta;
            (radial * radial + normal * normal).sqrt()
        } else {
            radial
        };
        worst = worst.max(b);
        if !(0.0..=pspan).contains(&pa_next) {
            worst = worst.max(beside(pa_next, p));
        }
        if worst > limit {
            return worst + spiral;
        }
        pa = pa_next;
        p_u = p_un;
        wq = wn;
        u = un;
        rho = rho_n;
    }
    if (pa - pspan).abs() > 1.0 {
        return f64::INFINITY;
    }
    // Gaps between the written ends and the input ends: the arc between a written end and the
    // angle of the input end. Planar: the farthest point of that piece of arc from the input end
    // is the written end (distance grows with the angle away from it). Helix: bounded by the
    // helix length of the gap plus the same-angle deviation.
    let (first, last) = (&pts[0], &pts[pts.len() - 1]);
    let (gap_start, gap_end) = if helical {
        let speed = (r * r + slope * slope).sqrt();
        let at = |theta: f64| h.plane.join(&(c + rotate(&(s - c), flip * theta) * (r / rs)), w0 + slope * theta);
        let theta_last = theta;
        (
            theta_first.max(0.0) * speed + (first - at(theta_first.clamp(0.0, span))).norm(),
            (span - theta_last).max(0.0) * speed + (last - at(theta_last.clamp(0.0, span))).norm(),
        )
    } else {
        let before_start = wrap_turn(pseudo_angle(&u0) - p_start) > 0.0;
        let after_end = pa < pspan;
        (
            if before_start { (first - first_end).norm() } else { 0.0 },
            if after_end { (last - last_end).norm() } else { 0.0 },
        )
    };
    worst.max(gap_start).max(gap_end) + spiral
}

/// `v` turned counter-clockwise by `angle` radians.
fn rotate(v: &V2, angle: f64) -> V2 {
    let (sin, cos) = angle.sin_cos();
    V2::new(v.x * cos - v.y * sin, v.x * sin + v.y * cos)
}

/// Largest difference, along the chord from `u` (relative to the centre, counter-clockwise
/// frame) by `d`, between the chord's normal coordinate and the helix's at the same angle:
/// the ends, and the roots of a quadratic where the derivative vanishes.
#[allow(clippy::too_many_arguments)]
fn normal_gap(u: &V2, d: &V2, wq: f64, wn: f64, theta: f64, delta: f64, w0: f64, slope: f64) -> f64 {
    let gap = |t: f64, th: f64| (wq + t * (wn - wq)) - (w0 + slope * th);
    let mut normal = gap(0.0, theta).abs().max(gap(1.0, theta + delta).abs());
    let dw = wn - wq;
    let len2 = d.norm_squared();
    if dw != 0.0 && len2 > 0.0 {
        // g'(t) = dw − slope·C/ρ(t)², C = u × d: critical where ρ(t)² = slope·C/dw.
        let target = slope * cross2(u, d) / dw;
        if target > 0.0 {
            // |u + t d|² = target → len2 t² + 2 (u·d) t + (|u|² − target) = 0.
            let (a2, b2, c2) = (len2, 2.0 * u.dot(d), u.norm_squared() - target);
            let disc = b2 * b2 - 4.0 * a2 * c2;
            if disc >= 0.0 {
                let sq = disc.sqrt();
                for t in [(-b2 - sq) / (2.0 * a2), (-b2 + sq) / (2.0 * a2)] {
                    if t > 0.0 && t < 1.0 {
                        let th = theta + angle_between(u, &(u + d * t));
                        normal = normal.max(gap(t, th).abs());
                    }
                }
            }
        }
    }
    normal
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
    use std::f64::consts::PI;

    #[test]
    fn pseudo_angle_is_monotone_and_opposites_differ_by_two() {
        let mut last = -1.0;
        for i in 0..3600 {
            let a = (i as f64 / 10.0).to_radians();
            let p = pseudo_angle(&V2::new(a.cos(), a.sin()));
            assert!(p > last, "not increasing at {i}");
            last = p;
            let q = pseudo_angle(&V2::new(-a.cos(), -a.sin()));
            assert!(((q - p).rem_euclid(4.0) - 2.0).abs() < 1e-12);
        }
    }

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
        assert!((helix(&pts, &h, f64::INFINITY) - sagitta).abs() < 1e-12);
        // Clockwise is the wrong winding.
        assert!(helix(&pts, &Helix { ccw: false, ..h }, f64::INFINITY).is_infinite());
    }

    #[test]
    fn collinear_points_measure_zero_against_their_line() {
        let pts: Vec<P3> = (0..5).map(|i| P3::new(i as f64, 2.0 * i as f64, 0.5)).collect();
        assert!(line(&pts, &pts[0], &pts[4], f64::INFINITY) < 1e-15);
        assert!(line(&pts, &pts[4], &pts[0], f64::INFINITY).is_infinite());
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
            let bound = helix(&pts, &h, f64::INFINITY);
            let sampled = sampled_hausdorff(&pts, &h);
            prop_assert!(bound.is_finite());
            // The sampled arc (2000 chords) lies inside the true one by up to its sagitta, which
            // can make a sampled distance exceed the true one by that much.
            let sagitta = r * (1.0 - (sweep / 4000.0).cos());
            prop_assert!(sampled <= bound + sagitta + 1e-12, "sampled {sampled} > bound {bound}");
            if planar {
                prop_assert!(bound - sampled < 1e-3 * r.max(1.0) * 0.01 + 1e-4, "bound {bound} sampled {sampled}");
            }
        }
    }
}
