//! Geometry on nalgebra: points, planes of circular motion, lines and arcs, exact distances and
//! circle fits.

pub mod arc;
pub mod circle;
pub mod dist;

pub use arc::Arc2;

/// A point in the plane (mm).
pub type P2 = nalgebra::Point2<f64>;
/// A vector in the plane.
pub type V2 = nalgebra::Vector2<f64>;
/// A point in space (mm).
pub type P3 = nalgebra::Point3<f64>;
/// A vector in space.
pub type V3 = nalgebra::Vector3<f64>;

/// The plane a circular move lies in, as G17/G18/G19 select it.
///
/// Each plane has in-plane coordinates (u, v) and the axis w along its normal, ordered so that
/// (u, v, w) is right-handed and counter-clockwise in (u, v) is G3: XY → (x, y, z),
/// XZ → (z, x, y), YZ → (y, z, x), as RS274 defines the arc sense of G18 and G19.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Plane {
    /// G17.
    #[default]
    Xy,
    /// G18.
    Xz,
    /// G19.
    Yz,
}

impl Plane {
    /// Indices of (u, v, w) in (x, y, z).
    #[inline]
    pub fn axes(self) -> [usize; 3] {
        match self {
            Plane::Xy => [0, 1, 2],
            Plane::Xz => [2, 0, 1],
            Plane::Yz => [1, 2, 0],
        }
    }

    /// The in-plane point of `p` and its coordinate along the plane's normal.
    #[inline]
    pub fn split(self, p: &P3) -> (P2, f64) {
        match self {
            Plane::Xy => (P2::new(p.x, p.y), p.z),
            Plane::Xz => (P2::new(p.z, p.x), p.y),
            Plane::Yz => (P2::new(p.y, p.z), p.x),
        }
    }

    /// The point with in-plane position `q` and normal coordinate `w`.
    #[inline]
    pub fn join(self, q: &P2, w: f64) -> P3 {
        let [iu, iv, iw] = self.axes();
        let mut p = P3::origin();
        p[iu] = q.x;
        p[iv] = q.y;
        p[iw] = w;
        p
    }

    /// Name used in tables and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Plane::Xy => "xy",
            Plane::Xz => "xz",
            Plane::Yz => "yz",
        }
    }

    /// Parses `xy`, `xz`, `yz` (also `zx`, `zy` and `g17`..`g19`).
    pub fn parse(text: &str) -> Option<Plane> {
        match text.trim().to_ascii_lowercase().as_str() {
            "xy" | "yx" | "g17" => Some(Plane::Xy),
            "xz" | "zx" | "g18" => Some(Plane::Xz),
            "yz" | "zy" | "g19" => Some(Plane::Yz),
            _ => None,
        }
    }

    /// The G code selecting this plane (17, 18, 19).
    pub fn gcode(self) -> u8 {
        match self {
            Plane::Xy => 17,
            Plane::Xz => 18,
            Plane::Yz => 19,
        }
    }
}

/// A rectangle in XY (mm), spelt `X0,X1,Y0,Y1` on every command line ([`crate::cli::region`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// Smallest x.
    pub x0: f64,
    /// Largest x.
    pub x1: f64,
    /// Smallest y.
    pub y0: f64,
    /// Largest y.
    pub y1: f64,
}

impl Region {
    /// True if `p`'s XY lies within the rectangle grown by `margin`.
    pub fn contains_within(&self, p: &P3, margin: f64) -> bool {
        p.x >= self.x0 - margin && p.x <= self.x1 + margin && p.y >= self.y0 - margin && p.y <= self.y1 + margin
    }
}

/// Cross product z-component of two plane vectors (positive when `b` is counter-clockwise of `a`).
pub fn cross2(a: &V2, b: &V2) -> f64 {
    a.x * b.y - a.y * b.x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planes_round_trip_and_are_right_handed() {
        let p = P3::new(1.0, 2.0, 3.0);
        for plane in [Plane::Xy, Plane::Xz, Plane::Yz] {
            let (q, w) = plane.split(&p);
            assert_eq!(plane.join(&q, w), p);
            // u × v = w for the unit vectors of the plane's axes.
            let [u, v, w] = plane.axes();
            let e = |i: usize| V3::from_fn(|k, _| if k == i { 1.0 } else { 0.0 });
            assert_eq!(e(u).cross(&e(v)), e(w));
            assert_eq!(Plane::parse(plane.name()), Some(plane));
        }
    }
}
