//! The bicubic height field: a bicubic polynomial is reproduced exactly; a sphere cap sampled on
//! a grid is fitted within a micrometre, and the written control net, read as a camkit model, has
//! the points on its surface (an independent evaluation by `camkit::model`).

use camkit::doc::model::ModelDoc;
use camkit::geom::P3;
use camkit::model::Model;
use surf_probe_fit::heightfield::fit;

fn grid(f: impl Fn(f64, f64) -> f64) -> Vec<P3> {
    let mut pts = Vec::new();
    for j in 0..=30 {
        for i in 0..=30 {
            let (x, y) = (-15.0 + i as f64, -15.0 + j as f64);
            pts.push(P3::new(x, y, f(x, y)));
        }
    }
    pts
}

#[test]
fn bicubic_polynomials_are_reproduced() {
    let f = |x: f64, y: f64| 2.0 + 0.1 * x - 0.05 * y + 0.003 * x * x * y - 0.0004 * y * y * y + 0.001 * x * y;
    let h = fit(&grid(f), 8, 8).unwrap();
    assert!(h.rms < 1e-9 && h.largest_residual.abs() < 1e-8, "{} {}", h.rms, h.largest_residual);
}

#[test]
fn sphere_cap_fits_and_loads_as_a_model() {
    let f = |x: f64, y: f64| (60.0f64 * 60.0 - x * x - y * y).sqrt() - 40.0;
    let pts = grid(f);
    let h = fit(&pts, 10, 10).unwrap();
    assert!(h.rms < 1e-4 && h.largest_residual.abs() < 1e-3, "{} {}", h.rms, h.largest_residual);
    let doc =
        serde_json::json!({"surfaces": [{"type": "bspline", "name": "measured", "control_points": h.control_points}]});
    let input = camkit::io::Input { name: "m.json".into(), data: doc.to_string().into_bytes() };
    let doc = ModelDoc::from_input(&input).unwrap();
    let model = Model::from_doc(&doc, "m.json", std::path::Path::new(".")).unwrap();
    let worst = pts.iter().map(|p| model.nearest(p).distance).fold(0.0, f64::max);
    assert!(worst < 1e-3, "{worst}");
}
