//! Two-surface mode (paper 000 §3.2(2), fig. 8–10): the stylus is corrected in XY and in Z until
//! it touches two surfaces at once, then moves on perpendicular to the XY part of the bisector of
//! both normals, and so traces the concave line where a ball end mill leaves material.

use crate::curve::{Curve, CurvePoint, Steps, Stylus, TwoSurfaceCurve, step};
use crate::{Failure, Region, TracedPath};
use camkit::geom::{P3, V3};
use camkit::model::Model;

/// Two-surface settings.
#[derive(Clone, Debug, PartialEq)]
pub struct TwoSurface {
    /// Surfaces A and B.
    pub surfaces: [usize; 2],
    /// A guess of the stylus centre near the concave line (default: beside B, on the +x side).
    pub start: Option<P3>,
    /// Trace the line the other way round.
    pub reverse: bool,
    /// The trace ends where it leaves this region (grown by 2r).
    pub region: Region,
}

/// Points a trace may have before it is declared not closing.
const MAX_POINTS: usize = 5_000_000;

/// The default start guess: on B's +x side at B's mid y, a stylus radius above A there.
fn default_guess(model: &Model, ts: &TwoSurface, r: f64) -> Option<P3> {
    let b = model.surfaces[ts.surfaces[1]].bounds();
    if !b.is_bounded() {
        return None;
    }
    let c = b.centre();
    let x = b.max.x + 0.3 * r;
    let on_a = model.nearest_on(&P3::new(x, c.y, b.max.z + r), ts.surfaces[0]);
    Some(P3::new(x, c.y, on_a.point.z + r))
}

/// Traces the concave line: one closed path, or one open path from end to end.
pub fn trace(model: &Model, stylus: Stylus, steps: &Steps, ts: &TwoSurface) -> Result<Vec<TracedPath>, Failure> {
    let r = stylus.radius;
    let guess = ts.start.or_else(|| default_guess(model, ts, r)).ok_or_else(|| Failure {
        at: P3::origin(),
        what: "surface B is unbounded: give --start near the concave line".into(),
    })?;
    let curve = TwoSurfaceCurve { model, stylus, surfaces: ts.surfaces, reverse: ts.reverse };
    // The first correction moves in the vertical plane through the guess along x and z.
    let seed = [V3::y(), V3::x()].iter().find_map(|t| curve.correct(&guess, t)).ok_or_else(|| Failure {
        at: guess,
        what: "no position touching both surfaces was found near the start: give --start closer to the concave line"
            .into(),
    })?;
    let (forward, closed, dev_f) = follow(&curve, seed, steps, &ts.region, r);
    if closed {
        return Ok(vec![TracedPath {
            points: forward.iter().map(|p| p.cl).collect(),
            deviation: dev_f,
            interrupted: false,
            unit: 0,
        }]);
    }
    // An open line: trace back from the seed the other way and join.
    let back_curve = TwoSurfaceCurve { model, stylus, surfaces: ts.surfaces, reverse: !ts.reverse };
    let back_seed = back_curve.correct(&seed.cl.centre, &seed.tangent).ok_or_else(|| Failure {
        at: seed.cl.centre,
        what: "the two-surface contact does not converge at the start".into(),
    })?;
    let (backward, _, dev_b) = follow(&back_curve, back_seed, steps, &ts.region, r);
    let mut pts: Vec<_> = backward.iter().rev().map(|p| p.cl).collect();
    pts.extend(forward.iter().skip(1).map(|p| p.cl));
    Ok(vec![TracedPath { points: pts, deviation: dev_f.max(dev_b), interrupted: false, unit: 0 }])
}

/// Steps from `seed` until the line closes, leaves the region, or the double contact is lost.
fn follow(
    curve: &TwoSurfaceCurve,
    seed: CurvePoint,
    steps: &Steps,
    region: &Region,
    r: f64,
) -> (Vec<CurvePoint>, bool, f64) {
    let mut pts = vec![seed];
    let mut h = steps.max_step * 0.25;
    let mut deviation: f64 = 0.0;
    let mut travelled = 0.0;
    while pts.len() < MAX_POINTS {
        let a = *pts.last().expect("a trace has a seed");
        let Some(st) = step(curve, &a, h, steps) else { break };
        let b = st.to;
        travelled += (b.cl.centre - a.cl.centre).norm();
        deviation = deviation.max(st.deviation);
        h = st.next;
        let closing = travelled > 4.0 * steps.min_step
            && pts.len() > 2
            && camkit::geom::dist::point_segment(&seed.cl.centre, &a.cl.centre, &b.cl.centre) <= steps.chord_tol + 1e-6;
        if closing {
            pts.push(seed);
            return (pts, true, deviation);
        }
        pts.push(b);
        if !region.contains_within(&b.cl.centre, 2.0 * r) {
            break;
        }
    }
    (pts, false, deviation)
}
