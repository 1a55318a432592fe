//! The feed model of the time estimate, from what the teeth meet at each sample: the arcs of the
//! tool circle in material (exact, from the simulation) and the direction of travel γ.
//!
//! A tooth at angle β cuts a chip `fz·cos(β − γ)` thick (zero behind the tool). Two limits set
//! the feed per tooth: the thickest chip (`chip`), and, as in paper 001's feed optimisation
//! ("切削抵抗がほぼ一定": the cutting force kept nearly constant), the mean cutting force per
//! revolution. In the mechanistic model every tooth pushes with `ap·h·(Kt t̂ + Kr r̂)`, so the
//! mean force is `z·ap·fz/2π · (Kt J + Kr I)·A` with `A = ∫ cos(β − γ)·(cos β, sin β) dβ` over
//! the arcs ahead and `J` the quarter turn; since `J·A ⊥ A`, its magnitude is
//! `z·ap·fz/2π · √(Kt² + Kr²)·|A|`: the cutting constants and the sense of rotation drop out of
//! any ratio of forces (edge forces are left out). The force allowed is the one of a straight
//! side cut at a given engagement (the threshold by default: above it the tool chips) at its
//! chip-limited feed, so any cut heavier than that one runs proportionally slower.

use crate::angles::AngleSet;
use std::f64::consts::{FRAC_PI_2, TAU};

/// What the teeth meet at one sample, per mm of feed per tooth.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Load {
    /// Thickest chip per mm of feed per tooth: the largest cos(β − γ) over the arcs ahead (0 in
    /// air, 1 when material lies straight ahead).
    pub chip: f64,
    /// Mean cutting force per revolution per mm of feed per tooth, in units of
    /// z·ap·√(Kt² + Kr²)/2π: |A| of the module comment (π/2 for a slot).
    pub force: f64,
}

impl Load {
    /// The load of material on the arcs `arcs` (radians, sorted and disjoint within [0, 2π))
    /// of the tool circle for travel at angle `gamma`; arcs behind the tool carry none.
    pub fn of_arcs(arcs: &[(f64, f64)], gamma: f64) -> Load {
        let ahead = AngleSet(arcs.iter().copied().collect()).intersect(&AngleSet::around(gamma, FRAC_PI_2));
        let (mut x, mut y, mut chip) = (0.0, 0.0, 0.0f64);
        for &(a, b) in &ahead.0 {
            // ∫ cos(β − γ)(cos β, sin β) dβ = ½ ∫ (cos(2β − γ) + cos γ, sin(2β − γ) + sin γ) dβ.
            x += 0.5 * ((b - a) * gamma.cos() + 0.5 * ((2.0 * b - gamma).sin() - (2.0 * a - gamma).sin()));
            y += 0.5 * ((b - a) * gamma.sin() - 0.5 * ((2.0 * b - gamma).cos() - (2.0 * a - gamma).cos()));
            let g = (gamma - a).rem_euclid(TAU);
            let c = if g <= b - a { 1.0 } else { (a - gamma).cos().max((b - gamma).cos()) };
            chip = chip.max(c);
        }
        Load { chip, force: x.hypot(y) }
    }

    /// A straight side cut of engagement `deg` degrees (material from the side of the tool
    /// forward over `deg`, as a climb cut meets it).
    pub fn side_cut(deg: f64) -> Load {
        Load::of_arcs(&[(0.0, deg.clamp(0.0, 180.0).to_radians())], FRAC_PI_2)
    }

    /// A slot: the whole half circle ahead.
    pub fn slot() -> Load {
        Load::side_cut(180.0)
    }
}

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
    /// The force limit: the engagement (degrees) of the straight side cut whose mean force at
    /// its chip-limited feed is the most the tool takes; `None`: no force limit.
    pub force_at: Option<f64>,
}

impl FeedModel {
    /// Feed per tooth (mm) allowed for `load`.
    pub fn fz(&self, load: &Load) -> f64 {
        let mut fz = self.fz_max;
        if load.chip > 0.0 {
            fz = fz.min(self.chip / load.chip);
        }
        if let Some(allowed) = self.force_limit()
            && load.force > 0.0
        {
            fz = fz.min(allowed / load.force);
        }
        fz
    }

    /// Feed (mm/min) allowed for `load`.
    pub fn feed(&self, load: &Load) -> f64 {
        self.fz(load) * self.teeth * self.spindle
    }

    /// The largest mean force (the units of [`Load::force`] times mm of feed per tooth).
    pub fn force_limit(&self) -> Option<f64> {
        self.force_at.map(|deg| {
            let side = Load::side_cut(deg);
            side.force * self.chip_only().fz(&side)
        })
    }

    /// The same model with the chip-thickness limit alone.
    pub fn chip_only(&self) -> FeedModel {
        FeedModel { force_at: None, ..*self }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    /// |A| of a side cut of engagement φ in closed form: ½·|(φ − ½ sin 2φ, sin²φ)|.
    fn side_force(phi: f64) -> f64 {
        0.5 * (phi - 0.5 * (2.0 * phi).sin()).hypot(phi.sin().powi(2))
    }

    /// The integral by the midpoint rule on each arc, a second method for any arcs.
    fn numeric(arcs: &[(f64, f64)], gamma: f64) -> (f64, f64) {
        let (mut x, mut y, mut chip) = (0.0, 0.0, 0.0f64);
        let n = 100_000;
        for &(lo, hi) in arcs {
            let h = (hi - lo) / n as f64;
            for k in 0..n {
                let b = lo + (k as f64 + 0.5) * h;
                let c = (b - gamma).cos().max(0.0);
                x += c * b.cos() * h;
                y += c * b.sin() * h;
                chip = chip.max(c);
            }
        }
        (x.hypot(y), chip)
    }

    #[test]
    fn side_cut_and_slot_match_the_closed_forms() {
        for deg in [1.0, 10.0, 40.0, 75.0, 90.0, 120.0, 180.0] {
            let l = Load::side_cut(deg);
            let phi = f64::to_radians(deg);
            assert!((l.force - side_force(phi)).abs() < 1e-12, "{deg}: {l:?}");
            assert!((l.chip - phi.min(FRAC_PI_2).sin()).abs() < 1e-12, "{deg}: {l:?}");
        }
        assert!((Load::slot().force - FRAC_PI_2).abs() < 1e-12);
        assert_eq!(Load::slot().chip, 1.0);
        // A slot weighs 6.8 times a 40° side cut per tooth feed.
        let ratio = Load::slot().force / Load::side_cut(40.0).force;
        assert!((ratio - 6.806).abs() < 1e-3, "{ratio}");
    }

    proptest! {
        /// The closed form agrees with the midpoint rule on arbitrary arcs and travel, material
        /// behind the tool counting for nothing.
        #[test]
        fn load_matches_numeric_integration(
            gamma in 0.0..TAU,
            cuts in proptest::collection::vec(0.0..TAU, 2..8),
        ) {
            let mut ends = cuts.clone();
            ends.sort_by(f64::total_cmp);
            let arcs: Vec<(f64, f64)> = ends.chunks_exact(2).map(|c| (c[0], c[1])).filter(|(a, b)| b > a).collect();
            let l = Load::of_arcs(&arcs, gamma);
            let (force, chip) = numeric(&arcs, gamma);
            prop_assert!((l.force - force).abs() < 1e-6, "{l:?} vs {force}");
            prop_assert!((l.chip - chip).abs() < 1e-4, "{l:?} vs {chip}");
        }

        /// Turning the whole picture turns nothing: the load depends on the arcs relative to
        /// the travel only.
        #[test]
        fn load_is_invariant_under_rotation(turn in 0.0..TAU, a in 0.0..PI, w in 0.0..PI) {
            let base = Load::of_arcs(&[(a, a + w)], 0.3);
            let r = AngleSet::around(a + 0.5 * w + turn, 0.5 * w);
            let turned = Load::of_arcs(&r.0, 0.3 + turn);
            prop_assert!((base.force - turned.force).abs() < 1e-12);
            prop_assert!((base.chip - turned.chip).abs() < 1e-12);
        }
    }

    #[test]
    fn chip_limit_then_force_limit() {
        let m = FeedModel { spindle: 1000.0, teeth: 2.0, chip: 0.02, fz_max: 0.1, force_at: None };
        // Chip thickness alone: fz = chip / sin φ up to 90°, chip beyond; air at fz_max.
        assert!((m.feed(&Load::slot()) - 40.0).abs() < 1e-12);
        assert!((m.feed(&Load::side_cut(30.0)) - 80.0).abs() < 1e-9);
        assert!((m.feed(&Load::default()) - 200.0).abs() < 1e-12);
        let f = FeedModel { force_at: Some(40.0), ..m };
        // Up to the limit's own side cut the chip decides; the side cut at 40° is at both limits.
        for deg in [5.0, 20.0, 39.0, 40.0] {
            let l = Load::side_cut(deg);
            assert!((f.feed(&l) - m.feed(&l)).abs() < 1e-9 * m.feed(&l), "{deg}");
        }
        // Beyond it the force does: feed × force is constant.
        let at40 = f.feed(&Load::side_cut(40.0)) * Load::side_cut(40.0).force;
        for deg in [41.0, 60.0, 90.0, 135.0, 180.0] {
            let l = Load::side_cut(deg);
            assert!(f.feed(&l) < m.feed(&l), "{deg}");
            assert!((f.feed(&l) * l.force - at40).abs() < 1e-9 * at40, "{deg}");
        }
        // The slot at 1/6.8 of the 40° side cut's feed, against 1/1.56 by the chip alone.
        let ratio = f.feed(&Load::side_cut(40.0)) / f.feed(&Load::slot());
        assert!((ratio - 6.806).abs() < 1e-3, "{ratio}");
        assert_eq!(f.chip_only(), m);
        // Material straight ahead over a narrow arc: thickest chip fz, hence slower than the side
        // cut of the same angle.
        let ahead = Load::of_arcs(&AngleSet::around(0.0, 20f64.to_radians()).0, 0.0);
        assert_eq!(ahead.chip, 1.0);
        assert!(f.feed(&ahead) < f.feed(&Load::side_cut(40.0)));
    }
}
