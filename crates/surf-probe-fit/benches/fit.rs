//! Speed of the geometric fits: a sphere of 1 M points (the target is under a second on
//! one core; run with RAYON_NUM_THREADS=1 for that figure) and a cylinder of 100 k points, on
//! reference sets with known solutions. Timing lives here, never in tests.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use surf_probe_fit::reference::{Spec, generate};
use surf_probe_fit::{Kind, Options, Shape, fit};

fn sphere(c: &mut Criterion) {
    let shape = Shape::Sphere { centre: [120.0, -85.0, 64.0], radius: 25.0 };
    let set = generate(&Spec { shape, points: 1_000_000, amplitude: 0.01, extent: 90.0, seed: 1 });
    let mut group = c.benchmark_group("sphere");
    group.sample_size(10);
    group.throughput(Throughput::Elements(set.points.len() as u64));
    group.bench_function("1M points, 90° cap", |b| {
        b.iter(|| black_box(fit(Kind::Sphere, &set.points, &Options::default()).expect("fits")))
    });
    group.finish();
}

fn cylinder(c: &mut Criterion) {
    let shape = Shape::Cylinder { point: [-40.0, 7.0, 3.0], axis: [0.1, 0.95, 0.3], radius: 12.5 };
    let set = generate(&Spec { shape, points: 100_000, amplitude: 0.01, extent: 60.0, seed: 2 });
    let mut group = c.benchmark_group("cylinder");
    group.sample_size(10);
    group.throughput(Throughput::Elements(set.points.len() as u64));
    group.bench_function("100k points", |b| {
        b.iter(|| black_box(fit(Kind::Cylinder, &set.points, &Options::default()).expect("fits")))
    });
    group.finish();
}

criterion_group!(benches, sphere, cylinder);
criterion_main!(benches);
