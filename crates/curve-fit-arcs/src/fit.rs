//! Fitting one piece to a range of points: a line or an arc from the written end of the piece
//! before it to the range's last point (as written). Arc centres lie on the bisector of the two
//! ends: the least-squares one, refined to minimax when least squares misses the tolerance by a
//! little. Every candidate is measured as it will be written.

use crate::Options;
use crate::deviation::{self, Helix};
use camkit::geom::{P2, P3, Plane, V2, arc::angle_between, cross2};

/// How the written program rounds what the fitter chooses.
pub trait Rounding {
    /// A position as a reader of the output gets it back.
    fn point(&self, p: &P3) -> P3;
    /// An arc centre (plane coordinates) as read back, given the start as written.
    fn centre(&self, c: &P2, start: &P2) -> P2;
}

/// No rounding: the output carries every bit (shortest round-trip numbers).
pub struct Exact;

impl Rounding for Exact {
    fn point(&self, p: &P3) -> P3 {
        *p
    }
    fn centre(&self, c: &P2, _start: &P2) -> P2 {
        *c
    }
}

/// The shape of a fitted piece.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A straight move.
    Line,
    /// A circular (or helical) move: centre as written, plane, sense.
    Arc {
        /// Centre in plane coordinates, as written.
        centre: P2,
        /// Plane of the arc.
        plane: Plane,
        /// Counter-clockwise in its plane.
        ccw: bool,
    },
}

/// One output move replacing the input between points `first` and `last` of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// Index of the input point the piece starts at.
    pub first: usize,
    /// Index of the input point it ends at.
    pub last: usize,
    /// Where it starts, as written (the previous piece's end).
    pub start: P3,
    /// Where it ends, as written.
    pub end: P3,
    /// Line or arc.
    pub shape: Shape,
    /// Verified bound of the Hausdorff distance to the input between `first` and `last` (mm).
    pub deviation: f64,
}

impl Piece {
    /// The arc as written, for arc pieces.
    pub fn helix(&self) -> Option<Helix> {
        match self.shape {
            Shape::Arc { centre, plane, ccw } => Some(Helix { plane, start: self.start, end: self.end, centre, ccw }),
            Shape::Line => None,
        }
    }

    /// Radius of an arc piece as written (mean of its end radii).
    pub fn radius(&self) -> Option<f64> {
        self.helix().map(|h| h.arc().0.r)
    }

    /// Unit tangent at the end, in `plane`'s coordinates.
    pub fn end_tangent(&self, plane: Plane) -> Option<V2> {
        match self.helix() {
            Some(h) => Some(deviation::end_tangent(&h)),
            None => camkit::geom::dist::unit2(&(plane.split(&self.end).0 - plane.split(&self.start).0)),
        }
    }
}

/// A direction a piece must start along (tangent continuity), within an angle, in a plane.
#[derive(Clone, Copy, Debug)]
pub struct Tangent {
    /// Unit direction in plane coordinates.
    pub dir: V2,
    /// Largest angle allowed between `dir` and the piece's start direction (radians).
    pub max_angle: f64,
    /// Plane the directions are compared in.
    pub plane: Plane,
}

impl Tangent {
    fn allows(&self, dir: &V2) -> bool {
        angle_between(&self.dir, dir).abs() <= self.max_angle
    }
}

/// What a candidate piece is fitted to: points `first..=last` of a run, from a written start.
pub struct Job<'a> {
    /// The run's points.
    pub pts: &'a [P3],
    /// The same points as written (rounded once per run: the search asks for the same ends often).
    pub written: &'a [P3],
    /// First point of the piece.
    pub first: usize,
    /// Last point of the piece.
    pub last: usize,
    /// The written start (the previous piece's end).
    pub start: P3,
    /// Tangent continuity with the previous piece.
    pub tangent: Option<Tangent>,
    /// Also try the minimax centre when least squares misses (slower, a little longer pieces).
    pub thorough: bool,
}

impl Job<'_> {
    fn span(&self) -> &[P3] {
        &self.pts[self.first..=self.last]
    }

    /// The piece's end as written.
    fn end(&self) -> P3 {
        self.written[self.last]
    }
}

/// Tries a line.
pub fn line(job: &Job, opts: &Options) -> Option<Piece> {
    let pts = job.span();
    let a = job.start;
    let b = job.end();
    if let Some(t) = &job.tangent {
        let dir = camkit::geom::dist::unit2(&(t.plane.split(&b).0 - t.plane.split(&a).0))?;
        if !t.allows(&dir) {
            return None;
        }
    }
    // Quick rejection on the middle point before the full measure.
    if camkit::geom::dist::point_segment(&pts[pts.len() / 2], &a, &b) > opts.tol {
        return None;
    }
    let deviation = deviation::line(pts, &a, &b, opts.tol);
    (deviation <= opts.tol).then_some(Piece {
        first: job.first,
        last: job.last,
        start: a,
        end: b,
        shape: Shape::Line,
        deviation,
    })
}

/// Least squares misses by at most this share of the tolerance before minimax is tried.
const MINIMAX_REACH: f64 = 0.5;

/// Tries an arc in `plane` (at least three points): least-squares centre, then (for a thorough
/// job) minimax if that misses the tolerance by a little, then (with tangent continuity) the
/// arc tangent to the previous piece.
pub fn arc(job: &Job, plane: Plane, opts: &Options, rounding: &dyn Rounding) -> Option<Piece> {
    if job.last < job.first + 2 {
        return None;
    }
    let pts = job.span();
    let (s, _) = plane.split(&job.start);
    let (e, _) = plane.split(&job.end());
    let bisector = Bisector::new(&s, &e)?;
    let inner = || pts[1..pts.len() - 1].iter().map(|p| plane.split(p).0);
    let reach = opts.tol * (1.0 + MINIMAX_REACH);
    let (piece, dev) = match bisector.least_squares(inner()) {
        Some(c) => arc_about(job, plane, c, opts, rounding, reach),
        None => (None, f64::INFINITY),
    };
    if piece.is_some() {
        return piece;
    }
    if job.thorough && dev <= reach {
        let rows: Vec<(f64, f64)> = inner().map(|p| bisector.row(&p)).collect();
        if let Some(c) = bisector.minimax(&rows) {
            let (piece, _) = arc_about(job, plane, c, opts, rounding, opts.tol);
            if piece.is_some() {
                return piece;
            }
        }
    }
    let t = job.tangent.as_ref().filter(|t| t.plane == plane)?;
    let c = camkit::geom::circle::tangent_through(&s, &t.dir, &e)?;
    arc_about(job, plane, c.c, opts, rounding, opts.tol).0
}

/// Centres of circles through the two ends `s`, `e`: `c(t) = m + t·n` on the bisector. The
/// algebraic residual `|p − c|² − |s − c|² = a − t·b` of a point is linear in `t` (and about
/// `2r` times its geometric distance).
struct Bisector {
    m: P2,
    n: V2,
    h2: f64,
}

impl Bisector {
    fn new(s: &P2, e: &P2) -> Option<Bisector> {
        let chord = e - s;
        let len = chord.norm();
        (len > 0.0).then(|| Bisector {
            m: P2::from((s.coords + e.coords) * 0.5),
            n: V2::new(-chord.y, chord.x) / len,
            h2: 0.25 * len * len,
        })
    }

    /// The residual row `(a, b)` of a point.
    fn row(&self, p: &P2) -> (f64, f64) {
        let d = p - self.m;
        (d.norm_squared() - self.h2, 2.0 * self.n.dot(&d))
    }

    fn least_squares(&self, pts: impl Iterator<Item = P2>) -> Option<P2> {
        let (mut sab, mut sbb) = (0.0, 0.0);
        for p in pts {
            let (a, b) = self.row(&p);
            sab += a * b;
            sbb += b * b;
        }
        (sbb > 0.0).then(|| self.m + self.n * (sab / sbb))
    }

    /// The minimax `t` by Lawson's iteratively reweighted least squares.
    fn minimax(&self, rows: &[(f64, f64)]) -> Option<P2> {
        const ITERATIONS: usize = 10;
        let mut w = vec![1.0; rows.len()];
        let mut t = 0.0;
        for _ in 0..ITERATIONS {
            let (mut sab, mut sbb) = (0.0, 0.0);
            for ((a, b), wk) in rows.iter().zip(&w) {
                sab += wk * a * b;
                sbb += wk * b * b;
            }
            if sbb <= 0.0 {
                return None;
            }
            t = sab / sbb;
            let total: f64 = rows.iter().zip(&w).map(|((a, b), wk)| wk * (a - b * t).abs()).sum();
            if total <= 0.0 {
                break;
            }
            for ((a, b), wk) in rows.iter().zip(w.iter_mut()) {
                *wk *= (a - b * t).abs() / total;
            }
        }
        Some(self.m + self.n * t)
    }
}

/// The arc piece about centre `c` and its deviation, if it meets every constraint. The measure
/// stops as soon as it exceeds `limit` (at least the tolerance, so a stopped measure never
/// passes for a fit).
fn arc_about(
    job: &Job,
    plane: Plane,
    c: P2,
    opts: &Options,
    rounding: &dyn Rounding,
    limit: f64,
) -> (Option<Piece>, f64) {
    let limit = limit.max(opts.tol);
    let none = (None, f64::INFINITY);
    let pts = job.span();
    let a = job.start;
    let b = job.end();
    let (pa, _) = plane.split(&a);
    let r = (pa - c).norm();
    if r < opts.min_radius || r > opts.max_radius || !r.is_finite() {
        return none;
    }
    let centre = rounding.centre(&c, &pa);
    // Quick rejection on three inner points before the full measure.
    let n = pts.len() - 1;
    for k in [n / 2, n / 4, 3 * n / 4] {
        if k > 0 && k < n && ((plane.split(&pts[k]).0 - centre).norm() - r).abs() > limit {
            return none;
        }
    }
    // Three points of an arc under a full turn, in order, turn the way the arc does; if the
    // points do not lie on such an arc, the measure finds the winding wrong.
    let (pm, _) = plane.split(&pts[n / 2]);
    let (pb, _) = plane.split(&b);
    let turn = cross2(&(pm - pa), &(pb - pm));
    if turn == 0.0 {
        return none;
    }
    let helix = Helix { plane, start: a, end: b, centre, ccw: turn > 0.0 };
    if !deviation::sweep_within(&helix, &opts.max_sweep.dir) {
        return none;
    }
    if let Some(t) = job.tangent.as_ref()
        && t.plane == plane
        && !t.allows(&deviation::start_tangent(&helix))
    {
        return none;
    }
    let deviation = deviation::helix(pts, &helix, limit);
    let piece = (deviation <= opts.tol).then_some(Piece {
        first: job.first,
        last: job.last,
        start: a,
        end: b,
        shape: Shape::Arc { centre, plane, ccw: helix.ccw },
        deviation,
    });
    (piece, deviation)
}

/// Points a probe looks at: about this many, spread evenly over the piece.
const PROBE_POINTS: usize = 16;

/// A quick guess whether a piece would fit: a line, or the least-squares arc of a subsample of
/// the points, within the tolerance at those points. Not a proof (chords, winding and the points
/// between are not looked at): the search uses it to find where to measure exactly.
pub fn probe(job: &Job, opts: &Options) -> bool {
    let pts = job.span();
    let n = pts.len() - 1;
    let a = job.start;
    let b = job.end();
    let step = (n / PROBE_POINTS).max(1);
    let sample = || (step..n).step_by(step).map(|k| &pts[k]);
    if sample().all(|p| camkit::geom::dist::point_segment(p, &a, &b) <= opts.tol) {
        return true;
    }
    if n < 2 {
        return false;
    }
    opts.planes.iter().any(|&plane| {
        let (s, _) = plane.split(&a);
        let (e, _) = plane.split(&b);
        let Some(c) = Bisector::new(&s, &e).and_then(|bis| bis.least_squares(sample().map(|p| plane.split(p).0)))
        else {
            return false;
        };
        let r = (s - c).norm();
        r >= opts.min_radius
            && r <= opts.max_radius
            && sample().all(|p| ((plane.split(p).0 - c).norm() - r).abs() <= opts.tol)
    })
}

/// The best piece for a job: a line when one fits (fewer numbers, no radius to round),
/// otherwise an arc in the first plane that fits.
pub fn best(job: &Job, opts: &Options, rounding: &dyn Rounding) -> Option<Piece> {
    if let Some(p) = line(job, opts) {
        return Some(p);
    }
    opts.planes.iter().find_map(|&plane| arc(job, plane, opts, rounding))
}
