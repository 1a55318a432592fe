//! Surfaces of revolution (STEP's SURFACE_OF_REVOLUTION): a profile curve in a half-plane
//! through the z axis swept about it, S(u, v) = Rz(u)·C(v) with C(v) = (ρ(v), 0, z(v)), ρ ≥ 0.
//!
//! The nearest point reduces exactly to the profile's in the half-plane through the query point
//! and the axis: |Rz(u)·C − q|² = ρ² + ρq² − 2ρρq·cos(u − θq) + (z − zq)² is least at u = θq for
//! every v when ρ ≥ 0, so the foot is the profile's nearest point to (ρq, 0, zq) (a bracketed
//! Newton iteration, [`super::face::EDGE_TOL`]) turned by θq.

use super::analytic::Foot;
use super::bvh::Aabb;
use super::face::{Samples, SplineCurve};
use super::patch::Derivs;
use crate::geom::{P3, V3};

/// A profile curve swept about the z axis.
#[derive(Clone, Debug)]
pub struct Revolution {
    /// The profile, in the half-plane y = 0, x ≥ 0 (x is the distance from the axis).
    profile: SplineCurve,
    /// True when the profile is a closed curve (v is then periodic).
    closed: bool,
    /// The profile's nearest-point samples over its domain, made once.
    samples: Samples,
}

impl Revolution {
    /// The surface swept by `profile`, whose control points lie in the half-plane y = 0, x ≥ 0
    /// (the caller has checked it); `closed` when the profile's ends meet.
    pub fn new(profile: SplineCurve) -> Revolution {
        let [t0, t1] = profile.domain();
        let (a, b) = (profile.eval(t0).0, profile.eval(t1).0);
        let closed = (a - b).norm() <= 1e-9 * (1.0 + a.coords.norm());
        let samples = profile.samples(t0, t1);
        Revolution { profile, closed, samples }
    }

    /// Parameter domain [u0, u1, v0, v1]: u the angle about z, v the profile's parameter.
    pub fn domain(&self) -> [f64; 4] {
        let [v0, v1] = self.profile.domain();
        [0.0, std::f64::consts::TAU, v0, v1]
    }

    /// The profile curve (x the distance from the axis, y = 0).
    pub fn profile(&self) -> &SplineCurve {
        &self.profile
    }

    /// True when the profile is closed (v periodic with the domain's length).
    pub fn closed(&self) -> bool {
        self.closed
    }

    /// Point and derivatives at (u, v).
    pub fn eval(&self, u: f64, v: f64) -> Derivs {
        let (c, c1, c2) = self.profile.eval(v);
        let (s, k) = u.sin_cos();
        let (r, r1, r2) = (c.x, c1.x, c2.x);
        Derivs {
            s: P3::new(r * k, r * s, c.z),
            su: V3::new(-r * s, r * k, 0.0),
            sv: V3::new(r1 * k, r1 * s, c1.z),
            suu: V3::new(-r * k, -r * s, 0.0),
            suv: V3::new(-r1 * s, r1 * k, 0.0),
            svv: V3::new(r2 * k, r2 * s, c2.z),
        }
    }

    /// Point at (u, v): bit for bit `eval(u, v).s`, without the derivatives.
    pub fn point(&self, u: f64, v: f64) -> P3 {
        let c = self.profile.point(v);
        let (s, k) = u.sin_cos();
        P3::new(c.x * k, c.x * s, c.z)
    }

    /// Unit normal at (u, v): the direction of Su × Sv = ρ·(z′ cos u, z′ sin u, −ρ′), taken from
    /// the profile's tangent so that it stays defined on the axis.
    pub fn normal(&self, u: f64, v: f64) -> Option<V3> {
        let (_, c1, _) = self.profile.eval(v);
        V3::new(c1.z * u.cos(), c1.z * u.sin(), -c1.x).try_normalize(crate::tol::LENGTH_EPS)
    }

    /// A box holding the surface: the profile's control points' reach from the axis and heights.
    pub fn bounds(&self) -> Aabb {
        let b = Aabb::of(&self.profile.ctrl);
        let r = self.profile.ctrl.iter().map(|p| p.x.abs()).fold(0.0, f64::max);
        Aabb { min: P3::new(-r, -r, b.min.z), max: P3::new(r, r, b.max.z) }
    }

    /// The nearest point to `q` no farther than `bound`: foot, (u, v) and whether the profile's
    /// iteration converged.
    pub fn nearest(&self, q: &P3, bound: f64) -> Option<(Foot, [f64; 2], bool)> {
        let rho = q.x.hypot(q.y);
        let u = if rho > 0.0 { q.y.atan2(q.x) } else { 0.0 };
        let (v, converged) = self.profile.nearest_in(&P3::new(rho, 0.0, q.z), &self.samples);
        let d = self.eval(u, v);
        if (d.s - q).norm() > bound {
            return None;
        }
        let normal =
            self.normal(u, v).unwrap_or_else(|| (q - d.s).try_normalize(crate::tol::LENGTH_EPS).unwrap_or(V3::z()));
        Some((Foot { point: d.s, normal }, [u, v], converged))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_1_SQRT_2;

    /// A quarter of the circle of radius 5 about (20, 0, 15) as a rational quadratic, from
    /// (25, 0, 15) to (20, 0, 20): swept about z it is a quarter of a torus.
    fn torus_quarter() -> Revolution {
        Revolution::new(SplineCurve {
            degree: 2,
            ctrl: vec![P3::new(25.0, 0.0, 15.0), P3::new(25.0, 0.0, 20.0), P3::new(20.0, 0.0, 20.0)],
            weights: Some(vec![1.0, FRAC_1_SQRT_2, 1.0]),
            knots: vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        })
    }

    #[test]
    fn swept_arc_is_the_torus() {
        let s = torus_quarter();
        assert!(!s.closed());
        for (x, y, z) in [(30.0, 4.0, 19.0), (-15.0, 18.0, 22.0), (0.5, -27.0, 16.0), (22.0, 1.0, 16.5)] {
            let q = P3::new(x, y, z);
            let (f, uv, ok) = s.nearest(&q, f64::INFINITY).unwrap();
            let rho = x.hypot(y);
            let want = (rho - 20.0).hypot(z - 15.0) - 5.0;
            assert!(ok && ((f.point - q).norm() - want.abs()).abs() < 1e-9, "{q}: {} vs {want}", (f.point - q).norm());
            let tube = P3::new(20.0 * x / rho, 20.0 * y / rho, 15.0);
            assert!((f.normal - (f.point - tube) / 5.0).norm() < 1e-9, "{q}: {}", f.normal);
            assert!((s.eval(uv[0], uv[1]).s - f.point).norm() < 1e-12);
        }
        for k in 0..=200 {
            let (u, v) = (k as f64 * 0.071 - 7.0, k as f64 / 200.0);
            assert_eq!(s.point(u, v), s.eval(u, v).s, "({u}, {v})");
        }
        // Below the quarter the end circle ρ = 25, z = 15 is nearest.
        let (f, _, _) = s.nearest(&P3::new(0.0, 30.0, 10.0), f64::INFINITY).unwrap();
        assert!((f.point - P3::new(0.0, 25.0, 15.0)).norm() < 1e-12, "{}", f.point);
        assert!(s.nearest(&P3::new(0.0, 30.0, 10.0), 5.0).is_none());
    }

    #[test]
    fn derivatives_match_differences() {
        let s = torus_quarter();
        let (u, v) = (0.7, 0.37);
        Derivs::assert_match_differences(|u, v| s.eval(u, v), u, v);
        let d = s.eval(u, v);
        let n = s.normal(u, v).unwrap();
        assert!((n - d.su.cross(&d.sv).normalize()).norm() < 1e-12);
    }
}
