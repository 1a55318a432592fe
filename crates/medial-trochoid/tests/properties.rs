//! Property tests: trochoids hold the threshold at the pitch chosen for them, medial-axis points
//! are equidistant from two boundary elements, and the side-cut engagement follows its closed form.

use camkit::contour::region::regions;
use camkit::contour::{Contour, Seg};
use camkit::geom::P2;
use medial_trochoid::engagement::Cut;
use medial_trochoid::medial::{MedialOptions, medial_axis};
use medial_trochoid::trochoid::{pitch_for, straight_engagement};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, ..ProptestConfig::default() })]

    /// The pitch chosen by bisection keeps every loop at or under the threshold, also when the
    /// loops are sampled four times finer than when the pitch was chosen.
    #[test]
    fn trochoid_engagement_stays_under_the_threshold(r in 2.0f64..8.0, k in 0.2f64..1.0, thr in 30.0f64..90.0) {
        let rt = k * r;
        let p = pitch_for(r, rt, thr, 0.1).expect("a pitch at 1% of R holds these thresholds");
        let fine = straight_engagement(r, rt, p, 0.025);
        prop_assert!(fine <= thr + 0.5, "r {r} rt {rt} pitch {p}: {fine}° over {thr}°");
    }

    /// Every point of the medial axis of an L-shaped pocket is as far from its nearest boundary
    /// element as its clearance says, and no boundary element is nearer.
    #[test]
    fn medial_axis_points_are_equidistant(w in 20.0f64..80.0, h in 20.0f64..80.0, a in 0.2f64..0.8, b in 0.2f64..0.8) {
        let pts = [
            P2::new(0.0, 0.0), P2::new(w, 0.0), P2::new(w, b * h), P2::new(a * w, b * h),
            P2::new(a * w, h), P2::new(0.0, h),
        ];
        let outer = Contour::polygon(&pts, true);
        let region = regions(std::slice::from_ref(&outer)).expect("an L is a region").0.remove(0);
        let m = medial_axis(&region, &MedialOptions::default()).expect("medial axis");
        prop_assert!(!m.edges.is_empty());
        let segs: Vec<Seg> = outer.segs().collect();
        for e in &m.edges {
            for (p, c) in e.points.iter().zip(&e.clearance) {
                let mut d: Vec<f64> = segs.iter().map(|s| s.distance_to(p)).collect();
                d.sort_by(f64::total_cmp);
                // Nearest element at the clearance; a second one (possibly sharing a corner) as near.
                prop_assert!((d[0] - c).abs() < 1e-5, "{p}: nearest {} vs clearance {c}", d[0]);
                prop_assert!((d[1] - d[0]).abs() < 1e-5, "{p}: {} vs {}", d[0], d[1]);
            }
        }
    }

    /// A straight side cut at any radial depth below the diameter: acos(1 − ae/R), exactly.
    #[test]
    fn side_cut_engagement_is_exact(r in 1.0f64..10.0, f in 0.01f64..1.99, t in 0.1f64..0.9) {
        let ae = f * r;
        let cut = Cut::new(r, vec![
            Seg::Line(P2::new(0.0, 0.0), P2::new(100.0, 0.0)),
            Seg::Line(P2::new(0.0, ae), P2::new(100.0, ae)),
        ]);
        let e = cut.engagement(1, t);
        prop_assert!((e - (1.0 - ae / r).acos()).abs() < 1e-9);
    }
}
