//! The measuring pieces against closed forms: the sensor's reading and its slope error, raw
//! records through paper 002's A/C chain and back, the rough surface's normals on a sphere, and
//! the plan's poses at the stand-off along the normals.

use camkit::doc::machine::Machine;
use camkit::geom::{P3, V3};
use surf_probe_fit::records::{Record, joints_for, to_point};
use surf_probe_fit::rng::Rng;
use surf_probe_fit::rough::{plan_from_surface, plan_on_sphere, triangulate};
use surf_probe_fit::sensor::Sensor;
use surf_probe_fit::shapes::Shape;

fn ball() -> Shape {
    Shape::Sphere { centre: [3.0, -2.0, 40.0], radius: 25.0 }
}

#[test]
fn reading_error_grows_with_incidence_as_modelled() {
    let exact = Sensor { noise: 0.0, slope_error: 0.0, ..Sensor::default() };
    let biased = Sensor { noise: 0.0, slope_error: 0.02, ..Sensor::default() };
    let mut rng = Rng::new(1);
    for deg in [0.0f64, 20.0, 45.0, 60.0, 70.0] {
        // A vertical beam hitting the sphere where its normal is `deg` from +Z.
        let t = deg.to_radians();
        let hit = P3::new(3.0 + 25.0 * t.sin(), -2.0, 40.0 + 25.0 * t.cos());
        let tip = hit + V3::z() * 50.0;
        let r = exact.read(&ball(), &tip, &V3::z(), &mut rng).unwrap();
        assert!((r.value - 50.0).abs() < 1e-9 && (r.incidence - deg).abs() < 1e-6, "{r:?}");
        let b = biased.read(&ball(), &tip, &V3::z(), &mut rng).unwrap();
        assert!((b.value - 50.0 - 0.02 * (1.0 / t.cos() - 1.0)).abs() < 1e-9);
        // Along the normal there is no slope error.
        let n = V3::new(t.sin(), 0.0, t.cos());
        let b = biased.read(&ball(), &(hit + n * 50.0), &n, &mut rng).unwrap();
        assert!((b.value - 50.0).abs() < 1e-9 && b.incidence < 1e-6);
    }
    assert!(exact.read(&ball(), &P3::new(3.0 + 24.9, -2.0, 90.0), &V3::z(), &mut rng).is_none(), "too oblique");
}

#[test]
fn records_round_trip_through_the_ac_chain() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/post-6axis/paper002-ac.json");
    let (m, chain) = Machine::read(path).unwrap();
    let chain = chain.with_frame(V3::zeros());
    let probes = plan_on_sphere(&P3::new(3.0, -2.0, 40.0), 25.0, 80.0, 20.0);
    let poses: Vec<(P3, V3)> = probes.iter().map(|p| (p.tip(50.0), p.normal)).collect();
    let joints = joints_for(&chain, &poses, m.singular_cone.to_radians()).unwrap();
    for ((p, (tip, axis)), j) in probes.iter().zip(&poses).zip(&joints) {
        let pose = chain.forward(j);
        assert!((pose.tip - tip).norm() < 1e-9 && (pose.axis - axis).norm() < 1e-9);
        let q = to_point(&chain, &Record { joints: *j, reading: 50.0 });
        assert!((q - p.point).norm() < 1e-9, "{q} vs {}", p.point);
    }
    // Tilted poses really turn the table.
    assert!(joints.iter().any(|j| j.rot[1].abs() > 60.0));
}

#[test]
fn rough_surface_normals_follow_the_sphere() {
    let c = P3::new(3.0, -2.0, 40.0);
    let mut pts = Vec::new();
    let mut paths = Vec::new();
    for j in -10..=10 {
        for i in -10..=10 {
            let (x, y) = (3.0 + 2.0 * i as f64, -2.0 + 2.0 * j as f64);
            let h = 625.0 - (x - 3.0).powi(2) - (y + 2.0).powi(2);
            if h > 25.0 {
                pts.push(P3::new(x, y, 40.0 + h.sqrt()));
                paths.push(j as i64);
            }
        }
    }
    let s = triangulate(&pts, 80.0).unwrap();
    assert!(s.facets.len() > pts.len());
    let probes = plan_from_surface(&pts, &paths, &s, 1);
    let mut worst: f64 = 0.0;
    for p in &probes {
        let n = (p.point - c).normalize();
        let slope = n.z.acos().to_degrees();
        if slope < 60.0 {
            worst = worst.max(p.normal.angle(&n).to_degrees());
        }
        assert!((p.tip(50.0) - p.point - p.normal * 50.0).norm() < 1e-12);
    }
    // A 2 mm raster on an R25 sphere: the quadric normals are within 0.1° below 60° of slope
    // (facet averages of the same triangulation lean by up to 4.4°: one raster step's angle).
    assert!(worst < 0.2, "{worst}°");
}
