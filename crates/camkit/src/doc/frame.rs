//! The workpiece frame document: where the workpiece sits on the machine, as `surf-probe-fit`
//! measures it and `post-6axis` uses it (paper 002 eq. 2's `xc, yc, za`).

use crate::error::Result;
use crate::geom::V3;
use crate::json::field_error;
use serde::{Deserialize, Serialize};

/// The workpiece frame: the translation `F` at the left end of a machine's chain
/// ([`crate::kinematics`]), so that workpiece coordinates = table coordinates + `(xc, yc, za)`.
/// On paper 002's A/C table machine, `(xc, yc)` is the C axis centre seen from the workpiece
/// origin (X, Y) and `za` the A axis seen from it (Z), as in eq. 2.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Frame {
    /// X of the translation (mm).
    pub xc: f64,
    /// Y of the translation (mm).
    pub yc: f64,
    /// Z of the translation (mm).
    pub za: f64,
    /// What produced the frame (free text).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// The fit behind the frame (centre, radius, residuals...): carried, not read.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<serde_json::Value>,
}

impl Frame {
    /// The frame with translation `t` (mm).
    pub fn new(t: V3) -> Frame {
        Frame { xc: t.x, yc: t.y, za: t.z, source: None, fit: None }
    }

    /// The frame whose workpiece origin is the table-coordinates point `origin` (e.g. a fitted
    /// sphere's centre measured with every rotary axis at zero).
    pub fn with_origin_at(origin: V3) -> Frame {
        Frame::new(-origin)
    }

    /// The translation `(xc, yc, za)`.
    pub fn offset(&self) -> V3 {
        V3::new(self.xc, self.yc, self.za)
    }

    /// Checks the numbers; errors name the file and field.
    pub fn validate(&self, file: &str) -> Result<()> {
        for (name, v) in [("xc", self.xc), ("yc", self.yc), ("za", self.za)] {
            if !v.is_finite() {
                return Err(field_error(file, name, format!("{name} must be a finite number of mm")));
            }
        }
        Ok(())
    }

    /// Reads and validates a frame document.
    pub fn read(path: &str) -> Result<Frame> {
        let input = crate::io::Input::open(path)?;
        crate::json::checked(&input, Frame::validate)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_and_round_trips() {
        let input = crate::io::Input {
            name: "f.json".into(),
            data: br#"{"xc": 1.5, "yc": -2, "za": 40, "fit": {"radius": 25.0}}"#.to_vec(),
        };
        let f: Frame = crate::json::from_input(&input).unwrap();
        assert_eq!(f.offset(), V3::new(1.5, -2.0, 40.0));
        assert_eq!(Frame::with_origin_at(V3::new(1.0, 2.0, 3.0)).offset(), V3::new(-1.0, -2.0, -3.0));
        let bad = crate::io::Input { name: "f.json".into(), data: br#"{"xc": 1, "yc": 2}"#.to_vec() };
        let e = crate::json::from_input::<Frame>(&bad).unwrap_err();
        assert!(e.to_string().contains("missing field `za`"), "{e}");
    }
}
