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
