//! Gouge checks: the whole tool body as an exact solid against the part (camkit's
//! [`Solid::clearance`]: every overlap of the body with the model is found, not samples of it),
//! the flat-type tool's flank probes, and the search for the tilt nearest the requested one,
//! inside the allowed range, at which the body does not cut in.

use crate::pose::Pose;
use camkit::collide::solid::{Body, Placement, Solid};
use camkit::doc::Tool;
use camkit::geom::P3;
use camkit::model::Model;

/// The part a pose is checked against: the model, and for a tool with a body (cylinder, ball,
/// flat end mill) that body and the model as a solid.
pub struct Part {
    /// The model (nearest-point queries: the flat-type correction and its flank probes).
    pub model: Model,
    body: Option<(Solid, Body)>,
}

impl Part {
    /// The part for `tool` whose body reaches `length` above its tip; with `solid`, the model as
    /// a solid (B-spline patches, bounded flipped cylinders, cones and tori as triangles within
    /// `chord` mm; see [`Solid::of_any`]). An error names the surface the solid cannot take.
    pub fn new(model: Model, tool: &Tool, length: f64, chord: f64, solid: bool) -> Result<Part, String> {
        let body = if solid {
            let body = Body::of(&Tool { length: Some(length), ..tool.clone() });
            Some((Solid::of_any(&model, chord)?, body))
        } else {
            None
        };
        Ok(Part { model, body })
    }

    /// Largest distance (mm) between a tessellated surface and its triangles: each penetration
    /// is exact against the triangles, so within this of the surface's own (0: exact surfaces).
    pub fn chord_error(&self) -> f64 {
        self.body.as_ref().map_or(0.0, |(s, _)| s.chord_error())
    }

    /// How deep the tool body at `pose` cuts into the part (mm, 0 when clear): the penetration
    /// depth of the body into the solid (for a mesh, the deepest overlap with one of its
    /// triangles, or the tip's depth inside a closed mesh). 0 for a part without a body.
    pub fn penetration(&self, pose: &Pose) -> f64 {
        self.body.as_ref().map_or(0.0, |(solid, body)| {
            let at = Placement { tip: pose.tip, axis: pose.axis, edge: pose.edge };
            (-solid.clearance(body, &at, 0.0)).max(0.0)
        })
    }
}

/// A point of the flat-type tool's flanks and how far outside the model it must stay (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// The point.
    pub point: P3,
    /// Required signed distance to the model (the stylus radius: the edge is the stylus's
    /// offset of the surface).
    pub clearance: f64,
}

/// Probes along the flat-type tool's two flanks from the tip, each to stay the stylus radius `r`
/// away (the edge is the stylus's offset of the surface).
pub fn flank_probes(tip: &P3, flanks: (camkit::geom::V3, camkit::geom::V3), length: f64, r: f64) -> Vec<Probe> {
    let count = 16;
    let mut out = Vec::with_capacity(2 * count);
    for f in [flanks.0, flanks.1] {
        for k in 1..=count {
            out.push(Probe { point: tip + f * (length * k as f64 / count as f64), clearance: r });
        }
    }
    out
}

/// Signed distance from `q` to the model: negative inside (behind the outward normal).
pub fn signed_distance(model: &Model, q: &P3) -> f64 {
    let n = model.nearest(q);
    if (q - n.point).dot(&n.normal) < 0.0 { -n.distance } else { n.distance }
}

/// How deep the deepest probe cuts into its clearance (mm, 0 when none does).
pub fn penetration(model: &Model, probes: &[Probe]) -> f64 {
    probes.iter().map(|p| p.clearance - signed_distance(model, &p.point)).fold(0.0, f64::max)
}

/// Outcome of the tilt search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adjusted {
    /// The tilt used (radians).
    pub tilt: f64,
    /// Penetration at that tilt (mm).
    pub gouge: f64,
}

/// The tilt nearest `start` inside `[lo, hi]` at which `gouge(tilt)` ≤ `tol`: candidates every
/// `step` outwards from `start` on both sides, the first clear one refined by bisection towards
/// `start` to `angle_tol`. Keeps `start` when no candidate clears.
pub fn adjust(start: f64, lo: f64, hi: f64, tol: f64, gouge: impl Fn(f64) -> f64) -> Adjusted {
    let g0 = gouge(start);
    if g0 <= tol {
        return Adjusted { tilt: start, gouge: g0 };
    }
    let step = ADJUST_STEP;
    let mut k = 1;
    loop {
        let d = step * k as f64;
        let candidates = [start - d, start + d];
        if candidates.iter().all(|&c| c < lo - step || c > hi + step) {
            return Adjusted { tilt: start, gouge: g0 };
        }
        for c in candidates {
            let c = c.clamp(lo, hi);
            let g = gouge(c);
            if g <= tol {
                // Bisect between the clear candidate and the gouging one a step nearer start.
                let (mut bad, mut good, mut gg) = (c + (start - c).signum() * step.min((start - c).abs()), c, g);
                while (good - bad).abs() > ADJUST_ANGLE_TOL {
                    let mid = 0.5 * (good + bad);
                    let gm = gouge(mid);
                    if gm <= tol { (good, gg) = (mid, gm) } else { bad = mid }
                }
                return Adjusted { tilt: good, gouge: gg };
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
    use camkit::geom::V3;
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
            let part = Part::new(model, &tool, 40.0, 1e-4, true).unwrap();
            let got = part.penetration(&pose);
            let sagitta = r * (1.0 - (std::f64::consts::PI / n as f64).cos());
            prop_assert!((got - exact.max(0.0)).abs() <= sagitta + 1e-6, "gouge {got}, exact {exact}");
        }
    }

    #[test]
    fn adjust_finds_the_nearest_clear_tilt() {
        // Gouge whenever tilt > −0.3: the clear tilt nearest −0.1 is −0.3.
        let a = adjust(-0.1, -0.35, 0.0, 1e-9, |t| (t + 0.3).max(0.0));
        assert!((a.tilt + 0.3).abs() <= ADJUST_ANGLE_TOL && a.gouge <= 1e-9, "{a:?}");
        // Nothing clear inside the range: the start is kept and reported.
        let a = adjust(-0.1, -0.2, 0.0, 1e-9, |t| (t + 0.3).max(0.0));
        assert_eq!(a.tilt, -0.1);
        assert!(a.gouge > 0.0);
    }
}
