//! The machine document: a kinematic chain ([`crate::kinematics`]) with axis limits, wrapping,
//! rotation sense and home, the spindle orientation of a non-rotating tool (the sixth axis of
//! paper 000), and how NC programs for it are written (dialect, header, words, decimals).

use super::frame::Frame;
use crate::error::Result;
use crate::geom::V3;
use crate::json::field_error;
use crate::kinematics::{Chain, Link, Policy, Rotary};
use serde::{Deserialize, Serialize};

/// The NC dialect a machine reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Dialect {
    /// ISO / Fanuc: `%`, `O` number, G43.4 tool-centre-point mode available.
    Fanuc,
    /// LinuxCNC (rs274ngc).
    #[default]
    Linuxcnc,
}

/// A rotary axis direction: `x`, `y`, `z` (or `-x`...) or a unit vector.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Direction {
    /// A named machine axis, optionally negated.
    Named(String),
    /// A unit vector.
    Vector([f64; 3]),
}

/// One link of the chain: exactly one of `rotary`, `offset`, `linear`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkDoc {
    /// Address letter of a rotary axis (`A`, `B`, `C`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotary: Option<String>,
    /// Direction of the rotary axis at zero (default: X for A, Y for B, Z for C).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub about: Option<Direction>,
    /// +1 or −1: the chain turns by sense × angle right-handed about `about` (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sense: Option<f64>,
    /// Lower limit (degrees).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// Upper limit (degrees).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    /// Endless axis: no limits, unwound between passes (default false).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wrap: Option<bool>,
    /// Angle at the start of the program (degrees, default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub home: Option<f64>,
    /// A fixed translation (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<[f64; 3]>,
    /// The linear axes X, Y, Z (`true`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear: Option<bool>,
}

/// Travel of the linear axes (mm), each `[min, max]`, checked on every block.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Travel {
    /// X travel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<[f64; 2]>,
    /// Y travel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y: Option<[f64; 2]>,
    /// Z travel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<[f64; 2]>,
}

impl Travel {
    /// `[min, max]` of linear axis `k` (0 = X).
    pub fn get(&self, k: usize) -> Option<[f64; 2]> {
        [self.x, self.y, self.z][k]
    }
}

/// How the spindle orientation of a non-rotating tool is commanded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpindleMode {
    /// Oriented spindle stop `M19 R<angle>` before the move (stepwise).
    M19,
    /// A rotary address in position mode, interpolated with the other axes.
    Axis,
}

/// The sixth axis: the spindle's orientation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spindle {
    /// `m19` or `axis`.
    pub mode: SpindleMode,
    /// Address letter in `axis` mode (e.g. `B` on an A/C machine).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub address: Option<String>,
    /// Controller angle (degrees) at which the edge faces the tool frame's +X (default 0).
    #[serde(default)]
    pub offset: f64,
    /// +1 or −1: the controller angle grows right-handed about the tool axis (default 1).
    #[serde(default = "one")]
    pub sense: f64,
}

/// Where to take the primary rotary angle when the tool axis comes within the singular cone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SingularRule {
    /// Interpolate it between the poses where the path enters and leaves the cone.
    #[default]
    Interpolate,
    /// Hold it at its value where the path enters the cone.
    Hold,
}

/// Turning policy of wrapping rotary axes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PolicyDoc {
    /// At most 180° between poses.
    #[default]
    Shortest,
    /// Positive sense only.
    Positive,
    /// Negative sense only.
    Negative,
}

/// Length units of the written program.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum UnitsDoc {
    /// G21.
    #[default]
    Mm,
    /// G20.
    Inch,
}

/// Coolant word.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Coolant {
    /// None.
    #[default]
    Off,
    /// M8.
    Flood,
    /// M7.
    Mist,
}

/// Fixed decimals per kind of address.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Decimals {
    /// X, Y, Z (in program units).
    #[serde(default = "four")]
    pub linear: u32,
    /// Rotary addresses and M19 R (degrees).
    #[serde(default = "four")]
    pub rotary: u32,
    /// F in G94 (program units per minute).
    #[serde(default = "one_u")]
    pub feed: u32,
    /// Significant digits of F in G93 (inverse time, 1/min).
    #[serde(default = "six")]
    pub inverse_time_digits: u32,
}

impl Default for Decimals {
    fn default() -> Self {
        Decimals { linear: 4, rotary: 4, feed: 1, inverse_time_digits: 6 }
    }
}

/// How programs for this machine are written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Program {
    /// Program number (`O` word, Fanuc).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub number: Option<u32>,
    /// Work offset code (G54..G59, default G54).
    #[serde(default = "g54")]
    pub work_offset: String,
    /// Tool-centre-point mode (Fanuc G43.4): X, Y, Z are the tool tip in the workpiece frame and
    /// the control does the kinematics.
    #[serde(default)]
    pub tcp: bool,
    /// Block numbers: first number and step, none when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block_numbers: Option<[u32; 2]>,
    /// Units of the written program.
    #[serde(default)]
    pub units: UnitsDoc,
    /// Decimals per address.
    #[serde(default)]
    pub decimals: Decimals,
    /// Tool number for `T<n> M6` and the length offset `G43 H<n>`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool: Option<u32>,
    /// Spindle speed (rpm) with M3; none for a non-rotating tool.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_speed: Option<f64>,
    /// Coolant.
    #[serde(default)]
    pub coolant: Coolant,
    /// Machine Z (G53) to retract to at the start and the end of the program.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub retract_z: Option<f64>,
    /// Extra lines after the header.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub header: Vec<String>,
    /// Extra lines before the end of the program.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub footer: Vec<String>,
}

impl Default for Program {
    fn default() -> Self {
        Program {
            number: None,
            work_offset: g54(),
            tcp: false,
            block_numbers: None,
            units: UnitsDoc::Mm,
            decimals: Decimals::default(),
            tool: None,
            spindle_speed: None,
            coolant: Coolant::Off,
            retract_z: None,
            header: Vec::new(),
            footer: Vec::new(),
        }
    }
}

/// A machine.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Machine {
    /// Name, written in the program's header comment.
    pub name: String,
    /// NC dialect.
    #[serde(default)]
    pub dialect: Dialect,
    /// The kinematic chain, workpiece to tool.
    pub chain: Vec<LinkDoc>,
    /// Linear travel limits.
    #[serde(default)]
    pub travel: Travel,
    /// The workpiece frame used when no frame document is given (default 0, 0, 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<Frame>,
    /// The spindle orientation of a non-rotating tool, if the machine can command it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle: Option<Spindle>,
    /// Half-angle (degrees) of the cone about the primary rotary axis inside which its angle is
    /// not computed from the tool axis (default 0.5).
    #[serde(default = "half")]
    pub singular_cone: f64,
    /// What the primary axis does inside the cone.
    #[serde(default)]
    pub singular: SingularRule,
    /// Turning policy of wrapping rotary axes.
    #[serde(default)]
    pub policy: PolicyDoc,
    /// How programs are written.
    #[serde(default)]
    pub program: Program,
}

fn one() -> f64 {
    1.0
}
fn half() -> f64 {
    0.5
}
fn four() -> u32 {
    4
}
fn six() -> u32 {
    6
}
fn one_u() -> u32 {
    1
}
fn g54() -> String {
    "G54".into()
}

/// Address letters a rotary axis or the spindle may use.
const ROTARY_LETTERS: &str = "ABC";

fn letter(text: &str) -> Option<char> {
    let mut chars = text.chars();
    let c = chars.next()?.to_ascii_uppercase();
    (chars.next().is_none() && ROTARY_LETTERS.contains(c)).then_some(c)
}

impl Machine {
    /// Checks the document and builds its chain (without a frame); errors name the JSON path.
    pub fn kinematics(&self, file: &str) -> Result<Chain> {
        let mut links = Vec::new();
        let mut rotaries = Vec::new();
        for (i, l) in self.chain.iter().enumerate() {
            let at = |field: &str| format!("chain[{i}]{field}");
            let kinds = [l.rotary.is_some(), l.offset.is_some(), l.linear.is_some()];
            if kinds.iter().filter(|k| **k).count() != 1 {
                return Err(field_error(file, &at(""), "a link has exactly one of `rotary`, `offset`, `linear`"));
            }
            if l.rotary.is_none()
                && (l.about.is_some()
                    || l.sense.is_some()
                    || l.min.is_some()
                    || l.max.is_some()
                    || l.wrap.is_some()
                    || l.home.is_some())
            {
                return Err(field_error(
                    file,
                    &at(""),
                    "`about`, `sense`, `min`, `max`, `wrap`, `home` belong to a rotary link",
                ));
            }
            if let Some(v) = l.offset {
                if v.iter().any(|c| !c.is_finite()) {
                    return Err(field_error(file, &at(".offset"), "offset must be three finite numbers of mm"));
                }
                links.push(Link::Offset(V3::from(v)));
            } else if let Some(lin) = l.linear {
                if !lin {
                    return Err(field_error(file, &at(".linear"), "write `\"linear\": true` for the linear axes"));
                }
                links.push(Link::Linear);
            } else if let Some(name) = &l.rotary {
                let address = letter(name).filter(|c| "ABC".contains(*c)).ok_or_else(|| {
                    field_error(file, &at(".rotary"), format!("rotary address must be A, B or C, got {name:?}"))
                })?;
                let dir = match &l.about {
                    None => match address {
                        'A' => V3::x(),
                        'B' => V3::y(),
                        _ => V3::z(),
                    },
                    Some(Direction::Named(n)) => {
                        let (neg, axis) = n.strip_prefix('-').map_or((false, n.as_str()), |a| (true, a));
                        let v = match axis.to_ascii_lowercase().as_str() {
                            "x" => V3::x(),
                            "y" => V3::y(),
                            "z" => V3::z(),
                            _ => {
                                return Err(field_error(
                                    file,
                                    &at(".about"),
                                    format!("expected x, y, z, -x, -y, -z or [i, j, k], got {n:?}"),
                                ));
                            }
                        };
                        if neg { -v } else { v }
                    }
                    Some(Direction::Vector(v)) => {
                        let v = V3::from(*v);
                        if !v.norm().is_finite() || (v.norm() - 1.0).abs() > crate::tol::UNIT_VECTOR_SLACK {
                            return Err(field_error(file, &at(".about"), "the axis direction must be a unit vector"));
                        }
                        v.normalize()
                    }
                };
                let sense = l.sense.unwrap_or(1.0);
                if sense != 1.0 && sense != -1.0 {
                    return Err(field_error(file, &at(".sense"), "sense must be 1 or -1"));
                }
                let wrap = l.wrap.unwrap_or(false);
                let limits = match (l.min, l.max) {
                    (None, None) => None,
                    (Some(lo), Some(hi)) if lo.is_finite() && hi.is_finite() && lo < hi => Some((lo, hi)),
                    _ => return Err(field_error(file, &at(".min"), "give both min and max (degrees), min < max")),
                };
                if wrap && limits.is_some() {
                    return Err(field_error(file, &at(".wrap"), "a wrapping axis has no limits"));
                }
                let home = l.home.unwrap_or(0.0);
                if limits.is_some_and(|(lo, hi)| !(lo..=hi).contains(&home)) || !home.is_finite() {
                    return Err(field_error(file, &at(".home"), "home must lie within the limits"));
                }
                if rotaries.iter().any(|r: &Rotary| r.address == address) {
                    return Err(field_error(file, &at(".rotary"), format!("axis {address} appears twice")));
                }
                links.push(Link::Rotary(rotaries.len()));
                rotaries.push(Rotary { address, dir, sense, limits, wrap, home, on_table: false });
            }
        }
        let chain = Chain::new(links, rotaries).map_err(|m| field_error(file, "chain", m))?;
        self.check_rest(file, &chain)?;
        let frame = self.frame.as_ref().map_or(V3::zeros(), Frame::offset);
        Ok(chain.with_frame(frame))
    }

    fn check_rest(&self, file: &str, chain: &Chain) -> Result<()> {
        for (k, name) in ["x", "y", "z"].iter().enumerate() {
            if let Some([lo, hi]) = self.travel.get(k)
                && !(lo.is_finite() && hi.is_finite() && lo < hi)
            {
                return Err(field_error(file, &format!("travel.{name}"), "travel is [min, max] with min < max"));
            }
        }
        if let Some(f) = &self.frame {
            f.validate(file)?;
        }
        if !(self.singular_cone.is_finite() && (0.0..45.0).contains(&self.singular_cone)) {
            return Err(field_error(file, "singular_cone", "singular_cone must be an angle from 0 to 45 degrees"));
        }
        if let Some(s) = &self.spindle {
            if s.sense != 1.0 && s.sense != -1.0 {
                return Err(field_error(file, "spindle.sense", "sense must be 1 or -1"));
            }
            if !s.offset.is_finite() {
                return Err(field_error(file, "spindle.offset", "offset must be a finite angle"));
            }
            match (s.mode, &s.address) {
                (SpindleMode::Axis, None) => {
                    return Err(field_error(file, "spindle.address", "axis mode needs an address letter"));
                }
                (SpindleMode::Axis, Some(a)) => {
                    let c = letter(a).ok_or_else(|| {
                        field_error(file, "spindle.address", format!("expected A, B or C, got {a:?}"))
                    })?;
                    if chain.rotaries().iter().any(|r| r.address == c) {
                        return Err(field_error(
                            file,
                            "spindle.address",
                            format!("{c} is already a rotary axis of the chain"),
                        ));
                    }
                }
                (SpindleMode::M19, Some(_)) => {
                    return Err(field_error(file, "spindle.address", "m19 mode takes no address"));
                }
                (SpindleMode::M19, None) => {}
            }
        }
        let p = &self.program;
        let wo = p.work_offset.to_ascii_uppercase();
        let valid_wo = matches!(wo.as_str(), "G54" | "G55" | "G56" | "G57" | "G58" | "G59")
            || wo.strip_prefix("G59.").is_some_and(|n| matches!(n, "1" | "2" | "3"));
        if !valid_wo {
            return Err(field_error(
                file,
                "program.work_offset",
                format!("expected G54..G59 or G59.1..G59.3, got {:?}", p.work_offset),
            ));
        }
        if p.tcp && self.dialect != Dialect::Fanuc {
            return Err(field_error(
                file,
                "program.tcp",
                "tool-centre-point mode (G43.4) is written in the fanuc dialect only",
            ));
        }
        if p.tcp && p.tool.is_none() {
            return Err(field_error(file, "program.tcp", "G43.4 needs a tool number for its H word (program.tool)"));
        }
        let d = &p.decimals;
        if d.linear > 8 || d.rotary > 8 || d.feed > 6 || !(3..=12).contains(&d.inverse_time_digits) {
            return Err(field_error(
                file,
                "program.decimals",
                "decimals: linear and rotary at most 8, feed at most 6, inverse_time_digits 3..12",
            ));
        }
        if p.spindle_speed.is_some_and(|s| !(s.is_finite() && s > 0.0)) {
            return Err(field_error(file, "program.spindle_speed", "spindle_speed must be a positive rpm"));
        }
        if p.retract_z.is_some_and(|z| !z.is_finite()) {
            return Err(field_error(file, "program.retract_z", "retract_z must be a finite number"));
        }
        if let Some([_, step]) = p.block_numbers
            && step == 0
        {
            return Err(field_error(file, "program.block_numbers", "block number step must be at least 1"));
        }
        for (name, lines) in [("program.header", &p.header), ("program.footer", &p.footer)] {
            if lines.iter().any(|l| l.contains('\n') || l.contains('\r')) {
                return Err(field_error(file, name, "one line per entry"));
            }
        }
        Ok(())
    }

    /// The turning policy.
    pub fn policy(&self) -> Policy {
        match self.policy {
            PolicyDoc::Shortest => Policy::Shortest,
            PolicyDoc::Positive => Policy::Positive,
            PolicyDoc::Negative => Policy::Negative,
        }
    }

    /// The spindle's address letter in axis mode.
    pub fn spindle_address(&self) -> Option<char> {
        self.spindle
            .as_ref()
            .filter(|s| s.mode == SpindleMode::Axis)
            .and_then(|s| s.address.as_deref())
            .and_then(letter)
    }

    /// Reads a machine document and builds its chain; errors name the file and JSON path.
    pub fn read(path: &str) -> Result<(Machine, Chain)> {
        let input = crate::io::Input::open(path)?;
        let m: Machine = crate::json::document(&input)?;
        let chain = m.kinematics(&input.name).map_err(|e| crate::json::at_value(&input, e))?;
        Ok((m, chain))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::{Family, Joints};

    fn parse(text: &str) -> Result<(Machine, Chain)> {
        let input = crate::io::Input { name: "m.json".into(), data: text.as_bytes().to_vec() };
        let m: Machine = crate::json::from_input(&input)?;
        let c = m.kinematics(&input.name)?;
        Ok((m, c))
    }

    #[test]
    fn paper_002_machine() {
        let (m, c) = parse(
            r#"{"name": "A/C", "chain": [{"rotary": "C", "sense": -1, "wrap": true}, {"offset": [0, 3.125, 0]},
                {"rotary": "A", "sense": -1, "min": -30, "max": 120}, {"linear": true}],
                "frame": {"xc": 12.5, "yc": -7.25, "za": 85}}"#,
        )
        .unwrap();
        assert_eq!(m.dialect, Dialect::Linuxcnc);
        assert_eq!(c.family(), Family::TableTable);
        assert_eq!(c.frame(), V3::new(12.5, -7.25, 85.0));
        let p = c.forward(&Joints { xyz: V3::zeros(), rot: [0.0, 0.0] });
        assert_eq!(p.tip.coords, V3::new(12.5, -7.25 + 3.125, 85.0));
    }

    #[test]
    fn errors_name_the_link() {
        let e = parse(r#"{"name": "x", "chain": [{"linear": true, "offset": [0,0,1]}]}"#).unwrap_err();
        assert_eq!(e.to_string(), "m.json (chain[0]): a link has exactly one of `rotary`, `offset`, `linear`");
        let e = parse(r#"{"name": "x", "chain": [{"rotary": "D"}, {"linear": true}]}"#).unwrap_err();
        assert!(e.to_string().contains("(chain[0].rotary)"), "{e}");
        let e = parse(r#"{"name": "x", "chain": [{"rotary": "A", "min": 10}, {"linear": true}]}"#).unwrap_err();
        assert!(e.to_string().contains("(chain[0].min)"), "{e}");
        let e = parse(r#"{"name": "x", "chain": [{"linear": true}], "program": {"tcp": true}}"#).unwrap_err();
        assert!(e.to_string().contains("fanuc dialect only"), "{e}");
        let e = parse(r#"{"name": "x", "chain": [{"linear": true}], "colour": 1}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `colour`"), "{e}");
        let e = parse(r#"{"name": "x", "chain": [{"linear": true}], "spindle": {"mode": "axis"}}"#).unwrap_err();
        assert!(e.to_string().contains("(spindle.address)"), "{e}");
    }

    /// A value that parses but fails a check is named at its line and column (issue 20, D14).
    #[test]
    fn a_bad_value_names_its_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("m.json");
        let text =
            "{\"name\": \"x\", \"chain\": [\n  {\"rotary\": \"A\"},\n  {\"rotary\": \"D\"}, {\"linear\": true}]}";
        std::fs::write(&p, text).unwrap();
        let e = Machine::read(p.to_str().unwrap()).unwrap_err();
        assert!(e.to_string().starts_with(&format!("{}:3:14 (chain[1].rotary): ", p.display())), "{e}");
    }
}
