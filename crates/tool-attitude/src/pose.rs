//! Tool poses from one contact: the cylindrical non-rotating tool tilted toward the feed
//! (paper 000 §3.2(1), fig. 6), the ball end mill with a tilt (paper 003 §3.1) and the flat end
//! mill along the normal with its machine angles (paper 002 §4.2, eq. 3–4).

use camkit::geom::{P3, V3};

/// Where a tool stands: tip, unit axis (tip towards the spindle) and, for a non-rotating tool,
/// the unit direction its cutting edge faces (perpendicular to the axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Tool tip (mm): the bottom-face centre of a cylinder or flat end mill, the lowest point of
    /// a ball end mill, the edge tip P2 of the flat-type tool.
    pub tip: P3,
    /// Unit tool axis.
    pub axis: V3,
    /// Unit direction the edge faces (non-rotating tools).
    pub edge: Option<V3>,
}

impl Pose {
    /// Spindle orientation (degrees) of the edge about the axis, in the convention of
    /// `post-6axis` (`camkit::kinematics::edge_angle`).
    pub fn spindle(&self) -> Option<f64> {
        self.edge.map(|e| camkit::kinematics::edge_angle(&self.axis, &e))
    }
}

/// The feed direction made tangent at a contact of unit normal `n`: the feed component
/// perpendicular to the normal; `None` when the feed runs along the normal.
pub fn tangent_feed(n: &V3, feed: &V3) -> Option<V3> {
    (feed - n * n.dot(feed)).try_normalize(camkit::tol::LENGTH_EPS)
}

/// The cylindrical non-rotating tool of radius `r` cutting at `p` (unit normal `n`, unit
/// tangent feed `f`) with tilt `theta` (radians; the paper's sign: negative leans the axis
/// toward the feed, so the rim's lowest point is at the front and the bottom face clears the
/// cut surface by |θ|). The axis is `n` turned by |θ| in the plane of `n` and `f`; the tip
/// (bottom-face centre) lies R behind `p` perpendicular to the axis in that plane; the edge
/// faces the feed.
pub fn cylinder(p: &P3, n: &V3, f: &V3, r: f64, theta: f64) -> Pose {
    let (s, c) = theta.sin_cos();
    let axis = n * c - f * s;
    let edge = f * c + n * s;
    Pose { tip: p - edge * r, axis, edge: Some(edge) }
}

/// The ball end mill of radius `r` touching at `p` (unit normal `n`): the ball centre is
/// `p + r·n` whatever the axis; the axis is `n` tilted by `zeta` (radians) toward `dir` (a unit
/// tangent: the feed for a lead angle, across it for paper 003's side tilt); tip = centre − r·axis.
pub fn ball(p: &P3, n: &V3, dir: &V3, r: f64, zeta: f64) -> Pose {
    let (s, c) = zeta.sin_cos();
    let axis = n * c + dir * s;
    let centre = p + n * r;
    Pose { tip: centre - axis * r, axis, edge: None }
}

/// The flat end mill along the normal: axis = `n`, tip at the contact point (paper 002 §4.2).
pub fn flat_mill(p: &P3, n: &V3) -> Pose {
    Pose { tip: *p, axis: *n, edge: None }
}

/// Paper 002 eq. (3)–(4): the table angles [a, c] (degrees) of an A/C machine that bring the
/// tool axis (u, v, w) to the spindle: a = atan(√(u²+v²)/w), c = atan(u/v), with quadrants.
pub fn machine_angles(axis: &V3) -> (f64, f64) {
    let (u, v, w) = (axis.x, axis.y, axis.z);
    let a = u.hypot(v).atan2(w).to_degrees();
    let c = if u.hypot(v) <= camkit::tol::LENGTH_EPS { 0.0 } else { u.atan2(v).to_degrees() };
    (a, c)
}

/// Feed directions of one pass from its consecutive positions: central differences inside, one
/// sided at the ends. `Err(i)` names the first row where consecutive positions coincide (no
/// direction); a pass of one row has none (`Err(0)`).
pub fn feed_directions(points: &[P3]) -> Result<Vec<V3>, usize> {
    let n = points.len();
    if n < 2 {
        return Err(0);
    }
    let step = |i: usize| (points[i + 1] - points[i]).try_normalize(camkit::tol::LENGTH_EPS).ok_or(i + 1);
    let steps: Vec<V3> = (0..n - 1).map(step).collect::<Result<_, _>>()?;
    Ok((0..n)
        .map(|i| match i {
            0 => steps[0],
            i if i == n - 1 => steps[n - 2],
            i => (steps[i - 1] + steps[i]).try_normalize(camkit::tol::LENGTH_EPS).unwrap_or(steps[i]),
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn machine_angles_eq_3_4() {
        assert_eq!(machine_angles(&V3::z()), (0.0, 0.0));
        let (a, c) = machine_angles(&V3::new(0.0, 1.0, 1.0).normalize());
        assert!((a - 45.0).abs() < 1e-12 && c.abs() < 1e-12);
        let (a, c) = machine_angles(&V3::new(1.0, 0.0, 0.0));
        assert!((a - 90.0).abs() < 1e-12 && (c - 90.0).abs() < 1e-12);
    }

    #[test]
    fn feed_needs_two_distinct_points() {
        assert_eq!(feed_directions(&[P3::origin()]), Err(0));
        assert_eq!(feed_directions(&[P3::origin(), P3::new(1.0, 0.0, 0.0), P3::new(1.0, 0.0, 0.0)]), Err(2));
        let f = feed_directions(&[P3::origin(), P3::new(1.0, 0.0, 0.0), P3::new(1.0, 1.0, 0.0)]).unwrap();
        assert!((f[1] - V3::new(1.0, 1.0, 0.0).normalize()).norm() < 1e-15);
    }

    #[test]
    fn cylinder_on_plane_closed_form() {
        // Plane z = 0, feed +x, θ = −5°: axis leans 5° toward +x, tip R·sin5° above the plane,
        // R·cos5° behind the cutting point; the edge faces the feed (s = 0 for a near-vertical axis).
        let th = (-5f64).to_radians();
        let pose = cylinder(&P3::origin(), &V3::z(), &V3::x(), 12.5, th);
        let a = 5f64.to_radians();
        assert!((pose.axis - V3::new(a.sin(), 0.0, a.cos())).norm() < 1e-15);
        assert!((pose.tip - P3::new(-12.5 * a.cos(), 0.0, 12.5 * a.sin())).norm() < 1e-12);
        assert!(pose.spindle().unwrap().abs() < 1e-9);
    }
}
