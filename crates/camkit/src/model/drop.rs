//! The drop-cutter on a whole model for a fixed tool axis: the highest tool tip along the axis at
//! which a [`Cutter`] touches the model, with the contact point and the model's normal there.
//!
//! The model is turned once into the axis frame (the tool axis becomes +z; the frame is the
//! shortest rotation taking the axis to +z, so for 0,0,1 it is the model's own). Meshes are
//! dropped onto exactly (facet, vertex and edge tests of [`super::cutter`]), pruned by a
//! hierarchy of boxes in that frame: a box outside the cutter's shadow, or whose top less the
//! cutter's height at the box's distance from the axis (a bound of every tip it can give) is not
//! above the best tip so far, is skipped. Planes, spheres and cylinders across or along the axis
//! have closed forms. Other surfaces (cones, tori, cylinders at a slant, free-form
//! patches) are refused by [`DropCutter::new`]: tessellate them to STL.

use super::analytic::Analytic;
use super::bvh::{Aabb, Bvh};
use super::cutter::{Cutter, Touch};
use super::{Geometry, Model};
use crate::geom::{P3, V3};
use nalgebra::{Isometry3, UnitQuaternion};

/// The rotation from the model's frame to the axis frame (tool axis → +z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisFrame {
    /// The tool axis (unit, model frame).
    pub axis: V3,
    rotation: UnitQuaternion<f64>,
}

impl AxisFrame {
    /// The frame of the unit `axis`: the shortest rotation taking it to +z (a half turn about x
    /// for −z).
    pub fn new(axis: V3) -> AxisFrame {
        let axis = axis.normalize();
        let rotation = UnitQuaternion::rotation_between(&axis, &V3::z())
            .unwrap_or_else(|| UnitQuaternion::from_axis_angle(&V3::x_axis(), std::f64::consts::PI));
        AxisFrame { axis, rotation }
    }

    /// A model point in the axis frame.
    pub fn to_frame(&self, p: &P3) -> P3 {
        self.rotation * p
    }

    /// An axis-frame point in the model's frame.
    pub fn to_model(&self, p: &P3) -> P3 {
        self.rotation.inverse_transform_point(p)
    }

    /// An axis-frame vector in the model's frame.
    pub fn vector_to_model(&self, v: &V3) -> V3 {
        self.rotation.inverse_transform_vector(v)
    }
}

/// One surface in the axis frame.
#[derive(Clone, Debug)]
enum Part {
    /// Triangles (corners, unit normal with n.z ≥ 0) in the hierarchy's order.
    Mesh { tris: Vec<([P3; 3], V3)>, index: Bvh },
    /// A plane not along the axis: a point and the unit normal with n.z > 0.
    Plane { point: P3, normal: V3 },
    /// A sphere.
    Sphere { centre: P3, radius: f64 },
    /// A cylinder across the axis: a point of its axis, the unit (horizontal) axis, the radius,
    /// its extent along the axis.
    Across { point: P3, axis: V3, radius: f64, from: f64, to: f64 },
    /// A finite cylinder along the axis: its upper rim (centre and radius).
    Rim { centre: P3, radius: f64 },
}

/// A surface the drop-cutter does not handle, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Unsupported {
    /// Index of the surface.
    pub surface: usize,
    /// What is wrong.
    pub what: String,
}

/// The drop at one point: tip, contact and the model's unit normal there (model frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drop {
    /// Tool tip.
    pub tip: P3,
    /// Contact point on the model.
    pub contact: P3,
    /// Unit normal of the model at the contact, pointing into the cutter.
    pub normal: V3,
    /// Index of the surface touched.
    pub surface: usize,
}

/// A model ready for drops of one cutter along one axis.
#[derive(Clone, Debug)]
pub struct DropCutter {
    /// The cutter.
    pub cutter: Cutter,
    /// The axis frame.
    pub frame: AxisFrame,
    parts: Vec<(Part, Aabb)>,
}

/// Cosine below which a direction counts as across the axis, and 1 − above which along it.
const ACROSS: f64 = 1e-12;

impl DropCutter {
    /// The model turned into the frame of `axis`, every surface checked.
    pub fn new(model: &Model, cutter: Cutter, axis: V3) -> Result<DropCutter, Unsupported> {
        let frame = AxisFrame::new(axis);
        let mut parts = Vec::with_capacity(model.surfaces.len());
        for (i, s) in model.surfaces.iter().enumerate() {
            let place = frame_of(&frame, s.placement.as_ref());
            let pt = |p: &P3| place * p;
            let vec = |v: &V3| place * v;
            let refuse = |what: &str| Unsupported { surface: i, what: what.to_string() };
            let part = match &s.geometry {
                Geometry::Mesh(m) => {
                    let tris: Vec<([P3; 3], V3)> = m
                        .corners()
                        .map(|t| {
                            let t = t.map(|p| pt(&p));
                            let n = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
                            (t, if n.z < 0.0 { -n } else { n })
                        })
                        .collect();
                    let boxes: Vec<Aabb> = tris.iter().map(|(t, _)| Aabb::of(t)).collect();
                    let index = Bvh::build(&boxes);
                    let tris = index.order.iter().map(|&k| tris[k as usize]).collect();
                    Part::Mesh { tris, index }
                }
                Geometry::Analytic(Analytic::Plane { point, normal }) => {
                    let n = vec(normal);
                    if n.z.abs() <= ACROSS {
                        return Err(refuse("a plane along the tool axis has no top for the cutter to rest on"));
                    }
                    Part::Plane { point: pt(point), normal: if n.z < 0.0 { -n } else { n } }
                }
                Geometry::Analytic(Analytic::Sphere { centre, radius }) => {
                    Part::Sphere { centre: pt(centre), radius: *radius }
                }
                Geometry::Analytic(Analytic::Cylinder { point, axis, radius, from, to }) => {
                    let (p, a) = (pt(point), vec(axis));
                    if a.z.abs() <= ACROSS {
                        let a = V3::new(a.x, a.y, 0.0).normalize();
                        if from.is_finite() || to.is_finite() {
                            return Err(refuse(
                                "a cylinder of finite length across the tool axis (its end circles are not handled): give it no length, or tessellate it",
                            ));
                        }
                        Part::Across { point: p, axis: a, radius: *radius, from: *from, to: *to }
                    } else if a.z.abs() >= 1.0 - ACROSS {
                        if !(from.is_finite() && to.is_finite()) {
                            return Err(refuse("an endless cylinder along the tool axis has no top"));
                        }
                        let top = if a.z > 0.0 { *to } else { *from };
                        let centre = p + a * top;
                        Part::Rim { centre, radius: *radius }
                    } else {
                        return Err(refuse("a cylinder at a slant to the tool axis: tessellate it to STL"));
                    }
                }
                Geometry::Analytic(Analytic::Cone { .. }) => {
                    return Err(refuse("cone surfaces are not handled by the drop-cutter: tessellate them to STL"));
                }
                Geometry::Analytic(Analytic::Torus { .. }) => {
                    return Err(refuse("torus surfaces are not handled by the drop-cutter: tessellate them to STL"));
                }
                Geometry::Patch(_) => {
                    return Err(refuse("free-form patches are not handled by the drop-cutter: tessellate them to STL"));
                }
                Geometry::Face(_) => {
                    return Err(refuse(
                        "trimmed STEP faces are not handled by the drop-cutter: tessellate them to STL",
                    ));
                }
            };
            let bounds = part_bounds(&part);
            parts.push((part, bounds));
        }
        Ok(DropCutter { cutter, frame, parts })
    }

    /// A box holding the model in the axis frame (unbounded if any surface is).
    pub fn bounds(&self) -> Aabb {
        self.parts.iter().fold(Aabb::empty(), |b, (_, pb)| b.union(pb))
    }

    /// The drop at (u, v) of the axis frame: the highest tip touching the model, or `None` where
    /// nothing of the model is under the cutter.
    pub fn drop(&self, u: f64, v: f64) -> Option<Drop> {
        let q = [u, v];
        let big_r = self.cutter.radius();
        let shadow = |b: &Aabb| {
            let dx = (b.min.x - u).max(u - b.max.x).max(0.0);
            let dy = (b.min.y - v).max(v - b.max.y).max(0.0);
            dx * dx + dy * dy <= big_r * big_r
        };
        let mut best: Option<(Touch, V3, usize)> = None;
        for (i, (part, bounds)) in self.parts.iter().enumerate() {
            if !shadow(bounds) || best.is_some_and(|(t, _, _)| bounds.max.z <= t.tip) {
                continue;
            }
            let floor = best.map_or(f64::NEG_INFINITY, |(t, _, _)| t.tip);
            let found = self.drop_part(q, part, floor);
            if let Some((t, n)) = found {
                if best.is_none_or(|(b, _, _)| t.tip > b.tip) {
                    best = Some((t, n, i));
                }
            }
        }
        let (t, n, surface) = best?;
        let normal = self.cutter.contact_normal(q, t.tip, &t.contact, n);
        Some(Drop {
            tip: self.frame.to_model(&P3::new(u, v, t.tip)),
            contact: self.frame.to_model(&t.contact),
            normal: self.frame.vector_to_model(&normal),
            surface,
        })
    }

    /// The drop onto one part above `floor`: the touch and the part's normal at the contact.
    fn drop_part(&self, q: [f64; 2], part: &Part, floor: f64) -> Option<(Touch, V3)> {
        let c = &self.cutter;
        match part {
            Part::Mesh { tris, index } => {
                // No point of a box is nearer the axis than the box itself, and f grows with ρ:
                // its top less f at that distance bounds every tip it can give.
                let bound = |b: &Aabb| {
                    let dx = (b.min.x - q[0]).max(q[0] - b.max.x).max(0.0);
                    let dy = (b.min.y - q[1]).max(q[1] - b.max.y).max(0.0);
                    let rho = dx.hypot(dy);
                    // Taken 1e-9 nearer: rounding of ρ must not lower the bound where f is steep
                    // (at the rim of a ball or bull-nose f′ is infinite).
                    let top =
                        if rho <= c.radius() { b.max.z - c.height((rho - 1e-9).max(0.0)) } else { f64::NEG_INFINITY };
                    if top > floor { top } else { f64::NEG_INFINITY }
                };
                index
                    .maximise(bound, |k, best| {
                        let (t, n) = &tris[k];
                        // The triangle's own box bounds its tips as a node's does.
                        if bound(&Aabb::of(t)) <= best.max(floor) {
                            return None;
                        }
                        c.drop_triangle(q, t, n, best.max(floor)).map(|touch| (touch.tip, (touch, *n)))
                    })
                    .map(|(_, found)| found)
            }
            Part::Plane { point, normal } => Some((c.drop_plane(q, point, normal), *normal)),
            Part::Sphere { centre, radius } => {
                let (dx, dy) = (centre.x - q[0], centre.y - q[1]);
                let d = dx.hypot(dy);
                let (ux, uy) = if d > 0.0 { (dx / d, dy / d) } else { (1.0, 0.0) };
                let (tip, along, z) = c.drop_circle(d, centre.z, *radius)?;
                let contact = P3::new(q[0] + ux * along, q[1] + uy * along, z);
                Some((Touch { tip, contact }, (contact - centre) / *radius))
            }
            Part::Across { point, axis, radius, from, to } => {
                let w = (q[0] - point.x) * axis.x + (q[1] - point.y) * axis.y;
                if !(*from..=*to).contains(&w) {
                    return None;
                }
                let foot = point + axis * w;
                let (dx, dy) = (foot.x - q[0], foot.y - q[1]);
                let d = dx.hypot(dy);
                let (ux, uy) = if d > 0.0 { (dx / d, dy / d) } else { (-axis.y, axis.x) };
                let (tip, along, z) = c.drop_circle(d, foot.z, *radius)?;
                let contact = P3::new(q[0] + ux * along, q[1] + uy * along, z);
                Some((Touch { tip, contact }, (contact - foot) / *radius))
            }
            Part::Rim { centre, radius } => {
                let (dx, dy) = (q[0] - centre.x, q[1] - centre.y);
                let d = dx.hypot(dy);
                let (ux, uy) = if d > 0.0 { (dx / d, dy / d) } else { (1.0, 0.0) };
                let rho = (d - radius).abs();
                if rho > c.radius() {
                    return None;
                }
                let contact = P3::new(centre.x + ux * radius, centre.y + uy * radius, centre.z);
                Some((Touch { tip: centre.z - c.height(rho), contact }, V3::new(ux, uy, 0.0)))
            }
        }
    }
}

/// The rigid motion from a surface's own frame to the axis frame.
fn frame_of(frame: &AxisFrame, placement: Option<&Isometry3<f64>>) -> Isometry3<f64> {
    let turn = Isometry3::from_parts(nalgebra::Translation3::identity(), frame.rotation);
    match placement {
        Some(p) => turn * p,
        None => turn,
    }
}

/// A box holding a part (axis frame).
fn part_bounds(part: &Part) -> Aabb {
    match part {
        Part::Mesh { index, .. } => index.bounds(),
        Part::Plane { .. } | Part::Across { .. } => Aabb::everything(),
        Part::Sphere { centre, radius } => {
            Aabb { min: centre - V3::repeat(*radius), max: centre + V3::repeat(*radius) }
        }
        Part::Rim { centre, radius } => {
            Aabb { min: centre - V3::new(*radius, *radius, 0.0), max: centre + V3::new(*radius, *radius, 0.0) }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::Input;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// On a random height-field mesh along a random axis, the pruned drop is the highest of
        /// every triangle's exact drop, and no sampled point of the mesh is above the cutter.
        #[test]
        fn pruned_drop_is_the_brute_force_one(
            heights in prop::collection::vec(-2.0..2.0f64, 49),
            c in prop_oneof![
                (0.3..4.0f64).prop_map(|radius| Cutter::Flat { radius }),
                (0.3..4.0f64).prop_map(|radius| Cutter::Ball { radius }),
                (0.3..4.0f64, 0.1..1.0f64).prop_map(|(radius, k)| Cutter::Bull { radius, corner: radius * k }),
                (0.3..4.0f64, 0.3..1.3f64).prop_map(|(radius, half_angle)| Cutter::Cone { radius, half_angle }),
            ],
            axis in prop::array::uniform3(-0.4..0.4f64),
            q in prop::array::uniform2(-2.0..8.0f64),
        ) {
            let p = |i: usize, j: usize| P3::new(i as f64, j as f64 + 0.3 * i as f64, heights[7 * i + j]);
            let mut tris = Vec::new();
            for i in 0..6 {
                for j in 0..6 {
                    tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                    tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
                }
            }
            let mesh = super::super::mesh::Mesh::new(&tris).unwrap();
            let m = Model { surfaces: vec![super::super::Surface::new("m".into(), Geometry::Mesh(mesh), None, false)] };
            let axis = V3::new(axis[0], axis[1], 1.0).normalize();
            let dc = DropCutter::new(&m, c, axis).unwrap();
            let frame = dc.frame;
            let mut brute: Option<Touch> = None;
            let mut samples = f64::NEG_INFINITY;
            for t in &tris {
                let t = t.map(|v| frame.to_frame(&v));
                let n = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
                brute = Touch::max(brute, c.drop_triangle(q, &t, &if n.z < 0.0 { -n } else { n }, f64::NEG_INFINITY));
                for a in 0..=20 {
                    for b in 0..=20 - a {
                        let s = t[0] + (t[1] - t[0]) * (a as f64 / 20.0) + (t[2] - t[0]) * (b as f64 / 20.0);
                        let rho = (s.x - q[0]).hypot(s.y - q[1]);
                        if rho <= c.radius() {
                            samples = samples.max(s.z - c.height(rho));
                        }
                    }
                }
            }
            let got = dc.drop(q[0], q[1]);
            prop_assert_eq!(got.is_some(), brute.is_some());
            if let (Some(g), Some(b)) = (got, brute) {
                let tip = frame.to_frame(&g.tip);
                prop_assert!((tip.z - b.tip).abs() <= 1e-12 * (1.0 + b.tip.abs()), "{} vs {}", tip.z, b.tip);
                prop_assert!(samples <= tip.z + 1e-9, "a sample is {} above", samples - tip.z);
                prop_assert!((g.normal.norm() - 1.0).abs() < 1e-9);
            }
        }
    }

    fn model(text: &str) -> Model {
        Model::load(&Input { name: "m.json".into(), data: text.as_bytes().to_vec() }).unwrap()
    }

    const CUTTERS: [Cutter; 4] = [
        Cutter::Flat { radius: 3.0 },
        Cutter::Ball { radius: 3.0 },
        Cutter::Bull { radius: 3.0, corner: 1.0 },
        Cutter::Cone { radius: 3.0, half_angle: 0.6 },
    ];

    /// The largest g = p·axis − f(ρ) over points of the model given by `sample`, for an
    /// independent check of the closed forms.
    fn sampled(c: &Cutter, frame: &AxisFrame, q: [f64; 2], points: &[P3]) -> f64 {
        let mut best = f64::NEG_INFINITY;
        for p in points {
            let p = frame.to_frame(p);
            let rho = (p.x - q[0]).hypot(p.y - q[1]);
            if rho <= c.radius() {
                best = best.max(p.z - c.height(rho));
            }
        }
        best
    }

    #[test]
    fn flat_on_a_sphere_is_the_closed_form() {
        // Sphere R = 10 at (1, 2, 3), flat R = 3: tip = 3 + 10 on top while the centre is under
        // the disc (d ≤ 3), else 3 + √(100 − (d − 3)²) (the rim on the sphere).
        let m = model(r#"{"surfaces": [{"type": "sphere", "centre": [1,2,3], "radius": 10}]}"#);
        let dc = DropCutter::new(&m, Cutter::Flat { radius: 3.0 }, V3::z()).unwrap();
        for d in [0.0, 2.0, 3.0, 5.0, 9.0, 12.9] {
            let want = 3.0 + (100.0 - (d - 3.0f64).max(0.0).powi(2)).sqrt();
            let got = dc.drop(1.0 + d, 2.0).unwrap();
            assert!((got.tip.z - want).abs() < 1e-12, "d {d}: {} vs {want}", got.tip.z);
            assert!(((got.contact - P3::new(1.0, 2.0, 3.0)).norm() - 10.0).abs() < 1e-12);
        }
        assert!(dc.drop(14.5, 2.0).is_none());
    }

    #[test]
    fn bull_on_a_cylinder_is_the_closed_form() {
        // Cylinder R = 5 along x at height 0, bull R = 3, r = 1: the disc of radius 2 at height
        // tip + 1 is 6 from the axis: tip = √(36 − max(e − 2, 0)²) − 1, e the offset in y.
        let m = model(r#"{"surfaces": [{"type": "cylinder", "point": [0,0,0], "axis": [1,0,0], "radius": 5}]}"#);
        let c = Cutter::Bull { radius: 3.0, corner: 1.0 };
        let dc = DropCutter::new(&m, c, V3::z()).unwrap();
        for e in [0.0, 1.5, 2.0, 4.0, 7.5] {
            let want = (36.0 - (e - 2.0f64).max(0.0).powi(2)).sqrt() - 1.0;
            let got = dc.drop(0.7, e).unwrap();
            assert!((got.tip.z - want).abs() < 1e-12, "e {e}: {} vs {want}", got.tip.z);
            assert!((got.contact.y.hypot(got.contact.z) - 5.0).abs() < 1e-12);
            // The normal points from the cylinder's axis through the contact.
            assert!((got.normal - V3::new(0.0, got.contact.y, got.contact.z) / 5.0).norm() < 1e-9);
        }
    }

    #[test]
    fn closed_forms_agree_with_sampling() {
        // Every cutter on a sphere, a cylinder across, a cylinder along (its rim) and a plane,
        // on a tilted axis too: the exact tip is at least every sampled point's g and close to
        // the best of them.
        let axes = [V3::z(), V3::new(0.3, -0.2, 1.0).normalize()];
        let sphere: Vec<P3> = (0..400)
            .flat_map(|i| {
                (0..800).map(move |j| {
                    let (t, p) = (std::f64::consts::PI * i as f64 / 399.0, std::f64::consts::TAU * j as f64 / 800.0);
                    P3::new(1.0 + 4.0 * t.sin() * p.cos(), 4.0 * t.sin() * p.sin(), -1.0 + 4.0 * t.cos())
                })
            })
            .collect();
        let m = model(r#"{"surfaces": [{"type": "sphere", "centre": [1,0,-1], "radius": 4}]}"#);
        for axis in axes {
            let frame = AxisFrame::new(axis);
            for c in CUTTERS {
                let dc = DropCutter::new(&m, c, axis).unwrap();
                for (u, v) in [(0.0, 0.0), (2.5, 1.0), (-4.0, 3.0), (5.5, -1.0)] {
                    let got = dc.drop(u, v);
                    let brute = sampled(&c, &frame, [u, v], &sphere);
                    match got {
                        None => assert_eq!(brute, f64::NEG_INFINITY),
                        Some(g) => {
                            let tip = frame.to_frame(&g.tip).z;
                            assert!(
                                brute <= tip + 1e-9 && tip - brute < 0.05,
                                "{c:?} {axis} ({u},{v}): {tip} vs {brute}"
                            );
                            assert!((frame.to_frame(&g.tip).x - u).abs() < 1e-12);
                        }
                    }
                }
            }
        }
        let cyl: Vec<P3> = (0..2000)
            .flat_map(|i| {
                (0..100).map(move |j| {
                    let t = std::f64::consts::TAU * i as f64 / 2000.0;
                    P3::new(-5.0 + 0.1 * j as f64, 2.0 * t.cos(), 1.0 + 2.0 * t.sin())
                })
            })
            .collect();
        let m = model(r#"{"surfaces": [{"type": "cylinder", "point": [0,0,1], "axis": [1,0,0], "radius": 2}]}"#);
        let frame = AxisFrame::new(V3::z());
        for c in CUTTERS {
            let dc = DropCutter::new(&m, c, V3::z()).unwrap();
            for v in [0.0, 1.0, 2.7, 4.5] {
                let tip = dc.drop(0.0, v).unwrap().tip.z;
                let brute = sampled(&c, &frame, [0.0, v], &cyl);
                assert!(brute <= tip + 1e-9 && tip - brute < 0.02, "{c:?} v {v}: {tip} vs {brute}");
            }
        }
        // A finite cylinder along the axis: the cutter rests on its upper rim.
        let rim: Vec<P3> = (0..20000)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / 20000.0;
                P3::new(2.0 * t.cos(), 2.0 * t.sin(), 7.0)
            })
            .collect();
        let m = model(
            r#"{"surfaces": [{"type": "cylinder", "point": [0,0,1], "axis": [0,0,-1], "radius": 2, "length": [-6, 0]}]}"#,
        );
        for c in CUTTERS {
            let dc = DropCutter::new(&m, c, V3::z()).unwrap();
            for u in [0.0, 1.0, 3.0, 4.5] {
                let tip = dc.drop(u, 0.2).unwrap().tip.z;
                let brute = sampled(&c, &frame, [u, 0.2], &rim);
                assert!(brute <= tip + 1e-9 && tip - brute < 0.01, "{c:?} u {u}: {tip} vs {brute}");
            }
        }
    }

    #[test]
    fn mesh_drop_is_the_highest_triangle_and_axis_turns() {
        // Two triangles making a roof along y; the ball rests on the ridge edge.
        let tris = [
            [P3::new(-5.0, -5.0, 0.0), P3::new(0.0, -5.0, 2.0), P3::new(0.0, 5.0, 2.0)],
            [P3::new(0.0, -5.0, 2.0), P3::new(5.0, -5.0, 0.0), P3::new(0.0, 5.0, 2.0)],
        ];
        let mesh = super::super::mesh::Mesh::new(&tris).unwrap();
        let m = Model { surfaces: vec![super::super::Surface::new("roof".into(), Geometry::Mesh(mesh), None, false)] };
        let dc = DropCutter::new(&m, Cutter::Ball { radius: 1.0 }, V3::z()).unwrap();
        let d = dc.drop(0.0, 0.0).unwrap();
        assert!((d.tip.z - 2.0).abs() < 1e-12 && (d.contact - P3::new(0.0, 0.0, 2.0)).norm() < 1e-12);
        assert!((d.normal - V3::z()).norm() < 1e-12);
        // Along −z the cutter comes from below (the frame turns half about x: y and z change
        // sign): under the corner (5, −5, 0) it rests on that corner.
        let dc = DropCutter::new(&m, Cutter::Flat { radius: 1.0 }, -V3::z()).unwrap();
        let d = dc.drop(4.5, 4.5).unwrap();
        assert!(d.tip.z.abs() < 1e-12 && (d.contact - P3::new(5.0, -5.0, 0.0)).norm() < 1e-12, "{d:?}");
        assert!((dc.frame.to_frame(&d.tip) - P3::new(4.5, 4.5, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn refuses_what_it_cannot_drop_onto() {
        let m = model(
            r#"{"surfaces": [{"type": "torus", "centre": [0,0,0], "axis": [0,0,1], "major_radius": 5, "minor_radius": 1}]}"#,
        );
        let e = DropCutter::new(&m, Cutter::Ball { radius: 1.0 }, V3::z()).unwrap_err();
        assert!(e.what.contains("torus"), "{e:?}");
        let m = model(r#"{"surfaces": [{"type": "plane", "point": [0,0,0], "normal": [1,0,0]}]}"#);
        assert!(DropCutter::new(&m, Cutter::Ball { radius: 1.0 }, V3::z()).is_err());
        assert!(DropCutter::new(&m, Cutter::Ball { radius: 1.0 }, V3::x()).is_ok());
    }
}
