//! STEP models (AP203, AP214, AP242 B-reps): every ADVANCED_FACE becomes a [`Face`] on camkit's
//! exact surface of its kind (PLANE, CYLINDRICAL_SURFACE, CONICAL_SURFACE, SPHERICAL_SURFACE,
//! TOROIDAL_SURFACE as analytic surfaces placed by their AXIS2_PLACEMENT_3D;
//! B_SPLINE_SURFACE_WITH_KNOTS, rational or not, as a patch; SURFACE_OF_REVOLUTION of a B-spline
//! or circle profile as a [`Revolution`]) trimmed by its loops (LINE, CIRCLE, ELLIPSE and
//! B_SPLINE_CURVE_WITH_KNOTS edges, also under SURFACE_CURVE / SEAM_CURVE), in millimetres
//! whatever the file's length unit, its normal turned over by ORIENTED_FACE and oriented shells
//! with orientation .F.. Any other surface or curve is an unsupported entity: an input error
//! naming it and its `#id`, or with `skip` a warning and the face left out.

use super::analytic::Analytic;
use super::face::{Carrier, Curve, Face, SplineCurve};
use super::part21::{Exchange, Instance, Param};
use super::patch::BSpline;
use super::revolution::Revolution;
use super::{Geometry, Surface};
use crate::doc::model::MAX_DEGREE;
use crate::error::{Error, Location, Result};
use crate::geom::{P3, V3};
use crate::io::Input;
use crate::tol::COORD_LIMIT;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion};
use std::collections::HashMap;
use std::f64::consts::TAU;

/// The surface entities read.
const SURFACES: &str = "PLANE, CYLINDRICAL_SURFACE, CONICAL_SURFACE, SPHERICAL_SURFACE, TOROIDAL_SURFACE, B_SPLINE_SURFACE_WITH_KNOTS, SURFACE_OF_REVOLUTION";

/// The edge curve entities read.
const CURVES: &str = "LINE, CIRCLE, ELLIPSE, B_SPLINE_CURVE_WITH_KNOTS (also as SURFACE_CURVE or SEAM_CURVE)";

/// Parameter length of the ellipse spline of [`ellipse_from`]: four quarter arcs.
const ELLIPSE_DOMAIN: f64 = 4.0;

/// Farthest (mm) a face's edges may lie from its surface: CAD systems write them within their
/// tolerance, 1e-7 to 1e-3 mm (the files in data/step within 1e-9); ten times the loosest.
const EDGE_FIT: f64 = 0.01;

/// Most knots a B-spline curve or surface direction may have: a million, far beyond CAD files
/// (a knot vector is as long as the control points and the degree), short of memory trouble.
const MAX_KNOTS: f64 = 1e6;

/// The ellipse `centre + x cos θ + y sin θ` (`x`, `y` its semi-axes as vectors) as an exact
/// rational quadratic spline of four quarter arcs (the affine image of the NURBS circle), starting
/// at `start` (a point of it) and running the way θ grows, over [0, [`ELLIPSE_DOMAIN`]].
fn ellipse_from(centre: P3, x: V3, y: V3, start: P3) -> SplineCurve {
    let d = start - centre;
    let t = (d.dot(&y) / y.norm_squared()).atan2(d.dot(&x) / x.norm_squared());
    let (c, s) = (t.cos(), t.sin());
    // The unit circle's nine control points turned by θ = t, then mapped onto the ellipse.
    let unit = [
        (1.0, 0.0),
        (1.0, 1.0),
        (0.0, 1.0),
        (-1.0, 1.0),
        (-1.0, 0.0),
        (-1.0, -1.0),
        (0.0, -1.0),
        (1.0, -1.0),
        (1.0, 0.0),
    ];
    let ctrl = unit.iter().map(|&(u, v)| centre + x * (u * c - v * s) + y * (u * s + v * c)).collect();
    let w = std::f64::consts::FRAC_1_SQRT_2;
    SplineCurve {
        degree: 2,
        ctrl,
        weights: Some(vec![1.0, w, 1.0, w, 1.0, w, 1.0, w, 1.0]),
        knots: vec![0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 4.0],
    }
}

/// Why a face could not be read.
enum Problem {
    /// An entity the reader does not take; the face can be left out.
    Unsupported(Error),
    /// A malformed file.
    Invalid(Error),
}

type Res<T> = std::result::Result<T, Problem>;

/// The file being read: its instances, name and units.
struct Reader<'a> {
    ex: &'a Exchange,
    file: &'a str,
    /// Millimetres per length unit of the file.
    mm: f64,
    /// Radians per plane angle unit.
    rad: f64,
}

/// Reads a STEP file's faces as surfaces; `skip` leaves faces with unsupported entities out
/// (with a warning each) instead of refusing the file.
pub fn load(input: &Input, skip: bool) -> Result<Vec<Surface>> {
    let ex = Exchange::parse(input.text()?, &input.name)?;
    let mut r = Reader { ex: &ex, file: &input.name, mm: 1.0, rad: 1.0 };
    r.mm = r.unit("LENGTH_UNIT", "METRE", 1000.0).map_err(problem_error)?;
    r.rad = r.unit("PLANE_ANGLE_UNIT", "RADIAN", 1.0).map_err(problem_error)?;
    let mut faces: Vec<usize> = ex
        .instances
        .iter()
        .filter(|(_, i)| i.parts.len() == 1 && i.parts[0].0 == "ADVANCED_FACE")
        .map(|(k, _)| *k)
        .collect();
    faces.sort_unstable();
    if faces.is_empty() {
        return Err(Error::input(
            "no surfaces: the STEP file holds no ADVANCED_FACE (a B-rep's faces); wireframe and tessellated STEP are not read",
        )
        .at(Location::file(&input.name)));
    }
    let reversed = r.reversed().map_err(problem_error)?;
    let mut out = Vec::new();
    for id in faces {
        match r.face(id, reversed.get(&id).copied().unwrap_or(false)) {
            Ok(s) => out.push(s),
            Err(Problem::Unsupported(e)) if skip => crate::cli::warn(&format!("{e}; face #{id} left out")),
            Err(Problem::Unsupported(e)) => {
                return Err(Error { message: format!("{}; --skip-unsupported leaves such faces out", e.message), ..e });
            }
            Err(Problem::Invalid(e)) => return Err(e),
        }
    }
    if out.is_empty() {
        return Err(
            Error::input("no surfaces: every face of the STEP file was left out").at(Location::file(&input.name))
        );
    }
    Ok(out)
}

fn problem_error(p: Problem) -> Error {
    match p {
        Problem::Unsupported(e) | Problem::Invalid(e) => e,
    }
}

impl Reader<'_> {
    /// The faces turned over by the shells that hold them: an ORIENTED_FACE, or a face of an
    /// ORIENTED_CLOSED_SHELL / ORIENTED_OPEN_SHELL (a BREP_WITH_VOIDS's void), with orientation
    /// .F.; each turning toggles.
    fn reversed(&self) -> Res<HashMap<usize, bool>> {
        let mut out: HashMap<usize, bool> = HashMap::new();
        let mut ids: Vec<usize> = self.ex.instances.keys().copied().collect();
        ids.sort_unstable();
        for id in ids {
            let inst = self.get(id)?;
            let face = |f: usize| -> Res<usize> {
                match self.get(f)?.part("ORIENTED_FACE") {
                    Some(p) => self.reference(f, p, 2),
                    None => Ok(f),
                }
            };
            if let Some(p) = inst.part("ORIENTED_FACE") {
                if !self.boolean(id, p, 3)? {
                    *out.entry(self.reference(id, p, 2)?).or_default() ^= true;
                }
            }
            for kind in ["ORIENTED_CLOSED_SHELL", "ORIENTED_OPEN_SHELL"] {
                let Some(p) = inst.part(kind) else { continue };
                if self.boolean(id, p, 3)? {
                    continue;
                }
                let shell = self.reference(id, p, 2)?;
                let sh = self.get(shell)?;
                let Some(sp) = sh.part("CLOSED_SHELL").or(sh.part("OPEN_SHELL")) else {
                    return Err(self.invalid(shell, "expected CLOSED_SHELL or OPEN_SHELL"));
                };
                for f in self.refs(shell, self.list(shell, sp, 1)?)? {
                    *out.entry(face(f)?).or_default() ^= true;
                }
            }
        }
        Ok(out)
    }

    fn at(&self, id: usize) -> Location {
        let line = self.ex.instances.get(&id).map_or(0, |i| i.line);
        Location::file(self.file).line(line)
    }

    fn invalid(&self, id: usize, what: impl std::fmt::Display) -> Problem {
        Problem::Invalid(Error::input(format!("#{id}: {what}")).at(self.at(id)))
    }

    fn unsupported(&self, id: usize, role: &str, read: &str) -> Problem {
        let k = self.ex.instances.get(&id).map_or(String::new(), Instance::keyword);
        Problem::Unsupported(
            Error::input(format!("unsupported entity {k} #{id} ({role}): the STEP reader takes {read}"))
                .at(self.at(id)),
        )
    }

    fn get(&self, id: usize) -> Res<&Instance> {
        self.ex.instances.get(&id).ok_or_else(|| {
            Problem::Invalid(Error::input(format!("#{id} is referenced but not defined")).at(Location::file(self.file)))
        })
    }

    /// The parameters of `id`'s part named `keyword`.
    fn part(&self, id: usize, keyword: &str) -> Res<&[Param]> {
        self.get(id)?.part(keyword).ok_or_else(|| self.invalid(id, format!("expected {keyword}")))
    }

    fn num(&self, id: usize, p: &[Param], i: usize) -> Res<f64> {
        match p.get(i) {
            Some(Param::Num(v)) => Ok(*v),
            Some(Param::Typed(_, v)) if matches!(v.first(), Some(Param::Num(_))) => self.num(id, v, 0),
            _ => Err(self.invalid(id, format!("parameter {} should be a number", i + 1))),
        }
    }

    fn reference(&self, id: usize, p: &[Param], i: usize) -> Res<usize> {
        match p.get(i) {
            Some(Param::Ref(r)) => Ok(*r),
            _ => Err(self.invalid(id, format!("parameter {} should be a reference #n", i + 1))),
        }
    }

    fn list<'p>(&self, id: usize, p: &'p [Param], i: usize) -> Res<&'p [Param]> {
        match p.get(i) {
            Some(Param::List(l)) => Ok(l),
            _ => Err(self.invalid(id, format!("parameter {} should be a list", i + 1))),
        }
    }

    fn boolean(&self, id: usize, p: &[Param], i: usize) -> Res<bool> {
        match p.get(i) {
            Some(Param::Enum(e)) if e == "T" => Ok(true),
            Some(Param::Enum(e)) if e == "F" => Ok(false),
            _ => Err(self.invalid(id, format!("parameter {} should be .T. or .F.", i + 1))),
        }
    }

    fn nums(&self, id: usize, p: &[Param]) -> Res<Vec<f64>> {
        (0..p.len()).map(|i| self.num(id, p, i)).collect()
    }

    fn refs(&self, id: usize, p: &[Param]) -> Res<Vec<usize>> {
        (0..p.len()).map(|i| self.reference(id, p, i)).collect()
    }

    /// The size of the file's unit of `kind` in `base` units: an SI unit with its prefix, or a
    /// conversion-based one (INCH, DEGREE) through its measure; 1 when the file names none.
    fn unit(&self, kind: &str, si: &str, per_si: f64) -> Res<f64> {
        let mut ids: Vec<usize> =
            self.ex.instances.iter().filter(|(_, i)| i.part(kind).is_some()).map(|(k, _)| *k).collect();
        ids.sort_unstable();
        // The unit the geometry's context assigns, else the first of the kind.
        let assigned =
            self.ex.instances.values().filter_map(|i| i.part("GLOBAL_UNIT_ASSIGNED_CONTEXT")).find_map(|p| {
                let Some(Param::List(units)) = p.first() else { return None };
                units.iter().find_map(|u| match u {
                    Param::Ref(r) if ids.contains(r) => Some(*r),
                    _ => None,
                })
            });
        let Some(id) = assigned.or(ids.first().copied()) else { return Ok(1.0) };
        self.unit_of(id, si, per_si)
    }

    fn unit_of(&self, id: usize, si: &str, per_si: f64) -> Res<f64> {
        let inst = self.get(id)?;
        if let Some(p) = inst.part("SI_UNIT") {
            let prefix = match p.first() {
                Some(Param::Enum(e)) => match e.as_str() {
                    "MILLI" => 1e-3,
                    "CENTI" => 1e-2,
                    "DECI" => 1e-1,
                    "MICRO" => 1e-6,
                    "KILO" => 1e3,
                    _ => return Err(self.invalid(id, format!("unit prefix .{e}. is not read"))),
                },
                _ => 1.0,
            };
            return match p.get(1) {
                Some(Param::Enum(n)) if n == si => Ok(prefix * per_si),
                _ => Err(self.invalid(id, format!("expected the SI unit .{si}.)"))),
            };
        }
        if let Some(p) = inst.part("CONVERSION_BASED_UNIT") {
            let m = self.reference(id, p, 1)?;
            let mp = &self.get(m)?.parts[0].1;
            let factor = self.num(m, mp, 0)?;
            let base = self.reference(m, mp, 1)?;
            return Ok(factor * self.unit_of(base, si, per_si)?);
        }
        Err(self.invalid(id, "the unit is neither an SI_UNIT nor a CONVERSION_BASED_UNIT"))
    }

    /// A CARTESIAN_POINT in mm.
    fn point(&self, id: usize) -> Res<P3> {
        let p = self.part(id, "CARTESIAN_POINT")?;
        let c = self.nums(id, self.list(id, p, 1)?)?;
        if c.len() != 3 {
            return Err(self.invalid(id, "a 3-D point needs three coordinates"));
        }
        let q = P3::new(c[0], c[1], c[2]) * self.mm;
        self.within_limit(id, q.coords.amax())?;
        Ok(q)
    }

    /// Refuses a coordinate or length beyond ±[`COORD_LIMIT`] mm, as every table does: there the
    /// micrometre tolerances fall below the floating-point resolution.
    fn within_limit(&self, id: usize, v: f64) -> Res<()> {
        if v.abs() <= COORD_LIMIT {
            return Ok(());
        }
        Err(self.invalid(id, format!("{v:e} mm is beyond ±{COORD_LIMIT:e} mm, where the micrometre tolerances fall below the floating-point resolution")))
    }

    /// A DIRECTION, unit.
    fn direction(&self, id: usize) -> Res<V3> {
        let p = self.part(id, "DIRECTION")?;
        let c = self.nums(id, self.list(id, p, 1)?)?;
        if c.len() != 3 {
            return Err(self.invalid(id, "a 3-D direction needs three components"));
        }
        V3::new(c[0], c[1], c[2]).try_normalize(1e-300).ok_or_else(|| self.invalid(id, "a zero direction"))
    }

    /// An AXIS2_PLACEMENT_3D as the rigid motion from its frame to the model's.
    fn axis2(&self, id: usize) -> Res<Isometry3<f64>> {
        let p = self.part(id, "AXIS2_PLACEMENT_3D")?;
        let origin = self.point(self.reference(id, p, 1)?)?;
        let z = match p.get(2) {
            Some(Param::Ref(d)) => self.direction(*d)?,
            _ => V3::z(),
        };
        let x0 = match p.get(3) {
            Some(Param::Ref(d)) => self.direction(*d)?,
            _ => super::analytic::any_perpendicular(&z),
        };
        let x = (x0 - z * x0.dot(&z))
            .try_normalize(1e-12)
            .ok_or_else(|| self.invalid(id, "ref_direction is parallel to the axis"))?;
        let rot = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, z.cross(&x), z]));
        Ok(Isometry3::from_parts(Translation3::from(origin.coords), UnitQuaternion::from_rotation_matrix(&rot)))
    }

    /// A face as a surface of the model; `reversed` when the shells that hold it turn it over.
    fn face(&self, id: usize, reversed: bool) -> Res<Surface> {
        let p = self.part(id, "ADVANCED_FACE")?;
        let bounds = self.refs(id, self.list(id, p, 1)?)?;
        let sid = self.reference(id, p, 2)?;
        let same_sense = self.boolean(id, p, 3)?;
        let s = self.get(sid)?;
        let analytic = ["PLANE", "CYLINDRICAL_SURFACE", "CONICAL_SURFACE", "SPHERICAL_SURFACE", "TOROIDAL_SURFACE"];
        let kind = s.parts[0].0.as_str();
        let mut profile = None;
        let placement = if s.parts.len() == 1 && analytic.contains(&kind) {
            let sp = &s.parts[0].1;
            Some(self.axis2(self.reference(sid, sp, 1)?)?)
        } else if s.parts.len() == 1 && kind == "SURFACE_OF_REVOLUTION" {
            let (iso, curve) = self.revolution(sid, id)?;
            profile = Some(curve);
            Some(iso)
        } else {
            None
        };
        let to_local = |q: P3| placement.map_or(q, |iso| iso.inverse_transform_point(&q));
        let vec_local = |v: V3| placement.map_or(v, |iso| iso.inverse_transform_vector(&v));
        let mut loops = Vec::new();
        for b in bounds {
            let bp = match self.get(b)?.parts[0].0.as_str() {
                "FACE_BOUND" => self.part(b, "FACE_BOUND")?,
                "FACE_OUTER_BOUND" => self.part(b, "FACE_OUTER_BOUND")?,
                _ => return Err(self.invalid(b, "expected FACE_BOUND or FACE_OUTER_BOUND")),
            };
            let lid = self.reference(b, bp, 1)?;
            let orientation = self.boolean(b, bp, 2)?;
            let lp = self.get(lid)?;
            if lp.part("VERTEX_LOOP").is_some() {
                continue; // a degenerate loop (a cone's apex, a sphere's pole) bounds nothing
            }
            let lp = self.part(lid, "EDGE_LOOP")?;
            let mut edges = Vec::new();
            for oe in self.refs(lid, self.list(lid, lp, 1)?)? {
                let op = self.part(oe, "ORIENTED_EDGE")?;
                let eid = self.reference(oe, op, 3)?;
                let along = self.boolean(oe, op, 4)?;
                let ep = self.part(eid, "EDGE_CURVE")?;
                let vertex = |i: usize| -> Res<P3> {
                    let v = self.reference(eid, ep, i)?;
                    let vp = self.part(v, "VERTEX_POINT")?;
                    self.point(self.reference(v, vp, 1)?)
                };
                let (v1, v2) = (to_local(vertex(1)?), to_local(vertex(2)?));
                let sense = self.boolean(eid, ep, 4)?;
                // The curve's own order runs from a to b.
                let (a, b) = if sense { (v1, v2) } else { (v2, v1) };
                let curve = self.curve(self.reference(eid, ep, 3)?, a, b, &to_local, &vec_local)?;
                // A curve that misses its vertices (a moved centre or control point) makes a loop
                // with gaps: its inside is undefined and the tessellation refines without end.
                let (s, e) = curve.ends();
                let off = ((s - a).norm().max((e - b).norm())).min((s - b).norm().max((e - a).norm()));
                if off > EDGE_FIT || off.is_nan() {
                    return Err(self.invalid(
                        eid,
                        format!("the edge's curve ends {off:.3e} mm from its vertices (more than {EDGE_FIT} mm): the edge and its vertices do not fit together"),
                    ));
                }
                edges.push((curve, sense == along));
            }
            if !orientation {
                edges = edges.into_iter().rev().map(|(c, f)| (c, !f)).collect();
            }
            // Each edge must start where the one before it ends (loop order, the first after the last).
            let run = |(c, fwd): &(Curve, bool)| {
                let (s, e) = c.ends();
                if *fwd { (s, e) } else { (e, s) }
            };
            for k in 0..edges.len() {
                let gap = (run(&edges[k]).1 - run(&edges[(k + 1) % edges.len()]).0).norm();
                if gap > EDGE_FIT || gap.is_nan() {
                    return Err(self.invalid(
                        lid,
                        format!("edge {} of the loop ends {gap:.3e} mm from the start of the next (more than {EDGE_FIT} mm): the loop is open", k + 1),
                    ));
                }
            }
            loops.push(edges);
        }
        let zrange = || {
            let b = loops.iter().flatten().fold(super::Aabb::empty(), |b, (c, _)| b.union(&c.bounds()));
            (b.min.z, b.max.z)
        };
        let sp = &s.parts[0].1;
        let carrier = match (s.parts.len(), kind) {
            (1, "PLANE") => Carrier::Analytic(Analytic::Plane { point: P3::origin(), normal: V3::z() }),
            (1, "CYLINDRICAL_SURFACE") => {
                let (from, to) = zrange();
                Carrier::Analytic(Analytic::Cylinder {
                    point: P3::origin(),
                    axis: V3::z(),
                    radius: self.length(sid, sp, 2)?,
                    from,
                    to,
                })
            }
            (1, "CONICAL_SURFACE") => {
                let r = self.num(sid, sp, 2)? * self.mm;
                let angle = self.num(sid, sp, 3)? * self.rad;
                if !(angle > 0.0 && angle < TAU / 4.0) || r < 0.0 {
                    return Err(self.invalid(sid, "a cone needs 0 < semi_angle < 90° and radius ≥ 0"));
                }
                let back = r / angle.tan();
                let (from, to) = zrange();
                Carrier::Analytic(Analytic::Cone {
                    apex: P3::new(0.0, 0.0, -back),
                    axis: V3::z(),
                    half_angle: angle,
                    from: (from + back).max(0.0),
                    to: to + back,
                })
            }
            (1, "SPHERICAL_SURFACE") => {
                Carrier::Analytic(Analytic::Sphere { centre: P3::origin(), radius: self.length(sid, sp, 2)? })
            }
            (1, "TOROIDAL_SURFACE") => Carrier::Analytic(Analytic::Torus {
                centre: P3::origin(),
                axis: V3::z(),
                major: self.length(sid, sp, 2)?,
                minor: self.length(sid, sp, 3)?,
            }),
            _ if s.part("B_SPLINE_SURFACE_WITH_KNOTS").is_some() => Carrier::Patch(self.bspline_surface(sid)?),
            _ if profile.is_some() => Carrier::Revolution(Revolution::new(profile.take().expect("a profile"))),
            _ => return Err(self.unsupported(sid, &format!("the surface of face #{id}"), SURFACES)),
        };
        let kind = match &carrier {
            Carrier::Analytic(Analytic::Plane { .. }) => "plane",
            Carrier::Analytic(Analytic::Cylinder { .. }) => "cylinder",
            Carrier::Analytic(Analytic::Cone { .. }) => "cone",
            Carrier::Analytic(Analytic::Sphere { .. }) => "sphere",
            Carrier::Analytic(Analytic::Torus { .. }) => "torus",
            Carrier::Patch(_) => "bspline",
            Carrier::Revolution(_) => "revolution",
        };
        let face = Face::new(carrier, loops, same_sense);
        // Edges far off their surface are a broken file (a moved control point, a wrong vertex):
        // traced, it gives gaps and endless searches, never the part.
        let (off, edge) = face.edges_off();
        if off > EDGE_FIT || off.is_nan() {
            return Err(self.invalid(
                id,
                format!("edge {} of the face lies {off:.3e} mm off its surface (more than {EDGE_FIT} mm): the face's edges and surface do not fit together", edge + 1),
            ));
        }
        Ok(Surface::new(format!("{kind}#{id}"), Geometry::Face(Box::new(face)), placement, same_sense == reversed))
    }

    /// A SURFACE_OF_REVOLUTION's frame (z its axis, x towards its swept curve) and the swept curve
    /// in that frame, which must lie in the half-plane y = 0, x ≥ 0: a B-spline curve as it is,
    /// a circle as the exact rational spline of four quarter arcs.
    fn revolution(&self, sid: usize, face: usize) -> Res<(Isometry3<f64>, SplineCurve)> {
        let sp = self.part(sid, "SURFACE_OF_REVOLUTION")?;
        let (cid, aid) = (self.reference(sid, sp, 1)?, self.reference(sid, sp, 2)?);
        let ap = self.part(aid, "AXIS1_PLACEMENT")?;
        let origin = self.point(self.reference(aid, ap, 1)?)?;
        let z = match ap.get(2) {
            Some(Param::Ref(d)) => self.direction(*d)?,
            _ => V3::z(),
        };
        let c = self.get(cid)?;
        let curve = if c.parts.len() == 1 && c.parts[0].0 == "CIRCLE" {
            let p = &c.parts[0].1;
            let iso = self.axis2(self.reference(cid, p, 1)?)?;
            let r = self.length(cid, p, 2)?;
            let (x, y) = (iso * V3::x() * r, iso * V3::y() * r);
            ellipse_from(iso * P3::origin(), x, y, iso * P3::new(r, 0.0, 0.0))
        } else if c.part("B_SPLINE_CURVE_WITH_KNOTS").is_some() {
            self.bspline_curve(cid)?
        } else {
            let read = "a B_SPLINE_CURVE_WITH_KNOTS or CIRCLE swept curve";
            return Err(self.unsupported(
                cid,
                &format!("the swept curve of SURFACE_OF_REVOLUTION #{sid} of face #{face}"),
                read,
            ));
        };
        // x towards the control point farthest from the axis.
        let radial = |p: &P3| (p - origin) - z * (p - origin).dot(&z);
        let far = curve.ctrl.iter().map(radial).max_by(|a, b| a.norm().total_cmp(&b.norm())).unwrap_or(V3::zeros());
        let x = far.try_normalize(1e-12).unwrap_or_else(|| super::analytic::any_perpendicular(&z));
        let rot = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, z.cross(&x), z]));
        let iso = Isometry3::from_parts(Translation3::from(origin.coords), UnitQuaternion::from_rotation_matrix(&rot));
        let ctrl: Vec<P3> = curve.ctrl.iter().map(|p| iso.inverse_transform_point(p)).collect();
        let tol = 1e-9 * (1.0 + far.norm());
        if ctrl.iter().any(|p| p.y.abs() > tol || p.x < -tol) {
            return Err(self.unsupported(
                sid,
                &format!("the surface of face #{face}, whose swept curve is not in a half-plane through the axis"),
                "surfaces of revolution of plane profiles",
            ));
        }
        let ctrl = ctrl.into_iter().map(|p| P3::new(p.x.max(0.0), 0.0, p.z)).collect();
        Ok((iso, SplineCurve { ctrl, ..curve }))
    }

    /// A positive length parameter in mm.
    fn length(&self, id: usize, p: &[Param], i: usize) -> Res<f64> {
        let v = self.num(id, p, i)? * self.mm;
        self.within_limit(id, v)?;
        if v > 0.0 { Ok(v) } else { Err(self.invalid(id, format!("parameter {} must be a positive length", i + 1))) }
    }

    /// An edge's curve in the face's frame, from `a` to `b` in the curve's own order.
    fn curve(&self, cid: usize, a: P3, b: P3, to_local: &dyn Fn(P3) -> P3, vec_local: &dyn Fn(V3) -> V3) -> Res<Curve> {
        let c = self.get(cid)?;
        let k = c.parts[0].0.as_str();
        if c.parts.len() == 1 && matches!(k, "SURFACE_CURVE" | "SEAM_CURVE" | "INTERSECTION_CURVE") {
            let inner = self.reference(cid, &c.parts[0].1, 1)?;
            return self.curve(inner, a, b, to_local, vec_local);
        }
        match (c.parts.len(), k) {
            (1, "LINE") => Ok(Curve::Line { a, b }),
            (1, "CIRCLE") => {
                let p = &c.parts[0].1;
                let iso = self.axis2(self.reference(cid, p, 1)?)?;
                let radius = self.length(cid, p, 2)?;
                let centre = to_local(iso * P3::origin());
                let (x, y) = (vec_local(iso * V3::x()), vec_local(iso * V3::y()));
                let angle = |q: P3| (q - centre).dot(&y).atan2((q - centre).dot(&x));
                let t0 = angle(a);
                let mut t1 = t0 + (angle(b) - t0).rem_euclid(TAU);
                if t1 - t0 < 1e-12 {
                    t1 += TAU; // a closed edge: the whole circle
                }
                Ok(Curve::Arc { centre, x, y, radius, t0, t1 })
            }
            (1, "ELLIPSE") => {
                let p = &c.parts[0].1;
                let iso = self.axis2(self.reference(cid, p, 1)?)?;
                let (ra, rb) = (self.length(cid, p, 2)?, self.length(cid, p, 3)?);
                let centre = to_local(iso * P3::origin());
                let (x, y) = (vec_local(iso * V3::x()) * ra, vec_local(iso * V3::y()) * rb);
                let curve = ellipse_from(centre, x, y, a);
                let t1 = if (a - b).norm() <= 1e-9 * (1.0 + a.coords.norm()) {
                    ELLIPSE_DOMAIN // a closed edge: the whole ellipse
                } else {
                    curve.nearest(&b, 0.0, ELLIPSE_DOMAIN).0
                };
                Ok(Curve::spline(curve, 0.0, t1))
            }
            _ if c.part("B_SPLINE_CURVE_WITH_KNOTS").is_some() => {
                let mut curve = self.bspline_curve(cid)?;
                curve.ctrl = curve.ctrl.into_iter().map(to_local).collect();
                let [d0, d1] = curve.domain();
                let (t0, t1) = if (a - b).norm() <= 1e-9 * (1.0 + a.coords.norm()) {
                    (d0, d1)
                } else {
                    let ta = curve.nearest(&a, d0, d1).0;
                    let tb = curve.nearest(&b, d0, d1).0;
                    (ta.min(tb), ta.max(tb))
                };
                Ok(Curve::spline(curve, t0, t1))
            }
            _ => Err(self.unsupported(cid, "an edge curve", CURVES)),
        }
    }

    /// Knots from distinct values and multiplicities.
    fn knots(&self, id: usize, mults: &[Param], values: &[Param]) -> Res<Vec<f64>> {
        let m = self.nums(id, mults)?;
        let v = self.nums(id, values)?;
        if m.len() != v.len() || m.iter().any(|x| *x < 1.0 || x.fract() != 0.0) {
            return Err(self.invalid(id, "knot multiplicities and knots must pair up"));
        }
        // A knot vector is one knot more than control points and degree together: far fewer.
        if m.iter().sum::<f64>() > MAX_KNOTS {
            return Err(self.invalid(id, format!("more than {MAX_KNOTS:e} knots")));
        }
        Ok(v.iter().zip(&m).flat_map(|(k, n)| std::iter::repeat_n(*k, *n as usize)).collect())
    }

    /// A B_SPLINE_CURVE_WITH_KNOTS, simple or complex (rational), in the file's frame (mm).
    fn bspline_curve(&self, id: usize) -> Res<SplineCurve> {
        let inst = self.get(id)?;
        let (head, tail) = match inst.part("B_SPLINE_CURVE") {
            Some(h) => (h, self.part(id, "B_SPLINE_CURVE_WITH_KNOTS")?),
            None => {
                let p = self.part(id, "B_SPLINE_CURVE_WITH_KNOTS")?;
                (p.get(1..).unwrap_or_default(), p.get(6..).unwrap_or_default())
            }
        };
        let degree = self.num(id, head, 0)?;
        let ctrl =
            self.refs(id, self.list(id, head, 1)?)?.into_iter().map(|c| self.point(c)).collect::<Res<Vec<_>>>()?;
        let knots = self.knots(id, self.list(id, tail, 0)?, self.list(id, tail, 1)?)?;
        let weights = match inst.part("RATIONAL_B_SPLINE_CURVE") {
            Some(w) => Some(self.nums(id, self.list(id, w, 0)?)?),
            None => None,
        };
        let p = degree as usize;
        if degree.fract() != 0.0 || !(1..=MAX_DEGREE).contains(&p) {
            return Err(self.invalid(id, format!("curve degree must be 1 to {MAX_DEGREE}")));
        }
        if knots.len() != ctrl.len() + p + 1
            || knots.windows(2).any(|w| w[1] < w[0])
            || weights.as_ref().is_some_and(|w| w.len() != ctrl.len() || w.iter().any(|x| *x <= 0.0))
        {
            return Err(self.invalid(id, "knots, control points and weights do not fit together"));
        }
        Ok(SplineCurve { degree: p, ctrl, weights, knots })
    }

    /// A B_SPLINE_SURFACE_WITH_KNOTS, simple or complex (rational), in mm.
    fn bspline_surface(&self, id: usize) -> Res<BSpline> {
        let inst = self.get(id)?;
        let (head, tail) = match inst.part("B_SPLINE_SURFACE") {
            Some(h) => (h, self.part(id, "B_SPLINE_SURFACE_WITH_KNOTS")?),
            None => {
                let p = self.part(id, "B_SPLINE_SURFACE_WITH_KNOTS")?;
                (p.get(1..).unwrap_or_default(), p.get(8..).unwrap_or_default())
            }
        };
        let degree = [self.num(id, head, 0)?, self.num(id, head, 1)?];
        let mut net = Vec::new();
        for row in self.list(id, head, 2)? {
            let Param::List(row) = row else { return Err(self.invalid(id, "control points must be a list of lists")) };
            net.push(self.refs(id, row)?.into_iter().map(|c| self.point(c)).collect::<Res<Vec<_>>>()?);
        }
        let weights = match inst.part("RATIONAL_B_SPLINE_SURFACE") {
            Some(w) => {
                let mut rows = Vec::new();
                for row in self.list(id, w, 0)? {
                    let Param::List(row) = row else { return Err(self.invalid(id, "weights must be a list of lists")) };
                    rows.push(self.nums(id, row)?);
                }
                Some(rows)
            }
            None => None,
        };
        let ku = self.knots(id, self.list(id, tail, 0)?, self.list(id, tail, 2)?)?;
        let kv = self.knots(id, self.list(id, tail, 1)?, self.list(id, tail, 3)?)?;
        let (p, q) = (degree[0] as usize, degree[1] as usize);
        let (nu, nv) = (net.len(), net.first().map_or(0, Vec::len));
        let fits = degree.iter().all(|d| d.fract() == 0.0 && (1.0..=MAX_DEGREE as f64).contains(d))
            && nu > p
            && nv > q
            && net.iter().all(|r| r.len() == nv)
            && ku.len() == nu + p + 1
            && kv.len() == nv + q + 1
            && ku.windows(2).chain(kv.windows(2)).all(|w| w[1] >= w[0])
            && ku[p] < ku[nu]
            && kv[q] < kv[nv]
            && weights.as_ref().is_none_or(|w| {
                w.len() == nu && w.iter().all(|r| r.len() == nv && r.iter().all(|x| x.is_finite() && *x > 0.0))
            });
        if !fits {
            return Err(self.invalid(
                id,
                format!("degrees (1 to {MAX_DEGREE}), knots, control points and weights do not fit together"),
            ));
        }
        Ok(BSpline::with_weights(&net, weights.as_deref(), [p, q], Some(ku), Some(kv)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;

    fn block() -> Model {
        let data = include_bytes!("../../../../data/step/block.step").to_vec();
        Model::load(&Input { name: "block.step".into(), data }).unwrap()
    }

    /// The block of `scripts/step-models.py` against its closed forms: nearest points, distances
    /// and outward normals (out of the material) on every kind of face.
    #[test]
    fn block_faces_against_closed_forms() {
        let m = block();
        let kinds: Vec<&str> = m.surfaces.iter().map(|s| s.name.split('#').next().unwrap()).collect();
        for (k, n) in [("plane", 7), ("cylinder", 5), ("sphere", 1), ("torus", 1)] {
            assert_eq!(kinds.iter().filter(|x| **x == k).count(), n, "{kinds:?}");
        }
        let dish = P3::new(50.0, 50.0, 70.0);
        let hole = P3::new(85.0, 85.0, 38.0);
        let check = |q: P3, point: P3, normal: V3, kind: &str| {
            let n = m.nearest(&q);
            assert!(m.surfaces[n.surface].name.starts_with(kind), "{q}: {}", m.surfaces[n.surface].name);
            assert!((n.point - point).norm() < 1e-10, "{q}: {} vs {point}", n.point);
            assert!((n.normal - normal).norm() < 1e-10, "{q}: normal {} vs {normal}", n.normal);
            assert!(n.converged);
        };
        // The dish: the sphere's foot, normal towards the centre (out of the material).
        for q in [P3::new(50.0, 50.0, 45.0), P3::new(60.0, 45.0, 38.0), P3::new(45.0, 55.0, 42.0)] {
            let u = (q - dish).normalize();
            check(q, dish + u * 40.0, -u, "sphere");
        }
        // High over the dish the top plane's hole rim is nearer than the dish's bottom.
        let q = P3::new(50.0, 50.0, 100.0);
        let n = m.nearest(&q);
        let rim = (40.0f64 * 40.0 - 30.0 * 30.0).sqrt();
        assert!((n.distance - rim.hypot(60.0)).abs() < 1e-10 && (n.point.z - 40.0).abs() < 1e-12, "{}", n.point);
        // The top plane beside the dish and its fillet-rimmed hole.
        check(P3::new(20.0, 80.0, 47.0), P3::new(20.0, 80.0, 40.0), V3::z(), "plane");
        // The hole's wall (normal towards its axis), its floor, and the torus rounding its rim.
        check(P3::new(85.0, 88.0, 30.0), P3::new(85.0, 91.0, 30.0), -V3::y(), "cylinder");
        check(P3::new(84.0, 85.0, 26.0), P3::new(84.0, 85.0, 25.0), V3::z(), "plane");
        let q = P3::new(85.0 - 6.5, 85.0, 39.5);
        let tube = hole + V3::new(-8.0, 0.0, 0.0);
        let u = (q - tube).normalize();
        check(q, tube + u * 2.0, u, "torus");
        // A vertical corner fillet R8 round (8, 8) and a side.
        let q = P3::new(2.0, 3.0, 20.0);
        let u = V3::new(-6.0, -5.0, 0.0).normalize();
        check(q, P3::new(8.0, 8.0, 20.0) + u * 8.0, u, "cylinder");
        check(P3::new(-5.0, 50.0, 20.0), P3::new(0.0, 50.0, 20.0), -V3::x(), "plane");
        check(P3::new(50.0, 50.0, -3.0), P3::new(50.0, 50.0, 0.0), -V3::z(), "plane");
    }

    fn data(name: &str) -> Model {
        let path = format!("{}/../../data/step/{name}", env!("CARGO_MANIFEST_DIR"));
        Model::load(&Input { name: name.into(), data: std::fs::read(path).unwrap() }).unwrap()
    }

    /// The point of the cubic Bézier profile of revolve.step at t, in (r, z): written out here,
    /// apart from the reader's spline code.
    fn knob_profile(t: f64) -> [f64; 2] {
        let (r, z) = ([30.0, 33.0, 22.0, 25.0], [0.0, 5.0, 10.0, 15.0]);
        let b = [(1.0 - t).powi(3), 3.0 * t * (1.0 - t).powi(2), 3.0 * t * t * (1.0 - t), t.powi(3)];
        [(0..4).map(|i| b[i] * r[i]).sum(), (0..4).map(|i| b[i] * z[i]).sum()]
    }

    /// The knob of revolve.step: its two SURFACE_OF_REVOLUTION faces against the torus's closed
    /// form (the swept exact quarter circle) and a dense search of the cubic profile, within
    /// 0.1 µm, with the outward normal along q − foot.
    #[test]
    fn surfaces_of_revolution_against_closed_forms() {
        let m = data("revolve.step");
        let kinds: Vec<&str> = m.surfaces.iter().map(|s| s.name.split('#').next().unwrap()).collect();
        assert_eq!(kinds.iter().filter(|k| **k == "revolution").count(), 2, "{kinds:?}");
        assert_eq!(kinds.iter().filter(|k| **k == "plane").count(), 2, "{kinds:?}");
        for (x, y, z) in [(24.0, 3.0, 18.0), (-15.0, 18.0, 21.0), (0.5, -27.0, 16.0), (19.0, -12.0, 19.5)] {
            let q = P3::new(x, y, z);
            let n = m.nearest(&q);
            let rho: f64 = x.hypot(y);
            let want = ((rho - 20.0).hypot(z - 15.0) - 5.0).abs();
            assert!(m.surfaces[n.surface].name.starts_with("revolution"), "{q}: {}", m.surfaces[n.surface].name);
            assert!((n.distance - want).abs() < 1e-7, "{q}: {} vs {want}", n.distance);
            assert!((n.normal - n.direction(&q)).norm() < 1e-7, "{q}: normal {}", n.normal);
        }
        for (x, y, z) in [(33.0, 4.0, 5.0), (-20.0, -15.0, 8.0), (0.0, 28.0, 12.0), (24.0, 24.0, 2.0)] {
            let q = P3::new(x, y, z);
            let n = m.nearest(&q);
            let rho: f64 = x.hypot(y);
            let d = |t: f64| {
                let [r, h] = knob_profile(t);
                (r - rho).hypot(h - z)
            };
            // The densest sample, then golden sections on its neighbourhood.
            let k: usize = 100_000;
            let i = (0..=k).min_by(|a, b| d(*a as f64 / k as f64).total_cmp(&d(*b as f64 / k as f64))).unwrap();
            let (a, b) = (i.saturating_sub(1) as f64 / k as f64, ((i + 1).min(k)) as f64 / k as f64);
            let want = d(crate::num::golden_arg(|t| -d(t), a, b, 100));
            assert!(m.surfaces[n.surface].name.starts_with("revolution"), "{q}: {}", m.surfaces[n.surface].name);
            assert!((n.distance - want).abs() < 1e-7, "{q}: {} vs {want}", n.distance);
            // Outward: along q − foot outside the knob, against it inside.
            assert!(n.normal.cross(&n.direction(&q)).norm() < 1e-6, "{q}: normal {}", n.normal);
            assert!(n.normal.z.abs() < 1.0 && n.normal.xy().dot(&q.coords.xy()) > 0.0, "{q}: normal {}", n.normal);
        }
        // Over the top disc.
        let n = m.nearest(&P3::new(5.0, -6.0, 23.0));
        assert!((n.point - P3::new(5.0, -6.0, 20.0)).norm() < 1e-12 && n.normal == V3::z(), "{}", n.point);
    }

    /// The closed periodic B-spline tube of tube.step is the cone r = 10 + z/6 (0 ≤ z ≤ 30): nearest
    /// points on both sides of its seam (u = 0 on +x) and inside it against that closed form.
    #[test]
    fn closed_bspline_tube_against_its_cone() {
        let m = data("tube.step");
        assert_eq!(m.surfaces.len(), 1);
        // Distance from (r, z) to the cone's generating segment (10, 0)–(15, 30).
        let cone = |q: &P3| {
            let (p, a, b) = ([q.x.hypot(q.y), q.z], [10.0, 0.0], [15.0, 30.0]);
            let d = [b[0] - a[0], b[1] - a[1]];
            let t = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1])).clamp(0.0, 1.0);
            (p[0] - a[0] - t * d[0]).hypot(p[1] - a[1] - t * d[1])
        };
        for (x, y, z) in [
            (14.0, 0.01, 12.0),
            (14.0, -0.01, 12.0),
            (8.0, -1e-7, 20.0),
            (9.0, 1e-7, 3.0),
            (-3.0, 11.0, 25.0),
            (0.0, -16.0, 4.0),
            (2.0, 2.0, 15.0),
            (13.0, 0.0, 33.0),
        ] {
            let q = P3::new(x, y, z);
            let n = m.nearest(&q);
            assert!((n.distance - cone(&q)).abs() < 1e-7, "{q}: {} vs {}", n.distance, cone(&q));
            assert!(n.converged);
        }
    }

    /// The void of void.step (an ORIENTED_CLOSED_SHELL .F. round a sphere face): its normal
    /// points into the void, out of the material; the block's outside faces point out.
    #[test]
    fn a_reversed_shell_turns_its_faces_over() {
        let m = data("void.step");
        let centre = P3::new(30.0, 30.0, 20.0);
        for q in [P3::new(30.0, 30.0, 22.0), P3::new(25.0, 33.0, 18.0), P3::new(30.0, 30.0, 28.0)] {
            let n = m.nearest(&q);
            let u = (q - centre).normalize();
            assert!(m.surfaces[n.surface].name.starts_with("sphere"), "{}", m.surfaces[n.surface].name);
            assert!((n.point - (centre + u * 10.0)).norm() < 1e-12, "{q}: {}", n.point);
            assert!((n.normal + u).norm() < 1e-12, "{q}: normal {} should point into the void", n.normal);
        }
        let n = m.nearest(&P3::new(30.0, 30.0, 45.0));
        assert!((n.point - P3::new(30.0, 30.0, 40.0)).norm() < 1e-12 && n.normal == V3::z());
        // The sphere face, bounded by a vertex loop alone, is the whole sphere.
        let n = m.nearest(&P3::new(30.0, 30.0, 15.0));
        assert!((n.point - P3::new(30.0, 30.0, 10.0)).norm() < 1e-12, "{}", n.point);
    }

    fn step(body: &str) -> String {
        format!("ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n{body}ENDSEC;\nEND-ISO-10303-21;\n")
    }

    fn load(text: &str, skip: bool) -> Result<Model> {
        Model::load_with(&Input { name: "t.stp".into(), data: text.as_bytes().to_vec() }, skip)
    }

    /// One square face 0..10 on the plane z = 0 in the given unit, and a face on a surface of
    /// revolution.
    fn square(unit: &str, second_surface: &str) -> String {
        let mut s = String::from(
            "#1 = CARTESIAN_POINT('',(0.,0.,0.));\n#2 = DIRECTION('',(0.,0.,1.));\n#3 = DIRECTION('',(1.,0.,0.));\n\
             #4 = AXIS2_PLACEMENT_3D('',#1,#2,#3);\n#5 = PLANE('',#4);\n",
        );
        let c = [(0, 0), (10, 0), (10, 10), (0, 10)];
        for (k, (x, y)) in c.iter().enumerate() {
            s += &format!(
                "#{} = CARTESIAN_POINT('',({x}.,{y}.,0.));\n#{} = VERTEX_POINT('',#{});\n",
                10 + k,
                20 + k,
                10 + k
            );
        }
        for k in 0..4 {
            s += &format!(
                "#{} = EDGE_CURVE('',#{},#{},#{},.T.);\n#{} = ORIENTED_EDGE('',*,*,#{},.T.);\n#{} = LINE('',#{},#99);\n",
                30 + k,
                20 + k,
                20 + (k + 1) % 4,
                50 + k,
                40 + k,
                30 + k,
                50 + k,
                10 + k
            );
        }
        s += "#99 = VECTOR('',#3,1.);\n#60 = EDGE_LOOP('',(#40,#41,#42,#43));\n#61 = FACE_OUTER_BOUND('',#60,.T.);\n\
              #62 = ADVANCED_FACE('',(#61),#5,.T.);\n";
        s += &format!("#70 = ( LENGTH_UNIT() NAMED_UNIT(*) {unit} );\n");
        s += second_surface;
        s
    }

    #[test]
    fn units_and_unsupported_entities() {
        let m = load(&step(&square("SI_UNIT(.MILLI.,.METRE.)", "")), false).unwrap();
        let n = m.nearest(&P3::new(5.0, 20.0, 3.0));
        assert!((n.point - P3::new(5.0, 10.0, 0.0)).norm() < 1e-12, "{}", n.point);
        let m = load(&step(&square("SI_UNIT($,.METRE.)", "")), false).unwrap();
        assert!((m.nearest(&P3::new(5e3, 2e4, 3.0)).point - P3::new(5e3, 1e4, 0.0)).norm() < 1e-9);
        let inch = "CONVERSION_BASED_UNIT('INCH',#71) );\n#71 = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#72);\n\
                    #72 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.)";
        let m = load(&step(&square(inch, "")), false).unwrap();
        assert!((m.nearest(&P3::new(100.0, 500.0, 3.0)).point - P3::new(100.0, 254.0, 0.0)).norm() < 1e-9);
        let revolved = "#80 = SURFACE_OF_REVOLUTION('',#50,#81);\n#81 = AXIS1_PLACEMENT('',#1,#2);\n\
                        #82 = ADVANCED_FACE('',(#61),#80,.T.);\n";
        let e = load(&step(&square("SI_UNIT(.MILLI.,.METRE.)", revolved)), false).unwrap_err();
        assert_eq!(e.exit_status(), 2);
        assert!(
            e.to_string().starts_with(
                "t.stp:20: unsupported entity LINE #50 (the swept curve of SURFACE_OF_REVOLUTION #80 of face #82)"
            ) && e.to_string().ends_with("--skip-unsupported leaves such faces out"),
            "{e}"
        );
        let m = load(&step(&square("SI_UNIT(.MILLI.,.METRE.)", revolved)), true).unwrap();
        assert_eq!(m.surfaces.len(), 1);
        let e = load(&step("#1 = CARTESIAN_POINT('',(0.,0.,0.));\n"), false).unwrap_err();
        assert!(e.to_string().starts_with("t.stp: no surfaces"), "{e}");
    }

    /// A plane face bounded by a half ellipse (semi-axes 10 and 5) and its major axis: the upper
    /// half, or the lower half whose arc crosses the ellipse's own start; and the whole ellipse.
    fn ellipse_face(from: usize, to: usize, closed: bool) -> String {
        let mut s = String::from(
            "#1 = CARTESIAN_POINT('',(0.,0.,0.));\n#2 = DIRECTION('',(0.,0.,1.));\n#3 = DIRECTION('',(1.,0.,0.));\n\
             #4 = AXIS2_PLACEMENT_3D('',#1,#2,#3);\n#5 = PLANE('',#4);\n#10 = CARTESIAN_POINT('',(10.,0.,0.));\n\
             #11 = CARTESIAN_POINT('',(-10.,0.,0.));\n#20 = VERTEX_POINT('',#10);\n#21 = VERTEX_POINT('',#11);\n\
             #50 = ELLIPSE('',#4,10.,5.);\n#99 = VECTOR('',#3,1.);\n#51 = LINE('',#11,#99);\n",
        );
        if closed {
            s += "#30 = EDGE_CURVE('',#20,#20,#50,.T.);\n#40 = ORIENTED_EDGE('',*,*,#30,.T.);\n#60 = EDGE_LOOP('',(#40));\n";
        } else {
            s += &format!(
                "#30 = EDGE_CURVE('',#{from},#{to},#50,.T.);\n#31 = EDGE_CURVE('',#{to},#{from},#51,.T.);\n\
                 #40 = ORIENTED_EDGE('',*,*,#30,.T.);\n#41 = ORIENTED_EDGE('',*,*,#31,.T.);\n#60 = EDGE_LOOP('',(#40,#41));\n"
            );
        }
        s + "#61 = FACE_OUTER_BOUND('',#60,.T.);\n#62 = ADVANCED_FACE('',(#61),#5,.T.);\n\
             #70 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\n"
    }

    #[test]
    fn ellipse_edges_bound_faces_exactly() {
        // The nearest point of the ellipse by brute force: the true one is no farther.
        let on_ellipse = |q: &P3| {
            (0..200_000)
                .map(|k| {
                    let t = TAU * k as f64 / 200_000.0;
                    (P3::new(10.0 * t.cos(), 5.0 * t.sin(), 0.0) - q).norm()
                })
                .fold(f64::INFINITY, f64::min)
        };
        let upper = load(&step(&ellipse_face(20, 21, false)), false).unwrap();
        let lower = load(&step(&ellipse_face(21, 20, false)), false).unwrap();
        let whole = load(&step(&ellipse_face(20, 20, true)), false).unwrap();
        let near = |m: &Model, q: P3| m.nearest(&q).point;
        assert!((near(&upper, P3::new(6.0, 2.0, 1.0)) - P3::new(6.0, 2.0, 0.0)).norm() < 1e-12);
        assert!((near(&upper, P3::new(6.0, -2.0, 1.0)) - P3::new(6.0, 0.0, 0.0)).norm() < 1e-9);
        assert!((near(&upper, P3::new(0.0, 8.0, 1.0)) - P3::new(0.0, 5.0, 0.0)).norm() < 1e-7);
        assert!((near(&lower, P3::new(6.0, -2.0, 1.0)) - P3::new(6.0, -2.0, 0.0)).norm() < 1e-12);
        assert!((near(&lower, P3::new(6.0, 2.0, 1.0)) - P3::new(6.0, 0.0, 0.0)).norm() < 1e-9);
        assert!((near(&lower, P3::new(0.0, -8.0, 1.0)) - P3::new(0.0, -5.0, 0.0)).norm() < 1e-7);
        for q in [P3::new(12.0, 7.0, 0.5), P3::new(-11.0, -3.0, 2.0), P3::new(3.0, -9.0, -1.0), P3::new(10.5, 0.2, 0.0)]
        {
            let n = whole.nearest(&q);
            let p = n.point;
            assert!(((p.x / 10.0).powi(2) + (p.y / 5.0).powi(2) - 1.0).abs() < 1e-9 && p.z.abs() < 1e-12, "{p}");
            assert!(n.distance <= on_ellipse(&q) + 1e-9, "{q}: {} against {}", n.distance, on_ellipse(&q));
        }
        assert!((near(&whole, P3::new(-4.0, 3.0, 2.0)) - P3::new(-4.0, 3.0, 0.0)).norm() < 1e-12);
    }
}
