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

// Scan coverage (issue 23): every scan line is the stylus's upper envelope over the model, as
// an independent drop gives it, wherever the model is under the line.

/// Corners of an STL file as the filter reads them (f32).
fn stl_corners(path: &std::path::Path) -> Vec<[P3; 3]> {
    let data = std::fs::read(path).unwrap();
    camkit::model::mesh::read_stl(&camkit::io::Input { name: "m.stl".into(), data }).unwrap()
}

/// Highest centre z over (x, y) where a ball of radius r touches one of `tris`, by brute force:
/// facets (foot inside), edges (foot inside) and corners of every triangle.
fn drop_on_mesh(tris: &[[P3; 3]], x: f64, y: f64, r: f64) -> Option<f64> {
    let mut best: Option<f64> = None;
    let mut take = |z: f64| best = Some(best.map_or(z, |b: f64| b.max(z)));
    for t in tris {
        let mut n = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
        if n.z < 0.0 {
            n = -n;
        }
        if n.z > 1e-12 {
            let z = t[0].z + (r - (x - t[0].x) * n.x - (y - t[0].y) * n.y) / n.z;
            let f = P3::new(x, y, z) - n * r;
            let inside = (0..3).all(|i| (t[(i + 1) % 3] - t[i]).cross(&(f - t[i])).dot(&n) >= -1e-12);
            if inside {
                take(z);
            }
        }
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let d2 = (x - a.x).powi(2) + (y - a.y).powi(2);
            if d2 <= r * r {
                take(a.z + (r * r - d2).sqrt());
            }
            // Edge: the largest over its points p of p.z + sqrt(r² − horizontal²), sampled
            // over the part within r horizontally (u where a quadratic is ≤ 0) and refined.
            let (e, w) = ((b - a).xy(), P3::new(x, y, 0.0).xy() - a.xy());
            let (qa, qb, qc) = (e.norm_squared(), -2.0 * e.dot(&w), w.norm_squared() - r * r);
            let disc = qb * qb - 4.0 * qa * qc;
            if qa < 1e-18 || disc < 0.0 {
                continue;
            }
            let (u0, u1) = (((-qb - disc.sqrt()) / (2.0 * qa)).max(0.0), ((-qb + disc.sqrt()) / (2.0 * qa)).min(1.0));
            if u0 > u1 {
                continue;
            }
            let k = 200;
            let z_at = |u: f64| {
                let p = a + (b - a) * u;
                let h2 = (x - p.x).powi(2) + (y - p.y).powi(2);
                (h2 <= r * r).then(|| p.z + (r * r - h2).sqrt())
            };
            let mut top: Option<(f64, f64)> = None;
            for j in 0..=k {
                let u = u0 + (u1 - u0) * j as f64 / k as f64;
                if let Some(z) = z_at(u).filter(|z| top.is_none_or(|(_, t)| *z > t)) {
                    top = Some((u, z));
                }
            }
            if let Some((u, _)) = top {
                // Golden-section refinement around the best sample.
                let step = (u1 - u0) / k as f64;
                let (mut lo, mut hi) = ((u - step).max(u0), (u + step).min(u1));
                for _ in 0..60 {
                    let (m1, m2) = (lo + (hi - lo) * 0.382, lo + (hi - lo) * 0.618);
                    if z_at(m1).unwrap_or(f64::NEG_INFINITY) >= z_at(m2).unwrap_or(f64::NEG_INFINITY) {
                        hi = m2;
                    } else {
                        lo = m1;
                    }
                }
                for u in [lo, hi, u] {
                    if let Some(z) = z_at(u) {
                        take(z);
                    }
                }
            }
        }
    }
    best
}

/// Coverage of a scan along x (angle 0) measured against `env` (highest centre z over (x, y),
/// None where the model is not under): per line y, the longest stretch with the model under it
/// that no path covers (sampled every 0.005 mm), and the deepest point below the envelope (its
/// lowest over ±1e-3 mm along the line, so a path climbing a vertical step is not counted).
fn coverage_along_x(cl: &[Cl], x0: f64, x1: f64, env: &dyn Fn(f64, f64) -> Option<f64>) -> (f64, f64) {
    let mut ys: Vec<f64> = cl.iter().map(|q| q.c.y).collect();
    ys.sort_by(f64::total_cmp);
    ys.dedup();
    let (mut gap, mut below): (f64, f64) = (0.0, 0.0);
    for &y in &ys {
        let on: Vec<&Cl> = cl.iter().filter(|q| q.c.y == y).collect();
        let mut spans: Vec<(f64, f64)> = Vec::new();
        for q in &on {
            match spans.last_mut() {
                Some(s) if on.iter().any(|p| p.path == q.path && p.c.x == s.0) => s.1 = s.1.max(q.c.x),
                _ => spans.push((q.c.x, q.c.x)),
            }
        }
        spans.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut holes = Vec::new();
        let mut reach = x0;
        for (a, b) in spans {
            if a > reach {
                holes.push((reach, a));
            }
            reach = reach.max(b);
        }
        holes.push((reach, x1));
        for (a, b) in holes {
            let n = ((b - a) / 0.005).ceil() as usize;
            let hits: Vec<f64> =
                (0..=n).map(|k| a + (b - a) * k as f64 / n.max(1) as f64).filter(|&x| env(x, y).is_some()).collect();
            if let (Some(f), Some(l)) = (hits.first(), hits.last()) {
                gap = gap.max(l - f);
            }
        }
        for q in &on {
            let e = [-1e-3, 0.0, 1e-3]
                .iter()
                .map(|d| env(q.c.x + d, y).unwrap_or(f64::NEG_INFINITY))
                .fold(f64::INFINITY, f64::min);
            below = below.max(e - q.c.z);
        }
    }
    (gap, below)
}

/// Runs a scan of `input` (a file in the work dir) and returns rows, report, stderr.
fn scan(w: &Work, input: &str, args: &[&str]) -> (Vec<Cl>, serde_json::Value, String) {
    let mut all = vec![input, "--mode", "scan", "-o", "cl.csv", "--report", "r.json"];
    all.extend_from_slice(args);
    let run = w.run(BIN, &all, b"");
    assert!(run.status == 0 || run.status == 1, "stderr: {}", run.stderr);
    let mut r = report(w, "r.json");
    r["exit_status"] = run.status.into();
    (rows(&w.read("cl.csv")), r, run.stderr)
}

/// The independent figures first, then the filter's own: exit 0 and its report agreeing.
fn assert_covered(r: &serde_json::Value, gap: f64, below: f64) {
    assert!(gap <= 2e-3, "a stretch of {gap} mm with the model under it is not covered");
    assert!(below <= 2e-3, "a CL point lies {below} mm below the envelope");
    assert_eq!(r["exit_status"], 0, "{r}");
    assert_eq!(r["lines_not_covered"], 0, "{r}");
    assert_eq!(r["points_below_envelope"], 0, "{r}");
    assert!(r["largest_coverage_gap_mm"].as_f64().unwrap() <= 1e-3, "{r}");
}

#[test]
fn s1_channel_lines_level_with_the_rim_are_traced() {
    let w = Work::new();
    std::fs::copy(data("stylus-trace/channel.stl"), w.path("channel.stl")).unwrap();
    let tris = stl_corners(&data("stylus-trace/channel.stl"));
    let (cl, r, _) = scan(&w, "channel.stl", &["-r", "3", "--pick", "5"]);
    for y in [35.0, 45.0] {
        let line: Vec<&Cl> = cl.iter().filter(|q| q.c.y == y).collect();
        assert!(!line.is_empty(), "line y = {y} is missing");
        let (lo, hi) = line.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| (a.min(q.c.x), b.max(q.c.x)));
        assert!(lo <= 1e-9 && hi >= 100.0 - 1e-9, "line y = {y} runs only from x {lo} to {hi}");
    }
    let (gap, below) = coverage_along_x(&cl, 0.0, 100.0, &|x, y| drop_on_mesh(&tris, x, y, 3.0));
    assert_covered(&r, gap, below);
}

#[test]
fn s1_groove_line_has_no_gap_where_a_drop_finds_the_model() {
    let w = Work::new();
    std::fs::copy(data("stylus-trace/groove-strip.stl"), w.path("g.stl")).unwrap();
    let tris = stl_corners(&data("stylus-trace/groove-strip.stl"));
    let (cl, r, stderr) = scan(&w, "g.stl", &["-r", "3", "--pick", "1", "--region=0,50,5,5.5"]);
    let (gap, below) = coverage_along_x(&cl, 0.0, 50.0, &|x, y| drop_on_mesh(&tris, x, y, 3.0));
    assert_covered(&r, gap, below);
    assert!(!stderr.contains("warning"), "{stderr}");
}

#[test]
fn s2_rod_end_line_is_a_few_passes_on_the_envelope() {
    let w = Work::new();
    w.write(
        "rod.json",
        r#"{"surfaces": [
 {"type": "plane", "name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]},
 {"type": "cylinder", "name": "rod", "point": [0, 12.7, 15], "axis": [1, 0, 0], "radius": 0.5, "length": [0, 40]}]}"#,
    );
    let (cl, r, _) = scan(&w, "rod.json", &["-r", "12.5", "--pick", "1", "--region=10,90,0,0.5"]);
    assert!(r["paths"].as_u64().unwrap() <= 3, "{} paths for one line", r["paths"]);
    // The rod's lateral surface and its end circle (sampled by angle), and the floor.
    let env = |x: f64, y: f64| {
        let mut z: f64 = 12.5;
        let h2 = (y - 12.7f64).powi(2);
        if (0.0..=40.0).contains(&x) && h2 <= 13f64.powi(2) {
            z = z.max(15.0 + (169.0 - h2).sqrt());
        }
        for k in 0..=20000 {
            let t = k as f64 / 20000.0 * std::f64::consts::TAU;
            for end in [0.0, 40.0] {
                let p = P3::new(end, 12.7 + 0.5 * t.cos(), 15.0 + 0.5 * t.sin());
                let d2 = (x - p.x).powi(2) + (y - p.y).powi(2);
                if d2 <= 12.5f64.powi(2) {
                    z = z.max(p.z + (12.5f64.powi(2) - d2).sqrt());
                }
            }
        }
        Some(z)
    };
    let (gap, below) = coverage_along_x(&cl, 10.0, 90.0, &env);
    assert_covered(&r, gap, below);
}

/// The floor and a ball of radius 10 at (50, 0, 30), r = 5: the envelope closed form.
fn floating_ball_envelope(x: f64, y: f64) -> Option<f64> {
    let rho2 = (x - 50.0).powi(2) + y * y;
    Some(if rho2 <= 225.0 { 30.0 + (225.0 - rho2).sqrt() } else { 5.0 })
}

#[test]
fn s3_scan_goes_over_a_floating_ball_not_along_the_floor_under_it() {
    let w = Work::new();
    w.write(
        "bf.json",
        r#"{"surfaces": [
 {"type": "plane", "name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]},
 {"type": "sphere", "name": "ball", "centre": [50, 0, 30], "radius": 10}]}"#,
    );
    let (cl, r, _) = scan(&w, "bf.json", &["-r", "5", "--pick", "4", "--region=20,80,-16,16"]);
    let (gap, below) = coverage_along_x(&cl, 20.0, 80.0, &floating_ball_envelope);
    assert_covered(&r, gap, below);
}

#[test]
fn s4_passes_end_at_the_silhouette_and_start_at_the_shadow() {
    let w = Work::new();
    w.write("s.json", r#"{"surfaces": [{"type": "sphere", "name": "S", "centre": [3, -2, 5], "radius": 30}]}"#);
    let (cl, r, _) = scan(&w, "s.json", &["-r", "5", "--pick", "2"]);
    let env = |x: f64, y: f64| {
        let rho2 = (x - 3.0).powi(2) + (y + 2.0).powi(2);
        (rho2 <= 35f64.powi(2)).then(|| 5.0 + (35f64.powi(2) - rho2).sqrt())
    };
    let (gap, below) = coverage_along_x(&cl, -27.0, 33.0, &env);
    assert_covered(&r, gap, below);
}

#[test]
fn coverage_is_measured_on_the_rounded_output() {
    // Rounded to 3 decimals, the 0.5 µm hop between passes at the ball's silhouettes is written
    // as 1 µm: within the gap tolerance widened by the rounding unit, and measured as written.
    let w = Work::new();
    w.write(
        "bf.json",
        r#"{"surfaces": [
 {"type": "plane", "name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]},
 {"type": "sphere", "name": "ball", "centre": [50, 0, 30], "radius": 10}]}"#,
    );
    let (cl, r, stderr) = scan(&w, "bf.json", &["-r", "5", "--pick", "4", "--region=20,80,-16,16", "--decimals", "3"]);
    assert_eq!(r["exit_status"], 0, "{stderr}");
    assert!((r["coverage_gap_tol_mm"].as_f64().unwrap() - 0.002).abs() < 1e-12, "{r}");
    let gap = r["largest_coverage_gap_mm"].as_f64().unwrap();
    assert!(gap > 0.0 && gap <= 0.002, "{r}");
    let (gap_measured, below) = coverage_along_x(&cl, 20.0, 80.0, &floating_ball_envelope);
    assert!(gap_measured <= 0.002 && below <= 2e-3, "{gap_measured} {below}");
}
