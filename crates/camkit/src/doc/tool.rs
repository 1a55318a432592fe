//! The tool document: what cuts, and its dimensions.

use crate::error::Result;
use crate::json::field_error;
use crate::model::cutter::Cutter;
use serde::{Deserialize, Serialize};

/// The shape of a tool.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ToolKind {
    /// Ball end mill: a hemisphere of `radius` at the tip.
    Ball,
    /// Square (flat) end mill of `radius`.
    Flat,
    /// Bull-nose end mill: flat bottom with `corner_radius` corners.
    Bull,
    /// Cone (engraving, chamfer) cutter: a cone of `half_angle` from its tip up to `radius`.
    Cone,
    /// Non-rotating cylindrical tool (paper 000 §2.1): the rim of a cylinder of `radius` cut square.
    CylindricalNonrotating,
    /// Non-rotating flat-type tool (paper 000 §3.2(2)): a wedge whose tip traces a concave line.
    FlatNonrotating,
}

/// A tool.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tool {
    /// Shape.
    pub kind: ToolKind,
    /// Radius R (mm): of the ball, the cutter, or the cylinder.
    pub radius: f64,
    /// Corner radius of a bull-nose tool (mm).
    #[serde(default)]
    pub corner_radius: f64,
    /// Half-angle of a cone cutter between its axis and its flank (degrees).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_angle: Option<f64>,
    /// Radius of a small flat ground at a ball end mill's tip, r0 of paper 003 (mm).
    #[serde(default)]
    pub tip_flat_radius: f64,
    /// Number of flutes (rotating tools).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flutes: Option<u32>,
    /// Length from the gauge line to the tip (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
    /// Tool number for the tool change (T word) and the length offset (H word).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub number: Option<u32>,
    /// Spindle speed (rpm) the tool cuts at; none for a non-rotating tool.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_speed: Option<f64>,
    /// Feed per tooth (mm): the cutting feed is feed_per_tooth × flutes × spindle_speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed_per_tooth: Option<f64>,
    /// Cutting feed (mm/min), when given directly instead of per tooth.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed: Option<f64>,
    /// Feed (mm/min) of plunges and ramps into material.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plunge_feed: Option<f64>,
    /// Diameter of the holder above the gauge line (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub holder_diameter: Option<f64>,
    /// Length of the holder above the gauge line (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub holder_length: Option<f64>,
    /// Included angle of a flat-type non-rotating tool's edge between its two flanks (degrees);
    /// paper 000 grinds it 5° below the model's corner angle to keep the second flank clear.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub included_angle: Option<f64>,
    /// Length of a flat-type tool's flank from the tip P2 to the control point P1 or P3 (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flank_length: Option<f64>,
    /// Range of tool tilt the tool cuts stably in, [min, max] degrees (paper 000: [−20, 0] for
    /// the cylindrical non-rotating tool); gouge avoidance keeps the tilt inside it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tilt_range: Option<[f64; 2]>,
}

impl Tool {
    /// Checks the dimensions; errors name the file and field.
    pub fn validate(&self, file: &str) -> Result<()> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(self.radius) {
            return Err(field_error(
                file,
                "radius",
                format!("radius must be a positive number of mm, got {}", self.radius),
            ));
        }
        if !(self.corner_radius >= 0.0 && self.corner_radius.is_finite()) {
            return Err(field_error(file, "corner_radius", "corner_radius must be a number of mm, at least 0"));
        }
        if self.corner_radius > self.radius {
            return Err(field_error(
                file,
                "corner_radius",
                format!(
                    "corner_radius {} exceeds the radius {}: it can be at most the radius",
                    self.corner_radius, self.radius
                ),
            ));
        }
        if self.kind == ToolKind::Bull && self.corner_radius == 0.0 {
            return Err(field_error(file, "corner_radius", "a bull-nose tool needs corner_radius > 0"));
        }
        match (self.kind, self.half_angle) {
            (ToolKind::Cone, None) => {
                return Err(field_error(file, "half_angle", "a cone cutter needs half_angle (degrees)"));
            }
            (ToolKind::Cone, Some(a)) if !(a > 0.0 && a < 90.0) => {
                return Err(field_error(
                    file,
                    "half_angle",
                    format!("half_angle must be between 0 and 90 degrees, got {a}"),
                ));
            }
            (ToolKind::Cone, _) => {}
            (_, Some(_)) => return Err(field_error(file, "half_angle", "half_angle is for a cone cutter")),
            _ => {}
        }
        if !(self.tip_flat_radius >= 0.0 && self.tip_flat_radius < self.radius) {
            return Err(field_error(file, "tip_flat_radius", "tip_flat_radius must be at least 0 and below radius"));
        }
        if self.flutes == Some(0) {
            return Err(field_error(file, "flutes", "a tool needs at least one flute"));
        }
        if self.length.is_some_and(|l| !positive(l)) {
            return Err(field_error(file, "length", "length must be positive"));
        }
        for (name, v) in [
            ("spindle_speed", self.spindle_speed),
            ("feed_per_tooth", self.feed_per_tooth),
            ("feed", self.feed),
            ("plunge_feed", self.plunge_feed),
            ("holder_diameter", self.holder_diameter),
            ("holder_length", self.holder_length),
        ] {
            if v.is_some_and(|v| !positive(v)) {
                return Err(field_error(
                    file,
                    name,
                    format!("{name} must be a positive number, got {}", v.unwrap_or(0.0)),
                ));
            }
        }
        if self.feed.is_some() && self.feed_per_tooth.is_some() {
            return Err(field_error(file, "feed", "give feed or feed_per_tooth, not both"));
        }
        if self.feed_per_tooth.is_some() && (self.flutes.is_none() || self.spindle_speed.is_none()) {
            return Err(field_error(file, "feed_per_tooth", "feed_per_tooth needs flutes and spindle_speed"));
        }
        if self.holder_diameter.is_some() != self.holder_length.is_some() {
            return Err(field_error(file, "holder_diameter", "give holder_diameter and holder_length together"));
        }
        if self.holder_diameter.is_some() && self.length.is_none() {
            return Err(field_error(file, "length", "a holder needs the tool's length (gauge line to tip)"));
        }
        if self.included_angle.is_some_and(|a| !(a > 0.0 && a < 180.0)) {
            return Err(field_error(file, "included_angle", "included_angle must be between 0 and 180 degrees"));
        }
        if self.flank_length.is_some_and(|l| !positive(l)) {
            return Err(field_error(file, "flank_length", "flank_length must be a positive number of mm"));
        }
        if let Some([lo, hi]) = self.tilt_range {
            if !(lo > -90.0 && lo <= hi && hi < 90.0) {
                return Err(field_error(
                    file,
                    "tilt_range",
                    "tilt_range must be [min, max] degrees with -90 < min <= max < 90",
                ));
            }
        }
        Ok(())
    }

    /// The cutting feed (mm/min): `feed`, or feed per tooth × flutes × spindle speed.
    pub fn cutting_feed(&self) -> Option<f64> {
        self.feed.or_else(|| Some(self.feed_per_tooth? * f64::from(self.flutes?) * self.spindle_speed?))
    }

    /// The cutter a fixed-axis drop takes, for the rotating end mills (`None` for the
    /// non-rotating tools).
    pub fn cutter(&self) -> Option<Cutter> {
        let radius = self.radius;
        Some(match self.kind {
            ToolKind::Flat => Cutter::Flat { radius },
            ToolKind::Ball => Cutter::Ball { radius },
            ToolKind::Bull => Cutter::Bull { radius, corner: self.corner_radius },
            ToolKind::Cone => Cutter::Cone { radius, half_angle: self.half_angle?.to_radians() },
            ToolKind::CylindricalNonrotating | ToolKind::FlatNonrotating => return None,
        })
    }

    /// Reads and validates a tool document.
    pub fn read(path: &str) -> Result<Tool> {
        let input = crate::io::Input::open(path)?;
        crate::json::checked(&input, Tool::validate)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Tool> {
        let input = crate::io::Input { name: "t.json".into(), data: text.as_bytes().to_vec() };
        let t: Tool = crate::json::from_input(&input)?;
        t.validate(&input.name)?;
        Ok(t)
    }

    #[test]
    fn reads_and_checks() {
        let t = parse(r#"{"kind": "ball", "radius": 5, "flutes": 2}"#).unwrap();
        assert_eq!(t.kind, ToolKind::Ball);
        assert_eq!(t.flutes, Some(2));
        let e = parse(r#"{"kind": "ball", "radius": -1}"#).unwrap_err();
        assert_eq!(e.to_string(), "t.json (radius): radius must be a positive number of mm, got -1");
        let e = parse(r#"{"kind": "drill", "radius": 1}"#).unwrap_err();
        assert!(e.to_string().starts_with("t.json:1:16 (kind): unknown variant `drill`"), "{e}");
        let e = parse(r#"{"kind": "bull", "radius": 5, "corner_radius": 6}"#).unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.json (corner_radius): corner_radius 6 exceeds the radius 5: it can be at most the radius"
        );
        let t = parse(r#"{"kind": "cone", "radius": 3, "half_angle": 45}"#).unwrap();
        assert_eq!(t.cutter(), Some(Cutter::Cone { radius: 3.0, half_angle: std::f64::consts::FRAC_PI_4 }));
        let e = parse(r#"{"kind": "cone", "radius": 3}"#).unwrap_err();
        assert!(e.to_string().contains("(half_angle)"), "{e}");
        let e = parse(r#"{"kind": "cone", "radius": 3, "half_angle": 90}"#).unwrap_err();
        assert!(e.to_string().contains("between 0 and 90"), "{e}");
        let e = parse(r#"{"kind": "bull", "radius": 5}"#).unwrap_err();
        assert!(e.to_string().contains("(corner_radius)"), "{e}");
        let t = parse(r#"{"kind": "flat-nonrotating", "radius": 5, "included_angle": 85, "flank_length": 3}"#).unwrap();
        assert_eq!((t.included_angle, t.flank_length), (Some(85.0), Some(3.0)));
        let e = parse(r#"{"kind": "flat-nonrotating", "radius": 5, "included_angle": 190}"#).unwrap_err();
        assert!(e.to_string().contains("(included_angle)"), "{e}");
        let e = parse(r#"{"kind": "cylindrical-nonrotating", "radius": 12.5, "tilt_range": [0, -20]}"#).unwrap_err();
        assert!(e.to_string().contains("(tilt_range)"), "{e}");
    }

    #[test]
    fn feeds_and_holder() {
        let t = parse(r#"{"kind": "flat", "radius": 4, "flutes": 3, "spindle_speed": 8000, "feed_per_tooth": 0.05}"#)
            .unwrap();
        assert!((t.cutting_feed().unwrap() - 1200.0).abs() < 1e-9);
        let t = parse(r#"{"kind": "flat", "radius": 4, "feed": 900}"#).unwrap();
        assert_eq!(t.cutting_feed(), Some(900.0));
        assert_eq!(parse(r#"{"kind": "flat", "radius": 4}"#).unwrap().cutting_feed(), None);
        let e = parse(r#"{"kind": "flat", "radius": 4, "feed_per_tooth": 0.05}"#).unwrap_err();
        assert!(e.to_string().contains("needs flutes and spindle_speed"), "{e}");
        let e = parse(
            r#"{"kind": "flat", "radius": 4, "feed": 900, "feed_per_tooth": 0.05, "flutes": 2, "spindle_speed": 1}"#,
        )
        .unwrap_err();
        assert!(e.to_string().contains("not both"), "{e}");
        let e = parse(r#"{"kind": "flat", "radius": 4, "plunge_feed": -3}"#).unwrap_err();
        assert_eq!(e.to_string(), "t.json (plunge_feed): plunge_feed must be a positive number, got -3");
        let e = parse(r#"{"kind": "flat", "radius": 4, "holder_diameter": 30}"#).unwrap_err();
        assert!(e.to_string().contains("together"), "{e}");
        let e = parse(r#"{"kind": "flat", "radius": 4, "holder_diameter": 30, "holder_length": 40}"#).unwrap_err();
        assert!(e.to_string().contains("(length)"), "{e}");
    }

    /// A value that parses but fails a check is named at its line and column (issue 20, D14).
    #[test]
    fn a_bad_value_names_its_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.json");
        std::fs::write(&p, "{\n  \"kind\": \"ball\",\n  \"radius\": 5,\n  \"flutes\": 0\n}").unwrap();
        let e = Tool::read(p.to_str().unwrap()).unwrap_err();
        assert_eq!(e.to_string(), format!("{}:4:13 (flutes): a tool needs at least one flute", p.display()));
    }
}
