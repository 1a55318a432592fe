//! Throughput of `post-6axis` in CL rows per second on one core: poses and the linearisation
//! check alone, then with the NC text written, then with the read-back check as the binary runs
//! it. Input: paper 000's smoothing of an R500 sphere (tool tilted −5° towards the feed, spindle
//! orientation along the feed) on the six-axis A/C machine, 0.2 mm between rows, so no block needs
//! inserting. Timing lives here, never in tests.

use camkit::doc::machine::Machine;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use post_6axis::plan;
use post_6axis::{Settings, nc, planning, post};
use std::hint::black_box;

mod common;
use common::rows;

fn bench(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/post-6axis/paper000-sixaxis-b.json");
    let (machine, chain) = Machine::read(path).expect("machine document");
    let cl = rows(100_000);
    let m = planning(&machine, &chain);
    let opts = plan::Options { tol: 0.004, ..plan::Options::default() };
    let (steps, stats) = plan::plan(&cl, &m, &opts).expect("plans");
    assert_eq!(stats.inserted, 0, "the bench measures rows before inserts");
    let mut group = c.benchmark_group("post-6axis");
    group.sample_size(10);
    group.throughput(Throughput::Elements(cl.len() as u64));
    group.bench_function("poses + linearisation check", |b| {
        b.iter(|| black_box(plan::plan(&cl, &m, &opts).expect("plans")))
    });
    let wopts = nc::WriteOptions { rotary_radius: 10.0, comments: vec![] };
    group.bench_function("poses + check + NC text", |b| {
        b.iter(|| {
            let (steps, _) = plan::plan(&cl, &m, &opts).expect("plans");
            black_box(nc::write(&steps, &machine, &chain, &wopts).expect("writes"))
        })
    });
    group.bench_function("NC text only", |b| {
        b.iter(|| black_box(nc::write(&steps, &machine, &chain, &wopts).expect("writes")))
    });
    let settings = Settings::default();
    group.bench_function("whole post with read-back", |b| {
        b.iter(|| black_box(post(&cl, "bench", &machine, &chain, &settings, vec![]).expect("posts")))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
