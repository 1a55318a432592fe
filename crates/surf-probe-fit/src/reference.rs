//! Reference data with a known least-squares solution, made the ISO 10360-6 way: points on the
//! true element displaced along its normals by residuals projected onto the null space of the
//! normal equations (for a sphere `Σeᵢ = 0` and `Σeᵢnᵢ = 0`), so the true parameters are the exact
//! geometric least-squares answer.

use crate::rng::Rng;
use crate::shapes::{Shape, basis};
use camkit::geom::{P3, V3};
use nalgebra::DMatrix;

/// What to generate.
#[derive(Clone, Debug, PartialEq)]
pub struct Spec {
    /// The true element (its parameters are the least-squares solution of the set).
    pub shape: Shape,
    /// Number of points.
    pub points: usize,
    /// Residuals are drawn uniformly in ±`amplitude` (mm) before projection.
    pub amplitude: f64,
    /// Sphere: half-angle (degrees) of the cap about +Z the points cover (180 = full sphere).
    /// Cylinder: length (mm) of the measured band. Plane: half-width (mm) of the square patch.
    /// Circle: the arc (degrees) covered.
    pub extent: f64,
    /// Random seed.
    pub seed: u64,
}

/// Points and the residual each carries.
#[derive(Clone, Debug, PartialEq)]
pub struct Set {
    /// Points.
    pub points: Vec<P3>,
    /// The residual of each point from the true element (after projection).
    pub residuals: Vec<f64>,
}

/// Generates the set. Each point is `foot + eᵢ nᵢ` where `foot` lies on the true element and
/// `nᵢ` is its normal there; the rows of the constraint matrix are the gradients of the distance
/// with respect to the element's parameters, written from the geometry here.
pub fn generate(spec: &Spec) -> Set {
    let mut rng = Rng::new(spec.seed);
    let mut feet = Vec::with_capacity(spec.points);
    let mut normals = Vec::with_capacity(spec.points);
    let mut rows: Vec<Vec<f64>> = Vec::with_capacity(spec.points);
    match &spec.shape {
        Shape::Sphere { centre, radius } => {
            let c = P3::from(*centre);
            let cos_max = spec.extent.to_radians().cos();
            for _ in 0..spec.points {
                let ct = rng.range(cos_max, 1.0);
                let st = (1.0 - ct * ct).max(0.0).sqrt();
                let phi = rng.range(0.0, std::f64::consts::TAU);
                let n = V3::new(st * phi.cos(), st * phi.sin(), ct);
                feet.push(c + n * *radius);
                normals.push(n);
                rows.push(vec![1.0, n.x, n.y, n.z]);
            }
        }
        Shape::Plane { point, normal } => {
            let n = V3::from(*normal).normalize();
            let (u, v) = basis(&n);
            for _ in 0..spec.points {
                let (s, t) = (rng.range(-spec.extent, spec.extent), rng.range(-spec.extent, spec.extent));
                feet.push(P3::from(*point) + u * s + v * t);
                normals.push(n);
                rows.push(vec![1.0, s, t]);
            }
        }
        Shape::Circle { centre, normal, radius } => {
            let n = V3::from(*normal).normalize();
            let (u, v) = basis(&n);
            for _ in 0..spec.points {
                let phi = rng.range(0.0, spec.extent.to_radians());
                let radial = u * phi.cos() + v * phi.sin();
                feet.push(P3::from(*centre) + radial * *radius);
                normals.push(radial);
                rows.push(vec![1.0, phi.cos(), phi.sin()]);
            }
        }
        Shape::Cylinder { point, axis, radius } => {
            let w = V3::from(*axis).normalize();
            let (u, v) = basis(&w);
            for _ in 0..spec.points {
                let phi = rng.range(0.0, std::f64::consts::TAU);
                let z = rng.range(-spec.extent / 2.0, spec.extent / 2.0);
                let (c, s) = (phi.cos(), phi.sin());
                feet.push(P3::from(*point) + w * z + (u * c + v * s) * *radius);
                normals.push(u * c + v * s);
                rows.push(vec![1.0, c, s, z * c, z * s]);
            }
        }
    }
    let p = rows[0].len();
    let a = DMatrix::from_fn(p, spec.points, |i, j| rows[j][i]);
    let e0 = nalgebra::DVector::from_fn(spec.points, |_, _| rng.range(-spec.amplitude, spec.amplitude));
    // e = e0 − Aᵀ (A Aᵀ)⁻¹ A e0: the part of e0 orthogonal to every parameter's gradient.
    let aat = &a * a.transpose();
    let y = aat.lu().solve(&(&a * &e0)).unwrap_or_else(|| nalgebra::DVector::zeros(p));
    let e = e0 - a.transpose() * y;
    let points = feet.iter().zip(&normals).zip(e.iter()).map(|((f, n), e)| f + n * *e).collect();
    Set { points, residuals: e.iter().copied().collect() }
}
