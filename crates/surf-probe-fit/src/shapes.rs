//! Geometric fits of a sphere, a plane, a circle and a cylinder: an algebraic (linear) start,
//! then least squares on orthogonal distances ([`crate::lsq`]), optionally robust (Huber weights
//! by iteratively reweighted least squares, or RANSAC and a refit of the inliers:
//! [`crate::ransac`]), with RMS, the largest residual, each parameter's
//! standard uncertainty and a warning for parameters the points determine poorly.

use crate::lsq::{self, Failure, Problem};
use crate::ransac::{self, Ransac};
use camkit::geom::{P3, V3};
use nalgebra::{Matrix3, Matrix4, SVector, SymmetricEigen, Vector4};
use serde::{Deserialize, Serialize};

/// Which element to fit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Centre and radius.
    Sphere,
    /// Point and unit normal.
    Plane,
    /// A circle in space: the best plane, then centre and radius in it.
    Circle,
    /// Axis (point, direction) and radius.
    Cylinder,
}

impl Kind {
    /// Number of parameters (the fewest points that determine the element).
    pub fn parameters(self) -> usize {
        match self {
            Kind::Sphere => 4,
            Kind::Plane => 3,
            Kind::Circle => 3,
            Kind::Cylinder => 5,
        }
    }

    /// Name in documents and messages.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Sphere => "sphere",
            Kind::Plane => "plane",
            Kind::Circle => "circle",
            Kind::Cylinder => "cylinder",
        }
    }
}

/// A fitted element (table or workpiece coordinates, mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "lowercase")]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Centre.
        centre: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// A plane.
    Plane {
        /// The centroid of the points, on the plane.
        point: [f64; 3],
        /// Unit normal (towards +Z where it has a Z component).
        normal: [f64; 3],
    },
    /// A circle in space.
    Circle {
        /// Centre.
        centre: [f64; 3],
        /// Unit normal of its plane.
        normal: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// A cylinder.
    Cylinder {
        /// The point of the axis nearest the points' centroid.
        point: [f64; 3],
        /// Unit axis direction.
        axis: [f64; 3],
        /// Radius.
        radius: f64,
    },
}

impl Shape {
    /// Signed orthogonal distance of `x` from the element (outwards positive; for a circle, the
    /// radial distance in its plane).
    pub fn distance(&self, x: &P3) -> f64 {
        match self {
            Shape::Sphere { centre, radius } => (x - P3::from(*centre)).norm() - radius,
            Shape::Plane { point, normal } => V3::from(*normal).dot(&(x - P3::from(*point))),
            Shape::Circle { centre, normal, radius } => {
                let d = x - P3::from(*centre);
                let n = V3::from(*normal);
                (d - n * n.dot(&d)).norm() - radius
            }
            Shape::Cylinder { point, axis, radius } => {
                let d = x - P3::from(*point);
                let a = V3::from(*axis);
                (d - a * a.dot(&d)).norm() - radius
            }
        }
    }

    /// Unit outward normal of the element at (or nearest to) `x`.
    pub fn normal_at(&self, x: &P3) -> V3 {
        match self {
            Shape::Sphere { centre, .. } => (x - P3::from(*centre)).normalize(),
            Shape::Plane { normal, .. } => V3::from(*normal),
            Shape::Circle { centre, normal, .. } | Shape::Cylinder { point: centre, axis: normal, .. } => {
                let d = x - P3::from(*centre);
                let n = V3::from(*normal);
                (d - n * n.dot(&d)).normalize()
            }
        }
    }
}

/// Robust weighting against outliers.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Robust {
    /// Plain least squares.
    #[default]
    None,
    /// Huber weights with threshold `k` robust standard deviations (1.345 is the usual choice).
    Huber(f64),
    /// RANSAC on minimal samples, then least squares on the inliers.
    Ransac(Ransac),
}

/// Settings of a fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Noise amplification above which a parameter is reported as poorly determined.
    pub max_amplification: f64,
    /// Robust weighting.
    pub robust: Robust,
}

impl Default for Options {
    fn default() -> Self {
        Options { max_amplification: DEFAULT_MAX_AMPLIFICATION, robust: Robust::None }
    }
}

/// Default threshold of [`Options::max_amplification`]: a 30° cap of a sphere stays below it
/// (centre-z and radius amplification ≈ 25), a 10° cap exceeds it (≈ 230, growing as 1/θ²).
pub const DEFAULT_MAX_AMPLIFICATION: f64 = 100.0;

/// One fitted parameter with its standard uncertainty.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Param {
    /// Name (`cx`, `radius`, `tilt_u`...).
    pub name: &'static str,
    /// Value, for parameters that are coordinates of the result; local corrections (tilts,
    /// offsets across an axis) are zero at the solution and have none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<f64>,
    /// Standard uncertainty (mm or radians) from the residuals: `σ₀ √((JᵀJ)⁻¹)ᵢᵢ`.
    pub u: f64,
    /// Noise amplification `√(n (JᵀJ)⁻¹ᵢᵢ)` (see [`lsq::Uncertainty`]).
    pub amplification: f64,
}

/// Robust fitting figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RobustInfo {
    /// `huber` or `ransac`.
    pub method: &'static str,
    /// Robust standard deviation of the residuals (1.4826 × median absolute residual, mm; RANSAC:
    /// of the inliers from the final fit).
    pub scale: f64,
    /// Points given a weight below 1 (RANSAC: the outliers, weight 0).
    pub downweighted: usize,
    /// Reweighting rounds (RANSAC: refit-and-reclassify rounds).
    pub rounds: usize,
    /// RANSAC: the inlier threshold on the distance (mm), given or from the robust scale.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub threshold: Option<f64>,
    /// RANSAC: points within the threshold of the final fit (the points it was fitted to).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inliers: Option<usize>,
    /// RANSAC: the other points.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub outliers: Option<usize>,
    /// RANSAC: hypotheses drawn (degenerate samples included).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hypotheses: Option<usize>,
    /// RANSAC: points per sample.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sample_size: Option<usize>,
    /// RANSAC: seed of the samples.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// RANSAC: indices (0-based, ascending) of the outliers in the input (not in the document).
    #[serde(skip)]
    pub outlier_indices: Vec<usize>,
}

impl RobustInfo {
    fn huber(scale: f64, downweighted: usize, rounds: usize) -> RobustInfo {
        RobustInfo {
            method: "huber",
            scale,
            downweighted,
            rounds,
            threshold: None,
            inliers: None,
            outliers: None,
            hypotheses: None,
            sample_size: None,
            seed: None,
            outlier_indices: Vec::new(),
        }
    }
}

/// A fit and its figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Fit {
    /// The element.
    #[serde(flatten)]
    pub shape: Shape,
    /// Number of points fitted (RANSAC: the inliers).
    pub points: usize,
    /// Root mean square of the orthogonal distances (mm).
    pub rms: f64,
    /// The largest orthogonal distance, signed (mm).
    pub largest_residual: f64,
    /// Index (0-based) of the point with the largest distance.
    pub largest_residual_index: usize,
    /// For a circle: RMS distance of the points from its plane (mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub out_of_plane_rms: Option<f64>,
    /// Accepted Levenberg–Marquardt steps (summed over reweighting rounds).
    pub iterations: usize,
    /// Parameters with standard uncertainties.
    pub parameters: Vec<Param>,
    /// Names of the parameters whose noise amplification exceeds the threshold.
    pub poorly_determined: Vec<&'static str>,
    /// Robust weighting, if used.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub robust: Option<RobustInfo>,
}

impl Fit {
    /// The warning to print for poorly determined parameters, if any.
    pub fn warning(&self) -> Option<String> {
        if self.poorly_determined.is_empty() {
            return None;
        }
        let worst = self
            .parameters
            .iter()
            .filter(|p| self.poorly_determined.contains(&p.name))
            .map(|p| format!("{} (amplification {:.0})", p.name, p.amplification))
            .collect::<Vec<_>>()
            .join(", ");
        Some(format!(
            "the points determine {worst} poorly: 1 µm of measuring noise moves them by that many µm / √n; \
             measure a larger part of the {}",
            match self.shape {
                Shape::Sphere { .. } => "sphere",
                Shape::Plane { .. } => "plane",
                Shape::Circle { .. } => "circle",
                Shape::Cylinder { .. } => "cylinder",
            }
        ))
    }
}

/// Why a fit failed.
#[derive(Clone, Debug, PartialEq)]
pub enum FitError {
    /// The points cannot determine the element (too few, on one plane or line...): bad input.
    Undetermined(String),
    /// The iteration did not converge or diverged.
    NotConverged(String),
}

impl std::fmt::Display for FitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FitError::Undetermined(m) | FitError::NotConverged(m) => f.write_str(m),
        }
    }
}

/// Fits `kind` to `points`.
pub fn fit(kind: Kind, points: &[P3], opts: &Options) -> Result<Fit, FitError> {
    if points.len() < kind.parameters() {
        return Err(FitError::Undetermined(format!(
            "{} points: a {} needs at least {}",
            points.len(),
            kind.name(),
            kind.parameters()
        )));
    }
    let spread = Spread::of(points);
    let flat = spread.sigma[0] <= camkit::tol::DEGENERATE_SPREAD_REL * spread.sigma[2];
    let line = spread.sigma[1] <= camkit::tol::DEGENERATE_SPREAD_REL * spread.sigma[2];
    if spread.sigma[2] == 0.0 {
        return Err(FitError::Undetermined("all points coincide".into()));
    }
    if line {
        return Err(FitError::Undetermined(format!("all points lie on one line: a {} is not determined", kind.name())));
    }
    if flat && matches!(kind, Kind::Sphere | Kind::Cylinder) {
        return Err(FitError::Undetermined(format!(
            "all points lie on one plane: a {} is not determined",
            kind.name()
        )));
    }
    if let Robust::Ransac(r) = opts.robust {
        return ransac::fit(kind, points, opts, &r, DIVERGENCE_FACTOR * spread.sigma[2]);
    }
    match kind {
        Kind::Sphere => fit_sphere(points, opts, &spread),
        Kind::Plane => fit_plane(points, opts, &spread),
        Kind::Circle => fit_circle(points, opts, &spread),
        Kind::Cylinder => fit_cylinder(points, opts, &spread),
    }
}

/// Centroid and principal directions of a point set.
struct Spread {
    centroid: P3,
    /// Standard deviations along the principal directions, ascending.
    sigma: [f64; 3],
    /// Principal directions (columns), in the order of `sigma`.
    dirs: Matrix3<f64>,
}

impl Spread {
    fn of(points: &[P3]) -> Spread {
        let n = points.len() as f64;
        let centroid = P3::from(points.iter().fold(V3::zeros(), |a, p| a + p.coords) / n);
        let mut cov = Matrix3::zeros();
        for p in points {
            let d = p - centroid;
            cov.syger(1.0 / n, &d, &d, 1.0);
        }
        cov.fill_upper_triangle_with_lower_triangle();
        let eig = SymmetricEigen::new(cov);
        let mut idx = [0usize, 1, 2];
        idx.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let sigma = idx.map(|i| eig.eigenvalues[i].max(0.0).sqrt());
        let dirs = Matrix3::from_columns(&idx.map(|i| eig.eigenvectors.column(i).into_owned()));
        Spread { centroid, sigma, dirs }
    }
}

/// A unit vector's sign made canonical: +Z where it has a Z component, else +Y, else +X.
fn canonical(n: V3) -> V3 {
    let key = if n.z.abs() > camkit::tol::ANGLE_EPS {
        n.z
    } else if n.y.abs() > camkit::tol::ANGLE_EPS {
        n.y
    } else {
        n.x
    };
    if key < 0.0 { -n } else { n }
}

/// Two unit vectors completing `n` to a right-handed orthonormal basis (a fixed function of `n`).
pub fn basis(n: &V3) -> (V3, V3) {
    let helper = if n.x.abs() < 0.6 { V3::x() } else { V3::y() };
    let u = (helper - n * n.dot(&helper)).normalize();
    (u, n.cross(&u))
}

/// Runs `problem` from `start`, with Huber reweighting when asked.
fn solve<const N: usize, P: Problem<N>>(
    problem: &P,
    start: P::State,
    points: &[P3],
    robust: Robust,
) -> Result<(lsq::Solution<P::State, N>, Option<RobustInfo>), FitError> {
    let fail = |f: Failure| match f {
        Failure::NotConverged { trials } => {
            FitError::NotConverged(format!("the fit did not converge in {trials} Levenberg-Marquardt trials"))
        }
        Failure::Diverged => FitError::NotConverged("the fit diverged (singular normal equations)".into()),
    };
    let mut sol = lsq::minimise(problem, start, points, None).map_err(fail)?;
    let Robust::Huber(k) = robust else { return Ok((sol, None)) };
    let mut iterations = sol.iterations;
    let mut weights = vec![1.0; points.len()];
    let mut info = RobustInfo::huber(0.0, 0, 0);
    for round in 1..=HUBER_ROUNDS {
        let res: Vec<f64> = points.iter().map(|x| problem.eval(&sol.state, x).0).collect();
        let mut abs: Vec<f64> = res.iter().map(|r| r.abs()).collect();
        abs.sort_by(f64::total_cmp);
        let scale = 1.4826 * abs[abs.len() / 2];
        let c = k * scale;
        let mut change: f64 = 0.0;
        for (w, r) in weights.iter_mut().zip(&res) {
            let nw = if c > 0.0 && r.abs() > c { c / r.abs() } else { 1.0 };
            change = change.max((nw - *w).abs());
            *w = nw;
        }
        info = RobustInfo::huber(scale, weights.iter().filter(|&&w| w < 1.0).count(), round);
        if change <= HUBER_WEIGHT_TOL && round > 1 {
            break;
        }
        sol = lsq::minimise(problem, sol.state, points, Some(&weights)).map_err(fail)?;
        iterations += sol.iterations;
    }
    sol.iterations = iterations;
    Ok((sol, Some(info)))
}

/// Most Huber reweighting rounds.
const HUBER_ROUNDS: usize = 50;
/// Reweighting stops when no weight changes by more than this.
const HUBER_WEIGHT_TOL: f64 = 1e-9;

/// Residual figures and uncertainties at a solution (unweighted).
fn summarise<const N: usize, P: Problem<N>>(
    problem: &P,
    state: &P::State,
    points: &[P3],
    names: [&'static str; N],
    values: [Option<f64>; N],
    opts: &Options,
) -> (f64, f64, usize, Vec<Param>, Vec<&'static str>) {
    let normal = lsq::normal(problem, state, points, None);
    let mut largest = 0.0;
    let mut at = 0;
    for (i, x) in points.iter().enumerate() {
        let r = problem.eval(state, x).0;
        if r.abs() > f64::abs(largest) {
            largest = r;
            at = i;
        }
    }
    let rms = (normal.cost / points.len() as f64).sqrt();
    let unc = lsq::uncertainty(&normal, points.len());
    let params: Vec<Param> = (0..N)
        .map(|k| Param { name: names[k], value: values[k], u: unc.u[k], amplification: unc.amplification[k] })
        .collect();
    let poor = params
        .iter()
        .filter(|p| p.amplification.is_nan() || p.amplification > opts.max_amplification)
        .map(|p| p.name)
        .collect();
    (rms, largest, at, params, poor)
}

/// Sphere: state `(cx, cy, cz, r)`; a radius beyond `largest_radius` has run off.
struct SphereProblem {
    largest_radius: f64,
}

impl Problem<4> for SphereProblem {
    type State = Vector4<f64>;

    fn eval(&self, s: &Vector4<f64>, x: &P3) -> (f64, SVector<f64, 4>) {
        let d = V3::new(x.x - s[0], x.y - s[1], x.z - s[2]);
        let dist = d.norm();
        let g = if dist > 0.0 { -d / dist } else { V3::zeros() };
        (dist - s[3], Vector4::new(g.x, g.y, g.z, -1.0))
    }

    fn retract(&self, s: &Vector4<f64>, delta: &SVector<f64, 4>) -> Vector4<f64> {
        s + delta
    }

    fn scale(&self, s: &Vector4<f64>) -> f64 {
        s.xyz().norm() + s[3].abs()
    }

    fn runaway(&self, s: &Vector4<f64>) -> bool {
        s[3].abs() > self.largest_radius
    }
}

/// The algebraic sphere: least squares of `|x|² = 2c·x + k` about the centroid.
pub fn algebraic_sphere(points: &[P3], centroid: &P3) -> Option<(P3, f64)> {
    let mut a = Matrix4::zeros();
    let mut b = Vector4::zeros();
    for p in points {
        let y = p - centroid;
        let row = Vector4::new(2.0 * y.x, 2.0 * y.y, 2.0 * y.z, 1.0);
        a.syger(1.0, &row, &row, 1.0);
        b += row * y.norm_squared();
    }
    a.fill_upper_triangle_with_lower_triangle();
    let sol = a.lu().solve(&b)?;
    let c = V3::new(sol[0], sol[1], sol[2]);
    let r2 = sol[3] + c.norm_squared();
    (r2 > 0.0 && r2.is_finite()).then(|| (centroid + c, r2.sqrt()))
}

fn fit_sphere(points: &[P3], opts: &Options, spread: &Spread) -> Result<Fit, FitError> {
    let (c, r) = algebraic_sphere(points, &spread.centroid)
        .ok_or_else(|| FitError::Undetermined("the points determine no sphere (algebraic fit is singular)".into()))?;
    let problem = SphereProblem { largest_radius: DIVERGENCE_FACTOR * spread.sigma[2] };
    let (sol, robust) = solve(&problem, Vector4::new(c.x, c.y, c.z, r), points, opts.robust)?;
    let s = sol.state;
    if s[3] > DIVERGENCE_FACTOR * spread.sigma[2] || s[3] <= 0.0 {
        return Err(FitError::NotConverged(format!(
            "the sphere's radius ran off to {:.6e} mm: the points are nearly on a plane",
            s[3]
        )));
    }
    let (rms, largest, at, params, poor) = summarise(
        &problem,
        &s,
        points,
        ["cx", "cy", "cz", "radius"],
        [Some(s[0]), Some(s[1]), Some(s[2]), Some(s[3])],
        opts,
    );
    Ok(Fit {
        shape: Shape::Sphere { centre: [s[0], s[1], s[2]], radius: s[3] },
        points: points.len(),
        rms,
        largest_residual: largest,
        largest_residual_index: at,
        out_of_plane_rms: None,
        iterations: sol.iterations,
        parameters: params,
        poorly_determined: poor,
        robust,
    })
}

/// A radius beyond this many standard deviations of the points' spread means a diverging fit.
const DIVERGENCE_FACTOR: f64 = 1e5;

/// Plane: state (point, unit normal); local parameters (offset along the normal, tilt towards
/// `u`, tilt towards `v`).
struct PlaneProblem;

#[derive(Clone, Debug)]
struct PlaneState {
    point: P3,
    n: V3,
    u: V3,
    v: V3,
}

impl PlaneState {
    fn new(point: P3, n: V3) -> PlaneState {
        let n = canonical(n.normalize());
        let (u, v) = basis(&n);
        PlaneState { point, n, u, v }
    }
}

impl Problem<3> for PlaneProblem {
    type State = PlaneState;

    fn eval(&self, s: &PlaneState, x: &P3) -> (f64, SVector<f64, 3>) {
        let d = x - s.point;
        (s.n.dot(&d), SVector::<f64, 3>::new(-1.0, s.u.dot(&d), s.v.dot(&d)))
    }

    fn retract(&self, s: &PlaneState, delta: &SVector<f64, 3>) -> PlaneState {
        PlaneState::new(s.point + s.n * delta[0], s.n + s.u * delta[1] + s.v * delta[2])
    }

    fn scale(&self, s: &PlaneState) -> f64 {
        s.point.coords.norm()
    }
}

fn plane_start(spread: &Spread) -> PlaneState {
    PlaneState::new(spread.centroid, spread.dirs.column(0).into_owned())
}

fn fit_plane(points: &[P3], opts: &Options, spread: &Spread) -> Result<Fit, FitError> {
    let (sol, robust) = solve(&PlaneProblem, plane_start(spread), points, opts.robust)?;
    let s = sol.state;
    let (rms, largest, at, params, poor) =
        summarise(&PlaneProblem, &s, points, ["offset", "tilt_u", "tilt_v"], [None, None, None], opts);
    Ok(Fit {
        shape: Shape::Plane { point: s.point.coords.into(), normal: s.n.into() },
        points: points.len(),
        rms,
        largest_residual: largest,
        largest_residual_index: at,
        out_of_plane_rms: None,
        iterations: sol.iterations,
        parameters: params,
        poorly_determined: poor,
        robust,
    })
}

/// Circle in its plane's coordinates (points given as `(u, v, 0)`): state `(a, b, r)`; a radius
/// beyond `largest_radius` has run off.
struct CircleProblem {
    largest_radius: f64,
}

impl Problem<3> for CircleProblem {
    type State = SVector<f64, 3>;

    fn eval(&self, s: &SVector<f64, 3>, x: &P3) -> (f64, SVector<f64, 3>) {
        let (dx, dy) = (x.x - s[0], x.y - s[1]);
        let dist = dx.hypot(dy);
        let (gx, gy) = if dist > 0.0 { (-dx / dist, -dy / dist) } else { (0.0, 0.0) };
        (dist - s[2], SVector::<f64, 3>::new(gx, gy, -1.0))
    }

    fn retract(&self, s: &SVector<f64, 3>, delta: &SVector<f64, 3>) -> SVector<f64, 3> {
        s + delta
    }

    fn scale(&self, s: &SVector<f64, 3>) -> f64 {
        s.norm()
    }

    fn runaway(&self, s: &SVector<f64, 3>) -> bool {
        s[2].abs() > self.largest_radius
    }
}

/// The algebraic (Kåsa) circle of 2D points `(x, y)`: centre and radius.
fn algebraic_circle(points: &[P3]) -> Option<(f64, f64, f64)> {
    let mut a = Matrix3::zeros();
    let mut b = V3::zeros();
    for p in points {
        let row = V3::new(2.0 * p.x, 2.0 * p.y, 1.0);
        a.syger(1.0, &row, &row, 1.0);
        b += row * (p.x * p.x + p.y * p.y);
    }
    a.fill_upper_triangle_with_lower_triangle();
    let s = a.lu().solve(&b)?;
    let r2 = s[2] + s[0] * s[0] + s[1] * s[1];
    (r2 > 0.0 && r2.is_finite()).then(|| (s[0], s[1], r2.sqrt()))
}

fn fit_circle(points: &[P3], opts: &Options, spread: &Spread) -> Result<Fit, FitError> {
    let plane = lsq::minimise(&PlaneProblem, plane_start(spread), points, None)
        .map_err(|_| FitError::NotConverged("the circle's plane did not converge".into()))?
        .state;
    let local: Vec<P3> = points
        .iter()
        .map(|p| {
            let d = p - plane.point;
            P3::new(plane.u.dot(&d), plane.v.dot(&d), 0.0)
        })
        .collect();
    let (a, b, r) = algebraic_circle(&local)
        .ok_or_else(|| FitError::Undetermined("the points determine no circle (algebraic fit is singular)".into()))?;
    let problem = CircleProblem { largest_radius: DIVERGENCE_FACTOR * spread.sigma[2] };
    let (sol, robust) = solve(&problem, SVector::<f64, 3>::new(a, b, r), &local, opts.robust)?;
    let s = sol.state;
    if s[2] > DIVERGENCE_FACTOR * spread.sigma[2] || s[2] <= 0.0 {
        return Err(FitError::NotConverged(format!(
            "the circle's radius ran off to {:.6e} mm: the points are nearly on a line",
            s[2]
        )));
    }
    let (rms, largest, at, params, poor) =
        summarise(&problem, &s, &local, ["centre_u", "centre_v", "radius"], [None, None, Some(s[2])], opts);
    let centre = plane.point + plane.u * s[0] + plane.v * s[1];
    let flat =
        (points.iter().map(|p| plane.n.dot(&(p - plane.point)).powi(2)).sum::<f64>() / points.len() as f64).sqrt();
    Ok(Fit {
        shape: Shape::Circle { centre: centre.coords.into(), normal: plane.n.into(), radius: s[2] },
        points: points.len(),
        rms,
        largest_residual: largest,
        largest_residual_index: at,
        out_of_plane_rms: Some(flat),
        iterations: sol.iterations,
        parameters: params,
        poorly_determined: poor,
        robust,
    })
}

/// Cylinder in Forbes' local parameterisation: the state is a point `o` on the axis, a rotation
/// `q` whose third column is the axis, and the radius; the local parameters move the axis point
/// across the axis (`x0, y0`), tilt the axis (`α, β`) and change the radius; a radius beyond
/// `largest_radius` has run off.
struct CylinderProblem {
    centroid: P3,
    largest_radius: f64,
}

#[derive(Clone, Debug)]
struct CylState {
    o: P3,
    q: Matrix3<f64>,
    r: f64,
}

impl CylState {
    fn new(o: P3, w: V3, r: f64) -> CylState {
        let w = canonical(w.normalize());
        let (u, v) = basis(&w);
        CylState { o, q: Matrix3::from_columns(&[u, v, w]), r }
    }

    fn axis(&self) -> V3 {
        self.q.column(2).into_owned()
    }
}

impl Problem<5> for CylinderProblem {
    type State = CylState;

    fn eval(&self, s: &CylState, x: &P3) -> (f64, SVector<f64, 5>) {
        let y = s.q.transpose() * (x - s.o);
        let rho = y.x.hypot(y.y);
        let (cx, cy) = if rho > 0.0 { (y.x / rho, y.y / rho) } else { (0.0, 0.0) };
        (rho - s.r, SVector::<f64, 5>::from([-cx, -cy, -cx * y.z, -cy * y.z, -1.0]))
    }

    fn retract(&self, s: &CylState, d: &SVector<f64, 5>) -> CylState {
        let o = s.o + s.q * V3::new(d[0], d[1], 0.0);
        let w = s.q * V3::new(d[2], d[3], 1.0).normalize();
        let o = o + w * w.dot(&(self.centroid - o));
        CylState::new(o, w, s.r + d[4])
    }

    fn scale(&self, s: &CylState) -> f64 {
        s.o.coords.norm() + s.r.abs()
    }

    fn runaway(&self, s: &CylState) -> bool {
        s.r.abs() > self.largest_radius
    }
}

fn fit_cylinder(points: &[P3], opts: &Options, spread: &Spread) -> Result<Fit, FitError> {
    let problem = CylinderProblem { centroid: spread.centroid, largest_radius: DIVERGENCE_FACTOR * spread.sigma[2] };
    let mut best: Option<(f64, lsq::Solution<CylState, 5>, Option<RobustInfo>)> = None;
    let mut last_err = None;
    // Start from each principal direction: the axis of a long cylinder is the largest, of a
    // short one (a disc-like band) the smallest.
    for k in [2, 0, 1] {
        let w: V3 = spread.dirs.column(k).into_owned();
        let (u, v) = basis(&w);
        let local: Vec<P3> = points
            .iter()
            .map(|p| {
                let d = p - spread.centroid;
                P3::new(u.dot(&d), v.dot(&d), 0.0)
            })
            .collect();
        let Some((a, b, r)) = algebraic_circle(&local) else { continue };
        let start = CylState::new(spread.centroid + u * a + v * b, w, r);
        match solve(&problem, start, points, opts.robust) {
            Ok((sol, info)) => {
                let cost = lsq::normal(&problem, &sol.state, points, None).cost;
                if sol.state.r > 0.0
                    && sol.state.r < DIVERGENCE_FACTOR * spread.sigma[2]
                    && best.as_ref().is_none_or(|(c, _, _)| cost < *c)
                {
                    best = Some((cost, sol, info));
                }
            }
            Err(e) => last_err = Some(e),
        }
    }
    let Some((_, sol, robust)) = best else {
        return Err(last_err.unwrap_or_else(|| FitError::Undetermined("the points determine no cylinder".into())));
    };
    let s = sol.state;
    let (rms, largest, at, params, poor) = summarise(
        &problem,
        &s,
        points,
        ["axis_u", "axis_v", "tilt_u", "tilt_v", "radius"],
        [None, None, None, None, Some(s.r)],
        opts,
    );
    Ok(Fit {
        shape: Shape::Cylinder { point: s.o.coords.into(), axis: s.axis().into(), radius: s.r },
        points: points.len(),
        rms,
        largest_residual: largest,
        largest_residual_index: at,
        out_of_plane_rms: None,
        iterations: sol.iterations,
        parameters: params,
        poorly_determined: poor,
        robust,
    })
}
