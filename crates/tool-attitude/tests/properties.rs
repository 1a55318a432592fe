//! Property tests of the poses on random contacts: unit axes, the requested tilt in the plane of
//! normal and feed, the tip R from the cutting point perpendicular to the axis, the rim touching
//! the tangent plane only at the cutting point, eq. (1) against the rim's own section, and the
//! flat-type flank lying on a plane control surface.

use camkit::geom::circle::circumcentre;
use camkit::geom::{P2, P3, V3};
use proptest::prelude::*;
use tool_attitude::flat_type::{self, Corner, Edge};
use tool_attitude::{edge, pose};

fn unit() -> impl Strategy<Value = V3> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
        .prop_filter("not tiny", |(x, y, z)| V3::new(*x, *y, *z).norm() > 0.2)
        .prop_map(|(x, y, z)| V3::new(x, y, z).normalize())
}

/// A normal and a feed not along it.
fn normal_and_feed() -> impl Strategy<Value = (V3, V3)> {
    (unit(), unit()).prop_filter("feed across the normal", |(n, f)| n.cross(f).norm() > 0.1)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn cylinder_pose_invariants((n, feed) in normal_and_feed(), deg in -20.0..0.0f64, r in 1.0..30.0f64,
                                px in -100.0..100.0f64, py in -100.0..100.0f64, pz in -100.0..100.0f64) {
        let p = P3::new(px, py, pz);
        let f = pose::tangent_feed(&n, &feed).unwrap();
        let theta = deg.to_radians();
        let pose = pose::cylinder(&p, &n, &f, r, theta);
        let a = pose.axis;
        prop_assert!((a.norm() - 1.0).abs() < 1e-12);
        // The angle to the normal is |θ| (measured through atan2, exact near 0) ...
        let angle = a.cross(&n).norm().atan2(a.dot(&n));
        prop_assert!((angle - theta.abs()).abs() < 1e-9, "{angle} vs {theta}");
        // ... in the plane of the normal and the feed, leaning toward the feed for θ < 0.
        prop_assert!(a.dot(&n.cross(&f)).abs() < 1e-12);
        prop_assert!(a.dot(&f) >= -1e-15);
        // Tip R from the cutting point, perpendicular to the axis.
        let d = pose.tip - p;
        prop_assert!((d.norm() - r).abs() < 1e-9);
        prop_assert!(d.dot(&a).abs() < 1e-9);
        // The rim touches the tangent plane at p only: every other rim point is above it.
        let e = pose.edge.unwrap();
        let v = a.cross(&e);
        for k in 1..64 {
            let (s, c) = (std::f64::consts::TAU * k as f64 / 64.0).sin_cos();
            let q = pose.tip + (e * c + v * s) * r;
            prop_assert!((q - p).dot(&n) > -1e-9);
        }
        // The edge faces the feed: spindle orientation reproduces it.
        let s = pose.spindle().unwrap();
        let back = camkit::kinematics::edge_direction(&a, s);
        prop_assert!((back - e).norm() < 1e-9);
    }

    /// Eq. (1) against an independent construction: the rim of a posed tool on the plane z = 0,
    /// cut at height T, and the circle through its lowest point and both cut points in the
    /// section across the feed.
    #[test]
    fn eq1_is_the_rim_section_circle(deg in -20.0..-1.0f64, t in 0.001..0.05f64, r in 5.0..20.0f64) {
        let theta = deg.to_radians();
        let pose = pose::cylinder(&P3::origin(), &V3::z(), &V3::x(), r, theta);
        let e = pose.edge.unwrap();
        let v = pose.axis.cross(&e);
        let rim = |phi: f64| pose.tip + (e * phi.cos() + v * phi.sin()) * r;
        // Height of the rim rises from 0 at φ = 0 to the top at φ = π: bisect for height T.
        let (mut lo, mut hi) = (0.0, std::f64::consts::PI);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if rim(mid).z < t { lo = mid } else { hi = mid }
        }
        let q = rim(lo);
        let section = |p: P3| P2::new(p.y, p.z);
        let c = circumcentre(&P2::new(0.0, 0.0), &section(q), &P2::new(-q.y, q.z)).unwrap();
        let radius = c.coords.norm();
        let eq1 = edge::edge_radius(r, t, theta).unwrap();
        prop_assert!((radius - eq1).abs() < 1e-6 * eq1, "{radius} vs {eq1}");
    }

    #[test]
    fn ball_pose_invariants((n, feed) in normal_and_feed(), deg in 0.0..15.0f64, r in 0.5..15.0f64, side in any::<bool>()) {
        let p = P3::new(1.0, 2.0, 3.0);
        let f = pose::tangent_feed(&n, &feed).unwrap();
        let dir = if side { f.cross(&n) } else { f };
        let zeta = deg.to_radians();
        let pose = pose::ball(&p, &n, &dir, r, zeta);
        prop_assert!((pose.axis.norm() - 1.0).abs() < 1e-12);
        let angle = pose.axis.cross(&n).norm().atan2(pose.axis.dot(&n));
        prop_assert!((angle - zeta).abs() < 1e-9);
        // The ball centre is r along the normal from the contact whatever the tilt.
        let centre = pose.tip + pose.axis * r;
        prop_assert!((centre - (p + n * r)).norm() < 1e-9);
    }

    /// The flat-type tool in a corner of two planes at any angle: the control flank lies exactly
    /// on its plane (offset r), the second flank stands off by the corner angle less the tool's.
    #[test]
    fn flat_type_on_planes(corner_deg in 40.0..150.0f64, margin in 0.0..10.0f64, r in 0.2..3.0f64,
                           flank in 0.5..10.0f64, spin in 0.0..std::f64::consts::TAU) {
        // Floor z = 0 (normal +z); the second plane through the y axis, corner angle β in the xz section.
        let beta = corner_deg.to_radians();
        let n2 = V3::new(beta.sin(), 0.0, -beta.cos());
        // Tip at distance r from both planes: along the section bisector.
        let tip = P3::new(r / (beta / 2.0).tan(), 0.0, r);
        let rot = nalgebra::Rotation3::from_axis_angle(&V3::z_axis(), spin);
        let c = Corner { centre: rot * tip, control: (rot * P3::new(tip.x, 0.0, 0.0), V3::z()), other: rot * n2 };
        let edge = Edge { included: (corner_deg - margin).to_radians(), flank };
        let dist = |q: &P3| q.z.abs();
        let sol = flat_type::solve(&c, &edge, &(rot * V3::y()), Some(&dist)).unwrap();
        prop_assert!(sol.correction.abs() < 1e-9);
        prop_assert!((sol.flank_gap - margin.to_radians()).abs() < 1e-9);
        let (first, second) = flat_type::flanks(&sol, &edge);
        for k in 0..=8 {
            let q = sol.pose.tip + first * (flank * k as f64 / 8.0);
            prop_assert!((q.z - r).abs() < 1e-9, "flank point {} off the offset plane", q.z);
        }
        // The second flank makes the tool's included angle with the first and leaves the second plane.
        prop_assert!((first.dot(&second) - edge.included.cos()).abs() < 1e-9);
        prop_assert!((sol.pose.axis.norm() - 1.0).abs() < 1e-12);
        prop_assert!(sol.pose.axis.dot(&(rot * V3::y())).abs() < 1e-12);
    }
}
