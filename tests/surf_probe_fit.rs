//! End-to-end tests of `surf-probe-fit`: the globe measurement (3-axis raster, rough Delaunay
//! surface, 5-axis plan along its normals on paper 002's A/C machine, simulated sensor, fit)
//! with the 5-axis fit beating the 3-axis one against the known sphere; the plan and the frame
//! accepted by `post-6axis`; the coastline on a fitted frame posted and read back by `post-6axis`;
//! reference sets reproduced through CSV; RANSAC against gross outliers; bad input refused with
//! one line and no output file.

use e2e::{Work, data};

const BIN: &str = "surf-probe-fit";

fn json(w: &Work, name: &str) -> serde_json::Value {
    serde_json::from_str(&w.read(name)).expect("JSON")
}

fn d(rel: &str) -> String {
    data(rel).to_str().unwrap().to_string()
}

#[test]
fn globe_five_axis_along_normals_beats_three_axis() {
    let w = Work::new();
    let truth = d("surf-probe-fit/globe-true.json");
    let machine = d("post-6axis/paper002-ac.json");
    w.run(BIN, &["raster", "--x", "-28,34", "--y", "-31,29", "--step", "2", "--z", "115.5", "-o", "raster.csv"], b"")
        .ok();
    w.run(BIN, &["simulate", "raster.csv", "--shape", &truth, "-o", "rec3.csv"], b"").ok();
    w.run(BIN, &["points", "rec3.csv", "-o", "pts3.csv"], b"").ok();
    w.run(BIN, &["fit", "pts3.csv", "--truth", &truth, "-o", "fit3.json", "--report", "r3.json"], b"").ok();
    w.run(BIN, &["plan", "pts3.csv", "--every", "5", "-o", "plan.csv", "--report", "plan.json"], b"").ok();
    let plan = json(&w, "plan.json");
    assert!(plan["probes"].as_u64().unwrap() > 50 && plan["largest_tilt_deg"].as_f64().unwrap() > 60.0, "{plan}");
    w.run(
        BIN,
        &["simulate", "plan.csv", "-m", &machine, "--shape", &truth, "-o", "rec5.csv", "--report", "s5.json"],
        b"",
    )
    .ok();
    let s5 = json(&w, "s5.json");
    assert_eq!(s5["lost"], 0, "{s5}");
    assert!(s5["largest_incidence_deg"].as_f64().unwrap() < 10.0, "{s5}");
    assert!(w.read("rec5.csv").starts_with("path,x,y,z,c,a,reading"));
    w.run(BIN, &["fit", "rec5.csv", "-m", &machine, "--truth", &truth, "-o", "fit5.json", "--report", "r5.json"], b"")
        .ok();
    let (r3, r5) = (json(&w, "r3.json"), json(&w, "r5.json"));
    let e3 = r3["origin_error_mm"].as_f64().unwrap().max(r3["radius_error_mm"].as_f64().unwrap().abs());
    let e5 = r5["origin_error_mm"].as_f64().unwrap().max(r5["radius_error_mm"].as_f64().unwrap().abs());
    assert!(e5 < 0.002 && e3 > 5.0 * e5, "3-axis {e3} mm, 5-axis {e5} mm");
    // The frame puts the workpiece origin at the fitted centre.
    let f = json(&w, "fit5.json");
    let c = &f["fit"]["centre"];
    for (k, name) in ["xc", "yc", "za"].iter().enumerate() {
        assert_eq!(f[name].as_f64().unwrap(), -c[k].as_f64().unwrap());
    }
}

#[test]
fn post_6axis_accepts_the_plan_and_the_frame() {
    let w = Work::new();
    let truth = d("surf-probe-fit/globe-true.json");
    let machine = d("post-6axis/paper002-ac.json");
    w.run(BIN, &["plan", "--fit", &truth, "--ring-step", "20", "--max-polar", "60", "-o", "plan.csv"], b"").ok();
    w.run(
        "post-6axis",
        &[
            "plan.csv",
            "-m",
            &machine,
            "--frame",
            &d("surf-probe-fit/table-frame.json"),
            "--feed",
            "500",
            "-o",
            "plan.ngc",
        ],
        b"",
    )
    .ok();
    assert!(w.read("plan.ngc").contains(" A"), "a 5-axis program");
    w.run(BIN, &["reference", "--centre", "3.2,-1.7,40.5", "--extent", "60", "--points", "200", "-o", "pts.csv"], b"")
        .ok();
    w.run(BIN, &["fit", "pts.csv", "-o", "frame.json"], b"").ok();
    w.write("cl.csv", "path,move,x,y,z,i,j,k\n0,rapid,0,0,30,0,0,1\n0,line,0,10,30,0,0.6,0.8\n");
    w.run("post-6axis", &["cl.csv", "-m", &machine, "--frame", "frame.json", "--feed", "300", "-o", "cut.ngc"], b"")
        .ok();
    assert!(w.exists("cut.ngc"));
}

#[test]
fn reference_sets_are_reproduced_through_csv() {
    let w = Work::new();
    for (shape, extra) in [
        ("sphere", vec!["--centre", "1200,-850,640", "--extent", "30"]),
        ("cylinder", vec!["--centre", "-40,7,3", "--axis", "0.1,0.95,0.3", "--radius", "12.5", "--extent", "60"]),
        ("plane", vec!["--centre", "10,20,30", "--axis", "0.3,-0.2,0.9", "--extent", "40"]),
        ("circle", vec!["--centre", "5,-3,12", "--axis", "0.3,-0.2,0.9", "--radius", "18", "--extent", "360"]),
    ] {
        let mut args = vec!["reference", "--shape", shape, "--points", "300", "-o", "pts.csv", "--report", "ref.json"];
        args.extend(extra);
        w.run(BIN, &args, b"").ok();
        w.run(BIN, &["fit", "pts.csv", "--shape", shape, "-o", "fit.json"], b"").ok();
        let (truth, fit) = (json(&w, "ref.json")["truth"].clone(), json(&w, "fit.json")["fit"].clone());
        let v = |j: &serde_json::Value, k: &str| -> Vec<f64> {
            match &j[k] {
                serde_json::Value::Array(a) => a.iter().map(|x| x.as_f64().unwrap()).collect(),
                x => vec![x.as_f64().unwrap()],
            }
        };
        let keys: &[&str] = match shape {
            "sphere" => &["centre", "radius"],
            "circle" => &["centre", "normal", "radius"],
            "cylinder" => &["radius"],
            _ => &["normal"],
        };
        for k in keys {
            for (a, b) in v(&truth, k).iter().zip(v(&fit, k)) {
                assert!((a - b).abs() < 1e-7, "{shape} {k}: {a} vs {b}");
            }
        }
    }
}

#[test]
fn small_cap_warns_about_the_radius() {
    let w = Work::new();
    w.run(BIN, &["reference", "--extent", "5", "--points", "300", "-o", "cap.csv"], b"").ok();
    let o = w.run(BIN, &["fit", "cap.csv", "-o", "fit.json"], b"");
    o.ok();
    assert!(o.stderr.contains("warning") && o.stderr.contains("radius"), "{}", o.stderr);
    assert!(json(&w, "fit.json")["fit"]["poorly_determined"].as_array().unwrap().iter().any(|p| p == "radius"));
}

#[test]
fn bad_input_is_refused() {
    let w = Work::new();
    w.write("three.csv", "x,y,z\n0,0,0\n1,0,0\n0,1,1\n");
    w.run(BIN, &["fit", "three.csv", "-o", "out.json"], b"").fails(2, "3 points: a sphere needs at least 4");
    let flat: String =
        (0..12).map(|k| format!("{},{},5\n", (k as f64).cos() * 10.0, (k as f64).sin() * 10.0)).collect();
    w.write("flat.csv", format!("x,y,z\n{flat}"));
    w.run(BIN, &["fit", "flat.csv", "-o", "out.json"], b"").fails(2, "all points lie on one plane");
    w.write("nan.csv", "x,y,z\n0,0,0\n1,0,NaN\n");
    w.run(BIN, &["fit", "nan.csv", "-o", "out.json"], b"").fails(2, "nan.csv:3");
    w.write("dup.csv", "x,y,z\n0,0,1\n1,0,0\n0,1,0\n-1,0,0\n1,0,0\n");
    w.run(BIN, &["fit", "dup.csv", "-o", "out.json"], b"").fails(2, "duplicate point: the same as line 3");
    w.write("rec.csv", "x,y,z,reading\n0,0,10,abc\n");
    w.run(BIN, &["fit", "rec.csv", "-o", "out.json"], b"").fails(2, "rec.csv:2:4 (reading)");
    // Nearly on a plane (a 1 µm bulge over 20 mm): the radius runs off, a failed fit (exit 1).
    let bulge: String = (0..40)
        .map(|k| {
            let (x, y) = ((k % 7) as f64 * 3.0, (k / 7) as f64 * 3.0);
            format!("{x},{y},{}\n", 1e-6 * ((x * x + y * y) / 400.0))
        })
        .collect();
    w.write("bulge.csv", format!("x,y,z\n{bulge}"));
    let o = w.run(BIN, &["fit", "bulge.csv", "-o", "out.json", "--report", "r.json", "--residuals", "res.csv"], b"");
    assert_eq!(o.status, 1, "{}", o.stderr);
    assert!(o.stderr.contains("radius ran off"), "{}", o.stderr);
    assert_eq!(o.stderr.trim_end().lines().count(), 1, "{}", o.stderr);
    // Fewer points than parameters for the other elements; the same refusals with RANSAC.
    w.write(
        "two.csv",
        "x,y,z
0,0,0
1,0,0
",
    );
    w.run(BIN, &["fit", "two.csv", "--shape", "plane", "-o", "out.json"], b"").fails(2, "a plane needs at least 3");
    w.run(BIN, &["fit", "three.csv", "--shape", "cylinder", "-o", "out.json"], b"")
        .fails(2, "a cylinder needs at least 5");
    w.run(BIN, &["fit", "flat.csv", "--robust", "ransac", "-o", "out.json"], b"")
        .fails(2, "all points lie on one plane");
    w.run(BIN, &["fit", "nan.csv", "--robust", "ransac", "-o", "out.json"], b"").fails(2, "nan.csv:3");
    w.run(BIN, &["fit", "dup.csv", "--robust", "huber", "-o", "out.json"], b"").fails(2, "duplicate point");
    // Every refusal above wrote to out.json (and the failed fit its report): none exists.
    assert!(!w.exists("out.json") && !w.exists("r.json") && !w.exists("res.csv"), "no partial output");
}

#[test]
fn coastline_on_the_fitted_sphere_is_offset_normal_to_the_tool_axis() {
    let w = Work::new();
    w.run(BIN, &["reference", "--centre", "3.2,-1.7,40.5", "--extent", "90", "--points", "300", "-o", "pts.csv"], b"")
        .ok();
    w.run(BIN, &["fit", "pts.csv", "-o", "frame.json"], b"").ok();
    let coast = d("surf-probe-fit/honshu-coastline.json");
    let args = ["map", &coast, "--frame", "frame.json", "--lon0", "138", "--depth", "0.2", "-o", "coast.csv"];
    w.run(BIN, &args, b"").ok();
    let radius = json(&w, "frame.json")["fit"]["radius"].as_f64().unwrap();
    let text = w.read("coast.csv");
    let mut rows = 0;
    for line in text.lines().skip(1) {
        let v: Vec<f64> = line.split(',').skip(2).take(6).map(|x| x.parse().unwrap()).collect();
        let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!((r - (radius - 0.2)).abs() < 1e-9, "{line}");
        assert!((v[0] / r - v[3]).abs() < 1e-9 && (v[2] / r - v[5]).abs() < 1e-9, "axis along the normal: {line}");
        rows += 1;
    }
    assert!(rows > 80);
    w.run("offset", &["coast.csv", "--3d", "--radius", "0.1", "--side", "left", "-o", "off.csv"], b"").ok();
    assert!(w.read("off.csv").lines().count() > 100);
    // A φ3 mm tool does not fit Honshu's bays, and around all three islands a tool would cut into
    // the neighbouring island (straits under 0.1 mm on this globe): refused, nothing written.
    let out = w.run("offset", &["coast.csv", "--3d", "--radius", "1.5", "--side", "left", "-o", "big.csv"], b"");
    out.fails(1, "the tool does not fit there");
    let japan = d("surf-probe-fit/japan-coastline.json");
    let args = ["map", &japan, "--frame", "frame.json", "--lon0", "138", "--depth", "0.2", "-o", "japan.csv"];
    w.run(BIN, &args, b"").ok();
    let out = w.run("offset", &["japan.csv", "--3d", "--radius", "0.1", "--side", "left", "-o", "japan-off.csv"], b"");
    out.fails(1, "the tool does not fit there");
    assert!(!w.exists("big.csv") && !w.exists("japan-off.csv"));
    // NC for the A/C table machine on the fitted frame; post-6axis reads its program back.
    let machine = d("post-6axis/paper002-ac.json");
    let post = ["off.csv", "-m", &machine, "--frame", "frame.json", "--feed", "300"];
    w.run("post-6axis", &[&post[..], &["-o", "coast.ngc", "--report", "post.json"]].concat(), b"").ok();
    let p = json(&w, "post.json");
    let tol = p["tol_mm"].as_f64().unwrap();
    assert!(p["largest_tip_deviation_mm"].as_f64().unwrap() <= tol, "{p}");
    assert!(p["largest_row_distance_mm"].as_f64().unwrap() <= tol, "{p}");
    assert!(p["largest_axis_deviation_deg"].as_f64().unwrap() <= p["angle_tol_deg"].as_f64().unwrap(), "{p}");
    assert_eq!(p["dropped_blocks"], 0, "{p}");
    assert!(p["blocks_checked"].as_u64().unwrap() > 100, "{p}");
    w.run("post-6axis", &[&post[..], &["--verify", "coast.ngc", "-o", "verify.json"]].concat(), b"").ok();
    let v = json(&w, "verify.json");
    assert!(v["largest_tip_deviation_mm"].as_f64().unwrap() <= tol, "{v}");
    w.write("bad.json", r#"{"parts": [[[140, 40]]]}"#);
    w.run(BIN, &["map", "bad.json", "--frame", "frame.json", "-o", "x.csv"], b"").fails(2, "parts[0]");
    w.write("bad.json", r#"{"parts": [[[140, 40], [141, 40]]], "sorce": "typo"}"#);
    w.run(BIN, &["map", "bad.json", "--frame", "frame.json", "-o", "x.csv"], b"").fails(2, "bad.json:1:");
    w.write("bad.json", r#"{"parts": [[[140, 40], [141, 95]]]}"#);
    w.run(BIN, &["map", "bad.json", "--frame", "frame.json", "-o", "x.csv"], b"").fails(2, "(parts[0][1])");
}

#[test]
fn free_form_height_field_from_the_raster() {
    let w = Work::new();
    let truth = d("surf-probe-fit/globe-true.json");
    let args = ["raster", "--x", "-8,14", "--y", "-11,7", "--step", "1", "--z", "115.5", "-o", "raster.csv"];
    w.run(BIN, &args, b"").ok();
    let args = ["simulate", "raster.csv", "--shape", &truth, "--slope-error", "0", "-o", "rec.csv"];
    w.run(BIN, &args, b"").ok();
    w.run(BIN, &["surface", "rec.csv", "--net", "8,8", "-o", "model.json", "--report", "s.json"], b"").ok();
    let r = json(&w, "s.json");
    assert!(r["rms_mm"].as_f64().unwrap() < 0.002, "{r}");
    let (ortho, vertical) = (r["orthogonal_rms_mm"].as_f64().unwrap(), r["rms_mm"].as_f64().unwrap());
    assert!(ortho > 0.0 && ortho <= vertical, "{r}");
    assert!(r["largest_orthogonal_mm"].as_f64().unwrap().abs() <= r["largest_residual_mm"].as_f64().unwrap().abs());
    assert_eq!(json(&w, "model.json")["surfaces"][0]["control_points"].as_array().unwrap().len(), 8);
    w.run(BIN, &["surface", "rec.csv", "--net", "30,30", "-o", "x.json"], b"")
        .fails(2, "a 30x30 net needs at least 900");
}

#[test]
fn ransac_drops_gross_outliers_reproducibly() {
    let w = Work::new();
    let args = ["reference", "--centre", "3.2,-1.7,40.5", "--extent", "90", "--points", "200", "--amplitude", "0.002"];
    w.run(BIN, &[&args[..], &["-o", "pts.csv"]].concat(), b"").ok();
    // 100 gross outliers (a third of the points): chips 0.5-2.5 mm above the sphere.
    let mut text = w.read("pts.csv");
    for k in 0..100 {
        let (t, p) = (0.015 * k as f64, 0.37 * k as f64);
        let r = 25.0 + 0.5 + 0.02 * k as f64;
        let (x, y, z) = (3.2 + r * t.sin() * p.cos(), -1.7 + r * t.sin() * p.sin(), 40.5 + r * t.cos());
        text.push_str(&format!("{x},{y},{z}\n"));
    }
    w.write("dirty.csv", text);
    let fit = ["fit", "dirty.csv", "--robust", "ransac", "--seed", "3"];
    w.run(BIN, &[&fit[..], &["-o", "a.json", "--report", "r.json"]].concat(), b"").ok();
    w.run(BIN, &[&fit[..], &["-o", "b.json", "--residuals", "res.csv"]].concat(), b"").ok();
    assert_eq!(w.read("a.json"), w.read("b.json"), "the same seed gives the same frame");
    let r = json(&w, "r.json");
    assert_eq!(r["outliers"], 100, "{r}");
    assert_eq!(r["inliers"], 200, "{r}");
    assert_eq!(r["robust"]["method"], "ransac");
    let t = r["threshold_mm"].as_f64().unwrap();
    assert!(t > 0.002 && t < 0.5, "{r}");
    // Per-point residuals: the input rows, the distance from the fit, the outliers flagged.
    let res = w.read("res.csv");
    let mut lines = res.lines();
    assert_eq!(lines.next(), Some("x,y,z,residual,outlier"));
    for (k, line) in lines.enumerate() {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        assert_eq!(v[4], if k < 200 { 0.0 } else { 1.0 }, "row {k}: {line}");
        assert!(if k < 200 { v[3].abs() <= t } else { v[3] >= 0.5 }, "row {k}: {line}");
    }
    // The outliers are the last 100 rows: lines 202.. (header line 1).
    assert_eq!(r["outlier_lines"].as_array().unwrap().len(), 20);
    assert_eq!(r["outlier_lines"][0], 202, "{r}");
    let centre = |j: &serde_json::Value| -> Vec<f64> {
        j["fit"]["centre"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
    };
    let off = |c: &[f64]| ((c[0] - 3.2).powi(2) + (c[1] + 1.7).powi(2) + (c[2] - 40.5).powi(2)).sqrt();
    let robust = json(&w, "a.json");
    assert!(off(&centre(&robust)) < 1e-7, "{robust}");
    assert!((robust["fit"]["radius"].as_f64().unwrap() - 25.0).abs() < 1e-7);
    w.run(BIN, &["fit", "dirty.csv", "-o", "plain.json"], b"").ok();
    assert!(off(&centre(&json(&w, "plain.json"))) > 0.05, "the plain fit is pulled off");
    // A given threshold, and bad settings.
    w.run(BIN, &[&fit[..], &["--ransac-threshold", "0.1", "--report", "g.json", "-o", "g.json.out"]].concat(), b"")
        .ok();
    assert_eq!(json(&w, "g.json")["threshold_mm"], 0.1);
    w.run(BIN, &[&fit[..], &["--confidence", "1", "-o", "x.json"]].concat(), b"").fails(2, "--confidence");
    w.run(BIN, &[&fit[..], &["--ransac-threshold", "-1", "-o", "x.json"]].concat(), b"").fails(2, "--ransac-threshold");
    w.write("four.csv", "x,y,z\n0,0,0\n1,1,1\n2,4,8\n3,9,27\n");
    w.run(BIN, &["fit", "four.csv", "--robust", "ransac", "-o", "x.json"], b"").fails(2, "sample of 4");
    assert!(!w.exists("x.json"), "no partial output");
}

/// Shape, truth and frame documents are read strictly: unknown fields, typos, strings for
/// numbers, a radius that is not positive and duplicate keys are refused with file:line:col and
/// the JSON path (they were accepted, or refused without a line, before), and a negative radius
/// never reaches the simulation.
#[test]
fn shape_and_frame_documents_are_read_strictly() {
    let w = Work::new();
    let truth = d("surf-probe-fit/globe-true.json");
    w.run(BIN, &["raster", "--x", "-8,14", "--y", "-11,7", "--step", "2", "--z", "115.5", "-o", "raster.csv"], b"")
        .ok();
    w.run(BIN, &["simulate", "raster.csv", "--shape", &truth, "-o", "rec.csv"], b"").ok();
    w.run(BIN, &["points", "rec.csv", "-o", "pts.csv"], b"").ok();
    w.run(BIN, &["fit", "pts.csv", "-o", "frame.json"], b"").ok();
    let cases = [
        (
            "typo.json",
            r#"{"shape": "sphere", "centre": [3.2, -1.7, 40.5], "radius": 25.0, "radious": 3}"#,
            "typo.json:1:",
        ),
        (
            "unknown.json",
            r#"{"bogus_field": 1, "shape": "sphere", "centre": [3.2, -1.7, 40.5], "radius": 25.0}"#,
            "(bogus_field): unknown field",
        ),
        (
            "string.json",
            r#"{"shape": "sphere", "centre": ["5", -1.7, 40.5], "radius": 25.0}"#,
            "string.json:1:34 (centre[0]): invalid type: string",
        ),
        (
            "negative.json",
            "{\"shape\": \"sphere\", \"centre\": [3.2, -1.7, 40.5],\n \"radius\": -1}",
            "negative.json:2:14 (radius): must be a positive number of mm, got -1",
        ),
        (
            "twice.json",
            r#"{"shape": "sphere", "centre": [3.2, -1.7, 40.5], "radius": 25, "radius": 26}"#,
            "duplicate field `radius`",
        ),
    ];
    for (name, text, needle) in cases {
        w.write(name, text);
        w.run(BIN, &["simulate", "raster.csv", "--shape", name, "-o", "x.csv"], b"").fails(2, needle);
        w.run(BIN, &["fit", "pts.csv", "--truth", name, "-o", "x.json"], b"").fails(2, needle);
    }
    // A frame document: its own fields by camkit's Frame, its fit as a shape document.
    let frame = w.read("frame.json");
    w.write("xc.json", frame.replacen("\"xc\": ", "\"xc\": \"5\", \"was\": ", 1));
    w.run(BIN, &["map", &d("surf-probe-fit/honshu-coastline.json"), "--frame", "xc.json", "-o", "x.csv"], b"")
        .fails(2, "xc.json:2:");
    w.write("fitr.json", frame.replacen("\"radius\": ", "\"radious\": 1, \"radius\": ", 1));
    w.run(BIN, &["plan", "--fit", "fitr.json", "-o", "x.csv"], b"").fails(2, "(fit.radious): unknown field");
    w.write("cyl.json", r#"{"shape": "cylinder", "point": [0, 0, 0], "axis": [0, 0, 1]}"#);
    w.run(BIN, &["fit", "pts.csv", "--truth", "cyl.json", "-o", "x.json"], b"").fails(2, "(radius): a cylinder needs");
    w.write("plane.json", r#"{"shape": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}"#);
    w.run(BIN, &["fit", "pts.csv", "--truth", "plane.json", "-o", "x.json"], b"")
        .fails(2, "the true element is a plane, the fit a sphere");
    assert!(!w.exists("x.csv") && !w.exists("x.json"));
}

/// Every numeric option must be a finite number in its range: NaN no longer reaches the output
/// tables (`reference --amplitude NaN` wrote NaN coordinates, exit 0).
#[test]
fn numeric_options_are_finite_and_in_range() {
    let w = Work::new();
    let coast = d("surf-probe-fit/honshu-coastline.json");
    let frame = d("surf-probe-fit/globe-true.json");
    let cases: [(&[&str], &str); 9] = [
        (&["reference", "--amplitude", "NaN"], "'--amplitude <AMPLITUDE>': expected a finite number, found \"NaN\""),
        (&["reference", "--centre", "NaN,0,0"], "--centre"),
        (&["reference", "--radius", "inf"], "--radius"),
        (&["reference", "--amplitude", "-1"], "--amplitude must be from 0"),
        (&["reference", "--extent", "200"], "--extent (a sphere's cap half-angle) must be from 0 to 180°"),
        (&["map", &coast, "--frame", &frame, "--lon0", "NaN"], "--lon0"),
        (&["map", &coast, "--frame", &frame, "--lon0", "1e300"], "--lon0 must be from -360 to 360°"),
        (&["plan", "--fit", &frame, "--max-polar", "-5"], "--max-polar must be from 0 to 180°"),
        (&["raster", "--x", "0,10", "--y", "0,10", "--z", "1e300"], "--z must be from -1000000 to 1000000 mm"),
    ];
    for (args, needle) in cases {
        w.run(BIN, &[args, &["-o", "x.csv"]].concat(), b"").fails(2, needle);
    }
    assert!(!w.exists("x.csv"));
}

/// The work of the generating sub-commands is estimated from the options before anything is
/// allocated, and refused past `--max-points` (they aborted on allocation before).
#[test]
fn work_past_the_bound_is_refused_before_it_starts() {
    let w = Work::new();
    let coast = d("surf-probe-fit/honshu-coastline.json");
    let frame = d("surf-probe-fit/globe-true.json");
    let cases: [(&[&str], &str); 5] = [
        (&["raster", "--x", "0,1e5", "--y", "0,10", "--step", "1e-9", "--z", "10"], "the raster of --region at --step"),
        (
            &["reference", "--points", "1000000000000"],
            "--points would give 1.0000e12 rows, more than --max-points 1000000",
        ),
        (
            &["map", &coast, "--frame", &frame, "--lon0", "138", "--step", "1e-9"],
            "--step 0.000000001° along the outlines",
        ),
        (&["plan", "--fit", &frame, "--ring-step", "1e-9"], "--ring-step"),
        (&["reference", "--max-points", "100000000000"], "--max-points must be at most 10000000"),
    ];
    for (args, needle) in cases {
        w.run(BIN, &[args, &["-o", "x.csv"]].concat(), b"").fails(2, needle);
    }
    // The bound can be raised (and lowered).
    w.run(BIN, &["reference", "--points", "2000", "--max-points", "1999", "-o", "x.csv"], b"").fails(2, "--points");
    w.run(BIN, &["reference", "--points", "2000", "--max-points", "2000", "-o", "ok.csv"], b"").ok();
    assert_eq!(w.read("ok.csv").lines().count(), 2001);
    assert!(!w.exists("x.csv"));
}

/// Column names of raw records match without regard to case, as the table reader's own columns do
/// (`READING` was "missing column `reading`").
#[test]
fn record_columns_match_in_any_case() {
    let w = Work::new();
    let truth = d("surf-probe-fit/globe-true.json");
    w.run(BIN, &["raster", "--x", "-8,14", "--y", "-11,7", "--step", "2", "--z", "115.5", "-o", "raster.csv"], b"")
        .ok();
    w.run(BIN, &["simulate", "raster.csv", "--shape", &truth, "-o", "rec.csv"], b"").ok();
    let rec = w.read("rec.csv");
    let (head, body) = rec.split_once('\n').unwrap();
    w.write("upper.csv", format!("{}\n{body}", head.to_uppercase()));
    let lower = w.run(BIN, &["points", "rec.csv"], b"").ok();
    assert_eq!(w.run(BIN, &["points", "upper.csv"], b"").ok(), lower);
    w.write("both.csv", format!("{head},READING\n{}", body.replace('\n', ",1\n")));
    w.run(BIN, &["points", "both.csv"], b"").fails(2, "are the same column `reading`");
}

/// `--truth` compares a cylinder by its axis line and a plane by its offset and normal (a perfect
/// fit reported 0.427 mm and 10 mm: distances between unrelated points), and a 5° cap reaches the
/// exact least-squares solution (7.3e-7 mm off before).
#[test]
fn truth_errors_mean_something_for_each_kind() {
    let w = Work::new();
    let run = |set: &str, shape: &str, truth: &str| -> serde_json::Value {
        let args = ["fit", &d(set), "--shape", shape, "--truth", &d(truth), "-o", "f.json", "--report", "r.json"];
        w.run(BIN, &args, b"").ok();
        json(&w, "r.json")
    };
    let r = run("surf-probe-fit/cylinder_half_s7.csv", "cylinder", "surf-probe-fit/cylinder_half_s7.truth.json");
    assert!(r.get("origin_error_mm").is_none(), "{r}");
    assert!(r["axis_distance_mm"].as_f64().unwrap() < 1e-3, "{r}");
    assert!(r["axis_angle_deg"].as_f64().unwrap() < 1e-2, "{r}");
    assert!(r["radius_error_mm"].as_f64().unwrap().abs() < 1e-3, "{r}");
    let r = run("surf-probe-fit/plane_tilted_s7.csv", "plane", "surf-probe-fit/plane_tilted_s7.truth_shifted.json");
    assert!(r.get("origin_error_mm").is_none(), "{r}");
    assert!(r["plane_offset_mm"].as_f64().unwrap().abs() < 1e-3, "{r}");
    assert!(r["normal_angle_deg"].as_f64().unwrap() < 1e-2, "{r}");
    let r = run("surf-probe-fit/cap5_seed51.csv", "sphere", "surf-probe-fit/cap5_seed51.truth.json");
    assert!(r["origin_error_mm"].as_f64().unwrap() <= 1e-9, "{r}");
    assert!(r["radius_error_mm"].as_f64().unwrap().abs() <= 1e-9, "{r}");
}

/// Seeded fuzz of every numeric option of every sub-command with extreme, tiny, negative, huge,
/// non-finite and non-numeric values: each run ends with 0, 1 or 2 (no panic, no signal) under a
/// 4 GiB address-space bound and a time bound, and writes no NaN, infinity or null.
#[test]
fn every_numeric_option_survives_extreme_values() {
    let w = Work::new();
    let truth = d("surf-probe-fit/globe-true.json");
    let coast = d("surf-probe-fit/honshu-coastline.json");
    w.run(BIN, &["raster", "--x", "-8,14", "--y", "-11,7", "--step", "2", "--z", "115.5", "-o", "raster.csv"], b"")
        .ok();
    w.run(BIN, &["simulate", "raster.csv", "--shape", &truth, "-o", "rec.csv"], b"").ok();
    w.run(BIN, &["points", "rec.csv", "-o", "pts.csv"], b"").ok();
    w.run(BIN, &["fit", "pts.csv", "-o", "frame.json"], b"").ok();
    let values = [
        "0",
        "-0",
        "1e-300",
        "-1e-300",
        "1e-9",
        "-1",
        "0.5",
        "3",
        "4",
        "90",
        "181",
        "1e6",
        "1e7",
        "1e300",
        "-1e300",
        "NaN",
        "inf",
        "-inf",
        "1e400",
        "x",
        "",
        "18446744073709551616",
        "1000000000000",
    ];
    // Sub-command, its fixed arguments, and each numeric option with how a value goes in.
    let raster: &[&str] = &["raster", "--x", "-8,14", "--y", "-11,7", "--z", "115.5"];
    let simulate: &[&str] = &["simulate", "raster.csv", "--shape", &truth];
    let plan_sphere: &[&str] = &["plan", "--fit", "frame.json"];
    let plan_rough: &[&str] = &["plan", "pts.csv"];
    let fit_huber: &[&str] = &["fit", "pts.csv", "--robust", "huber"];
    let fit_ransac: &[&str] = &["fit", "pts.csv", "--robust", "ransac", "--max-hypotheses", "200"];
    let map: &[&str] = &["map", &coast, "--frame", "frame.json"];
    let options: Vec<(&[&str], &str, &str)> = vec![
        (raster, "--x", "{},14"),
        (raster, "--y", "-11,{}"),
        (raster, "--step", "{}"),
        (raster, "--z", "{}"),
        (raster, "--max-points", "{}"),
        (simulate, "--standoff", "{}"),
        (simulate, "--range", "{}"),
        (simulate, "--noise", "{}"),
        (simulate, "--slope-error", "{}"),
        (simulate, "--max-incidence", "{}"),
        (simulate, "--seed", "{}"),
        (plan_sphere, "--standoff", "{}"),
        (plan_sphere, "--max-polar", "{}"),
        (plan_sphere, "--ring-step", "{}"),
        (plan_sphere, "--max-points", "{}"),
        (plan_rough, "--every", "{}"),
        (plan_rough, "--max-slope", "{}"),
        (&["reference"], "--centre", "{},0,0"),
        (&["reference", "--shape", "cylinder"], "--axis", "0,{},1"),
        (&["reference", "--shape", "circle"], "--radius", "{}"),
        (&["reference", "--shape", "plane"], "--extent", "{}"),
        (&["reference"], "--extent", "{}"),
        (&["reference"], "--points", "{}"),
        (&["reference"], "--amplitude", "{}"),
        (&["reference"], "--seed", "{}"),
        (fit_huber, "--huber-k", "{}"),
        (fit_ransac, "--ransac-threshold", "{}"),
        (fit_ransac, "--confidence", "{}"),
        (fit_ransac, "--seed", "{}"),
        (&["fit", "pts.csv", "--robust", "ransac"], "--max-hypotheses", "{}"),
        (&["fit", "pts.csv"], "--max-amplification", "{}"),
        (&["surface", "pts.csv"], "--net", "{},8"),
        (map, "--lon0", "{}"),
        (map, "--step", "{}"),
        (map, "--depth", "{}"),
        (map, "--max-points", "{}"),
    ];
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let mut runs = 0;
    for (base, option, form) in &options {
        let mut picks: Vec<&str> = vec!["NaN", "1e300", "1e-9", "0"];
        picks.extend((0..5).map(|_| values[(next() % values.len() as u64) as usize]));
        for v in picks {
            let value = form.replace("{}", v);
            let args: Vec<&str> = base.iter().copied().chain([*option, value.as_str()]).collect();
            let out = std::process::Command::new("sh")
                .arg("-c")
                .arg("ulimit -v 4194304; exec timeout 60 \"$0\" \"$@\"")
                .arg(e2e::bin(BIN))
                .args(&args)
                .current_dir(w.path(""))
                .output()
                .expect("run");
            let status = out.status.code().unwrap_or(-1);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!((0..=2).contains(&status), "{args:?}: status {status}, stderr {stderr}");
            assert!(!stderr.contains("internal error") && !stderr.contains("panicked"), "{args:?}: {stderr}");
            if status != 0 {
                assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: one line: {stderr}");
            }
            let text = String::from_utf8_lossy(&out.stdout).to_lowercase();
            assert!(
                !text.contains("nan") && !text.contains("inf") && !text.contains("null"),
                "{args:?}: non-finite output"
            );
            runs += 1;
        }
    }
    assert!(runs >= 300, "{runs} runs");
}

/// One spelling of a rectangle (issue 21): `raster --region X0,X1,Y0,Y1` as in stylus-trace and
/// rough-sim writes the same raster as the older `--x MIN,MAX --y MIN,MAX`; a reversed range is
/// refused naming `--region`.
#[test]
fn raster_region_is_spelt_as_everywhere() {
    let w = Work::new();
    let new = w.run(BIN, &["raster", "--region=-8,14,-11,7", "--step", "2", "--z", "115.5"], b"").ok();
    let old = w.run(BIN, &["raster", "--x", "-8,14", "--y", "-11,7", "--step", "2", "--z", "115.5"], b"").ok();
    assert_eq!(new, old);
    assert!(new.lines().count() > 100, "{new}");
    w.run(BIN, &["raster", "--region=14,-8,-11,7", "--z", "115.5"], b"").fails(2, "--region");
    w.run(BIN, &["raster", "--z", "115.5"], b"").fails(2, "--region");
}
