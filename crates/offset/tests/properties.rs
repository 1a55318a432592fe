//! Property tests of the verified offset kernel (`camkit::contour`) as `offset` uses it: random
//! contours of lines and arcs, with and without islands, measured by brute force (every input
//! piece, no spatial index) at sample points of every output piece.

use camkit::contour::offset::{Side, offset_contour};
use camkit::contour::pocket::{Direction, Passes, PocketOptions, pocket};
use camkit::contour::region::regions;
use camkit::contour::{Contour, OffsetOptions, Seg, Vertex};
use camkit::geom::P2;
use proptest::prelude::*;
use std::f64::consts::TAU;

/// The promise: every output point within this of distance R (mm).
const TOL: f64 = 1e-6;

/// Distance from `p` to the nearest piece of `input`, over every piece.
fn distance(input: &[&Contour], p: &P2) -> f64 {
    input.iter().flat_map(|c| c.segs()).map(|s| s.distance_to(p)).fold(f64::INFINITY, f64::min)
}

/// Sample points of every piece of `c` (ends and seven interior points).
fn samples(c: &Contour) -> Vec<P2> {
    c.segs().flat_map(|s: Seg| (0..=8).map(move |k| s.point_at(k as f64 / 8.0))).collect()
}

/// A star-shaped closed contour, counter-clockwise: radius `radii[k]` at angle k·2π/n, each piece
/// an arc of bulge `bulges[k]` (0 = line).
fn star(radii: &[f64], bulges: &[f64]) -> Contour {
    let n = radii.len();
    let vertices = (0..n)
        .map(|k| {
            let a = TAU * k as f64 / n as f64;
            Vertex { p: P2::new(radii[k] * a.cos(), radii[k] * a.sin()), bulge: bulges[k % bulges.len()] }
        })
        .collect();
    Contour { vertices, closed: true }
}

/// Radii and bulges of a random star (a quarter of the pieces arcs when `arcs`).
fn star_parts() -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
    (6usize..24).prop_flat_map(|n| {
        (
            prop::collection::vec(20.0f64..40.0, n),
            prop::collection::vec(prop_oneof![3 => Just(0.0), 1 => -0.25f64..0.25], n),
        )
    })
}

/// No loop of `out` crosses itself or another.
fn no_crossings(out: &[Contour]) -> Result<(), TestCaseError> {
    for (i, a) in out.iter().enumerate() {
        prop_assert!(a.self_crossing().is_none(), "loop {i} crosses itself");
        for b in &out[i + 1..] {
            prop_assert!(a.crossing_with(b).is_none(), "loops cross");
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// A closed contour offset either way: every output point at distance R within 1e-6 mm, inside
    /// for the left of a counter-clockwise loop and outside for the right, closed, uncrossed.
    #[test]
    fn closed_offsets_keep_distance_r_on_the_chosen_side(
        (radii, bulges) in star_parts(),
        d in 0.5f64..8.0,
        left in any::<bool>(),
    ) {
        let c = star(&radii, &bulges);
        prop_assume!(c.self_crossing().is_none());
        let side = if left { Side::Left } else { Side::Right };
        let o = offset_contour(&c, d, side, &OffsetOptions::default()).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert!(!o.contours.is_empty());
        for out in &o.contours {
            prop_assert!(out.closed);
            for p in samples(out) {
                let dist = distance(&[&c], &p);
                prop_assert!((dist - d).abs() <= TOL, "point {p} at {dist} mm, R = {d}");
                prop_assert_eq!(c.winding_number(&p) != 0, left, "point {} on the wrong side", p);
            }
        }
        no_crossings(&o.contours)?;
        prop_assert!(o.check.deviation() <= TOL);
    }

    /// An open zig-zag of lines and arcs offset to one side: distance R everywhere, on that side
    /// of the nearest piece.
    #[test]
    fn open_offsets_keep_distance_r(
        ys in prop::collection::vec(-10.0f64..10.0, 3..16),
        bulges in prop::collection::vec(prop_oneof![2 => Just(0.0), 1 => -0.3f64..0.3], 16),
        d in 0.3f64..4.0,
        left in any::<bool>(),
    ) {
        let vertices = ys.iter().enumerate().map(|(k, &y)| Vertex { p: P2::new(8.0 * k as f64, y), bulge: bulges[k] }).collect();
        let c = Contour { vertices, closed: false };
        prop_assume!(c.self_crossing().is_none());
        let side = if left { Side::Left } else { Side::Right };
        let o = offset_contour(&c, d, side, &OffsetOptions::default()).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert!(!o.contours.is_empty());
        for out in &o.contours {
            for p in samples(out) {
                let dist = distance(&[&c], &p);
                prop_assert!((dist - d).abs() <= TOL, "point {p} at {dist} mm, R = {d}");
            }
        }
    }

    /// A pocket with islands: every pass at its stated distance from the region's loops (boundary
    /// and islands) within 1e-6 mm, inside the material, no passes crossing.
    #[test]
    fn pocket_passes_around_islands_keep_their_distance(
        (radii, bulges) in star_parts(),
        island_r in 2.0f64..4.5,
        gap in 10.0f64..11.0,
        radius in 0.5f64..2.0,
        step in 1.0f64..3.0,
    ) {
        let outer = star(&radii, &bulges);
        prop_assume!(outer.self_crossing().is_none());
        // Two islands apart (gap > 2 island_r): a circle and a square, clockwise, well inside every
        // star (radii ≥ 20, arcs bulging in by at most 3 mm).
        let circle = Contour::circle(P2::new(-gap * 0.5, 0.0), island_r, 0.0, false);
        let h = island_r;
        let (cx, cy) = (gap * 0.5, 2.0);
        let square = Contour::polygon(
            &[P2::new(cx - h, cy - h), P2::new(cx - h, cy + h), P2::new(cx + h, cy + h), P2::new(cx + h, cy - h)],
            true,
        );
        let (rs, _) = regions(&[outer.clone(), circle.clone(), square.clone()]).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(rs.len(), 1);
        prop_assert_eq!(rs[0].islands.len(), 2);
        let opts = PocketOptions { radius, step, passes: Passes::Count(3), direction: Direction::Climb, offset: OffsetOptions::default() };
        let p = pocket(&rs, &opts).map_err(|e| TestCaseError::fail(format!("{:?}", e.error)))?;
        prop_assert!(!p.passes.is_empty());
        let loops = [&outer, &circle, &square];
        for pass in &p.passes {
            prop_assert!(pass.contour.closed);
            for q in samples(&pass.contour) {
                let dist = distance(&loops, &q);
                prop_assert!((dist - pass.distance).abs() <= TOL, "point {q} at {dist} mm, pass at {}", pass.distance);
                prop_assert!(rs[0].contains(&q));
            }
        }
        let all: Vec<Contour> = p.passes.iter().map(|x| x.contour.clone()).collect();
        no_crossings(&all)?;
    }
}
