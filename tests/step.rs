//! End-to-end tests of STEP models (data/step, made by `freecadcmd scripts/step-models.py`):
//! `stylus-trace` on STEP faces against the same surfaces as a model JSON document and against
//! closed forms, the B-spline face's CL identical to the model JSON's, and bad STEP input refused
//! with one line (exit 2) or, with --skip-unsupported, the face left out with a warning.

use camkit::geom::{P3, V3};
use camkit::num::golden_arg;
use e2e::{Outcome, Work, data};

const BIN: &str = "stylus-trace";

/// What the issue promises on analytic faces: 0.1 µm.
const EXACT: f64 = 1e-4;

/// Rows of a CL table as name → text maps.
fn table(text: &str) -> Vec<Vec<(String, String)>> {
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().expect("header").split(',').map(str::to_string).collect();
    lines.map(|l| header.iter().cloned().zip(l.split(',').map(str::to_string)).collect()).collect()
}

fn num(row: &[(String, String)], key: &str) -> f64 {
    row.iter().find(|(k, _)| k == key).map(|(_, v)| v.parse().unwrap()).unwrap_or_else(|| panic!("no {key}"))
}

fn text<'a>(row: &'a [(String, String)], key: &str) -> &'a str {
    row.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str()).unwrap()
}

fn p3(row: &[(String, String)], x: &str, y: &str, z: &str) -> P3 {
    P3::new(num(row, x), num(row, y), num(row, z))
}

/// The signed distance of a point from a closed-form surface.
type Offset = dyn Fn(&P3) -> f64;

/// Traces `model` (a path under data/) over `region` with a stylus of radius 3.
fn trace(w: &Work, model: &str, region: &str, out: &str) -> Vec<Vec<(String, String)>> {
    trace_picked(w, model, region, out, "2")
}

/// [`trace`] with scan lines `pick` mm apart.
fn trace_picked(w: &Work, model: &str, region: &str, out: &str, pick: &str) -> Vec<Vec<(String, String)>> {
    let m = data(model).display().to_string();
    let region = format!("--region={region}");
    w.run(BIN, &[&m, "-r", "3", "--pick", pick, &region, "--contact-tol", "1e-6", "-q", "-o", out], b"").ok();
    table(&w.read(out))
}

/// The STEP halves of a sphere, a cylinder and a torus (faces.step) against the same surfaces as a
/// model JSON document (faces.json): over each, the CL points are those of the JSON model (the
/// same points on the sphere and the cylinder; on the torus, whose steps round differently near
/// its axis, each on the closed-form CL surface) and within 0.1 µm of the closed form.
#[test]
fn step_faces_agree_with_the_analytic_model() {
    let w = Work::new();
    let cases: [(&str, &Offset); 3] = [
        ("-15,15,-15,15", &|c: &P3| c.coords.norm() - 20.0),
        ("45,95,-12,12", &|c: &P3| c.y.hypot(c.z) - 10.0),
        ("-14,14,48,72", &|c: &P3| (c.x.hypot(c.y - 60.0) - 10.0).hypot(c.z) - 6.0),
    ];
    for (k, (region, off)) in cases.iter().enumerate() {
        let step = trace(&w, "step/faces.step", region, "s.csv");
        let json = trace(&w, "step/faces.json", region, "j.csv");
        assert!(step.len() > 300 && step.len() == json.len(), "{region}: {} vs {} rows", step.len(), json.len());
        let worst = step.iter().map(|r| (off(&p3(r, "x", "y", "z")) - 3.0).abs()).fold(0.0, f64::max);
        assert!(worst <= EXACT, "{region}: CL off the closed form by {worst}");
        if k < 2 {
            for (a, b) in step.iter().zip(&json) {
                let d = (p3(a, "x", "y", "z") - p3(b, "x", "y", "z")).norm();
                assert!(d <= 1e-12, "{region}: STEP and JSON CL differ by {d}");
            }
        }
    }
}

/// A scan line grazing a face's side: faces.step's roof (a half cylinder of radius 10 over z ≥ 0)
/// is touched by the stylus on the line y = 13 only at its equator, exactly r away. The tracer may
/// pass such a contact by the contact tolerance, so the coverage check names no gap there (it named
/// the whole line, 60 mm, and exited 1); the line before it is traced on the offset cylinder.
#[test]
fn a_scan_line_grazing_a_face_is_no_gap() {
    let w = Work::new();
    let m = data("step/faces.step").display().to_string();
    w.run(BIN, &[&m, "-r", "3", "--pick", "0.5", "--region=40,100,12.5,13.5", "-q", "-o", "g.csv"], b"").ok();
    let rows = table(&w.read("g.csv"));
    let before = rows.iter().filter(|r| (num(r, "y") - 12.5).abs() < 1e-9).count();
    assert!(before > 20, "{before} rows on y = 12.5");
    let worst = rows.iter().map(|r| (num(r, "y").hypot(num(r, "z")) - 13.0).abs()).fold(0.0, f64::max);
    assert!(worst <= 1e-4, "CL off the offset cylinder by {worst}");
    assert!(rows.iter().all(|r| num(r, "y") <= 13.0 + 1e-9), "a row beyond the roof's shadow");
}

/// A B-spline face (natural boundary) and the same surface as a model JSON document: identical CL.
#[test]
fn bspline_face_gives_the_json_models_cl() {
    let w = Work::new();
    let step = trace(&w, "step/bspline.step", "0,60,0,40", "s.csv");
    let json = trace(&w, "step/bspline.json", "0,60,0,40", "j.csv");
    assert!(step.len() > 500 && step.len() == json.len(), "{} vs {} rows", step.len(), json.len());
    for (a, b) in step.iter().zip(&json) {
        for ((ka, va), (_, vb)) in a.iter().zip(b) {
            if ka != "surface" {
                assert_eq!(va, vb, "column {ka}");
            }
        }
    }
}

/// The block (planes, R8 corner cylinders, the R40 dish, the R6 hole and its R2 torus rim)
/// traced whole: every contact lies on its face's closed-form surface, the stylus centre r from
/// it, and where the contact is inside a face (along the normal) the closed-form distance of the
/// centre from that surface is r within 0.1 µm.
#[test]
fn block_against_closed_forms() {
    let w = Work::new();
    let rows = trace(&w, "step/block.step", "0,100,0,100", "b.csv");
    let dish = P3::new(50.0, 50.0, 70.0);
    let corners = [(8.0, 8.0), (92.0, 8.0), (92.0, 92.0), (8.0, 92.0)];
    let mut seen = std::collections::BTreeMap::new();
    for r in &rows {
        let (c, p, n) = (p3(r, "x", "y", "z"), p3(r, "px", "py", "pz"), p3(r, "nx", "ny", "nz").coords);
        let kind = text(r, "surface").split('#').next().unwrap().to_string();
        // Signed distance of a point from the face's surface (closed form) and its outward normal.
        let surface = |q: &P3| -> (f64, V3) {
            match kind.as_str() {
                "sphere" => (40.0 - (q - dish).norm(), (dish - q).normalize()),
                "torus" => {
                    let (dx, dy) = (q.x - 85.0, q.y - 85.0);
                    let rho = dx.hypot(dy);
                    let tube = P3::new(85.0 + dx / rho * 8.0, 85.0 + dy / rho * 8.0, 38.0);
                    ((q - tube).norm() - 2.0, (q - tube).normalize())
                }
                "cylinder" => {
                    let hole = (p.x - 85.0).hypot(p.y - 85.0);
                    if (hole - 6.0).abs() < 1e-6 {
                        let d = V3::new(85.0 - q.x, 85.0 - q.y, 0.0);
                        (6.0 - (q.x - 85.0).hypot(q.y - 85.0), d.normalize())
                    } else {
                        let (cx, cy) = *corners
                            .iter()
                            .min_by(|a, b| {
                                let da = (p.x - a.0).hypot(p.y - a.1);
                                let db = (p.x - b.0).hypot(p.y - b.1);
                                da.total_cmp(&db)
                            })
                            .unwrap();
                        let d = V3::new(q.x - cx, q.y - cy, 0.0);
                        (d.norm() - 8.0, d.normalize())
                    }
                }
                _ => {
                    // One of the block's planes: its sides, top, bottom and the hole's floor.
                    let planes = [(0, 0.0), (0, 100.0), (1, 0.0), (1, 100.0), (2, 0.0), (2, 40.0), (2, 25.0)];
                    (planes.iter().map(|(k, v)| (q[*k] - v).abs()).fold(f64::INFINITY, f64::min), n)
                }
            }
        };
        let (on, normal) = surface(&p);
        assert!(on.abs() < 1e-9, "{kind}: contact {p} is {on} off its surface");
        assert!(((c - p).norm() - 3.0).abs() <= EXACT, "{kind}: centre {c} not r from {p}");
        // Off the face's edges the centre lies along the surface's normal: r from the surface.
        if ((c - p).normalize() - normal).norm() < 1e-6 && kind != "plane" {
            let (d, _) = surface(&c);
            assert!((d - 3.0).abs() <= EXACT, "{kind}: centre {c} is {d} from the surface");
            *seen.entry(format!("{kind} inside")).or_insert(0) += 1;
        }
        *seen.entry(kind).or_insert(0) += 1;
    }
    for kind in ["plane", "cylinder", "sphere", "torus", "cylinder inside", "sphere inside", "torus inside"] {
        assert!(seen.get(kind).is_some_and(|n| *n > 10), "{kind} touched too rarely: {seen:?}");
    }
}

/// A STEP file that is not one, one with no faces, and one with an unsupported surface: one line
/// naming file (line, entity and #id), exit 2, no output; --skip-unsupported warns and goes on.
#[test]
fn bad_step_input_is_refused_with_one_line() {
    let w = Work::new();
    let run = |file: &str, extra: &[&str]| {
        let mut args = vec![file, "-r", "3", "-o", "out.csv", "-q"];
        args.extend_from_slice(extra);
        w.run(BIN, &args, b"")
    };
    w.write("solid.step", "solid cube\n  facet normal 0 0 1\n");
    run("solid.step", &[]).fails(2, "solid.step:1: not a STEP file: it does not start with ISO-10303-21;");
    w.write("empty.stp", "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1 = CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;\n");
    run("empty.stp", &[]).fails(2, "empty.stp: no surfaces: the STEP file holds no ADVANCED_FACE");
    w.write("bad.step", "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1 = CARTESIAN_POINT('',(0.,0.,0.);\nENDSEC;\n");
    run("bad.step", &[]).fails(2, "bad.step:5:35: expected ',' or ')'");
    let block = std::fs::read_to_string(data("step/block.step")).unwrap();
    let line = block.lines().position(|l| l.contains("TOROIDAL_SURFACE")).unwrap() + 1;
    let odd = block.replace("TOROIDAL_SURFACE('',#44,8.,2.)", "DEGENERATE_TOROIDAL_SURFACE('',#44,8.,2.,.T.)");
    assert_ne!(odd, block);
    w.write("odd.STP", &odd);
    run("odd.STP", &[]).fails(
        2,
        &format!("odd.STP:{line}: unsupported entity DEGENERATE_TOROIDAL_SURFACE #43 (the surface of face #323)"),
    );
    assert!(!w.exists("out.csv"));
    let o = run("odd.STP", &["--skip-unsupported"]);
    o.ok();
    assert!(o.stderr.contains("warning") && o.stderr.contains("face #323 left out"), "{}", o.stderr);
    assert_eq!(o.stderr.trim_end().lines().count(), 1, "{}", o.stderr);
}

/// Issue 20, found by the STEP family of scripts/fuzz-parsers.py on mutants of bspline.step: a
/// B-spline curve cut short (a panic), a coordinate of 1e12 mm (searches without end), a
/// control point of the surface moved 20 mm so that its edge no longer lies on it (46 s, then the
/// coverage check failed), and a knot repeated a million times: each one line naming file, line
/// and entity, exit 2, no output.
#[test]
fn broken_step_geometry_is_refused_with_one_line() {
    let w = Work::new();
    let run = |file: &str| w.run(BIN, &[file, "-r", "3", "--pick", "10", "-o", "out.csv", "-q"], b"");
    let good = std::fs::read_to_string(data("step/bspline.step")).unwrap();
    let line = |key: &str| good.lines().position(|l| l.starts_with(key)).unwrap() + 1;
    let cases = [
        (
            ".UNSPECIFIED.,.F.\n  ,.F.,(4,4),(0.,1.),.PIECEWISE_BEZIER_KNOTS.);",
            ".F.);",
            "#27",
            "#27: parameter 1 should be a list",
        ),
        (
            "#35 = CARTESIAN_POINT('',(0.,13.5,2.))",
            "#35 = CARTESIAN_POINT('',(0.,1e12,2.))",
            "#35",
            "#35: 1e12 mm is beyond ±1e9 mm",
        ),
        (
            "#35 = CARTESIAN_POINT('',(0.,13.5,2.))",
            "#35 = CARTESIAN_POINT('',(0.,33.5,2.))",
            "#17",
            "#17: edge 1 of the face lies",
        ),
        ("(4,1,4),(0.,1.,2.)", "(4,1000001,4),(0.,1.,2.)", "#65", "#65: more than 1e6 knots"),
    ];
    for (from, to, at, want) in cases {
        let bad = good.replacen(from, to, 1);
        assert_ne!(bad, good, "{from}");
        w.write("b.step", &bad);
        let o = run("b.step");
        o.fails(2, &format!("b.step:{}: {want}", line(at)));
        assert!(!w.exists("out.csv"));
    }
}

/// Runs filter `name` with `args` in `w` under a CPU-time limit of `seconds` (a hang guard).
fn limited(w: &Work, seconds: u32, name: &str, args: &[&str]) -> Outcome {
    let out = std::process::Command::new("sh")
        .current_dir(w.path(""))
        .arg("-c")
        .arg(format!("ulimit -t {seconds}; exec \"$0\" \"$@\""))
        .arg(e2e::bin(name))
        .args(args)
        .output()
        .unwrap();
    Outcome {
        status: out.status.code().unwrap_or(-1),
        stdout: out.stdout,
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// What the STEP family's fuzzing found running for minutes or hours, each from one number
/// changed: an edge circle's centre moved 1e9 mm off its vertices (refused naming the edge, as
/// is a loop whose edges are listed out of order); an
/// interior control point of bspline.step's surface at z = 12 345 mm, a valid 5 km spike (the
/// gouge check's triangles are refused from their start grid, the stylus's scan by its work
/// counted at the B-spline surfaces' cost, the drop-cutter traces it, its steep pieces bounded
/// by their capped planes); and the surface's knots stretched from (0, 1, 2) to (0, 1e8, 2e8),
/// the same surface (triangulated in (u, v) scaled to lengths: the gouge check gives the same
/// rows and chord as on the file itself).
#[test]
fn extreme_step_geometry_is_refused_or_bounded() {
    let w = Work::new();
    let faces = std::fs::read_to_string(data("step/faces.step")).unwrap();
    let moved = faces.replacen("#81 = CARTESIAN_POINT('',(100.,0.,0.))", "#81 = CARTESIAN_POINT('',(1e9,0.,0.))", 1);
    assert_ne!(moved, faces);
    w.write("moved.step", &moved);
    let line = moved.lines().position(|l| l.starts_with("#73 ")).unwrap() + 1;
    w.run(BIN, &["moved.step", "-r", "3", "--pick", "10", "-o", "out.csv", "-q"], b"").fails(
        2,
        &format!("moved.step:{line}: #73: the edge's curve ends 1.000e9 mm from its vertices (more than 0.01 mm)"),
    );
    assert!(!w.exists("out.csv"));
    let shuffled =
        faces.replacen("#71 = EDGE_LOOP('',(#72,#96,#112,#129))", "#71 = EDGE_LOOP('',(#72,#112,#96,#129))", 1);
    assert_ne!(shuffled, faces);
    w.write("shuffled.step", &shuffled);
    let line = shuffled.lines().position(|l| l.starts_with("#71 ")).unwrap() + 1;
    w.run(BIN, &["shuffled.step", "-r", "3", "--pick", "10", "-o", "out.csv", "-q"], b"")
        .fails(2, &format!("shuffled.step:{line}: #71: edge 1 of the loop ends 6.000e1 mm from the start of the next"));

    let good = std::fs::read_to_string(data("step/bspline.step")).unwrap();
    let spike =
        good.replacen("#44 = CARTESIAN_POINT('',(30.,26.5,10.5))", "#44 = CARTESIAN_POINT('',(30.,26.5,12345.))", 1);
    assert_ne!(spike, good);
    w.write("spike.step", &spike);
    let high: String = std::iter::once("path,move,x,y,z,i,j,k\n".to_string())
        .chain((0..40).map(|k| format!("1,{},{},{},6000,0,0,1\n", if k == 0 { "rapid" } else { "line" }, k, k % 7)))
        .collect();
    w.write("high.csv", &high);
    w.write("ball.json", r#"{"kind": "ball", "radius": 3}"#);
    let check = |m: &str| {
        limited(
            &w,
            60,
            "tool-attitude",
            &["high.csv", "--tool", "ball.json", "--axis", "0,0,1", "--model", m, "-o", "t.csv", "--report", "r.json"],
        )
    };
    check("spike.step").fails(2, "the faces' triangles need at least 16785409 vertices");
    limited(&w, 60, BIN, &["spike.step", "-r", "3", "--pick", "10", "-o", "out.csv", "-q"])
        .fails(2, "on surfaces 50 times as costly as analytic ones");
    assert!(!w.exists("out.csv"));
    limited(
        &w,
        60,
        BIN,
        &["spike.step", "--tool", "ball.json", "--pick", "6", "--max-step", "3", "-o", "drops.csv", "-q"],
    )
    .ok();
    assert!(table(&w.read("drops.csv")).iter().any(|r| num(r, "z") > 1000.0), "no drop onto the spike");

    let stretched = good.replacen("(4,1,4),(4,4),(0.,1.,2.),(0.,1.),", "(4,1,4),(4,4),(0.,1.E8,2.E8),(0.,1.),", 1);
    assert_ne!(stretched, good);
    w.write("stretched.step", &stretched);
    let b = data("step/bspline.step").display().to_string();
    let mut seen = Vec::new();
    for m in [b.as_str(), "stretched.step"] {
        check(m).ok();
        let r: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
        seen.push((w.read("t.csv"), r["gouge_chord_mm"].as_f64().unwrap()));
    }
    assert_eq!(seen[0].0, seen[1].0);
    assert!(seen[1].1 <= 0.25e-3 && (seen[0].1 - seen[1].1).abs() < 1e-9, "{seen:?}");
}

/// tool-attitude with --model on the STEP block: the ball end mill on the CL of the dish is
/// clear (no row deeper than the gouge tolerance, the deepest within the faces' triangles' chord),
/// and a contact moved 0.1 mm down is found gouging by 0.1·n_z (the normal's z), within the chord.
#[test]
fn tool_attitude_gouge_checks_against_step_faces() {
    let w = Work::new();
    let m = data("step/block.step").display().to_string();
    // Contacts to 1 nm, so that what the check reads is the triangles' chord alone.
    let trace = [&m, "-r", "3", "--pick", "5", "--region=30,70,30,70", "--contact-tol", "1e-6", "-q", "-o", "cl.csv"];
    w.run(BIN, &trace, b"").ok();
    let (r, chord) = clear_ball_check(&w, &m);
    // The faces' outlines run through points of their edges within the chord (no longer the
    // loops' polygons, arcs every π/256, whose sagitta at the dish's rim, R26.5, was 0.5 µm): the
    // balls grazing the rim read no more than the chord.
    assert!(r["largest_gouge_mm"].as_f64().unwrap() <= chord, "{r}");
    // One contact 0.1 mm lower.
    let cl = w.read("cl.csv");
    let rows = table(&cl);
    let k = rows.len() / 2;
    let nz = num(&rows[k], "nz");
    let deepest = lowered_gouge(&w, &cl, k, &m);
    assert!((deepest - 0.1 * nz).abs() <= chord + 1e-6, "deepest {deepest} vs {}", 0.1 * nz);
}

/// Fixed-axis cutters on STEP faces: the halves of a sphere, a cylinder and a torus (faces.step)
/// and a B-spline face give the tips of the same surfaces as a model JSON document (closed forms
/// on the sphere and the torus) within 1e-9 mm, for each cutter; the block is traced whole.
#[test]
fn fixed_axis_cutters_on_step_faces() {
    let w = Work::new();
    let tools = [
        ("flat", r#"{"kind": "flat", "radius": 3}"#),
        ("ball", r#"{"kind": "ball", "radius": 3}"#),
        ("bull", r#"{"kind": "bull", "radius": 3, "corner_radius": 1}"#),
        ("cone", r#"{"kind": "cone", "radius": 3, "half_angle": 40}"#),
    ];
    let tips = |model: &str, tool: &str, region: &str, out: &str| {
        let m = data(model).to_string_lossy().into_owned();
        let region = format!("--region={region}");
        w.run(BIN, &[&m, "--tool", tool, "--pick", "3", "--max-step", "1.5", &region, "-o", out], b"").ok();
        table(&w.read(out))
    };
    for (name, text) in tools {
        let tool = format!("{name}.json");
        w.write(&tool, text);
        for (model, region) in
            [("faces", "-15,15,-15,15"), ("faces", "45,95,-8,8"), ("faces", "-14,14,48,72"), ("bspline", "0,60,0,40")]
        {
            let step = tips(&format!("step/{model}.step"), &tool, region, "s.csv");
            let json = tips(&format!("step/{model}.json"), &tool, region, "j.csv");
            assert!(
                step.len() > 50 && step.len() == json.len(),
                "{name} {region}: {} vs {} rows",
                step.len(),
                json.len()
            );
            for (a, b) in step.iter().zip(&json) {
                let d = (p3(a, "x", "y", "z") - p3(b, "x", "y", "z")).norm();
                assert!(d <= 1e-9, "{name} {model} {region}: STEP and JSON tips differ by {d}");
            }
        }
        let block = tips("step/block.step", &tool, "-5,35,-5,35", "b.csv");
        assert!(block.len() > 150, "{name}: {} rows on the block", block.len());
    }
}

/// The cubic profile of revolve.step at t in (r, z), written out apart from camkit's splines.
fn knob_profile(t: f64) -> [f64; 2] {
    let (r, z) = ([30.0, 33.0, 22.0, 25.0], [0.0, 5.0, 10.0, 15.0]);
    let b = [(1.0 - t).powi(3), 3.0 * t * (1.0 - t).powi(2), 3.0 * t * t * (1.0 - t), t.powi(3)];
    [(0..4).map(|i| b[i] * r[i]).sum(), (0..4).map(|i| b[i] * z[i]).sum()]
}

/// Distance in the half-plane from (r, z) to the cubic profile: the densest of 20 000 samples,
/// then golden sections round it.
fn to_knob_profile(r: f64, z: f64) -> f64 {
    let d = |t: f64| {
        let [a, b] = knob_profile(t);
        (a - r).hypot(b - z)
    };
    let k: usize = 20_000;
    let i = (0..=k).min_by(|a, b| d(*a as f64 / k as f64).total_cmp(&d(*b as f64 / k as f64))).unwrap();
    let (a, b) = (i.saturating_sub(1) as f64 / k as f64, ((i + 1).min(k)) as f64 / k as f64);
    d(golden_arg(|t| -d(t), a, b, 80))
}

/// The knob of revolve.step (two SURFACE_OF_REVOLUTION faces between two discs) traced whole:
/// each contact on its closed-form surface (the swept quarter circle is a torus; the swept cubic
/// checked against its profile written out here), the stylus centre r from it within 0.1 µm.
#[test]
fn surfaces_of_revolution_against_closed_forms() {
    let w = Work::new();
    let rows = trace_picked(&w, "step/revolve.step", "-1,36,-36,36", "k.csv", "5");
    let mut seen = std::collections::BTreeMap::new();
    for r in &rows {
        let (c, p) = (p3(r, "x", "y", "z"), p3(r, "px", "py", "pz"));
        let rho = |q: &P3| q.x.hypot(q.y);
        let kind = if text(r, "surface").starts_with("plane") {
            "plane"
        } else if p.z >= 15.0 - 1e-9 && rho(&p) >= 20.0 - 1e-9 {
            "torus"
        } else {
            "cubic"
        };
        let surface = |q: &P3| match kind {
            "plane" => (q.z - if p.z > 10.0 { 20.0 } else { 0.0 }).abs(),
            "torus" => ((rho(q) - 20.0).hypot(q.z - 15.0) - 5.0).abs(),
            _ => to_knob_profile(rho(q), q.z),
        };
        assert!(surface(&p) < 1e-7, "{kind}: contact {p} is {} off its surface", surface(&p));
        assert!(((c - p).norm() - 3.0).abs() <= EXACT, "{kind}: centre {c} not r from {p}");
        let n = p3(r, "nx", "ny", "nz").coords;
        if ((c - p).normalize() - n).norm() < 1e-6 && kind != "plane" {
            let d = surface(&c);
            assert!((d - 3.0).abs() <= EXACT, "{kind}: centre {c} is {d} from the surface");
            *seen.entry(kind).or_insert(0) += 1;
        }
    }
    for kind in ["torus", "cubic"] {
        assert!(seen.get(kind).is_some_and(|n| *n > 20), "{kind} touched too rarely: {seen:?}");
    }
}

/// The closed periodic B-spline tube of tube.step (exactly the cone r = 10 + z/6) traced from
/// above, across its seam (u = 0 on +x): every stylus centre 3 from the cone (or its rims) within 0.1 µm.
#[test]
fn closed_bspline_tube_against_its_cone() {
    let w = Work::new();
    // Beside the axis, where the stylus in the cone touches both sides at once (a crease).
    let rows = trace_picked(&w, "step/tube.step", "4,17,-8,8", "t.csv", "2");
    assert!(rows.len() > 300, "{} rows", rows.len());
    let cone = |q: &P3| {
        let (p, a, b) = ([q.x.hypot(q.y), q.z], [10.0, 0.0], [15.0, 30.0]);
        let d = [b[0] - a[0], b[1] - a[1]];
        let t = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1])).clamp(0.0, 1.0);
        (p[0] - a[0] - t * d[0]).hypot(p[1] - a[1] - t * d[1])
    };
    let worst = rows.iter().map(|r| (cone(&p3(r, "x", "y", "z")) - 3.0).abs()).fold(0.0, f64::max);
    assert!(worst <= EXACT, "CL off the cone by {worst}");
    let seam = rows.iter().filter(|r| num(r, "py").abs() < 1.0 && num(r, "px") > 0.0).count();
    assert!(seam > 5, "only {seam} contacts near the seam");
}

/// tool-attitude --model on the knob: the ball on the traced CL is clear, the faces' triangles
/// within the asked chord (a quarter of the gouge tolerance, 0.25 µm), and a contact moved
/// 0.1 mm down is found gouging by 0.1·n_z within that chord.
#[test]
fn tool_attitude_gouge_checks_surfaces_of_revolution() {
    let w = Work::new();
    let m = data("step/revolve.step").display().to_string();
    w.run(BIN, &[&m, "-r", "3", "--pick", "6", "--region=0,34,-34,34", "-q", "-o", "cl.csv"], b"").ok();
    let (_, chord) = clear_ball_check(&w, &m);
    let cl = w.read("cl.csv");
    let rows = table(&cl);
    // A row on the cubic face, 0.1 mm lower.
    let k = rows.iter().position(|r| text(r, "surface").starts_with("revolution") && num(r, "pz") < 14.0).unwrap();
    let nz = num(&rows[k], "nz");
    let deepest = lowered_gouge(&w, &cl, k, &m);
    // The ball's depth in the curved face: its radius less the lowered centre's distance from
    // the swept cubic (the profile written out here); about 0.1 n_z.
    let c = p3(&rows[k], "x", "y", "z") - V3::z() * 0.1;
    let want = 3.0 - to_knob_profile(c.x.hypot(c.y), c.z);
    assert!((deepest - want).abs() <= chord + 1e-6, "deepest {deepest} vs {want}");
    assert!((deepest - 0.1 * nz).abs() < 0.01, "deepest {deepest} vs {}", 0.1 * nz);
}

/// Fixed-axis cutters on the knob of revolve.step (its curved faces are surfaces of revolution):
/// round the axis the nearest point of each circle of the surface is the one in the tip's
/// half-plane, so the highest tip is the largest z − f(|ρ − D|) over the profile (D the tip's
/// distance from the axis) — sampled here from the profile written out (discs, cubic, quarter
/// circle). No sample stands above a tip, and each tip is within the sampling's reach of them.
#[test]
fn fixed_axis_cutters_on_surfaces_of_revolution() {
    let w = Work::new();
    let m = data("step/revolve.step").display().to_string();
    let mut profile: Vec<[f64; 2]> = Vec::new();
    let k = 20_000;
    for i in 0..=k {
        let t = i as f64 / k as f64;
        let a = t * std::f64::consts::FRAC_PI_2;
        profile.push(knob_profile(t));
        profile.extend([[20.0 + 5.0 * a.cos(), 15.0 + 5.0 * a.sin()], [20.0 * t, 20.0], [30.0 * t, 0.0]]);
    }
    let (radius, corner, half) = (3.0f64, 1.0f64, 40f64.to_radians());
    type Profile = Box<dyn Fn(f64) -> f64>;
    let tools: [(&str, &str, Profile); 4] = [
        ("flat", r#"{"kind": "flat", "radius": 3}"#, Box::new(|_| 0.0)),
        ("ball", r#"{"kind": "ball", "radius": 3}"#, Box::new(move |d: f64| radius - (radius * radius - d * d).sqrt())),
        (
            "bull",
            r#"{"kind": "bull", "radius": 3, "corner_radius": 1}"#,
            Box::new(move |d: f64| {
                let e = (d - (radius - corner)).max(0.0);
                corner - (corner * corner - e * e).sqrt()
            }),
        ),
        ("cone", r#"{"kind": "cone", "radius": 3, "half_angle": 40}"#, Box::new(move |d: f64| d / half.tan())),
    ];
    for (name, text, f) in &tools {
        let tool = format!("{name}.json");
        w.write(&tool, text);
        w.run(BIN, &[&m, "--tool", &tool, "--pick", "3", "--max-step", "1", "--region=0,36,-4,4", "-o", "k.csv"], b"")
            .ok();
        let rows = table(&w.read("k.csv"));
        assert!(rows.len() > 60, "{name}: {} rows", rows.len());
        for r in &rows {
            let tip = p3(r, "x", "y", "z");
            let d = tip.x.hypot(tip.y);
            let brute = profile
                .iter()
                .filter(|p| (p[0] - d).abs() <= radius)
                .map(|p| p[1] - f((p[0] - d).abs()))
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(brute <= tip.z + 1e-9, "{name}: a sample {} above the tip {tip}", brute - tip.z);
            assert!(tip.z - brute <= 2e-3, "{name}: tip {tip} {} above every sample", tip.z - brute);
        }
    }
}

/// tool-attitude's gouge check of a ball R3 on `input` against the model `m`.
fn ball_check(w: &Work, input: &str, m: &str) -> Outcome {
    w.write("ball.json", r#"{"kind": "ball", "radius": 3}"#);
    w.run("tool-attitude", &[input, "--tool", "ball.json", "--model", m, "-o", "t.csv", "--report", "r.json"], b"")
}

/// The ball's check on cl.csv finds no gouge with the faces' triangles within the asked chord
/// (0.25 µm): its report and that chord.
fn clear_ball_check(w: &Work, m: &str) -> (serde_json::Value, f64) {
    ball_check(w, "cl.csv", m).ok();
    let r: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
    let chord = r["gouge_chord_mm"].as_f64().unwrap();
    assert!(chord > 0.0 && chord <= 0.25e-3, "{r}");
    assert_eq!(r["gouge_rows"], 0, "{r}");
    (r, chord)
}

/// The ball's check (`ball_check`, its input low.csv) on the table `cl` with row `k`'s tip and
/// contact moved 0.1 mm down: it fails naming that one row, and the depth it reports.
fn lowered_gouge(w: &Work, cl: &str, k: usize, m: &str) -> f64 {
    let mut lines: Vec<String> = cl.lines().map(str::to_string).collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let (iz, ipz) = (header.iter().position(|h| *h == "z").unwrap(), header.iter().position(|h| *h == "pz").unwrap());
    let mut f: Vec<String> = lines[k + 1].split(',').map(str::to_string).collect();
    for i in [iz, ipz] {
        f[i] = (f[i].parse::<f64>().unwrap() - 0.1).to_string();
    }
    lines[k + 1] = f.join(",");
    w.write("low.csv", lines.join("\n") + "\n");
    let o = ball_check(w, "low.csv", m);
    o.fails(1, &format!("low.csv:{}: 1 row(s) gouge the model by more than 0.001 mm", k + 2));
    o.stderr.split("deepest ").nth(1).unwrap().trim_end().trim_end_matches(" mm)").parse().unwrap()
}
