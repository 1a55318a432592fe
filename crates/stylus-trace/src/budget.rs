//! The resources a run will need, estimated from its options and the model's bounding box before
//! any work starts, and the bounds they are held to: `--max-memory` (bytes held: the CL points,
//! their output rows and the scan lines) and `--max-points` (CL points plus stylus drops, each a
//! few dozen nearest-point queries, about a microsecond). A run past either, or one whose
//! coordinates are so far out that round-off exceeds the contact tolerance, is refused as bad
//! input naming the option and the estimate, rather than aborting on an allocation or running
//! for hours.

use crate::Region;
use crate::curve::{Steps, Stylus};
use camkit::error::{Error, Result};
use camkit::model::Aabb;

/// Default bound of `--max-points`: about two minutes on two cores on analytic surfaces (a drop
/// on a sphere took 0.7 µs, 1.6e7 of them 6.8 s, at r = 1e-4 mm), up to ten on meshes (4.4 µs a
/// unit measured beside a sliver wall).
pub const DEFAULT_POINTS: f64 = 1e8;
/// Default bound of `--max-memory` (MB).
pub const DEFAULT_MEMORY_MB: u64 = 2147;
/// Bytes a CL point holds until it is written (the point, its table row and its text; 0.85 kB
/// measured on a sphere from 27 k to 272 k points).
const POINT_BYTES: f64 = 1024.0;
/// Bytes of one sample of the coverage check (its position and whether a drop hit).
const SAMPLE_BYTES: f64 = 16.0;
/// Bytes of one scan line or contour level (its frame and its list of passes).
const UNIT_BYTES: f64 = 128.0;
/// Round-off may be this many times a coordinate's last bit before it eats the contact
/// tolerance: a distance is a difference of positions, and a correction a few dozen of them.
const ROUND_OFF_MARGIN: f64 = 128.0;

/// The bounds of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Bytes (`--max-memory`).
    pub memory: f64,
    /// CL points and drops (`--max-points`).
    pub points: f64,
    /// What a point or drop costs on the model against one on an analytic surface
    /// ([`camkit::model::Model::query_weight`]): the points are counted that many times.
    pub weight: f64,
}

/// What a run is estimated to need.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Need {
    /// Bytes held at once.
    pub memory: f64,
    /// CL points and stylus drops.
    pub points: f64,
}

impl Need {
    /// Refuses a need beyond the budget; `what` names the run and the options that drive it.
    pub fn check(&self, budget: &Budget, what: &str) -> Result<()> {
        if !camkit::budget::fits(self.memory, budget.memory) {
            return Err(Error::input(format!(
                "{what} needs an estimated {:.0} MB, more than the bound of {:.0} MB (--max-memory): coarsen the steps, give a smaller --region or raise --max-memory",
                self.memory / 1e6,
                budget.memory / 1e6
            )));
        }
        if !camkit::budget::fits(self.points * budget.weight, budget.points) {
            let weighted = if budget.weight > 1.0 {
                format!(
                    " on surfaces {} times as costly as analytic ones ({:.3e} in all)",
                    budget.weight,
                    self.points * budget.weight
                )
            } else {
                String::new()
            };
            return Err(Error::input(format!(
                "{what} needs an estimated {:.3e} CL points and drops{weighted}, more than the bound of {:.3e} (--max-points): coarsen the steps, give a smaller --region or raise --max-points",
                self.points, budget.points
            )));
        }
        Ok(())
    }
}

/// The part of `region` the stylus can touch: the region and the model's box grown by r, in XY
/// (the region itself for an unbounded model); `None` when they miss each other.
pub fn traced_area(region: &Region, bounds: &Aabb, radius: f64) -> Option<Region> {
    let r = if bounds.is_bounded() {
        Region {
            x0: region.x0.max(bounds.min.x - radius),
            x1: region.x1.min(bounds.max.x + radius),
            y0: region.y0.max(bounds.min.y - radius),
            y1: region.y1.min(bounds.max.y + radius),
        }
    } else {
        *region
    };
    (r.x0 <= r.x1 && r.y0 <= r.y1).then_some(r)
}

/// Largest coordinate (mm) a run with this contact tolerance handles: beyond it the last bit of
/// a position, times [`ROUND_OFF_MARGIN`], exceeds the tolerance.
pub fn largest_coordinate(contact_tol: f64) -> f64 {
    contact_tol / (ROUND_OFF_MARGIN * f64::EPSILON)
}

/// Refuses coordinates (or lengths, the stylus radius) larger than [`largest_coordinate`];
/// `what` names where they come from.
pub fn check_round_off(values: &[f64], contact_tol: f64, what: &str) -> Result<()> {
    let limit = largest_coordinate(contact_tol);
    match values.iter().map(|v| v.abs()).find(|v| !camkit::budget::fits(*v, limit)) {
        Some(v) => Err(Error::input(format!(
            "{what} reaches {v:e} mm, beyond {limit:.3e} mm where the round-off of positions exceeds --contact-tol {contact_tol}: move the model towards the origin or give a --region near it"
        ))),
        None => Ok(()),
    }
}

/// Refuses a shortest step below the round-off of the coordinates `values` (64 of their last
/// bits, the largest of them at least 1 mm): such a step cannot be taken, and a bisection down to
/// it would never end.
pub fn check_min_step(min_step: f64, values: &[f64]) -> Result<()> {
    let largest = values.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let floor = 64.0 * f64::EPSILON * largest;
    if min_step < floor {
        return Err(Error::input(format!(
            "--min-step {min_step} is below the round-off of positions here ({floor:.1e} mm, coordinates up to {largest:e} mm)"
        )));
    }
    Ok(())
}

/// How many drops of ordinary length one drop costs: the stylus is lowered by steps about as long
/// as its distance from the model, which beside a part far taller than it is wide (a stray vertex
/// far up in z: a sliver wall) stays about the part's width all the way down from its top. The
/// model's `height` over the traced area's narrower side (at least r), at least 1.
pub fn drop_length(area: &Region, height: f64, radius: f64) -> f64 {
    let width = (area.x1 - area.x0).min(area.y1 - area.y0).max(radius);
    (height / width).max(1.0)
}

/// Scan mode: `lines` lines `pick` apart at `angle` degrees across `region`, the model under
/// them within `area` (the traced area), `height` high. At least the CL points of every line
/// over the area at the longest step; the samples where chords are checked by drops, one every
/// min(longest step, r/4), by the tracer over the area and by the coverage check along the whole
/// of every line (which holds a line's samples at once, in every thread); and a drop at least per
/// line. The line over the model's top climbs to it and comes down: the model's height twice at
/// the longest step (beside a stray vertex far up, a sliver a million mm high, this is where the
/// hours go). Every point is checked by a drop too, so points and drops cost [`drop_length`] each.
#[allow(clippy::too_many_arguments)]
pub fn scan(
    lines: f64,
    region: &Region,
    area: &Region,
    height: f64,
    angle: f64,
    pick: f64,
    stylus: &Stylus,
    steps: &Steps,
) -> Need {
    let (s, c) = angle.to_radians().sin_cos();
    let along = |r: &Region| (r.x1 - r.x0) * c.abs() + (r.y1 - r.y0) * s.abs();
    let across = (area.x1 - area.x0) * s.abs() + (area.y1 - area.y0) * c.abs();
    let crossing = lines.min(across / pick + 1.0);
    let points = (crossing * along(area) + 2.0 * height) / steps.max_step;
    let spacing = crate::scan::sample_spacing(stylus, steps);
    let traced_samples = crossing * along(area) / spacing;
    let line_samples = along(region) / spacing;
    let threads = lines.min(rayon::current_num_threads() as f64);
    let drops = points + traced_samples + lines * line_samples + lines;
    Need {
        memory: points * POINT_BYTES + lines * UNIT_BYTES + threads * line_samples * SAMPLE_BYTES,
        points: drops * drop_length(area, height, stylus.radius),
    }
}

/// Number of scan lines of a region at `angle` degrees, `pick` apart (as [`crate::scan::lines`]
/// makes them, before any is made).
pub fn scan_lines(region: &Region, angle: f64, pick: f64) -> f64 {
    let (s, c) = angle.to_radians().sin_cos();
    let across = (region.x1 - region.x0) * s.abs() + (region.y1 - region.y0) * c.abs();
    (across / pick).floor() + 1.0
}

/// Fixed-axis cutter mode: `lines` scan lines over `region`, each no longer than its diagonal,
/// a drop every `step` along it (and both ends).
pub fn fixed_axis(lines: f64, region: &Region, step: f64) -> Need {
    let diagonal = (region.x1 - region.x0).hypot(region.y1 - region.y0);
    let points = lines * ((diagonal / step).ceil() + 2.0);
    Need { memory: points * POINT_BYTES + lines * UNIT_BYTES, points }
}

/// Contour mode: `levels` levels across `region`, the model within `area` (the traced area); at
/// each, at least a loop round the area's outline at the longest step, and the seed lines r apart
/// across the whole region, each marched at steps of the order of r over the area.
pub fn contour(levels: f64, region: &Region, area: &Region, stylus: &Stylus, steps: &Steps) -> Need {
    let r = stylus.radius;
    let (w, h) = (area.x1 - area.x0 + 4.0 * r, area.y1 - area.y0 + 2.0 * r);
    let points = levels * 2.0 * (w + h) / steps.max_step;
    let seed_lines = (region.y1 - region.y0) / r + 3.0;
    let seeds = levels * seed_lines * (w / r + 1.0);
    Need { memory: points * POINT_BYTES + levels * UNIT_BYTES, points: points + seeds }
}

/// Two-surface mode: one concave line, as long as the way round the traced area's box `height`
/// high, at the longest step.
pub fn two_surface(area: &Region, height: f64, steps: &Steps) -> Need {
    let length = 2.0 * (area.x1 - area.x0 + area.y1 - area.y0 + height);
    let points = length / steps.max_step;
    Need { memory: points * POINT_BYTES, points }
}

#[cfg(test)]
mod tests {
    use super::*;

    const STYLUS: Stylus = Stylus { radius: 12.5, contact_tol: 1e-4 };
    const STEPS: Steps = Steps { chord_tol: 1e-3, max_step: 2.0, min_step: 1e-4 };

    /// The sphere R500 traced over 200 × 200 mm at pick 0.5 gave 401 lines, 54 429 points,
    /// 94 128 coverage drops and 39 699 chord samples: the estimate (of drops of ordinary length,
    /// the part as high as wide) is below the points and the work, within a factor of two of each.
    #[test]
    fn scan_estimate_matches_a_measured_run() {
        let area = Region { x0: -100.0, x1: 100.0, y0: -100.0, y1: 100.0 };
        assert_eq!(scan_lines(&area, 0.0, 0.5), 401.0);
        let need = scan(401.0, &area, &area, 200.0, 0.0, 0.5, &STYLUS, &STEPS);
        let points = (401.0 * 200.0 + 2.0 * 200.0) / STEPS.max_step;
        assert!(points < 54_429.0 && 2.0 * points > 54_429.0, "{points}");
        let work = 54_429.0 + 94_128.0 + 39_699.0;
        assert!(need.points < work && 2.0 * need.points > work, "{}", need.points);
        assert!(need.memory > points * 850.0);
        need.check(&Budget { memory: 2.147e9, points: DEFAULT_POINTS, weight: 1.0 }, "scan").unwrap();
    }

    /// Infinite or absurd estimates are refused, naming the bound.
    #[test]
    fn absurd_needs_are_refused() {
        let budget = Budget { memory: 2.147e9, points: DEFAULT_POINTS, weight: 1.0 };
        let area = Region { x0: -20.0, x1: 20.0, y0: -20.0, y1: 20.0 };
        let e = scan(scan_lines(&area, 0.0, 1e-9), &area, &area, 40.0, 0.0, 1e-9, &STYLUS, &STEPS)
            .check(&budget, "x")
            .unwrap_err();
        assert!(e.to_string().contains("--max-memory"), "{e}");
        let e = contour(f64::INFINITY, &area, &area, &STYLUS, &STEPS).check(&budget, "x").unwrap_err();
        assert!(e.to_string().contains("--max-memory"), "{e}");
        let e = Need { memory: 0.0, points: f64::NAN }.check(&budget, "x").unwrap_err();
        assert!(e.to_string().contains("--max-points"), "{e}");
        assert!(check_round_off(&[1e3, -2e13], 1e-4, "the model").is_err());
        assert!(check_round_off(&[1e3, -2e8], 1e-4, "the model").is_ok());
        assert!(check_round_off(&[f64::NAN], 1e-4, "the model").is_err());
        // A sliver wall 1e6 mm up over a 50 mm part: each drop costs 2e4 ordinary ones.
        assert_eq!(drop_length(&area, 1e6, 5.0), 1e6 / 40.0);
        assert_eq!(drop_length(&area, 30.0, 5.0), 1.0);
    }

    /// A 40 mm dome whose STL has one vertex 1e6 mm up (fuzz-flagged files that ran for hours
    /// under an estimate of 1.9e7): the line over it climbs 1e6 mm and back, 1e6 points of
    /// 2.5e4 drops each, far past the default bound; the dome alone stays far below it.
    #[test]
    fn a_stray_vertex_far_up_is_refused_by_its_climb() {
        let budget = Budget { memory: 2.147e9, points: DEFAULT_POINTS, weight: 1.0 };
        let stylus = Stylus { radius: 5.0, contact_tol: 1e-4 };
        let steps = Steps { chord_tol: 1e-3, max_step: 2.0, min_step: 1e-4 };
        let area = Region { x0: -20.0, x1: 20.0, y0: -20.0, y1: 20.0 };
        let lines = scan_lines(&area, 0.0, 5.0);
        let spike = scan(lines, &area, &area, 1e6 + 11.0, 0.0, 5.0, &stylus, &steps);
        assert!(spike.points > 2e10, "{}", spike.points);
        let e = spike.check(&budget, "scan").unwrap_err();
        assert!(e.to_string().contains("--max-points"), "{e}");
        let dome = scan(lines, &area, &area, 20.0 + 11.0, 0.0, 5.0, &stylus, &steps);
        assert!(dome.points < 1e-4 * DEFAULT_POINTS, "{}", dome.points);
    }
}
