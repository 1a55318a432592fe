//! The shape document of a known element (`simulate --shape`, `fit --truth`, `plan --fit`,
//! `map --frame`): `{"shape": "sphere", "centre": [..], "radius": r}` and the like, or a frame
//! document (`camkit::doc::Frame`) whose `fit` holds one. Read strictly: unknown fields (a typo
//! such as `radious`), duplicate keys, strings for numbers, a radius that is not positive and a
//! zero normal or axis are bad input naming the file, line, column and JSON path, so a wrong
//! document never reaches a simulation or a report.

use crate::shapes::Shape;
use camkit::doc::Frame;
use camkit::error::Result;
use camkit::geom::V3;
use camkit::io::Input;
use camkit::json::{field_error, from_input};
use serde::de::{Error as _, IgnoredAny};
use serde::{Deserialize, Deserializer};

/// The element's kind as the document names it.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(rename_all = "lowercase")]
enum KindName {
    Sphere,
    Plane,
    Circle,
    Cylinder,
}

/// A shape document as written; a fit's figures (a frame's `fit` carries them) are allowed and
/// not read.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ShapeDoc {
    shape: KindName,
    #[serde(default)]
    centre: Option<[f64; 3]>,
    #[serde(default)]
    point: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "unit")]
    normal: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "unit")]
    axis: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "positive")]
    radius: Option<f64>,
    #[serde(default, rename = "points")]
    _points: Option<IgnoredAny>,
    #[serde(default, rename = "rms")]
    _rms: Option<IgnoredAny>,
    #[serde(default, rename = "largest_residual")]
    _largest_residual: Option<IgnoredAny>,
    #[serde(default, rename = "largest_residual_index")]
    _largest_residual_index: Option<IgnoredAny>,
    #[serde(default, rename = "out_of_plane_rms")]
    _out_of_plane_rms: Option<IgnoredAny>,
    #[serde(default, rename = "iterations")]
    _iterations: Option<IgnoredAny>,
    #[serde(default, rename = "parameters")]
    _parameters: Option<IgnoredAny>,
    #[serde(default, rename = "poorly_determined")]
    _poorly_determined: Option<IgnoredAny>,
    #[serde(default, rename = "robust")]
    _robust: Option<IgnoredAny>,
}

/// A frame document's `fit`, read as a shape document (the frame's own fields are checked by
/// `camkit::doc::Frame`).
#[derive(Deserialize)]
struct FitOf {
    #[serde(default)]
    fit: Option<ShapeDoc>,
}

/// A radius: a positive number of mm (the error carries the value's line and column).
fn positive<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Option<f64>, D::Error> {
    let v = f64::deserialize(d)?;
    if v > 0.0 { Ok(Some(v)) } else { Err(D::Error::custom(format!("must be a positive number of mm, got {v}"))) }
}

/// A direction: three numbers, not all zero; made unit length.
fn unit<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Option<[f64; 3]>, D::Error> {
    let v = V3::from(<[f64; 3]>::deserialize(d)?);
    let n = v.norm();
    if n > 0.0 && n.is_finite() {
        Ok(Some((v / n).into()))
    } else {
        Err(D::Error::custom("must be a non-zero direction [x, y, z]"))
    }
}

/// Reads the shape document (or the frame document with a `fit`) at `path`.
pub fn read_shape(path: &str) -> Result<Shape> {
    let input = Input::open(path)?;
    shape_of(&input).map_err(|e| camkit::json::at_value(&input, e))
}

/// The shape `input` holds (a shape document, or a frame document with a `fit`).
fn shape_of(input: &Input) -> Result<Shape> {
    let peek: serde_json::Value = from_input(input)?;
    if peek.get("shape").is_some() || peek.get("fit").is_none() && peek.get("xc").is_none() {
        let doc: ShapeDoc = from_input(input)?;
        return doc.shape(&input.name, "");
    }
    let frame: Frame = from_input(input)?;
    frame.validate(&input.name)?;
    let fit: FitOf = from_input(input)?;
    match fit.fit {
        Some(doc) => doc.shape(&input.name, "fit."),
        None => Err(field_error(&input.name, "fit", "the frame document holds no fit (a shape)")),
    }
}

impl ShapeDoc {
    /// The element, with the fields its kind needs and no others; `at` prefixes JSON paths.
    fn shape(self, file: &str, at: &str) -> Result<Shape> {
        let (kind, needs): (&str, [&str; 3]) = match self.shape {
            KindName::Sphere => ("sphere", ["centre", "radius", ""]),
            KindName::Plane => ("plane", ["point", "normal", ""]),
            KindName::Circle => ("circle", ["centre", "normal", "radius"]),
            KindName::Cylinder => ("cylinder", ["point", "axis", "radius"]),
        };
        let given = [
            ("centre", self.centre.is_some()),
            ("point", self.point.is_some()),
            ("normal", self.normal.is_some()),
            ("axis", self.axis.is_some()),
            ("radius", self.radius.is_some()),
        ];
        for (name, present) in given {
            if present != needs.contains(&name) {
                let what =
                    if present { format!("a {kind} has no `{name}`") } else { format!("a {kind} needs `{name}`") };
                return Err(field_error(file, &format!("{at}{name}"), what));
            }
        }
        let get = |v: Option<[f64; 3]>| v.unwrap_or_default();
        let radius = self.radius.unwrap_or_default();
        Ok(match self.shape {
            KindName::Sphere => Shape::Sphere { centre: get(self.centre), radius },
            KindName::Plane => Shape::Plane { point: get(self.point), normal: get(self.normal) },
            KindName::Circle => Shape::Circle { centre: get(self.centre), normal: get(self.normal), radius },
            KindName::Cylinder => Shape::Cylinder { point: get(self.point), axis: get(self.axis), radius },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Shape> {
        static COUNT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let k = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let path = std::env::temp_dir().join(format!("spf-doc-{}-{k}.json", std::process::id()));
        std::fs::write(&path, text).unwrap();
        let r = read_shape(path.to_str().unwrap());
        std::fs::remove_file(&path).unwrap();
        r
    }

    /// The error message after the (temporary) file name.
    fn err(text: &str) -> String {
        let e = read(text).unwrap_err().to_string();
        e[e.find(".json").unwrap() + 5..].to_string()
    }

    #[test]
    fn shape_documents_are_read_strictly() {
        let ok = read(r#"{"shape": "sphere", "centre": [1, 2, 3], "radius": 25}"#).unwrap();
        assert_eq!(ok, Shape::Sphere { centre: [1.0, 2.0, 3.0], radius: 25.0 });
        let e = err(r#"{"shape": "sphere", "centre": [1, 2, 3], "radius": 25, "radious": 3}"#);
        assert!(e.starts_with(":1:") && e.contains("(radious): unknown field `radious`"), "{e}");
        let e = err(r#"{"shape": "sphere", "centre": ["5", 2, 3], "radius": 25}"#);
        assert!(e.starts_with(":1:") && e.contains("(centre[0]): invalid type: string"), "{e}");
        let e = err("{\"shape\": \"sphere\", \"centre\": [1, 2, 3],\n \"radius\": -1}");
        assert!(e.starts_with(":2:") && e.contains("(radius): must be a positive number of mm, got -1"), "{e}");
        let e = err(r#"{"shape": "sphere", "centre": [1, 2, 3], "radius": 2, "radius": 3}"#);
        assert!(e.contains("duplicate field `radius`"), "{e}");
        let e = err(r#"{"shape": "plane", "point": [1, 2, 3], "normal": [0, 0, 0]}"#);
        assert!(e.contains("(normal): must be a non-zero direction"), "{e}");
        let e = err(r#"{"shape": "cylinder", "point": [1, 2, 3], "axis": [0, 0, 1]}"#);
        assert!(e.contains("(radius): a cylinder needs `radius`"), "{e}");
        let e = err(r#"{"shape": "plane", "point": [1, 2, 3], "normal": [0, 0, 2], "radius": 1}"#);
        assert!(e.contains("(radius): a plane has no `radius`"), "{e}");
        let p = read(r#"{"shape": "plane", "point": [1, 2, 3], "normal": [0, 0, 2]}"#).unwrap();
        assert_eq!(p, Shape::Plane { point: [1.0, 2.0, 3.0], normal: [0.0, 0.0, 1.0] });
    }

    #[test]
    fn frame_documents_give_their_fit() {
        let fit = r#""fit": {"shape": "sphere", "centre": [1, 2, 3], "radius": 25, "rms": 0.1, "points": 9}"#;
        let ok = read(&format!(r#"{{"xc": -1, "yc": -2, "za": -3, {fit}}}"#)).unwrap();
        assert_eq!(ok, Shape::Sphere { centre: [1.0, 2.0, 3.0], radius: 25.0 });
        let e = err(&format!(r#"{{"xc": "5", "yc": -2, "za": -3, {fit}}}"#));
        assert!(e.starts_with(":1:") && e.contains("(xc): invalid type: string"), "{e}");
        let e = err(r#"{"xc": 1, "yc": 2, "za": 3, "fit": {"shape": "sphere", "centre": [1, 2, 3], "radius": 0}}"#);
        assert!(e.contains("(fit.radius): must be a positive number"), "{e}");
        assert!(err(r#"{"xc": 1, "yc": 2, "za": 3}"#).contains("(fit): the frame document holds no fit"));
    }
}
