//! Defined models and their nearest-point queries: the geometry behind copy simulation
//! (`stylus-trace`), gouge checks (`tool-attitude`) and any filter that asks "how far is this
//! point from the part, where, and which way is out?".
//!
//! A [`Model`] is the union of [`Surface`]s read from a [`crate::doc::model::ModelDoc`] (or one
//! STL file). [`Model::nearest`] returns the nearest point over *all* surfaces, the outward normal
//! there, the distance and which surface it is on: exact for analytic surfaces and meshes,
//! converged to [`patch::FOOT_TOL`] for B-spline patches (with a flag when Newton failed).
//! [`Model::nearest_on`] asks one surface only (two-surface contact); `nearest_within` prunes by
//! a distance bound, which makes clearance checks of many points cheap. [`drop::DropCutter`]
//! answers the other question of fixed-axis machining: how high does a cutter ([`cutter`]) rest
//! on the model along its axis.

pub mod analytic;
pub mod bvh;
pub mod cutter;
pub mod drop;
pub mod face;
pub mod mesh;
pub mod part21;
pub mod patch;
pub mod revolution;
pub mod sheet;
pub mod step;

use crate::doc::model::{ModelDoc, Placement, SurfaceDoc};
use crate::error::{Error, Location, Result};
use crate::geom::{P3, V3};
use crate::io::Input;
use analytic::{Analytic, Foot};
pub use bvh::Aabb;
use mesh::Mesh;
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion};
use patch::BSpline;
use std::path::Path;

/// The geometry of one surface.
#[derive(Clone, Debug)]
pub enum Geometry {
    /// Plane, sphere, cylinder, cone or torus.
    Analytic(Analytic),
    /// B-spline or Bézier patch.
    Patch(BSpline),
    /// Triangle mesh.
    Mesh(Mesh),
    /// A trimmed face of a CAD B-rep (a STEP file's ADVANCED_FACE).
    Face(Box<face::Face>),
}

/// One surface of a model: its geometry as defined, a placement, and the normal's orientation.
#[derive(Clone, Debug)]
pub struct Surface {
    /// Name for output (`sphere#1` by default).
    pub name: String,
    /// Geometry in its own frame.
    pub geometry: Geometry,
    /// Rigid placement from the surface's frame to the model's (None: identity).
    pub placement: Option<Isometry3<f64>>,
    /// True when the outward normal is reversed.
    pub flip: bool,
    bounds: Aabb,
}

/// The answer to a nearest-point query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// The nearest point of the model.
    pub point: P3,
    /// Unit outward normal of the surface at `point` (the face normal on a mesh).
    pub normal: V3,
    /// Distance from the query point to `point`.
    pub distance: f64,
    /// Index of the surface in [`Model::surfaces`].
    pub surface: usize,
    /// False when a patch's Newton iteration did not converge to [`patch::FOOT_TOL`].
    pub converged: bool,
}

impl Nearest {
    /// Unit vector from the nearest point towards `q` (the outward normal when `q` is on the
    /// surface): the direction of L in paper 000 eq. (2).
    pub fn direction(&self, q: &P3) -> V3 {
        (q - self.point).try_normalize(crate::tol::LENGTH_EPS).unwrap_or(self.normal)
    }
}

impl Surface {
    /// A surface with its bounds computed.
    pub fn new(name: String, geometry: Geometry, placement: Option<Isometry3<f64>>, flip: bool) -> Surface {
        let local = match &geometry {
            Geometry::Analytic(a) => a.bounds(),
            Geometry::Patch(p) => p.bounds(),
            Geometry::Mesh(m) => m.bounds(),
            Geometry::Face(f) => f.bounds(),
        };
        let bounds = match &placement {
            Some(iso) if local.is_bounded() => {
                let mut b = Aabb::empty();
                for k in 0..8 {
                    let c = P3::new(
                        if k & 1 == 0 { local.min.x } else { local.max.x },
                        if k & 2 == 0 { local.min.y } else { local.max.y },
                        if k & 4 == 0 { local.min.z } else { local.max.z },
                    );
                    b = b.with(&(iso * c));
                }
                b
            }
            Some(_) => Aabb::everything(),
            None => local,
        };
        Surface { name, geometry, placement, flip, bounds }
    }

    /// A box holding the surface in the model's frame.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The nearest point of this surface no farther than `bound`: foot (model frame, normal
    /// flipped as asked) and whether it converged.
    pub fn nearest(&self, q: &P3, bound: f64) -> Option<(Foot, bool)> {
        let local_q = match &self.placement {
            Some(iso) => iso.inverse_transform_point(q),
            None => *q,
        };
        let (foot, converged) = match &self.geometry {
            Geometry::Analytic(a) => {
                let f = a.foot(&local_q);
                if (f.point - local_q).norm() > bound {
                    return None;
                }
                (f, true)
            }
            Geometry::Patch(p) => p.nearest(&local_q, bound).map(|(f, _, c)| (f, c))?,
            Geometry::Mesh(m) => (m.nearest(&local_q, bound)?.foot, true),
            Geometry::Face(f) => f.nearest(&local_q, bound)?,
        };
        let normal = if self.flip { -foot.normal } else { foot.normal };
        let foot = match &self.placement {
            Some(iso) => Foot { point: iso * foot.point, normal: iso * normal },
            None => Foot { point: foot.point, normal },
        };
        Some((foot, converged))
    }
}

/// A defined model: the union of its surfaces.
#[derive(Clone, Debug)]
pub struct Model {
    /// The surfaces in document order.
    pub surfaces: Vec<Surface>,
}

impl Model {
    /// The nearest point of the whole model to `q`.
    pub fn nearest(&self, q: &P3) -> Nearest {
        self.nearest_within(q, f64::INFINITY).expect("a model has at least one surface")
    }

    /// The nearest point of the whole model no farther than `bound` from `q`.
    pub fn nearest_within(&self, q: &P3, bound: f64) -> Option<Nearest> {
        let mut best: Option<Nearest> = None;
        let mut limit = bound;
        // Surfaces in order of their boxes' distance; stop once a box is beyond the best.
        let mut order: Vec<(f64, usize)> =
            self.surfaces.iter().enumerate().map(|(i, s)| (s.bounds.dist2(q), i)).collect();
        if order.len() > 1 {
            order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        }
        for (d2, i) in order {
            if d2.sqrt() > limit {
                break;
            }
            if let Some(n) = self.nearest_on_within(q, i, limit) {
                if best.is_none_or(|b| n.distance < b.distance) {
                    limit = n.distance;
                    best = Some(n);
                }
            }
        }
        best
    }

    /// The nearest point of surface `i` alone.
    pub fn nearest_on(&self, q: &P3, i: usize) -> Nearest {
        self.nearest_on_within(q, i, f64::INFINITY).expect("an unbounded query finds a point")
    }

    /// The nearest point of surface `i` no farther than `bound`.
    pub fn nearest_on_within(&self, q: &P3, i: usize, bound: f64) -> Option<Nearest> {
        let (foot, converged) = self.surfaces[i].nearest(q, bound)?;
        Some(Nearest {
            point: foot.point,
            normal: foot.normal,
            distance: (q - foot.point).norm(),
            surface: i,
            converged,
        })
    }

    /// Distance from `q` to the model.
    pub fn distance(&self, q: &P3) -> f64 {
        self.nearest(q).distance
    }

    /// A box holding the model (unbounded if any surface is).
    pub fn bounds(&self) -> Aabb {
        self.surfaces.iter().fold(Aabb::empty(), |b, s| b.union(&s.bounds))
    }

    /// Index of the surface called `name` (or given by its index as text).
    pub fn surface_index(&self, name: &str) -> Option<usize> {
        self.surfaces
            .iter()
            .position(|s| s.name == name)
            .or_else(|| name.parse().ok().filter(|&i| i < self.surfaces.len()))
    }

    /// The cost of a nearest-point query or a drop on the model against one on an analytic
    /// surface, for work estimates: that of its costliest kind of surface (measured in stylus
    /// scans, µs per CL point and drop: a sphere 14, an STL 6, trimmed planes and cylinders 47,
    /// a B-spline patch 65–2 000, a surface of revolution 3 700; Newton on spans against closed
    /// forms).
    pub fn query_weight(&self) -> f64 {
        let weight = |s: &Surface| match &s.geometry {
            Geometry::Analytic(_) | Geometry::Mesh(_) => 1.0,
            Geometry::Patch(_) => 50.0,
            Geometry::Face(f) => match f.carrier() {
                face::Carrier::Analytic(_) => 4.0,
                face::Carrier::Patch(_) => 50.0,
                face::Carrier::Revolution(_) => 250.0,
            },
        };
        self.surfaces.iter().map(weight).fold(1.0, f64::max)
    }

    /// Number of triangles over all meshes.
    pub fn triangles(&self) -> usize {
        self.surfaces.iter().map(|s| if let Geometry::Mesh(m) = &s.geometry { m.len() } else { 0 }).sum()
    }

    /// What the model's STL files held that their meshes leave out, one entry per file that had
    /// any (see [`mesh::Dropped`]).
    pub fn dropped(&self) -> Vec<&mesh::Dropped> {
        self.surfaces
            .iter()
            .filter_map(|s| if let Geometry::Mesh(m) = &s.geometry { Some(m.dropped()) } else { None })
            .filter(|d| !d.is_empty())
            .collect()
    }

    /// Zero-area and repeated STL facets left out, over all meshes: the report's counts.
    pub fn dropped_counts(&self) -> (usize, usize) {
        self.dropped().iter().fold((0, 0), |(a, b), d| (a + d.degenerate.len(), b + d.duplicate.len()))
    }

    /// STL facets left out: with `strict` the first is an input error naming its file and facet;
    /// else a warning for each file that had any (one line).
    pub fn check_dropped(&self, strict: bool) -> Result<()> {
        for d in self.dropped() {
            if strict {
                return Err(d.refusal().expect("something was dropped"));
            }
            crate::cli::warn(&d.summary());
        }
        Ok(())
    }

    /// Reads a model: a model document (`.json`), one STL file (`.stl`) as a one-surface
    /// model, or a STEP file (`.step`, `.stp`) with a trimmed surface per face, refusing
    /// unsupported STEP entities. STL files named in a document are found relative to it.
    pub fn load(input: &Input) -> Result<Model> {
        Model::load_with(input, false)
    }

    /// [`Model::load`], leaving out (with a warning each) the STEP faces whose entities are not
    /// supported when `skip_unsupported`.
    pub fn load_with(input: &Input, skip_unsupported: bool) -> Result<Model> {
        if matches!(input.extension().as_str(), "step" | "stp") {
            return Ok(Model { surfaces: step::load(input, skip_unsupported)? });
        }
        if input.extension() == "stl" {
            let mesh = mesh::load_stl(input)?;
            let name = Path::new(&input.name).file_stem().map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
            return Ok(Model { surfaces: vec![Surface::new(name, Geometry::Mesh(mesh), None, false)] });
        }
        let doc = ModelDoc::from_input(input)?;
        let base = if input.name == "stdin" {
            Path::new(".")
        } else {
            Path::new(&input.name).parent().unwrap_or(Path::new("."))
        };
        Model::from_doc(&doc, &input.name, base)
    }

    /// Builds a validated document's geometry; STL paths are relative to `base`.
    pub fn from_doc(doc: &ModelDoc, file: &str, base: &Path) -> Result<Model> {
        let p3 = |a: &[f64; 3]| P3::new(a[0], a[1], a[2]);
        let unit = |a: &[f64; 3]| V3::new(a[0], a[1], a[2]).normalize();
        let mut surfaces = Vec::with_capacity(doc.surfaces.len());
        for (i, s) in doc.surfaces.iter().enumerate() {
            let (name, flip, placement) = s.common();
            let name = name.map_or_else(|| format!("{}#{i}", s.kind()), str::to_string);
            let geometry = match s {
                SurfaceDoc::Plane(d) => {
                    Geometry::Analytic(Analytic::Plane { point: p3(&d.point), normal: unit(&d.normal) })
                }
                SurfaceDoc::Sphere(d) => {
                    Geometry::Analytic(Analytic::Sphere { centre: p3(&d.centre), radius: d.radius })
                }
                SurfaceDoc::Cylinder(d) => {
                    let [from, to] = d.length.unwrap_or([-f64::INFINITY, f64::INFINITY]);
                    Geometry::Analytic(Analytic::Cylinder {
                        point: p3(&d.point),
                        axis: unit(&d.axis),
                        radius: d.radius,
                        from,
                        to,
                    })
                }
                SurfaceDoc::Cone(d) => Geometry::Analytic(Analytic::Cone {
                    apex: p3(&d.apex),
                    axis: unit(&d.axis),
                    half_angle: d.half_angle.to_radians(),
                    from: d.length[0],
                    to: d.length[1],
                }),
                SurfaceDoc::Torus(d) => Geometry::Analytic(Analytic::Torus {
                    centre: p3(&d.centre),
                    axis: unit(&d.axis),
                    major: d.major_radius,
                    minor: d.minor_radius,
                }),
                SurfaceDoc::Bspline(d) => {
                    let net: Vec<Vec<P3>> = d.control_points.iter().map(|r| r.iter().map(p3).collect()).collect();
                    Geometry::Patch(BSpline::with_weights(
                        &net,
                        d.weights.as_deref(),
                        d.degree,
                        d.knots_u.clone(),
                        d.knots_v.clone(),
                    ))
                }
                SurfaceDoc::Bezier(d) => {
                    let net: Vec<Vec<P3>> = d.control_points.iter().map(|r| r.iter().map(p3).collect()).collect();
                    let degree = [net.len() - 1, net[0].len() - 1];
                    Geometry::Patch(BSpline::new(&net, degree, None, None))
                }
                SurfaceDoc::Stl(d) => {
                    let path = base.join(&d.file);
                    let shown = path.display().to_string();
                    let data = std::fs::read(&path).map_err(|e| {
                        Error::io(e, &format!("cannot read {shown}"))
                            .or_at(|| Location::file(file).field(format!("surfaces[{i}].file")))
                    })?;
                    Geometry::Mesh(mesh::load_stl(&Input { name: shown, data })?)
                }
            };
            surfaces.push(Surface::new(name, geometry, placement.map(isometry), flip));
        }
        Ok(Model { surfaces })
    }
}

/// The rigid motion of a placement.
pub fn isometry(p: &Placement) -> Isometry3<f64> {
    let axis = Unit::new_normalize(V3::new(p.axis[0], p.axis[1], p.axis[2]));
    let rotation = UnitQuaternion::from_axis_angle(&axis, p.angle.to_radians());
    Isometry3::from_parts(Translation3::new(p.translate[0], p.translate[1], p.translate[2]), rotation)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(text: &str) -> Model {
        Model::load(&Input { name: "m.json".into(), data: text.as_bytes().to_vec() }).unwrap()
    }

    #[test]
    fn composite_nearest_is_the_nearer_surface() {
        let m = model(
            r#"{"surfaces": [{"type": "plane", "point": [0,0,0], "normal": [0,0,1], "name": "floor"},
                             {"type": "sphere", "centre": [0,0,3], "radius": 2, "name": "ball"}]}"#,
        );
        let n = m.nearest(&P3::new(0.0, 0.0, 6.0));
        assert_eq!((n.surface, n.distance), (1, 1.0));
        assert_eq!(n.normal, V3::z());
        let n = m.nearest(&P3::new(10.0, 0.0, 0.5));
        assert_eq!((n.surface, n.distance), (0, 0.5));
        assert_eq!(m.surface_index("ball"), Some(1));
        assert!(m.nearest_within(&P3::new(10.0, 0.0, 0.5), 0.4).is_none());
        assert!(!m.bounds().is_bounded());
    }

    #[test]
    fn placement_moves_the_surface() {
        // A cylinder along x, turned 90° about z, becomes a cylinder along y shifted by 5 in x.
        let m = model(
            r#"{"surfaces": [{"type": "cylinder", "point": [0,0,0], "axis": [1,0,0], "radius": 2, "length": [-10, 10],
                "placement": {"translate": [5, 0, 0], "axis": [0, 0, 1], "angle": 90}}]}"#,
        );
        let n = m.nearest(&P3::new(5.0, 3.0, 4.0));
        assert!((n.point - P3::new(5.0, 3.0, 2.0)).norm() < 1e-12, "{}", n.point);
        assert!((n.normal - V3::z()).norm() < 1e-12);
        let b = m.bounds();
        assert!((b.min - P3::new(3.0, -10.0, -2.0)).norm() < 1e-9 && (b.max - P3::new(7.0, 10.0, 2.0)).norm() < 1e-9);
        let flipped = model(r#"{"surfaces": [{"type": "sphere", "centre": [0,0,0], "radius": 1, "flip": true}]}"#);
        assert_eq!(flipped.nearest(&P3::new(0.0, 0.0, 3.0)).normal, -V3::z());
    }

    #[test]
    fn missing_stl_names_the_document_field() {
        let e = Model::load(&Input {
            name: "/nonexistent/m.json".into(),
            data: br#"{"surfaces": [{"type": "stl", "file": "gone.stl"}]}"#.to_vec(),
        })
        .unwrap_err();
        assert!(e.to_string().contains("(surfaces[0].file)") && e.to_string().contains("gone.stl"), "{e}");
        assert_eq!(e.exit_status(), 2);
    }
}
