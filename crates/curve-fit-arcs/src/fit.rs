//! Fitting one piece to a range of points: a line or an arc from the written end of the piece
//! before it, ending either exactly at the range's last point (at corners and run ends) or at the
//! point of the fitted line or circle nearest to it (elsewhere: the joint may sit anywhere
//! within the tolerance, which lets pieces run longer). Arc centres are least-squares, refined to
//! minimax when least squares misses the tolerance; every candidate is measured as written.

use crate::Options;
use crate::deviation::{self, Helix};
use camkit::geom::{P2, P3, Plane, V2, V3, arc::angle_between};
use nalgebra::{Matrix2, Matrix3, Vector2};

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

/// What a candidate piece is fitted to.
pub struct Job<'a> {
    /// The run's points.
    pub pts: &'a [P3],
    /// First point of the piece.
    pub first: usize,
    /// Last point of the piece.
    pub last: usize,
    /// The written start.
    pub start: P3,
    /// End exactly at `pts[last]` (rounded) rather than where the fit is best.
    pub fixed_end: bool,
    /// Tangent continuity with the previous piece.
    pub tangent: Option<Tangent>,
}

impl Job<'_> {
    fn span(&self) -> &[P3] {
        &self.pts[self.first..=self.last]
    }
}

/// Minimax solution of the linear residuals `aₖ − Bₖ·x` by Lawson's iteratively reweighted
/// least squares, starting from `x` (the least-squares solution).
fn lawson<const D: usize>(
    rows: &[(f64, nalgebra::SVector<f64, D>)],
    mut x: nalgebra::SVector<f64, D>,
) -> nalgebra::SVector<f64, D> {
    const ITERATIONS: usize = 24;
    let mut w = vec![1.0 / rows.len() as f64; rows.len()];
    for _ in 0..ITERATIONS {
        let res: Vec<f64> = rows.iter().map(|(a, b)| (a - b.dot(&x)).abs()).collect();
        let total: f64 = w.iter().zip(&res).map(|(w, r)| w * r).sum();
        if total <= 0.0 {
            break;
        }
        for (wk, rk) in w.iter_mut().zip(&res) {
            *wk *= rk / total;
        }
        let mut m = nalgebra::SMatrix::<f64, D, D>::zeros();
        let mut v = nalgebra::SVector::<f64, D>::zeros();
        for ((a, b), wk) in rows.iter().zip(&w) {
            m += b * b.transpose() * *wk;
            v += b * (*a * *wk);
        }
        match m.try_inverse() {
            Some(inv) => x = inv * v,
            None => break,
        }
    }
    x
}

/// Tries a line.
pub fn line(job: &Job, opts: &Options, rounding: &dyn Rounding) -> Option<Piece> {
    let pts = job.span();
    let a = job.start;
    let target = pts[pts.len() - 1];
    let b = if job.fixed_end {
        rounding.point(&target)
    } else {
        // The least-squares line through the start; the end is the last point's projection.
        let mut m = Matrix3::zeros();
        for p in pts {
            let d = p - a;
            m += d * d.transpose();
        }
        let chord = target - a;
        let eig = m.symmetric_eigen();
        let (k, _) = eig
            .eigenvalues
            .iter()
            .enumerate()
            .fold((0, f64::MIN), |best, (i, v)| if *v > best.1 { (i, *v) } else { best });
        let u: V3 = eig.eigenvectors.column(k).into_owned();
        let u = if u.dot(&chord) < 0.0 { -u } else { u };
        rounding.point(&(a + u * chord.dot(&u)))
    };
    if let Some(t) = &job.tangent {
        let dir = camkit::geom::dist::unit2(&(t.plane.split(&b).0 - t.plane.split(&a).0))?;
        if !t.allows(&dir) {
            return None;
        }
    }
    let deviation = deviation::line(pts, &a, &b);
    (deviation <= opts.tol).then_some(Piece {
        first: job.first,
        last: job.last,
        start: a,
        end: b,
        shape: Shape::Line,
        deviation,
    })
}

/// Tries an arc in `plane` (at least three points): least-squares centre, then minimax if
/// that misses the tolerance, then (with tangent continuity) the arc tangent to the previous
/// piece.
pub fn arc(job: &Job, plane: Plane, opts: &Options, rounding: &dyn Rounding) -> Option<Piece> {
    if job.last < job.first + 2 {
        return None;
    }
    let pts = job.span();
    let (s, _) = plane.split(&job.start);
    let target = pts[pts.len() - 1];
    let flat: Vec<P2> = pts[1..].iter().map(|p| plane.split(p).0).collect();
    let fixed_end = job.fixed_end.then(|| plane.split(&rounding.point(&target)).0);
    let centres = CentreFit::new(&s, fixed_end.as_ref(), &flat)?;
    let mut tried = centres.least_squares().and_then(|c| arc_about(job, plane, c, opts, rounding));
    if tried.is_none() {
        tried = centres.minimax().and_then(|c| arc_about(job, plane, c, opts, rounding));
    }
    if tried.is_none()
        && let Some(t) = job.tangent.as_ref().filter(|t| t.plane == plane)
    {
        let through = fixed_end.unwrap_or(flat[flat.len() - 1]);
        let c = camkit::geom::circle::tangent_through(&s, &t.dir, &through)?;
        tried = arc_about(job, plane, c.c, opts, rounding);
    }
    tried
}

/// Centres of circles through the start (and the fixed end, if any) fitted to points, as the
/// linear residuals of `|p − c|² − |s − c|²` (about `2r` times the geometric distance).
struct CentreFit {
    /// Residual rows in the free parameters.
    rows: Vec<(f64, Vector2<f64>)>,
    /// Maps the free parameters to a centre.
    origin: P2,
    /// With a fixed end: the unit normal of the chord (one free parameter along it).
    normal: Option<V2>,
}

impl CentreFit {
    fn new(s: &P2, fixed_end: Option<&P2>, pts: &[P2]) -> Option<CentreFit> {
        match fixed_end {
            Some(e) => {
                // Centres on the bisector m + t·n: residual |p−m|² − h² − 2t n·(p−m).
                let chord = e - s;
                let len = chord.norm();
                if len == 0.0 {
                    return None;
                }
                let m = P2::from((s.coords + e.coords) * 0.5);
                let n = V2::new(-chord.y, chord.x) / len;
                let h2 = 0.25 * len * len;
                let rows = pts[..pts.len() - 1]
                    .iter()
                    .map(|p| {
                        let d = p - m;
                        (d.norm_squared() - h2, Vector2::new(2.0 * n.dot(&d), 0.0))
                    })
                    .collect();
                Some(CentreFit { rows, origin: m, normal: Some(n) })
            }
            None => {
                // Centres c = s + x: residual |q|² − 2 x·q with q = p − s.
                let rows = pts
                    .iter()
                    .map(|p| {
                        let q = p - s;
                        (q.norm_squared(), 2.0 * q)
                    })
                    .collect();
                Some(CentreFit { rows, origin: *s, normal: None })
            }
        }
    }

    fn centre(&self, x: &Vector2<f64>) -> P2 {
        match self.normal {
            Some(n) => self.origin + n * x.x,
            None => self.origin + x,
        }
    }

    fn least_squares(&self) -> Option<P2> {
        let mut m = Matrix2::zeros();
        let mut v = Vector2::zeros();
        for (a, b) in &self.rows {
            m += b * b.transpose();
            v += b * *a;
        }
        let x = if self.normal.is_some() {
            if m[(0, 0)] <= 0.0 {
                return None;
            }
            Vector2::new(v.x / m[(0, 0)], 0.0)
        } else {
            m.try_inverse()? * v
        };
        Some(self.centre(&x))
    }

    fn minimax(&self) -> Option<P2> {
        let ls = self.least_squares()?;
        Some(match self.normal {
            Some(n) => {
                let rows: Vec<(f64, nalgebra::Vector1<f64>)> =
                    self.rows.iter().map(|(a, b)| (*a, nalgebra::Vector1::new(b.x))).collect();
                let x0 = nalgebra::Vector1::new((ls - self.origin).dot(&n));
                self.origin + n * lawson(&rows, x0).x
            }
            None => self.centre(&lawson(&self.rows, ls - self.origin)),
        })
    }
}

/// The arc piece about centre `c`, if it meets every constraint.
fn arc_about(job: &Job, plane: Plane, c: P2, opts: &Options, rounding: &dyn Rounding) -> Option<Piece> {
    let pts = job.span();
    let a = job.start;
    let (pa, _) = plane.split(&a);
    let target = pts[pts.len() - 1];
    let b = if job.fixed_end {
        rounding.point(&target)
    } else {
        // The point of the circle (at the target's height along the plane normal) nearest the target.
        let (t, w) = plane.split(&target);
        let r = (pa - c).norm();
        let dir = camkit::geom::dist::unit2(&(t - c))?;
        rounding.point(&plane.join(&(c + dir * r), w))
    };
    let r = 0.5 * ((pa - c).norm() + (plane.split(&b).0 - c).norm());
    if r < opts.min_radius || r > opts.max_radius || !r.is_finite() {
        return None;
    }
    let centre = rounding.centre(&c, &pa);
    // The sense is the way the points wind about the centre.
    let mut turn = 0.0;
    let mut prev = pa - centre;
    for p in &pts[1..] {
        let v = plane.split(p).0 - centre;
        turn += angle_between(&prev, &v);
        prev = v;
    }
    if turn.abs() > opts.max_sweep || turn == 0.0 {
        return None;
    }
    let ccw = turn > 0.0;
    let helix = Helix { plane, start: a, end: b, centre, ccw };
    if let Some(t) = job.tangent.as_ref()
        && t.plane == plane
        && !t.allows(&deviation::start_tangent(&helix))
    {
        return None;
    }
    let deviation = deviation::helix(pts, &helix);
    (deviation <= opts.tol).then_some(Piece {
        first: job.first,
        last: job.last,
        start: a,
        end: b,
        shape: Shape::Arc { centre, plane, ccw },
        deviation,
    })
}

/// The best piece for a job: a line when one fits (fewer numbers, no radius to round),
/// otherwise an arc in the first plane that fits.
pub fn best(job: &Job, opts: &Options, rounding: &dyn Rounding) -> Option<Piece> {
    if let Some(p) = line(job, opts, rounding) {
        return Some(p);
    }
    opts.planes.iter().find_map(|&plane| arc(job, plane, opts, rounding))
}
