//! The step over after each pass: the straight side cut's at the threshold, or less after a pass
//! that curves round the pocket (a concentric pass cuts outward at more than the side cut's
//! engagement), so that round pockets are cut by concentric passes that hold the threshold.

use crate::Settings;
use crate::corner::concave_step;
use camkit::contour::{Contour, Seg};

/// Arcs of a pass tighter than this many tool radii are left to the trochoids like corners: the
/// step after a pass is limited only by its arcs of radius R/8 or more, which keeps it over a
/// ninth of the straight side cut's ([`concave_step`] at ρ = R/8).
pub const STEP_ARCS_FROM: f64 = 0.125;

/// The step after a pass whose loops (oriented as a region: material to the right of travel
/// when cut) are `loops`: `s.step`, or less where the loops curve round the pocket. A pass
/// along an arc of radius ρ centred on the pocket's side cuts outward from the concentric pass
/// a step inside it at acos(1 − s/R − s/ρ + s²/(2ρR)), more than the straight side cut's, so
/// the step is the largest that holds the threshold on the pass's tightest such arc of radius
/// R × [`STEP_ARCS_FROM`] or more.
pub fn step_after(loops: &[Contour], s: &Settings) -> f64 {
    let tightest = loops
        .iter()
        .flat_map(|c| c.segs())
        .filter_map(|g| match g {
            Seg::Arc(a) if a.sweep > 0.0 && a.r >= STEP_ARCS_FROM * s.radius => Some(a.r),
            _ => None,
        })
        .reduce(f64::min);
    tightest.map_or(s.step, |rho| s.step.min(concave_step(s.radius, rho, s.threshold.to_radians())))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corner::concave_engagement;
    use crate::default_step;
    use crate::feed::FeedModel;
    use crate::medial::MedialOptions;
    use camkit::geom::P2;

    #[test]
    fn the_step_after_a_pass_follows_its_tightest_arc_round_the_pocket() {
        let s = Settings {
            radius: 4.0,
            step: default_step(4.0, 40.0),
            threshold: 40.0,
            trochoid_radius: 2.0,
            pitch: None,
            allowance: 0.0,
            corner_radius: None,
            sample: 0.5,
            medial: MedialOptions::default(),
            feed: FeedModel { spindle: 4800.0, teeth: 6.0, chip: 0.03, fz_max: 0.1, force_at: Some(40.0) },
            entry: crate::program::Entry::FLAT,
        };
        let phi = 40f64.to_radians();
        let square =
            Contour::polygon(&[P2::new(0.0, 0.0), P2::new(9.0, 0.0), P2::new(9.0, 9.0), P2::new(0.0, 9.0)], true);
        // Straight sides: the given step.
        assert_eq!(step_after(std::slice::from_ref(&square), &s), s.step);
        // A pass round a circle of radius 10 (counter-clockwise: the pocket's side), and an island's
        // loop (clockwise: it curves away from the material) of radius 3.
        let round = Contour::circle(P2::new(50.0, 0.0), 10.0, 0.0, true);
        let island = Contour::circle(P2::new(50.0, 0.0), 3.0, 0.0, false);
        let step = step_after(&[square.clone(), round.clone(), island], &s);
        assert!((step - concave_step(4.0, 10.0, phi)).abs() < 1e-15);
        assert!((concave_engagement(4.0, 10.0, step) - phi).abs() < 1e-12);
        // The tightest arc decides, down to R/8; tighter ones are left to the trochoids.
        let tight = Contour::circle(P2::new(0.0, 50.0), 0.6, 0.0, true);
        let step = step_after(&[round.clone(), tight], &s);
        assert!((step - concave_step(4.0, 0.6, phi)).abs() < 1e-15);
        let tighter = Contour::circle(P2::new(0.0, 50.0), 0.49, 0.0, true);
        assert_eq!(step_after(&[round.clone(), tighter], &s), concave_step(4.0, 10.0, phi));
        // A step given under the concave one stays.
        let small = Settings { step: 0.2, ..s };
        assert_eq!(step_after(&[round], &small), 0.2);
    }
}
