//! Golden cases of the kind cavalier_contours tests (near-tangent line/arc joins, touching loops,
//! collinear runs and repeated points, repeated offsets, dense stars where its default epsilons
//! fail), compared on invariants measured by brute force rather than on its exact vertex lists.

use camkit::contour::offset::{Side, offset_contour};
use camkit::contour::{Contour, OffsetOptions, Seg, Vertex};
use camkit::geom::P2;
use std::f64::consts::{PI, TAU};

const TOL: f64 = 1e-6;

/// Largest |distance to `input` − d| over sample points of `out`, by brute force.
fn worst(input: &Contour, out: &[Contour], d: f64) -> f64 {
    let segs: Vec<Seg> = input.segs().collect();
    out.iter()
        .flat_map(|c| c.segs().collect::<Vec<_>>())
        .flat_map(|s| (0..=8).map(move |k| s.point_at(k as f64 / 8.0)))
        .map(|p| (segs.iter().map(|s| s.distance_to(&p)).fold(f64::INFINITY, f64::min) - d).abs())
        .fold(0.0, f64::max)
}

fn offset(c: &Contour, d: f64, side: Side) -> Vec<Contour> {
    let o = offset_contour(c, d, side, &OffsetOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(worst(c, &o.contours, d) <= TOL, "{}", worst(c, &o.contours, d));
    for (i, a) in o.contours.iter().enumerate() {
        assert!(a.self_crossing().is_none());
        assert!(o.contours[i + 1..].iter().all(|b| a.crossing_with(b).is_none()));
        assert_eq!(a.closed, c.closed);
    }
    o.contours
}

fn v(x: f64, y: f64, bulge: f64) -> Vertex {
    Vertex { p: P2::new(x, y), bulge }
}

#[test]
fn near_tangent_line_arc_joins() {
    // A slot: two lines and two half circles, the joins tangent up to 1e-9 rad either way.
    for tilt in [0.0, 1e-9, -1e-9] {
        let c = Contour {
            vertices: vec![v(0.0, 0.0, 0.0), v(30.0, tilt, 1.0), v(30.0, 10.0, 0.0), v(0.0, 10.0 - tilt, 1.0)],
            closed: true,
        };
        for (d, side) in [(2.0, Side::Left), (2.0, Side::Right), (4.999, Side::Left)] {
            let out = offset(&c, d, side);
            assert_eq!(out.len(), 1);
            // Closed form: a slot of half width 5 ± d.
            let h = if side == Side::Left { 5.0 - d } else { 5.0 + d };
            let area = 30.0 * 2.0 * h + PI * h * h;
            assert!((out[0].area() - area).abs() < 1e-6, "{} vs {area}", out[0].area());
        }
        // Wider than the slot: nothing.
        assert!(offset(&c, 5.001, Side::Left).is_empty());
    }
}

#[test]
fn touching_and_splitting_loops_at_a_neck() {
    // Two 20 × 20 rooms joined by a neck 2 mm wide: R just under, at and just over 1 mm.
    let rooms = Contour::polygon(
        &[
            P2::new(0.0, 0.0),
            P2::new(20.0, 0.0),
            P2::new(20.0, 9.0),
            P2::new(30.0, 9.0),
            P2::new(30.0, 0.0),
            P2::new(50.0, 0.0),
            P2::new(50.0, 20.0),
            P2::new(30.0, 20.0),
            P2::new(30.0, 11.0),
            P2::new(20.0, 11.0),
            P2::new(20.0, 20.0),
            P2::new(0.0, 20.0),
        ],
        true,
    );
    assert_eq!(offset(&rooms, 0.999, Side::Left).len(), 1);
    // At exactly half the neck the walls' offsets coincide along the neck's middle line, a
    // stretch and not one point (loops touching at one point are split there: see camkit's
    // `loops_touching_at_exactly_2r_are_split_at_the_touching_point`). No run at 1 mm verifies;
    // half the tolerance inside, the offset runs up the middle and back, within the tolerance.
    let o = offset_contour(&rooms, 1.0, Side::Left, &OffsetOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(o.attempts > 1, "the exact distance gives loops along each other");
    assert!(o.check.above.max(o.check.below) <= OffsetOptions::default().tol);
    for x in [20.5, 25.0, 29.5] {
        let mid = P2::new(x, 10.0);
        let near = o.contours.iter().flat_map(Contour::segs).map(|s| s.distance_to(&mid)).fold(f64::INFINITY, f64::min);
        assert!(near <= 1e-6, "({x}, 10) is {near} mm from the offset");
    }
    assert_eq!(offset(&rooms, 1.001, Side::Left).len(), 2);
}

#[test]
fn collinear_runs_and_repeated_points() {
    // A 40 × 20 rectangle with its bottom split into 400 collinear pieces and a doubled corner.
    let mut pts: Vec<P2> = (0..400).map(|i| P2::new(i as f64 * 0.1, 0.0)).collect();
    pts.extend([P2::new(40.0, 0.0), P2::new(40.0, 0.0), P2::new(40.0, 20.0), P2::new(0.0, 20.0)]);
    let c = Contour::polygon(&pts, true);
    let out = offset(&c, 3.0, Side::Right);
    let area = 40.0 * 20.0 + 2.0 * 3.0 * 60.0 + PI * 9.0;
    assert!((out[0].area() - area).abs() < 1e-6);
    let inside = offset(&c, 3.0, Side::Left);
    assert!((inside[0].area() - 34.0 * 14.0).abs() < 1e-6);
}

#[test]
fn repeated_offsets_add_up() {
    // Outward offsets of a convex contour compose: by 1.5 then 2.5 equals by 4 (closed form).
    let c = Contour {
        vertices: vec![v(0.0, 0.0, 0.0), v(30.0, 0.0, 0.2), v(30.0, 15.0, 0.0), v(0.0, 15.0, 0.0)],
        closed: true,
    };
    let once = offset(&c, 4.0, Side::Right);
    let first = offset(&c, 1.5, Side::Right);
    let twice = offset(&first[0], 2.5, Side::Right);
    assert!((once[0].area() - twice[0].area()).abs() < 1e-6, "{} vs {}", once[0].area(), twice[0].area());
    assert!(worst(&c, &twice, 4.0) <= TOL);
    // Inward twice by 2 equals inward by 4 on a circle split into 64 arcs.
    let n = 64;
    let b = (TAU / n as f64 / 4.0).tan();
    let circle = Contour {
        vertices: (0..n)
            .map(|k| {
                let a = TAU * k as f64 / n as f64;
                v(20.0 * a.cos(), 20.0 * a.sin(), b)
            })
            .collect(),
        closed: true,
    };
    let a = offset(&circle, 2.0, Side::Left);
    let a = offset(&a[0], 2.0, Side::Left);
    assert!((a[0].area() - PI * 16.0 * 16.0).abs() < 1e-6);
}

/// A star of `n` vertices, r = 50 + 15 cos 8θ; arcs of alternating bulge ±0.05 if `arcs`.
fn star(n: usize, arcs: bool) -> Contour {
    let vertices = (0..n)
        .map(|i| {
            let a = TAU * i as f64 / n as f64;
            let r = 50.0 + 15.0 * (8.0 * a).cos();
            v(
                r * a.cos(),
                r * a.sin(),
                if !arcs {
                    0.0
                } else if i % 2 == 0 {
                    0.05
                } else {
                    -0.05
                },
            )
        })
        .collect();
    Contour { vertices, closed: true }
}

#[test]
fn dense_stars_where_bare_default_epsilons_fail_still_verify() {
    // 10 k line vertices: bare cavalier with default options gouges here by 2e-6 mm or more (and
    // trips its own debug assertions); see scripts/bench-offset.sh.
    let c = star(10_000, false);
    let o = offset_contour(&c, 2.0, Side::Left, &OffsetOptions::default()).expect("verified");
    assert_eq!(o.contours.len(), 1);
    assert!(o.contours[0].closed && o.check.deviation() <= TOL);
    // Brute force on every 50th output vertex (all 10 k input pieces each).
    let segs: Vec<Seg> = c.segs().collect();
    for q in o.contours[0].vertices.iter().step_by(50) {
        let d = segs.iter().map(|s| s.distance_to(&q.p)).fold(f64::INFINITY, f64::min);
        assert!((d - 2.0).abs() <= TOL, "{} at {d}", q.p);
    }
}
