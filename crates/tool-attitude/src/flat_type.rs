//! The flat-type non-rotating tool (paper 000 §3.2(2), fig. 7–10): the edge tip P2 sits at the
//! stylus centre touching both surfaces of a concave corner; the basic axis is the bisector of
//! the two normals; the axis is then turned about the corner line until the control stylus at
//! P1 (or P3), a flank length from P2 along the edge, touches its surface too, so that flank lies
//! on the surface (offset by the stylus radius r). The second flank stands off the other surface
//! by the model's corner angle less the tool's included angle (the paper grinds it 5° smaller).

use crate::pose::Pose;
use camkit::geom::{P3, V3};

/// One two-surface contact as `stylus-trace --mode two-surface` writes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corner {
    /// Stylus centre = edge tip P2.
    pub centre: P3,
    /// Contact and unit normal on the control surface (the flank that is made to lie on it).
    pub control: (P3, V3),
    /// Unit normal of the other surface.
    pub other: V3,
}

/// The tool's edge: included angle between the flanks (radians) and flank length P2→P1 (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Edge {
    /// Included angle β.
    pub included: f64,
    /// Distance from P2 to the control point.
    pub flank: f64,
}

/// A solved flat-type pose and its figures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlatPose {
    /// Tip P2, axis, and the direction the cutting face looks (the feed).
    pub pose: Pose,
    /// Turn of the control flank from the control surface's tangent (radians, positive away from
    /// it) that brings the control stylus onto the surface.
    pub correction: f64,
    /// The model's corner angle between the surfaces in the section (radians).
    pub corner_angle: f64,
    /// Angle by which the second flank stands off its surface (radians; negative cuts into it).
    pub flank_gap: f64,
    /// Control point P1 (or P3).
    pub control_point: P3,
}

/// Why a corner has no pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FlatError {
    /// The two normals are parallel: no corner line.
    NoCorner,
    /// The control stylus could not be brought onto its surface.
    NoContact,
}

/// Solves the pose at `c` for feed `feed` (any vector along the corner line's direction of
/// travel). `distance_to_control(q)` is the distance from q to the control surface (the model's
/// nearest-point query); `None` uses the tangent plane at the control contact (no correction).
pub fn solve(
    c: &Corner,
    edge: &Edge,
    feed: &V3,
    distance_to_control: Option<&dyn Fn(&P3) -> f64>,
) -> Result<FlatPose, FlatError> {
    let (pc, nc) = c.control;
    let line = nc.cross(&c.other).try_normalize(1e-9).ok_or(FlatError::NoCorner)?;
    // Section basis: e0 along the control surface away from the other one, nc out of it.
    let e0 = (c.other - nc * nc.dot(&c.other)).try_normalize(1e-9).ok_or(FlatError::NoCorner)?;
    let other_dir = (nc - c.other * c.other.dot(&nc)).normalize();
    let corner_angle = e0.dot(&other_dir).clamp(-1.0, 1.0).acos();
    let r = (c.centre - pc).norm();
    let flank_at = |d: f64| e0 * d.cos() + nc * d.sin();
    let mut delta = 0.0;
    if let Some(dist) = distance_to_control {
        // Secant on g(δ) = |P1(δ) − surface| − r; g is smooth and nearly linear in δ.
        let g = |d: f64| dist(&(c.centre + flank_at(d) * edge.flank)) - r;
        let (mut d0, mut g0) = (0.0, g(0.0));
        let mut d1 = if g0 > 0.0 { -1e-4 } else { 1e-4 };
        let mut g1 = g(d1);
        let mut done = g0.abs() <= CONTROL_TOL;
        for _ in 0..60 {
            if done {
                break;
            }
            if (g1 - g0).abs() < f64::MIN_POSITIVE {
                return Err(FlatError::NoContact);
            }
            let d2 = d1 - g1 * (d1 - d0) / (g1 - g0);
            (d0, g0) = (d1, g1);
            d1 = d2.clamp(-1.0, 1.0);
            g1 = g(d1);
            done = g1.abs() <= CONTROL_TOL;
        }
        if !done {
            return Err(FlatError::NoContact);
        }
        delta = if g0.abs() <= CONTROL_TOL && g0.abs() < g1.abs() { d0 } else { d1 };
    }
    let flank = flank_at(delta);
    let up = nc * delta.cos() - e0 * delta.sin();
    let half = edge.included / 2.0;
    let axis = flank * half.cos() + up * half.sin();
    let face = if line.dot(feed) >= 0.0 { line } else { -line };
    Ok(FlatPose {
        pose: Pose { tip: c.centre, axis, edge: Some(face) },
        correction: delta,
        corner_angle,
        flank_gap: corner_angle - edge.included - delta,
        control_point: c.centre + flank * edge.flank,
    })
}

/// The control stylus touches its surface when |distance − r| is below this (mm): the paper's
/// two-surface contact criterion, 0.1 µm.
pub const CONTROL_TOL: f64 = 1e-7;

/// Both flanks' directions of a solved pose (unit, from P2): the first toward the control point,
/// the second the included angle from it through the axis (the wedge the gouge check places).
pub fn flanks(p: &FlatPose, edge: &Edge) -> (V3, V3) {
    let a = p.pose.axis;
    let first = (p.control_point - p.pose.tip).normalize();
    // Rotate the first flank by the included angle through the axis, in the section plane.
    let w = (a - first * first.dot(&a)).normalize();
    (first, first * edge.included.cos() + w * edge.included.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Floor z = 0 and wall x = 0 (material at x < 0), stylus r = 1 in the corner, tool 85°.
    #[test]
    fn square_corner_closed_form() {
        let c = Corner { centre: P3::new(1.0, 0.0, 1.0), control: (P3::new(1.0, 0.0, 0.0), V3::z()), other: V3::x() };
        let edge = Edge { included: 85f64.to_radians(), flank: 3.0 };
        let plane = |q: &P3| q.z.abs();
        let p = solve(&c, &edge, &V3::y(), Some(&plane)).unwrap();
        assert!(p.correction.abs() < 1e-12);
        assert!((p.corner_angle - 90f64.to_radians()).abs() < 1e-12);
        assert!((p.flank_gap - 5f64.to_radians()).abs() < 1e-12);
        // Axis 42.5° up from the floor toward the wall side, i.e. leaning away from the wall.
        let h = 42.5f64.to_radians();
        assert!((p.pose.axis - V3::new(h.cos(), 0.0, h.sin())).norm() < 1e-12);
        assert!((p.control_point - P3::new(4.0, 0.0, 1.0)).norm() < 1e-12);
        assert_eq!(p.pose.edge, Some(V3::y()));
        let (first, second) = flanks(&p, &edge);
        assert!((first - V3::x()).norm() < 1e-12);
        assert!((second.dot(&V3::x()) - 85f64.to_radians().cos()).abs() < 1e-12);
    }

    /// Control surface a sphere of radius 20 under the flank: the control point touches it.
    #[test]
    fn curved_control_surface_is_touched() {
        let centre = P3::new(0.0, 0.0, -20.0);
        let dist = |q: &P3| ((q - centre).norm() - 20.0).abs();
        let pc = P3::origin();
        let c = Corner { centre: P3::new(0.0, 0.0, 1.0), control: (pc, V3::z()), other: V3::x() };
        let edge = Edge { included: 85f64.to_radians(), flank: 3.0 };
        let p = solve(&c, &edge, &V3::y(), Some(&dist)).unwrap();
        assert!((dist(&p.control_point) - 1.0).abs() <= CONTROL_TOL);
        // Closed form: P1 on the sphere of radius 21 about the centre, 3 from P2 = (0,0,1):
        // the angle at P2 below the tangent is asin(3 / (2·21)).
        let expect = -(3.0f64 / 42.0).asin();
        assert!((p.correction - expect).abs() < 1e-6, "{} vs {expect}", p.correction);
    }
}
