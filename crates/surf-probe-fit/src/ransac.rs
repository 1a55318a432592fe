//! RANSAC against gross outliers: elements through random minimal samples (sphere 4 points, plane
//! 3, circle 3, cylinder 6), the best kept, its inliers refitted by the geometric least squares of
//! [`crate::shapes`] until the inlier set settles.
//!
//! With a given inlier threshold the hypotheses are scored by MSAC's truncated cost
//! `Σ min(rᵢ², t²)`; without one by the median of `rᵢ²` (least median of squares) with
//! Rousseeuw's robust scale `σ̂ = 1.4826 (1 + 5/(n − s)) √med rᵢ²` of the best hypothesis. Each new
//! best is replaced by the least-squares fit of its inliers when that scores better (LO-RANSAC),
//! so the scale comes from a refit, not from a noisy minimal
//! sample. The number of hypotheses follows from the wanted confidence `p` and the
//! best inlier ratio `w` seen so far: `N = ln(1 − p) / ln(1 − wˢ)` (without a given threshold
//! `w` is taken as at most ½, the breakdown point of the median: a poor element's own threshold
//! is wide and would count most points as its inliers). Samples come from one seeded
//! generator and are scored in fixed batches in parallel, so the result is the same for any
//! thread count and every run with the same seed.
//!
//! Without a given threshold it comes from the data's own scale, not a fixed share of the points:
//! `t = k(n) σ̂` with `k(n)` the Gaussian quantile a clean set of `n` points exceeds anywhere with
//! probability [`CLEAN_FLAG_PROBABILITY`] (Bonferroni; at least [`MIN_THRESHOLD_SIGMAS`]: 4.3 at
//! 500 points), and after each refit `σ̂ = 1.4826 × median |r|` of the inliers. So a set with
//! Gaussian noise and no outliers keeps every point and gives exactly the plain fit, while gross
//! outliers (far beyond the noise) are all left out.

use crate::rng::Rng;
use crate::shapes::{self, Fit, FitError, Kind, Options, Robust, RobustInfo, Shape};
use camkit::geom::{P3, V3};
use nalgebra::Matrix3;
use rayon::prelude::*;

/// RANSAC settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ransac {
    /// Inlier threshold on the orthogonal distance (mm); `None`: from the robust scale.
    pub threshold: Option<f64>,
    /// Wanted probability that at least one sample is free of outliers.
    pub confidence: f64,
    /// Seed of the sample generator.
    pub seed: u64,
    /// Most hypotheses drawn, whatever the inlier ratio.
    pub max_hypotheses: usize,
}

impl Default for Ransac {
    fn default() -> Self {
        Ransac { threshold: None, confidence: 0.99, seed: 1, max_hypotheses: 10_000 }
    }
}

/// Hypotheses scored together (in parallel); the stopping rule is checked between batches.
const BATCH: usize = 32;

/// Without a given threshold: the probability that a clean set with Gaussian noise loses any
/// point to the threshold (it is the Bonferroni quantile for this probability).
pub const CLEAN_FLAG_PROBABILITY: f64 = 0.01;

/// The smallest threshold in robust standard deviations (small sets).
pub const MIN_THRESHOLD_SIGMAS: f64 = 3.5;

/// The largest share of outliers the least median of squares tolerates: without a given
/// threshold, the number of hypotheses assumes at most this inlier ratio.
const LMEDS_BREAKDOWN: f64 = 0.5;

/// Most refit-and-reclassify rounds.
const MAX_ROUNDS: usize = 20;

/// Points in one sample: the fewest that determine the element, but six for a cylinder (five
/// points lie on up to six cylinders; the sixth picks one, and the geometric fit of the sample
/// starts from the algebraic one).
pub fn sample_size(kind: Kind) -> usize {
    match kind {
        Kind::Sphere => 4,
        Kind::Plane | Kind::Circle => 3,
        Kind::Cylinder => 6,
    }
}

/// Unsigned distance of `x` from the element used to tell inliers: orthogonal distance, for a
/// circle the distance in space from the circle (in-plane and out-of-plane parts together).
pub fn residual(shape: &Shape, x: &P3) -> f64 {
    match shape {
        Shape::Circle { centre, normal, radius } => {
            let d = x - P3::from(*centre);
            let n = V3::from(*normal);
            let h = n.dot(&d);
            ((d - n * h).norm() - radius).hypot(h)
        }
        _ => shape.distance(x).abs(),
    }
}

/// The element through a minimal sample, or `None` for a degenerate one.
fn hypothesis(kind: Kind, s: &[P3], largest_radius: f64) -> Option<Shape> {
    let rel = camkit::tol::DEGENERATE_SPREAD_REL;
    let shape = match kind {
        Kind::Sphere => {
            let (a, b, c) = (s[1] - s[0], s[2] - s[0], s[3] - s[0]);
            let m = Matrix3::from_rows(&[a.transpose(), b.transpose(), c.transpose()]) * 2.0;
            if m.determinant().abs() <= rel * 8.0 * a.norm() * b.norm() * c.norm() {
                return None;
            }
            let o = m.lu().solve(&V3::new(a.norm_squared(), b.norm_squared(), c.norm_squared()))?;
            Shape::Sphere { centre: (s[0] + o).coords.into(), radius: o.norm() }
        }
        Kind::Plane => {
            let (a, b) = (s[1] - s[0], s[2] - s[0]);
            let n = a.cross(&b);
            if n.norm() <= rel * a.norm() * b.norm() {
                return None;
            }
            Shape::Plane { point: s[0].coords.into(), normal: n.normalize().into() }
        }
        Kind::Circle => {
            let (a, b) = (s[1] - s[0], s[2] - s[0]);
            let n = a.cross(&b);
            if n.norm() <= rel * a.norm() * b.norm() {
                return None;
            }
            let o = (b * a.norm_squared() - a * b.norm_squared()).cross(&n) / (2.0 * n.norm_squared());
            Shape::Circle { centre: (s[0] + o).coords.into(), normal: n.normalize().into(), radius: o.norm() }
        }
        Kind::Cylinder => shapes::fit(kind, s, &Options::default()).ok()?.shape,
    };
    let radius = match shape {
        Shape::Sphere { radius, .. } | Shape::Circle { radius, .. } | Shape::Cylinder { radius, .. } => radius,
        Shape::Plane { .. } => 0.0,
    };
    (radius.is_finite() && radius <= largest_radius).then_some(shape)
}

/// A scored hypothesis: cost (lower is better), the element, its inlier count at the threshold
/// (given, or the one its own robust scale implies).
struct Scored {
    cost: f64,
    shape: Shape,
    inliers: usize,
    /// Robust scale `σ̂` of its residuals (least-median mode) or 0.
    scale: f64,
}

fn score(shape: Shape, points: &[P3], threshold: Option<f64>, s: usize) -> Scored {
    let mut r: Vec<f64> = points.iter().map(|x| residual(&shape, x)).collect();
    match threshold {
        Some(t) => {
            let cost = r.iter().map(|r| (r * r).min(t * t)).sum();
            Scored { cost, shape, inliers: r.iter().filter(|&&r| r <= t).count(), scale: 0.0 }
        }
        None => {
            let mid = r.len() / 2;
            let med = *r.select_nth_unstable_by(mid, f64::total_cmp).1;
            let scale = robust_scale(med, points.len(), s);
            let t = threshold_of(scale, points.len());
            Scored { cost: med, shape, inliers: r.iter().filter(|&&r| r <= t).count(), scale }
        }
    }
}

/// Local optimisation (LO-RANSAC): a new best hypothesis is replaced by the least-squares fit of
/// its inliers when that scores better; a minimal sample's element carries the noise of its few
/// points, and the refit is what the final answer will be near.
fn refine(h: Scored, kind: Kind, points: &[P3], opts: &Options, threshold: Option<f64>, s: usize) -> Scored {
    let t = threshold.unwrap_or_else(|| threshold_of(h.scale, points.len()));
    let subset: Vec<P3> = points.iter().filter(|x| residual(&h.shape, x) <= t).copied().collect();
    if subset.len() <= s {
        return h;
    }
    match shapes::fit(kind, &subset, &Options { robust: Robust::None, ..*opts }) {
        Ok(f) => {
            let refit = score(f.shape, points, threshold, s);
            if refit.cost < h.cost { refit } else { h }
        }
        Err(_) => h,
    }
}

/// Rousseeuw's robust standard deviation from the median absolute residual of a hypothesis
/// through `s` of `n` points.
fn robust_scale(median: f64, n: usize, s: usize) -> f64 {
    1.4826 * (1.0 + 5.0 / (n - s) as f64) * median
}

/// The inlier threshold a robust scale implies for `n` points (never below round-off).
fn threshold_of(scale: f64, n: usize) -> f64 {
    (threshold_sigmas(n) * scale).max(camkit::tol::ROUNDOFF_ABS)
}

/// `k(n)`: the distance in standard deviations that any of `n` Gaussian residuals exceeds with
/// probability [`CLEAN_FLAG_PROBABILITY`] (`2n Q(k) = p`, Q the upper normal tail), at least
/// [`MIN_THRESHOLD_SIGMAS`].
pub fn threshold_sigmas(n: usize) -> f64 {
    let want = CLEAN_FLAG_PROBABILITY / (2.0 * n.max(1) as f64);
    let (mut lo, mut hi) = (MIN_THRESHOLD_SIGMAS, 40.0);
    if normal_tail(lo) <= want {
        return lo;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if normal_tail(mid) > want { lo = mid } else { hi = mid }
    }
    hi
}

/// Upper tail `Q(k) = P(Z > k)` of the standard normal distribution (Numerical Recipes' `erfcc`,
/// relative error below 1.2e-7).
fn normal_tail(k: f64) -> f64 {
    let z = k / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.26551223
        + t * (1.00002368
            + t * (0.37409196
                + t * (0.09678418
                    + t * (-0.18628806
                        + t * (0.27886807
                            + t * (-1.13520398 + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277))))))));
    0.5 * t * poly.exp()
}

/// Robust standard deviation `1.4826 × median |r|` of residuals.
fn mad_scale(abs: &mut [f64]) -> f64 {
    let mid = abs.len() / 2;
    1.4826 * *abs.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Hypotheses needed for `confidence` with inlier ratio `w` and samples of `s` points.
fn needed(confidence: f64, w: f64, s: usize) -> f64 {
    let good = w.powi(s as i32);
    if good >= 1.0 {
        return 0.0;
    }
    if good <= 0.0 {
        return f64::INFINITY;
    }
    ((1.0 - confidence).ln() / (1.0 - good).ln()).ceil()
}

/// `s` distinct indices below `n`.
fn draw(rng: &mut Rng, n: usize, s: usize) -> Vec<usize> {
    let mut idx = Vec::with_capacity(s);
    while idx.len() < s {
        let k = (rng.next_u64() % n as u64) as usize;
        if !idx.contains(&k) {
            idx.push(k);
        }
    }
    idx
}

/// RANSAC, then the geometric least-squares fit of the inliers (see the module comment).
/// `largest_radius` bounds the radius of a hypothesis (larger ones are degenerate samples).
pub fn fit(kind: Kind, points: &[P3], opts: &Options, r: &Ransac, largest_radius: f64) -> Result<Fit, FitError> {
    let s = sample_size(kind);
    let n = points.len();
    if n <= s {
        return Err(FitError::Undetermined(format!(
            "{n} points: RANSAC for a {} needs more than its sample of {s}",
            kind.name()
        )));
    }
    let mut rng = Rng::new(r.seed);
    let mut best: Option<Scored> = None;
    let mut drawn = 0usize;
    let mut wanted = r.max_hypotheses as f64;
    while (drawn as f64) < wanted.min(r.max_hypotheses as f64) {
        let batch = BATCH.min(r.max_hypotheses - drawn);
        let samples: Vec<Vec<usize>> = (0..batch).map(|_| draw(&mut rng, n, s)).collect();
        drawn += batch;
        let scored: Vec<Option<Scored>> = samples
            .par_iter()
            .map(|idx| {
                let sample: Vec<P3> = idx.iter().map(|&k| points[k]).collect();
                hypothesis(kind, &sample, largest_radius).map(|h| score(h, points, r.threshold, s))
            })
            .collect();
        for h in scored.into_iter().flatten() {
            if best.as_ref().is_none_or(|b| h.cost < b.cost) {
                let h = refine(h, kind, points, opts, r.threshold, s);
                let w = h.inliers as f64 / n as f64;
                // Without a given threshold a poor element's scale is large and so is the share of
                // points within its own threshold: count on no more than the breakdown point.
                wanted = needed(r.confidence, if r.threshold.is_some() { w } else { w.min(LMEDS_BREAKDOWN) }, s);
                best = Some(h);
            }
        }
    }
    let Some(best) = best else {
        return Err(FitError::Undetermined(format!(
            "RANSAC drew {drawn} samples and every one was degenerate: the points determine no {}",
            kind.name()
        )));
    };
    let mut threshold = r.threshold.unwrap_or_else(|| threshold_of(best.scale, n));
    let classify =
        |shape: &Shape, t: f64| -> Vec<usize> { (0..n).filter(|&k| residual(shape, &points[k]) <= t).collect() };
    let plain = Options { robust: Robust::None, ..*opts };
    let mut inliers = classify(&best.shape, threshold);
    let mut rounds = 0;
    let fitted = loop {
        rounds += 1;
        if inliers.len() <= s {
            return Err(FitError::Undetermined(format!(
                "RANSAC kept {} inliers within {threshold:.3e} mm: too few to fit a {}",
                inliers.len(),
                kind.name()
            )));
        }
        let subset: Vec<P3> = inliers.iter().map(|&k| points[k]).collect();
        let f = shapes::fit(kind, &subset, &plain)?;
        if r.threshold.is_none() {
            // The scale of the inliers' own residuals from their fit.
            let mut abs: Vec<f64> = subset.iter().map(|x| residual(&f.shape, x)).collect();
            threshold = threshold_of(mad_scale(&mut abs), n);
        }
        let next = classify(&f.shape, threshold);
        if next == inliers || rounds == MAX_ROUNDS {
            break f;
        }
        inliers = next;
    };
    let mut f = fitted;
    f.largest_residual_index = inliers[f.largest_residual_index];
    let mut abs: Vec<f64> = inliers.iter().map(|&k| residual(&f.shape, &points[k])).collect();
    let mut is_inlier = vec![false; n];
    for &k in &inliers {
        is_inlier[k] = true;
    }
    let outliers: Vec<usize> = (0..n).filter(|&k| !is_inlier[k]).collect();
    f.robust = Some(RobustInfo {
        method: "ransac",
        scale: mad_scale(&mut abs),
        downweighted: outliers.len(),
        rounds,
        threshold: Some(threshold),
        inliers: Some(inliers.len()),
        outliers: Some(outliers.len()),
        hypotheses: Some(drawn),
        sample_size: Some(s),
        seed: Some(r.seed),
        outlier_indices: outliers,
    });
    Ok(f)
}
