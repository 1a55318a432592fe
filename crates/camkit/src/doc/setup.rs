//! The setup document: what a job needs beyond its toolpath to become a safe program — the stock,
//! the part, the heights the tool moves at between cuts, how it enters material, and the tool by
//! reference. Paths inside it are relative to the setup file.

use super::machine::Coolant;
use super::tool::Tool;
use crate::contour::region::Region;
use crate::error::{Error, Location, Result};
use crate::geom::P3;
use crate::json::field_error;
use crate::model::Model;
use crate::model::bvh::Aabb;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The stock, one of: a box (`min`, `max`), a region of closed contours with `top` and `bottom`,
/// or a model's bounding box grown by `margin`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StockDoc {
    /// Lowest corner of a box (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<[f64; 3]>,
    /// Highest corner of a box (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<[f64; 3]>,
    /// Closed contours (DXF or toolpath table) whose regions are the stock's outline.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<String>,
    /// Top of a region stock (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top: Option<f64>,
    /// Bottom of a region stock (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bottom: Option<f64>,
    /// A model (model document or STL) whose bounding box, grown by `margin`, is the stock.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// Growth of the model's bounding box on each side, x y z (mm, default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub margin: Option<[f64; 3]>,
}

/// The finished part the feed moves must keep their clearance from: a model, or closed contours
/// (pocket boundaries and islands) standing as vertical walls from `floor` to `top`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartDoc {
    /// Model document or STL.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// Closed contours (DXF or toolpath table): the walls of a 2.5-D part.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contours: Option<String>,
    /// Lowest z the tool tip may reach inside the contours (the pocket floor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub floor: Option<f64>,
    /// Top of the walls (default the stock top).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top: Option<f64>,
}

/// How the tool enters material: straight down at `feed`, or ramping at `ramp_angle` degrees
/// from the horizontal along the pass it starts.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlungeDoc {
    /// Feed of the plunge or ramp (mm/min; default the tool's `plunge_feed`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed: Option<f64>,
    /// Ramp angle (degrees, 0 < · ≤ 90; 90 or absent: plunge straight down).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ramp_angle: Option<f64>,
}

/// Tangent arcs into and out of the 2-D passes (constant z, vertical tool).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lead {
    /// Radius of the arcs (mm).
    pub radius: f64,
    /// Sweep of the arcs (degrees, default 90).
    #[serde(default = "quarter")]
    pub angle: f64,
}

fn quarter() -> f64 {
    90.0
}
fn one() -> f64 {
    1.0
}
fn default_tolerance() -> f64 {
    0.01
}

/// A job's setup.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Setup {
    /// The tool document.
    pub tool: String,
    /// The stock.
    pub stock: StockDoc,
    /// The finished part, for the feed moves' clearance.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub part: Option<PartDoc>,
    /// Highest z of the finished part (default the stock top): the safe height must clear it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub part_top: Option<f64>,
    /// Height of rapid traverses over the whole stock (mm, workpiece z).
    pub clearance_height: f64,
    /// Retract height between passes (mm, workpiece z), used where no material above it is in the way.
    pub safe_height: f64,
    /// Distance above material where rapids end and feed begins (mm, default 1).
    #[serde(default = "one")]
    pub approach: f64,
    /// How the tool enters material.
    #[serde(default)]
    pub plunge: PlungeDoc,
    /// Lead-in and lead-out arcs of 2-D passes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lead: Option<Lead>,
    /// Clearance the feed moves keep from the part (mm, default 0; negative: an engraving depth).
    #[serde(default)]
    pub allowance: f64,
    /// How much nearer than `allowance` a feed move may come before it counts as a collision
    /// (mm, default 0.01).
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Coolant.
    #[serde(default)]
    pub coolant: Coolant,
    /// Spacing of the material map that tracks the stock the program has cut (mm; default a fifth
    /// of the tool radius, at most 0.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<f64>,
}

/// The stock as a solid: a box, or regions between a bottom and a top.
#[derive(Clone, Debug, PartialEq)]
pub enum Stock {
    /// An axis-aligned box.
    Box {
        /// Lowest corner.
        min: P3,
        /// Highest corner.
        max: P3,
    },
    /// Closed regions extruded from `bottom` to `top`.
    Region {
        /// The outline's regions.
        regions: Vec<Region>,
        /// Top z.
        top: f64,
        /// Bottom z.
        bottom: f64,
    },
}

impl Stock {
    /// Top z.
    pub fn top(&self) -> f64 {
        match self {
            Stock::Box { max, .. } => max.z,
            Stock::Region { top, .. } => *top,
        }
    }

    /// Bottom z.
    pub fn bottom(&self) -> f64 {
        match self {
            Stock::Box { min, .. } => min.z,
            Stock::Region { bottom, .. } => *bottom,
        }
    }

    /// The stock's extent in XY: (min, max).
    pub fn extent(&self) -> ([f64; 2], [f64; 2]) {
        match self {
            Stock::Box { min, max } => ([min.x, min.y], [max.x, max.y]),
            Stock::Region { regions, .. } => {
                let mut lo = [f64::INFINITY; 2];
                let mut hi = [f64::NEG_INFINITY; 2];
                for (a, b) in regions.iter().filter_map(|r| r.outer.bounds()) {
                    lo = [lo[0].min(a.x), lo[1].min(a.y)];
                    hi = [hi[0].max(b.x), hi[1].max(b.y)];
                }
                (lo, hi)
            }
        }
    }

    /// True if the point (x, y) lies inside the stock's outline.
    pub fn covers(&self, x: f64, y: f64) -> bool {
        match self {
            Stock::Box { min, max } => x >= min.x && x <= max.x && y >= min.y && y <= max.y,
            Stock::Region { regions, .. } => {
                let p = crate::geom::P2::new(x, y);
                regions.iter().any(|r| r.contains(&p))
            }
        }
    }
}

/// The finished part, resolved.
#[derive(Clone, Debug)]
pub enum Part {
    /// A model.
    Model(Box<Model>),
    /// Vertical walls: regions whose loops the tool must keep off, from `floor` to `top`.
    Walls {
        /// The regions (the tool works inside them).
        regions: Vec<Region>,
        /// Lowest tip z inside them.
        floor: f64,
        /// Top of the walls.
        top: f64,
    },
}

/// A setup with its files read and its numbers checked.
#[derive(Clone, Debug)]
pub struct Job {
    /// The setup file, for messages.
    pub file: String,
    /// The setup document's text (empty if not read from one), so that an error about one of its
    /// fields found later names that field's line and column.
    pub source: String,
    /// The tool.
    pub tool: Tool,
    /// The tool document's path, for messages.
    pub tool_file: String,
    /// The stock.
    pub stock: Stock,
    /// The part, if given.
    pub part: Option<Part>,
    /// The part's top.
    pub part_top: f64,
    /// Rapid traverse height.
    pub clearance_height: f64,
    /// Retract height.
    pub safe_height: f64,
    /// Approach distance above material.
    pub approach: f64,
    /// Feed of plunges and ramps (mm/min).
    pub plunge_feed: f64,
    /// Ramp angle (degrees), if ramping.
    pub ramp_angle: Option<f64>,
    /// Lead arcs.
    pub lead: Option<Lead>,
    /// Promised clearance from the part.
    pub allowance: f64,
    /// Tolerance of that clearance.
    pub tolerance: f64,
    /// Coolant.
    pub coolant: Coolant,
    /// Material map spacing (mm).
    pub resolution: f64,
}

impl Setup {
    /// Reads a setup document and everything it names; errors name the file and the JSON path.
    pub fn read(path: &str) -> Result<Job> {
        let input = crate::io::Input::open(path)?;
        let setup: Setup = crate::json::document(&input)?;
        let base = match Path::new(path).parent() {
            Some(p) if path != "-" && !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let mut job = setup.resolve(&input.name, &base).map_err(|e| crate::json::at_value(&input, e))?;
        job.source = input.text()?.to_string();
        Ok(job)
    }

    /// Reads the files the setup names (relative to `base`) and checks every number.
    pub fn resolve(&self, file: &str, base: &Path) -> Result<Job> {
        let rel = |p: &str| -> String {
            if Path::new(p).is_absolute() { p.to_string() } else { base.join(p).to_string_lossy().into_owned() }
        };
        // A file the setup names, read with the setup's field in the message when it is missing.
        let named = |field: &str, p: &str| -> Result<String> {
            let full = rel(p);
            if !Path::new(&full).exists() {
                return Err(field_error(file, field, format!("{full}: no such file")));
            }
            Ok(full)
        };
        let finite = |field: &str, v: f64| -> Result<f64> {
            if v.is_finite() {
                Ok(v)
            } else {
                Err(field_error(file, field, format!("{field} must be a finite number")))
            }
        };
        let tool_file = named("tool", &self.tool)?;
        let tool = Tool::read(&tool_file)?;
        let s = &self.stock;
        let kinds = [s.min.is_some() || s.max.is_some(), s.region.is_some(), s.model.is_some()];
        if kinds.iter().filter(|k| **k).count() != 1 {
            return Err(field_error(
                file,
                "stock",
                "the stock is one of: a box (`min`, `max`), a `region` with `top` and `bottom`, or a `model` with `margin`",
            ));
        }
        let stock = if kinds[0] {
            let (Some(min), Some(max)) = (s.min, s.max) else {
                return Err(field_error(file, "stock", "a box stock needs both `min` and `max`"));
            };
            if s.top.is_some() || s.bottom.is_some() || s.margin.is_some() {
                return Err(field_error(file, "stock", "a box stock has only `min` and `max`"));
            }
            for k in 0..3 {
                finite("stock.min", min[k])?;
                finite("stock.max", max[k])?;
                if max[k] <= min[k] {
                    return Err(field_error(file, "stock.max", "each coordinate of `max` must be above `min`'s"));
                }
            }
            Stock::Box { min: P3::from(min), max: P3::from(max) }
        } else if let Some(region) = &s.region {
            let (Some(top), Some(bottom)) = (s.top, s.bottom) else {
                return Err(field_error(file, "stock", "a region stock needs `top` and `bottom`"));
            };
            if finite("stock.top", top)? <= finite("stock.bottom", bottom)? {
                return Err(field_error(file, "stock.top", "`top` must be above `bottom`"));
            }
            if s.margin.is_some() {
                return Err(field_error(file, "stock.margin", "`margin` grows a model's box, not a region"));
            }
            let regions = crate::contour::load::regions(&named("stock.region", region)?)?;
            Stock::Region { regions, top, bottom }
        } else {
            let model_file = named("stock.model", s.model.as_deref().unwrap_or_default())?;
            if s.top.is_some() || s.bottom.is_some() {
                return Err(field_error(file, "stock", "a model's stock is its bounding box grown by `margin`"));
            }
            let m = s.margin.unwrap_or([0.0; 3]);
            if m.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(field_error(file, "stock.margin", "`margin` must be three numbers ≥ 0 (mm)"));
            }
            let model = Model::load(&crate::io::Input::open(&model_file)?)?;
            let b: Aabb = model.bounds();
            if !b.is_bounded() {
                return Err(field_error(
                    file,
                    "stock.model",
                    "the model is unbounded (an analytic surface): give the stock as a box",
                ));
            }
            Stock::Box {
                min: P3::new(b.min.x - m[0], b.min.y - m[1], b.min.z - m[2]),
                max: P3::new(b.max.x + m[0], b.max.y + m[1], b.max.z + m[2]),
            }
        };
        let top = stock.top();
        let part = match &self.part {
            None => None,
            Some(p) => Some(match (&p.model, &p.contours) {
                (Some(m), None) => {
                    if p.floor.is_some() || p.top.is_some() {
                        return Err(field_error(file, "part", "`floor` and `top` belong to a part given by contours"));
                    }
                    Part::Model(Box::new(Model::load(&crate::io::Input::open(&named("part.model", m)?)?)?))
                }
                (None, Some(c)) => {
                    let Some(floor) = p.floor else {
                        return Err(field_error(file, "part.floor", "a part given by contours needs its `floor`"));
                    };
                    let wall_top = finite("part.top", p.top.unwrap_or(top))?;
                    if wall_top <= finite("part.floor", floor)? {
                        return Err(field_error(file, "part.top", "the walls' `top` must be above the `floor`"));
                    }
                    Part::Walls {
                        regions: crate::contour::load::regions(&named("part.contours", c)?)?,
                        floor,
                        top: wall_top,
                    }
                }
                _ => {
                    return Err(field_error(
                        file,
                        "part",
                        "the part is one of: a `model`, or `contours` with a `floor`",
                    ));
                }
            }),
        };
        let part_top = finite("part_top", self.part_top.unwrap_or(top))?;
        let clearance_height = finite("clearance_height", self.clearance_height)?;
        let safe_height = finite("safe_height", self.safe_height)?;
        let approach = finite("approach", self.approach)?;
        if approach <= 0.0 {
            return Err(field_error(file, "approach", "approach must be a positive distance (mm)"));
        }
        if clearance_height < top + approach {
            return Err(field_error(
                file,
                "clearance_height",
                format!(
                    "clearance_height {clearance_height} is below the stock top {top} plus the approach {approach}: rapids there would run through the stock"
                ),
            ));
        }
        if safe_height > clearance_height {
            return Err(field_error(file, "safe_height", "safe_height must not be above clearance_height"));
        }
        if safe_height < part_top + approach {
            return Err(field_error(
                file,
                "safe_height",
                format!("safe_height {safe_height} is below the part top {part_top} plus the approach {approach}"),
            ));
        }
        let plunge_feed = match (self.plunge.feed, tool.plunge_feed) {
            (Some(f), _) | (None, Some(f)) => f,
            (None, None) => {
                return Err(field_error(
                    file,
                    "plunge.feed",
                    format!("no plunge feed: give plunge.feed here or plunge_feed in {tool_file}"),
                ));
            }
        };
        if !(plunge_feed.is_finite() && plunge_feed > 0.0) {
            return Err(field_error(file, "plunge.feed", "the plunge feed must be a positive number (mm/min)"));
        }
        let ramp_angle = match self.plunge.ramp_angle {
            Some(a) if !(a > 0.0 && a <= 90.0) => {
                return Err(field_error(file, "plunge.ramp_angle", "ramp_angle must be over 0 and at most 90 degrees"));
            }
            Some(a) if a < 90.0 => Some(a),
            _ => None,
        };
        if let Some(l) = &self.lead {
            if !(l.radius.is_finite() && l.radius > 0.0) {
                return Err(field_error(file, "lead.radius", "the lead radius must be a positive number (mm)"));
            }
            if !(l.angle > 0.0 && l.angle <= 180.0) {
                return Err(field_error(file, "lead.angle", "the lead angle must be over 0 and at most 180 degrees"));
            }
        }
        let allowance = finite("allowance", self.allowance)?;
        let tolerance = finite("tolerance", self.tolerance)?;
        if tolerance <= 0.0 {
            return Err(field_error(file, "tolerance", "tolerance must be a positive distance (mm)"));
        }
        let resolution = match self.resolution {
            Some(r) if !(r.is_finite() && r > 0.0) => {
                return Err(field_error(file, "resolution", "resolution must be a positive distance (mm)"));
            }
            Some(r) => r,
            None => (tool.radius / 5.0).min(0.5),
        };
        Ok(Job {
            file: file.to_string(),
            source: String::new(),
            tool,
            tool_file,
            stock,
            part,
            part_top,
            clearance_height,
            safe_height,
            approach,
            plunge_feed,
            ramp_angle,
            lead: self.lead,
            allowance,
            tolerance,
            coolant: self.coolant,
            resolution,
        })
    }
}

impl Job {
    /// The error for a field of this setup.
    pub fn error(&self, field: &str, message: impl Into<String>) -> Error {
        let mut at = Location::file(&self.file);
        if let Some((line, column)) = crate::json::locate(&self.source, field) {
            at = at.line(line).column(column);
        }
        Error::input(message).at(at.field(field))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Writes files into a scratch directory and reads the setup `text` from there.
    fn job(text: &str, files: &[(&str, &str)]) -> Result<Job> {
        let dir = tempfile::tempdir().unwrap();
        for (name, body) in files {
            std::fs::write(dir.path().join(name), body).unwrap();
        }
        let p = dir.path().join("setup.json");
        std::fs::write(&p, text).unwrap();
        Setup::read(p.to_str().unwrap())
    }

    const TOOL: (&str, &str) = ("t.json", r#"{"kind": "flat", "radius": 4, "number": 3, "plunge_feed": 200}"#);

    #[test]
    fn a_box_job_reads_with_defaults() {
        let j = job(
            r#"{"tool": "t.json", "stock": {"min": [0, 0, -20], "max": [100, 80, 0]},
                "clearance_height": 25, "safe_height": 5}"#,
            &[TOOL],
        )
        .unwrap();
        assert_eq!(j.stock.top(), 0.0);
        assert_eq!((j.approach, j.plunge_feed, j.tolerance, j.resolution), (1.0, 200.0, 0.01, 0.5));
        assert!(j.stock.covers(50.0, 40.0) && !j.stock.covers(-1.0, 40.0));
        assert!(j.part.is_none() && j.ramp_angle.is_none());
    }

    #[test]
    fn contours_make_a_region_stock_and_a_walled_part() {
        let square = "path,move,x,y,z\n0,line,0,0,0\n0,line,50,0,0\n0,line,50,50,0\n0,line,0,50,0\n0,line,0,0,0\n";
        let j = job(
            r#"{"tool": "t.json", "stock": {"region": "sq.csv", "top": 0, "bottom": -30},
                "part": {"contours": "sq.csv", "floor": -12}, "clearance_height": 20, "safe_height": 3,
                "plunge": {"feed": 150, "ramp_angle": 3}, "lead": {"radius": 2}}"#,
            &[TOOL, ("sq.csv", square)],
        )
        .unwrap();
        assert!(j.stock.covers(25.0, 25.0) && !j.stock.covers(55.0, 25.0));
        assert_eq!(j.stock.extent(), ([0.0, 0.0], [50.0, 50.0]));
        assert_eq!((j.plunge_feed, j.ramp_angle), (150.0, Some(3.0)));
        assert_eq!(j.lead.map(|l| l.angle), Some(90.0));
        match &j.part {
            Some(Part::Walls { regions, floor, top }) => assert_eq!((regions.len(), *floor, *top), (1, -12.0, 0.0)),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn bad_setups_name_the_field() {
        let base = r#""tool": "t.json", "stock": {"min": [0, 0, -20], "max": [100, 80, 0]}"#;
        let cases = [
            (format!("{{{base}, \"clearance_height\": -1, \"safe_height\": 5}}"), "(clearance_height): clearance_height -1 is below the stock top"),
            (format!("{{{base}, \"clearance_height\": 20, \"safe_height\": 0.5}}"), "(safe_height): safe_height 0.5 is below the part top"),
            (format!("{{{base}, \"clearance_height\": 20, \"safe_height\": 30}}"), "(safe_height): safe_height must not be above"),
            (format!("{{{base}, \"clearance_height\": 20, \"safe_height\": 5, \"approach\": 0}}"), "(approach)"),
            (format!("{{{base}, \"clearance_height\": 20, \"safe_height\": 5, \"plunge\": {{\"ramp_angle\": 0}}}}"), "(plunge.ramp_angle)"),
            (format!("{{{base}, \"clearance_height\": 20, \"safe_height\": 5, \"part\": {{\"contours\": \"x.csv\"}}}}"), "(part.floor)"),
            (format!("{{{base}, \"clearance_height\": 20, \"safe_height\": 5, \"part\": {{\"model\": \"nothere.stl\"}}}}"), "(part.model): "),
            (format!("{{{base}, \"clearance_height\": 20, \"safe_height\": 5, \"lead\": {{\"radius\": -2}}}}"), "(lead.radius)"),
            (r#"{"tool": "t.json", "stock": {"min": [0, 0, 0]}, "clearance_height": 20, "safe_height": 5}"#.to_string(), "(stock): a box stock needs both"),
            (r#"{"tool": "t.json", "stock": {"min": [0, 0, 0], "max": [1, 1, 1], "model": "m.stl"}, "clearance_height": 20, "safe_height": 5}"#.to_string(), "(stock): the stock is one of"),
            (r#"{"tool": "t.json", "stock": {"min": [0, 0, 0], "max": [1, 1, 1]}, "clearance_height": 20, "safe_hieght": 5}"#.to_string(), "(safe_hieght): unknown field"),
        ];
        for (text, needle) in cases {
            let e = job(&text, &[TOOL]).unwrap_err();
            assert!(e.to_string().contains(needle), "{text}\n{e}");
            assert_eq!(e.exit_status(), 2, "{e}");
        }
        let e = job(
            &format!("{{{base}, \"clearance_height\": 20, \"safe_height\": 5}}"),
            &[("t.json", r#"{"kind": "flat", "radius": 4}"#)],
        )
        .unwrap_err();
        assert!(e.to_string().contains("(plunge.feed): no plunge feed"), "{e}");
    }

    #[test]
    fn a_model_box_stock_grows_the_bounds() {
        let tri = [P3::new(0.0, 0.0, 0.0), P3::new(10.0, 0.0, 0.0), P3::new(0.0, 20.0, 5.0)];
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("m.stl"), crate::model::mesh::binary_stl(&[tri])).unwrap();
        std::fs::write(dir.path().join(TOOL.0), TOOL.1).unwrap();
        let p = dir.path().join("s.json");
        std::fs::write(
            &p,
            r#"{"tool": "t.json", "stock": {"model": "m.stl", "margin": [1, 2, 0.5]}, "clearance_height": 20, "safe_height": 7}"#,
        )
        .unwrap();
        let j = Setup::read(p.to_str().unwrap()).unwrap();
        assert_eq!(j.stock, Stock::Box { min: P3::new(-1.0, -2.0, -0.5), max: P3::new(11.0, 22.0, 5.5) });
    }

    /// A value that parses but fails a check is named at its line and column (issue 20, D14).
    #[test]
    fn a_bad_value_names_its_line_and_column() {
        let text =
            "{\"tool\": \"t.json\", \"stock\": {\"min\": [0, 0, 0]},\n \"clearance_height\": 20, \"safe_height\": 5}";
        let e = job(text, &[TOOL]).unwrap_err();
        assert!(e.to_string().contains("setup.json:1:29 (stock): "), "{e}");
        let e = job(text, &[("t.json", r#"{"kind": "flat", "radius": -4}"#)]).unwrap_err();
        assert!(e.to_string().contains("t.json:1:28 (radius): "), "{e}");
    }
}
