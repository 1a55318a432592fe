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
    w.run(BIN, &["flat.stl", "-r", "1", "--strict", "-o", "out.csv"], b"")
        .fails(2, "flat.stl (facet 2): degenerate triangle (zero area): corners (0, 0, 0), (1, 0, 0), (2, 0, 0)");
    assert!(!w.exists("out.csv"));
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

// Issue 20 P4: every filter estimates its work and memory before it starts and refuses what
// would exceed its bounds; absurd option values are refused naming the option.

/// Runs stylus-trace in `w` under a 4 GiB address-space limit and a 20 s timeout (`timeout`
/// exits 124 when it strikes, a signal shows as 128 + its number).
fn bounded_run(w: &Work, args: &[&str]) -> e2e::Outcome {
    let bin = e2e::bin(BIN);
    let script = "ulimit -v 4194304; exec \"$0\" \"$@\"";
    let mut all = vec!["20", "sh", "-c", script, bin.to_str().unwrap()];
    all.extend_from_slice(args);
    let out = std::process::Command::new("timeout")
        .args(&all)
        .current_dir(w.path(""))
        .env_remove("RUST_BACKTRACE")
        .stdin(std::process::Stdio::null())
        .output()
        .expect("spawn");
    e2e::Outcome {
        status: out.status.code().unwrap_or(-1),
        stdout: out.stdout,
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// The reproducers of issue 20 P4, built here: once 4 GiB allocation failures or hours, now
/// one line naming the option or the model, exit 2, at once.
#[test]
fn p4_runs_past_their_bounds_are_refused_before_they_start() {
    let w = Work::new();
    w.write(
        "sphere.json",
        r#"{"surfaces": [{"type": "sphere", "name": "R500", "centre": [0, 0, -500], "radius": 500}]}"#,
    );
    // A closed box mesh with one corner pulled 4.29e9 mm out (a stray vertex), and the box ×1e12.
    let mut stray = box_mesh(P3::new(-20.0, -20.0, 0.0), P3::new(20.0, 20.0, 20.0));
    stray[4][2].y = 4.294967296e9;
    w.write("stray.stl", camkit::model::mesh::binary_stl(&stray));
    let huge: Vec<[P3; 3]> =
        box_mesh(P3::new(-20.0, -20.0, 0.0), P3::new(20.0, 20.0, 20.0)).iter().map(|t| t.map(|p| p * 1e12)).collect();
    w.write("huge.stl", camkit::model::mesh::binary_stl(&huge));
    // One vertex of one top facet moved 1e6 mm up (as in fuzz-flagged domes that ran for hours):
    // the line over it would climb a sliver a million mm high.
    let mut spike = box_mesh(P3::new(-20.0, -20.0, 0.0), P3::new(20.0, 20.0, 20.0));
    let top = spike.iter().position(|t| t.iter().all(|p| p.z == 20.0)).expect("a top facet");
    spike[top][0].z = 1e6;
    w.write("spike.stl", camkit::model::mesh::binary_stl(&spike));
    let cases: [(&[&str], &str); 7] = [
        (&["stray.stl", "-r", "5", "--pick", "5"], "stray.stl: the area traced within the model's bounding box"),
        (&["spike.stl", "-r", "5", "--pick", "5"], "(--max-points)"),
        (&["huge.stl", "-r", "5", "--pick", "5"], "beyond 3.518e9 mm where the round-off"),
        (&["sphere.json", "-r", "12.5", "--pick", "1e-9", "--region", "-20,20,-20,20"], "(--max-memory)"),
        (&["sphere.json", "-r", "12.5", "--mode", "contour", "--z-step", "1e-9"], "contour mode at --z-step"),
        (&["sphere.json", "-r", "12.5", "--pick", "10", "--region", "-1e300,1e300,-1,1"], "--region reaches 1e300"),
        (&["sphere.json", "-r", "12.5", "--pick", "0.5", "--max-points", "1000"], "(--max-points)"),
    ];
    for (args, needle) in cases {
        let started = std::time::Instant::now();
        let out = bounded_run(&w, args);
        out.fails(2, needle);
        assert!(started.elapsed().as_secs_f64() < 5.0, "{args:?} took {:?}", started.elapsed());
    }
    // Within the bounds the same model is traced.
    let out =
        bounded_run(&w, &["sphere.json", "-r", "12.5", "--pick", "10", "--region", "-1e3,1e3,-1,1", "-o", "s.csv"]);
    assert_eq!(out.status, 0, "{}", out.stderr);
    assert!(rows(&w.read("s.csv")).len() > 100);
}

/// Seeded property test over every numeric option (alone and three at a time): 0, negative,
/// NaN, infinities, 1e-300, 1e300 and ordinary values never panic, exit 0, 1 or 2 only, with
/// one stderr line when they fail, within 20 s and 4 GiB.
#[test]
fn every_numeric_option_is_bounded_for_any_value() {
    let w = Work::new();
    w.write("ball.json", r#"{"surfaces": [{"type": "sphere", "name": "ball", "centre": [0,0,10], "radius": 10}]}"#);
    w.write(
        "two.json",
        r#"{"surfaces": [{"type": "plane", "name": "floor", "point": [0,0,0], "normal": [0,0,1]},
                         {"type": "sphere", "name": "ball", "centre": [0,0,10], "radius": 10}]}"#,
    );
    w.write("box.stl", camkit::model::mesh::binary_stl(&box_mesh(P3::new(0.0, 0.0, 0.0), P3::new(10.0, 8.0, 5.0))));
    let values = [
        "0",
        "-1",
        "NaN",
        "inf",
        "-inf",
        "1e-300",
        "1e300",
        "-1e300",
        "1e-9",
        "1e9",
        "0.5",
        "3",
        "-0",
        "1e-5",
        "1e5",
        "4294967297",
        "18446744073709551616",
    ];
    // Option, its base mode's arguments, and how a value is placed (X: the value in a list).
    let options: [(&str, &[&str], &str); 19] = [
        ("-r", &["ball.json", "--pick", "2"], "X"),
        ("--pick", &["ball.json", "-r", "2"], "X"),
        ("--angle", &["ball.json", "-r", "2", "--pick", "2"], "X"),
        ("--chord-tol", &["box.stl", "-r", "2", "--pick", "2"], "X"),
        ("--contact-tol", &["ball.json", "-r", "2", "--pick", "2"], "X"),
        ("--max-step", &["box.stl", "-r", "2", "--pick", "2"], "X"),
        ("--min-step", &["ball.json", "-r", "2", "--pick", "2"], "X"),
        ("--decimals", &["ball.json", "-r", "2", "--pick", "2"], "X"),
        ("--threads", &["ball.json", "-r", "2", "--pick", "2"], "X"),
        ("--max-memory", &["ball.json", "-r", "2", "--pick", "2"], "X"),
        ("--max-points", &["ball.json", "-r", "2", "--pick", "2"], "X"),
        ("--region", &["ball.json", "-r", "2", "--pick", "2"], "X,5,-5,5"),
        ("--region", &["box.stl", "-r", "2", "--pick", "2"], "-5,X,-5,5"),
        ("--region", &["ball.json", "-r", "2", "--pick", "2"], "-5,5,-5,X"),
        ("--z-step", &["ball.json", "-r", "2", "--mode", "contour"], "X"),
        ("--levels", &["box.stl", "-r", "2", "--mode", "contour"], "3,X"),
        ("--region", &["box.stl", "-r", "2", "--mode", "contour", "--levels", "3"], "-5,5,-5,X"),
        ("--start", &["two.json", "-r", "2", "--mode", "two-surface", "--region", "-20,20,-20,20"], "X,0,2"),
        ("--start", &["two.json", "-r", "2", "--mode", "two-surface", "--region", "-20,20,-20,20"], "6,0,X"),
    ];
    let check = |args: &[String]| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let started = std::time::Instant::now();
        let out = bounded_run(&w, &args);
        let took = started.elapsed().as_secs_f64();
        assert!(matches!(out.status, 0..=2), "{args:?}: status {}, stderr {}", out.status, out.stderr);
        assert!(!out.stderr.contains("internal error") && !out.stderr.contains("panicked"), "{args:?}: {}", out.stderr);
        if out.status != 0 {
            let last = out.stderr.trim_end().lines().filter(|l| !l.contains(": warning: ")).count();
            assert_eq!(last, 1, "{args:?}: one error line: {}", out.stderr);
        }
        assert!(took < 20.0, "{args:?} took {took} s");
        out.status
    };
    let mut statuses = [0usize; 3];
    let with = |(opt, base, shape): &(&str, &[&str], &str), v: &str| -> Vec<String> {
        let mut a: Vec<String> = base.iter().map(|s| s.to_string()).collect();
        a.extend(["-o".into(), "o.csv".into(), format!("{opt}={}", shape.replace('X', v))]);
        // The time is bounded by --max-points: a tenth of the default keeps each run short.
        if *opt != "--max-points" {
            a.push("--max-points=1e7".into());
        }
        a
    };
    for o in &options {
        for v in values {
            statuses[check(&with(o, v)) as usize] += 1;
        }
    }
    // Three options of the scan mode at once (not --max-points), seeded.
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move |n: usize| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as usize % n
    };
    for _ in 0..40 {
        let mut chosen: Vec<usize> = Vec::new();
        while chosen.len() < 3 {
            let k = next(10);
            if !chosen.contains(&k) {
                chosen.push(k);
            }
        }
        let mut a: Vec<String> = ["box.stl", "-o", "o.csv", "--max-points=1e7"].map(String::from).to_vec();
        for (opt, default) in [("-r", "2"), ("--pick", "2")] {
            if !chosen.iter().any(|&k| options[k].0 == opt) {
                a.push(format!("{opt}={default}"));
            }
        }
        a.extend(chosen.iter().map(|&k| format!("{}={}", options[k].0, values[next(values.len())])));
        statuses[check(&a) as usize] += 1;
    }
    eprintln!("statuses 0/1/2: {statuses:?}");
    assert!(statuses[0] > 20 && statuses[2] > 100, "{statuses:?}");
}

/// A closed box from `lo` to `hi`: 12 triangles, corners counter-clockwise seen from outside.
fn box_mesh(lo: P3, hi: P3) -> Vec<[P3; 3]> {
    let c = |i: usize| P3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][(i >> 1) & 1], [lo.z, hi.z][(i >> 2) & 1]);
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    quads.iter().flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]]).collect()
}

// Issue 19: STL files as users have them.

/// An OpenSCAD-style STL: a closed box with zero-area slivers along its edges (collinear
/// corners, as a CSG union leaves them) and a facet written twice. Today the first sliver
/// refuses the whole file; now the slivers and the repeat are left out with one warning and
/// counted in the report, the box is traced exactly as without them, and --strict refuses,
/// naming the facet.
#[test]
fn openscad_slivers_and_a_duplicate_facet_are_dropped_and_counted() {
    let w = Work::new();
    let clean = box_mesh(P3::new(0.0, 0.0, 0.0), P3::new(30.0, 20.0, 10.0));
    let mut scad = clean.clone();
    for k in 0..22 {
        // A sliver on the top edge y = 0: three collinear points.
        let x = 1.0 + k as f64;
        scad.insert(
            2 * k % scad.len(),
            [P3::new(x, 0.0, 10.0), P3::new(x + 0.5, 0.0, 10.0), P3::new(x + 0.25, 0.0, 10.0)],
        );
    }
    scad.push(clean[3]);
    w.write("box.stl", camkit::model::mesh::binary_stl(&clean));
    w.write("scad.stl", camkit::model::mesh::binary_stl(&scad));
    let args = ["-r", "3", "--pick", "2"];
    let out = w.run(BIN, &[&["box.stl", "-o", "box.csv", "--report", "box.json"], &args[..]].concat(), b"");
    out.ok();
    assert!(out.stderr.is_empty(), "{}", out.stderr);
    let out = w.run(BIN, &[&["scad.stl", "-o", "scad.csv", "--report", "scad.json"], &args[..]].concat(), b"");
    out.ok();
    let first = scad.iter().position(|t| *t == clean[3]).unwrap() + 1;
    assert_eq!(
        out.stderr.trim_end(),
        format!(
            "stylus-trace: warning: scad.stl: 22 zero-area facets (the first facet 1) and 1 duplicate facets (the first facet 35, a repeat of facet {first}) dropped (--strict refuses them)"
        )
    );
    let (clean_rep, scad_rep) = (report(&w, "box.json"), report(&w, "scad.json"));
    assert_eq!(
        (scad_rep["degenerate_facets_dropped"].as_u64(), scad_rep["duplicate_facets_dropped"].as_u64()),
        (Some(22), Some(1))
    );
    assert_eq!(clean_rep["degenerate_facets_dropped"], 0);
    assert_eq!((scad_rep["triangles"].as_u64(), scad_rep["points"].clone()), (Some(12), clean_rep["points"].clone()));
    assert_eq!(w.read("scad.csv").replace("scad", "box"), w.read("box.csv"));
    w.run(BIN, &[&["scad.stl", "--strict", "-o", "strict.csv"], &args[..]].concat(), b"").fails(
        2,
        "scad.stl (facet 1): degenerate triangle (zero area): corners (13, 0, 10), (13.5, 0, 10), (13.25, 0, 10)",
    );
    assert!(!w.exists("strict.csv"));
}

/// An open mesh (a box with its top face taken out: a hole) is traced like any mesh: nearest
/// points need no closed solid. Over the hole the stylus goes down inside the box; every CL
/// point is r from the triangles by brute force.
#[test]
fn a_mesh_with_a_hole_is_traced() {
    let w = Work::new();
    let mut tris = box_mesh(P3::new(0.0, 0.0, 0.0), P3::new(30.0, 20.0, 10.0));
    tris.drain(2..4);
    w.write("open.stl", camkit::model::mesh::binary_stl(&tris));
    let (cl, rep, stderr) = scan(&w, "open.stl", &["-r", "3", "--pick", "2"]);
    assert!(stderr.is_empty(), "{stderr}");
    assert_eq!(rep["triangles"], 10);
    let tris = as_f32(&tris);
    for q in &cl {
        let d = mesh_distance(&q.c, &tris);
        assert!((d - 3.0).abs() <= CONTACT, "{:?} is {d} from the mesh", q.c);
    }
    // Inside the box, down at its floor: the stylus centre 3 mm above z = 0.
    assert!(cl.iter().any(|q| (q.c.z - 3.0).abs() <= CONTACT && q.c.x > 5.0 && q.c.x < 25.0));
}

/// Rows of a fixed-axis (`--tool`) table: tip, axis, contact, normal, and the `point` column.
fn tips(csv: &str) -> Vec<(P3, V3, P3, V3, String)> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let (x, i, px, nx, point) = (col("x"), col("i"), col("px"), col("nx"), col("point"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let p3 = |k: usize| P3::new(f[k].parse().unwrap(), f[k + 1].parse().unwrap(), f[k + 2].parse().unwrap());
            (p3(x), p3(i).coords, p3(px), p3(nx).coords, f[point].to_string())
        })
        .collect()
}

/// The four cutters of the OpenCAMLib reference (scripts/dropcutter-ocl.py): flat R3, ball R3,
/// bull R3 r1, cone R3 with a half-angle of 0.6 rad.
const OCL_CUTTERS: [(&str, &str); 4] = [
    ("flat", r#"{"kind": "flat", "radius": 3}"#),
    ("ball", r#"{"kind": "ball", "radius": 3}"#),
    ("bull", r#"{"kind": "bull", "radius": 3, "corner_radius": 1}"#),
    ("cone", r#"{"kind": "cone", "radius": 3, "half_angle": 34.37746770784939}"#),
];

/// Issue 19: the fixed-axis cutters against OpenCAMLib's drop-cutter on the same STL and grid
/// (data/stylus-trace/dropcut-ocl.csv, made by scripts/dropcutter-ocl.py): the same points have
/// the model under the cutter, and the tips agree within 1 µm — except where OpenCAMLib's cone
/// is lower than ours, and there our contact proves it wrong: the contact lies on the mesh and
/// touches the cone at our tip, so OpenCAMLib's tip puts the cone into the mesh.
#[test]
fn fixed_axis_cutters_agree_with_opencamlib() {
    let w = Work::new();
    let stl = data("stylus-trace/dropcut-freeform.stl");
    let stl = stl.to_str().unwrap();
    let reference = std::fs::read_to_string(data("stylus-trace/dropcut-ocl.csv")).unwrap();
    // Positions as keys (−0 as 0).
    let bits = |v: f64| (v + 0.0).to_bits();
    let mut ocl = std::collections::HashMap::new();
    for l in reference.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let f: Vec<&str> = l.split(',').collect();
        let key = (f[0].to_string(), bits(f[1].parse().unwrap()), bits(f[2].parse().unwrap()));
        ocl.insert(key, f[3].parse::<f64>().unwrap());
    }
    let model = camkit::model::Model::load(&camkit::io::Input::open(stl).unwrap()).unwrap();
    for (name, doc) in OCL_CUTTERS {
        w.write(&format!("{name}.json"), doc);
        let out = w.run(
            BIN,
            &[stl, "--tool", &format!("{name}.json"), "--region=-3,23,-3,23", "--pick", "1", "--max-step", "1"],
            b"",
        );
        let rows = tips(&out.ok());
        let (mut worst, mut proven) = (0.0f64, 0);
        for (tip, axis, contact, _, point) in &rows {
            assert_eq!((axis, point.as_str()), (&V3::z(), "tip"));
            let z = ocl
                .remove(&(name.to_string(), bits(tip.x), bits(tip.y)))
                .unwrap_or_else(|| panic!("{name}: OpenCAMLib has no point at {tip}"));
            let diff = tip.z - z;
            if name == "cone" && diff > 1e-6 {
                let rho = (contact.x - tip.x).hypot(contact.y - tip.y);
                assert!(rho <= 3.0 + 1e-9 && (contact.z - rho / 0.6f64.tan() - tip.z).abs() < 1e-9, "{tip} {contact}");
                assert!(model.distance(contact) < 1e-6, "{name}: contact {contact} off the mesh");
                proven += 1;
            } else {
                worst = worst.max(diff.abs());
            }
        }
        assert!(worst <= 1e-6, "{name}: {worst} mm from OpenCAMLib");
        assert!(rows.len() > 600 && (name == "cone" || proven == 0), "{name}: {} rows, {proven}", rows.len());
        eprintln!(
            "{name}: {} tips, largest difference {worst:.2e} mm, {proven} where OpenCAMLib is provably low",
            rows.len()
        );
    }
    // What OpenCAMLib has that we do not: only points with nothing under the cutter (−100).
    assert!(ocl.values().all(|z| *z == -100.0), "{:?}", ocl.iter().find(|(_, z)| **z != -100.0));
}

/// Closed forms on analytic models: flat on a sphere, bull on a tilted plane and on a cylinder
/// across the axis and in a funnel (a cone); a ball on a sphere along a slanted axis, on a slanted
/// cylinder and on a torus; the same table for 1 and 2 threads.
#[test]
fn fixed_axis_cutters_on_analytic_models() {
    let w = Work::new();
    w.write("flat.json", r#"{"kind": "flat", "radius": 2}"#);
    w.write("bull.json", r#"{"kind": "bull", "radius": 4, "corner_radius": 1.5}"#);
    w.write("ball.json", r#"{"kind": "ball", "radius": 2}"#);
    w.write("sphere.json", r#"{"surfaces": [{"type": "sphere", "centre": [0, 0, 0], "radius": 10}]}"#);
    let run = |model: &str, tool: &str, extra: &[&str]| {
        let out = w.run(BIN, &[&[model, "--tool", tool, "--pick", "0.5", "--max-step", "0.5"], extra].concat(), b"");
        tips(&out.ok())
    };
    // Flat R2 on the sphere R10: tip z = √(100 − max(d − 2, 0)²) at distance d from the centre.
    let rows = run("sphere.json", "flat.json", &[]);
    assert!(rows.len() > 1000);
    for (tip, _, contact, n, _) in &rows {
        let d = tip.x.hypot(tip.y);
        let want = (100.0 - (d - 2.0f64).max(0.0).powi(2)).sqrt();
        assert!((tip.z - want).abs() < 1e-9, "{tip}: {want}");
        assert!((contact.coords.norm() - 10.0).abs() < 1e-9 && (n - contact.coords / 10.0).norm() < 1e-9);
    }
    // Bull R4 r1.5 on the plane z = x·tan 20°: tip = (x + 2.5)·tanθ + 1.5·(1/cosθ − 1).
    let th = 20f64.to_radians();
    w.write(
        "plane.json",
        format!(
            r#"{{"surfaces": [{{"type": "plane", "point": [0, 0, 0], "normal": [{}, 0, {}]}}]}}"#,
            -th.sin(),
            th.cos()
        ),
    );
    for (tip, _, _, n, _) in &run("plane.json", "bull.json", &["--region=-5,5,-1,1"]) {
        let want = (tip.x + 2.5) * th.tan() + 1.5 * (1.0 / th.cos() - 1.0);
        assert!((tip.z - want).abs() < 1e-9, "{tip}: {want}");
        assert!((n - V3::new(-th.sin(), 0.0, th.cos())).norm() < 1e-9);
    }
    // Bull on a cylinder R5 along y: the disc of radius 2.5 at tip + 1.5 is 6.5 from the axis:
    // tip = √(6.5² − max(|x| − 2.5, 0)²) − 1.5.
    w.write("cyl.json", r#"{"surfaces": [{"type": "cylinder", "point": [0, 0, 0], "axis": [0, 1, 0], "radius": 5}]}"#);
    let rows = run("cyl.json", "bull.json", &["--region=-10,10,-1,1"]);
    assert!(rows.iter().any(|r| r.0.x.abs() > 8.0));
    for (tip, ..) in &rows {
        let want = (6.5f64.powi(2) - (tip.x.abs() - 2.5).max(0.0).powi(2)).sqrt() - 1.5;
        assert!((tip.z - want).abs() < 1e-9, "{tip}: {want}");
    }
    // Ball R2 along a slanted axis: the ball's centre tip + 2·axis is 12 from the sphere's.
    let axis = V3::new(1.0, -1.0, 2.0).normalize();
    let rows = run("sphere.json", "ball.json", &["--axis", "1,-1,2", "--threads", "1"]);
    assert!(rows.len() > 1000);
    for (tip, a, ..) in &rows {
        assert!((a - axis).norm() < 1e-12);
        assert!(((tip + axis * 2.0).coords.norm() - 12.0).abs() < 1e-9, "{tip}");
    }
    // Ball R2 on an endless cylinder R3 through the origin along (sin 50°, 0, cos 50°): the
    // centre (x, y, tip + 2) is 5 from the axis, the higher root; a flat is refused there.
    let th = 50f64.to_radians();
    let axis = V3::new(th.sin(), 0.0, th.cos());
    w.write(
        "slant.json",
        format!(
            r#"{{"surfaces": [{{"type": "cylinder", "point": [0, 0, 0], "axis": [{}, 0, {}], "radius": 3}}]}}"#,
            th.sin(),
            th.cos()
        ),
    );
    let rows = run("slant.json", "ball.json", &["--region=-4,4,-4.75,4.75"]);
    assert!(rows.len() > 300);
    for (tip, _, contact, n, _) in &rows {
        // x sin + z cos = t along the axis: |c − t·axis|² = 25 is a quadratic in z.
        let (x, y) = (tip.x, tip.y);
        let (a2, b1, c0) = (th.sin().powi(2), -2.0 * x * th.sin() * th.cos(), x * x * th.cos().powi(2) + y * y - 25.0);
        let want = (-b1 + (b1 * b1 - 4.0 * a2 * c0).sqrt()) / (2.0 * a2) - 2.0;
        assert!((tip.z - want).abs() < 1e-9, "{tip}: {want}");
        let radial = |p: &P3| p.coords - axis * p.coords.dot(&axis);
        assert!((radial(contact).norm() - 3.0).abs() < 1e-9 && (n - radial(contact) / 3.0).norm() < 1e-9);
    }
    // Ball R2 on a torus R 8, r 1 about z: the centre is 3 from the tube's centre circle, so
    // tip = √(9 − (d − 8)²) − 2 at distance d from the torus's axis.
    w.write("torus.json", r#"{"surfaces": [{"type": "torus", "centre": [0, 0, 0], "axis": [0, 0, 1], "major_radius": 8, "minor_radius": 1}]}"#);
    let rows = run("torus.json", "ball.json", &["--region=5.5,10.5,-1,1"]);
    assert!(rows.len() > 40);
    for (tip, ..) in &rows {
        let d = tip.x.hypot(tip.y);
        let want = (9.0 - (d - 8.0f64).powi(2)).sqrt() - 2.0;
        assert!((tip.z - want).abs() < 1e-9, "{tip}: {want}");
    }
    // Bull R4 r1.5 in a funnel z = ρ·tan 60° (a cone opening up, half-angle 30°, 20 long): the
    // far wall through the disc's far edge, tip = (d + 2.5)·tan 60° + 1.5·(1/cos 60° − 1).
    w.write(
        "funnel.json",
        r#"{"surfaces": [{"type": "cone", "apex": [0, 0, 0], "axis": [0, 0, 1], "half_angle": 30, "length": [0, 20]}]}"#,
    );
    let th = 60f64.to_radians();
    let rows = run("funnel.json", "bull.json", &["--region=-2,2,-2,2"]);
    assert!(rows.len() > 40);
    for (tip, ..) in &rows {
        let want = (tip.x.hypot(tip.y) + 2.5) * th.tan() + 1.5 * (1.0 / th.cos() - 1.0);
        assert!((tip.z - want).abs() < 1e-9, "{tip}: {want}");
    }
    // Flat R2 on the same slanted cylinder R3 (its top z = (x cos θ + √(9 − y²)) / sin θ): the
    // tip is the highest of that over the disc, never below a dense sampling of it.
    let (th, axis) = (50f64.to_radians(), V3::new(50f64.to_radians().sin(), 0.0, 50f64.to_radians().cos()));
    let rows = run("slant.json", "flat.json", &["--region=-4,4,-3,3"]);
    assert!(rows.len() > 200);
    for (tip, _, contact, ..) in &rows {
        let mut brute = f64::NEG_INFINITY;
        for i in -60..=60 {
            for j in -60..=60 {
                let (x, y) = (tip.x + i as f64 / 30.0, tip.y + j as f64 / 30.0);
                if (x - tip.x).hypot(y - tip.y) <= 2.0 && y.abs() <= 3.0 {
                    brute = brute.max((x * th.cos() + (9.0 - y * y).sqrt()) / th.sin());
                }
            }
        }
        assert!(tip.z >= brute - 1e-9 && tip.z - brute < 0.05, "{tip}: sampled {brute}");
        let radial = contact.coords - axis * contact.coords.dot(&axis);
        assert!((radial.norm() - 3.0).abs() < 1e-9 && (contact.z - tip.z).abs() < 1e-12);
    }
    let threads = |n: &str| {
        let args = ["--tool", "ball.json", "--pick", "0.5", "--max-step", "0.5", "--axis", "1,-1,2", "--threads", n];
        w.run(BIN, &[&["sphere.json"][..], &args].concat(), b"")
    };
    let (two, one) = (threads("2"), threads("1"));
    assert_eq!(one.ok(), two.ok());
}

/// Bad cutters and models: one line, exit 2, no output.
#[test]
fn fixed_axis_bad_input() {
    let w = Work::new();
    w.write("sphere.json", r#"{"surfaces": [{"type": "sphere", "centre": [0, 0, 0], "radius": 10}]}"#);
    w.write("torus.json", r#"{"surfaces": [{"type": "torus", "centre": [0, 0, 0], "axis": [0, 0, 1], "major_radius": 5, "minor_radius": 1}]}"#);
    w.write("bull.json", r#"{"kind": "bull", "radius": 3, "corner_radius": 4}"#);
    w.write("cone.json", r#"{"kind": "cone", "radius": 3}"#);
    w.write("ball.json", r#"{"kind": "ball", "radius": 3}"#);
    w.write("cyl.json", r#"{"kind": "cylindrical-nonrotating", "radius": 3}"#);
    let go = |args: &[&str]| w.run(BIN, &[args, &["-o", "out.csv"]].concat(), b"");
    go(&["sphere.json", "--tool", "bull.json"])
        .fails(2, "bull.json:1:48 (corner_radius): corner_radius 4 exceeds the radius 3");
    go(&["sphere.json", "--tool", "cone.json"]).fails(2, "cone.json:1:1 (half_angle): a cone cutter needs half_angle");
    go(&["sphere.json", "--tool", "cyl.json"]).fails(2, "does not rotate");
    w.write("wall.json", r#"{"surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [1, 0, 0]}]}"#);
    go(&["wall.json", "--tool", "ball.json"])
        .fails(2, "wall.json: surface plane#0: a plane along the tool axis has no top for the cutter to rest on");
    go(&["sphere.json", "--tool", "ball.json", "--mode", "contour"]).fails(2, "--mode scan only");
    go(&["sphere.json", "--tool", "ball.json", "--axis", "0,0,0"]).fails(2, "--axis must be a nonzero direction");
    go(&["sphere.json", "--tool", "ball.json", "--region=20,30,20,30"]).fails(2, "misses the model");
    // Coordinates where round-off exceeds the contact tolerance, given or from the model.
    go(&["sphere.json", "--tool", "ball.json", "--region=-1e300,1e300,-1,1"])
        .fails(2, "sphere.json: the area the cutter drops onto within --region reaches 1e300 mm");
    w.write("far.json", r#"{"surfaces": [{"type": "sphere", "centre": [1e13, 0, 0], "radius": 10}]}"#);
    go(&["far.json", "--tool", "ball.json"]).fails(2, "within the model's bounding box (the default --region) reaches");
    assert!(!w.exists("out.csv"));
}

/// Issue 19: the ball stylus's stream says it holds stylus centres of radius r.
#[test]
fn the_stylus_stream_records_its_meaning() {
    let w = Work::new();
    w.write("sphere.json", r#"{"surfaces": [{"type": "sphere", "centre": [0, 0, 0], "radius": 10}]}"#);
    let out = w.run(BIN, &["sphere.json", "-r", "3", "--pick", "4"], b"");
    let text = out.ok();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (p, r) = (
        header.iter().position(|h| *h == "point").unwrap(),
        header.iter().position(|h| *h == "stylus_radius").unwrap(),
    );
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        assert_eq!((f[p], f[r]), ("stylus-centre", "3"));
    }
}

/// A stray vertex 12 km above a wavy field (one triangle turned into a needle, as a mangled STL
/// has it): the drops beside the needle no longer creep down its whole height (more than 60 s
/// of CPU before), and the scan still covers the envelope. Run under a 20 s CPU limit.
#[test]
fn a_needle_12_km_tall_is_traced_at_once() {
    let mut tris = as_f32(&wave());
    tris[300][1].z = 12_345.678;
    let w = Work::new();
    w.write("needle.stl", camkit::model::mesh::binary_stl(&tris));
    let run = std::process::Command::new("sh")
        .current_dir(w.path(""))
        .arg("-c")
        .arg("ulimit -t 20; exec \"$0\" needle.stl --mode scan -r 3 --pick 4 -o cl.csv --report r.json")
        .arg(e2e::bin(BIN))
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(0), "{}", String::from_utf8_lossy(&run.stderr));
    let mut r = report(&w, "r.json");
    r["exit_status"] = 0.into();
    let cl = rows(&w.read("cl.csv"));
    let stored = as_f32(&tris);
    let (gap, below) = coverage_along_x(&cl, 0.0, 60.0, &|x, y| drop_on_mesh(&stored, x, y, 3.0));
    assert_covered(&r, gap, below);
    assert!(cl.iter().any(|q| q.c.z > 1000.0), "no pass goes over the needle");
}
