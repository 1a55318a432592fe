//! The memory a plan will hold, estimated from the pocket and the settings before planning
//! (see [`camkit::budget`]): the passes and trochoids cover the pocket at the step over, their
//! samples lie `--sample` apart, each sample is simulated and written once per layer, and the
//! Voronoi input holds the arcs' chords. Tiny spacings or huge layer counts are refused up
//! front instead of aborting on an allocation (5.6 GB at `--sample 1e-6` on a 60 × 40 pocket)
//! or running for hours.

use crate::Settings;
use camkit::contour::Seg;
use camkit::contour::region::Region;

/// Default `--max-work` (engagement samples): about 10 minutes of CPU at the 60 to 190 µs a
/// sample measured on the demo pockets, a plan of a square metre at a 4 mm tool.
pub const DEFAULT_WORK: f64 = 4e6;

/// Bytes held per engagement sample of one program: the sample, its engagement, load and feed,
/// and the pieces of the cut it indexes (a generous round figure).
const SAMPLE_BYTES: f64 = 256.0;
/// Bytes per Voronoi input point (the builder's site, its cells and edges).
const SITE_BYTES: f64 = 1024.0;

/// Engagement samples of one layer's plan of `regions` under `s` (both programs), estimated:
/// the offset passes (the area over the step over plus the walls) and the trochoids (a loop of
/// 2π·rt per pitch along the walls, the pitch being the step over unless given), `--sample`
/// apart, and the chords of the arcs in the Voronoi input. Also that input's sites.
fn samples_and_sites(regions: &[Region], s: &Settings) -> (f64, f64) {
    let loops = regions.iter().flat_map(|r| r.loops());
    let (mut area, mut walls, mut sites) = (0.0, 0.0, 0.0);
    for c in loops {
        area += c.area();
        walls += c.length();
        for seg in c.segs() {
            sites += match seg {
                Seg::Line(..) => 1.0,
                // Chords of sagitta s span 2·acos(1 − s/r) ≈ 2·√(2s/r) of the arc.
                Seg::Arc(a) => 1.0 + a.sweep.abs() / (2.0 * (2.0 * s.medial.sagitta / a.r).min(2.0).sqrt()),
            };
        }
    }
    let passes = area.abs() / s.step + walls;
    let trochoids = walls * std::f64::consts::TAU * s.trochoid_radius / s.pitch.unwrap_or(s.step);
    ((passes + trochoids) / s.sample + sites, sites)
}

/// Bytes the plan of `regions` under `s`, written as `layers` layers, is estimated to hold:
/// both programs' samples, their rows once per layer, and the Voronoi input.
pub fn memory(regions: &[Region], s: &Settings, layers: usize) -> f64 {
    let (samples, sites) = samples_and_sites(regions, s);
    2.0 * samples * (SAMPLE_BYTES + layers as f64 * camkit::budget::ROW_BYTES) + sites * SITE_BYTES
}

/// Work of the plan of `regions` under `s` in estimated engagement samples (`--max-work`):
/// the layers share one plan, so their count does not add to it.
pub fn work(regions: &[Region], s: &Settings) -> f64 {
    samples_and_sites(regions, s).0
}

/// Engagement samples of a given program analysed at `sample` mm (`--analyse`): one per
/// `sample` of each move and its end; they are the work and are held once with their rows.
pub fn given_samples(program: &crate::Program, sample: f64) -> f64 {
    program.moves.iter().map(|m| (m.seg.length() / sample).ceil().max(1.0)).sum()
}

/// Bytes held by the analysis of `samples` engagement samples of a given program.
pub fn given_memory(samples: f64) -> f64 {
    samples * (SAMPLE_BYTES + camkit::budget::ROW_BYTES)
}
