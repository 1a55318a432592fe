//! Named tolerances and fuzzy comparisons: the only place epsilons are written down.
//!
//! Every comparison that needs slack uses one of these names, so a reader can see what a
//! tolerance protects against and a change to it happens in one place.

/// Two positions closer than this (mm) are the same point: repeated points are dropped.
pub const POINT_EPS: f64 = 1e-9;

/// Lengths below this (mm) are zero: degenerate segments, zero vectors.
pub const LENGTH_EPS: f64 = 1e-12;

/// Angles below this (radians) are zero: parallel directions, full circles.
pub const ANGLE_EPS: f64 = 1e-12;

/// A direction read from input is accepted as a unit vector if its length is within this of 1;
/// it is then normalised (with a warning where the filter says so).
pub const UNIT_VECTOR_SLACK: f64 = 1e-3;

/// Relative slack for floating-point round-off when a computed figure is checked against a
/// promised bound (e.g. a deviation against `--tol`): `bound * (1 + ROUNDOFF_REL)`.
pub const ROUNDOFF_REL: f64 = 1e-9;

/// Absolute slack (mm) for round-off in distance checks at the scale of a machine (≤ 10 m).
pub const ROUNDOFF_ABS: f64 = 1e-9;

/// Largest accepted error (mm) of a verified offset: every output point lies within this of the
/// offset distance from the input, none closer than the distance minus this.
pub const OFFSET_TOL: f64 = 1e-6;

/// Repeated points and collinear runs within this (mm) are merged when an offset retries on a
/// cleaned input; the result is still verified against the original.
pub const CLEAN_EPS: f64 = 1e-9;

/// Largest difference (mm) between an input arc's start and end radius about its centre that a
/// reader accepts; the arc is then taken through both ends with its sweep.
pub const ARC_END_MISMATCH: f64 = 1e-3;

/// A point set whose smallest principal spread (standard deviation) is below this fraction of its
/// largest lies on one plane (or, for the middle spread, one line): an element it cannot
/// determine (a sphere from coplanar points) is refused instead of fitted.
pub const DEGENERATE_SPREAD_REL: f64 = 1e-9;

/// Largest gap (mm) between the ends of two DXF entities that `dxf::read` joins into one contour
/// (CAD exports leave round-off gaps of this order; the later piece's start is kept).
pub const DXF_JOIN: f64 = 1e-4;

/// Default largest distance (mm) between a drawing's curve (an SVG Bézier or elliptical arc, a
/// DXF ELLIPSE or SPLINE) and the lines and arcs it is read as (`--curve-tol`).
pub const CURVE_TOL: f64 = 1e-3;

/// `a` and `b` differ by at most `eps`.
pub fn near(a: f64, b: f64, eps: f64) -> bool {
    (a - b).abs() <= eps
}

/// `a` and `b` differ by at most `rel` relative to the larger magnitude (or `rel` absolutely
/// when both are below 1).
pub fn near_rel(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1.0)
}

/// A measured `value` does not exceed a promised `bound`, allowing only floating-point round-off.
pub fn within(value: f64, bound: f64) -> bool {
    value <= bound * (1.0 + ROUNDOFF_REL) + ROUNDOFF_ABS
}

/// `x` is zero to within [`LENGTH_EPS`].
pub fn is_zero_length(x: f64) -> bool {
    x.abs() <= LENGTH_EPS
}

/// Largest coordinate (mm) a table may hold: beyond it a double's spacing (1.2e-7 mm at 1e9) nears
/// the micrometre tolerances the filters promise.
pub const COORD_LIMIT: f64 = 1e9;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comparisons() {
        assert!(near(1.0, 1.0 + 5e-10, POINT_EPS));
        assert!(!near(1.0, 1.0 + 2e-9, POINT_EPS));
        assert!(near_rel(1e6, 1e6 + 0.5, 1e-6));
        assert!(!near_rel(1e6, 1e6 + 2.0, 1e-6));
        assert!(within(0.01, 0.01));
        assert!(!within(0.010001, 0.01));
        assert!(is_zero_length(1e-13));
        assert!(!is_zero_length(1e-11));
    }
}
