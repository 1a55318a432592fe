//! A smooth height field for free-form parts: a bicubic B-spline `z(x, y)` over the points'
//! bounding box fitted by least squares to the heights (clamped uniform knots; control points at
//! the Greville abscissae, so x and y are exactly linear in the parameters), with a small
//! second-difference penalty that keeps spans without points determined. It is written as the
//! `bspline` surface of a `camkit::doc::model` document, which `stylus-trace` reads.
//!
//! Residuals are reported both vertically (`z` minus the height) and orthogonally: the distance
//! from each point to its closest point on the surface, found by Newton's method on the squared
//! distance over `(x, y)` from the vertical foot (with a descent line search, so the orthogonal
//! distance never exceeds the vertical one beyond round-off).

use camkit::geom::{P3, V3};
use nalgebra::{DMatrix, DVector, Matrix2, Vector2};
use rayon::prelude::*;

/// A fitted height field.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightField {
    /// Control points `[i][j]` (i along x, j along y).
    pub control_points: Vec<Vec<[f64; 3]>>,
    /// RMS of the vertical residuals (mm).
    pub rms: f64,
    /// Largest vertical residual, signed (mm).
    pub largest_residual: f64,
    /// RMS of the orthogonal distances of the points from the surface (mm).
    pub orthogonal_rms: f64,
    /// Largest orthogonal distance, signed (above the surface positive, mm).
    pub largest_orthogonal: f64,
    /// Control points along x and y.
    nu: usize,
    nv: usize,
    /// The box `x0, x1, y0, y1` the surface spans.
    bounds: [f64; 4],
    /// Control heights, `i * nv + j`.
    heights: Vec<f64>,
}

/// A point of the surface with its height derivatives with respect to x and y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jet {
    /// Height.
    pub h: f64,
    /// `∂h/∂x`, `∂h/∂y`.
    pub hx: f64,
    /// See `hx`.
    pub hy: f64,
    /// `∂²h/∂x²`, `∂²h/∂x∂y`, `∂²h/∂y²`.
    pub hxx: f64,
    /// See `hxx`.
    pub hxy: f64,
    /// See `hxx`.
    pub hyy: f64,
}

/// The closest point of the surface to a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Foot {
    /// The closest point.
    pub point: P3,
    /// Signed distance: positive above the surface (on the side of its upward normal).
    pub distance: f64,
    /// Newton steps taken.
    pub steps: usize,
}

/// Most Newton steps of the closest-point search.
const NEWTON_STEPS: usize = 50;

/// Newton stops when a step is shorter than this fraction of the box's size.
const NEWTON_STEP_REL: f64 = 1e-14;

impl HeightField {
    /// Height and derivatives at `(x, y)` (clamped to the box).
    pub fn jet(&self, x: f64, y: f64) -> Jet {
        let [x0, x1, y0, y1] = self.bounds;
        let (sx, sy) = (x1 - x0, y1 - y0);
        let u = ((x - x0) / sx).clamp(0.0, 1.0);
        let v = ((y - y0) / sy).clamp(0.0, 1.0);
        let ((iu, du), (iv, dv)) = (basis_ders(self.nu, u), basis_ders(self.nv, v));
        let z = |a: usize, b: usize| self.heights[(iu + a) * self.nv + iv + b];
        let mut d = [[0.0; 3]; 3];
        for (k, duk) in du.iter().enumerate() {
            for (l, dvl) in dv.iter().enumerate().take(3 - k) {
                d[k][l] = (0..4).map(|a| duk[a] * (0..4).map(|b| dvl[b] * z(a, b)).sum::<f64>()).sum();
            }
        }
        Jet {
            h: d[0][0],
            hx: d[1][0] / sx,
            hy: d[0][1] / sy,
            hxx: d[2][0] / (sx * sx),
            hxy: d[1][1] / (sx * sy),
            hyy: d[0][2] / (sy * sy),
        }
    }

    /// The closest point of the surface (over its box) to `p`: Newton on `½|S(x, y) − p|²` from
    /// the vertical foot, each step halved until the distance decreases.
    pub fn closest(&self, p: &P3) -> Foot {
        let [x0, x1, y0, y1] = self.bounds;
        let clamp = |q: Vector2<f64>| Vector2::new(q.x.clamp(x0, x1), q.y.clamp(y0, y1));
        let cost = |q: &Vector2<f64>, j: &Jet| 0.5 * ((q.x - p.x).powi(2) + (q.y - p.y).powi(2) + (j.h - p.z).powi(2));
        let mut q = clamp(Vector2::new(p.x, p.y));
        let mut j = self.jet(q.x, q.y);
        let mut f = cost(&q, &j);
        let floor = NEWTON_STEP_REL * (x1 - x0).max(y1 - y0);
        let mut steps = 0;
        let grad =
            |q: &Vector2<f64>, j: &Jet| Vector2::new(q.x - p.x + (j.h - p.z) * j.hx, q.y - p.y + (j.h - p.z) * j.hy);
        while steps < NEWTON_STEPS {
            let e = j.h - p.z;
            let g = grad(&q, &j);
            let hess = Matrix2::new(
                1.0 + j.hx * j.hx + e * j.hxx,
                j.hx * j.hy + e * j.hxy,
                j.hx * j.hy + e * j.hxy,
                1.0 + j.hy * j.hy + e * j.hyy,
            );
            let newton = hess.cholesky().map(|c| -c.solve(&g));
            let dir = newton.unwrap_or(-g);
            let mut t = 1.0;
            let mut next = None;
            while t * dir.norm() > floor {
                let cand = clamp(q + dir * t);
                let jc = self.jet(cand.x, cand.y);
                let fc = cost(&cand, &jc);
                // Near the foot the squared distance is flat to round-off while the full Newton
                // step still halves the error: there a smaller gradient decides.
                let flat = newton.is_some()
                    && t == 1.0
                    && fc <= f * (1.0 + camkit::tol::ROUNDOFF_REL)
                    && grad(&cand, &jc).norm() < g.norm();
                if fc < f || flat {
                    next = Some((cand, jc, fc));
                    break;
                }
                t *= 0.5;
            }
            let Some((cand, jc, fc)) = next else { break };
            steps += 1;
            let moved = (cand - q).norm();
            (q, j, f) = (cand, jc, fc);
            if moved <= floor {
                break;
            }
        }
        let point = P3::new(q.x, q.y, j.h);
        let up = V3::new(-j.hx, -j.hy, 1.0);
        let d = (p - point).norm();
        let distance = if (p - point).dot(&up) < 0.0 { -d } else { d };
        Foot { point, distance, steps }
    }
}

/// Values and first and second derivatives (with respect to `t`) of the four non-zero cubic
/// B-spline basis functions at `t` on the clamped uniform knot vector of `n` control points, and
/// the index of the first (The NURBS Book, A2.3).
fn basis_ders(n: usize, t: f64) -> (usize, [[f64; 4]; 3]) {
    const P: usize = 3;
    let spans = n - P;
    let knot = |k: usize| -> f64 {
        if k <= P {
            0.0
        } else if k >= n {
            1.0
        } else {
            (k - P) as f64 / spans as f64
        }
    };
    let span = ((t * spans as f64).floor() as usize).min(spans - 1) + P;
    let mut ndu = [[0.0; 4]; 4];
    let (mut left, mut right) = ([0.0; 4], [0.0; 4]);
    ndu[0][0] = 1.0;
    for j in 1..=P {
        left[j] = t - knot(span + 1 - j);
        right[j] = knot(span + j) - t;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let tmp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        ndu[j][j] = saved;
    }
    let mut ders = [[0.0; 4]; 3];
    for j in 0..=P {
        ders[0][j] = ndu[j][P];
    }
    for r in 0..=P as i64 {
        let mut a = [[0.0; 4]; 2];
        let (mut s1, mut s2) = (0, 1);
        a[0][0] = 1.0;
        for k in 1..=2i64 {
            let mut d = 0.0;
            let (rk, pk) = (r - k, P as i64 - k);
            if r >= k {
                a[s2][0] = a[s1][0] / ndu[(pk + 1) as usize][rk as usize];
                d = a[s2][0] * ndu[rk as usize][pk as usize];
            }
            let j1 = if rk >= -1 { 1 } else { -rk };
            let j2 = if r - 1 <= pk { k - 1 } else { P as i64 - r };
            for j in j1..=j2 {
                let (ju, rkj) = (j as usize, (rk + j) as usize);
                a[s2][ju] = (a[s1][ju] - a[s1][ju - 1]) / ndu[(pk + 1) as usize][rkj];
                d += a[s2][ju] * ndu[rkj][pk as usize];
            }
            if r <= pk {
                a[s2][k as usize] = -a[s1][(k - 1) as usize] / ndu[(pk + 1) as usize][r as usize];
                d += a[s2][k as usize] * ndu[r as usize][pk as usize];
            }
            ders[k as usize][r as usize] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = P as f64;
    for (k, dk) in ders.iter_mut().enumerate().skip(1) {
        for x in dk.iter_mut() {
            *x *= factor;
        }
        factor *= (P - k) as f64;
    }
    (span - P, ders)
}

/// The four non-zero cubic B-spline basis values at `t` ∈ [0, 1] on a clamped uniform knot
/// vector with `n` control points, and the index of the first.
fn basis(n: usize, t: f64) -> (usize, [f64; 4]) {
    let spans = n - 3;
    let knots: Vec<f64> = (0..n + 4)
        .map(|k| {
            if k < 4 {
                0.0
            } else if k >= n {
                1.0
            } else {
                (k - 3) as f64 / spans as f64
            }
        })
        .collect();
    let span = ((t * spans as f64).floor() as usize).min(spans - 1) + 3;
    // Cox–de Boor, triangular scheme (The NURBS Book, A2.2).
    let mut out = [0.0; 4];
    let (mut left, mut right) = ([0.0; 4], [0.0; 4]);
    out[0] = 1.0;
    for j in 1..=3 {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            let tmp = out[r] / (right[r + 1] + left[j - r]);
            out[r] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        out[j] = saved;
    }
    (span - 3, out)
}

/// Weight of the second-difference penalty relative to the data (per point).
const SMOOTHING: f64 = 1e-12;

/// Fits a `nu × nv` (each ≥ 4) bicubic height field to `points`; `None` if the points span no area.
pub fn fit(points: &[P3], nu: usize, nv: usize) -> Option<HeightField> {
    let (x0, x1) = points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.x), b.max(p.x)));
    let (y0, y1) = points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.y), b.max(p.y)));
    if !(x1 > x0 && y1 > y0) || nu < 4 || nv < 4 {
        return None;
    }
    let n = nu * nv;
    let mut ata = DMatrix::<f64>::zeros(n, n);
    let mut atb = DVector::<f64>::zeros(n);
    let param = |p: &P3| ((p.x - x0) / (x1 - x0), (p.y - y0) / (y1 - y0));
    for p in points {
        let (u, v) = param(p);
        let ((iu, bu), (iv, bv)) = (basis(nu, u), basis(nv, v));
        let mut idx = [0usize; 16];
        let mut val = [0.0; 16];
        for a in 0..4 {
            for b in 0..4 {
                idx[a * 4 + b] = (iu + a) * nv + iv + b;
                val[a * 4 + b] = bu[a] * bv[b];
            }
        }
        for r in 0..16 {
            atb[idx[r]] += val[r] * p.z;
            for c in 0..16 {
                ata[(idx[r], idx[c])] += val[r] * val[c];
            }
        }
    }
    // Second differences of the control heights along both directions.
    let w = SMOOTHING * points.len() as f64;
    let mut penalise = |a: usize, b: usize, c: usize| {
        for (i, ci) in [(a, 1.0), (b, -2.0), (c, 1.0)] {
            for (j, cj) in [(a, 1.0), (b, -2.0), (c, 1.0)] {
                ata[(i, j)] += w * ci * cj;
            }
        }
    };
    for i in 0..nu {
        for j in 0..nv {
            if i + 2 < nu {
                penalise(i * nv + j, (i + 1) * nv + j, (i + 2) * nv + j);
            }
            if j + 2 < nv {
                penalise(i * nv + j, i * nv + j + 1, i * nv + j + 2);
            }
        }
    }
    let z = ata.cholesky()?.solve(&atb);
    let greville = |n: usize, k: usize| -> f64 {
        let spans = (n - 3) as f64;
        let knot = |m: usize| {
            if m < 4 {
                0.0
            } else if m >= n {
                1.0
            } else {
                (m - 3) as f64 / spans
            }
        };
        (knot(k + 1) + knot(k + 2) + knot(k + 3)) / 3.0
    };
    let control_points = (0..nu)
        .map(|i| {
            (0..nv)
                .map(|j| [x0 + (x1 - x0) * greville(nu, i), y0 + (y1 - y0) * greville(nv, j), z[i * nv + j]])
                .collect()
        })
        .collect();
    let mut h = HeightField {
        control_points,
        rms: 0.0,
        largest_residual: 0.0,
        orthogonal_rms: 0.0,
        largest_orthogonal: 0.0,
        nu,
        nv,
        bounds: [x0, x1, y0, y1],
        heights: z.iter().copied().collect(),
    };
    let residuals: Vec<(f64, f64)> =
        points.par_iter().map(|p| (p.z - h.jet(p.x, p.y).h, h.closest(p).distance)).collect();
    let signed_largest = |a: f64, b: f64| if b.abs() > a.abs() { b } else { a };
    let n = points.len() as f64;
    h.rms = (residuals.iter().map(|r| r.0 * r.0).sum::<f64>() / n).sqrt();
    h.largest_residual = residuals.iter().map(|r| r.0).fold(0.0, signed_largest);
    h.orthogonal_rms = (residuals.iter().map(|r| r.1 * r.1).sum::<f64>() / n).sqrt();
    h.largest_orthogonal = residuals.iter().map(|r| r.1).fold(0.0, signed_largest);
    Some(h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_match_the_values_and_differences() {
        for n in [4, 5, 9] {
            for t in [0.0, 0.03, 0.37, 0.5, 0.81, 1.0] {
                let (i, d) = basis_ders(n, t);
                assert_eq!((i, d[0]), basis(n, t));
                assert!(d[1].iter().sum::<f64>().abs() < 1e-12 && d[2].iter().sum::<f64>().abs() < 1e-9);
                let hstep = 1e-6;
                let (ta, tb) = ((t - hstep).max(0.0), (t + hstep).min(1.0));
                let ((ia, a), (ib, b)) = (basis_ders(n, ta), basis_ders(n, tb));
                if ia == i && ib == i {
                    for k in 0..4 {
                        let (d1, d2) = ((b[0][k] - a[0][k]) / (tb - ta), (b[1][k] - a[1][k]) / (tb - ta));
                        assert!((d1 - d[1][k]).abs() < 1e-4 * (1.0 + d[1][k].abs()), "n {n} t {t}: {d1} {}", d[1][k]);
                        assert!((d2 - d[2][k]).abs() < 1e-3 * (1.0 + d[2][k].abs()), "n {n} t {t}: {d2} {}", d[2][k]);
                    }
                }
            }
        }
    }

    #[test]
    fn basis_is_a_partition_of_unity() {
        for t in [0.0, 0.1, 0.5, 0.77, 1.0] {
            let (_, b) = basis(7, t);
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-14 && b.iter().all(|&x| x >= 0.0));
        }
    }
}
