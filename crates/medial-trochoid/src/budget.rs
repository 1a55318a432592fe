//! The memory a plan will hold, estimated from the pocket and the settings before planning
//! (see [`camkit::budget`]): the passes and trochoids cover the pocket at the step over, their
//! samples lie `--sample` apart, each sample is simulated and written once per layer, and the
//! Voronoi input holds the arcs' chords. Tiny spacings or huge layer counts are refused up
//! front instead of aborting on an allocation (5.6 GB at `--sample 1e-6` on a 60 × 40 pocket)
//! or running for hours.

use crate::Settings;
use camkit::contour::Seg;
use camkit::contour::region::Region;

/// Bytes held per engagement sample of one program: the sample, its engagement, load and feed,
/// and the pieces of the cut it indexes (a generous round figure).
const SAMPLE_BYTES: f64 = 256.0;
/// Bytes per Voronoi input point (the builder's site, its cells and edges).
const SITE_BYTES: f64 = 1024.0;

/// Bytes the plan of `regions` under `s`, written as `layers` layers, is estimated to hold:
/// both programs' samples (the offset passes, the area over the step over plus the walls; the
/// trochoids, a loop of 2π·rt per pitch along the walls, the pitch being the step over unless
/// given), their rows once per layer, and the chords of the arcs in the Voronoi input.
pub fn memory(regions: &[Region], s: &Settings, layers: usize) -> f64 {
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
    let samples = (passes + trochoids) / s.sample + sites;
    2.0 * samples * (SAMPLE_BYTES + layers as f64 * camkit::budget::ROW_BYTES) + sites * SITE_BYTES
}
