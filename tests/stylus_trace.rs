//! End-to-end tests of `stylus-trace`: CL points measured against closed forms and independent
//! brute-force distances, the chord tolerance checked densely, the demo models traced, the same
//! output for any thread count, and bad input refused with one clear line and no output file.

use camkit::geom::{P3, V3};
use e2e::{Work, data};

const BIN: &str = "stylus-trace";
/// The contact tolerance promised by default (0.1 µm).
const CONTACT: f64 = 1e-4;

/// One CL row: centre, contact, normal, path, and the second contact if any.
#[derive(Debug)]
struct Cl {
    path: i64,
    c: P3,
    p: P3,
    n: V3,
    p2: Option<P3>,
}

fn rows(csv: &str) -> Vec<Cl> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let (path, x, px, nx) = (col("path"), col("x"), col("px"), col("nx"));
    let p2x = header.iter().position(|h| *h == "p2x");
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let num = |i: usize| f[i].parse::<f64>().unwrap_or_else(|_| panic!("number in {l}"));
            let p3 = |i: usize| P3::new(num(i), num(i + 1), num(i + 2));
            Cl {
                path: f[path].parse().unwrap(),
                c: p3(x),
                p: p3(px),
                n: p3(nx).coords,
                p2: p2x.filter(|&i| !f[i].is_empty()).map(p3),
            }
        })
        .collect()
}

fn report(w: &Work, name: &str) -> serde_json::Value {
    serde_json::from_str(&w.read(name)).expect("report is JSON")
}

/// Traces `model` (a JSON text) with `args`; returns the CL rows and the report.
fn trace(w: &Work, model: &str, args: &[&str]) -> (Vec<Cl>, serde_json::Value) {
    w.write("model.json", model);
    let mut all = vec!["model.json", "-o", "cl.csv", "--report", "r.json"];
    all.extend_from_slice(args);
    w.run(BIN, &all, b"").ok();
    (rows(&w.read("cl.csv")), report(w, "r.json"))
}

/// Largest distance from the chords of each path to a CL curve given by its distance function,
/// sampled 16 times per chord.
fn chord_deviation(cl: &[Cl], off_curve: impl Fn(&P3) -> f64) -> f64 {
    let mut worst: f64 = 0.0;
    for w in cl.windows(2).filter(|w| w[0].path == w[1].path) {
        for k in 1..16 {
            let m = w[0].c + (w[1].c - w[0].c) * (k as f64 / 16.0);
            worst = worst.max(off_curve(&m));
        }
    }
    worst
}

#[test]
fn sphere_r500_scan_is_exact_to_a_tenth_of_a_micron() {
    let w = Work::new();
    let model = std::fs::read_to_string(data("stylus-trace/sphere-smoothing.json")).unwrap();
    let (cl, r) = trace(&w, &model, &["-r", "12.5", "--region", "-50,50,-50,50", "--pick", "1"]);
    let centre = P3::new(0.0, 0.0, -500.0);
    let worst = cl.iter().map(|q| ((q.c - centre).norm() - 512.5).abs()).fold(0.0, f64::max);
    assert!(worst <= CONTACT, "centre off the offset sphere by {worst}");
    // Contact on the sphere, normal along the radius.
    for q in &cl {
        assert!(((q.p - centre).norm() - 500.0).abs() < 1e-9);
        assert!((q.n - (q.c - q.p) / 12.5).norm() < 1e-6);
    }
    // 101 scan lines of y = const, from x = −50 to 50, as the region says.
    assert_eq!(r["paths"], 101);
    let ys: std::collections::BTreeSet<i64> = cl.iter().map(|q| (q.c.y * 1e6).round() as i64).collect();
    assert_eq!(ys.len(), 101);
    for path in 0..101 {
        let line: Vec<&Cl> = cl.iter().filter(|q| q.path == path).collect();
        assert_eq!((line[0].c.x, line[line.len() - 1].c.x), (-50.0, 50.0));
    }
    // The chord tolerance against the true CL curve (the offset circle in each plane y = const).
    let dev = chord_deviation(&cl, |m| {
        let rho = (512.5f64.powi(2) - m.y * m.y).sqrt();
        (m.x.hypot(m.z + 500.0) - rho).abs()
    });
    assert!(dev <= 0.001, "chord deviation {dev}");
    assert!(r["largest_residual_mm"].as_f64().unwrap() <= CONTACT);
    assert!(r["min_clearance_mm"].as_f64().unwrap() >= -CONTACT);
}

/// Distance from a point to a cone's lateral surface (apex at the origin, axis z, half angle a,
/// heights 0..h), by its own formula: the point's half-plane and the generator segment.
fn cone_distance(q: &P3, a: f64, h: f64) -> f64 {
    let (rho, z) = (q.x.hypot(q.y), q.z);
    let g = V3::new(a.sin(), 0.0, a.cos());
    let t = (rho * g.x + z * g.z).clamp(0.0, h / a.cos());
    ((rho - t * g.x).powi(2) + (z - t * g.z).powi(2)).sqrt()
}

#[test]
fn plane_cylinder_cone_and_torus_are_traced_at_distance_r() {
    let w = Work::new();
    let r = 3.0;
    // A tilted plane: every centre is r above it.
    let (cl, _) = trace(
        &w,
        r#"{"surfaces": [{"type": "plane", "point": [0, 0, 1], "normal": [0.2, -0.1, 1]}]}"#,
        &["-r", "3", "--region", "0,40,0,20", "--pick", "5", "--zigzag"],
    );
    let n = V3::new(0.2, -0.1, 1.0).normalize();
    for q in &cl {
        assert!(((q.c - P3::new(0.0, 0.0, 1.0)).dot(&n) - r).abs() <= CONTACT);
    }
    // A plane needs only the longest steps (2 mm, after 0.5 and 1 to start): 5 lines of 40 mm.
    assert!(cl.len() <= 5 * 23, "{} points", cl.len());
    // A horizontal cylinder along x, scanned across its axis.
    let (cl, _) = trace(
        &w,
        r#"{"surfaces": [{"type": "cylinder", "point": [0, 0, 0], "axis": [1, 0, 0], "radius": 20, "length": [0, 30]}]}"#,
        &["-r", "3", "--region", "0,30,-15,15", "--angle", "90", "--pick", "3"],
    );
    let worst = cl.iter().map(|q| (q.c.y.hypot(q.c.z) - 23.0).abs()).fold(0.0, f64::max);
    assert!(worst <= CONTACT, "cylinder: {worst}");
    let dev = chord_deviation(&cl, |m| (m.y.hypot(m.z) - 23.0).abs());
    assert!(dev <= 0.001, "cylinder chord deviation {dev}");
    // A cone standing on its apex opening upwards, scanned over its rim and into it.
    let (cl, _) = trace(
        &w,
        r#"{"surfaces": [{"type": "cone", "apex": [0, 0, 0], "axis": [0, 0, 1], "half_angle": 40, "length": [0, 20]}]}"#,
        &["-r", "3", "--region", "-10,10,-10,10", "--pick", "4"],
    );
    let worst = cl.iter().map(|q| (cone_distance(&q.c, 40f64.to_radians(), 20.0) - r).abs()).fold(0.0, f64::max);
    assert!(worst <= CONTACT, "cone: {worst}");
    // A torus at three contour levels: every centre 8 + r from the tube's circle.
    let (cl, rep) = trace(
        &w,
        r#"{"surfaces": [{"type": "torus", "centre": [0, 0, 0], "axis": [0, 0, 1], "major_radius": 30, "minor_radius": 8}]}"#,
        &["-r", "3", "--mode", "contour", "--levels", "-6,0,6"],
    );
    let worst = cl.iter().map(|q| ((q.c.x.hypot(q.c.y) - 30.0).hypot(q.c.z) - 11.0).abs()).fold(0.0, f64::max);
    assert!(worst <= CONTACT, "torus: {worst}");
    assert_eq!(rep["paths"], 6, "outer and inner loop at each level");
    for path in 0..6 {
        let l: Vec<&Cl> = cl.iter().filter(|q| q.path == path).collect();
        assert_eq!(l[0].c, l[l.len() - 1].c, "loops close");
    }
    let dev = chord_deviation(&cl, |m| ((m.x.hypot(m.y) - 30.0).hypot(m.z) - 11.0).abs());
    assert!(dev <= 0.001, "torus chord deviation {dev}");
}

#[test]
fn two_surface_on_a_sphere_resting_on_a_plane() {
    let w = Work::new();
    // A ball of R 10 on the floor: the stylus touching both runs round a circle of radius
    // 2·sqrt(R·r) at height r.
    let (cl, rep) = trace(
        &w,
        r#"{"surfaces": [{"type": "plane", "name": "floor", "point": [0,0,0], "normal": [0,0,1]},
                         {"type": "sphere", "name": "ball", "centre": [0,0,10], "radius": 10}]}"#,
        &["-r", "2", "--mode", "two-surface", "--region", "-20,20,-20,20"],
    );
    assert_eq!(rep["paths"], 1);
    let expect = 2.0 * (10.0f64 * 2.0).sqrt();
    for q in &cl {
        assert!((q.c.z - 2.0).abs() <= CONTACT);
        assert!(((q.c - P3::new(0.0, 0.0, 10.0)).norm() - 12.0).abs() <= CONTACT);
        assert!((q.c.x.hypot(q.c.y) - expect).abs() <= 1e-3);
        assert!(q.p2.is_some());
    }
    assert_eq!(cl[0].c, cl[cl.len() - 1].c, "the line closes");
    let dev = chord_deviation(&cl, |m| (m.x.hypot(m.y) - expect).abs().max((m.z - 2.0).abs()));
    assert!(dev <= 0.001, "chord deviation {dev}");
}

#[test]
fn concave_remainder_touches_free_form_and_sphere_within_a_tenth_of_a_micron() {
    let w = Work::new();
    let model = data("stylus-trace/concave-remainder.json");
    let out = w.run(
        BIN,
        &[
            model.to_str().unwrap(),
            "--mode",
            "two-surface",
            "-r",
            "1",
            "-o",
            "cl.csv",
            "--report",
            "r.json",
            "--svg",
            "cl.svg",
        ],
        b"",
    );
    out.ok();
    let cl = rows(&w.read("cl.csv"));
    assert!(cl.len() > 100);
    assert_eq!(cl[0].c, cl[cl.len() - 1].c, "the concave line round the sphere closes");
    let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    let net: Vec<Vec<P3>> = doc["surfaces"][0]["control_points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|row| {
            row.as_array()
                .unwrap()
                .iter()
                .map(|p| P3::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap(), p[2].as_f64().unwrap()))
                .collect()
        })
        .collect();
    let patch = camkit::model::patch::BSpline::new(&net, [3, 3], None, None);
    for q in cl.iter().step_by(cl.len() / 20) {
        // Sphere: closed form.
        assert!(((q.c - P3::new(50.0, 50.0, 16.0)).norm() - 26.0).abs() <= CONTACT);
        // Free-form: nested grid search on the patch (no Newton), refined to 1e-9 in u, v.
        let mut best = (0.5, 0.5, f64::INFINITY);
        let mut span = 0.5;
        for _ in 0..8 {
            let (cu, cv) = (best.0, best.1);
            for i in -10..=10 {
                for j in -10..=10 {
                    let (u, v) =
                        ((cu + span * i as f64 / 10.0).clamp(0.0, 1.0), (cv + span * j as f64 / 10.0).clamp(0.0, 1.0));
                    let d = (patch.eval(u, v).s - q.c).norm();
                    if d < best.2 {
                        best = (u, v, d);
                    }
                }
            }
            span /= 8.0;
        }
        assert!((best.2 - 1.0).abs() <= CONTACT, "free-form distance {} at {}", best.2, q.c);
        assert!(q.p2.is_some());
    }
    let svg = w.read("cl.svg");
    assert!(svg.starts_with("<svg") || svg.starts_with("<?xml"), "an SVG");
}

#[test]
fn bezier_paraboloid_scan_keeps_r_by_grid_search() {
    // z = (x² + y²)/40 over [−20, 20]² exactly, as a biquadratic Bézier patch: x and y are
    // linear in u and v, z = a_i + a_j with a = (10, −10, 10).
    let a = [10.0, -10.0, 10.0];
    let net: Vec<String> = (0..3)
        .map(|i| {
            let row: Vec<String> =
                (0..3).map(|j| format!("[{}, {}, {}]", 20 * i as i64 - 20, 20 * j as i64 - 20, a[i] + a[j])).collect();
            format!("[{}]", row.join(", "))
        })
        .collect();
    let w = Work::new();
    let (cl, rep) = trace(
        &w,
        &format!(r#"{{"surfaces": [{{"type": "bezier", "control_points": [{}]}}]}}"#, net.join(", ")),
        &["-r", "4", "--region", "-15,15,-15,15", "--pick", "5", "--angle", "20", "--zigzag"],
    );
    assert!(cl.len() > 50 && rep["paths"].as_u64().unwrap() >= 6);
    // Independent distance: nested grid search over (x, y) on the explicit surface.
    let dist = |q: &P3| {
        let f = |x: f64, y: f64| (q - P3::new(x, y, (x * x + y * y) / 40.0)).norm();
        let (mut bx, mut by, mut best) = (0.0, 0.0, f64::INFINITY);
        let mut span = 20.0;
        for _ in 0..9 {
            let (cx, cy) = (bx, by);
            for i in -10..=10 {
                for j in -10..=10 {
                    let (x, y) = (
                        (cx + span * i as f64 / 10.0).clamp(-20.0, 20.0),
                        (cy + span * j as f64 / 10.0).clamp(-20.0, 20.0),
                    );
                    let d = f(x, y);
                    if d < best {
                        (bx, by, best) = (x, y, d);
                    }
                }
            }
            span /= 8.0;
        }
        best
    };
    let worst = cl.iter().map(|q| (dist(&q.c) - 4.0).abs()).fold(0.0, f64::max);
    assert!(worst <= CONTACT, "a CL point is {worst} mm off r from the paraboloid");
}

/// Distance from `q` to triangle abc, by projection and edges (independent of camkit's).
fn triangle_distance(q: &P3, a: &P3, b: &P3, c: &P3) -> f64 {
    let n = (b - a).cross(&(c - a)).normalize();
    let foot = q - n * (q - a).dot(&n);
    let inside = [(a, b), (b, c), (c, a)].iter().all(|(s, e)| (*e - *s).cross(&(foot - *s)).dot(&n) >= 0.0);
    if inside {
        return (q - a).dot(&n).abs();
    }
    [(a, b), (b, c), (c, a)]
        .iter()
        .map(|(s, e)| camkit::geom::dist::point_segment(q, s, e))
        .fold(f64::INFINITY, f64::min)
}

/// A wavy height field with a steep ridge, 2 × 24 × 24 triangles over 60 × 60 mm.
fn wave() -> Vec<[P3; 3]> {
    let f = |i: usize, j: usize| {
        let (x, y) = (i as f64 * 2.5, j as f64 * 2.5);
        P3::new(x, y, 4.0 * (x / 9.0).sin() * (y / 13.0).cos() + if (25.0..35.0).contains(&x) { 6.0 } else { 0.0 })
    };
    let mut tris = Vec::new();
    for i in 0..24 {
        for j in 0..24 {
            tris.push([f(i, j), f(i + 1, j), f(i + 1, j + 1)]);
            tris.push([f(i, j), f(i + 1, j + 1), f(i, j + 1)]);
        }
    }
    tris
}

/// The triangles as the STL stores them (f32 corners).
fn as_f32(tris: &[[P3; 3]]) -> Vec<[P3; 3]> {
    let f = |p: &P3| P3::new(p.x as f32 as f64, p.y as f32 as f64, p.z as f32 as f64);
    tris.iter().map(|t| [f(&t[0]), f(&t[1]), f(&t[2])]).collect()
}

/// Distance from `q` to the nearest of `tris`, by brute force.
fn mesh_distance(q: &P3, tris: &[[P3; 3]]) -> f64 {
    tris.iter().map(|[a, b, c]| triangle_distance(q, a, b, c)).fold(f64::INFINITY, f64::min)
}

#[test]
fn ascii_stl_contours_at_several_levels_keep_r_from_the_mesh() {
    let tris = as_f32(&wave());
    // The same f32 corners as ASCII STL (shortest round-trip decimals).
    let mut text = String::from("solid wave\n");
    for t in &tris {
        text.push_str("facet normal 0 0 0\n outer loop\n");
        for p in t {
            text.push_str(&format!("  vertex {} {} {}\n", p.x as f32, p.y as f32, p.z as f32));
        }
        text.push_str(" endloop\nendfacet\n");
    }
    text.push_str("endsolid wave\n");
    let w = Work::new();
    w.write("wave.stl", &text);
    let binary = Work::new();
    binary.write("wave.stl", camkit::model::mesh::binary_stl(&tris));
    // Read as ASCII, the mesh gives the same scan as the binary file of the same corners.
    for at in [&w, &binary] {
        at.run(BIN, &["wave.stl", "-r", "2", "--pick", "6", "--zigzag", "-o", "scan.csv"], b"").ok();
    }
    let (ascii_scan, binary_scan) = (w.read("scan.csv"), binary.read("scan.csv"));
    assert!(ascii_scan.lines().count() > 100 && ascii_scan == binary_scan, "ASCII and binary STL scans differ");
    // Contour levels every 1.5 mm from the top down, inside the field.
    w.run(
        BIN,
        &["wave.stl", "-r", "2", "--mode", "contour", "--z-step", "1.5", "--region", "5,55,5,55", "-o", "cl.csv"],
        b"",
    )
    .ok();
    let cl = rows(&w.read("cl.csv"));
    let levels: std::collections::BTreeSet<i64> = cl.iter().map(|q| (q.c.z * 1e6).round() as i64).collect();
    assert!(levels.len() >= 4, "{} levels", levels.len());
    for path in 0..=cl.last().unwrap().path {
        let l: Vec<&Cl> = cl.iter().filter(|q| q.path == path).collect();
        assert!(l.iter().all(|q| q.c.z == l[0].c.z), "a contour stays at its level");
    }
    let worst = cl.iter().map(|q| (mesh_distance(&q.c, &tris) - 2.0).abs()).fold(0.0, f64::max);
    assert!(worst <= CONTACT, "a contour point is {worst} mm off r from the mesh");
}

#[test]
fn mesh_scan_never_comes_closer_than_r_by_brute_force() {
    let tris = wave();
    let w = Work::new();
    w.write("wave.stl", camkit::model::mesh::binary_stl(&tris));
    w.run(BIN, &["wave.stl", "-r", "2.5", "--pick", "3", "--angle", "30", "-o", "cl.csv", "--report", "r.json"], b"")
        .ok();
    let cl = rows(&w.read("cl.csv"));
    assert!(cl.len() > 300);
    let stored = as_f32(&tris);
    let worst_in = cl.iter().map(|q| (mesh_distance(&q.c, &stored) - 2.5).abs()).fold(0.0, f64::max);
    assert!(worst_in <= CONTACT, "a CL point is {worst_in} mm off r from the mesh");
    // Inside every chord, | distance to the mesh − r | is a lower bound of the distance to the
    // true CL curve (distance is 1-Lipschitz): it must stay within the chord tolerance.
    let mut worst_chord: f64 = 0.0;
    for q in cl.windows(2).filter(|q| q[0].path == q[1].path) {
        for f in [0.25, 0.5, 0.75] {
            let m = q[0].c + (q[1].c - q[0].c) * f;
            worst_chord = worst_chord.max((mesh_distance(&m, &stored) - 2.5).abs());
        }
    }
    assert!(worst_chord <= 0.001, "a chord strays {worst_chord} mm from the CL curve");
    assert_eq!(report(&w, "r.json")["triangles"], 1152);
}

#[test]
fn output_is_the_same_for_any_thread_count() {
    let w = Work::new();
    let model = data("stylus-trace/concave-remainder.json");
    let m = model.to_str().unwrap();
    w.run(BIN, &[m, "-r", "2", "--pick", "4", "--zigzag", "--threads", "1", "-o", "one.csv"], b"").ok();
    w.run(BIN, &[m, "-r", "2", "--pick", "4", "--zigzag", "--threads", "2", "-o", "two.csv"], b"").ok();
    assert_eq!(w.read("one.csv"), w.read("two.csv"));
    // And the composite model is traced without penetrating either surface.
    let cl = rows(&w.read("one.csv"));
    for q in &cl {
        assert!((q.c - P3::new(50.0, 50.0, 16.0)).norm() >= 27.0 - CONTACT);
    }
}

#[test]
fn bad_input_gets_one_clear_line_and_no_output() {
    let w = Work::new();
    let run = |model: &str, args: &[&str]| {
        w.write("m.json", model);
        let mut all = vec!["m.json", "-o", "out.csv"];
        all.extend_from_slice(args);
        let out = w.run(BIN, &all, b"");
        assert!(!w.exists("out.csv"), "no output file after a failure");
        out
    };
    let sphere = r#"{"surfaces": [{"type": "sphere", "centre": [0,0,0], "radius": 10}]}"#;
    run(r#"{"surfaces": [{"type": "sphear", "centre": [0,0,0], "radius": 10}]}"#, &["-r", "1"])
        .fails(2, "m.json:1:31 (surfaces[0].type): unknown variant `sphear`");
    run(r#"{"surfaces": [{"type": "sphere", "centre": [0,0,0]}]}"#, &["-r", "1"]).fails(2, "missing field `radius`");
    run(
        r#"{"surfaces": [{"type": "cone", "apex": [0,0,0], "axis": [0,0,0], "half_angle": 30, "length": [0,1]}]}"#,
        &["-r", "1"],
    )
    .fails(2, "(surfaces[0].axis): axis must be a non-zero direction");
    run(
        r#"{"surfaces": [{"type": "bspline", "degree": [1, 1], "weights": [[1, 1], [-1, 1]],
            "control_points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]]}]}"#,
        &["-r", "1"],
    )
    .fails(2, "(surfaces[0].weights[1][0]): a weight must be a positive number, got -1");
    run(sphere, &["-r", "0"]).fails(2, "--radius must be a positive number");
    run(sphere, &["-r", "-2"]).fails(2, "--radius must be a positive number");
    run(sphere, &["-r", "1", "--region", "100,200,100,200"]).fails(2, "misses the model");
    run(r#"{"surfaces": [{"type": "plane", "point": [0,0,0], "normal": [0,0,1]}]}"#, &["-r", "1"])
        .fails(2, "the model is unbounded");
    run(sphere, &["-r", "1", "--mode", "contour"]).fails(2, "contour mode needs --levels");
    run(sphere, &["-r", "1", "--mode", "two-surface"]).fails(2, "two-surface mode needs --surfaces");
    // A step that cannot hold the chord tolerance: the stylus stops, a failed check (exit 1).
    run(
        sphere,
        &["-r", "1", "--mode", "contour", "--levels", "0", "--min-step", "1", "--max-step", "2", "--chord-tol", "1e-6"],
    )
    .fails(1, "the stylus stopped at");
    // STL files: empty, truncated, degenerate.
    let tri = [P3::new(0.0, 0.0, 0.0), P3::new(1.0, 0.0, 0.0), P3::new(0.0, 1.0, 0.0)];
    let good = camkit::model::mesh::binary_stl(&[tri]);
    w.write("empty.stl", b"");
    w.write("cut.stl", &good[..good.len() - 10]);
    w.write("flat.stl", camkit::model::mesh::binary_stl(&[tri, [tri[0], tri[1], P3::new(2.0, 0.0, 0.0)]]));
    let stl = |name: &str| {
        let out = w.run(BIN, &[name, "-r", "1", "-o", "out.csv"], b"");
        assert!(!w.exists("out.csv"));
        out
    };
    stl("empty.stl").fails(2, "empty.stl: empty STL file");
    stl("cut.stl").fails(2, "cut.stl: truncated binary STL");
    stl("flat.stl").fails(2, "flat.stl (facet 2): degenerate triangle");
    run(r#"{"surfaces": [{"type": "stl", "file": "missing.stl"}]}"#, &["-r", "1"]).fails(2, "(surfaces[0].file)");
}
