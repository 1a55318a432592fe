//! Analytic surfaces and their exact nearest points: plane, sphere, cylinder, cone, torus. Each
//! surface of revolution reduces to a 2D problem in the half-plane through its axis and the query
//! point, solved in closed form.

use super::bvh::Aabb;
use crate::geom::{P3, V3};

/// The foot of the perpendicular from a query point: the nearest point and the outward normal
/// there (before any flip).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Foot {
    /// Nearest point of the surface.
    pub point: P3,
    /// Unit outward normal at that point.
    pub normal: V3,
}

/// An analytic surface in its own placement.
#[derive(Clone, Debug, PartialEq)]
pub enum Analytic {
    /// Unbounded plane through `point` with unit `normal`.
    Plane {
        /// A point of the plane.
        point: P3,
        /// Unit outward normal.
        normal: V3,
    },
    /// Sphere.
    Sphere {
        /// Centre.
        centre: P3,
        /// Radius.
        radius: f64,
    },
    /// Lateral surface of a circular cylinder, between `from` and `to` along the unit `axis`
    /// from `point` (infinite values for an unbounded one).
    Cylinder {
        /// A point of the axis.
        point: P3,
        /// Unit axis.
        axis: V3,
        /// Radius.
        radius: f64,
        /// Axial start.
        from: f64,
        /// Axial end.
        to: f64,
    },
    /// Lateral surface of a cone with apex `apex`, unit `axis`, half angle `half_angle`
    /// (radians), between `from` and `to` along the axis.
    Cone {
        /// Apex.
        apex: P3,
        /// Unit axis (the cone opens along it).
        axis: V3,
        /// Half angle (radians).
        half_angle: f64,
        /// Axial start (≥ 0).
        from: f64,
        /// Axial end.
        to: f64,
    },
    /// Torus around the unit `axis` through `centre`.
    Torus {
        /// Centre.
        centre: P3,
        /// Unit axis.
        axis: V3,
        /// Radius of the tube's centre circle.
        major: f64,
        /// Radius of the tube.
        minor: f64,
    },
}

/// A unit vector perpendicular to the unit vector `a`.
pub fn any_perpendicular(a: &V3) -> V3 {
    let helper = if a.x.abs() < 0.9 { V3::x() } else { V3::y() };
    a.cross(&helper).normalize()
}

/// Splits `q − origin` into the axial coordinate along unit `axis` and the radial unit vector
/// and distance (an arbitrary radial direction on the axis).
fn cylindrical(q: &P3, origin: &P3, axis: &V3) -> (f64, V3, f64) {
    let d = q - origin;
    let h = d.dot(axis);
    let radial = d - axis * h;
    let rho = radial.norm();
    let e = if rho > crate::tol::LENGTH_EPS { radial / rho } else { any_perpendicular(axis) };
    (h, e, rho)
}

/// Nearest point of the segment from `a` to `b` in the plane to `p`.
fn segment_foot(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    let t = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0);
    [a[0] + t * d[0], a[1] + t * d[1]]
}

impl Analytic {
    /// The exact nearest point of the surface to `q` and the outward normal there.
    pub fn foot(&self, q: &P3) -> Foot {
        match *self {
            Analytic::Plane { point, normal } => Foot { point: q - normal * (q - point).dot(&normal), normal },
            Analytic::Sphere { centre, radius } => {
                let d = q - centre;
                let n = d.norm();
                let normal = if n > crate::tol::LENGTH_EPS { d / n } else { V3::z() };
                Foot { point: centre + normal * radius, normal }
            }
            Analytic::Cylinder { point, axis, radius, from, to } => {
                let (h, e, _) = cylindrical(q, &point, &axis);
                Foot { point: point + axis * h.clamp(from, to) + e * radius, normal: e }
            }
            Analytic::Cone { apex, axis, half_angle, from, to } => {
                let (h, e, rho) = cylindrical(q, &apex, &axis);
                let t = half_angle.tan();
                let [fh, fr] = segment_foot([h, rho], [from, from * t], [to, to * t]);
                let (s, c) = half_angle.sin_cos();
                Foot { point: apex + axis * fh + e * fr, normal: e * c - axis * s }
            }
            Analytic::Torus { centre, axis, major, minor } => {
                let (_, e, _) = cylindrical(q, &centre, &axis);
                // The tube's circle on this side of the axis, and on the far side (nearer only for
                // points inside a self-intersecting torus).
                let mut best: Option<(f64, Foot)> = None;
                for side in [1.0, -1.0] {
                    let c = centre + e * (major * side);
                    let d = q - c;
                    let n = d.norm();
                    let normal = if n > crate::tol::LENGTH_EPS { d / n } else { axis };
                    let foot = Foot { point: c + normal * minor, normal };
                    let dist = (foot.point - q).norm();
                    if best.as_ref().is_none_or(|(b, _)| dist < *b) {
                        best = Some((dist, foot));
                    }
                }
                best.map(|(_, f)| f).unwrap_or(Foot { point: *q, normal: axis })
            }
        }
    }

    /// A box holding the surface (all space for unbounded ones).
    pub fn bounds(&self) -> Aabb {
        // Half-extents of a circle of radius r around the unit axis a: r·sqrt(1 − a_i²).
        let circle = |c: P3, a: &V3, r: f64| {
            let ext = V3::from_fn(|i, _| r * (1.0 - a[i] * a[i]).max(0.0).sqrt());
            Aabb { min: c - ext, max: c + ext }
        };
        match *self {
            Analytic::Plane { .. } => Aabb::everything(),
            Analytic::Sphere { centre, radius } => {
                Aabb { min: centre - V3::repeat(radius), max: centre + V3::repeat(radius) }
            }
            Analytic::Cylinder { point, axis, radius, from, to } => {
                if from.is_finite() && to.is_finite() {
                    circle(point + axis * from, &axis, radius).union(&circle(point + axis * to, &axis, radius))
                } else {
                    Aabb::everything()
                }
            }
            Analytic::Cone { apex, axis, half_angle, from, to } => {
                let t = half_angle.tan();
                circle(apex + axis * from, &axis, from * t).union(&circle(apex + axis * to, &axis, to * t))
            }
            Analytic::Torus { centre, axis, major, minor } => circle(centre, &axis, major).inflate(minor),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The foot is on the surface, the normal is unit, and `q` lies along the normal from it.
    fn check(s: &Analytic, q: P3, on_surface: impl Fn(&P3) -> f64) {
        let f = s.foot(&q);
        assert!(on_surface(&f.point).abs() < 1e-12, "{s:?} {q} → {:?}", f.point);
        assert!((f.normal.norm() - 1.0).abs() < 1e-12);
        let d = q - f.point;
        assert!(d.cross(&f.normal).norm() < 1e-9 * (1.0 + d.norm()), "{s:?}: {q} not along the normal");
    }

    #[test]
    fn feet_are_on_the_surface_along_the_normal() {
        let sphere = Analytic::Sphere { centre: P3::new(1.0, 2.0, 3.0), radius: 5.0 };
        check(&sphere, P3::new(4.0, -1.0, 9.0), |p| (p - P3::new(1.0, 2.0, 3.0)).norm() - 5.0);
        let axis = V3::new(1.0, 1.0, 0.5).normalize();
        let cyl = Analytic::Cylinder { point: P3::origin(), axis, radius: 2.0, from: -1e9, to: 1e9 };
        check(&cyl, P3::new(3.0, -2.0, 1.0), |p| (p.coords - axis * p.coords.dot(&axis)).norm() - 2.0);
        let torus = Analytic::Torus { centre: P3::origin(), axis: V3::z(), major: 10.0, minor: 3.0 };
        let on_torus = |p: &P3| (p.x.hypot(p.y) - 10.0).hypot(p.z) - 3.0;
        check(&torus, P3::new(12.0, 5.0, 1.0), on_torus);
        check(&torus, P3::new(1.0, 0.5, -0.2), on_torus);
        let cone = Analytic::Cone { apex: P3::origin(), axis: V3::z(), half_angle: 0.5, from: 0.0, to: 20.0 };
        let on_cone = |p: &P3| p.x.hypot(p.y) - p.z * 0.5f64.tan();
        check(&cone, P3::new(10.0, 3.0, 4.0), on_cone);
        check(&cone, P3::new(0.5, 0.1, 8.0), on_cone);
        // Beyond the cone's end the nearest point is on its rim.
        let f = cone.foot(&P3::new(0.0, 30.0, 40.0));
        assert!((f.point.z - 20.0).abs() < 1e-12);
    }
}
