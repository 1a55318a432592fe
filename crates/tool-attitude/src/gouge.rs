//! Gouge checks: the tool body as probe points that must each stay a clearance outside the
//! model (signed distance from the nearest-point query), and the search for the tilt nearest the
//! requested one, inside the allowed range, at which no probe cuts in.

use camkit::geom::{P3, V3};
use camkit::model::Model;

/// A point of the tool body and how far outside the model it must stay (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// The point.
    pub point: P3,
    /// Required signed distance to the model (0 for a body surface point, r for a point on an
    /// axis or edge that the body surrounds by r).
    pub clearance: f64,
}

/// Points round a circle of `radius` about `centre` in the plane normal to unit `axis`, the
/// first in the direction `u` (unit, perpendicular to the axis).
fn ring(out: &mut Vec<Probe>, centre: &P3, axis: &V3, u: &V3, radius: f64, count: usize, clearance: f64) {
    let v = axis.cross(u);
    for k in 0..count {
        let (s, c) = (std::f64::consts::TAU * k as f64 / count as f64).sin_cos();
        out.push(Probe { point: centre + (u * c + v * s) * radius, clearance });
    }
}

/// Probes of a flat-bottomed cylinder of `radius` and `length` standing on its bottom-face
/// centre `tip` along `axis`: the rim (96 points, the first towards `edge`, so the cutting point
/// and the rim point opposite it, where a tilted tool gouges first, are probed exactly), three
/// inner rings, the centre, and rings up the side. Used for the cylindrical non-rotating tool
/// (`edge` = the edge direction) and the flat end mill (`None`: any direction).
pub fn cylinder_probes(tip: &P3, axis: &V3, edge: Option<&V3>, radius: f64, length: f64) -> Vec<Probe> {
    let u =
        edge.copied().unwrap_or_else(|| axis.cross(&if axis.x.abs() < 0.9 { V3::x() } else { V3::y() }).normalize());
    let mut out = Vec::with_capacity(400);
    ring(&mut out, tip, axis, &u, radius, 96, 0.0);
    for k in 1..4 {
        ring(&mut out, tip, axis, &u, radius * k as f64 / 4.0, 48, 0.0);
    }
    out.push(Probe { point: *tip, clearance: 0.0 });
    let levels = 4;
    for k in 1..=levels {
        ring(&mut out, &(tip + axis * (length * k as f64 / levels as f64)), axis, &u, radius, 48, 0.0);
    }
    out
}

/// Probes of a ball end mill: points on the axis from the ball centre up `length`, each to stay
/// `radius` away (the capsule round the axis holds the ball and the shank).
pub fn ball_probes(tip: &P3, axis: &V3, radius: f64, length: f64) -> Vec<Probe> {
    let centre = tip + axis * radius;
    let count = 16;
    (0..=count)
        .map(|k| Probe { point: centre + axis * (length * k as f64 / count as f64), clearance: radius })
        .collect()
}

/// Probes along the flat-type tool's two flanks from the tip, each to stay the stylus radius `r`
/// away (the edge is the stylus's offset of the surface).
pub fn flank_probes(tip: &P3, flanks: (V3, V3), length: f64, r: f64) -> Vec<Probe> {
    let count = 16;
    let mut out = Vec::with_capacity(2 * count);
    for f in [flanks.0, flanks.1] {
        for k in 1..=count {
            out.push(Probe { point: tip + f * (length * k as f64 / count as f64), clearance: r });
        }
    }
    out
}

/// Signed distance from `q` to the model: negative inside (behind the outward normal).
pub fn signed_distance(model: &Model, q: &P3) -> f64 {
    let n = model.nearest(q);
    if (q - n.point).dot(&n.normal) < 0.0 { -n.distance } else { n.distance }
}

/// How deep the deepest probe cuts into its clearance (mm, 0 when none does).
pub fn penetration(model: &Model, probes: &[Probe]) -> f64 {
    probes.iter().map(|p| p.clearance - signed_distance(model, &p.point)).fold(0.0, f64::max)
}

/// Outcome of the tilt search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adjusted {
    /// The tilt used (radians).
    pub tilt: f64,
    /// Penetration at that tilt (mm).
    pub gouge: f64,
}

/// The tilt nearest `start` inside `[lo, hi]` at which `gouge(tilt)` ≤ `tol`: candidates every
/// `step` outwards from `start` on both sides, the first clear one refined by bisection towards
/// `start` to `angle_tol`. Keeps `start` when no candidate clears.
pub fn adjust(start: f64, lo: f64, hi: f64, tol: f64, gouge: impl Fn(f64) -> f64) -> Adjusted {
    let g0 = gouge(start);
    if g0 <= tol {
        return Adjusted { tilt: start, gouge: g0 };
    }
    let step = ADJUST_STEP;
    let mut k = 1;
    loop {
        let d = step * k as f64;
        let candidates = [start - d, start + d];
        if candidates.iter().all(|&c| c < lo - step || c > hi + step) {
            return Adjusted { tilt: start, gouge: g0 };
        }
        for c in candidates {
            let c = c.clamp(lo, hi);
            let g = gouge(c);
            if g <= tol {
                // Bisect between the clear candidate and the gouging one a step nearer start.
                let (mut bad, mut good, mut gg) = (c + (start - c).signum() * step.min((start - c).abs()), c, g);
                while (good - bad).abs() > ADJUST_ANGLE_TOL {
                    let mid = 0.5 * (good + bad);
                    let gm = gouge(mid);
                    if gm <= tol { (good, gg) = (mid, gm) } else { bad = mid }
                }
                return Adjusted { tilt: good, gouge: gg };
            }
        }
        k += 1;
    }
}

/// Step (radians) of the outward search for a clear tilt: 0.25°.
pub const ADJUST_STEP: f64 = 0.25 * std::f64::consts::PI / 180.0;

/// The adjusted tilt is found to within this (radians).
pub const ADJUST_ANGLE_TOL: f64 = 1e-7;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adjust_finds_the_nearest_clear_tilt() {
        // Gouge whenever tilt > −0.3: the clear tilt nearest −0.1 is −0.3.
        let a = adjust(-0.1, -0.35, 0.0, 1e-9, |t| (t + 0.3).max(0.0));
        assert!((a.tilt + 0.3).abs() <= ADJUST_ANGLE_TOL && a.gouge <= 1e-9, "{a:?}");
        // Nothing clear inside the range: the start is kept and reported.
        let a = adjust(-0.1, -0.2, 0.0, 1e-9, |t| (t + 0.3).max(0.0));
        assert_eq!(a.tilt, -0.1);
        assert!(a.gouge > 0.0);
    }
}
