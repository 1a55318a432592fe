//! Property tests of the fit against independent answers: dense sampling of the written pieces
//! with exact point-to-segment distances (not the filter's own measure), closed forms for
//! exactly sampled arcs and lines, and G-code written and read back.

use camkit::geom::{Arc2, P2, P3, Plane, V2};
use camkit::table::{Move, Row, Schema, Table};
use curve_fit_arcs::fit::{Exact, Piece, Shape};
use curve_fit_arcs::{Options, segment};
use proptest::prelude::*;

/// Largest distance between a written arc and the polyline of its samples (their sagitta).
fn sampling_error(p: &Piece, step: f64) -> f64 {
    match p.radius() {
        Some(r) => r * (1.0 - (0.5 * (step / r).min(std::f64::consts::PI)).cos()),
        None => 0.0,
    }
}

/// Points along a written piece, at most `step` apart (arcs as the controller runs them).
fn piece_samples(p: &Piece, step: f64) -> Vec<P3> {
    match p.shape {
        Shape::Line => {
            let n = (((p.end - p.start).norm() / step).ceil() as usize).max(1);
            (0..=n).map(|i| p.start + (p.end - p.start) * (i as f64 / n as f64)).collect()
        }
        Shape::Arc { centre, plane, ccw } => {
            let (s, ws) = plane.split(&p.start);
            let (e, we) = plane.split(&p.end);
            let arc = Arc2::from_centre(centre, &s, &e, ccw, false);
            let (r0, r1) = ((s - centre).norm(), (e - centre).norm());
            let n = ((arc.sweep.abs() * arc.r / step).ceil() as usize).max(1);
            (0..=n)
                .map(|i| {
                    let t = i as f64 / n as f64;
                    let a = arc.start + arc.sweep * t;
                    let rad = r0 + (r1 - r0) * t;
                    plane.join(&(centre + V2::new(a.cos(), a.sin()) * rad), ws + (we - ws) * t)
                })
                .collect()
        }
    }
}

fn seg_dist(p: &P3, a: &P3, b: &P3) -> f64 {
    let d = b - a;
    let l2 = d.norm_squared();
    let t = if l2 > 0.0 { ((p - a).dot(&d) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + d * t)).norm()
}

fn polyline_dist(p: &P3, line: &[P3]) -> f64 {
    line.windows(2).map(|w| seg_dist(p, &w[0], &w[1])).fold(f64::INFINITY, f64::min)
}

/// Sampled two-sided Hausdorff distance between each written piece and the stretch of input it
/// replaces (a stronger, local form of the global check), samples at most `step` apart (and at
/// most 2000 per piece and chord), and the largest error the sampling itself may add.
fn sampled_deviation(pts: &[P3], pieces: &[Piece], step: f64) -> (f64, f64) {
    let mut worst: f64 = 0.0;
    let mut slack: f64 = 0.0;
    for p in pieces {
        let input = &pts[p.first..=p.last];
        let length: f64 = input.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        let step = step.max(length / 2000.0);
        let out = piece_samples(p, step);
        slack = slack.max(sampling_error(p, step));
        let dense_in: Vec<P3> = input
            .windows(2)
            .flat_map(|w| {
                let n = (((w[1] - w[0]).norm() / step).ceil() as usize).clamp(1, 2000);
                (0..n).map(move |i| w[0] + (w[1] - w[0]) * (i as f64 / n as f64))
            })
            .chain(input.last().copied())
            .collect();
        let a = dense_in.iter().map(|q| polyline_dist(q, &out)).fold(0.0, f64::max);
        let b = out.iter().map(|q| polyline_dist(q, input)).fold(0.0, f64::max);
        worst = worst.max(a).max(b);
    }
    (worst, slack)
}

/// A smooth random curve: a sum of a few sinusoids in x and y plus a drift, sampled along its
/// parameter, with bounded noise added to every point but the ends.
fn noisy_curve(coeffs: &[f64], n: usize, step: f64, noise: &[f64], amplitude: f64) -> Vec<P3> {
    (0..n)
        .map(|i| {
            let t = i as f64 * step;
            let mut x = t;
            let mut y = 0.0;
            for (k, c) in coeffs.chunks(2).enumerate() {
                let f = 0.05 * (k + 1) as f64;
                x += c[0] * (f * t).sin();
                y += c[1] * (f * t + k as f64).cos();
            }
            let e = if i == 0 || i == n - 1 {
                (0.0, 0.0)
            } else {
                (noise[2 * i % noise.len()], noise[(2 * i + 1) % noise.len()])
            };
            P3::new(x + amplitude * e.0, y + amplitude * e.1, 0.0)
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Noise below the tolerance: every input point and chord within tol of the output and every
    /// output point within tol of the input, by dense sampling and exact segment distances.
    #[test]
    fn smooth_noisy_curves_stay_within_tolerance(
        coeffs in proptest::collection::vec(-8.0..8.0f64, 6),
        n in 20usize..400,
        step in 0.05..1.0f64,
        noise in proptest::collection::vec(-1.0..1.0f64, 64),
        tol in prop_oneof![Just(0.005), Just(0.01), Just(0.05)],
        paper: bool,
    ) {
        let pts = noisy_curve(&coeffs, n, step, &noise, 0.4 * tol);
        prop_assume!(pts.windows(2).all(|w| (w[1] - w[0]).norm() > 1e-6));
        let method = if paper { curve_fit_arcs::Method::Paper } else { curve_fit_arcs::Method::Fewest };
        let opts = Options { tol, method, ..Options::default() };
        let pieces = segment::segment(&pts, &opts, &Exact).unwrap();
        prop_assert_eq!(pieces.first().unwrap().first, 0);
        prop_assert_eq!(pieces.last().unwrap().last, pts.len() - 1);
        prop_assert!(pieces.windows(2).all(|w| w[0].last == w[1].first && w[0].end == w[1].start));
        let (worst, slack) = sampled_deviation(&pts, &pieces, tol / 10.0);
        // Sampled arcs lie inside the true ones by at most their sagitta (`slack`).
        prop_assert!(worst <= tol + slack + 1e-12, "sampled deviation {worst} > tol {tol}");
        let claimed = pieces.iter().map(|p| p.deviation).fold(0.0, f64::max);
        prop_assert!(claimed <= tol && worst <= claimed + slack + 1e-12, "claimed {claimed}, sampled {worst}, slack {slack}");
    }

    /// Exactly sampled arcs give one arc whose radius and centre match to 1e-9 relative (the
    /// tolerance must cover the chords' sagitta: the input is the polyline, not the arc).
    #[test]
    fn exact_arcs_become_one_arc(
        cx in -200.0..200.0f64, cy in -200.0..200.0f64, r in 0.5..500.0f64,
        start in -3.1..3.1f64, sweep in 0.2..5.5f64, ccw: bool, n in 5usize..300,
    ) {
        // Turns of more than the corner angle (60°) between chords are corners, kept sharp.
        prop_assume!(sweep / (n as f64) < 50f64.to_radians());
        let sense = if ccw { 1.0 } else { -1.0 };
        let pts: Vec<P3> = (0..=n).map(|i| {
            let a = start + sense * sweep * i as f64 / n as f64;
            P3::new(cx + r * a.cos(), cy + r * a.sin(), 0.0)
        }).collect();
        let sagitta = r * (1.0 - (0.5 * sweep / n as f64).cos());
        let opts = Options { tol: sagitta * 1.001 + 1e-9 * r, ..Options::default() };
        let pieces = segment::segment(&pts, &opts, &Exact).unwrap();
        prop_assert_eq!(pieces.len(), 1, "{:?}", pieces);
        let Shape::Arc { centre, ccw: sense_out, .. } = pieces[0].shape else { panic!("not an arc: {:?}", pieces[0]) };
        prop_assert_eq!(sense_out, ccw);
        let scale = r.max(cx.abs()).max(cy.abs());
        prop_assert!((centre - P2::new(cx, cy)).norm() <= 1e-9 * scale, "centre {centre:?}");
        prop_assert!((pieces[0].radius().unwrap() - r).abs() <= 1e-9 * scale);
    }

    /// Collinear points give one line.
    #[test]
    fn collinear_points_become_one_line(
        a in proptest::array::uniform3(-100.0..100.0f64), d in proptest::array::uniform3(-1.0..1.0f64),
        ts in proptest::collection::vec(0.001..1.0f64, 2..200),
    ) {
        let d = camkit::geom::V3::from(d);
        prop_assume!(d.norm() > 0.1);
        let mut t = 0.0;
        let pts: Vec<P3> = std::iter::once(0.0).chain(ts.iter().map(|s| { t += s; t })).map(|t| P3::from(a) + d * t).collect();
        let pieces = segment::segment(&pts, &Options { tol: 1e-9, ..Options::default() }, &Exact).unwrap();
        prop_assert_eq!(pieces.len(), 1);
        prop_assert_eq!(pieces[0].shape, Shape::Line);
    }

    /// A table written as G-code and read back keeps every position (to the written decimals)
    /// and every arc centre.
    #[test]
    fn table_to_gcode_to_table_keeps_positions(
        moves in proptest::collection::vec((0u8..4, -500.0..500.0f64, -500.0..500.0f64, -50.0..50.0f64, 0.5..50.0f64), 1..60),
    ) {
        let mut rows = vec![Row::at(0, P3::new(0.0, 0.0, 0.0))];
        for (kind, x, y, z, r) in &moves {
            let prev = rows.last().unwrap().pos;
            let mut row = Row::at(0, P3::new(*x, *y, *z));
            row.mv = match kind { 0 => Move::Rapid, 1 => Move::Line, 2 => Move::Cw, _ => Move::Ccw };
            if row.mv.is_arc() {
                // A centre equidistant from both ends: on the bisector at distance r from the midpoint.
                let (a, b) = (P2::new(prev.x, prev.y), P2::new(*x, *y));
                let chord = b - a;
                prop_assume!(chord.norm() > 1e-3);
                let m = P2::from((a.coords + b.coords) * 0.5);
                row.centre = Some(m + V2::new(-chord.y, chord.x) / chord.norm() * *r);
            }
            row.f = Some(1000.0);
            rows.push(row);
        }
        let table = Table { schema: Schema::default(), rows };
        let text = camkit::gcode::table_to_program(&table, "t", 6).unwrap();
        let program = camkit::gcode::read("t.nc", String::from_utf8(text).unwrap()).unwrap();
        let (back, _) = camkit::gcode::program_to_table(&program);
        prop_assert_eq!(back.rows.len(), table.rows.len());
        for (a, b) in table.rows.iter().zip(&back.rows).skip(1) {
            prop_assert!((a.pos - b.pos).norm() <= 1e-6, "{:?} vs {:?}", a.pos, b.pos);
            prop_assert_eq!(a.mv, b.mv);
            if let (Some(c1), Some(c2)) = (a.centre, b.centre) {
                prop_assert!((c1 - c2).norm() <= 2e-6, "centre {c1:?} vs {c2:?}");
            }
            prop_assert_eq!(b.plane, Plane::Xy);
        }
    }
}
