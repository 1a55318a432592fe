//! Choosing one pose among the inverse solutions: inside the axis limits, continuous with the
//! previous pose (smallest rotary move under a policy), and holding the primary axis near the
//! singularity instead of spinning it.

use super::{Chain, principal_deg};
use crate::geom::V3;

/// Which way a wrapping rotary axis may turn between two poses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Policy {
    /// The smaller of the two ways (at most 180°).
    #[default]
    Shortest,
    /// Only in the positive sense.
    Positive,
    /// Only in the negative sense.
    Negative,
}

impl Policy {
    /// Parses `shortest`, `positive`, `negative`.
    pub fn parse(text: &str) -> Option<Policy> {
        match text {
            "shortest" => Some(Policy::Shortest),
            "positive" => Some(Policy::Positive),
            "negative" => Some(Policy::Negative),
            _ => None,
        }
    }
}

/// The chosen rotary angles for one pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Choice {
    /// Rotary angles (degrees), unwound: continuous with the previous pose.
    pub rot: [f64; 2],
    /// Which inverse branch (0 or 1) was taken.
    pub branch: usize,
    /// The tool axis lies within the singular cone about the primary rotary axis; the primary
    /// angle was held, not computed.
    pub singular: bool,
}

/// Why no pose was found, in the user's terms (axis, angle, limits).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Unreachable(pub String);

/// Picks poses for one machine.
#[derive(Clone, Debug)]
pub struct Solver<'a> {
    /// The machine.
    pub chain: &'a Chain,
    /// Turning policy of wrapping axes.
    pub policy: Policy,
    /// Half-angle (radians) of the cone about the primary rotary axis inside which the primary
    /// angle is held.
    pub cone: f64,
}

impl Solver<'_> {
    /// The angle equivalent to `angle` (modulo 360°) for rotary `k` reached from `prev` by the
    /// policy (wrapping axes) or nearest to it inside the limits (others); `None` if every
    /// equivalent lies outside the limits.
    pub fn unwind(&self, k: usize, angle: f64, prev: f64) -> Option<f64> {
        let r = &self.chain.rotaries()[k];
        let near = prev + principal_deg(angle - prev);
        if r.wrap {
            return Some(match self.policy {
                Policy::Shortest => near,
                Policy::Positive => prev + (angle - prev).rem_euclid(360.0),
                Policy::Negative => prev - (prev - angle).rem_euclid(360.0),
            });
        }
        let mut best: Option<f64> = None;
        for turns in [0.0, -1.0, 1.0, -2.0, 2.0] {
            let a = near + 360.0 * turns;
            if r.admits(a) && best.is_none_or(|b| (a - prev).abs() < (b - prev).abs()) {
                best = Some(a);
            }
        }
        best
    }

    /// Rotary angles for tool axis `axis` continuous with `prev`: both branches, every turn
    /// inside the limits, the smallest total rotary move wins. Inside the singular cone the
    /// primary angle is held at `prev[0]`.
    pub fn choose(&self, axis: &V3, prev: &[f64; 2]) -> Result<Choice, Unreachable> {
        let chain = self.chain;
        let Some(o) = chain.orientations(axis) else {
            return Err(Unreachable(match chain.rotaries().len() {
                0 => "the tool axis is not 0,0,1 and the machine has no rotary axis".into(),
                _ => format!(
                    "no rotary angles of this machine turn the tool onto axis {:.6},{:.6},{:.6}",
                    axis.x, axis.y, axis.z
                ),
            }));
        };
        if o.count == 2 && o.off_primary < self.cone {
            return self.hold(axis, prev[0], prev);
        }
        let n = chain.rotaries().len();
        let mut best: Option<(f64, Choice)> = None;
        let mut why = Vec::new();
        for (b, rot) in o.branch[..o.count].iter().enumerate() {
            let mut out = [0.0; 2];
            let mut ok = true;
            for k in 0..n {
                match self.unwind(k, rot[k], prev[k]) {
                    Some(a) => out[k] = a,
                    None => {
                        let r = &chain.rotaries()[k];
                        let (lo, hi) = r.limits.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
                        why.push(format!("{} would be {:.4}° (limits {lo}..{hi})", r.address, rot[k]));
                        ok = false;
                        break;
                    }
                }
            }
            if !ok {
                continue;
            }
            // Ties go to the branch whose secondary angle is not negative (paper 002 eq. 3's).
            let cost: f64 =
                (0..n).map(|k| (out[k] - prev[k]).abs()).sum::<f64>() + if n == 2 && out[1] < 0.0 { 1e-9 } else { 0.0 };
            if best.as_ref().is_none_or(|(c, _)| cost < *c - 1e-12) {
                best = Some((cost, Choice { rot: out, branch: b, singular: false }));
            }
        }
        best.map(|(_, c)| c)
            .ok_or_else(|| Unreachable(format!("no solution within the axis limits: {}", why.join(" or "))))
    }

    /// The pose with the primary angle fixed at `primary` and the secondary angle bringing the
    /// tool axis nearest to `axis` (the singular cone's rule), unwound from `prev`.
    pub fn hold(&self, axis: &V3, primary: f64, prev: &[f64; 2]) -> Result<Choice, Unreachable> {
        let chain = self.chain;
        let sec = chain.secondary_for(axis, primary);
        let r = &chain.rotaries()[1];
        let a = self.unwind(1, sec, prev[1]).ok_or_else(|| {
            let (lo, hi) = r.limits.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
            Unreachable(format!(
                "no solution within the axis limits near the singularity: {} would be {sec:.4}° (limits {lo}..{hi})",
                r.address
            ))
        })?;
        if !chain.rotaries()[0].admits(primary) {
            return Err(Unreachable(format!(
                "{} held at {primary:.4}° is outside its limits",
                chain.rotaries()[0].address
            )));
        }
        Ok(Choice { rot: [primary, a], branch: 0, singular: true })
    }
}
