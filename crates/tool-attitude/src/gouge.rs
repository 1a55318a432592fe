//! Gouge checks: the whole tool body as an exact solid against the part (camkit's
//! [`Solid::clearance`]: every overlap of the body with the model is found, not samples of it;
//! the flat-type tool's body is the thin wedge of its two flanks), and the search for the tilt
//! nearest the requested one, inside the allowed range, at which the body does not cut in.

use crate::pose::Pose;
use camkit::collide::solid::{Body, Placement, Solid};
use camkit::doc::Tool;
use camkit::model::Model;

/// The part a pose is checked against: the model, the tool's body (cylinder, ball, flat end mill,
/// the flat-type tool's wedge of its flanks) and the model as a solid.
pub struct Part {
    /// The model (nearest-point queries: the flat-type correction).
    pub model: Model,
    solid: Solid,
    body: Body,
}

impl Part {
    /// The part for `tool` whose body reaches `length` above its tip (the flat-type tool's wedge
    /// reaches its `flank_length` along each flank instead), with the model as a solid (B-spline
    /// patches, trimmed STEP faces, bounded flipped cylinders, cones and tori as triangles within
    /// `chord` mm; see [`Solid::of_any`]). An error names the surface the solid cannot take.
    pub fn new(model: Model, tool: &Tool, length: f64, chord: f64) -> Result<Part, String> {
        let body = Body::of(&Tool { length: Some(length), ..tool.clone() });
        let solid = Solid::of_any(&model, chord)?;
        Ok(Part { model, solid, body })
    }

    /// Largest distance (mm) between a tessellated surface and its triangles: each penetration
    /// is exact against the triangles, so within this of the surface's own (0: exact surfaces).
    pub fn chord_error(&self) -> f64 {
        self.solid.chord_error()
    }

    /// How deep the tool body at `pose` cuts into the part (mm, 0 when clear): the penetration
    /// depth of the body into the solid (for a mesh, the deepest overlap with one of its
    /// triangles, or the tip's depth inside a closed mesh).
    pub fn penetration(&self, pose: &Pose) -> f64 {
        self.penetration_within(pose, 0.0)
    }

    /// How far the tool body at `pose` comes inside `stand_off` mm of the part (mm, 0 when it
    /// keeps that far off): `stand_off` less the signed clearance. The flat-type tool's edge is
    /// the stylus's offset of the surface, so its wedge must keep the stylus radius off. The
    /// body is placed with its edge (tool +X, across the wedge's plane) along `pose.edge`.
    pub fn penetration_within(&self, pose: &Pose, stand_off: f64) -> f64 {
        let at = Placement { tip: pose.tip, axis: pose.axis, edge: pose.edge };
        (stand_off - self.solid.clearance(&self.body, &at, stand_off)).max(0.0)
    }

    /// Whether the body at `pose` cuts in deeper than `tol` (mm): `penetration(pose) > tol`,
    /// decided at the first overlap that deep rather than after measuring every one.
    pub fn gouges(&self, pose: &Pose, tol: f64) -> bool {
        let at = Placement { tip: pose.tip, axis: pose.axis, edge: pose.edge };
        // penetration > tol ⇔ clearance < −tol (a clearance of −0 reads as no penetration).
        self.solid.clearance_below(&self.body, &at, 0.0, -tol) < -tol
    }
}

/// Outcome of the tilt search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adjusted {
    /// The tilt used (radians).
    pub tilt: f64,
    /// Penetration at that tilt (mm).
    pub gouge: f64,
}

/// The tilt nearest `start` inside `[lo, hi]` that is clear (`over(tilt)` false: the gouge no
/// deeper than the tolerance): candidates every `step` outwards from `start` on both sides, the
/// first clear one refined by bisection towards `start` to `angle_tol`. Keeps `start` when no
/// candidate clears. The search asks only the yes/no `over` and measures `gouge` (mm) at the tilt
/// it returns.
pub fn adjust(start: f64, lo: f64, hi: f64, gouge: impl Fn(f64) -> f64, over: impl Fn(f64) -> bool) -> Adjusted {
    let clear = |t: f64| !over(t);
    if clear(start) {
        return Adjusted { tilt: start, gouge: gouge(start) };
    }
    let step = ADJUST_STEP;
    let mut k = 1;
    loop {
        let d = step * k as f64;
        let candidates = [start - d, start + d];
        if candidates.iter().all(|&c| c < lo - step || c > hi + step) {
            return Adjusted { tilt: start, gouge: gouge(start) };
        }
        for c in candidates {
            let c = c.clamp(lo, hi);
            if clear(c) {
                // Bisect between the clear candidate and the gouging one a step nearer start.
                let (mut bad, mut good) = (c + (start - c).signum() * step.min((start - c).abs()), c);
                while (good - bad).abs() > ADJUST_ANGLE_TOL {
                    let mid = 0.5 * (good + bad);
                    if clear(mid) { good = mid } else { bad = mid }
                }
                return Adjusted { tilt: good, gouge: gouge(good) };
            }
        }
        k += 1;
    }
}

/// Step (radians) of the outward search for a clear tilt: 0.25°.
pub const ADJUST_STEP: f64 = 0.25 * std::f64::consts::PI / 180.0;

/// The adjusted tilt is found to within this (radians).
pub const ADJUST_ANGLE_TOL: f64 = 1e-7;

#[cfg(test)]
mod tests {
    use super::*;
    use camkit::geom::{P3, V3};
    use camkit::model::analytic::Analytic;
    use camkit::model::mesh::Mesh;
    use camkit::model::{Geometry, Surface};
    use proptest::prelude::*;

    /// A closed prism of `n` sides (radius `r` to its edges) round the line through `b` along the
    /// horizontal unit `d`, 400 mm long, faces turned outwards.
    fn prism(b: P3, d: V3, r: f64, n: usize) -> Vec<[P3; 3]> {
        let (u, w) = (V3::z().cross(&d), V3::z());
        let ring = |t: f64| -> Vec<P3> {
            (0..n)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / n as f64;
                    b + d * t + (u * a.cos() + w * a.sin()) * r
                })
                .collect()
        };
        let (p, q) = (ring(-200.0), ring(200.0));
        let (cp, cq) = (b - d * 200.0, b + d * 200.0);
        let mut tris = Vec::new();
        for k in 0..n {
            let m = (k + 1) % n;
            tris.extend([[p[k], q[m], q[k]], [p[k], p[m], q[m]], [cp, p[m], p[k]], [cq, q[k], q[m]]]);
        }
        tris
    }

    /// Parameter along the segment `a + s·e` (s in 0..len, unit e) of its nearest point to the
    /// line through `b` along unit `d`, unclamped, and the distance there.
    fn segment_line(a: &P3, e: &V3, b: &P3, d: &V3) -> (f64, f64) {
        let w = a - b;
        let (k, c, f) = (e.dot(d), e.dot(&w), d.dot(&w));
        let s = (k * f - c) / (1.0 - k * k);
        let q = a + e * s;
        let u = d.dot(&(q - b));
        (s, (q - (b + d * u)).norm())
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        /// A thin rod (a 64-sided prism of radius 0.5) at a random height, angle and depth
        /// beside the φ25 cylinder standing on a floor at a random tilt: the body check finds it
        /// at the depth an independent closed form gives (segment-to-line distance from the
        /// tool's axis to the rod's, less the radii), within the prism's sagitta.
        #[test]
        fn thin_rods_beside_the_body_are_found(
            zr in 1.0f64..34.0, depth in -0.2f64..0.45, phi in -0.5f64..0.5, tilt in -20.0f64..0.0, x0 in -15.0f64..15.0,
        ) {
            let (big, r, n) = (12.5, 0.5, 64);
            let pose = crate::pose::cylinder(&P3::origin(), &V3::z(), &V3::x(), big, tilt.to_radians());
            let d = V3::new(phi.cos(), phi.sin(), 0.0);
            // The rod's axis `big + r − depth` from the tool's axis at height zr, across it.
            let on_axis = pose.tip + pose.axis * ((zr - pose.tip.z) / pose.axis.z);
            let across = V3::z().cross(&d);
            let b = on_axis + across * (big + r - depth) + d * x0;
            let (s, dist) = segment_line(&pose.tip, &pose.axis, &b, &d);
            prop_assume!(s > 1.0 && s < 39.0);
            let exact = big + r - dist;
            let model = Model { surfaces: vec![
                Surface::new("floor".into(), Geometry::Analytic(Analytic::Plane { point: P3::origin(), normal: V3::z() }), None, false),
                Surface::new("rod".into(), Geometry::Mesh(Mesh::new(&prism(b, d, r, n)).unwrap()), None, false),
            ] };
            let tool: Tool = camkit::json::from_input(&camkit::io::Input {
                name: "t.json".into(),
                data: br#"{"kind": "cylindrical-nonrotating", "radius": 12.5}"#.to_vec(),
            }).unwrap();
            let part = Part::new(model, &tool, 40.0, 1e-4).unwrap();
            let got = part.penetration(&pose);
            let sagitta = r * (1.0 - (std::f64::consts::PI / n as f64).cos());
            prop_assert!((got - exact.max(0.0)).abs() <= sagitta + 1e-6, "gouge {got}, exact {exact}");
        }
    }

    /// A tool document from JSON text.
    fn tool(json: &str) -> Tool {
        camkit::json::from_input(&camkit::io::Input { name: "t.json".into(), data: json.as_bytes().to_vec() }).unwrap()
    }

    /// A surface of `geometry`, not flipped.
    fn surface(name: &str, geometry: Geometry) -> Surface {
        Surface::new(name.into(), geometry, None, false)
    }

    /// The flat-type tool's body is the wedge of the flanks `flat_type::solve` computes: a small
    /// ball 0.3 mm beyond either flank's end (along the flank, so its nearest point of the wedge
    /// is that corner) stands exactly 0.3 − 0.1 from the body, in a skew corner where the
    /// wedge's plane, its half angle and its edge direction all matter.
    #[test]
    fn flat_type_wedge_corners_are_the_flanks() {
        let nc = V3::new(0.2, 0.1, 1.0).normalize();
        let other = V3::new(1.0, -0.3, 0.2).normalize();
        let corner = crate::flat_type::Corner {
            centre: P3::new(3.0, -2.0, 5.0),
            control: (P3::new(3.0, -2.0, 5.0) - nc, nc),
            other,
        };
        let edge = crate::flat_type::Edge { included: 65f64.to_radians(), flank: 1.5 };
        let fp = crate::flat_type::solve(&corner, &edge, &V3::new(0.3, 1.0, -0.2), None).unwrap();
        let (first, second) = crate::flat_type::flanks(&fp, &edge);
        let t = tool(r#"{"kind": "flat-nonrotating", "radius": 5, "included_angle": 65, "flank_length": 1.5}"#);
        for f in [first, second] {
            let centre = fp.pose.tip + f * (edge.flank + 0.3);
            let model =
                Model { surfaces: vec![surface("ball", Geometry::Analytic(Analytic::Sphere { centre, radius: 0.1 }))] };
            let part = Part::new(model, &t, 30.0, 1e-4).unwrap();
            let got = part.penetration_within(&fp.pose, 1.0);
            assert!((got - 0.8).abs() < 1e-9, "flank {f:?}: {got}");
        }
    }

    /// A thin rod (radius 0.5) on the floor of a square corner, across the flat-type tool's
    /// first flank (32 mm long: the old 16 probes 2 mm apart) midway between two of the old
    /// probes. The probes all stand more than the stylus radius off the rod (the old check
    /// reported no gouge); the wedge check finds it at the depth an independent closed form
    /// gives: stylus radius + rod radius − the segment-to-line distance from the flank to the
    /// rod's axis.
    #[test]
    fn thin_rod_between_flank_probes_is_found() {
        let (r, rod, flank, count) = (0.25, 0.5, 32.0, 16);
        let t = tool(r#"{"kind": "flat-nonrotating", "radius": 5, "included_angle": 85, "flank_length": 32}"#);
        let setup = crate::Setup {
            shape: crate::Shape::FlatType {
                edge: crate::flat_type::Edge { included: 85f64.to_radians(), flank },
                control_second: false,
            },
            tilt: 0.0,
            range: (0.0, 0.0),
            length: 30.0,
            gouge_tol: 1e-3,
        };
        let contact = crate::Contact {
            centre: P3::new(r, 0.0, r),
            point: P3::new(r, 0.0, 0.0),
            normal: V3::z(),
            second: Some((P3::new(0.0, 0.0, r), V3::x())),
            surfaces: (Some(0), Some(1)),
            feed: V3::y(),
        };
        let plane = |normal: V3| Geometry::Analytic(Analytic::Plane { point: P3::origin(), normal });
        // (probe interval, angle of the rod from the flank in degrees, rod axis below the flank).
        for (k, phi, below) in [(5, 90.0, 0.3), (9, 70.0, 0.3), (2, 110.0, 0.6), (12, 90.0, 0.9)] {
            let phi: f64 = f64::to_radians(phi);
            let d = V3::new(phi.cos(), phi.sin(), 0.0);
            let step = flank / count as f64;
            let b = P3::new(r + step * (k as f64 + 0.5), 0.0, r - below);
            let model = Model {
                surfaces: vec![
                    surface("floor", plane(V3::z())),
                    surface("wall", plane(V3::x())),
                    surface(
                        "rod",
                        Geometry::Analytic(Analytic::Cylinder {
                            point: b,
                            axis: d,
                            radius: rod,
                            from: -200.0,
                            to: 200.0,
                        }),
                    ),
                ],
            };
            let part = Part::new(model, &t, 30.0, 1e-4).unwrap();
            let a = crate::attitude(&setup, &contact, Some(&part)).unwrap();
            let (first, _) = crate::flat_type::flanks(
                &crate::flat_type::FlatPose {
                    pose: a.pose,
                    correction: 0.0,
                    corner_angle: 0.0,
                    flank_gap: 0.0,
                    control_point: a.pose.tip + V3::x() * flank,
                },
                &crate::flat_type::Edge { included: 85f64.to_radians(), flank },
            );
            assert!((first - V3::x()).norm() < 1e-12 && (a.pose.tip - contact.centre).norm() < 1e-12);
            // The old probes: every one more than r off the rod's surface.
            for j in 1..=count {
                let q = a.pose.tip + first * (step * j as f64);
                let w = q - b;
                let off = (w - d * w.dot(&d)).norm() - rod;
                assert!(off > r, "probe {j} is {off} off the rod");
            }
            let (s, dist) = segment_line(&a.pose.tip, &first, &b, &d);
            assert!(s > 0.0 && s < flank);
            let exact = (r + rod - dist).max(0.0);
            let got = a.gouge.unwrap();
            assert!((got - exact).abs() < 1e-6, "rod {k}: gouge {got}, exact {exact}");
        }
    }

    #[test]
    fn adjust_finds_the_nearest_clear_tilt() {
        // Gouge whenever tilt > −0.3: the clear tilt nearest −0.1 is −0.3.
        let g = |t: f64| (t + 0.3).max(0.0);
        let a = adjust(-0.1, -0.35, 0.0, g, |t| g(t) > 1e-9);
        assert!((a.tilt + 0.3).abs() <= ADJUST_ANGLE_TOL && a.gouge <= 1e-9, "{a:?}");
        // Nothing clear inside the range: the start is kept and reported.
        let a = adjust(-0.1, -0.2, 0.0, g, |t| g(t) > 1e-9);
        assert_eq!(a.tilt, -0.1);
        assert!(a.gouge > 0.0);
    }
}
