//! Side by side with bare cavalier_contours on dense stars and a pocket to empty: time (median
//! and best of interleaved runs), whether bare cavalier's result passes our verification, and
//! our retries.
//! Also writes the inputs as polygons for the pyclipper script (`scripts/bench-offset.sh`).
//!
//! `cargo run --release -p offset --example offset_peers -- [OUTDIR]`

use camkit::contour::offset::{Side, check_offset, offset_contour};
use camkit::contour::pocket::{Direction, Passes, PocketOptions, pocket};
use camkit::contour::region::regions;
use camkit::contour::{Contour, OffsetOptions, Vertex};
use camkit::geom::P2;
use cavalier_contours::polyline::{PlineOffsetOptions, PlineSource, PlineSourceMut, Polyline};
use cavalier_contours::shape_algorithms::{Shape, ShapeOffsetOptions};
use std::time::Instant;

mod stars;
use stars::star;

fn pline(c: &Contour) -> Polyline<f64> {
    let mut p = Polyline::new_closed();
    for v in &c.vertices {
        p.add(v.p.x, v.p.y, v.bulge);
    }
    p
}

fn contour_of(p: &Polyline<f64>) -> Contour {
    Contour {
        vertices: p.iter_vertexes().map(|v| Vertex { p: P2::new(v.x, v.y), bulge: v.bulge }).collect(),
        closed: p.is_closed(),
    }
}

/// Median and best seconds of `runs` calls of `a` and of `b`, interleaved (a, b, a, b, ...) so
/// that both see the same load, with the last results.
fn time2<A, B>(runs: usize, mut a: impl FnMut() -> A, mut b: impl FnMut() -> B) -> ([f64; 2], [f64; 2], A, B) {
    let (mut ta, mut tb, mut ra, mut rb) = (Vec::new(), Vec::new(), None, None);
    for _ in 0..runs {
        let s = Instant::now();
        ra = Some(a());
        ta.push(s.elapsed().as_secs_f64());
        let s = Instant::now();
        rb = Some(b());
        tb.push(s.elapsed().as_secs_f64());
    }
    let stats = |t: &mut Vec<f64>| {
        t.sort_by(f64::total_cmp);
        [t[t.len() / 2], t[0]]
    };
    (stats(&mut ta), stats(&mut tb), ra.expect("ran"), rb.expect("ran"))
}

fn main() {
    let dir = std::env::args().nth(1).unwrap_or_else(|| "target/offset-bench".into());
    std::fs::create_dir_all(&dir).expect("output dir");
    println!(
        "| input | offset | bare cavalier ms (median / best) | bare result | ours ms (median / best) | kernel runs | \
         ratio median | ratio best |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (n, arcs) in [(1000, false), (10_000, false), (1000, true), (10_000, true)] {
        let c = star(n, arcs);
        let poly: String = c.vertices.iter().map(|v| format!("{},{}\n", v.p.x, v.p.y)).collect();
        let name = format!("star-{n}-{}", if arcs { "arcs" } else { "lines" });
        std::fs::write(format!("{dir}/{name}.csv"), format!("x,y\n{poly}")).expect("write");
        let p = pline(&c);
        for d in [2.0, 5.0, -2.0] {
            let runs = if n > 5000 { 9 } else { 31 };
            let side = if d > 0.0 { Side::Left } else { Side::Right };
            let (bare_s, ours_s, bare, ours) = time2(
                runs,
                || p.parallel_offset_opt(d, &PlineOffsetOptions::default()),
                || offset_contour(&c, d.abs(), side, &OffsetOptions::default()),
            );
            let open = bare.iter().filter(|q| !q.is_closed()).count();
            // Bare cavalier's own result through our verification.
            let bare_contours: Vec<Contour> = bare.iter().map(contour_of).collect();
            let bare_check = check_offset(&[&c], &bare_contours, d.abs(), side, true, OffsetOptions::default().tol);
            let (verdict, runs_used) = match &ours {
                Ok(o) => (format!("{} loops", o.contours.len()), o.attempts.to_string()),
                Err(e) => (format!("error: {e}"), "-".into()),
            };
            let bare_text = match bare_check {
                Ok(_) => format!("{} loops, verified", bare.len()),
                Err(e) => format!("FAILS ({} pieces, {open} open): {}", bare.len(), e.describe()),
            };
            println!(
                "| {name} | {d:+} | {:.2} / {:.2} | {bare_text} | {:.2} / {:.2} ({verdict}) | {runs_used} | {:.2} | {:.2} |",
                bare_s[0] * 1e3,
                bare_s[1] * 1e3,
                ours_s[0] * 1e3,
                ours_s[1] * 1e3,
                ours_s[0] / bare_s[0],
                ours_s[1] / bare_s[1]
            );
        }
    }
    // Pocket to empty: the 10k line star, tool radius 1.5, step 2.
    let c = star(10_000, false);
    let (rs, _) = regions(std::slice::from_ref(&c)).expect("a region");
    let opts = PocketOptions {
        radius: 1.5,
        step: 2.0,
        passes: Passes::UntilEmpty,
        direction: Direction::Climb,
        offset: OffsetOptions::default(),
    };
    let shape = Shape::from_plines([pline(&rs[0].outer)]);
    let bare = || {
        let mut k = 0;
        loop {
            let s = shape.parallel_offset(1.5 + 2.0 * k as f64, &ShapeOffsetOptions::default());
            if s.ccw_plines.is_empty() && s.cw_plines.is_empty() {
                break k;
            }
            k += 1;
        }
    };
    let (bare_s, ours_s, levels, ours) = time2(5, bare, || pocket(&rs, &opts));
    let ours = ours.expect("pocket");
    println!(
        "| star-10000-lines pocket | r 1.5 step 2 | {:.2} / {:.2} | {levels} levels | {:.2} / {:.2} ({} passes, {} levels) | {} | {:.2} | {:.2} |",
        bare_s[0] * 1e3,
        bare_s[1] * 1e3,
        ours_s[0] * 1e3,
        ours_s[1] * 1e3,
        ours.passes.len(),
        ours.passes.iter().map(|p| p.level + 1).max().unwrap_or(0),
        ours.attempts,
        ours_s[0] / bare_s[0],
        ours_s[1] / bare_s[1]
    );
}
