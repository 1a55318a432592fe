//! Property tests of the tracer against closed forms: for randomly placed spheres, tori, tilted
//! cylinders and NURBS cylinders, random stylus radii and scan directions, every CL point lies at
//! distance r from the surface within the contact tolerance (by the surface's own formula, not
//! the model's query), every chord stays within the chord tolerance of the true CL curve (sampled
//! densely), one-way and zig-zag scans give the same points, and contour levels close. Random
//! closed meshes and analytic composites: every scan line is the stylus's upper envelope as an
//! independent drop gives it.

use camkit::geom::{P3, V3};
use camkit::io::Input;
use camkit::model::Model;
use proptest::prelude::*;
use stylus_trace::coverage::{self, Tolerances};
use stylus_trace::curve::{Steps, Stylus};
use stylus_trace::scan::Scan;
use stylus_trace::two_surface::TwoSurface;
use stylus_trace::{Mode, Options, Region, TracedPath, trace};

const CONTACT: f64 = 1e-4;
const CHORD: f64 = 1e-3;

fn model(json: &str) -> Model {
    Model::load(&Input { name: "m.json".into(), data: json.as_bytes().to_vec() }).expect("a valid model")
}

fn options(r: f64, mode: Mode) -> Options {
    Options {
        stylus: Stylus { radius: r, contact_tol: CONTACT },
        steps: Steps { chord_tol: CHORD, max_step: 2.0, min_step: 1e-4 },
        mode,
    }
}

fn scan(region: Region, angle: f64, pick: f64, zigzag: bool) -> Mode {
    Mode::Scan(Scan { region, angle, pick, zigzag })
}

/// Largest |f(centre)| over the CL points and largest |f| at 15 points inside every chord, for a
/// signed distance f from the true CL surface (the offset of the model by r).
fn off(paths: &[TracedPath], f: impl Fn(&P3) -> f64) -> (f64, f64) {
    let mut at_points: f64 = 0.0;
    let mut on_chords: f64 = 0.0;
    for p in paths {
        for q in &p.points {
            at_points = at_points.max(f(&q.centre).abs());
        }
        for w in p.points.windows(2) {
            for k in 1..16 {
                on_chords = on_chords.max(f(&(w[0].centre + (w[1].centre - w[0].centre) * (k as f64 / 16.0))).abs());
            }
        }
    }
    (at_points, on_chords)
}

fn unit(theta: f64, phi: f64) -> V3 {
    V3::new(phi.sin() * theta.cos(), phi.sin() * theta.sin(), phi.cos())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// A sphere anywhere, any stylus, any scan direction: centres at R + r.
    #[test]
    fn sphere_scan_is_on_the_offset_sphere(
        cx in -20.0..20.0f64, cy in -20.0..20.0f64, cz in -10.0..10.0f64,
        big in 5.0..60.0f64, r in 0.5..8.0f64, angle in 0.0..180.0f64, pick in 3.0..9.0f64,
    ) {
        let m = model(&format!(r#"{{"surfaces": [{{"type": "sphere", "centre": [{cx}, {cy}, {cz}], "radius": {big}}}]}}"#));
        let region = Region { x0: cx - big * 0.8, x1: cx + big * 0.8, y0: cy - big * 0.8, y1: cy + big * 0.8 };
        let paths = trace(&m, &options(r, scan(region, angle, pick, false)), &|| ()).unwrap();
        prop_assert!(!paths.is_empty());
        let c = P3::new(cx, cy, cz);
        let (pts, chords) = off(&paths, |q| (q - c).norm() - (big + r));
        prop_assert!(pts <= CONTACT, "centre off by {}", pts);
        prop_assert!(chords <= CHORD, "chord off by {}", chords);
    }

    /// One-way and zig-zag scans give the same points, every other line reversed.
    #[test]
    fn zigzag_reverses_every_other_line(angle in 0.0..90.0f64, pick in 2.0..6.0f64) {
        let m = model(r#"{"surfaces": [{"type": "torus", "centre": [0, 0, 0], "axis": [0, 0, 1], "major_radius": 20, "minor_radius": 6}]}"#);
        let region = Region { x0: -30.0, x1: 30.0, y0: -30.0, y1: 30.0 };
        let one = trace(&m, &options(2.0, scan(region, angle, pick, false)), &|| ()).unwrap();
        let zig = trace(&m, &options(2.0, scan(region, angle, pick, true)), &|| ()).unwrap();
        let (s, c) = angle.to_radians().sin_cos();
        let d = V3::new(c, s, 0.0);
        let f = |q: &P3| (q.x.hypot(q.y) - 20.0).hypot(q.z) - 8.0;
        for paths in [&one, &zig] {
            let (pts, chords) = off(paths, f);
            prop_assert!(pts <= CONTACT && chords <= CHORD, "torus: {} {}", pts, chords);
        }
        // Directions: every pass of one scan line runs the same way, and the passes of adjacent
        // lines (stations across d one pick apart) run opposite ways.
        let across = V3::new(-s, c, 0.0);
        let mut runs: std::collections::BTreeMap<i64, Vec<f64>> = Default::default();
        for p in &zig {
            let line = (p.points[0].centre.coords.dot(&across) / pick).round() as i64;
            let run = (p.points[p.points.len() - 1].centre - p.points[0].centre).dot(&d);
            runs.entry(line).or_default().push(run.signum());
        }
        prop_assert!(runs.len() > 5);
        for (k, signs) in &runs {
            prop_assert!(signs.iter().all(|s| *s == signs[0]), "line {} runs both ways", k);
            if let Some(next) = runs.get(&(k + 1)) {
                prop_assert!(next[0] == -signs[0], "lines {} and {} run the same way", k, k + 1);
            }
        }
        for p in &one {
            prop_assert!((p.points[p.points.len() - 1].centre - p.points[0].centre).dot(&d) > 0.0);
        }
    }

    /// A cylinder placed at any tilt, and the same cylinder as an exact NURBS: centres at R + r.
    #[test]
    fn tilted_and_nurbs_cylinders_are_on_the_offset_cylinder(
        theta in 0.0..std::f64::consts::TAU, tilt in 0.0..0.3f64, big in 8.0..30.0f64, r in 0.5..5.0f64, angle in 0.0..180.0f64,
    ) {
        // Analytic: axis nearly horizontal, through the origin.
        let axis = V3::new(theta.cos() * tilt.cos(), theta.sin() * tilt.cos(), tilt.sin());
        let m = model(&format!(
            r#"{{"surfaces": [{{"type": "cylinder", "point": [0, 0, 0], "axis": [{}, {}, {}], "radius": {big}, "length": [-25, 25]}}]}}"#,
            axis.x, axis.y, axis.z
        ));
        let region = Region { x0: -15.0, x1: 15.0, y0: -15.0, y1: 15.0 };
        let paths = trace(&m, &options(r, scan(region, angle, 5.0, true)), &|| ()).unwrap();
        // The exact distance to the open tube (lateral surface, or its rim beyond the ends), less
        // r: inside the tube and over its rims too.
        let f = |q: &P3| {
            let h = q.coords.dot(&axis);
            let rho = (q.coords - axis * h).norm();
            (rho - big).hypot((h.abs() - 25.0).max(0.0)) - r
        };
        let (pts, chords) = off(&paths, f);
        prop_assert!(pts <= CONTACT && chords <= CHORD, "cylinder: {} {}", pts, chords);
        // NURBS: half a cylinder about y, rational quadratic quarters, rotated about z by theta.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let row = |y: f64| format!("[[{big}, {y}, 0], [{big}, {y}, {big}], [0, {y}, {big}], [-{big}, {y}, {big}], [-{big}, {y}, 0]]");
        let m = model(&format!(
            r#"{{"surfaces": [{{"type": "bspline", "degree": [1, 2], "control_points": [{}, {}],
                "weights": [[1, {h}, 1, {h}, 1], [1, {h}, 1, {h}, 1]], "knots_v": [0, 0, 0, 0.5, 0.5, 1, 1, 1],
                "placement": {{"axis": [0, 0, 1], "angle": {}}}}}]}}"#,
            row(-25.0), row(25.0), theta.to_degrees()
        ));
        let paths = trace(&m, &options(r, scan(region, angle, 5.0, false)), &|| ()).unwrap();
        // In the patch's own frame: radial distance over the half above z = 0, else the distance
        // to its straight edges (x = ±R, z = 0), less r.
        let f = |q: &P3| {
            let xl = q.x * theta.cos() + q.y * theta.sin();
            if q.z >= 0.0 { xl.hypot(q.z) - (big + r) } else { (xl.abs() - big).hypot(q.z) - r }
        };
        let (pts, chords) = off(&paths, f);
        prop_assert!(pts <= CONTACT && chords <= CHORD, "NURBS cylinder: {} {}", pts, chords);
    }

    /// Contour levels on a torus with a tilted axis: every level's loops close on the offset torus.
    /// Levels fall anywhere through the tube, also just under the tilted tube's top ridge or over
    /// its bottom one, where the offset surface is nearly horizontal and the correction in the
    /// level has little slope to work with.
    #[test]
    fn contour_levels_close_on_the_offset_torus(
        theta in 0.0..std::f64::consts::TAU, phi in 0.0..0.4f64, r in 0.5..4.0f64, z in -8.0..8.0f64,
    ) {
        let axis = unit(theta, phi);
        let m = model(&format!(
            r#"{{"surfaces": [{{"type": "torus", "centre": [0, 0, 0], "axis": [{}, {}, {}], "major_radius": 25, "minor_radius": 7}}]}}"#,
            axis.x, axis.y, axis.z
        ));
        let region = Region { x0: -40.0, x1: 40.0, y0: -40.0, y1: 40.0 };
        let paths = trace(&m, &options(r, Mode::Contour { region, levels: vec![z, z * 0.5 - 1.0] }), &|| ()).unwrap();
        prop_assert!(paths.len() >= 2);
        let f = |q: &P3| {
            let h = q.coords.dot(&axis);
            let rho = (q.coords - axis * h).norm();
            (rho - 25.0).hypot(h) - (7.0 + r)
        };
        let (pts, chords) = off(&paths, f);
        prop_assert!(pts <= CONTACT && chords <= CHORD, "torus: {} {}", pts, chords);
        for p in &paths {
            prop_assert!(p.points.iter().all(|q| (q.centre.z - p.points[0].centre.z).abs() < 1e-12), "a level stays level");
            prop_assert_eq!(p.points[0].centre, p.points[p.points.len() - 1].centre);
        }
    }

    /// Two-surface contact on a ball resting on a tilted plane: the Newton correction in XY and Z
    /// converges onto the circle where the stylus is r from the plane and R + r from the ball's
    /// centre (radius 2·sqrt(R·r) about the ball's foot), and the line closes.
    #[test]
    fn two_surface_converges_on_a_ball_resting_on_a_tilted_plane(
        theta in 0.0..std::f64::consts::TAU, phi in 0.0..0.5f64, big in 5.0..30.0f64, r in 0.5..4.0f64,
    ) {
        let n = unit(theta, phi);
        let s = P3::from(n * big);
        let m = model(&format!(
            r#"{{"surfaces": [{{"type": "plane", "point": [0, 0, 0], "normal": [{}, {}, {}]}},
                             {{"type": "sphere", "centre": [{}, {}, {}], "radius": {big}}}]}}"#,
            n.x, n.y, n.z, s.x, s.y, s.z
        ));
        let e = n.cross(&V3::z()).try_normalize(1e-9).unwrap_or(V3::x());
        let rho = 2.0 * (big * r).sqrt();
        let start = P3::from(n * r) + e * rho;
        let reach = big + rho + 10.0;
        let ts = TwoSurface {
            surfaces: [0, 1],
            start: Some(start),
            reverse: false,
            region: Region { x0: -reach, x1: reach, y0: -reach, y1: reach },
        };
        let paths = trace(&m, &options(r, Mode::TwoSurface(ts)), &|| ()).unwrap();
        prop_assert_eq!(paths.len(), 1);
        let pts = &paths[0].points;
        prop_assert!(pts.len() > 8);
        prop_assert_eq!(pts[0].centre, pts[pts.len() - 1].centre, "the line closes");
        for q in pts {
            prop_assert!((q.centre.coords.dot(&n) - r).abs() <= CONTACT, "plane: {}", q.centre.coords.dot(&n) - r);
            prop_assert!(((q.centre - s).norm() - (big + r)).abs() <= CONTACT, "ball: {}", (q.centre - s).norm() - (big + r));
            prop_assert!(q.second.is_some());
        }
        // Chords of the circle (in its plane, radius rho about the ball's foot) within 1 µm.
        let (_, chords) = off(&paths, |q| {
            let v = q - P3::from(n * r);
            (v - n * v.dot(&n)).norm() - rho
        });
        prop_assert!(chords <= CHORD, "chord off by {}", chords);
    }
}

/// Every scan line against the independent drop ([`stylus_trace::envelope`]): no stretch with
/// the model under it left uncovered beyond the chord tolerance, no CL point below the envelope.
fn assert_lines_cover(m: &Model, opts: &Options) -> Result<(), TestCaseError> {
    let Mode::Scan(s) = &opts.mode else { unreachable!("a scan") };
    let paths = trace(m, opts, &|| ()).map_err(|f| TestCaseError::fail(format!("{f:?}")))?;
    let tol = Tolerances {
        gap: CHORD,
        below: CONTACT,
        chord: CHORD + CONTACT,
        spacing: stylus_trace::scan::sample_spacing(&opts.stylus, &opts.steps),
    };
    let c = coverage::check(m, opts.stylus.radius, s, &paths, &tol, &|v| v);
    prop_assert!(c.defects.is_empty(), "{:?}", &c.defects[..c.defects.len().min(3)]);
    prop_assert!(c.largest_gap <= CHORD && c.points_below == 0 && c.chords_below == 0, "{:?}", c);
    Ok(())
}

/// A closed block whose top is a random height field on a coarse grid over [0, 40]², sides and
/// bottom flat, and a closed box floating over part of it.
fn block_and_box(heights: &[f64], n: usize, boxed: [f64; 4]) -> Vec<[P3; 3]> {
    let step = 40.0 / n as f64;
    let top = |i: usize, j: usize| P3::new(i as f64 * step, j as f64 * step, heights[j * (n + 1) + i]);
    let bot = |i: usize, j: usize| P3::new(i as f64 * step, j as f64 * step, -5.0);
    let mut t = Vec::new();
    let mut quad = |a: P3, b: P3, c: P3, d: P3| {
        t.push([a, b, c]);
        t.push([a, c, d]);
    };
    for i in 0..n {
        for j in 0..n {
            quad(top(i, j), top(i + 1, j), top(i + 1, j + 1), top(i, j + 1));
            quad(bot(i, j), bot(i, j + 1), bot(i + 1, j + 1), bot(i + 1, j));
        }
        quad(bot(i, 0), bot(i + 1, 0), top(i + 1, 0), top(i, 0));
        quad(bot(i + 1, n), bot(i, n), top(i, n), top(i + 1, n));
        quad(bot(0, i + 1), bot(0, i), top(0, i), top(0, i + 1));
        quad(bot(n, i), bot(n, i + 1), top(n, i + 1), top(n, i));
    }
    let [x, y, z, s] = boxed;
    let p = |a: f64, b: f64, c: f64| P3::new(x + a * s, y + b * s * 0.6, z + c * 3.0);
    let v = [
        p(0., 0., 0.),
        p(1., 0., 0.),
        p(1., 1., 0.),
        p(0., 1., 0.),
        p(0., 0., 1.),
        p(1., 0., 1.),
        p(1., 1., 1.),
        p(0., 1., 1.),
    ];
    for [a, b, c, d] in [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]] {
        quad(v[a], v[b], v[c], v[d]);
    }
    t
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random closed meshes (a height-field block and a box floating over it, so lines meet
    /// steps, overhangs and jumps of the envelope): every scan line is the envelope.
    #[test]
    fn mesh_scan_lines_are_the_envelope(
        heights in proptest::collection::vec(0.0..8.0f64, 36),
        bx in 0.0..30.0f64, by in 0.0..30.0f64, bz in 6.0..20.0f64, bs in 4.0..14.0f64,
        r in 0.8..5.0f64, angle in 0.0..180.0f64, pick in 2.5..6.0f64,
    ) {
        let tris = block_and_box(&heights, 5, [bx, by, bz, bs]);
        let m = Model::load(&Input { name: "m.stl".into(), data: camkit::model::mesh::binary_stl(&tris) }).unwrap();
        let region = Region { x0: -3.0, x1: 43.0, y0: -3.0, y1: 43.0 };
        assert_lines_cover(&m, &options(r, scan(region, angle, pick, false)))?;
    }

    /// A floor, spheres resting on it or floating over it, and a finite cylinder lying across:
    /// every scan line is the envelope.
    #[test]
    fn analytic_composite_scan_lines_are_the_envelope(
        balls in proptest::collection::vec((-20.0..20.0f64, -20.0..20.0f64, 0.0..25.0f64, 2.0..9.0f64), 1..4),
        theta in 0.0..std::f64::consts::PI, cz in 3.0..15.0f64, rho in 0.5..4.0f64,
        r in 0.8..6.0f64, angle in 0.0..180.0f64, pick in 2.0..5.0f64,
    ) {
        let mut surfaces = vec![r#"{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}"#.to_string()];
        for (x, y, z, big) in balls {
            surfaces.push(format!(r#"{{"type": "sphere", "centre": [{x}, {y}, {}], "radius": {big}}}"#, z + big));
        }
        surfaces.push(format!(
            r#"{{"type": "cylinder", "point": [0, 0, {cz}], "axis": [{}, {}, 0], "radius": {rho}, "length": [-15, 15]}}"#,
            theta.cos(), theta.sin()
        ));
        let m = model(&format!(r#"{{"surfaces": [{}]}}"#, surfaces.join(",")));
        let region = Region { x0: -25.0, x1: 25.0, y0: -25.0, y1: 25.0 };
        assert_lines_cover(&m, &options(r, scan(region, angle, pick, false)))?;
    }
}
