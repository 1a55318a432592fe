//! A smooth height field for free-form parts: a bicubic B-spline `z(x, y)` over the points'
//! bounding box fitted by least squares to the heights (clamped uniform knots; control points at
//! the Greville abscissae, so x and y are exactly linear in the parameters), with a small
//! second-difference penalty that keeps spans without points determined. It is written as the
//! `bspline` surface of a `camkit::doc::model` document, which `stylus-trace` reads.

use camkit::geom::P3;
use nalgebra::{DMatrix, DVector};

/// A fitted height field.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightField {
    /// Control points `[i][j]` (i along x, j along y).
    pub control_points: Vec<Vec<[f64; 3]>>,
    /// RMS of the vertical residuals (mm).
    pub rms: f64,
    /// Largest vertical residual, signed (mm).
    pub largest_residual: f64,
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
    let mut ss = 0.0;
    let mut largest: f64 = 0.0;
    for p in points {
        let (u, v) = param(p);
        let ((iu, bu), (iv, bv)) = (basis(nu, u), basis(nv, v));
        let mut h = 0.0;
        for a in 0..4 {
            for b in 0..4 {
                h += bu[a] * bv[b] * z[(iu + a) * nv + iv + b];
            }
        }
        let r = p.z - h;
        ss += r * r;
        if r.abs() > largest.abs() {
            largest = r;
        }
    }
    Some(HeightField { control_points, rms: (ss / points.len() as f64).sqrt(), largest_residual: largest })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_a_partition_of_unity() {
        for t in [0.0, 0.1, 0.5, 0.77, 1.0] {
            let (_, b) = basis(7, t);
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-14 && b.iter().all(|&x| x >= 0.0));
        }
    }
}
