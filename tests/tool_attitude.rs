//! End-to-end tests of `tool-attitude`: the built binary on contact streams generated on planes,
//! spheres and cylinders (closed forms for every tool), the rear gouge in a concave region
//! against its closed-form tilt, the flat-type tool against chord sagittas, real pipelines
//! `stylus-trace | tool-attitude | post-6axis`, and bad input refused with file, line and column.

use camkit::geom::{P3, V3};
use e2e::{Work, data};
use std::collections::HashMap;

const BIN: &str = "tool-attitude";

/// A table parsed by header name.
struct Rows {
    cols: HashMap<String, usize>,
    rows: Vec<Vec<String>>,
}

impl Rows {
    fn parse(csv: &str) -> Rows {
        let mut lines = csv.lines();
        let cols = lines.next().expect("header").split(',').enumerate().map(|(i, h)| (h.to_string(), i)).collect();
        Rows { cols, rows: lines.map(|l| l.split(',').map(str::to_string).collect()).collect() }
    }
    fn num(&self, k: usize, name: &str) -> f64 {
        let i = *self.cols.get(name).unwrap_or_else(|| panic!("no column {name}"));
        self.rows[k][i].parse().unwrap_or_else(|_| panic!("{name} in row {k}: {:?}", self.rows[k][i]))
    }
    fn p3(&self, k: usize, x: &str, y: &str, z: &str) -> P3 {
        P3::new(self.num(k, x), self.num(k, y), self.num(k, z))
    }
    fn tip(&self, k: usize) -> P3 {
        self.p3(k, "x", "y", "z")
    }
    fn axis(&self, k: usize) -> V3 {
        self.p3(k, "i", "j", "k").coords
    }
}

/// A contact stream (one path) from contact points and unit normals, stylus radius `r`.
fn stream(contacts: &[(P3, V3)], r: f64) -> String {
    let mut s = String::from("path,x,y,z,px,py,pz,nx,ny,nz\n");
    for (p, n) in contacts {
        let c = p + n * r;
        s += &format!("0,{},{},{},{},{},{},{},{},{}\n", c.x, c.y, c.z, p.x, p.y, p.z, n.x, n.y, n.z);
    }
    s
}

/// Contacts on a circle of radius `rho` about `centre` in the plane spanned by `u`, `w`, from
/// angle `a0` in `count` points `da` apart; `inward` normals point to the centre (concave).
fn circle(centre: P3, (u, w): (V3, V3), rho: f64, (a0, da, count): (f64, f64, usize), inward: bool) -> Vec<(P3, V3)> {
    (0..count)
        .map(|k| {
            let a = a0 + da * k as f64;
            let radial = u * a.cos() + w * a.sin();
            (centre + radial * rho, if inward { -radial } else { radial })
        })
        .collect()
}

/// The unit tangent of the generated path at row k (central differences of a uniformly sampled
/// circle are exactly tangent; the end rows are skipped by the checks).
fn tangent(c: &[(P3, V3)], k: usize) -> V3 {
    (c[k + 1].0 - c[k - 1].0).normalize()
}

fn angle(a: &V3, b: &V3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// A concave cylinder R 100 along y, lowest along the line x = 0, z = 0.
const CONCAVE_CYLINDER: &str =
    r#"{"surfaces": [{"type": "cylinder", "point": [0, 0, 100], "axis": [0, 1, 0], "radius": 100, "flip": true}]}"#;

const CYL: &str = r#"{"kind": "cylindrical-nonrotating", "radius": 12.5, "length": 40}"#;

#[test]
fn cylindrical_tool_closed_forms_on_plane_sphere_and_cylinder() {
    let w = Work::new();
    w.write("tool.json", CYL);
    let line: Vec<(P3, V3)> = (0..20).map(|k| (P3::new(k as f64, 0.5 * k as f64, 0.0), V3::z())).collect();
    let cases = [
        ("plane", r#"{"surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}]}"#, line),
        (
            "sphere",
            r#"{"surfaces": [{"type": "sphere", "centre": [0, 0, -50], "radius": 50}]}"#,
            circle(P3::new(0.0, 0.0, -50.0), (V3::new(0.6, 0.8, 0.0), V3::z()), 50.0, (1.2, 0.02, 20), false),
        ),
        (
            "trough",
            r#"{"surfaces": [{"type": "cylinder", "point": [0, 0, 400], "axis": [0, 1, 0], "radius": 400, "flip": true}]}"#,
            circle(P3::new(0.0, 3.0, 400.0), (V3::x(), V3::z()), 400.0, (-1.8, 0.01, 20), true),
        ),
    ];
    for (name, model, contacts) in &cases {
        w.write("m.json", model);
        w.write("cl.csv", stream(contacts, 12.5));
        let out = w.run(BIN, &["cl.csv", "--tool", "tool.json", "--model", "m.json", "--report", "r.json"], b"").ok();
        let t = Rows::parse(&out);
        assert_eq!(t.rows.len(), contacts.len());
        for k in 1..contacts.len() - 1 {
            let (p, n) = contacts[k];
            let (a, tip) = (t.axis(k), t.tip(k));
            assert!((a.norm() - 1.0).abs() < 1e-12, "{name}: axis unit");
            assert!((angle(&a, &n) - 5f64.to_radians()).abs() < 1e-9, "{name} row {k}: tilt");
            let f = tangent(contacts, k);
            assert!(a.dot(&n.cross(&f)).abs() < 1e-9, "{name} row {k}: axis in the plane of normal and feed");
            assert!(a.dot(&f) > 0.0, "{name}: θ < 0 leans the axis toward the feed");
            assert!(((tip - p).norm() - 12.5).abs() < 1e-9 && (tip - p).dot(&a).abs() < 1e-9, "{name}: tip");
            assert!((t.num(k, "r_edge") - 12.5 / 5f64.to_radians().sin()).abs() < 1e-9);
            assert!(t.num(k, "gouge") <= 1e-9, "{name}: no gouge");
            assert_eq!(t.num(k, "tilt"), -5.0);
            let s = t.num(k, "s");
            let edge = camkit::kinematics::edge_direction(&a, s);
            assert!((edge - (p - tip) / 12.5).norm() < 1e-9, "{name}: s turns the edge to the cutting point");
        }
    }
}

#[test]
fn rear_gouge_in_a_concave_region_takes_the_closed_form_tilt() {
    // Trough of radius ρ = 100: the tilted bottom face's rear rim point clears iff sin|θ| ≥ R/ρ.
    let w = Work::new();
    let rho = 100.0;
    w.write("m.json", CONCAVE_CYLINDER);
    let contacts = circle(P3::new(0.0, 0.0, rho), (V3::x(), V3::z()), rho, (-1.7, 0.01, 10), true);
    w.write("cl.csv", stream(&contacts, 12.5));
    w.write("tool.json", CYL);
    let args = ["cl.csv", "--tool", "tool.json", "--model", "m.json", "--gouge-tol", "1e-9", "--report", "r.json"];
    let t = Rows::parse(&w.run(BIN, &args, b"").ok());
    let expect = -(12.5f64 / rho).asin().to_degrees();
    for k in 0..t.rows.len() {
        assert!((t.num(k, "tilt") - expect).abs() < 1e-4, "row {k}: {} vs {expect}", t.num(k, "tilt"));
        assert!(t.num(k, "gouge") <= 1e-9);
    }
    let report: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
    assert_eq!(report["adjusted_rows"], 10);
    // A tool whose range stops at −6° cannot clear it: exit 1 naming the first row, no output.
    w.write("short.json", r#"{"kind": "cylindrical-nonrotating", "radius": 12.5, "tilt_range": [-6, 0]}"#);
    let bad = ["cl.csv", "--tool", "short.json", "--model", "m.json", "-o", "tool.csv"];
    w.run(BIN, &bad, b"").fails(1, "cl.csv:2: 10 row(s) gouge the model");
    assert!(!w.exists("tool.csv"));
    // --allow-gouge writes them with the depth, which is the rear rim point's at −5°.
    let mut allow = bad.to_vec();
    allow.push("--allow-gouge");
    let out = w.run(BIN, &allow, b"");
    assert_eq!(out.status, 0, "{}", out.stderr);
    let t = Rows::parse(&w.read("tool.csv"));
    let a = 5f64.to_radians();
    let depth = ((2.0 * 12.5 * a.cos()).powi(2) + (rho - 2.0 * 12.5 * a.sin()).powi(2)).sqrt() - rho;
    assert!((t.num(3, "gouge") - depth).abs() < 1e-9, "{} vs {depth}", t.num(3, "gouge"));
    assert_eq!(t.num(3, "tilt"), -5.0);
}

#[test]
fn ball_and_flat_end_mill_closed_forms_on_a_sphere() {
    let w = Work::new();
    let centre = P3::new(0.0, 0.0, -50.0);
    let contacts = circle(centre, (V3::new(0.6, 0.8, 0.0), V3::z()), 50.0, (1.0, 0.02, 15), false);
    w.write("cl.csv", stream(&contacts, 5.0));
    w.write("m.json", r#"{"surfaces": [{"type": "sphere", "centre": [0, 0, -50], "radius": 50}]}"#);
    let ball = w
        .run(
            BIN,
            &[
                "cl.csv",
                "--tool",
                data("tool-attitude/ball-r5.json").to_str().unwrap(),
                "--tilt",
                "10",
                "--model",
                "m.json",
            ],
            b"",
        )
        .ok();
    let t = Rows::parse(&ball);
    assert!(!t.cols.contains_key("s"), "a rotating tool has no spindle orientation");
    for k in 1..contacts.len() - 1 {
        let (p, n) = contacts[k];
        let a = t.axis(k);
        assert!((angle(&a, &n) - 10f64.to_radians()).abs() < 1e-9);
        assert!(a.dot(&tangent(&contacts, k)).abs() < 1e-9, "paper 003's tilt is across the feed");
        // Ball centre on the offset sphere of radius 55 along the normal; tip r below it.
        let c = t.tip(k) + a * 5.0;
        assert!((c - (p + n * 5.0)).norm() < 1e-9);
        assert!(((c - centre).norm() - 55.0).abs() < 1e-9);
        assert!(t.num(k, "gouge") <= 1e-9);
    }
    let flat = w.run(BIN, &["cl.csv", "--tool", data("tool-attitude/flat-r5.json").to_str().unwrap()], b"").ok();
    let t = Rows::parse(&flat);
    for (k, (p, n)) in contacts.iter().enumerate() {
        assert!((t.axis(k) - n).norm() < 1e-12 && (t.tip(k) - p).norm() < 1e-12);
        // Eq. 3–4 against the sphere's own angles: a = polar angle of the normal, c its azimuth from +y.
        let polar = (n.z).acos().to_degrees();
        assert!((t.num(k, "ac_a") - polar).abs() < 1e-9);
        assert!((t.num(k, "ac_c") - 0.6f64.atan2(0.8).to_degrees()).abs() < 1e-9);
    }
}

/// A floor z = 0 and an R25 sphere centred at z = 10: the stylus of radius 1 touches both on a
/// horizontal circle; the corner angle there is 180° − acos(−9/26).
fn corner_stream() -> String {
    let rs = 25.0f64;
    let cs = P3::new(0.0, 0.0, 10.0);
    let h = ((rs + 1.0).powi(2) - 81.0).sqrt();
    let mut s = String::from("path,x,y,z,px,py,pz,nx,ny,nz,surface,p2x,p2y,p2z,n2x,n2y,n2z,surface2\n");
    for k in 0..12 {
        let a = 0.05 * k as f64;
        let c = P3::new(h * a.cos(), h * a.sin(), 1.0);
        let n2 = (c - cs) / (rs + 1.0);
        let p2 = cs + n2 * rs;
        s += &format!(
            "0,{},{},{},{},{},0,0,0,1,floor,{},{},{},{},{},{},ball\n",
            c.x, c.y, c.z, c.x, c.y, p2.x, p2.y, p2.z, n2.x, n2.y, n2.z
        );
    }
    s
}

#[test]
fn flat_type_tool_lies_on_the_control_surface() {
    let w = Work::new();
    w.write("cl.csv", corner_stream());
    w.write(
        "m.json",
        r#"{"surfaces": [{"type": "plane", "name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]},
        {"type": "sphere", "name": "ball", "centre": [0, 0, 10], "radius": 25}]}"#,
    );
    w.write("t3.json", r#"{"kind": "flat-nonrotating", "radius": 5, "included_angle": 65, "flank_length": 3}"#);
    let corner = 180.0 - (-9.0f64 / 26.0).acos().to_degrees();
    // P1 on the floor: no control correction, the flank on the plane, the second flank off by
    // corner − 65°, the axis off the bisector by half of that.
    let t = Rows::parse(&w.run(BIN, &["cl.csv", "--tool", "t3.json", "--model", "m.json"], b"").ok());
    for k in 0..t.rows.len() {
        assert!((t.num(k, "tilt") - (65.0 - corner) / 2.0).abs() < 1e-9, "axis off the bisector by half the margin");
        assert!((t.num(k, "flank_gap") - (corner - 65.0)).abs() < 1e-9);
        assert!(t.num(k, "gouge") < 1e-9, "flank on the floor");
        let a = t.axis(k);
        assert!((a.norm() - 1.0).abs() < 1e-12);
        // Axis 32.5° up from the floor flank, which points away from the sphere.
        assert!((a.z - 32.5f64.to_radians().sin()).abs() < 1e-9);
        assert!(t.num(k, "s").is_finite());
    }
    // P3 on the sphere: the control point touches the offset sphere (R 26), the axis turns a
    // further asin(L / 2·26) toward it and the straight flank's chord sinks by the sagitta 26 − √(26² − (L/2)²).
    let out =
        w.run(BIN, &["cl.csv", "--tool", "t3.json", "--model", "m.json", "--control", "p3", "--allow-gouge"], b"");
    assert_eq!(out.status, 0);
    let t = Rows::parse(&out.out());
    let sag = 26.0 - (26.0f64.powi(2) - 1.5f64.powi(2)).sqrt();
    for k in 0..t.rows.len() {
        let expect = (65.0 - corner) / 2.0 - (3.0f64 / 52.0).asin().to_degrees();
        assert!((t.num(k, "tilt") - expect).abs() < 1e-5, "{} vs {expect}", t.num(k, "tilt"));
        assert!((t.num(k, "gouge") - sag).abs() < 1e-6, "{} vs {sag}", t.num(k, "gouge"));
    }
}

#[test]
fn pipelines_to_six_axis_nc() {
    let w = Work::new();
    // Sphere smoothing, a patch of the R500 sphere: stylus-trace | tool-attitude | post-6axis.
    let model = data("stylus-trace/sphere-smoothing.json");
    let model = model.to_str().unwrap();
    let cl = w
        .run("stylus-trace", &[model, "--mode", "scan", "-r", "12.5", "--pick", "2.5", "--region=-5,5,-5,5"], b"")
        .ok();
    let tool = data("tool-attitude/cylinder-phi25.json");
    let out = w.run(BIN, &["--tool", tool.to_str().unwrap(), "--model", model], cl.as_bytes()).ok();
    let t = Rows::parse(&out);
    assert!(t.rows.len() > 10);
    let centre = P3::new(0.0, 0.0, -500.0);
    for k in 0..t.rows.len() {
        let p = t.p3(k, "px", "py", "pz");
        let n = (p - centre) / 500.0;
        assert!((angle(&t.axis(k), &n) - 5f64.to_radians()).abs() < 1e-9);
        assert!(((t.tip(k) - p).norm() - 12.5).abs() < 1e-9);
        assert!((t.num(k, "r_edge") - 143.42141557).abs() < 1e-6, "paper 000: R' at −5°");
    }
    w.write("tool.csv", &out);
    let machine = data("post-6axis/paper000-sixaxis-b.json");
    let nc = w.run("post-6axis", &["tool.csv", "--machine", machine.to_str().unwrap(), "--feed", "1000"], b"").ok();
    assert!(nc.lines().any(|l| l.starts_with("G0 ") && l.contains(" B")), "spindle orientation as B");
    // Concave remainder: the two-surface trace | the flat-type tool with the model.
    let model = data("stylus-trace/concave-remainder.json");
    let model = model.to_str().unwrap();
    let cl = w
        .run(
            "stylus-trace",
            &[model, "--mode", "two-surface", "--surfaces", "free-form,R25", "-r", "1", "--chord-tol", "0.01"],
            b"",
        )
        .ok();
    let tool = data("tool-attitude/flat-type.json");
    w.write("r.json", "");
    let out =
        w.run(BIN, &["--tool", tool.to_str().unwrap(), "--model", model, "--report", "r.json"], cl.as_bytes()).ok();
    let report: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
    assert_eq!(report["gouge_rows"], 0);
    // The flanks' wedge against the solid (was 16 probes a flank): the flank on the B-spline keeps
    // the stylus radius off to within its largest gouge, 0.82 µm (the probes: 0.826 µm).
    assert_eq!(report["gouge_check"], "body");
    let largest = report["largest_gouge_mm"].as_f64().unwrap();
    assert!(largest > 0.0005 && largest < 0.001, "largest gouge {largest}");
    assert!(report["flank_gap_min_deg"].as_f64().unwrap() > 4.0);
    w.write("tool2.csv", &out);
    let machine = data("post-6axis/paper000-sixaxis-m19.json");
    let nc = w.run("post-6axis", &["tool2.csv", "--machine", machine.to_str().unwrap(), "--feed", "500"], b"").ok();
    assert!(nc.contains("M19 R"));
}

#[test]
fn edge_radius_chooses_the_tilt() {
    let w = Work::new();
    w.write("tool.json", CYL);
    let contacts: Vec<(P3, V3)> = (0..3).map(|k| (P3::new(k as f64, 0.0, 0.0), V3::z())).collect();
    w.write("cl.csv", stream(&contacts, 12.5));
    let re = format!("{}", 12.5 / 20f64.to_radians().sin());
    let t = Rows::parse(&w.run(BIN, &["cl.csv", "--tool", "tool.json", "--edge-radius", &re], b"").ok());
    assert!((t.num(0, "tilt") + 20.0).abs() < 1e-9, "36.5 mm is the paper's −20°");
    w.run(BIN, &["cl.csv", "--tool", "tool.json", "--edge-radius", "30"], b"").fails(2, "--edge-radius 30");
    // With a depth of cut, eq. 1 itself: R' = 200 at T = 0.02 mm.
    let t = Rows::parse(
        &w.run(BIN, &["cl.csv", "--tool", "tool.json", "--edge-radius", "200", "--cut-depth", "0.02"], b"").ok(),
    );
    assert!((t.num(0, "r_edge") - 200.0).abs() < 1e-9);
}

#[test]
fn bad_input_is_refused_with_its_place() {
    let w = Work::new();
    w.write("tool.json", CYL);
    let ok: Vec<(P3, V3)> = (0..3).map(|k| (P3::new(k as f64, 0.0, 0.0), V3::z())).collect();
    let run = |csv: &str, extra: &[&str]| {
        w.write("cl.csv", csv);
        let mut args = vec!["cl.csv", "--tool", "tool.json", "-o", "out.csv"];
        args.extend_from_slice(extra);
        w.run(BIN, &args, b"")
    };
    // A path of one row: no feed direction.
    let one = "path,x,y,z,px,py,pz,nx,ny,nz\n0,0,0,12.5,0,0,0,0,0,1\n1,1,0,12.5,1,0,0,0,0,1\n1,2,0,12.5,2,0,0,0,0,1\n";
    run(one, &[]).fails(2, "cl.csv:2: path 0 has 1 row");
    // A non-unit normal: line and column of nx.
    let bad = stream(&ok, 12.5).replace(",1,0,0,0,0,1\n", ",1,0,0,0,0,1.5\n");
    run(&bad, &[]).fails(2, "cl.csv:3:8 (nx): the normal (0, 0, 1.5) is not a unit vector");
    let zero = stream(&ok, 12.5).replacen("0,0,1\n", "0,0,0\n", 1);
    run(&zero, &[]).fails(2, "cl.csv:2:8 (nx)");
    run("path,x,y,z\n0,1,2,3\n", &[]).fails(2, "missing column `px`");
    run(&stream(&ok, 12.5).replacen("0,0,1\n", "0,0,nan\n", 1), &[]).fails(2, "cl.csv:2:10 (nz)");
    run(&stream(&ok, 12.5), &["--tilt", "-25"]).fails(2, "tilt -25° is outside the tool's range [-20, 0]");
    run(&stream(&ok, 12.5), &["--tilt", "3"]).fails(2, "outside the tool's range");
    w.write("tool.json", r#"{"kind": "cylindrical-nonrotating"}"#);
    run(&stream(&ok, 12.5), &[]).fails(2, "missing field `radius`");
    w.write("tool.json", r#"{"kind": "flat-nonrotating", "radius": 5, "included_angle": 60}"#);
    run(&stream(&ok, 12.5), &[]).fails(2, "tool.json:1:1 (flank_length)");
    w.write("tool.json", r#"{"kind": "flat-nonrotating", "radius": 5, "included_angle": 60, "flank_length": 2}"#);
    run(&stream(&ok, 12.5), &[]).fails(2, "missing column `p2x`");
    w.write("tool.json", r#"{"kind": "bull", "radius": 5, "corner_radius": 1}"#);
    run(&stream(&ok, 12.5), &[]).fails(2, "tool.json:1:10 (kind)");
    assert!(!w.exists("out.csv"), "nothing written on bad input");
}

#[test]
fn output_is_the_same_for_any_thread_count() {
    let w = Work::new();
    w.write("m.json", CONCAVE_CYLINDER);
    let contacts = circle(P3::new(0.0, 0.0, 100.0), (V3::x(), V3::z()), 100.0, (-1.7, 0.01, 40), true);
    w.write("cl.csv", stream(&contacts, 12.5));
    w.write("tool.json", CYL);
    let run = |threads: &str| {
        let out = std::process::Command::new(e2e::bin(BIN))
            .args(["cl.csv", "--tool", "tool.json", "--model", "m.json"])
            .current_dir(w.path(""))
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .expect("run");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        out.stdout
    };
    assert_eq!(run("1"), run("3"));
}

/// `--axis`: a ball end mill on a fixed axis from a stylus trace of a sphere (stylus of the tool's
/// radius): every tip 3 below its stylus centre, the ball tangent to the sphere (its centre 53 from
/// the sphere's), no gouge by the model check; a tilted fixed axis moves the tip along it; flat
/// tools, zero and malformed axes, and --axis with --tilt are refused.
#[test]
fn fixed_axis_ball_tips_from_a_stylus_trace() {
    let w = Work::new();
    w.write("sphere.json", r#"{"surfaces": [{"type": "sphere", "centre": [0, 0, -50], "radius": 50}]}"#);
    w.write("ball.json", r#"{"kind": "ball", "radius": 3, "length": 20}"#);
    w.write("flat.json", r#"{"kind": "flat", "radius": 3}"#);
    let cl = w
        .run("stylus-trace", &["sphere.json", "--mode", "scan", "-r", "3", "--pick", "4", "--region=-20,20,-8,8"], b"")
        .ok();
    w.write("cl.csv", &cl);
    let out = w
        .run(
            BIN,
            &["cl.csv", "--tool", "ball.json", "--axis", "0,0,1", "--model", "sphere.json", "--report", "r.json"],
            b"",
        )
        .ok();
    let (c, s) = (Rows::parse(&out), Rows::parse(&cl));
    assert_eq!(c.rows.len(), s.rows.len());
    assert!(c.rows.len() > 50);
    for k in 0..c.rows.len() {
        let (tip, centre) = (c.tip(k), s.tip(k));
        assert!((centre - tip - V3::new(0.0, 0.0, 3.0)).norm() < 1e-9, "row {k}");
        assert!((((tip + V3::new(0.0, 0.0, 3.0)) - P3::new(0.0, 0.0, -50.0)).norm() - 53.0).abs() < 1e-6);
        assert!((c.axis(k) - V3::z()).norm() < 1e-12);
    }
    let r: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
    assert!(r["largest_gouge_mm"].as_f64().unwrap() < 1e-6, "{r}");
    let tilted = w.run(BIN, &["cl.csv", "--tool", "ball.json", "--axis", "0,3,4"], b"").ok();
    let t = Rows::parse(&tilted);
    assert!((s.tip(0) - t.tip(0) - V3::new(0.0, 1.8, 2.4)).norm() < 1e-9);
    w.run(BIN, &["cl.csv", "--tool", "flat.json", "--axis", "0,0,1"], b"")
        .fails(2, "flat.json:1:10 (kind): --axis (a fixed axis) takes a ball end mill");
    w.run(BIN, &["cl.csv", "--tool", "ball.json", "--axis", "0,0,0"], b"")
        .fails(2, "--axis must be a nonzero direction");
    w.run(BIN, &["cl.csv", "--tool", "ball.json", "--axis", "0,1"], b"").fails(2, "--axis takes three numbers");
    let o = w.run(BIN, &["cl.csv", "--tool", "ball.json", "--axis", "0,0,1", "--tilt", "3"], b"");
    assert_eq!(o.status, 2, "{}", o.stderr);
}

/// Contacts along x on the floor z = 0 (normal +z) from `x0` every `dx`, `count` of them.
fn floor_line(x0: f64, dx: f64, count: usize) -> Vec<(P3, V3)> {
    (0..count).map(|k| (P3::new(x0 + dx * k as f64, 0.0, 0.0), V3::z())).collect()
}

/// Distance from `q` to the solid flat-bottomed cylinder of radius `r` standing `length` on
/// `tip` along unit `axis` (0 inside).
fn distance_to_cylinder(q: &P3, tip: &P3, axis: &V3, r: f64, length: f64) -> f64 {
    let d = q - tip;
    let h = d.dot(axis);
    let rho = (d - axis * h).norm();
    (rho - r).max(0.0).hypot((-h).max(h - length).max(0.0))
}

/// A bump (sphere) standing out of a floor (plane) beside the tool's bottom face: the tool is
/// checked against both surfaces as one solid, not against the nearest surface alone, so the
/// rows where the bump is under the face gouge (exit 1 naming the first), and every row's gouge
/// figure is the bump's depth in the tool (closed form: radius less the centre's distance from
/// the solid cylinder). Today's probes took the sign from the floor and saw nothing.
#[test]
fn a_bump_out_of_a_floor_is_found_under_the_bottom_face() {
    let w = Work::new();
    let (centre, rb) = (P3::new(50.0, 8.0, -0.5), 2.0);
    w.write(
        "m.json",
        r#"{"surfaces": [{"type": "plane", "name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]},
            {"type": "sphere", "name": "bump", "centre": [50, 8, -0.5], "radius": 2}]}"#,
    );
    w.write("cl.csv", stream(&floor_line(20.0, 1.0, 61), 12.5));
    w.write("tool.json", CYL);
    let args = ["cl.csv", "--tool", "tool.json", "--tilt=-5", "--model", "m.json", "-o", "t.csv"];
    w.run(BIN, &args, b"").fails(1, "row(s) gouge the model");
    assert!(!w.exists("t.csv"));
    let mut allow = args.to_vec();
    allow.extend(["--allow-gouge", "--report", "r.json"]);
    assert_eq!(w.run(BIN, &allow, b"").status, 0);
    let t = Rows::parse(&w.read("t.csv"));
    let mut gouging = 0;
    for k in 0..t.rows.len() {
        let depth = rb - distance_to_cylinder(&centre, &t.tip(k), &t.axis(k).normalize(), 12.5, 40.0);
        let g = t.num(k, "gouge");
        assert!((g - depth.max(0.0)).abs() < 1e-6, "row {k}: gouge {g}, the bump is {depth} inside");
        gouging += usize::from(g > 0.001);
    }
    let report: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
    assert!(gouging > 0 && report["gouge_rows"] == gouging, "{gouging} {}", report["gouge_rows"]);
    assert!(report["largest_gouge_mm"].as_f64().unwrap() > 1.0);
    assert_eq!(report["gouge_check"], "body");
}

/// A closed prism of `n` sides round the x axis segment 0..100 at (y, z), radius `r` to its
/// edges, one edge towards −y; faces turned outwards.
fn rod_stl(y: f64, z: f64, r: f64, n: usize) -> Vec<u8> {
    let ring = |x: f64| -> Vec<P3> {
        (0..n)
            .map(|k| {
                let a = -std::f64::consts::FRAC_PI_2 + std::f64::consts::TAU * k as f64 / n as f64;
                P3::new(x, y + r * a.cos(), z + r * a.sin())
            })
            .collect()
    };
    let (a, b) = (ring(0.0), ring(100.0));
    let (ca, cb) = (P3::new(0.0, y, z), P3::new(100.0, y, z));
    let mut tris = Vec::new();
    for k in 0..n {
        let m = (k + 1) % n;
        tris.push([a[k], b[m], b[k]]);
        tris.push([a[k], a[m], b[m]]);
        tris.push([ca, a[m], a[k]]);
        tris.push([cb, b[k], b[m]]);
    }
    camkit::model::mesh::binary_stl(&tris)
}

/// A 1 mm rod (a closed 32-sided prism along x) 0.3 mm inside the side of the φ25 cylinder at
/// heights between and on the old probe rings (10 and 11.05 mm of a 40 mm body; 4 rings 10 mm
/// apart): found on every row at its depth, no tilt clears it (tilting toward the feed does
/// not move the side across the rod), and the run fails naming the first row.
#[test]
fn a_rod_beside_the_tool_side_is_found_at_any_height() {
    for zr in [10.0, 11.05, 20.0, 37.0] {
        let w = Work::new();
        w.write("rod.stl", rod_stl(12.7, zr, 0.5, 32));
        w.write(
            "m.json",
            r#"{"surfaces": [{"type": "plane", "name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]},
                {"type": "stl", "name": "rod", "file": "rod.stl"}]}"#,
        );
        w.write("cl.csv", stream(&floor_line(44.0, 0.25, 37), 12.5));
        w.write("tool.json", CYL);
        let args = ["cl.csv", "--tool", "tool.json", "--tilt=-5", "--model", "m.json", "-o", "t.csv"];
        w.run(BIN, &args, b"").fails(1, "cl.csv:2: 37 row(s) gouge the model");
        let mut allow = args.to_vec();
        allow.push("--allow-gouge");
        assert_eq!(w.run(BIN, &allow, b"").status, 0);
        let t = Rows::parse(&w.read("t.csv"));
        for k in 0..t.rows.len() {
            // The rod's edge line (y = 12.2) against the tool's side (12.5 from its axis, which
            // lies in the plane y = 0): 0.3 inside wherever the rod's height meets the body.
            assert!((t.num(k, "gouge") - 0.3).abs() < 1e-6, "rod at {zr}, row {k}: {}", t.num(k, "gouge"));
        }
    }
}

/// Issue 19: a model STL with a zero-area sliver and a repeated facet (a box as OpenSCAD leaves
/// it) is gouge-checked like the clean box, with one warning and the counts in the report;
/// `--strict` refuses it naming the facet.
#[test]
fn model_stl_slivers_are_dropped_with_a_warning_or_refused_strictly() {
    let w = Work::new();
    let (lo, hi) = ([0.0, 0.0, 0.0], [30.0, 20.0, 10.0]);
    let c = |i: usize| P3::new([lo[0], hi[0]][i & 1], [lo[1], hi[1]][(i >> 1) & 1], [lo[2], hi[2]][(i >> 2) & 1]);
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut tris: Vec<[P3; 3]> =
        quads.iter().flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]]).collect();
    w.write("box.stl", camkit::model::mesh::binary_stl(&tris));
    tris.insert(5, [c(4), P3::new(10.0, 0.0, 10.0), c(5)]);
    tris.push(tris[2]);
    w.write("scad.stl", camkit::model::mesh::binary_stl(&tris));
    w.write("ball.json", r#"{"kind": "ball", "radius": 3, "length": 20}"#);
    let cl = w.run("stylus-trace", &["box.stl", "-r", "3", "--pick", "4"], b"").ok();
    w.write("cl.csv", &cl);
    let args = |model: &'static str, report: &'static str| {
        ["cl.csv", "--tool", "ball.json", "--axis", "0,0,1", "--model", model, "--report", report]
    };
    let clean = w.run(BIN, &args("box.stl", "box.json"), b"");
    let scad = w.run(BIN, &args("scad.stl", "scad.json"), b"");
    assert_eq!(scad.ok(), clean.ok());
    assert_eq!(
        scad.stderr.trim_end(),
        "tool-attitude: warning: scad.stl: 1 zero-area facets (the first facet 6) and 1 duplicate facets (the first facet 14, a repeat of facet 3) dropped (--strict refuses them)"
    );
    let r: serde_json::Value = serde_json::from_str(&w.read("scad.json")).unwrap();
    assert_eq!((r["degenerate_facets_dropped"].as_u64(), r["duplicate_facets_dropped"].as_u64()), (Some(1), Some(1)));
    assert!(r["largest_gouge_mm"].as_f64().unwrap() < 1e-6, "{r}");
    w.run(BIN, &[&args("scad.stl", "s.json")[..], &["--strict"]].concat(), b"")
        .fails(2, "scad.stl (facet 6): degenerate triangle (zero area)");
}

/// Issue 19: the stream says which stylus traced it. A ball of another radius is refused (exit 2,
/// naming both radii), with and without --axis; the output says `point` = tip and post-6axis
/// takes it, while it refuses the stylus-centre stream itself.
#[test]
fn the_stylus_radius_recorded_in_the_stream_must_be_the_balls() {
    let w = Work::new();
    w.write("sphere.json", r#"{"surfaces": [{"type": "sphere", "centre": [0, 0, 0], "radius": 10}]}"#);
    w.write("ball3.json", r#"{"kind": "ball", "radius": 3}"#);
    w.write("ball5.json", r#"{"kind": "ball", "radius": 5}"#);
    let cl = w.run("stylus-trace", &["sphere.json", "-r", "3", "--pick", "4", "--region=-5,5,-5,5"], b"").ok();
    w.write("cl.csv", &cl);
    let needle = "ball5.json:1:28 (radius): the tool's radius 5 mm differs from the radius 3 mm of the stylus that traced cl.csv";
    w.run(BIN, &["cl.csv", "--tool", "ball5.json", "--axis", "0,0,1", "-o", "tip.csv"], b"").fails(2, needle);
    w.run(BIN, &["cl.csv", "--tool", "ball5.json", "-o", "tip.csv"], b"").fails(2, needle);
    assert!(!w.exists("tip.csv"));
    let machine = data("post-6axis/three-axis.json");
    let machine = machine.to_str().unwrap();
    w.run("post-6axis", &["cl.csv", "--machine", machine, "--feed", "1000", "-o", "cl.nc"], b"").fails(
        2,
        "cl.csv:2 (point): the stream's x,y,z are the centres of a stylus of radius 3 mm (column point = stylus-centre), not tool tips: the program would cut 3 mm in the air; run tool-attitude on it first",
    );
    assert!(!w.exists("cl.nc"));
    let tips = w.run(BIN, &["cl.csv", "--tool", "ball3.json", "--axis", "0,0,1", "-o", "tip.csv"], b"");
    tips.ok();
    let t = Rows::parse(&w.read("tip.csv"));
    assert!(!t.cols.contains_key("stylus_radius"));
    assert!(t.rows.iter().all(|r| r[t.cols["point"]] == "tip"));
    // Tips given back to --axis would be lowered a second time: refused.
    w.run(BIN, &["tip.csv", "--tool", "ball3.json", "--axis", "0,0,1"], b"").fails(2, "tool tips already");
    w.run("post-6axis", &["tip.csv", "--machine", machine, "--feed", "1000", "-o", "tip.nc"], b"").ok();
    // The tilted ball takes the stream too and marks its rows tips.
    let out = w.run(BIN, &["cl.csv", "--tool", "ball3.json"], b"").ok();
    let t = Rows::parse(&out);
    assert!(t.rows.iter().all(|r| r[t.cols["point"]] == "tip") && !t.cols.contains_key("stylus_radius"));
}

/// `--axis` streams the table in chunks of 16 384 rows: 40 000 stylus centres over a floor, the
/// last 5 000 sunk 0.5 mm into it, give every tip 3 below its centre, the gouges from the first
/// sunk row (named by its line) on, and the same table whatever the thread count.
#[test]
fn fixed_axis_streams_across_chunks() {
    let w = Work::new();
    w.write("floor.json", r#"{"surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}]}"#);
    w.write("ball.json", r#"{"kind": "ball", "radius": 3, "length": 20}"#);
    let mut cl = String::from("path,x,y,z,point,stylus_radius\n");
    for k in 0..40_000 {
        let z = if k >= 35_000 { 2.5 } else { 3.0 };
        cl.push_str(&format!("{},{},{},{z},stylus-centre,3\n", k / 1000, (k % 1000) as f64 * 0.1, k / 1000));
    }
    w.write("cl.csv", &cl);
    let args = ["cl.csv", "--tool", "ball.json", "--axis", "0,0,1", "--model", "floor.json", "--allow-gouge"];
    let run = |threads: &str| {
        std::process::Command::new(e2e::bin(BIN))
            .args(args)
            .args(["--report", "r.json"])
            .current_dir(w.path(""))
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .expect("run")
    };
    let (one, three) = (run("1"), run("3"));
    assert_eq!(one.stdout, three.stdout);
    let stderr = String::from_utf8_lossy(&three.stderr);
    assert!(stderr.contains("cl.csv:35002: 5000 row(s) gouge the model"), "{stderr}");
    let out = String::from_utf8(three.stdout).unwrap();
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "path,x,y,z,i,j,k,point,gouge");
    assert_eq!(lines.len(), 40_001);
    for (k, line) in lines[1..].iter().enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let (z, gouge): (f64, f64) = (f[3].parse().unwrap(), f[8].parse().unwrap());
        let sunk = k >= 35_000;
        assert_eq!(z, if sunk { -0.5 } else { 0.0 }, "row {k}");
        assert!((gouge - if sunk { 0.5 } else { 0.0 }).abs() < 1e-6, "row {k}: gouge {gouge}");
        assert_eq!(f[7], "tip");
    }
    let r: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
    assert_eq!(
        (r["rows"].as_u64(), r["paths"].as_u64(), r["gouge_rows"].as_u64()),
        (Some(40_000), Some(40), Some(5000))
    );
    // Without --allow-gouge: exit 1 naming the first sunk row, no output.
    w.run(BIN, &[&args[..7], &["-o", "t.csv"]].concat(), b"").fails(1, "cl.csv:35002: 5000 row(s) gouge");
    assert!(!w.exists("t.csv"));
}

/// The tilt modes stream pass by pass (a row's feed direction needs its neighbours): whole passes
/// are solved in parallel once a chunk's worth of rows waits. Thirty passes across a concave
/// cylinder, solved as one chunk (the default holds them all: the whole-program answer), one pass
/// at a time and seven rows at a time, on one thread and on three, give the same table and
/// figures; a bad row in the last pass is still refused with its line, and nothing is written.
#[test]
fn tilt_modes_stream_pass_by_pass() {
    let w = Work::new();
    w.write("m.json", CONCAVE_CYLINDER);
    w.write("tool.json", CYL);
    let mut cl = String::from("path,x,y,z,px,py,pz,nx,ny,nz\n");
    for pass in 0..30 {
        let contacts = circle(P3::new(0.0, pass as f64, 100.0), (V3::x(), V3::z()), 100.0, (-1.7, 0.01, 40), true);
        for (p, n) in &contacts {
            let c = p + n * 12.5;
            cl += &format!("{pass},{},{},{},{},{},{},{},{},{}\n", c.x, c.y, c.z, p.x, p.y, p.z, n.x, n.y, n.z);
        }
    }
    w.write("cl.csv", &cl);
    let run = |threads: &str, chunk: Option<&str>| {
        let mut c = std::process::Command::new(e2e::bin(BIN));
        c.args(["cl.csv", "--tool", "tool.json", "--model", "m.json", "--report", "r.json"]);
        if let Some(n) = chunk {
            c.args(["--chunk-rows", n]);
        }
        let out = c.current_dir(w.path("")).env("RAYON_NUM_THREADS", threads).output().expect("run");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let mut r: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
        for k in ["seconds", "solve_seconds", "rows_per_second", "threads"] {
            r.as_object_mut().unwrap().remove(k);
        }
        (out.stdout, r)
    };
    let whole = run("3", None);
    assert_eq!(whole.1["rows"].as_u64(), Some(1200));
    assert_eq!(whole.1["paths"].as_u64(), Some(30));
    assert_eq!(String::from_utf8_lossy(&whole.0).lines().count(), 1201);
    for (threads, chunk) in [("1", None), ("1", Some("1")), ("3", Some("1")), ("3", Some("7")), ("1", Some("40"))] {
        let got = run(threads, chunk);
        assert!(got.0 == whole.0, "table differs on {threads} threads, chunks of {chunk:?} rows");
        assert_eq!(got.1, whole.1, "report on {threads} threads, chunks of {chunk:?} rows");
    }
    // The last pass's 20th row without its normal: refused by line, in any chunking.
    let mut bad: Vec<String> = cl.lines().map(str::to_string).collect();
    let line = 1 + 29 * 40 + 20;
    let f: Vec<&str> = bad[line - 1].split(',').collect();
    bad[line - 1] = format!("{},,,", f[..7].join(","));
    w.write("bad.csv", bad.join("\n") + "\n");
    for chunk in ["1", "16384"] {
        w.run(BIN, &["bad.csv", "--tool", "tool.json", "--chunk-rows", chunk, "-o", "out.csv"], b"")
            .fails(2, &format!("bad.csv:{line}:8 (nx): empty contact point or normal"));
        assert!(!w.exists("out.csv"));
    }
}
