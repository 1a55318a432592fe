//! Contour-line mode: the motion plane is z = const and the stylus follows the model's outline at
//! that height (a waterline), once round every loop. Loops are found from seeds where lines
//! across the level cross the CL curve; a loop of an island is at least 2r wide, so seed lines
//! r apart meet every one.

use crate::curve::{ClPoint, Curve, CurvePoint, PlaneCurve, Steps, Stylus, step};
use crate::{Failure, Region, TracedPath};
use camkit::geom::{P3, V3};
use camkit::model::Model;

/// Points a loop may have before it is declared not closing.
const MAX_LOOP_POINTS: usize = 5_000_000;

/// Traces every loop at height `z` inside the region. Points where the stylus is behind the
/// surface it touches (round the edge of a sheet, under it) are left out, splitting the loop.
pub fn trace_level(
    model: &Model,
    stylus: Stylus,
    steps: &Steps,
    region: &Region,
    z: f64,
) -> Result<Vec<TracedPath>, Failure> {
    let curve = PlaneCurve { model, stylus, plane_normal: V3::z(), flat_moves: Some(stylus.radius * 0.25) };
    let r = stylus.radius;
    let mut loops: Vec<(Vec<CurvePoint>, f64)> = Vec::new();
    // Loops wholly behind the surface (inside a solid) are never written: only seeds in front
    // start a loop, and the parts of a loop behind a sheet's edge are cut out below.
    for seed in seeds(&curve, region, z).into_iter().filter(|s| s.cl.front) {
        let covered =
            loops.iter().any(|(pts, dev)| near_polyline(&seed.cl.centre, pts, dev + steps.chord_tol * 2.0 + 1e-6));
        if covered {
            continue;
        }
        loops.push(trace_loop(&curve, seed, steps, region, r)?);
    }
    let mut out = Vec::new();
    for (pts, deviation) in loops {
        for run in front_runs(&pts) {
            out.push(TracedPath { points: run, deviation, interrupted: false, unit: 0 });
        }
    }
    Ok(out)
}

/// Follows the loop through `seed` until it comes back (or leaves the region's box grown by r).
fn trace_loop(
    curve: &PlaneCurve,
    seed: CurvePoint,
    steps: &Steps,
    region: &Region,
    r: f64,
) -> Result<(Vec<CurvePoint>, f64), Failure> {
    let mut pts = vec![seed];
    let mut h = steps.max_step * 0.25;
    let mut deviation: f64 = 0.0;
    let mut travelled = 0.0;
    loop {
        let a = *pts.last().expect("a loop has a seed");
        let Some(st) = step(curve, &a, h, steps) else {
            return Err(Failure { at: a.cl.centre, what: "the stylus cannot follow the outline here".into() });
        };
        let b = st.to;
        travelled += (b.cl.centre - a.cl.centre).norm();
        deviation = deviation.max(st.deviation);
        h = st.next;
        // Back at the seed: the chord a → b passes it.
        let closing = travelled > 4.0 * steps.min_step
            && pts.len() > 2
            && camkit::geom::dist::point_segment(&seed.cl.centre, &a.cl.centre, &b.cl.centre) <= steps.chord_tol + 1e-6;
        if closing {
            pts.push(seed);
            return Ok((pts, deviation));
        }
        if !region.contains_within(&b.cl.centre, r * 2.0) {
            pts.push(b);
            return Ok((pts, deviation));
        }
        pts.push(b);
        if pts.len() > MAX_LOOP_POINTS {
            return Err(Failure { at: b.cl.centre, what: "the outline does not close".into() });
        }
    }
}

/// Points where the CL curve crosses lines y = const (r apart) across the region.
fn seeds(curve: &PlaneCurve, region: &Region, z: f64) -> Vec<CurvePoint> {
    let r = curve.stylus.radius;
    let (x0, x1) = (region.x0 - 2.0 * r, region.x1 + 2.0 * r);
    let (y0, y1) = (region.y0 - r, region.y1 + r);
    let n = ((y1 - y0) / r).ceil().max(1.0) as usize;
    // Marching by |L| − r cannot step over a crossing; near-grazing it steps at least this.
    let least = 0.02 * r;
    let mut out = Vec::new();
    for k in 0..=n {
        let y = y0 + (y1 - y0) * k as f64 / n as f64;
        let mut x = x0;
        let f = |x: f64| curve.model.nearest(&P3::new(x, y, z)).distance - r;
        let mut fx = f(x);
        while x < x1 {
            let xn = (x + fx.abs().max(least)).min(x1);
            let fn_ = f(xn);
            if (fx > 0.0) != (fn_ > 0.0) {
                // Across the line, the step direction is y: the correction moves along x.
                let guess = P3::new(if fx.abs() < fn_.abs() { x } else { xn }, y, z);
                if let Some(p) = curve.correct(&guess, &V3::y()) {
                    out.push(p);
                }
            }
            (x, fx) = (xn, fn_);
            if xn >= x1 {
                break;
            }
        }
    }
    out
}

/// True if `p` is within `tol` of the polyline through `pts`.
fn near_polyline(p: &P3, pts: &[CurvePoint], tol: f64) -> bool {
    pts.windows(2).any(|w| camkit::geom::dist::point_segment(p, &w[0].cl.centre, &w[1].cl.centre) <= tol)
        || pts.first().is_some_and(|q| (q.cl.centre - p).norm() <= tol)
}

/// The maximal runs of points in front of the surface they touch. Points behind it (inside a
/// solid's material, round a sheet's edge and under it) are left out, splitting the loop; a loop
/// wholly in front is kept whole and closed.
fn front_runs(pts: &[CurvePoint]) -> Vec<Vec<ClPoint>> {
    let all: Vec<ClPoint> = pts.iter().map(|p| p.cl).collect();
    let closed = pts.len() > 2 && pts.first().map(|p| p.cl.centre) == pts.last().map(|p| p.cl.centre);
    if all.iter().all(|p| p.front) {
        return vec![all];
    }
    // Start the walk at a point behind, so runs do not wrap round the loop's seam.
    let ring = if closed { &all[..all.len() - 1] } else { &all[..] };
    let shift = if closed { ring.iter().position(|p| !p.front).unwrap_or(0) } else { 0 };
    let mut runs = Vec::new();
    let mut run: Vec<ClPoint> = Vec::new();
    for k in 0..ring.len() {
        let p = ring[(k + shift) % ring.len()];
        if p.front {
            run.push(p);
        } else if !run.is_empty() {
            runs.push(std::mem::take(&mut run));
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs.retain(|r| r.len() >= 2);
    runs
}
