//! One verified offset of a dense star, for instruction counts of its phases under callgrind
//! (`callgrind_annotate --inclusive=yes` splits the kernel run from the verification), or with
//! `time` as a fourth argument the best wall times of the kernel alone, of the verification of
//! its result and of the whole verified offset.
//!
//! `RAYON_NUM_THREADS=1 valgrind --tool=callgrind target/release/examples/offset_phases N lines|arcs D [bare]`
//! (`bare`: cavalier_contours alone with its default options; `none`: the star alone; `pocket`: a pocket to empty with
//! radius D and step 2, timed; `pocket1`: that pocket once; `barepocket`: bare cavalier's shape offsets of the same
//! levels once; `levels`: each region offset of such a pocket timed alone).

use camkit::contour::offset::{Side, check_offset, offset_contour};
use camkit::contour::pocket::{Direction, Passes, PocketOptions};
use camkit::contour::region::Region;
use camkit::contour::{Contour, OffsetOptions, Vertex};
use camkit::geom::P2;
use cavalier_contours::polyline::{PlineOffsetOptions, PlineSource, PlineSourceMut, Polyline};
use std::time::Instant;

mod stars;

fn best<R>(runs: usize, mut f: impl FnMut() -> R) -> (f64, R) {
    let mut t = f64::INFINITY;
    let mut r = f();
    for _ in 0..runs {
        let s = Instant::now();
        r = f();
        t = t.min(s.elapsed().as_secs_f64());
    }
    (t * 1e3, r)
}

/// The region of `c` and the options of a climb pocket to empty at radius |d|, step 2.
fn pocket_of(c: &Contour, d: f64, offset: OffsetOptions) -> (Vec<Region>, PocketOptions) {
    let (rs, _) = camkit::contour::region::regions(std::slice::from_ref(c)).expect("a region");
    let po =
        PocketOptions { radius: d.abs(), step: 2.0, passes: Passes::UntilEmpty, direction: Direction::Climb, offset };
    (rs, po)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1000);
    let arcs = args.get(2).is_some_and(|s| s == "arcs");
    let d: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(2.0);
    let c = stars::star(n, arcs);
    let side = if d > 0.0 { Side::Left } else { Side::Right };
    let opts = OffsetOptions::default();
    if args.get(4).is_some_and(|s| s == "none") {
        // The star alone: the instructions every mode spends before its offset.
        println!("{} vertices", c.vertices.len());
        return;
    }
    if args.get(4).is_some_and(|s| s == "bare") {
        // Bare cavalier_contours alone (default options), for its instruction count.
        let mut p = Polyline::new_closed();
        for v in &c.vertices {
            p.add(v.p.x, v.p.y, v.bulge);
        }
        println!("{} pieces", p.parallel_offset_opt(d, &PlineOffsetOptions::default()).len());
        return;
    }
    if args.get(4).is_some_and(|s| s == "barepocket") {
        // Bare cavalier_contours' pocket to empty (default options, levels D + 2k until none is
        // left), once: the peer of `pocket` for instruction counts.
        use cavalier_contours::shape_algorithms::{Shape, ShapeOffsetOptions};
        let mut p = Polyline::new_closed();
        for v in &c.vertices {
            p.add(v.p.x, v.p.y, v.bulge);
        }
        let shape = Shape::from_plines([p]);
        let mut k = 0;
        while !shape.parallel_offset(d.abs() + 2.0 * k as f64, &ShapeOffsetOptions::default()).ccw_plines.is_empty() {
            k += 1;
        }
        println!("bare pocket: {k} levels");
        return;
    }
    if args.get(4).is_some_and(|s| s == "pocket1") {
        // Our pocket to empty once (radius D, step 2), for instruction counts.
        let (rs, po) = pocket_of(&c, d, opts);
        let p = camkit::contour::pocket::pocket(&rs, &po).expect("pocket");
        println!("pocket: {} passes, {} kernel runs", p.passes.len(), p.attempts);
        return;
    }
    if args.get(4).is_some_and(|s| s == "pocket") {
        let (rs, po) = pocket_of(&c, d, opts);
        let (ms, p) = best(2, || camkit::contour::pocket::pocket(&rs, &po));
        let p = p.expect("pocket");
        println!(
            "pocket: {ms:.1} ms, {} passes, {} kernel runs, {} clean-ups",
            p.passes.len(),
            p.attempts,
            p.clean_ups
        );
        return;
    }
    if args.get(4).is_some_and(|s| s == "levels") {
        let (rs, _) = camkit::contour::region::regions(std::slice::from_ref(&c)).expect("a region");
        let only: Option<f64> = args.get(5).and_then(|s| s.parse().ok());
        for k in 0..32 {
            let r = 1.5 + 2.0 * k as f64;
            if only.is_some_and(|o| o != r) {
                continue;
            }
            let (ms, o) = best(3, || camkit::contour::offset_region(&rs[0], r, &opts));
            let o = o.expect("verified");
            println!("level {k} d {r}: {ms:.2} ms, {} loops, {} attempts", o.contours.len(), o.attempts);
        }
        return;
    }
    if args.get(4).is_some_and(|s| s == "time") {
        let runs = if n > 5000 { 9 } else { 41 };
        let mut p = Polyline::new_closed();
        for v in &c.vertices {
            p.add(v.p.x, v.p.y, v.bulge);
        }
        let (bare, _) = best(runs, || p.parallel_offset_opt(d, &PlineOffsetOptions::default()));
        let eps = PlineOffsetOptions { pos_equal_eps: 1e-5, offset_dist_eps: 1e-5, ..Default::default() };
        let (kernel, out) = best(runs, || p.parallel_offset_opt(d, &eps));
        let index = p.create_aabb_index();
        let with_index = PlineOffsetOptions { aabb_index: Some(&index), ..eps };
        let (kernel_ix, out_ix) = best(runs, || p.parallel_offset_opt(d, &with_index));
        let same = out.len() == out_ix.len() && out.iter().zip(&out_ix).all(|(a, b)| a.vertex_data == b.vertex_data);
        println!("kernel with a given index {kernel_ix:.3} ms, same result: {same}");
        let out: Vec<Contour> = out
            .iter()
            .map(|q| Contour {
                vertices: q.iter_vertexes().map(|v| Vertex { p: P2::new(v.x, v.y), bulge: v.bulge }).collect(),
                closed: true,
            })
            .collect();
        let (check, _) = best(runs, || check_offset(&[&c], &out, d.abs(), side, true, opts.tol));
        let (ours, _) = best(runs, || offset_contour(&c, d.abs(), side, &opts));
        println!("bare {bare:.3} ms, kernel (eps 1e-5) {kernel:.3} ms, check {check:.3} ms, ours {ours:.3} ms");
        return;
    }
    let o = offset_contour(&c, d.abs(), side, &opts).expect("a verified offset");
    println!("{} loops, {} pieces, {} kernel runs", o.contours.len(), o.check.pieces, o.attempts);
}
