//! Property tests of the tracer against closed forms: for randomly placed spheres, tori, tilted
//! cylinders and NURBS cylinders, random stylus radii and scan directions, every CL point lies at
//! distance r from the surface within the contact tolerance (by the surface's own formula, not
//! the model's query), every chord stays within the chord tolerance of the true CL curve (sampled
//! densely), one-way and zig-zag scans give the same points, and contour levels close.

use camkit::geom::{P3, V3};
use camkit::io::Input;
use camkit::model::Model;
use proptest::prelude::*;
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
