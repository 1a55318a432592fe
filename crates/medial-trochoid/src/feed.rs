//! The feed model of the time estimate: constant maximum chip thickness. With engagement φ the
//! thickest chip is `fz·sin φ` (φ ≤ 90°) or `fz` (φ > 90°), so the feed per tooth that keeps it
//! at `chip` is `chip / sin(min(φ, 90°))`, capped by the tool's largest feed per tooth.
//! Optionally, a hard-steel derating: above `derate_above` degrees the feed is multiplied by
//! `derate` (paper 001: tools chip at high engagement in HRC53 steel; the factor is the user's
//! cutting data, not the paper's, and 1 switches it off).

/// Cutting data of the tool.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeedModel {
    /// Spindle speed (1/min).
    pub spindle: f64,
    /// Number of teeth.
    pub teeth: f64,
    /// Largest chip thickness (mm).
    pub chip: f64,
    /// Largest feed per tooth the tool allows (mm).
    pub fz_max: f64,
    /// Engagement (degrees) above which the derating applies.
    pub derate_above: f64,
    /// Factor on the feed above `derate_above` (1: no derating).
    pub derate: f64,
}

impl FeedModel {
    /// Feed (mm/min) allowed at engagement `deg` degrees.
    pub fn feed(&self, deg: f64) -> f64 {
        let s = deg.clamp(0.0, 90.0).to_radians().sin();
        let fz = if s <= 0.0 { self.fz_max } else { (self.chip / s).min(self.fz_max) };
        // A side cut at exactly the threshold is not derated for its round-off.
        let k = if deg > self.derate_above + crate::ENGAGEMENT_ROUNDOFF_DEG { self.derate } else { 1.0 };
        fz * self.teeth * self.spindle * k
    }

    /// The same model without the derating.
    pub fn underated(&self) -> FeedModel {
        FeedModel { derate: 1.0, ..*self }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feed_falls_with_engagement() {
        let m = FeedModel { spindle: 1000.0, teeth: 2.0, chip: 0.02, fz_max: 0.1, derate_above: 40.0, derate: 1.0 };
        assert!((m.feed(180.0) - 40.0).abs() < 1e-12);
        assert!((m.feed(30.0) - 80.0).abs() < 1e-9);
        assert!((m.feed(1.0) - 200.0).abs() < 1e-9);
        assert!(m.feed(40.0) > m.feed(60.0));
        let d = FeedModel { derate: 0.5, ..m };
        assert!((d.feed(40.0) - m.feed(40.0)).abs() < 1e-12);
        assert!((d.feed(40.1) - 0.5 * m.feed(40.1)).abs() < 1e-12);
        assert!((d.feed(180.0) - 20.0).abs() < 1e-12);
        assert_eq!(d.underated(), m);
    }
}
