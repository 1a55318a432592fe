//! The cutting tool as the simulation sees it: a ball end mill of radius r with Z straight
//! flutes on meridians of the ball (paper 003 eq. 1–2), optionally ground flat at the tip
//! (eq. 6–7), turning one way or the other about its axis.

use camkit::doc::{Tool, ToolKind};
use camkit::error::{Error, Result};
use camkit::json::field_error;
use std::f64::consts::PI;

/// Sense of rotation seen from the shank looking toward the tip (from +w, paper eq. 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rotation {
    /// Counter-clockwise: the flute angle grows (paper eq. 1, fig. 3).
    Ccw,
    /// Clockwise.
    Cw,
}

impl Rotation {
    /// +1 for counter-clockwise, −1 for clockwise.
    pub fn sign(self) -> f64 {
        match self {
            Rotation::Ccw => 1.0,
            Rotation::Cw => -1.0,
        }
    }
}

/// A ball end mill with its flutes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cutter {
    /// Ball radius r (mm).
    pub radius: f64,
    /// Number of flutes Z, evenly spaced (eq. 2).
    pub flutes: u32,
    /// Radius r0 of the flat ground at the tip (mm), 0 for a plain ball.
    pub flat_radius: f64,
    /// Sense of rotation.
    pub rotation: Rotation,
}

impl Cutter {
    /// A plain ball end mill turning counter-clockwise (the paper's).
    pub fn ball(radius: f64, flutes: u32) -> Cutter {
        Cutter { radius, flutes, flat_radius: 0.0, rotation: Rotation::Ccw }
    }

    /// The cutter of a tool document; `flutes` overrides the document's count, which must be
    /// given one way or the other.
    pub fn from_tool(tool: &Tool, file: &str, flutes: Option<u32>) -> Result<Cutter> {
        if tool.kind != ToolKind::Ball {
            return Err(field_error(file, "kind", format!("rough-sim simulates ball end mills, got {:?}", tool.kind)));
        }
        let flutes = flutes.or(tool.flutes).ok_or_else(|| {
            field_error(file, "flutes", "the number of flutes is needed (in the tool document or --flutes)")
        })?;
        let c = Cutter { radius: tool.radius, flutes, flat_radius: tool.tip_flat_radius, rotation: Rotation::Ccw };
        c.validate()?;
        Ok(c)
    }

    /// Checks the dimensions.
    pub fn validate(&self) -> Result<()> {
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return Err(Error::input(format!("tool radius must be a positive number of mm, got {}", self.radius)));
        }
        if self.flutes == 0 {
            return Err(Error::input("a tool needs at least one flute, got 0"));
        }
        if self.flutes > 64 {
            return Err(Error::input(format!("at most 64 flutes are simulated, got {}", self.flutes)));
        }
        if !(self.flat_radius >= 0.0 && self.flat_radius < self.radius) {
            return Err(Error::input(format!(
                "tip flat radius must be at least 0 and below the radius {}, got {}",
                self.radius, self.flat_radius
            )));
        }
        Ok(())
    }

    /// Angle between flutes, 2π/Z (rad).
    pub fn pitch(&self) -> f64 {
        2.0 * PI / self.flutes as f64
    }

    /// Distance from the ball centre to the flat along the axis, √(r² − r0²) (mm); r for a ball.
    pub fn flat_depth(&self) -> f64 {
        (self.radius * self.radius - self.flat_radius * self.flat_radius).sqrt()
    }

    /// δ of paper 003 fig. 7(a): how much shorter the flat makes the tool, r − √(r² − r0²) (mm).
    pub fn flat_error(&self) -> f64 {
        self.radius - self.flat_depth()
    }

    /// Angle ξ0 from the axis where the ball zone of the flutes begins, asin(r0/r) (rad).
    pub fn xi0(&self) -> f64 {
        (self.flat_radius / self.radius).asin()
    }

    /// Depth of the tool's lowest point below its ball centre when the axis is tilted by `tilt`
    /// (rad) from the vertical: r on the ball, less on the flat while the flat is lowest.
    pub fn lowest_below_centre(&self, tilt: f64) -> f64 {
        if tilt.abs() >= self.xi0() {
            self.radius
        } else {
            self.flat_depth() * tilt.cos() + self.flat_radius * tilt.abs().sin()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_error_of_the_paper() {
        let c = Cutter { flat_radius: 0.55, ..Cutter::ball(5.0, 2) };
        // Paper 003 §3.3: r0 = 0.55 mm gives δ = 30 µm.
        assert!((c.flat_error() * 1000.0 - 30.3).abs() < 0.1, "{}", c.flat_error());
        assert_eq!(c.lowest_below_centre(0.0), c.flat_depth());
        assert_eq!(c.lowest_below_centre(0.5), 5.0);
        assert!(Cutter::ball(5.0, 0).validate().is_err());
        assert!(Cutter { flat_radius: 5.0, ..Cutter::ball(5.0, 2) }.validate().is_err());
    }
}
