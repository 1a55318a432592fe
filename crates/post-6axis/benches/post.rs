//! Throughput of `post-6axis` in CL rows per second on one core: poses and the linearisation
//! check alone, then with the NC text written, then with the read-back check as the binary runs
//! it. Input: paper 000's smoothing of an R500 sphere (tool tilted −5° towards the feed, spindle
//! orientation along the feed) on the six-axis A/C machine, 0.2 mm between rows, so no block needs
//! inserting. Timing lives here, never in tests.

use camkit::doc::machine::Machine;
use camkit::geom::{P3, V3};
use camkit::kinematics::edge_angle;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use post_6axis::plan::{self, Cl};
use post_6axis::{Settings, nc, planning, post};
use std::hint::black_box;

/// Scan lines over the top of an R500 sphere, `n` rows.
fn rows(n: usize) -> Vec<Cl> {
    let (r, c) = (500.0, P3::new(0.0, 0.0, -500.0));
    let per_line = 1000;
    (0..n)
        .map(|i| {
            let (line, k) = (i / per_line, i % per_line);
            let y = -20.0 + line as f64;
            let x = -100.0 + k as f64 * 0.2;
            let p = P3::new(x, y, c.z + (r * r - x * x - y * y).sqrt());
            let normal = (p - c) / r;
            let feed = V3::x();
            let feed = (feed - normal * normal.dot(&feed)).normalize();
            let t = (-5.0f64).to_radians();
            let axis = (normal * t.cos() + feed * t.sin()).normalize();
            let s = edge_angle(&axis, &(feed - axis * axis.dot(&feed)).normalize());
            Cl { tip: p, axis, s: Some(s), feed: Some(1000.0), rapid: k == 0, line: i as u64 + 2 }
        })
        .collect()
}

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
