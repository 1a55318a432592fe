//! Throughput of `curve-fit-arcs`: G-code read, fitted and written (MB/s of input), and points
//! fitted per second on a dense smooth curve. Timing lives here, never in tests.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use curve_fit_arcs::gcode_runs::fit_source;
use curve_fit_arcs::{Options, fit::Exact, segment};
use std::hint::black_box;

fn gcode(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/gcode/cncjs_jsdc-engrave.gcode");
    let source = std::fs::read_to_string(path).expect("data/gcode/cncjs_jsdc-engrave.gcode");
    let mut group = c.benchmark_group("gcode");
    group.throughput(Throughput::Bytes(source.len() as u64));
    for tol in [0.025, 0.005] {
        let opts = Options { tol, ..Options::default() };
        group.bench_function(format!("jsdc tol {tol}"), |b| {
            b.iter(|| {
                let mut out = Vec::with_capacity(source.len());
                black_box(
                    fit_source("jsdc", &mut || Ok(source.as_bytes()), &mut out, &opts, None, false).expect("fits"),
                );
                out
            })
        });
    }
    group.bench_function("jsdc read only", |b| {
        b.iter(|| black_box(camkit::gcode::read("jsdc", source.clone()).expect("parses")))
    });
    group.finish();
}

fn points(c: &mut Criterion) {
    // A spiral sampled every 0.05 mm: curvature changes everywhere, as in real CAM output.
    let pts: Vec<_> = (0..20_000)
        .map(|i| {
            let t = i as f64 * 0.002;
            let r = 10.0 + 2.0 * t;
            camkit::geom::P3::new(r * t.cos(), r * t.sin(), 0.0)
        })
        .collect();
    let mut group = c.benchmark_group("points");
    group.throughput(Throughput::Elements(pts.len() as u64));
    let opts = Options { tol: 0.01, ..Options::default() };
    group.bench_function("spiral 20k tol 0.01", |b| {
        b.iter(|| black_box(segment::segment(&pts, &opts, &Exact).expect("fits")))
    });
    group.finish();
}

criterion_group!(benches, gcode, points);
criterion_main!(benches);
