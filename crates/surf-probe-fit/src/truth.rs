//! A fitted element against the true one (`fit --truth`): errors that mean something for its kind.
//! A sphere or circle has a centre to compare; a cylinder's axis point and a plane's point are
//! anywhere along the axis or in the plane, so comparing them as points reports a distance
//! between unrelated points. A cylinder is compared by the distance of its axis line from the
//! true one and the angle between them, a plane by its offset from the true plane and the angle
//! between the normals.

use crate::shapes::Shape;
use camkit::geom::{P3, V3};

/// Errors of a fit as named report keys (mm, degrees), in a fixed order.
pub fn errors(got: &Shape, truth: &Shape) -> Result<Vec<(&'static str, f64)>, String> {
    let angle = |a: &[f64; 3], b: &[f64; 3]| line_angle(&V3::from(*a), &V3::from(*b));
    Ok(match (got, truth) {
        (Shape::Sphere { centre: c, radius: r }, Shape::Sphere { centre: c0, radius: r0 }) => {
            vec![("origin_error_mm", (P3::from(*c) - P3::from(*c0)).norm()), ("radius_error_mm", r - r0)]
        }
        (Shape::Circle { centre: c, normal: n, radius: r }, Shape::Circle { centre: c0, normal: n0, radius: r0 }) => {
            vec![
                ("origin_error_mm", (P3::from(*c) - P3::from(*c0)).norm()),
                ("radius_error_mm", r - r0),
                ("normal_angle_deg", angle(n, n0)),
            ]
        }
        (Shape::Cylinder { point: p, axis: a, radius: r }, Shape::Cylinder { point: p0, axis: a0, radius: r0 }) => {
            // The fitted axis point is the one nearest the points' centroid: the distance of the
            // true axis there.
            let d = P3::from(*p) - P3::from(*p0);
            let a0 = V3::from(*a0).normalize();
            vec![
                ("axis_distance_mm", (d - a0 * a0.dot(&d)).norm()),
                ("axis_angle_deg", angle(a, &a0.into())),
                ("radius_error_mm", r - r0),
            ]
        }
        (Shape::Plane { point: p, normal: n }, Shape::Plane { point: p0, normal: n0 }) => {
            // The fitted point is the points' centroid: the true plane's offset there.
            let n0v = V3::from(*n0).normalize();
            vec![("plane_offset_mm", n0v.dot(&(P3::from(*p) - P3::from(*p0)))), ("normal_angle_deg", angle(n, n0))]
        }
        _ => return Err(format!("the true element is a {}, the fit a {}", name(truth), name(got))),
    })
}

/// Angle (degrees, 0 to 90) between two lines of directions `a` and `b` (either sign).
fn line_angle(a: &V3, b: &V3) -> f64 {
    let (a, b) = (a.normalize(), b.normalize());
    // atan2 of sine and cosine stays accurate for tiny angles, where acos does not.
    a.cross(&b).norm().atan2(a.dot(&b).abs()).to_degrees()
}

fn name(s: &Shape) -> &'static str {
    match s {
        Shape::Sphere { .. } => "sphere",
        Shape::Plane { .. } => "plane",
        Shape::Circle { .. } => "circle",
        Shape::Cylinder { .. } => "cylinder",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_and_plane_compare_lines_and_planes_not_points() {
        let axis = V3::new(0.0, 0.3, 0.9).normalize();
        let truth = Shape::Cylinder { point: [5.0, 5.0, 0.0], axis: axis.into(), radius: 20.0 };
        // The same cylinder described by another point of its axis.
        let p = P3::new(5.0, 5.0, 0.0) + axis * 37.0;
        let got = Shape::Cylinder { point: p.coords.into(), axis: (-axis).into(), radius: 20.0 };
        for (k, v) in errors(&got, &truth).unwrap() {
            assert!(v.abs() < 1e-12, "{k} = {v}");
        }
        let n = V3::new(0.1, -0.2, 1.0).normalize();
        let truth = Shape::Plane { point: [0.0, 0.0, 1.0], normal: n.into() };
        let q = P3::new(0.0, 0.0, 1.0) + n.cross(&V3::x()) * 10.0 + n * 0.25;
        let got = Shape::Plane { point: q.coords.into(), normal: n.into() };
        let e = errors(&got, &truth).unwrap();
        assert!((e[0].1 - 0.25).abs() < 1e-12 && e[1].1.abs() < 1e-12, "{e:?}");
        let sphere = Shape::Sphere { centre: [0.0; 3], radius: 1.0 };
        assert!(errors(&sphere, &truth).is_err());
    }
}
