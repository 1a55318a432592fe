//! The bicubic height field: a bicubic polynomial is reproduced exactly; a sphere cap sampled on
//! a grid is fitted within a micrometre, and the written control net, read as a camkit model, has
//! the points on its surface (an independent evaluation by `camkit::model`). Orthogonal distances
//! (closest point by Newton) against closed forms: a tilted plane, a curved bicubic patch (points
//! offset along its analytic normal), a sphere cap (distance from the centre minus the radius).

use camkit::doc::model::ModelDoc;
use camkit::geom::{P3, V3};
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

/// Points offset by `d` along the unit normal of `z = f(x, y)` (gradient `g`) at interior grid
/// positions, with the feet and offsets.
fn offsets(f: impl Fn(f64, f64) -> f64, g: impl Fn(f64, f64) -> (f64, f64)) -> Vec<(P3, P3, f64)> {
    let mut out = Vec::new();
    for k in 0..200 {
        let (x, y) = (-12.0 + 24.0 * ((k * 37) % 200) as f64 / 199.0, -12.0 + 24.0 * k as f64 / 199.0);
        let d = 0.5 * ((k as f64) * 0.7).sin();
        let (gx, gy) = g(x, y);
        let n = V3::new(-gx, -gy, 1.0).normalize();
        let foot = P3::new(x, y, f(x, y));
        out.push((foot + n * d, foot, d));
    }
    out
}

#[test]
fn orthogonal_distance_on_a_tilted_plane() {
    let (a, b) = (0.3, -0.2);
    let h = fit(&grid(|x, y| a * x + b * y + 1.0), 6, 6).unwrap();
    assert!(h.rms < 1e-9 && h.orthogonal_rms < 1e-9, "{} {}", h.rms, h.orthogonal_rms);
    let slope = (1.0f64 + a * a + b * b).sqrt();
    for (p, foot, d) in offsets(|x, y| a * x + b * y + 1.0, |_, _| (a, b)) {
        let c = h.closest(&p);
        assert!((c.distance - d).abs() < 1e-9 && (c.point - foot).norm() < 1e-9, "{p} {c:?} {d}");
        // The vertical residual is the orthogonal distance times sqrt(1 + a^2 + b^2).
        assert!((p.z - h.jet(p.x, p.y).h - d * slope).abs() < 1e-9);
    }
}

#[test]
fn orthogonal_distance_on_a_curved_patch() {
    let f = |x: f64, y: f64| 2.0 + 0.1 * x - 0.05 * y + 0.003 * x * x * y - 0.0004 * y * y * y + 0.001 * x * y;
    let g = |x: f64, y: f64| (0.1 + 0.006 * x * y + 0.001 * y, -0.05 + 0.003 * x * x - 0.0012 * y * y + 0.001 * x);
    let h = fit(&grid(f), 8, 8).unwrap();
    let mut worst_vertical: f64 = 0.0;
    for (p, foot, d) in offsets(f, g) {
        let c = h.closest(&p);
        assert!((c.distance - d).abs() < 1e-9 && (c.point - foot).norm() < 1e-8, "{p} {c:?} {d}");
        let vertical = p.z - h.jet(p.x, p.y).h;
        assert!(vertical.abs() >= c.distance.abs() - 1e-12);
        worst_vertical = worst_vertical.max((vertical - d).abs());
    }
    assert!(worst_vertical > 0.01, "the vertical residual differs from the distance: {worst_vertical}");
}

#[test]
fn orthogonal_distance_on_a_sphere_cap() {
    let (r, zc) = (30.0, -10.0);
    let f = |x: f64, y: f64| (r * r - x * x - y * y).sqrt() + zc;
    let h = fit(&grid(f), 16, 16).unwrap();
    let approx = h.largest_residual.abs();
    assert!(approx < 1e-4, "{approx}");
    // An R30 cap up to 41° of slope: orthogonal distances within twice the surface's own
    // approximation error (2.6e-5 mm; found 2.6e-5) of |p − c| − R, where vertical residuals are up
    // to 34 % larger.
    let centre = P3::new(0.0, 0.0, zc);
    let mut steep = 0;
    for k in 0..100 {
        let (x, y) = (-14.0 + 28.0 * ((k * 37) % 100) as f64 / 99.0, -14.0 + 28.0 * k as f64 / 99.0);
        let d = 0.3 * ((k as f64) * 1.3).cos();
        let on = P3::new(x, y, f(x, y));
        let p = on + (on - centre).normalize() * d;
        let exact = (p - centre).norm() - r;
        let c = h.closest(&p);
        assert!((c.distance - exact).abs() <= 2.0 * approx, "{p}: {} vs {exact}", c.distance);
        let vertical = p.z - h.jet(p.x, p.y).h;
        if (vertical - exact).abs() > 0.1 * exact.abs() + 4.0 * approx {
            steep += 1;
        }
    }
    assert!(steep > 10, "vertical residuals err by over 10 % on the steeper part: {steep}");
}

#[test]
fn fitted_field_reports_orthogonal_residuals() {
    let (a, b) = (0.6, 0.4);
    let mut pts = grid(|x, y| a * x + b * y);
    for (k, p) in pts.iter_mut().enumerate() {
        p.z += 0.002 * ((k * 7919) % 13) as f64 / 6.0 - 0.002;
    }
    let h = fit(&pts, 6, 6).unwrap();
    let slope = (1.0f64 + a * a + b * b).sqrt();
    assert!((h.orthogonal_rms * slope / h.rms - 1.0).abs() < 0.01, "{} {}", h.orthogonal_rms, h.rms);
    assert!(h.largest_orthogonal.abs() <= h.largest_residual.abs() && h.largest_orthogonal != 0.0);
}
