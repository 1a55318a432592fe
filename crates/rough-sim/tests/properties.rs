//! Property tests of the envelope on random cutting conditions: the simulated surface never
//! rises above any point an edge swept through (it is below the tool envelope), never passes
//! below the swept ball (no overcut), and is itself a point of the edge the solver names.

use proptest::prelude::*;
use rough_sim::cutter::Cutter;
use rough_sim::kinematics::Zone;
use rough_sim::patch::{Conditions, node_cut};

/// Solver tolerance of a cut height at a node (mm): far below the stated 0.1 µm.
const EXACT: f64 = 1e-9;

fn conditions() -> impl Strategy<Value = Conditions> {
    (2.0..15.0f64, 1u32..5, 0.05..1.0f64, 0.02..0.7f64, 0.0..20.0f64, any::<bool>(), 0.0..360.0f64).prop_map(
        |(r, z, pick, fz, tilt, plus, phase)| Conditions {
            cutter: Cutter::ball(r, z),
            pick,
            feed_per_tooth: fz,
            tilt: tilt.to_radians(),
            lean: if plus { 1.0 } else { -1.0 },
            pass_phase: phase.to_radians(),
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Any edge point of any pass near the cell (random flute, spindle angle and radial
    /// distance) is at or above the surface at its own (x, y).
    #[test]
    fn surface_never_exceeds_the_edge_envelope(
        cond in conditions(),
        k in -2i64..=2,
        n in 0u32..4,
        y_frac in 0.0..1.0f64,
        radial_frac in 0.0..1.0f64,
    ) {
        let mv = cond.pass(k, 0.0, cond.feed_per_tooth);
        let n = n % cond.cutter.flutes;
        // The centre over the cell's length (±0.5 mm), where neighbouring passes all reach.
        let theta = (y_frac * (cond.feed_per_tooth + 1.0) - 0.5 - mv.c0.y) / mv.feed_per_radian();
        let radial = radial_frac * cond.cutter.radius.min(1.0);
        let p = mv.edge_point(&cond.cutter, n, theta, radial);
        let (_, cut) = node_cut(&cond, p.x, p.y).expect("an edge passed over its own point");
        prop_assert!(cut.z <= p.z + EXACT, "surface {} above edge point {} at ({}, {})", cut.z, p.z, p.x, p.y);
    }

    /// At a random point of the cell the surface is no lower than the ball swept along the
    /// nearest pass, and is the point of the flute and spindle angle the solver reports.
    #[test]
    fn surface_is_an_edge_point_above_the_swept_ball(
        cond in conditions(),
        u in -0.5..0.5f64,
        v in 0.0..1.0f64,
    ) {
        let (x, y) = (u * cond.pick, v * cond.feed_per_tooth);
        let (k, cut) = node_cut(&cond, x, y).expect("the cell is cut");
        let r = cond.cutter.radius;
        let swept = (-3..=3)
            .map(|j| {
                let d = x - j as f64 * cond.pick;
                if d.abs() < r { r - (r * r - d * d).sqrt() } else { f64::INFINITY }
            })
            .fold(f64::INFINITY, f64::min);
        prop_assert!(cut.z >= swept - EXACT, "cut {} below the swept ball {}", cut.z, swept);
        if cut.zone != Zone::Flat {
            let mv = cond.pass(k, y, y);
            let p = mv.edge_point(&cond.cutter, cut.flute, cut.theta, cut.radial);
            let off = ((p.x - x).powi(2) + (p.y - y).powi(2)).sqrt();
            prop_assert!(off < 1e-6 && (p.z - cut.z).abs() < 1e-6, "edge point {p:?} vs cut {cut:?} at ({x}, {y})");
        }
    }
}
