//! Scanning-line mode: motion planes stand vertical along the scan direction, one per pick feed;
//! on each the stylus is dropped from above onto the model and then copies it to the end of the
//! region. Where the model falls away under the stylus (an overhang, the edge of a sheet) the pass
//! ends and the stylus is dropped again beyond it.

use crate::curve::{Curve, CurvePoint, PlaneCurve, Steps, Stylus, step};
use crate::{Failure, Region, TracedPath};
use camkit::geom::{P3, V3};
use camkit::model::Model;

/// Scan settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scan {
    /// Region in XY.
    pub region: Region,
    /// Scan direction, degrees from +x towards +y.
    pub angle: f64,
    /// Distance between motion planes (mm).
    pub pick: f64,
    /// Alternate the direction of successive lines.
    pub zigzag: bool,
}

/// One scan line's frame: points o + s·d + z·ẑ for s in [s0, s1].
#[derive(Clone, Copy, Debug)]
pub struct Line {
    /// Origin (z = 0).
    pub origin: P3,
    /// Unit direction of travel (horizontal).
    pub dir: V3,
    /// Start parameter.
    pub s0: f64,
    /// End parameter.
    pub s1: f64,
}

impl Line {
    /// The point at parameter `s`, height `z`.
    pub fn at(&self, s: f64, z: f64) -> P3 {
        P3::new(self.origin.x + self.dir.x * s, self.origin.y + self.dir.y * s, z)
    }

    /// The parameter of `p`'s foot on the line.
    pub fn s_of(&self, p: &P3) -> f64 {
        (p - self.origin).dot(&self.dir)
    }
}

/// The scan lines covering the region: lines along the direction, spaced by the pick feed across
/// it from the region's edge, each clipped to the region (lines that only graze a corner are
/// dropped).
pub fn lines(scan: &Scan) -> Vec<Line> {
    let (s, c) = scan.angle.to_radians().sin_cos();
    let d = V3::new(c, s, 0.0);
    let across = V3::new(-s, c, 0.0);
    let r = &scan.region;
    let corners =
        [P3::new(r.x0, r.y0, 0.0), P3::new(r.x1, r.y0, 0.0), P3::new(r.x0, r.y1, 0.0), P3::new(r.x1, r.y1, 0.0)];
    let side = |p: &P3| p.coords.dot(&across);
    let (v0, v1) = corners.iter().fold((f64::INFINITY, -f64::INFINITY), |(a, b), p| (a.min(side(p)), b.max(side(p))));
    let n = ((v1 - v0) / scan.pick + 1e-9).floor() as usize;
    let mut out = Vec::new();
    for k in 0..=n {
        let origin = P3::from(across * (v0 + k as f64 * scan.pick));
        // Slab clipping of origin + s·d against the rectangle.
        let (mut s0, mut s1) = (-f64::INFINITY, f64::INFINITY);
        for (o, dd, lo, hi) in [(origin.x, d.x, r.x0, r.x1), (origin.y, d.y, r.y0, r.y1)] {
            if dd.abs() < 1e-12 {
                if o < lo - 1e-9 || o > hi + 1e-9 {
                    (s0, s1) = (1.0, 0.0);
                }
            } else {
                let (a, b) = ((lo - o) / dd, (hi - o) / dd);
                (s0, s1) = (s0.max(a.min(b)), s1.min(a.max(b)));
            }
        }
        if s1 - s0 <= 1e-9 {
            continue;
        }
        let backward = scan.zigzag && out.len() % 2 == 1;
        out.push(if backward { Line { origin, dir: -d, s0: -s1, s1: -s0 } } else { Line { origin, dir: d, s0, s1 } });
    }
    out
}

/// Traces scan line number `unit`; the passes it yields, in order. A pass ends at the region's end, where
/// the model falls away (an overhang), or where the stylus cannot follow it (`interrupted`).
pub fn trace_line(
    model: &Model,
    stylus: Stylus,
    steps: &Steps,
    line: &Line,
    unit: usize,
) -> Result<Vec<TracedPath>, Failure> {
    let curve = PlaneCurve { model, stylus, plane_normal: V3::z().cross(&line.dir), flat_moves: None };
    let bounds = model.bounds();
    let (z_top, z_bottom) = if bounds.is_bounded() {
        (bounds.max.z + stylus.radius + 1.0, bounds.min.z - stylus.radius - 1.0)
    } else {
        (1e4, -1e4)
    };
    // Where nothing is under the stylus, look again this far on.
    let probe = steps.max_step.min(stylus.radius * 0.5);
    let mut paths = Vec::new();
    let mut s = line.s0;
    while s <= line.s1 {
        let Some(start) = drop(&curve, line, s, z_top, z_bottom) else {
            s = if s < line.s1 { (s + probe).min(line.s1) } else { f64::INFINITY };
            continue;
        };
        let mut pts = vec![start];
        let mut h = steps.max_step * 0.25;
        let mut deviation: f64 = 0.0;
        let mut ended_at = line.s1;
        let mut interrupted = false;
        loop {
            let a = *pts.last().expect("a pass has a start");
            let sa = line.s_of(&a.cl.centre);
            if sa >= line.s1 - camkit::tol::POINT_EPS {
                break;
            }
            // Overhang: the curve turns back under the model; this pass ends here.
            if a.tangent.dot(&line.dir) < -1e-6 {
                ended_at = sa;
                break;
            }
            let Some(st) = step(&curve, &a, h, steps) else {
                // The stylus loses the model (it slides off a sheet's side): the pass ends here
                // and the stylus is dropped again farther on.
                ended_at = sa;
                interrupted = true;
                break;
            };
            let mut next = st.to;
            if line.s_of(&next.cl.centre) > line.s1 {
                // The last point lies on the region's end: drop onto the curve there.
                let t = (line.s1 - sa) / (line.s_of(&next.cl.centre) - sa);
                let guess = a.cl.centre + (next.cl.centre - a.cl.centre) * t;
                match curve.correct(&P3::new(guess.x, guess.y, guess.z.max(next.cl.centre.z)), &line.dir) {
                    Some(end) => next = end,
                    None => {
                        next = st.to;
                    }
                }
            }
            deviation = deviation.max(st.deviation);
            h = st.next;
            pts.push(next);
        }
        paths.push(TracedPath { points: pts.into_iter().map(|p| p.cl).collect(), deviation, interrupted, unit });
        // Always onwards: a drop's correction may have landed behind where it was dropped.
        s = if ended_at >= line.s1 { f64::INFINITY } else { ended_at.max(s) + steps.min_step.max(1e-3) };
    }
    Ok(paths)
}

/// The stylus dropped from `z_top` at `s` onto the first contact, or `None` if it falls past
/// `z_bottom`. Sphere tracing (steps of |L| − r never pass through the model, |L| being
/// 1-Lipschitz) brings it close; a vertical Newton correction lands it.
fn drop(curve: &PlaneCurve, line: &Line, s: f64, z_top: f64, z_bottom: f64) -> Option<CurvePoint> {
    let r = curve.stylus.radius;
    // Beside a vertical wall |L| − r stays small without a contact below; a step this long can
    // pass a contact only by a depth of step²/8r, the contact tolerance.
    let least = (8.0 * r * curve.stylus.contact_tol).sqrt();
    let mut z = z_top;
    for _ in 0..100_000 {
        let c = line.at(s, z);
        let n = curve.model.nearest(&c);
        let gap = n.distance - r;
        if gap <= 0.05 * r && n.direction(&c).z.abs() >= 0.2 {
            let p = curve.correct(&c, &line.dir)?;
            return (p.cl.centre.z >= z_bottom).then_some(p);
        }
        z -= gap.max(least);
        if z < z_bottom {
            return None;
        }
    }
    None
}
