//! Times medial-trochoid's stages on a many-sided pocket: a regular N-gon of radius 40 mm (or,
//! with `wavy`, radius 40 + 3 sin 6θ around a round R8 island), φ10 tool, default options.
//! Prints the offset-only figures (hot samples, largest engagement) and the plan's.
//! Usage: ngon N [wavy].

use camkit::contour::Contour;
use camkit::contour::region::regions;
use camkit::geom::P2;
use medial_trochoid::feed::FeedModel;
use medial_trochoid::medial::MedialOptions;
use medial_trochoid::program::Tag;
use medial_trochoid::{Settings, plan};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(400);
    let wavy = args.get(2).is_some_and(|s| s == "wavy");
    let pts: Vec<P2> = (0..n)
        .map(|k| {
            let a = k as f64 / n as f64 * std::f64::consts::TAU;
            let r = 40.0 + if wavy { 3.0 * (6.0 * a).sin() } else { 0.0 };
            P2::new(50.0 + r * a.cos(), 50.0 + r * a.sin())
        })
        .collect();
    let mut loops = vec![Contour::polygon(&pts, true)];
    if wavy {
        loops.push(Contour::circle(P2::new(50.0, 50.0), 8.0, 0.0, false));
    }
    let regions = regions(&loops).expect("a simple pocket").0;
    let r = 5.0;
    let s = Settings {
        radius: r,
        step: r * (1.0 - 40f64.to_radians().cos()),
        threshold: 40.0,
        trochoid_radius: 0.5 * r,
        pitch: None,
        allowance: 0.0,
        corner_radius: None,
        sample: 0.5,
        medial: MedialOptions::default(),
        feed: FeedModel { spindle: 4800.0, teeth: 6.0, chip: 0.03, fz_max: 0.1, force_at: Some(40.0) },
        entry: medial_trochoid::program::Entry::FLAT,
    };
    let t0 = Instant::now();
    let p = plan(&regions, &s).expect("a plan");
    let secs = t0.elapsed().as_secs_f64();
    let count = |t: Tag| p.trochoidal.program.moves.iter().filter(|m| m.tag == t).count();
    println!(
        "{n}-gon{}: {secs:.2} s; offset-only: {} samples, {} hot, largest {:.6}°; trochoidal: {} samples, moves trochoid {} contour {} link {}, largest {:.6}°, over {}, links over {}, runs {}, uncleared {}, rests {}, repair rounds {}, left over {}",
        if wavy { " wavy+island" } else { "" },
        p.offset_only.samples.len(),
        p.danger_samples,
        p.offset_only.max_cutting,
        p.trochoidal.samples.len(),
        count(Tag::Trochoid),
        count(Tag::Contour),
        count(Tag::Link),
        p.trochoidal.max_cutting,
        p.trochoidal.over,
        p.trochoidal.over_links,
        p.runs.len(),
        p.uncleared.len(),
        p.rests.len(),
        p.repair_rounds,
        p.left_over.len(),
    );
}
