//! The model document: a *defined model* made of one or more surfaces (analytic surfaces with any
//! placement, bicubic B-spline or Bézier patches, STL meshes), read with errors naming the JSON
//! path and checked by [`ModelDoc::validate`]. [`crate::model::Model`] turns it into geometry.
//!
//! ```json
//! {"surfaces": [
//!   {"type": "bspline", "name": "free-form", "control_points": [[[0,0,0], [0,25,3]], [[25,0,1], [25,25,4]]], "degree": [1, 1]},
//!   {"type": "sphere", "name": "ball", "centre": [50, 50, -5], "radius": 25},
//!   {"type": "stl", "file": "part.stl", "placement": {"translate": [0, 0, 10], "axis": [0, 0, 1], "angle": 90}}
//! ]}
//! ```

use crate::error::Result;
use crate::json::field_error;
use serde::{Deserialize, Serialize};

/// A whole model: the union of its surfaces.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelDoc {
    /// The surfaces, in order; their index (or name) identifies them in output and options.
    pub surfaces: Vec<SurfaceDoc>,
}

/// A rigid placement applied to a surface: rotation by `angle` degrees about `axis` through the
/// origin, then translation by `translate`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Placement {
    /// Translation (mm), applied after the rotation.
    #[serde(default)]
    pub translate: [f64; 3],
    /// Rotation axis (any length > 0); default z.
    #[serde(default = "z_axis")]
    pub axis: [f64; 3],
    /// Rotation angle (degrees, right-handed about `axis`).
    #[serde(default)]
    pub angle: f64,
}

fn z_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

/// Declares a surface kind's document with the fields every kind shares appended.
macro_rules! surface_kind {
    ($(#[$meta:meta])* $kind:ident { $($(#[$fmeta:meta])* $field:ident : $ty:ty),* $(,)? }) => {
        $(#[$meta])*
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct $kind {
            $($(#[$fmeta])* pub $field: $ty,)*
            /// Name shown in output (default: the kind and index, `sphere#1`).
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub name: Option<String>,
            /// Reverse the outward normal (a bore instead of a boss, the underside of a sheet).
            #[serde(default, skip_serializing_if = "std::ops::Not::not")]
            pub flip: bool,
            /// Rigid placement applied to the surface as defined.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub placement: Option<Placement>,
        }
    };
}

surface_kind!(
    /// An unbounded plane through `point` with outward `normal`.
    PlaneDoc {
        /// A point of the plane (mm).
        point: [f64; 3],
        /// Outward normal (any length > 0).
        normal: [f64; 3],
    }
);
surface_kind!(
    /// A sphere; the normal points away from the centre.
    SphereDoc {
        /// Centre (mm).
        centre: [f64; 3],
        /// Radius (mm).
        radius: f64,
    }
);
surface_kind!(
    /// The lateral surface of a circular cylinder around the line through `point` along `axis`,
    /// limited to `length` = [from, to] mm along the axis from `point` (unbounded if absent).
    CylinderDoc {
        /// A point of the axis (mm).
        point: [f64; 3],
        /// Axis direction.
        axis: [f64; 3],
        /// Radius (mm).
        radius: f64,
        /// Axial extent [from, to] (mm from `point`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        length: Option<[f64; 2]>,
    }
);
surface_kind!(
    /// The lateral surface of a circular cone with its apex at `apex`, opening along `axis` with
    /// `half_angle` degrees, between `length` = [from, to] mm from the apex along the axis.
    ConeDoc {
        /// Apex (mm).
        apex: [f64; 3],
        /// Axis direction, from the apex into the cone.
        axis: [f64; 3],
        /// Half opening angle (degrees).
        half_angle: f64,
        /// Axial extent [from, to] (mm from the apex).
        length: [f64; 2],
    }
);
surface_kind!(
    /// A torus around `axis` through `centre`: a tube of `minor_radius` around a circle of
    /// `major_radius`.
    TorusDoc {
        /// Centre (mm).
        centre: [f64; 3],
        /// Axis direction.
        axis: [f64; 3],
        /// Radius of the tube's centre circle (mm).
        major_radius: f64,
        /// Radius of the tube (mm).
        minor_radius: f64,
    }
);
surface_kind!(
    /// A B-spline surface: `control_points[i][j]` (i along u, j along v), degrees [p, q]
    /// (default [3, 3]), knot vectors (default clamped uniform), and weights for a NURBS
    /// surface. The normal is Su × Sv.
    BsplineDoc {
        /// Control net, rows along u.
        control_points: Vec<Vec<[f64; 3]>>,
        /// Degrees [p, q] in u and v, 1 to 7.
        #[serde(default = "cubic")]
        degree: [usize; 2],
        /// Knots in u: non-decreasing, n + p + 1 of them.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        knots_u: Option<Vec<f64>>,
        /// Knots in v.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        knots_v: Option<Vec<f64>>,
        /// Weights of the control points, same shape as the net (a NURBS surface); all > 0.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        weights: Option<Vec<Vec<f64>>>,
    }
);
surface_kind!(
    /// A Bézier patch: one span whose degrees are the net's size less one (4 × 4 is bicubic).
    BezierDoc {
        /// Control net, rows along u.
        control_points: Vec<Vec<[f64; 3]>>,
    }
);
surface_kind!(
    /// A triangle mesh from an STL file (binary or ASCII), relative to the model document.
    StlDoc {
        /// Path of the STL file, relative to the model document.
        file: String,
    }
);

fn cubic() -> [usize; 2] {
    [3, 3]
}

/// One surface of a model, tagged by `type`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case")]
#[allow(missing_docs)] // each kind is documented on its struct
pub enum SurfaceDoc {
    Plane(PlaneDoc),
    Sphere(SphereDoc),
    Cylinder(CylinderDoc),
    Cone(ConeDoc),
    Torus(TorusDoc),
    Bspline(BsplineDoc),
    Bezier(BezierDoc),
    Stl(StlDoc),
}

/// Largest degree of a patch.
pub const MAX_DEGREE: usize = 7;

impl SurfaceDoc {
    /// The kind's name as written in `type`.
    pub fn kind(&self) -> &'static str {
        match self {
            SurfaceDoc::Plane(_) => "plane",
            SurfaceDoc::Sphere(_) => "sphere",
            SurfaceDoc::Cylinder(_) => "cylinder",
            SurfaceDoc::Cone(_) => "cone",
            SurfaceDoc::Torus(_) => "torus",
            SurfaceDoc::Bspline(_) => "bspline",
            SurfaceDoc::Bezier(_) => "bezier",
            SurfaceDoc::Stl(_) => "stl",
        }
    }

    /// The shared fields: name, flip, placement.
    pub fn common(&self) -> (Option<&str>, bool, Option<&Placement>) {
        macro_rules! c {
            ($d:expr) => {
                ($d.name.as_deref(), $d.flip, $d.placement.as_ref())
            };
        }
        match self {
            SurfaceDoc::Plane(d) => c!(d),
            SurfaceDoc::Sphere(d) => c!(d),
            SurfaceDoc::Cylinder(d) => c!(d),
            SurfaceDoc::Cone(d) => c!(d),
            SurfaceDoc::Torus(d) => c!(d),
            SurfaceDoc::Bspline(d) => c!(d),
            SurfaceDoc::Bezier(d) => c!(d),
            SurfaceDoc::Stl(d) => c!(d),
        }
    }
}

impl ModelDoc {
    /// Checks every dimension; errors name the file and the JSON path of the field.
    pub fn validate(&self, file: &str) -> Result<()> {
        if self.surfaces.is_empty() {
            return Err(field_error(file, "surfaces", "a model needs at least one surface"));
        }
        let mut names: Vec<String> = Vec::new();
        for (i, s) in self.surfaces.iter().enumerate() {
            let at = |field: &str| {
                if field.is_empty() { format!("surfaces[{i}]") } else { format!("surfaces[{i}].{field}") }
            };
            let err = |field: &str, msg: String| field_error(file, &at(field), msg);
            let finite = |field: &str, v: &[f64]| -> Result<()> {
                if v.iter().all(|x| x.is_finite()) { Ok(()) } else { Err(err(field, "numbers must be finite".into())) }
            };
            let positive = |field: &str, v: f64| -> Result<()> {
                if v.is_finite() && v > 0.0 {
                    Ok(())
                } else {
                    Err(err(field, format!("{field} must be a positive number of mm, got {v}")))
                }
            };
            let direction = |field: &str, v: &[f64; 3]| -> Result<()> {
                finite(field, v)?;
                if v.iter().map(|x| x * x).sum::<f64>().sqrt() > crate::tol::LENGTH_EPS {
                    Ok(())
                } else {
                    Err(err(field, format!("{field} must be a non-zero direction")))
                }
            };
            let (name, _, placement) = s.common();
            if let Some(name) = name {
                if name.is_empty() || names.iter().any(|n| n == name) {
                    return Err(err("name", format!("surface names must be non-empty and unique, got {name:?}")));
                }
                names.push(name.to_string());
            }
            if let Some(p) = placement {
                finite("placement.translate", &p.translate)?;
                direction("placement.axis", &p.axis)?;
                finite("placement.angle", &[p.angle])?;
            }
            match s {
                SurfaceDoc::Plane(d) => {
                    finite("point", &d.point)?;
                    direction("normal", &d.normal)?;
                }
                SurfaceDoc::Sphere(d) => {
                    finite("centre", &d.centre)?;
                    positive("radius", d.radius)?;
                }
                SurfaceDoc::Cylinder(d) => {
                    finite("point", &d.point)?;
                    direction("axis", &d.axis)?;
                    positive("radius", d.radius)?;
                    if let Some([a, b]) = d.length {
                        if !(a.is_finite() && b.is_finite() && a < b) {
                            return Err(err(
                                "length",
                                format!("length must be [from, to] with from < to, got [{a}, {b}]"),
                            ));
                        }
                    }
                }
                SurfaceDoc::Cone(d) => {
                    finite("apex", &d.apex)?;
                    direction("axis", &d.axis)?;
                    if !(d.half_angle > 0.0 && d.half_angle < 90.0) {
                        return Err(err(
                            "half_angle",
                            format!("half_angle must be between 0 and 90 degrees, got {}", d.half_angle),
                        ));
                    }
                    let [a, b] = d.length;
                    if !(a.is_finite() && b.is_finite() && 0.0 <= a && a < b) {
                        return Err(err(
                            "length",
                            format!("length must be [from, to] with 0 ≤ from < to, got [{a}, {b}]"),
                        ));
                    }
                }
                SurfaceDoc::Torus(d) => {
                    finite("centre", &d.centre)?;
                    direction("axis", &d.axis)?;
                    positive("major_radius", d.major_radius)?;
                    positive("minor_radius", d.minor_radius)?;
                }
                SurfaceDoc::Bspline(d) => {
                    check_net(&d.control_points, &at("control_points"), file)?;
                    let (nu, nv) = (d.control_points.len(), d.control_points[0].len());
                    let [p, q] = d.degree;
                    for (deg, n, field) in [(p, nu, "degree"), (q, nv, "degree")] {
                        if !(1..=MAX_DEGREE).contains(&deg) || deg >= n {
                            return Err(err(
                                field,
                                format!(
                                    "degree must be 1 to {MAX_DEGREE} and below the number of control points ({n}), got {deg}"
                                ),
                            ));
                        }
                    }
                    check_knots(d.knots_u.as_deref(), nu, p, &at("knots_u"), file)?;
                    check_knots(d.knots_v.as_deref(), nv, q, &at("knots_v"), file)?;
                    if let Some(w) = &d.weights {
                        check_weights(w, nu, nv, &at("weights"), file)?;
                    }
                }
                SurfaceDoc::Bezier(d) => {
                    check_net(&d.control_points, &at("control_points"), file)?;
                    let (nu, nv) = (d.control_points.len(), d.control_points[0].len());
                    if nu < 2 || nv < 2 || nu > MAX_DEGREE + 1 || nv > MAX_DEGREE + 1 {
                        return Err(err(
                            "control_points",
                            format!("a Bézier net must be 2 to {} points each way, got {nu} × {nv}", MAX_DEGREE + 1),
                        ));
                    }
                }
                SurfaceDoc::Stl(d) => {
                    if d.file.trim().is_empty() {
                        return Err(err("file", "file must name an STL file".into()));
                    }
                }
            }
        }
        Ok(())
    }
}

/// A rectangular net of finite points, at least 2 × 2.
fn check_net(net: &[Vec<[f64; 3]>], path: &str, file: &str) -> Result<()> {
    if net.len() < 2 || net[0].len() < 2 {
        return Err(field_error(file, path, "a control net needs at least 2 × 2 points"));
    }
    for (i, row) in net.iter().enumerate() {
        if row.len() != net[0].len() {
            return Err(field_error(
                file,
                &format!("{path}[{i}]"),
                format!("every row of the net needs {} points, this one has {}", net[0].len(), row.len()),
            ));
        }
        for (j, p) in row.iter().enumerate() {
            if !p.iter().all(|x| x.is_finite()) {
                return Err(field_error(file, &format!("{path}[{i}][{j}]"), "numbers must be finite"));
            }
        }
    }
    Ok(())
}

/// Weights of a NURBS net: the net's shape, every one finite and positive (which keeps the
/// surface inside its control points' hull).
fn check_weights(w: &[Vec<f64>], nu: usize, nv: usize, path: &str, file: &str) -> Result<()> {
    if w.len() != nu || w.iter().any(|row| row.len() != nv) {
        return Err(field_error(file, path, format!("weights must have the net's shape ({nu} × {nv})")));
    }
    for (i, row) in w.iter().enumerate() {
        for (j, x) in row.iter().enumerate() {
            if !(x.is_finite() && *x > 0.0) {
                return Err(field_error(
                    file,
                    &format!("{path}[{i}][{j}]"),
                    format!("a weight must be a positive number, got {x}"),
                ));
            }
        }
    }
    Ok(())
}

/// `n + p + 1` finite non-decreasing knots with a non-empty domain and no knot repeated more than
/// `p` times inside it.
fn check_knots(knots: Option<&[f64]>, n: usize, p: usize, path: &str, file: &str) -> Result<()> {
    let Some(k) = knots else { return Ok(()) };
    if k.len() != n + p + 1 {
        return Err(field_error(
            file,
            path,
            format!("{} knots needed (points + degree + 1), got {}", n + p + 1, k.len()),
        ));
    }
    if !k.iter().all(|x| x.is_finite()) || k.windows(2).any(|w| w[1] < w[0]) {
        return Err(field_error(file, path, "knots must be finite and non-decreasing"));
    }
    if k[p] >= k[n] {
        return Err(field_error(file, path, "the knots leave an empty parameter domain"));
    }
    for w in k[1..n].windows(p + 1) {
        if w[0] == w[p] {
            return Err(field_error(file, path, format!("an inner knot is repeated more than the degree ({p}) times")));
        }
    }
    Ok(())
}

impl ModelDoc {
    /// Reads a model document (not its STL files) and validates it.
    pub fn from_input(input: &crate::io::Input) -> Result<ModelDoc> {
        crate::json::checked(input, ModelDoc::validate)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<ModelDoc> {
        ModelDoc::from_input(&crate::io::Input { name: "m.json".into(), data: text.as_bytes().to_vec() })
    }

    #[test]
    fn reads_every_kind_and_names_bad_fields() {
        let doc = parse(
            r#"{"surfaces": [
              {"type": "sphere", "centre": [0,0,-500], "radius": 500, "name": "dome"},
              {"type": "plane", "point": [0,0,0], "normal": [0,0,1], "flip": true},
              {"type": "cylinder", "point": [0,0,0], "axis": [0,0,1], "radius": 5, "length": [0, 10]},
              {"type": "cone", "apex": [0,0,0], "axis": [0,0,1], "half_angle": 30, "length": [1, 10]},
              {"type": "torus", "centre": [0,0,0], "axis": [0,1,0], "major_radius": 10, "minor_radius": 2,
               "placement": {"translate": [1,2,3], "angle": 15}},
              {"type": "bezier", "control_points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,1]]]},
              {"type": "stl", "file": "part.stl"}
            ]}"#,
        )
        .unwrap();
        assert_eq!(doc.surfaces.len(), 7);
        assert_eq!(doc.surfaces[0].common().0, Some("dome"));
        assert!(doc.surfaces[1].common().1);
        let e = parse(r#"{"surfaces": [{"type": "sphre", "centre": [0,0,0], "radius": 1}]}"#).unwrap_err();
        assert!(e.to_string().starts_with("m.json:1:30 (surfaces[0].type): unknown variant `sphre`"), "{e}");
        let e = parse(r#"{"surfaces": [{"type": "sphere", "centre": [0,0,0]}]}"#).unwrap_err();
        assert!(e.to_string().contains("(surfaces[0]") && e.to_string().contains("missing field `radius`"), "{e}");
        let e =
            parse(r#"{"surfaces": [{"type": "sphere", "centre": [0,0,0], "radius": 1, "colour": 2}]}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `colour`"), "{e}");
        let e = parse(r#"{"surfaces": [{"type": "sphere", "centre": [0,0,0], "radius": -1}]}"#).unwrap_err();
        assert_eq!(e.to_string(), "m.json:1:63 (surfaces[0].radius): radius must be a positive number of mm, got -1");
        let e = parse(r#"{"surfaces": [{"type": "bspline", "control_points": [[[0,0,0],[0,1,0]],[[1,0,0]]]}]}"#)
            .unwrap_err();
        assert!(e.to_string().contains("(surfaces[0].control_points[1])"), "{e}");
        let e =
            parse(r#"{"surfaces": [{"type": "bspline", "control_points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]]}]}"#)
                .unwrap_err();
        assert!(e.to_string().contains("(surfaces[0].degree)"), "{e}");
        let nurbs = |w: &str| {
            parse(&format!(
                r#"{{"surfaces": [{{"type": "bspline", "degree": [1, 1], "weights": {w},
                    "control_points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]]}}]}}"#
            ))
        };
        assert!(nurbs("[[1, 2], [0.5, 1]]").is_ok());
        let e = nurbs("[[1, 2], [0, 1]]").unwrap_err();
        assert!(e.to_string().contains("(surfaces[0].weights[1][0]): a weight must be a positive number"), "{e}");
        let e = nurbs("[[1, 2, 3], [1, 1]]").unwrap_err();
        assert!(e.to_string().contains("(surfaces[0].weights): weights must have the net's shape (2 × 2)"), "{e}");
        assert!(parse(r#"{"surfaces": []}"#).unwrap_err().to_string().contains("at least one surface"));
    }

    /// A value that parses but fails a check is named at its line and column (issue 20, D14).
    #[test]
    fn a_bad_value_names_its_line_and_column() {
        let e = parse("{\"surfaces\": [\n  {\"type\": \"sphere\", \"centre\": [0,0,0], \"radius\": 5},\n  {\"type\": \"sphere\", \"centre\": [0,0,0], \"radius\": -5}]}").unwrap_err();
        assert!(e.to_string().starts_with("m.json:3:"), "{e}");
        assert!(e.to_string().contains("(surfaces[1].radius)"), "{e}");
    }
}
