//! Material that no finite convex shape holds, measured in closed form: everything outside a
//! sphere (a spherical cavity) or outside an unbounded cylinder (a bore). A convex body cuts into
//! such material by the largest distance of its points from the centre or the axis, less the
//! radius; a distance to a point or a line is convex, so that largest distance is reached at the
//! body's extreme points: a capsule's two end centres (plus its radius), a cylinder's two rim
//! circles (rounded ones: the circles of the rounding's centres, plus the corner radius), a
//! wedge's three corners.

use crate::geom::{P3, V3};
use crate::model::analytic::any_perpendicular;

/// Material outside a sphere or an unbounded cylinder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hollow {
    /// Everything farther than `radius` from `centre` (a sphere with its normal flipped).
    Cavity {
        /// Centre (mm).
        centre: P3,
        /// Radius (mm).
        radius: f64,
    },
    /// Everything farther than `radius` from the line through `point` along unit `axis` (an
    /// unbounded cylinder with its normal flipped).
    Bore {
        /// A point of the axis.
        point: P3,
        /// Unit axis.
        axis: V3,
        /// Radius (mm).
        radius: f64,
    },
}

/// An extreme part of a convex body, in model coordinates, with the radius of the rounding that
/// surrounds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Extreme {
    /// A point, surrounded by a ball of `pad`.
    Point {
        /// The point.
        at: P3,
        /// Radius of the ball round it.
        pad: f64,
    },
    /// A circle of `radius` about `centre` in the plane normal to unit `normal`, surrounded by a
    /// tube of `pad`.
    Circle {
        /// Centre.
        centre: P3,
        /// Unit normal of its plane.
        normal: V3,
        /// Radius.
        radius: f64,
        /// Radius of the tube round it.
        pad: f64,
    },
}

impl Hollow {
    /// Signed clearance (mm) of a convex body given by its extreme parts: the radius less the
    /// largest distance of the body from the centre or axis (negative: the depth it cuts in).
    pub fn clearance(&self, extremes: &[Extreme]) -> f64 {
        let (radius, far) = match *self {
            Hollow::Cavity { centre, radius } => {
                (radius, extremes.iter().map(|e| farthest_from_point(e, &centre)).fold(f64::NEG_INFINITY, f64::max))
            }
            Hollow::Bore { point, axis, radius } => (
                radius,
                extremes.iter().map(|e| farthest_from_line(e, &point, &axis)).fold(f64::NEG_INFINITY, f64::max),
            ),
        };
        radius - far
    }
}

/// Largest distance from `c` of the points of an extreme part and its rounding: closed form (the
/// circle's point opposite `c`'s foot on its plane).
fn farthest_from_point(e: &Extreme, c: &P3) -> f64 {
    match *e {
        Extreme::Point { at, pad } => (at - c).norm() + pad,
        Extreme::Circle { centre, normal, radius, pad } => {
            let w = c - centre;
            let h = w.dot(&normal);
            let across = (w - normal * h).norm();
            h.hypot(across + radius) + pad
        }
    }
}

/// Samples round a circle before each local maximum of the distance to a line is refined: the
/// squared distance is a trigonometric polynomial of degree 2 (at most two maxima), so every
/// maximum lies in a bracket of samples that rises to it.
const CIRCLE_SAMPLES: usize = 360;

/// Largest distance from the line through `p` along unit `e` of the points of an extreme part and
/// its rounding. On a circle: every local maximum of the squared distance among
/// [`CIRCLE_SAMPLES`] samples refined by golden-section search to round-off.
fn farthest_from_line(x: &Extreme, p: &P3, e: &V3) -> f64 {
    let off = |q: &P3| {
        let w = q - p;
        (w - e * w.dot(e)).norm_squared()
    };
    match *x {
        Extreme::Point { at, pad } => off(&at).sqrt() + pad,
        Extreme::Circle { centre, normal, radius, pad } => {
            let u = any_perpendicular(&normal);
            let v = normal.cross(&u);
            let g = |t: f64| off(&(centre + (u * t.cos() + v * t.sin()) * radius));
            let h = std::f64::consts::TAU / CIRCLE_SAMPLES as f64;
            let s: Vec<f64> = (0..CIRCLE_SAMPLES).map(|k| g(h * k as f64)).collect();
            let mut best = s.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            for k in 0..CIRCLE_SAMPLES {
                let (prev, next) = (s[(k + CIRCLE_SAMPLES - 1) % CIRCLE_SAMPLES], s[(k + 1) % CIRCLE_SAMPLES]);
                if s[k] >= prev && s[k] >= next {
                    best = best.max(golden_max(&g, h * (k as f64 - 1.0), h * (k as f64 + 1.0)));
                }
            }
            best.max(0.0).sqrt() + pad
        }
    }
}

/// The largest value of `g` on `[a, b]`, where it rises to one maximum and falls (golden
/// section to the interval's round-off).
fn golden_max(g: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    g(crate::num::golden_arg(g, a, b, 80))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circles_in_a_cavity_and_a_bore() {
        // A circle of radius 3 about (1, 0, 2) normal z: farthest from the origin at (4, 0, 2).
        let c = Extreme::Circle { centre: P3::new(1.0, 0.0, 2.0), normal: V3::z(), radius: 3.0, pad: 0.5 };
        let cav = Hollow::Cavity { centre: P3::origin(), radius: 10.0 };
        assert!((cav.clearance(&[c]) - (10.0 - 20f64.sqrt() - 0.5)).abs() < 1e-12);
        // The same circle in a bore along x through the origin: farthest (y, z) = (±3, 2).
        let bore = Hollow::Bore { point: P3::origin(), axis: V3::x(), radius: 10.0 };
        assert!((bore.clearance(&[c]) - (10.0 - 13f64.sqrt() - 0.5)).abs() < 1e-12, "{}", bore.clearance(&[c]));
        // Tilted circle against a bore along z: dense sampling agrees.
        let n = V3::new(0.3, -0.5, 0.8).normalize();
        let c = Extreme::Circle { centre: P3::new(2.0, 1.0, 0.0), normal: n, radius: 4.0, pad: 0.0 };
        let bore = Hollow::Bore { point: P3::new(0.5, 0.0, 0.0), axis: V3::z(), radius: 20.0 };
        let u = any_perpendicular(&n);
        let v = n.cross(&u);
        let dense = (0..200_000)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / 200_000.0;
                let q = P3::new(2.0, 1.0, 0.0) + (u * t.cos() + v * t.sin()) * 4.0;
                (q.x - 0.5).hypot(q.y)
            })
            .fold(0.0, f64::max);
        assert!((bore.clearance(&[c]) - (20.0 - dense)).abs() < 1e-9);
    }
}
