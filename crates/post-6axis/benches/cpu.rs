//! CL rows per CPU-second of one thread, read from `/proc/thread-self/schedstat` (Linux): the
//! issue's "1 M CL rows per second on one core before linearisation inserts" as a figure that a
//! loaded machine does not distort, unlike criterion's wall-clock figures (benches/post.rs).
//! Same input as benches/post.rs, on the six-axis machine and on paper 002's A/C machine. Every
//! stage runs in a one-thread rayon pool, measured on that thread.

use camkit::doc::machine::Machine;
use post_6axis::plan::{self, Cl};
use post_6axis::{Settings, nc, planning, post};
use std::hint::black_box;

mod common;
use common::rows;

/// A named stage of the post and the closure that runs it once.
type Stage<'a> = (&'static str, Box<dyn Fn() + Send + 'a>);

/// CPU time (ns) this thread has run.
fn thread_cpu_ns() -> u64 {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").expect("Linux schedstat");
    text.split_whitespace().next().and_then(|v| v.parse().ok()).expect("schedstat's first field")
}

/// Best CPU seconds of `runs` runs of `f`.
fn best(runs: usize, mut f: impl FnMut()) -> f64 {
    (0..runs)
        .map(|_| {
            let t0 = thread_cpu_ns();
            f();
            (thread_cpu_ns() - t0) as f64 * 1e-9
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    // `cargo bench` passes `--bench`; anything else (e.g. `cargo test --benches`) only checks it runs.
    let runs = if std::env::args().any(|a| a == "--bench") { 7 } else { 1 };
    let n = if runs > 1 { 100_000 } else { 2_000 };
    println!("| machine | stage | rows | CPU s (best of {runs}) | rows per CPU-second |");
    println!("|---|---|---|---|---|");
    for name in ["paper000-sixaxis-b.json", "paper002-ac.json"] {
        let path = format!("{}/../../data/post-6axis/{name}", env!("CARGO_MANIFEST_DIR"));
        let (machine, chain) = Machine::read(&path).expect("machine document");
        let mut cl = rows(n);
        if machine.spindle.is_none() {
            cl.iter_mut().for_each(|r: &mut Cl| r.s = None);
        }
        let m = planning(&machine, &chain);
        let opts = plan::Options { tol: 0.004, ..plan::Options::default() };
        let (steps, stats) = plan::plan(&cl, &m, &opts).expect("plans");
        assert_eq!(stats.inserted, 0, "the bench measures rows before inserts");
        let wopts = nc::WriteOptions { rotary_radius: 10.0, comments: vec![] };
        let settings = Settings::default();
        let stages: [Stage; 3] = [
            ("poses + linearisation check", Box::new(|| drop(black_box(plan::plan(&cl, &m, &opts).expect("plans"))))),
            ("NC text", Box::new(|| drop(black_box(nc::write(&steps, &machine, &chain, &wopts).expect("writes"))))),
            (
                "whole post with read-back",
                Box::new(|| drop(black_box(post(&cl, "bench", &machine, &chain, &settings, vec![]).expect("posts")))),
            ),
        ];
        // One worker thread: the read-back check's parallel chunks run on the thread measured.
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a thread pool");
        for (stage, f) in stages {
            let s = pool.install(|| best(runs, f));
            println!("| {name} | {stage} | {n} | {s:.4} | {:.0} |", n as f64 / s);
        }
    }
}
