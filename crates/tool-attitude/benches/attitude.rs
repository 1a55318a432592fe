//! Speed of the cylindrical tool's poses with and without the gouge check, on an R500 sphere.

use camkit::geom::{P3, V3};
use camkit::io::Input;
use camkit::model::Model;
use criterion::{Criterion, criterion_group, criterion_main};
use tool_attitude::gouge::Part;
use tool_attitude::{Contact, Setup, Shape, attitude};

fn contacts() -> Vec<Contact> {
    let centre = P3::new(0.0, 0.0, -500.0);
    (0..1000)
        .map(|k| {
            let x = -50.0 + 0.1 * k as f64;
            let point = centre + V3::new(x, 0.0, 500.0).normalize() * 500.0;
            let normal = (point - centre).normalize();
            Contact {
                centre: point + normal * 12.5,
                point,
                normal,
                second: None,
                surfaces: (None, None),
                feed: V3::x(),
            }
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let cs = contacts();
    let setup = Setup {
        shape: Shape::Cylinder { radius: 12.5, cut_depth: 0.0 },
        tilt: (-5f64).to_radians(),
        range: ((-20f64).to_radians(), 0.0),
        length: 50.0,
        gouge_tol: 0.001,
    };
    let doc = r#"{"surfaces": [{"type": "sphere", "centre": [0, 0, -500], "radius": 500}]}"#;
    let model = Model::load(&Input { name: "sphere.json".into(), data: doc.as_bytes().to_vec() }).unwrap();
    let tool = r#"{"kind": "cylindrical-nonrotating", "radius": 12.5}"#;
    let tool: camkit::doc::Tool =
        camkit::json::from_input(&Input { name: "tool.json".into(), data: tool.as_bytes().to_vec() }).unwrap();
    let part = Part::new(model, &tool, 50.0, 2.5e-4).unwrap();
    for (name, m) in [("cylinder_1000_rows", None), ("cylinder_1000_rows_gouge_check", Some(&part))] {
        c.bench_function(name, |b| {
            b.iter(|| cs.iter().map(|ct| attitude(&setup, ct, m).unwrap().pose.tip.x).sum::<f64>())
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
