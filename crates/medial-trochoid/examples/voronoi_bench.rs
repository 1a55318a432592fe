//! Times the medial axis (boostvoronoi) of a wavy star pocket with N segments and writes the
//! segments it used (`builder_input`: integer, in the medial axis's own frame, grid RESOLUTION mm,
//! default the library's 1e-6) so that scripts/bench-trochoid.sh can give the same input to
//! Boost.Voronoi (pyvoronoi), and the ends of the kept medial edges in the same integer frame to
//! SEGMENTS_FILE.ends. Usage: voronoi_bench N SEGMENTS_FILE [RESOLUTION].

use camkit::contour::Contour;
use camkit::contour::region::regions;
use camkit::geom::P2;
use medial_trochoid::medial::{MedialOptions, builder_input, medial_axis};
use std::io::Write;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1000);
    let file = args.get(2).cloned().unwrap_or_else(|| "segments.txt".into());
    // A star with 7 lobes and a fine ripple: no two segments cross, many reflex vertices.
    let pts: Vec<P2> = (0..n)
        .map(|k| {
            let t = k as f64 / n as f64 * std::f64::consts::TAU;
            let r = 40.0 + 8.0 * (7.0 * t).sin() + 0.3 * ((n as f64 / 4.0).floor() * t).sin();
            P2::new(r * t.cos(), r * t.sin())
        })
        .collect();
    let region = regions(&[Contour::polygon(&pts, true)]).expect("a simple star").0.remove(0);
    let mut opts = MedialOptions::default();
    if let Some(r) = args.get(3) {
        opts.resolution = r.parse().expect("RESOLUTION in mm");
    }
    let (mut times, mut builds) = (Vec::new(), Vec::new());
    let mut edges = 0;
    let mut ends: Vec<P2> = Vec::new();
    for _ in 0..7 {
        let t0 = Instant::now();
        let m = medial_axis(&region, &opts).expect("medial axis");
        times.push(t0.elapsed().as_secs_f64());
        builds.push(m.build_seconds);
        edges = m.edges.len();
        ends = m.edges.iter().flat_map(|e| [e.points[0], e.points[e.points.len() - 1]]).collect();
    }
    times.sort_by(f64::total_cmp);
    builds.sort_by(f64::total_cmp);
    let (frame, segments) = builder_input(&region, &opts).expect("snapped boundary");
    let mut f = std::fs::File::create(&file).expect("segments file");
    for [ax, ay, bx, by] in segments {
        writeln!(f, "{ax} {ay} {bx} {by}").expect("write");
    }
    let mut g = std::fs::File::create(format!("{file}.ends")).expect("ends file");
    for p in &ends {
        let (x, y) = frame.to_grid(p);
        writeln!(g, "{x} {y}").expect("write");
    }
    println!(
        "segments {n} medial_edges {edges} best_ms {:.3} median_ms {:.3} (voronoi build alone: best {:.3} median {:.3})",
        times[0] * 1e3,
        times[3] * 1e3,
        builds[0] * 1e3,
        builds[3] * 1e3
    );
}
