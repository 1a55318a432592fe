//! A laser displacement sensor simulator: the beam leaves the sensor's reference point (its "tool
//! tip") along the negative tool axis; the reading is the distance to the surface, with noise and
//! a systematic error that grows with the incidence angle between the beam and the surface normal
//! (paper 002 §3: a 3-axis scan errs on slopes, a measurement along the normal does not).

use crate::rng::Rng;
use crate::shapes::Shape;
use camkit::geom::{P3, V3};

/// The sensor's properties.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensor {
    /// Nominal distance (mm) from the reference point to the surface (middle of the range).
    pub standoff: f64,
    /// Half measuring range (mm) about the stand-off; readings outside are lost.
    pub range: f64,
    /// Standard deviation (mm) of the reading noise at normal incidence; it grows as `1/cos θ`.
    pub noise: f64,
    /// Systematic error coefficient (mm): the reading is longer by `slope_error (1/cos θ − 1)`.
    pub slope_error: f64,
    /// Largest incidence angle (degrees) that still returns a reading.
    pub max_incidence: f64,
}

impl Default for Sensor {
    fn default() -> Self {
        Sensor { standoff: 50.0, range: 40.0, noise: 0.0005, slope_error: 0.02, max_incidence: 75.0 }
    }
}

/// One simulated reading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// The distance the sensor reports (mm).
    pub value: f64,
    /// The true distance to the surface (mm).
    pub truth: f64,
    /// Incidence angle (degrees).
    pub incidence: f64,
}

/// Distance along the ray `o + t d` (t > 0) to the first hit of the element's surface, with the
/// outward normal there. Circles are not surfaces: `None`.
pub fn intersect(shape: &Shape, o: &P3, d: &V3) -> Option<(f64, V3)> {
    let first_root = |a: f64, b: f64, c: f64| -> Option<f64> {
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 || a == 0.0 {
            return None;
        }
        let q = -0.5 * (b + b.signum() * disc.sqrt());
        let (t1, t2) = (q / a, c / q);
        let (lo, hi) = if t1 < t2 { (t1, t2) } else { (t2, t1) };
        if lo > 0.0 {
            Some(lo)
        } else if hi > 0.0 {
            Some(hi)
        } else {
            None
        }
    };
    let t = match shape {
        Shape::Sphere { centre, radius } => {
            let m = o - P3::from(*centre);
            first_root(d.norm_squared(), 2.0 * m.dot(d), m.norm_squared() - radius * radius)?
        }
        Shape::Plane { point, normal } => {
            let n = V3::from(*normal);
            let den = n.dot(d);
            let t = n.dot(&(P3::from(*point) - o)) / den;
            (den != 0.0 && t > 0.0).then_some(t)?
        }
        Shape::Cylinder { point, axis, radius } => {
            let w = V3::from(*axis);
            let m = o - P3::from(*point);
            let (mp, dp) = (m - w * w.dot(&m), d - w * w.dot(d));
            first_root(dp.norm_squared(), 2.0 * mp.dot(&dp), mp.norm_squared() - radius * radius)?
        }
        Shape::Circle { .. } => return None,
    };
    let hit = o + d * t;
    Some((t, shape.normal_at(&hit)))
}

impl Sensor {
    /// The reading of a sensor at `tip` with tool axis `axis` (unit; the beam runs along −axis)
    /// over `shape`, or `None` when the beam misses, the spot is lost (incidence beyond the limit)
    /// or the surface is outside the measuring range.
    pub fn read(&self, shape: &Shape, tip: &P3, axis: &V3, rng: &mut Rng) -> Option<Reading> {
        let beam = -axis.normalize();
        let (t, n) = intersect(shape, tip, &beam)?;
        let cos = (-beam).dot(&n);
        let incidence = cos.clamp(-1.0, 1.0).acos().to_degrees();
        if cos <= 0.0 || incidence > self.max_incidence || (t - self.standoff).abs() > self.range {
            return None;
        }
        let value = t + self.slope_error * (1.0 / cos - 1.0) + self.noise / cos * rng.normal();
        Some(Reading { value, truth: t, incidence })
    }
}

/// The measured point of a reading: `tip − reading · axis`.
pub fn point_of(tip: &P3, axis: &V3, reading: f64) -> P3 {
    tip - axis.normalize() * reading
}
