//! The drop-cutter on a whole model for a fixed tool axis: the highest tool tip along the axis at
//! which a [`Cutter`] touches the model, with the contact point and the model's normal there.
//!
//! The model is turned once into the axis frame (the tool axis becomes +z; the frame is the
//! shortest rotation taking the axis to +z, so for 0,0,1 it is the model's own). Meshes are
//! dropped onto exactly (facet, vertex and edge tests of [`super::cutter`]), pruned by a
//! hierarchy of boxes in that frame: a box outside the cutter's shadow, or whose top less the
//! cutter's height at the box's distance from the axis (a bound of every tip it can give) is not
//! above the best tip so far, is skipped; so is one whose slab (the plane of its triangles' mean
//! normal through its highest corner along it) gives no tip above the best, and a triangle whose
//! own plane does not. Each corner and edge shared by several triangles is tested in one of
//! them, and a drop along a line starts from the tip touching the contact before. Planes, spheres and cylinders across or along the axis
//! have closed forms, and so have a ball on an endless cylinder at a slant and a flat, ball or
//! bull-nose on a torus or a finite cone along the axis. Every other surface (B-spline patches,
//! trimmed STEP faces, finite cylinders across the axis or at a slant, endless ones at a slant
//! under a flat, bull-nose or cone, cones and tori at any angle or under a cone cutter) is made
//! exact rational Bézier patches and searched by [`super::sheet`] to its 1e-9 mm. Only what has
//! no top along the axis (a plane along it, an endless cylinder along it, a cylinder or cone
//! endless one way) is refused by [`DropCutter::new`].

use super::analytic::Analytic;
use super::bvh::{Aabb, Bvh};
use super::cutter::{Cutter, Facet, Owned, Plane, Touch};
use super::sheet::{Sheet, Trim, analytic_pieces, face_pieces};
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
    /// Triangles in the hierarchy's order with their boxes (a bound of a triangle's tips as a
    /// node's is), and each node's slab.
    Mesh { tris: Vec<(Facet, Aabb)>, index: Bvh, slabs: Vec<Option<Plane>> },
    /// A plane not along the axis: a point and the unit normal with n.z > 0.
    Plane { point: P3, normal: V3 },
    /// A sphere.
    Sphere { centre: P3, radius: f64 },
    /// A cylinder across the axis: a point of its axis, the unit (horizontal) axis, the radius,
    /// its extent along the axis.
    Across { point: P3, axis: V3, radius: f64, from: f64, to: f64 },
    /// A finite cylinder along the axis: its upper rim (centre and radius).
    Rim { centre: P3, radius: f64 },
    /// An endless cylinder at a slant, for a ball: a point of its axis, the unit axis, the radius.
    Slant { point: P3, axis: V3, radius: f64 },
    /// A torus whose axis is along the tool axis, for a flat, ball or bull-nose: centre, radii.
    Torus { centre: P3, major: f64, minor: f64 },
    /// A finite cone along the tool axis, for a flat, ball or bull-nose: a point of its axis and
    /// its section's ends (distance from the axis, height).
    Revolved { centre: P3, ends: [[f64; 2]; 2] },
    /// Smooth pieces (B-spline patches, a face's carrier, other finite analytic surfaces) as
    /// rational Bézier patches, searched by [`Sheet::drop`].
    Sheet(Sheet),
    /// An endless cylinder at a slant, for a flat, bull-nose or cone: a point of its axis, the
    /// unit axis, the radius (the length under the cutter made a sheet at each drop).
    Tube { point: P3, axis: V3, radius: f64 },
}

/// The bits of a point (−0 as 0): equal points give equal drops.
fn point_key(p: &P3) -> [u64; 3] {
    [p.x, p.y, p.z].map(|v| (v + 0.0).to_bits())
}

/// The triangles of a mesh (corners in the axis frame, in the hierarchy's order) ready for
/// `cutter`, with their boxes. Each shared corner and edge is tested by the first triangle
/// holding it, which is searched whenever the feature can give the best tip (its box holds it).
fn facets(cutter: &Cutter, tris: Vec<[P3; 3]>) -> Vec<(Facet, Aabb)> {
    use std::collections::{HashMap, HashSet};
    let mut corners: HashSet<[u64; 3]> = HashSet::with_capacity(tris.len());
    // Edge (lower key first) → its first triangle, its edge number there, and whether it runs
    // from the lower key.
    type Key = [u64; 3];
    let mut edges: HashMap<(Key, Key), (usize, usize, bool)> = HashMap::with_capacity(2 * tris.len());
    let mut out: Vec<(Facet, Aabb)> = Vec::with_capacity(tris.len());
    for (i, t) in tris.into_iter().enumerate() {
        let n = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
        let keys = t.map(|p| point_key(&p));
        let mut own = Owned { corners: 0, edges: 0, reversed: 0 };
        for k in 0..3 {
            if corners.insert(keys[k]) {
                own.corners |= 1 << k;
            }
            let (a, b) = (keys[k], keys[(k + 1) % 3]);
            let up = a <= b;
            let key = if up { (a, b) } else { (b, a) };
            match edges.get(&key) {
                None => {
                    edges.insert(key, (i, k, up));
                    own.edges |= 1 << k;
                }
                Some(&(first, j, way)) if way != up => {
                    out[first].0.own.reversed |= 1 << j;
                }
                Some(_) => {}
            }
        }
        out.push((Facet::new(cutter, t, if n.z < 0.0 { -n } else { n }, own), Aabb::of(&t)));
    }
    out
}

/// Each node's slab: the plane of the mean normal of its triangles (taken if n.z ≥ 0.1) through
/// its corner highest along that normal. Everything under the node lies below that plane, so the
/// drop onto the plane bounds its tips; on a smooth mesh the plane hugs the node's triangles far
/// more closely than its box's top does on a slope.
fn slabs(cutter: &Cutter, tris: &[(Facet, Aabb)], index: &Bvh) -> Vec<Option<Plane>> {
    index
        .spans()
        .into_iter()
        .map(|span| {
            let tris = &tris[span];
            // Area-weighted: each triangle's normal (n.z ≥ 0) times its doubled area.
            let sum =
                tris.iter().fold(V3::zeros(), |s, (f, _)| s + f.n * (f.t[1] - f.t[0]).cross(&(f.t[2] - f.t[0])).norm());
            let n = sum.try_normalize(1e-300)?;
            if n.z < 0.1 {
                return None;
            }
            let top =
                tris.iter().flat_map(|(f, _)| f.t).max_by(|a, b| n.dot(&a.coords).total_cmp(&n.dot(&b.coords)))?;
            Some(Plane::new(cutter, top, n))
        })
        .collect()
}

/// What a bound by a plane is raised by for rounding (mm): the plane's drop and the features'
/// tips round differently, by far less than this for models within a few metres.
pub const PLANE_MARGIN: f64 = 1e-9;

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
        DropCutter::build(model, cutter, axis, true)
    }

    /// [`DropCutter::new`] where every surface has a closed form (meshes too), refusing those
    /// searched by [`super::sheet`]: for the quick start heights of stylus-trace's scan and the
    /// relief grid of plots, which fall back to nearest points there.
    pub fn closed_forms(model: &Model, cutter: Cutter, axis: V3) -> Result<DropCutter, Unsupported> {
        DropCutter::build(model, cutter, axis, false)
    }

    /// [`DropCutter::new`], with the searched surfaces if `search`.
    fn build(model: &Model, cutter: Cutter, axis: V3, search: bool) -> Result<DropCutter, Unsupported> {
        let frame = AxisFrame::new(axis);
        let mut parts = Vec::with_capacity(model.surfaces.len());
        for (i, s) in model.surfaces.iter().enumerate() {
            let place = frame_of(&frame, s.placement.as_ref());
            let pt = |p: &P3| place * p;
            let vec = |v: &V3| place * v;
            let refuse = |what: &str| Unsupported { surface: i, what: what.to_string() };
            let part = match &s.geometry {
                Geometry::Mesh(m) => {
                    let tris: Vec<[P3; 3]> = m.corners().map(|t| t.map(|p| pt(&p))).collect();
                    let boxes: Vec<Aabb> = tris.iter().map(|t| Aabb::of(t)).collect();
                    let index = Bvh::build(&boxes);
                    let tris = facets(&cutter, index.order.iter().map(|&k| tris[k as usize]).collect());
                    let slabs = slabs(&cutter, &tris, &index);
                    Part::Mesh { tris, index, slabs }
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
                Geometry::Analytic(whole @ Analytic::Cylinder { point, axis, radius, from, to }) => {
                    let (p, a) = (pt(point), vec(axis));
                    if a.z.abs() <= ACROSS {
                        let a = V3::new(a.x, a.y, 0.0).normalize();
                        if from.is_finite() && to.is_finite() {
                            sheet(whole, &place)
                        } else if from.is_finite() || to.is_finite() {
                            return Err(refuse(
                                "a cylinder across the tool axis endless one way only: give it both ends or none",
                            ));
                        } else {
                            Part::Across { point: p, axis: a, radius: *radius, from: *from, to: *to }
                        }
                    } else if a.z.abs() >= 1.0 - ACROSS {
                        if !(from.is_finite() && to.is_finite()) {
                            return Err(refuse("an endless cylinder along the tool axis has no top"));
                        }
                        let top = if a.z > 0.0 { *to } else { *from };
                        let centre = p + a * top;
                        Part::Rim { centre, radius: *radius }
                    } else if !from.is_finite() && !to.is_finite() {
                        if matches!(cutter, Cutter::Ball { .. }) {
                            Part::Slant { point: p, axis: a, radius: *radius }
                        } else {
                            Part::Tube { point: p, axis: a, radius: *radius }
                        }
                    } else if from.is_finite() && to.is_finite() {
                        sheet(whole, &place)
                    } else {
                        return Err(refuse(
                            "a cylinder at a slant to the tool axis endless one way only: give it both ends or none",
                        ));
                    }
                }
                Geometry::Analytic(whole @ Analytic::Cone { apex, axis, half_angle, from, to }) => {
                    let a = vec(axis);
                    if !(from.is_finite() && to.is_finite()) {
                        return Err(refuse("an endless cone has no top for the cutter to rest on: give it a length"));
                    }
                    if a.z.abs() < 1.0 - ACROSS || matches!(cutter, Cutter::Cone { .. }) {
                        sheet(whole, &place)
                    } else {
                        let apex = pt(apex);
                        let end = |t: f64| [t * half_angle.tan(), apex.z + a.z.signum() * t];
                        Part::Revolved { centre: apex, ends: [end(*from), end(*to)] }
                    }
                }
                Geometry::Analytic(whole @ Analytic::Torus { centre, axis, major, minor }) => {
                    if vec(axis).z.abs() < 1.0 - ACROSS || matches!(cutter, Cutter::Cone { .. }) {
                        sheet(whole, &place)
                    } else {
                        Part::Torus { centre: pt(centre), major: *major, minor: *minor }
                    }
                }
                Geometry::Patch(b) => {
                    Part::Sheet(Sheet::new(b.bezier_pieces().iter().map(|p| p.moved(&place)).collect(), None))
                }
                Geometry::Face(f) => {
                    let trim = Trim::new(f, &place);
                    Part::Sheet(Sheet::new(face_pieces(f).iter().map(|p| p.moved(&place)).collect(), Some(trim)))
                }
            };
            if !search && matches!(part, Part::Sheet(_) | Part::Tube { .. }) {
                return Err(refuse("no closed form: searched by the drop-cutter's branch-and-bound"));
            }
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
        self.drop_near(u, v, None)
    }

    /// [`DropCutter::drop`] given a point `near` of the model (model frame; the contact of the
    /// drop before, along a line) and the surface holding it: the tip touching it is a lower bound
    /// of the drop, so the search prunes with it from the start (taken [`PLANE_MARGIN`] lower, so
    /// the best is never pruned for rounding), and that surface is searched first (its drop is
    /// likely the best, which then prunes the others). The result is the drop's whatever the point.
    pub fn drop_near(&self, u: f64, v: f64, near: Option<(P3, usize)>) -> Option<Drop> {
        let q = [u, v];
        let big_r = self.cutter.radius();
        let first = near.map_or(0, |n| n.1.min(self.parts.len().saturating_sub(1)));
        let start = near.map_or(f64::NEG_INFINITY, |(p, _)| {
            let p = self.frame.to_frame(&p);
            let rho = (p.x - u).hypot(p.y - v);
            // Lower by the sheets' TOL too: they leave out what is not TOL above the floor.
            if rho <= big_r {
                p.z - self.cutter.height(rho) - PLANE_MARGIN - super::sheet::TOL
            } else {
                f64::NEG_INFINITY
            }
        });
        let shadow = |b: &Aabb| {
            let dx = (b.min.x - u).max(u - b.max.x).max(0.0);
            let dy = (b.min.y - v).max(v - b.max.y).max(0.0);
            dx * dx + dy * dy <= big_r * big_r
        };
        let mut best: Option<(Touch, V3, usize)> = None;
        let order = std::iter::once(first).chain((0..self.parts.len()).filter(|&i| i != first));
        for i in order.filter(|&i| i < self.parts.len()) {
            let (part, bounds) = &self.parts[i];
            let floor = best.map_or(start, |(t, _, _)| t.tip.max(start));
            if !shadow(bounds) || bounds.max.z <= floor {
                continue;
            }
            let found = self.drop_part(q, part, floor);
            if let Some((t, n)) = found {
                if best.is_none_or(|(b, _, _)| t.tip > b.tip) {
                    best = Some((t, n, i));
                }
            }
        }
        let Some((t, n, surface)) = best else {
            // Parts give nothing more than TOL above the floor: the start's own part may be one.
            return if start.is_finite() { self.drop_near(u, v, None) } else { None };
        };
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
            Part::Mesh { tris, index, slabs } => {
                // No point of a box is nearer the axis than the box itself, and f grows with ρ:
                // its top less f at that distance bounds every tip it can give.
                let bound = |b: &Aabb| {
                    let dx = (b.min.x - q[0]).max(q[0] - b.max.x).max(0.0);
                    let dy = (b.min.y - q[1]).max(q[1] - b.max.y).max(0.0);
                    let rho = (dx * dx + dy * dy).sqrt();
                    // Taken 1e-9 nearer: rounding of ρ must not lower the bound where f is steep
                    // (at the rim of a ball or bull-nose f′ is infinite).
                    let top =
                        if rho <= c.radius() { b.max.z - c.height((rho - 1e-9).max(0.0)) } else { f64::NEG_INFINITY };
                    if top > floor { top } else { f64::NEG_INFINITY }
                };
                let node_bound = |n: usize, b: &Aabb| {
                    let top = bound(b);
                    match &slabs[n] {
                        Some(p) if top > f64::NEG_INFINITY => {
                            let top = top.min(c.drop_on(q, p).tip + PLANE_MARGIN);
                            if top > floor { top } else { f64::NEG_INFINITY }
                        }
                        _ => top,
                    }
                };
                index
                    .maximise(node_bound, |k, best| {
                        let (f, b) = &tris[k];
                        // The triangle's own box bounds its tips as a node's does.
                        let floor = best.max(floor);
                        if bound(b) <= floor {
                            return None;
                        }
                        c.drop_facet(q, f, floor).map(|touch| (touch.tip, (touch, f.n)))
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
            Part::Slant { point, axis, radius } => {
                // The ball's centre (q, z) is R + r from the axis where it touches: |A + zB|² =
                // (R + r)² with A = (q − point) × axis, B = z × axis; the higher root.
                let big_r = c.radius();
                let a = V3::new(q[0] - point.x, q[1] - point.y, -point.z).cross(axis);
                let b = V3::z().cross(axis);
                let (bb, ab) = (b.norm_squared(), a.dot(&b));
                let disc = ab * ab - bb * (a.norm_squared() - (radius + big_r).powi(2));
                if disc < 0.0 {
                    return None;
                }
                let z = (disc.sqrt() - ab) / bb;
                let centre = P3::new(q[0], q[1], z);
                let foot = point + axis * (centre - point).dot(axis);
                let n = (centre - foot).normalize();
                Some((Touch { tip: z - big_r, contact: centre - n * big_r }, n))
            }
            Part::Torus { centre, major, minor } => {
                let (dx, dy) = (q[0] - centre.x, q[1] - centre.y);
                let d = dx.hypot(dy);
                let (ux, uy) = if d > 0.0 { (dx / d, dy / d) } else { (1.0, 0.0) };
                let (tip, along, z) = c.drop_torus(d, centre.z, *major, *minor)?;
                let contact = P3::new(centre.x + ux * along, centre.y + uy * along, z);
                let core = P3::new(centre.x + ux * major, centre.y + uy * major, centre.z);
                Some((Touch { tip, contact }, (contact - core) / *minor))
            }
            Part::Revolved { centre, ends } => {
                let (dx, dy) = (q[0] - centre.x, q[1] - centre.y);
                let d = dx.hypot(dy);
                let (ux, uy) = if d > 0.0 { (dx / d, dy / d) } else { (1.0, 0.0) };
                let (tip, p, n) = c.drop_section(d, ends[0], ends[1])?;
                let contact = P3::new(centre.x + ux * p[0], centre.y + uy * p[0], p[1]);
                Some((Touch { tip, contact }, V3::new(ux * n[0], uy * n[0], n[1])))
            }
            Part::Sheet(sheet) => sheet.drop(c, q, floor),
            Part::Tube { point, axis, radius } => {
                // The axis's points whose circle can reach the shadow: |(P(t) − q).xy| ≤ R + r.
                let (ex, ey) = (point.x - q[0], point.y - q[1]);
                let aa = axis.x * axis.x + axis.y * axis.y;
                let bb = ex * axis.x + ey * axis.y;
                let disc = bb * bb - aa * (ex * ex + ey * ey - (c.radius() + radius).powi(2));
                if disc < 0.0 {
                    return None;
                }
                let (from, to) = ((-bb - disc.sqrt()) / aa, (-bb + disc.sqrt()) / aa);
                let cyl = Analytic::Cylinder { point: *point, axis: *axis, radius: *radius, from, to };
                Sheet::new(analytic_pieces(&cyl).expect("a finite cylinder"), None).drop(c, q, floor)
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

/// A finite analytic surface made rational patches, moved into the axis frame by `place`.
fn sheet(a: &Analytic, place: &Isometry3<f64>) -> Part {
    let pieces = analytic_pieces(a).expect("a finite surface");
    Part::Sheet(Sheet::new(pieces.iter().map(|p| p.moved(place)).collect(), None))
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
        Part::Sheet(sheet) => sheet.bounds(),
        Part::Tube { .. } => Aabb::everything(),
        Part::Plane { .. } | Part::Across { .. } | Part::Slant { .. } => Aabb::everything(),
        Part::Sphere { centre, radius } => {
            Aabb { min: centre - V3::repeat(*radius), max: centre + V3::repeat(*radius) }
        }
        Part::Torus { centre, major, minor } => {
            let e = V3::new(major + minor, major + minor, *minor);
            Aabb { min: centre - e, max: centre + e }
        }
        Part::Revolved { centre, ends } => {
            let r = ends[0][0].max(ends[1][0]);
            let (z0, z1) = (ends[0][1].min(ends[1][1]), ends[0][1].max(ends[1][1]));
            Aabb { min: P3::new(centre.x - r, centre.y - r, z0), max: P3::new(centre.x + r, centre.y + r, z1) }
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
            near in (0..1000usize, 0..1000usize),
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
            // Started from any point of the mesh (a corner, or a point inside a triangle), the
            // search finds the same drop.
            for near in [p(near.0 % 7, near.1 % 7), nalgebra::center(&tris[near.0 % 72][0], &tris[near.0 % 72][2])] {
                let again = dc.drop_near(q[0], q[1], Some((near, 0)));
                prop_assert_eq!(again.is_some(), got.is_some());
                if let (Some(a), Some(g)) = (again, got) {
                    prop_assert!((a.tip - g.tip).norm() <= 1e-12 * (1.0 + g.tip.z.abs()), "{:?} vs {:?}", a.tip, g.tip);
                }
            }
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

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// A ball on an endless cylinder at a slant: the closed form is exact, so it is at least
        /// the drop onto the cylinder tessellated finely (corners on it: the mesh lies inside)
        /// and the mesh's no lower than the exact drop onto the cylinder of the polygons' apothem
        /// (radius less the sagitta s), about s / n·z below the exact one (first order: 1 %
        /// allowed for the facets' tilt); the contact is on the cylinder, R from the ball's centre.
        #[test]
        fn ball_on_a_slanted_cylinder_is_above_its_tessellation_by_at_most_the_sagitta(
            tilt in 0.35..1.45f64,
            turn in 0.0..std::f64::consts::TAU,
            radius in 0.5..5.0f64,
            big_r in 0.3..4.0f64,
            q in prop::array::uniform2(-4.0..4.0f64),
        ) {
            let axis = V3::new(tilt.sin() * turn.cos(), tilt.sin() * turn.sin(), tilt.cos());
            let point = P3::new(0.3, -0.2, 1.0);
            let surface = Geometry::Analytic(Analytic::Cylinder { point, axis, radius, from: f64::NEG_INFINITY, to: f64::INFINITY });
            let m = Model { surfaces: vec![super::super::Surface::new("c".into(), surface, None, false)] };
            let ball = Cutter::Ball { radius: big_r };
            let got = DropCutter::new(&m, ball, V3::z()).unwrap().drop(q[0], q[1]);
            // The tessellation: 720 strips along the axis, ±60 around the point nearest q's
            // vertical line (the shadow reaches at most (R + r) / sin(tilt) < 30 along it).
            let n = 720;
            let (e1, e2) = (super::super::analytic::any_perpendicular(&axis), axis.cross(&super::super::analytic::any_perpendicular(&axis)));
            let mid = (P3::new(q[0], q[1], 0.0) - point).dot(&axis);
            let at = |k: usize, t: f64| {
                let th = std::f64::consts::TAU * k as f64 / n as f64;
                point + axis * (mid + t) + (e1 * th.cos() + e2 * th.sin()) * radius
            };
            let mut tris = Vec::new();
            for k in 0..n {
                tris.push([at(k, -60.0), at(k + 1, -60.0), at(k + 1, 60.0)]);
                tris.push([at(k, -60.0), at(k + 1, 60.0), at(k, 60.0)]);
            }
            let mesh = super::super::mesh::Mesh::new(&tris).unwrap();
            let mm = Model { surfaces: vec![super::super::Surface::new("t".into(), Geometry::Mesh(mesh), None, false)] };
            let want = DropCutter::new(&mm, ball, V3::z()).unwrap().drop(q[0], q[1]);
            let sagitta = radius * (1.0 - (std::f64::consts::PI / n as f64).cos());
            match (got, want) {
                (None, None) => {}
                (Some(g), Some(w)) => {
                    prop_assert!(g.tip.z >= w.tip.z - 1e-9, "exact {} below the mesh's {}", g.tip.z, w.tip.z);
                    // The mesh lies between the cylinder and the one of the polygons' apothem
                    // (radius − s): the ball rests no lower than on that one, in closed form.
                    let inner = Geometry::Analytic(Analytic::Cylinder { point, axis, radius: radius - sagitta, from: f64::NEG_INFINITY, to: f64::INFINITY });
                    let mi = Model { surfaces: vec![super::super::Surface::new("i".into(), inner, None, false)] };
                    if let Some(lo) = DropCutter::new(&mi, ball, V3::z()).unwrap().drop(q[0], q[1]) {
                        prop_assert!(w.tip.z >= lo.tip.z - 1e-9, "mesh {} under the inner cylinder's {}", w.tip.z, lo.tip.z);
                    }
                    if g.normal.z > 0.05 {
                        // About s / n·z: the first-order size of that gap where the contact is not steep.
                        prop_assert!(g.tip.z - w.tip.z <= 1.01 * sagitta / g.normal.z + 1e-9, "exact {} mesh {}", g.tip.z, w.tip.z);
                    }
                    let c = g.contact - point;
                    prop_assert!(((c - axis * c.dot(&axis)).norm() - radius).abs() < 1e-9);
                    prop_assert!(((g.tip + V3::z() * big_r - g.contact).norm() - big_r).abs() < 1e-9);
                }
                // The mesh inside the cylinder may be out of reach only where the ball touches it
                // within s of its rim: ρ ≥ R − s, n·z = √(1 − (ρ/R)²) ≤ √(2s/R).
                (Some(g), None) => prop_assert!(g.normal.z <= 2.0 * (2.0 * sagitta / big_r).sqrt(), "{g:?}"),
                (None, Some(w)) => prop_assert!(false, "the mesh is under the ball: {w:?}"),
            }
        }
    }

    #[test]
    fn flat_on_a_torus_along_its_axis_is_the_closed_form() {
        // Torus R 5, r 1 at (1, 2, 3) about z (given upside down), flat R 2 at distance d from
        // its axis: the disc spans ρ over [d − 2, d + 2]; on the top (tip 4) while that holds 5,
        // else at the nearer end ρ*: tip 3 + √(1 − (ρ* − 5)²).
        let m = model(
            r#"{"surfaces": [{"type": "torus", "centre": [1,2,3], "axis": [0,0,-1], "major_radius": 5, "minor_radius": 1}]}"#,
        );
        let dc = DropCutter::new(&m, Cutter::Flat { radius: 2.0 }, V3::z()).unwrap();
        for d in [2.5, 3.0, 5.0, 7.0, 7.5, 7.9] {
            let near = 5.0f64.clamp(d - 2.0, d + 2.0);
            let want = 3.0 + (1.0 - (near - 5.0f64).powi(2)).sqrt();
            let got = dc.drop(1.0, 2.0 + d).unwrap();
            assert!((got.tip.z - want).abs() < 1e-12, "d {d}: {} vs {want}", got.tip.z);
            // The contact is on the tube, the normal from the tube's centre circle through it.
            let c = got.contact - P3::new(1.0, 2.0, 3.0);
            let core = V3::new(c.x, c.y, 0.0).normalize() * 5.0;
            assert!(((c - core).norm() - 1.0).abs() < 1e-12 && (got.normal - (c - core)).norm() < 1e-12);
        }
        // Over the hole (ρ within [0, 2], the tube from 4) and beyond the rim nothing is under it.
        assert!(dc.drop(1.0, 2.0).is_none() && dc.drop(1.0, 2.0 + 8.1).is_none());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(32))]
        /// Flat, ball and bull-nose on a torus along the tool axis against the torus tessellated
        /// (corners on it, 360 × 90 cells): the two drops differ by at most the tessellation's
        /// sagitta seen along the contact's normal, and the contact is on the torus.
        #[test]
        fn torus_drop_is_within_the_sagitta_of_its_tessellation(
            c in prop_oneof![
                (0.3..3.0f64).prop_map(|radius| Cutter::Flat { radius }),
                (0.3..3.0f64).prop_map(|radius| Cutter::Ball { radius }),
                (0.3..3.0f64, 0.1..1.0f64).prop_map(|(radius, k)| Cutter::Bull { radius, corner: radius * k }),
            ],
            major in 2.0..6.0f64,
            minor in 0.3..1.5f64,
            q in prop::array::uniform2(-8.0..8.0f64),
        ) {
            let torus = Geometry::Analytic(Analytic::Torus { centre: P3::new(0.5, -0.5, 1.0), axis: V3::z(), major, minor });
            let m = Model { surfaces: vec![super::super::Surface::new("t".into(), torus, None, false)] };
            let got = DropCutter::new(&m, c, V3::z()).unwrap().drop(q[0], q[1]);
            let (nu, nv) = (360, 90);
            let at = |i: usize, j: usize| {
                let (u, v) = (std::f64::consts::TAU * i as f64 / nu as f64, std::f64::consts::TAU * j as f64 / nv as f64);
                P3::new(0.5 + (major + minor * v.cos()) * u.cos(), -0.5 + (major + minor * v.cos()) * u.sin(), 1.0 + minor * v.sin())
            };
            let mut tris = Vec::new();
            for i in 0..nu {
                for j in 0..nv {
                    tris.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                    tris.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
            let mesh = super::super::mesh::Mesh::new(&tris).unwrap();
            let mm = Model { surfaces: vec![super::super::Surface::new("m".into(), Geometry::Mesh(mesh), None, false)] };
            let want = DropCutter::new(&mm, c, V3::z()).unwrap().drop(q[0], q[1]);
            let sagitta = (major + minor) * (1.0 - (std::f64::consts::PI / nu as f64).cos())
                + minor * (1.0 - (std::f64::consts::PI / nv as f64).cos());
            match (got, want) {
                (None, None) => {}
                (Some(g), Some(w)) => {
                    if g.normal.z > 0.05 {
                        prop_assert!((g.tip.z - w.tip.z).abs() <= sagitta / g.normal.z + 1e-9, "exact {} mesh {}", g.tip.z, w.tip.z);
                    }
                    prop_assert!(g.tip.z >= w.tip.z - sagitta / 0.05 - 1e-9);
                    let p = g.contact - P3::new(0.5, -0.5, 1.0);
                    let core = V3::new(p.x, p.y, 0.0).normalize() * major;
                    prop_assert!(((p - core).norm() - minor).abs() < 1e-9);
                }
                // Only where the cutter's rim just reaches the tube (from outside or over the
                // hole) may one of them miss.
                (g, w) => {
                    let d = (q[0] - 0.5).hypot(q[1] + 0.5);
                    let rim = (d - c.radius() - major - minor).abs().min((d + c.radius() - major + minor).abs());
                    prop_assert!(rim < 10.0 * sagitta, "{g:?} {w:?}");
                }
            }
        }
    }

    #[test]
    fn bull_on_a_cone_along_its_axis_is_the_closed_form() {
        // A funnel z = ρ·cot 30° (apex at the origin, opening up, 0 ≤ t ≤ 10), bull R 3, r 1 at
        // distance d from its axis: the far wall, a plane at 60° to the tool axis through the
        // disc's far edge, gives tip = (d + c)·tan 60° + r·(1/cos 60° − 1), c = 2 (the
        // plane formula of a bull), while the contact stays on the wall.
        let m = model(
            r#"{"surfaces": [{"type": "cone", "apex": [0,0,0], "axis": [0,0,1], "half_angle": 30, "length": [0, 10]}]}"#,
        );
        let c = Cutter::Bull { radius: 3.0, corner: 1.0 };
        let dc = DropCutter::new(&m, c, V3::z()).unwrap();
        let th = 60f64.to_radians();
        for d in [0.0, 0.5, 1.5, 2.0] {
            let want = (d + 2.0) * th.tan() + (1.0 / th.cos() - 1.0);
            let got = dc.drop(-d, 0.0).unwrap();
            assert!((got.tip.z - want).abs() < 1e-12, "d {d}: {} vs {want}", got.tip.z);
            let p = got.contact;
            assert!((p.x.hypot(p.y) * th.tan() - p.z).abs() < 1e-12, "{p:?}");
        }
        // Past the rim (ρ = 10/√3 = 5.77 at height 10) a ball rests on it: its centre is R
        // from the rim circle, tip = 10 + √(R² − (ρ_q − 5.77)²) − R.
        let dc = DropCutter::new(&m, Cutter::Ball { radius: 2.0 }, V3::z()).unwrap();
        let rim = 10.0 * 30f64.to_radians().tan();
        for e in [0.3, 1.0, 1.9] {
            let want = 10.0 + (4.0f64 - e * e).sqrt() - 2.0;
            let got = dc.drop(rim + e, 0.0).unwrap();
            assert!((got.tip.z - want).abs() < 1e-12, "e {e}: {} vs {want}", got.tip.z);
            assert!((got.contact - P3::new(rim, 0.0, 10.0)).norm() < 1e-12);
        }
        // A cone cutter in the funnel (searched): never below a dense sampling of the wall, the
        // contact on it.
        let c = Cutter::Cone { radius: 1.0, half_angle: 0.5 };
        let dc = DropCutter::new(&m, c, V3::z()).unwrap();
        for d in [0.0, 0.7, 3.0, 5.5] {
            let got = dc.drop(-d, 0.0).unwrap();
            let points: Vec<P3> = (0..=400)
                .flat_map(|i| {
                    (0..=400).map(move |j| {
                        let (t, a) = (10.0 * i as f64 / 400.0, std::f64::consts::TAU * j as f64 / 400.0);
                        P3::new(t * th.tan().recip() * a.cos(), t * th.tan().recip() * a.sin(), t)
                    })
                })
                .collect();
            let brute = sampled(&c, &dc.frame, [-d, 0.0], &points);
            assert!(brute <= got.tip.z + 1e-9 && got.tip.z - brute < 5e-3, "d {d}: {} vs sampled {brute}", got.tip.z);
            let p = got.contact;
            assert!((p.x.hypot(p.y) * th.tan() - p.z).abs() < 1e-9, "{p:?}");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// Flat, ball and bull-nose on a finite cone along the tool axis (opening up or down)
        /// against the cone tessellated into 720 strips: on the side the mesh lies and within the
        /// sagitta over n·z of it, and the contact on the cone.
        #[test]
        fn cone_drop_is_within_the_sagitta_of_its_tessellation(
            c in prop_oneof![
                (0.3..3.0f64).prop_map(|radius| Cutter::Flat { radius }),
                (0.3..3.0f64).prop_map(|radius| Cutter::Ball { radius }),
                (0.3..3.0f64, 0.1..1.0f64).prop_map(|(radius, k)| Cutter::Bull { radius, corner: radius * k }),
            ],
            up in prop::bool::ANY,
            half_angle in 0.2..1.4f64,
            from in 0.0..3.0f64,
            length in 0.5..6.0f64,
            q in prop::array::uniform2(-9.0..9.0f64),
        ) {
            let axis = if up { V3::z() } else { -V3::z() };
            let apex = P3::new(0.5, -0.5, 1.0);
            let cone = Geometry::Analytic(Analytic::Cone { apex, axis, half_angle, from, to: from + length });
            let m = Model { surfaces: vec![super::super::Surface::new("k".into(), cone, None, false)] };
            let got = DropCutter::new(&m, c, V3::z()).unwrap().drop(q[0], q[1]);
            let n = 720;
            let at = |k: usize, t: f64| {
                let th = std::f64::consts::TAU * k as f64 / n as f64;
                apex + axis * t + V3::new(th.cos(), th.sin(), 0.0) * (t * half_angle.tan())
            };
            let mut tris = Vec::new();
            for k in 0..n {
                let (t0, t1) = (from, from + length);
                if t0 > 0.0 {
                    tris.push([at(k, t0), at(k + 1, t0), at(k + 1, t1)]);
                }
                tris.push([at(k, t0), at(k + 1, t1), at(k, t1)]);
            }
            let mesh = super::super::mesh::Mesh::new(&tris).unwrap();
            let mm = Model { surfaces: vec![super::super::Surface::new("m".into(), Geometry::Mesh(mesh), None, false)] };
            let want = DropCutter::new(&mm, c, V3::z()).unwrap().drop(q[0], q[1]);
            let rim = (from + length) * half_angle.tan();
            let sagitta = rim * (1.0 - (std::f64::consts::PI / n as f64).cos());
            match (got, want) {
                (None, None) => {}
                (Some(g), Some(w)) => {
                    // The strips' chords lie nearer the axis: under a roof (opening down) the
                    // mesh is inside the cone, in a funnel (opening up) above its wall (at a
                    // rim circle either, as the rim's polygon lies inside its circle).
                    let t = (g.contact - apex).dot(&axis);
                    let wall = t > from + 1e-6 && t < from + length - 1e-6;
                    if up && wall {
                        prop_assert!(g.tip.z <= w.tip.z + 1e-9, "exact {} above the mesh's {}", g.tip.z, w.tip.z);
                    } else if !up && wall {
                        prop_assert!(g.tip.z >= w.tip.z - 1e-9, "exact {} below the mesh's {}", g.tip.z, w.tip.z);
                    }
                    if g.normal.z > 0.05 {
                        prop_assert!((g.tip.z - w.tip.z).abs() <= sagitta / g.normal.z + 1e-9, "exact {} mesh {}", g.tip.z, w.tip.z);
                    }
                    let p = g.contact - apex;
                    let t = p.dot(&axis);
                    prop_assert!(t >= from - 1e-9 && t <= from + length + 1e-9);
                    prop_assert!((V3::new(p.x, p.y, 0.0).norm() - t * half_angle.tan()).abs() < 1e-9);
                }
                // Only where the cutter's rim just reaches the cone's rim may one of them miss.
                (g, w) => {
                    let d = (q[0] - 0.5).hypot(q[1] + 0.5);
                    prop_assert!((d - c.radius() - rim).abs() < 10.0 * sagitta, "{g:?} {w:?}");
                }
            }
        }
    }

    #[test]
    fn ball_on_a_slanted_cylinder_is_the_closed_form() {
        // Cylinder r = 2 through the origin along (sin θ, 0, cos θ), ball R = 1 at (0, 0): the
        // centre is 3 from the axis straight above it, at height 3 / sin θ; the tip is R lower.
        for theta in [0.4f64, 0.9, 1.3] {
            let m = model(&format!(
                r#"{{"surfaces": [{{"type": "cylinder", "point": [0,0,0], "axis": [{}, 0, {}], "radius": 2}}]}}"#,
                theta.sin(),
                theta.cos()
            ));
            let d = DropCutter::new(&m, Cutter::Ball { radius: 1.0 }, V3::z()).unwrap().drop(0.0, 0.0).unwrap();
            assert!((d.tip.z - (3.0 / theta.sin() - 1.0)).abs() < 1e-12, "{theta}: {}", d.tip.z);
            // The normal is the radial direction, across the axis in the x-z plane.
            assert!((d.normal - V3::new(-theta.cos(), 0.0, theta.sin())).norm() < 1e-12, "{:?}", d.normal);
        }
    }

    #[test]
    fn refuses_what_it_cannot_drop_onto() {
        // What has no top along the axis, or no end one way.
        for (text, what) in [
            (r#"{"type": "plane", "point": [0,0,0], "normal": [1,0,0]}"#, "plane"),
            (r#"{"type": "cylinder", "point": [0,0,0], "axis": [0,0,1], "radius": 1}"#, "along the tool axis"),
        ] {
            let m = model(&format!(r#"{{"surfaces": [{text}]}}"#));
            for c in CUTTERS {
                let e = DropCutter::new(&m, c, V3::z()).unwrap_err();
                assert!(e.what.contains(what), "{e:?}");
            }
        }
        // Everything else is dropped onto, whatever the cutter and the axis.
        for text in [
            r#"{"type": "torus", "centre": [0,0,0], "axis": [0,1,1], "major_radius": 5, "minor_radius": 1}"#,
            r#"{"type": "cylinder", "point": [0,0,0], "axis": [1,0,1], "radius": 1}"#,
            r#"{"type": "cylinder", "point": [0,0,0], "axis": [1,0,1], "radius": 1, "length": [0, 5]}"#,
            r#"{"type": "cylinder", "point": [0,0,0], "axis": [1,0,0], "radius": 1, "length": [0, 5]}"#,
            r#"{"type": "cone", "apex": [0,0,0], "axis": [1,0,1], "half_angle": 20, "length": [1, 5]}"#,
        ] {
            let m = model(&format!(r#"{{"surfaces": [{text}]}}"#));
            for c in CUTTERS {
                for axis in [V3::z(), V3::new(0.3, -0.2, 1.0)] {
                    assert!(DropCutter::new(&m, c, axis).is_ok(), "{text} {c:?}");
                }
            }
        }
    }
}
