//! Throughput of `rough-sim`: grid nodes of the paper's surface computed per second, every node
//! by the exact envelope (all cores) for the plain ball and the flat-tipped tool, and the
//! issue's 10 × 10 mm patch at a 1 µm grid (one period computed, then repeated). Timing lives
//! here, never in tests.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rough_sim::cutter::Cutter;
use rough_sim::patch::{Conditions, Grid, simulate, simulate_nodes};
use std::hint::black_box;

/// Paper 003 fig. 2: r 5 mm, 2 flutes, pick 0.5 mm, 0.5 mm per tooth, tilt `tilt_deg`.
fn paper(tilt_deg: f64, flat_radius: f64) -> Conditions {
    Conditions {
        cutter: Cutter { flat_radius, ..Cutter::ball(5.0, 2) },
        pick: 0.5,
        feed_per_tooth: 0.5,
        tilt: tilt_deg.to_radians(),
        lean: -1.0,
        pass_phase: std::f64::consts::FRAC_PI_2,
    }
}

fn patch(c: &mut Criterion) {
    let mut group = c.benchmark_group("every node");
    group.sample_size(10);
    // A 1 × 1 mm patch (two pick feeds by two feeds per tooth) at a 5 µm grid: 201 × 201 nodes.
    let grid = Grid::covering(-0.5, 0.5, 0.0, 1.0, 0.005);
    group.throughput(Throughput::Elements((grid.nx * grid.ny) as u64));
    for (name, cond) in
        [("ball tilt 0", paper(0.0, 0.0)), ("ball tilt 3", paper(3.0, 0.0)), ("flat 0.5", paper(0.0, 0.5))]
    {
        group.bench_function(name, |b| b.iter(|| black_box(simulate_nodes(&cond, &grid))));
    }
    group.finish();
    // The speed case: 10 × 10 mm at 1 µm, 10⁸ nodes (800 MB of heights).
    let mut group = c.benchmark_group("patch 10 mm");
    group.sample_size(10);
    let grid = Grid::covering(-5.0, 5.0, 0.0, 10.0, 0.001);
    group.throughput(Throughput::Elements((grid.nx * grid.ny) as u64));
    let cond = paper(3.0, 0.0);
    group.bench_function("ball tilt 3, 1 um", |b| b.iter(|| black_box(simulate(&cond, &grid))));
    group.finish();
}

criterion_group!(benches, patch);
criterion_main!(benches);
