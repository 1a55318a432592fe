//! Scanning-line mode: motion planes stand vertical along the scan direction, one per pick feed;
//! on each the stylus is dropped from above onto the model and then copies it to the end of the
//! region. The CL of a line is the stylus's upper envelope over the model: a pass goes on only
//! while its points are on it (touching from above, moving on, nothing of the model over them),
//! so it ends at a silhouette (the model falls away: an overhang, the edge of a sheet) or under
//! something higher, at the point found by bisection, and the stylus is dropped again just beyond.
//! Where copying cannot go on (the motion plane nearly tangent to the offset surface) the pass
//! goes on by drops while their chords stay within the chord tolerance.

use crate::curve::{AIM, Curve, CurvePoint, PlaneCurve, Steps, Stylus, step};
use crate::{Failure, Region, TracedPath};
use camkit::geom::{P3, V3};
use camkit::model::Model;
use camkit::model::drop::DropCutter;

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

/// What a line's tracer needs besides the line: the curve, the column heights and the steps.
struct Tracer<'a> {
    curve: PlaneCurve<'a>,
    line: &'a Line,
    steps: &'a Steps,
    /// Where drops start.
    z_top: f64,
    /// Where a drop gives up.
    z_bottom: f64,
    /// How far past a pass's end the stylus is dropped again (below the coverage check's gap
    /// tolerance, the chord tolerance).
    hop: f64,
    /// Spacing of the sample positions along the line where chords are checked.
    spacing: f64,
    /// The exact drop of the stylus as a ball cutter, where the model allows one: drops start
    /// just above its contact instead of creeping down beside tall walls from the top.
    exact: Option<&'a DropCutter>,
}

/// Spacing of the positions along a scan line where the chords between CL points are checked
/// against the envelope, by the tracer and by the coverage check alike: min(longest step, r/4).
pub fn sample_spacing(stylus: &Stylus, steps: &Steps) -> f64 {
    steps.max_step.min(0.25 * stylus.radius)
}

/// Traces line number `unit`; the passes it yields, in order. A pass ends at the region's end,
/// at a silhouette, under a higher part of the model, or where the envelope jumps.
pub fn trace_line(
    model: &Model,
    exact: Option<&DropCutter>,
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
    let hop = (steps.chord_tol * 0.5).max(steps.min_step);
    let t = Tracer { curve, line, steps, z_top, z_bottom, hop, spacing: sample_spacing(&stylus, steps), exact };
    let mut paths = Vec::new();
    let mut s = line.s0;
    let mut missed: Option<f64> = None;
    while s <= line.s1 {
        let mut start = match t.land_or_clear(s) {
            Ok(p) => p,
            Err(clear) => {
                // Nothing is under the stylus, nor within `clear` of it: look again that far
                // on (a shadow shorter than the hop may be passed over).
                missed = Some(s);
                s = if s < line.s1 { (s + clear.max(t.hop)).min(line.s1) } else { f64::INFINITY };
                continue;
            }
        };
        // After a miss, the model's shadow begins somewhere before s: find it.
        if let Some(mut m) = missed.take() {
            let mut hit = s;
            while hit - m > 0.5 * t.hop {
                let mid = 0.5 * (m + hit);
                match t.land(mid) {
                    Some(p) => {
                        hit = mid;
                        start = p;
                    }
                    None => m = mid,
                }
            }
        }
        let (pass, ended_at) = t.follow(start);
        paths.push(TracedPath { unit, ..pass });
        // Always onwards: a drop's correction may have landed behind where it was dropped.
        s = if ended_at >= line.s1 { f64::INFINITY } else { ended_at.max(s) + t.hop };
    }
    Ok(paths)
}

impl Tracer<'_> {
    fn s_of(&self, p: &CurvePoint) -> f64 {
        self.line.s_of(&p.cl.centre)
    }

    /// True when `b`, reached from `a`, is on the upper envelope: it touches from above or from
    /// the side (the tangent does not turn back), it does not go back along the line, and no
    /// part of the model lies over it: a drop from the top meets nothing above it where its
    /// contact faces up, and lands on it (across the envelope, within ten contact tolerances)
    /// where the face is steep. A pass climbing a vertical wall (a step of the envelope) goes on.
    fn on_envelope(&self, a: &CurvePoint, b: &CurvePoint) -> bool {
        let back = 1e-9;
        if b.tangent.dot(&self.line.dir) < -back || self.s_of(b) < self.s_of(a) - back {
            return false;
        }
        let (up, c, tol) = (b.cl.normal.z, b.cl.centre, 10.0 * self.curve.stylus.contact_tol);
        if up <= 1e-6 {
            return true;
        }
        if up >= 0.05 {
            return !matches!(self.descend(c.x, c.y, c.z + tol / up), Descent::Contact { .. });
        }
        match self.land_or_clear(self.s_of(b)) {
            Ok(top) => (top.cl.centre.z - c.z) * top.cl.normal.z.abs() <= tol,
            Err(_) => true,
        }
    }

    /// True when the chord from `a` to `b` runs nowhere below the envelope by more than the chord
    /// tolerance (across it: the vertical depth times the z of its normal) at the sample positions
    /// inside it: a part of the model narrower than a step, which copying steps over, ends the
    /// pass before it.
    fn chord_clear(&self, a: &CurvePoint, b: &CurvePoint) -> bool {
        let (sa, sb) = (self.s_of(a), self.s_of(b));
        let (s0, w) = (self.line.s0, self.spacing);
        let mut j = ((sa - s0) / w).floor() as i64 + 1;
        loop {
            let s = s0 + j as f64 * w;
            j += 1;
            if s >= sb {
                return true;
            }
            if s <= sa {
                continue;
            }
            let c = a.cl.centre + (b.cl.centre - a.cl.centre) * ((s - sa) / (sb - sa));
            if let Descent::Contact { below, above } = self.descend(c.x, c.y, c.z) {
                match self.settle(s, below, above) {
                    Some(top) if (top.cl.centre.z - c.z) * top.cl.normal.z.abs() <= self.steps.chord_tol => {}
                    _ => return false,
                }
            }
        }
    }

    /// The stylus dropped at `s` onto its highest contact, or `None` if nothing is under it.
    fn land(&self, s: f64) -> Option<CurvePoint> {
        self.land_or_clear(s).ok()
    }

    /// The stylus dropped at `s` onto its highest contact, or how far it is clear of the model
    /// (a lower bound of |L| − r down the whole column; 0 if it touched but did not settle).
    fn land_or_clear(&self, s: f64) -> Result<CurvePoint, f64> {
        let p = self.line.at(s, 0.0);
        match self.descend(p.x, p.y, self.z_bottom) {
            Descent::Contact { below, above } => self.settle(s, below, above).ok_or(0.0),
            Descent::Clear { margin } => Err(margin),
        }
    }

    /// Sphere tracing down the vertical through (x, y) from the top to `z_stop`: steps of
    /// |L| − r never pass a contact, |L| being 1-Lipschitz; near a face that faces up the step
    /// is the vertical Newton step (|L| − r)/L̂_z, and it is never shorter than a length that can
    /// pass a contact only by a depth of step²/8r, the contact tolerance (beside a vertical wall
    /// |L| − r stays small without a contact below). With the exact drop the tracing starts just
    /// above its contact (nothing above it touches), and where it finds none the creeping beside
    /// a wall stops after [`CREEP`] shortest steps: a 12 km needle is not crept down 0.05 mm at a
    /// time.
    fn descend(&self, x: f64, y: f64, z_stop: f64) -> Descent {
        let (r, tol) = (self.curve.stylus.radius, self.curve.stylus.contact_tol);
        let least = (8.0 * r * tol).sqrt();
        let gap_at = |z: f64| {
            let c = P3::new(x, y, z);
            let n = self.curve.model.nearest(&c);
            (n.distance - r, n.direction(&c).z)
        };
        let mut z = self.z_top;
        // A lower bound of |L| − r over the column searched so far: between heights a step h
        // apart with gaps g₀, g₁ it is at least (g₀ + g₁ − h)/2, |L| being 1-Lipschitz.
        let mut margin = f64::INFINITY;
        // Shortest steps still allowed (none counted without the exact drop).
        let mut creep = usize::MAX;
        match self.exact.map(|dc| dc.drop(x, y)) {
            // Above the highest contact |L| ≥ r: the column skipped has a margin of 0.
            Some(Some(d)) => {
                let start = (d.tip.z + r + 4.0 * least).max(z_stop);
                if start < z {
                    (z, margin) = (start, 0.0);
                }
            }
            Some(None) => creep = CREEP,
            None => {}
        }
        let mut above: Option<(f64, f64)> = None;
        for _ in 0..100_000 {
            let (gap, up) = gap_at(z.max(z_stop));
            if let Some((za, ga)) = above {
                margin = margin.min(0.5 * (ga + gap - (za - z.max(z_stop))));
            }
            if z <= z_stop {
                return Descent::Clear { margin: margin.max(0.0) };
            }
            // Newton from above a face that bulges up stays above the contact: close enough is
            // a contact too.
            if gap <= self.curve.stylus.target() {
                return Descent::Contact { below: z, above };
            }
            above = Some((z, gap));
            let h = if up > 0.2 { (gap / up).min(gap + least) } else { gap.max(least) };
            if h <= least {
                if creep == 0 {
                    // The exact drop meets nothing: |L| ≥ r down the rest of the column.
                    return Descent::Clear { margin: 0.0 };
                }
                creep = creep.saturating_sub(1);
            }
            z -= h;
        }
        Descent::Clear { margin: 0.0 }
    }

    /// The contact between a height inside (|L| < r at `below`) and one outside (`above`, with
    /// its |L| − r), by regula falsi (Illinois) on |L| − r down to the correction target.
    fn settle(&self, s: f64, below: f64, above: Option<(f64, f64)>) -> Option<CurvePoint> {
        let stylus = self.curve.stylus;
        let target = stylus.target();
        let at = |z: f64| {
            let c = self.line.at(s, z);
            let n = self.curve.model.nearest(&c);
            (c, n, n.distance - stylus.radius)
        };
        let (c, n, gap) = at(below);
        if gap.abs() <= target || above.is_none() {
            return if n.converged && gap.abs() <= stylus.contact_tol { self.curve.finish(c, &n, 1) } else { None };
        }
        let ((mut z0, mut f0), (mut z1, mut f1)) = ((below, gap), above.expect("checked above"));
        let mut side = 0;
        for it in 1..=200 {
            let z = if f1 - f0 != 0.0 { z0 - f0 * (z1 - z0) / (f1 - f0) } else { 0.5 * (z0 + z1) };
            let z = if z > z0.min(z1) && z < z0.max(z1) { z } else { 0.5 * (z0 + z1) };
            let (c, n, f) = at(z);
            if f.abs() <= target || (z1 - z0).abs() < 1e-13 * (1.0 + z.abs()) {
                return (n.converged && f.abs() <= stylus.contact_tol).then(|| self.curve.finish(c, &n, it)).flatten();
            }
            if f < 0.0 {
                (z0, f0) = (z, f);
                if side == -1 {
                    f1 *= 0.5;
                }
                side = -1;
            } else {
                (z1, f1) = (z, f);
                if side == 1 {
                    f0 *= 0.5;
                }
                side = 1;
            }
        }
        None
    }

    /// One pass from `start` along the envelope; the pass and the parameter where it ends.
    fn follow(&self, start: CurvePoint) -> (TracedPath, f64) {
        let (line, steps) = (self.line, self.steps);
        let mut pts = vec![start];
        let mut h = steps.max_step * 0.25;
        let mut deviation: f64 = 0.0;
        let mut ended_at = line.s1;
        let mut interrupted = false;
        loop {
            let a = *pts.last().expect("a pass has a start");
            let sa = self.s_of(&a);
            if sa >= line.s1 - camkit::tol::POINT_EPS {
                break;
            }
            let (mut next, dev, next_h) = match step(&self.curve, &a, h, steps) {
                Some(st) if self.on_envelope(&a, &st.to) && self.chord_clear(&a, &st.to) => {
                    (st.to, st.deviation, st.next)
                }
                Some(st) => {
                    // It left the envelope within this step: end the pass where it does.
                    if let Some(b) = self.boundary(&a, (st.to.cl.centre - a.cl.centre).norm()) {
                        pts.push(b);
                    }
                    ended_at = self.s_of(pts.last().expect("a pass has a start"));
                    break;
                }
                None => match self.drop_step(&a, h) {
                    Some(found) => found,
                    None => {
                        // Neither copying nor drops go on: the envelope jumps here.
                        ended_at = sa;
                        interrupted = true;
                        break;
                    }
                },
            };
            if self.s_of(&next) > line.s1 {
                // The last point lies on the region's end: drop onto the curve there.
                let t = (line.s1 - sa) / (self.s_of(&next) - sa);
                let guess = a.cl.centre + (next.cl.centre - a.cl.centre) * t;
                if let Some(end) = self
                    .curve
                    .correct(&P3::new(guess.x, guess.y, guess.z.max(next.cl.centre.z)), &line.dir)
                    .or_else(|| self.land(line.s1))
                {
                    next = end;
                }
            }
            deviation = deviation.max(dev);
            h = next_h;
            pts.push(next);
        }
        let pass = TracedPath { points: pts.into_iter().map(|p| p.cl).collect(), deviation, interrupted, unit: 0 };
        (pass, ended_at)
    }

    /// The farthest point on the envelope from `a` along its tangent, the step of length `bad`
    /// having left it: bisection on the step length down to the shortest step.
    fn boundary(&self, a: &CurvePoint, bad: f64) -> Option<CurvePoint> {
        let (mut lo, mut hi, mut best) = (0.0, bad, None);
        while hi - lo > self.steps.min_step {
            let mid = 0.5 * (lo + hi);
            // Round-off: no length lies between them any more.
            if mid <= lo || mid >= hi {
                break;
            }
            let p = self.curve.correct(&(a.cl.centre + a.tangent * mid), &a.tangent).filter(|p| {
                (p.cl.centre - a.cl.centre).dot(&a.tangent) > 0.0 && self.on_envelope(a, p) && self.chord_clear(a, p)
            });
            match p {
                Some(p) => {
                    lo = mid;
                    best = Some(p);
                }
                None => hi = mid,
            }
        }
        best
    }

    /// A step by drops where copying cannot go on: the stylus dropped `h` on (shortened down to
    /// the shortest step) is taken when the drop halfway lies within the chord tolerance of the
    /// chord. The new point, its chord deviation and the next step length.
    fn drop_step(&self, a: &CurvePoint, h: f64) -> Option<(CurvePoint, f64, f64)> {
        let (steps, sa) = (self.steps, self.s_of(a));
        let mut h = h.clamp(steps.min_step, steps.max_step);
        loop {
            let sb = (sa + h).min(self.line.s1);
            if let (Some(b), Some(m)) = (self.land(sb), self.land(0.5 * (sa + sb))) {
                let mid = a.cl.centre + (b.cl.centre - a.cl.centre) * 0.5;
                let dev = (m.cl.centre.z - mid.z).abs();
                if dev <= steps.chord_tol * AIM && self.s_of(&b) > sa && self.chord_clear(a, &b) {
                    return Some((b, dev, (2.0 * h).min(steps.max_step)));
                }
            }
            if h <= steps.min_step {
                return None;
            }
            h = (h * 0.5).max(steps.min_step);
        }
    }
}

/// Shortest steps a drop may creep down beside a wall where the exact drop meets nothing.
const CREEP: usize = 64;

/// The end of a drop.
enum Descent {
    /// The stylus met the model: a height inside it (or within the target of touching) and the
    /// last one outside with its |L| − r.
    Contact { below: f64, above: Option<(f64, f64)> },
    /// It went down to the stop without touching; |L| − r was at least `margin` all the way,
    /// so no column within that distance horizontally touches either.
    Clear {
        /// Lower bound of |L| − r along the column.
        margin: f64,
    },
}
