//! Levenberg–Marquardt on orthogonal distances: the geometric least-squares engine every
//! iterative fit uses, with the parameter covariance and a conditioning figure at the solution.
//!
//! The normal equations are summed over fixed chunks of points in parallel and the chunk sums
//! added in order, so the result does not depend on the number of threads.

use camkit::geom::P3;
use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

/// Points per chunk of the parallel sums (fixed, so sums are identical for any thread count).
const CHUNK: usize = 8192;

/// Largest number of Levenberg–Marquardt trials before a fit is declared not converged.
pub const MAX_TRIALS: usize = 200;

/// The iteration ends when the undamped Gauss–Newton step is shorter than this, relative to the
/// size of the parameters: they are then at the floating-point floor of the minimum (a few ulps
/// of the largest coordinate, whatever the conditioning: the step is the gradient's, not a
/// fixed tolerance's).
const STEP_REL: f64 = 1e-14;

/// Relative round-off of one distance (a few ulps of the coordinates it is computed from).
const DISTANCE_ULPS: f64 = 8.0 * f64::EPSILON;

/// A geometric fit problem: signed orthogonal distances of points from a shape described by a
/// state, with the gradient of each distance with respect to `N` local parameters.
pub trait Problem<const N: usize>: Sync {
    /// The shape's description (global coordinates).
    type State: Clone + Send + Sync;
    /// Signed distance of `x` from the shape (outwards positive) and its gradient with respect to
    /// the local parameters at `s`.
    fn eval(&self, s: &Self::State, x: &P3) -> (f64, SVector<f64, N>);
    /// The state moved by the local parameter step `delta`.
    fn retract(&self, s: &Self::State, delta: &SVector<f64, N>) -> Self::State;
    /// Typical size (mm) of the state's coordinates: steps are judged relative to it.
    fn scale(&self, s: &Self::State) -> f64;
    /// True when the state has run off where no solution can be (a radius far beyond the points'
    /// spread, as on points nearly on a plane): the iteration stops there and the caller reports it.
    fn runaway(&self, _s: &Self::State) -> bool {
        false
    }
}

/// Normal equations at one state: `JᵀWJ`, `JᵀWr`, the weighted sum of squares.
#[derive(Clone, Copy, Debug)]
pub struct Normal<const N: usize> {
    /// `JᵀWJ`.
    pub jtj: SMatrix<f64, N, N>,
    /// `JᵀWr`.
    pub jtr: SVector<f64, N>,
    /// `Σ wᵢ rᵢ²`.
    pub cost: f64,
}

impl<const N: usize> Normal<N> {
    fn zero() -> Self {
        Normal { jtj: SMatrix::zeros(), jtr: SVector::zeros(), cost: 0.0 }
    }

    fn add(mut self, o: &Self) -> Self {
        self.jtj += o.jtj;
        self.jtr += o.jtr;
        self.cost += o.cost;
        self
    }
}

/// Sums the normal equations of `problem` at `s` over `points` (optional weights).
pub fn normal<const N: usize, P: Problem<N>>(problem: &P, s: &P::State, points: &[P3], w: Option<&[f64]>) -> Normal<N> {
    let chunk = |k: usize, pts: &[P3]| {
        let mut n = Normal::<N>::zero();
        for (i, x) in pts.iter().enumerate() {
            let (r, g) = problem.eval(s, x);
            let wi = w.map_or(1.0, |w| w[k * CHUNK + i]);
            n.jtj.syger(wi, &g, &g, 1.0);
            n.jtr += g * (wi * r);
            n.cost += wi * r * r;
        }
        n
    };
    let parts: Vec<Normal<N>> = points.par_chunks(CHUNK).enumerate().map(|(k, pts)| chunk(k, pts)).collect();
    let mut total = parts.iter().fold(Normal::zero(), |a, b| a.add(b));
    total.jtj.fill_upper_triangle_with_lower_triangle();
    total
}

/// Why an iteration failed.
#[derive(Clone, Debug, PartialEq)]
pub enum Failure {
    /// No convergence within [`MAX_TRIALS`] trials.
    NotConverged {
        /// Trials made.
        trials: usize,
    },
    /// The parameters ran off to non-finite values or the normal equations became singular.
    Diverged,
}

/// The result of an iteration.
#[derive(Clone, Debug)]
pub struct Solution<S, const N: usize> {
    /// Final state.
    pub state: S,
    /// Normal equations at the final state.
    pub normal: Normal<N>,
    /// Accepted steps.
    pub iterations: usize,
}

/// Minimises `Σ wᵢ dᵢ²` from `start` by Levenberg–Marquardt (Marquardt's diagonal scaling).
///
/// Convergence is judged by the gradient, not by a damped step or a fixed tolerance: the
/// iteration ends when the undamped Gauss–Newton step `−(JᵀWJ)⁻¹JᵀWr` is below [`STEP_REL`] of
/// the parameters' size. Once the decrease that step promises is below the round-off of the cost
/// itself, the cost can no longer tell better from worse: Gauss–Newton steps are then taken as
/// long as each shortens the next one (the gradient still knows the way), and the iteration ends
/// at the first that does not. So ill-conditioned fits (a small cap of a sphere) reach the
/// floating-point floor instead of stopping where the cost goes flat.
pub fn minimise<const N: usize, P: Problem<N>>(
    problem: &P,
    start: P::State,
    points: &[P3],
    w: Option<&[f64]>,
) -> Result<Solution<P::State, N>, Failure> {
    let mut state = start;
    let mut n = normal(problem, &state, points, w);
    if !n.cost.is_finite() {
        return Err(Failure::Diverged);
    }
    let mut lambda = 1e-4;
    let mut iterations = 0;
    for trial in 0..MAX_TRIALS {
        let scale = 1.0 + problem.scale(&state);
        if let Some(gn) = gauss_newton(&n) {
            if gn.norm() <= STEP_REL * scale {
                return Ok(Solution { state, normal: n, iterations });
            }
            if -gn.dot(&n.jtr) <= cost_roundoff(n.cost, points.len(), scale) {
                let next = problem.retract(&state, &gn);
                let m = normal(problem, &next, points, w);
                let shorter = gauss_newton(&m).is_some_and(|g| g.norm() < gn.norm());
                if !(shorter && m.cost <= n.cost + cost_roundoff(n.cost, points.len(), scale)) {
                    return Ok(Solution { state, normal: n, iterations });
                }
                state = next;
                n = m;
                iterations += 1;
                continue;
            }
        }
        let mut a = n.jtj;
        for k in 0..N {
            a[(k, k)] += lambda * n.jtj[(k, k)].max(f64::MIN_POSITIVE);
        }
        let Some(chol) = a.cholesky() else {
            lambda *= 10.0;
            if lambda > 1e30 {
                return Err(Failure::Diverged);
            }
            continue;
        };
        let delta = -chol.solve(&n.jtr);
        if !delta.iter().all(|d| d.is_finite()) {
            return Err(Failure::Diverged);
        }
        let next = problem.retract(&state, &delta);
        let m = normal(problem, &next, points, w);
        if m.cost.is_finite() && m.cost <= n.cost {
            state = next;
            n = m;
            iterations += 1;
            lambda = (lambda / 10.0).max(1e-12);
            if problem.runaway(&state) {
                return Ok(Solution { state, normal: n, iterations });
            }
        } else {
            lambda *= 10.0;
            if lambda > 1e30 {
                return Err(Failure::NotConverged { trials: trial + 1 });
            }
        }
    }
    Err(Failure::NotConverged { trials: MAX_TRIALS })
}

/// The undamped Gauss–Newton step at `n`, if the normal equations are positive definite.
fn gauss_newton<const N: usize>(n: &Normal<N>) -> Option<SVector<f64, N>> {
    let step = -n.jtj.cholesky()?.solve(&n.jtr);
    step.iter().all(|d| d.is_finite()).then_some(step)
}

/// Round-off of a cost `Σ rᵢ²` of `points` distances each computed from coordinates of size
/// `scale`: `Σ (2|rᵢ| δr + δr²)` with `δr` a few ulps of `scale`, plus the sum's own rounding.
fn cost_roundoff(cost: f64, points: usize, scale: f64) -> f64 {
    let n = points as f64;
    let dr = DISTANCE_ULPS * scale;
    2.0 * (n * cost).sqrt() * dr + n * dr * dr + n * f64::EPSILON * cost
}

/// Standard uncertainties and conditioning of the local parameters at a solution.
#[derive(Clone, Debug, PartialEq)]
pub struct Uncertainty<const N: usize> {
    /// Standard uncertainty of each parameter: `σ₀ √((JᵀJ)⁻¹)ᵢᵢ` with `σ₀² = Σr²/(n − N)`.
    pub u: [f64; N],
    /// Noise amplification of each parameter: `√(n (JᵀJ)⁻¹ᵢᵢ)`, the parameter's standard
    /// uncertainty per unit standard deviation of the points, times √n. About 1 for a parameter
    /// the points determine well (a full sphere's radius); large when they do not (a small cap).
    pub amplification: [f64; N],
}

/// The uncertainty of a solution with `n` points and unweighted normal equations `normal`.
/// Singular normal equations give infinite uncertainties.
pub fn uncertainty<const N: usize>(normal: &Normal<N>, n: usize) -> Uncertainty<N> {
    let dof = n.saturating_sub(N).max(1) as f64;
    let sigma0 = (normal.cost / dof).sqrt();
    let inv = normal.jtj.try_inverse();
    let mut u = [f64::INFINITY; N];
    let mut amplification = [f64::INFINITY; N];
    if let Some(inv) = inv {
        for k in 0..N {
            let d = inv[(k, k)];
            if d.is_finite() && d >= 0.0 {
                u[k] = sigma0 * d.sqrt();
                amplification[k] = (n as f64 * d).sqrt();
            }
        }
    }
    Uncertainty { u, amplification }
}
