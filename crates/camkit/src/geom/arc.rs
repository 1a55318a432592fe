//! Circular arcs in a plane: centre, radius, start angle and signed sweep.

use super::{P2, V2, cross2};
use std::f64::consts::{PI, TAU};

/// A circular arc: points `c + r·(cos φ, sin φ)` for φ from `start` through `start + sweep`.
/// A positive sweep runs counter-clockwise (G3 in its plane), a negative one clockwise (G2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arc2 {
    /// Centre.
    pub c: P2,
    /// Radius (> 0).
    pub r: f64,
    /// Angle of the start point from the centre, radians.
    pub start: f64,
    /// Signed angle swept, radians, |sweep| ≤ 2π.
    pub sweep: f64,
}

/// Angle of `v` in (−π, π].
pub fn angle_of(v: &V2) -> f64 {
    v.y.atan2(v.x)
}

/// Signed angle from `a` to `b` in (−π, π].
pub fn angle_between(a: &V2, b: &V2) -> f64 {
    cross2(a, b).atan2(a.dot(b))
}

impl Arc2 {
    /// The arc about `c` from `p0` to `p1` turning counter-clockwise if `ccw`. The radius is the
    /// mean of the two end radii. Coincident ends give a full circle when `full_if_closed`, an
    /// empty arc otherwise.
    pub fn from_centre(c: P2, p0: &P2, p1: &P2, ccw: bool, full_if_closed: bool) -> Arc2 {
        let v0 = p0 - c;
        let v1 = p1 - c;
        let r = 0.5 * (v0.norm() + v1.norm());
        let start = angle_of(&v0);
        let mut sweep = angle_between(&v0, &v1);
        if ccw {
            if sweep < 0.0 || (sweep == 0.0 && full_if_closed) {
                sweep += TAU;
            }
        } else if sweep > 0.0 || (sweep == 0.0 && full_if_closed) {
            sweep -= TAU;
        }
        Arc2 { c, r, start, sweep }
    }

    /// The arc through three points in order, or `None` if they are collinear or coincide.
    pub fn through(p0: &P2, pm: &P2, p1: &P2) -> Option<Arc2> {
        let c = super::circle::circumcentre(p0, pm, p1)?;
        let ccw = cross2(&(pm - p0), &(p1 - pm)) > 0.0;
        Some(Arc2::from_centre(c, p0, p1, ccw, false))
    }

    /// True if the arc turns counter-clockwise.
    pub fn ccw(&self) -> bool {
        self.sweep > 0.0
    }

    /// Point at angle `phi`.
    pub fn point_at(&self, phi: f64) -> P2 {
        self.c + self.r * V2::new(phi.cos(), phi.sin())
    }

    /// Start point.
    pub fn start_point(&self) -> P2 {
        self.point_at(self.start)
    }

    /// End point.
    pub fn end_point(&self) -> P2 {
        self.point_at(self.start + self.sweep)
    }

    /// Point at fraction `t` ∈ [0, 1] of the sweep.
    pub fn point_at_fraction(&self, t: f64) -> P2 {
        self.point_at(self.start + t * self.sweep)
    }

    /// Arc length.
    pub fn length(&self) -> f64 {
        self.r * self.sweep.abs()
    }

    /// How far along the sweep (radians, in the sweep's direction, in [0, 2π)) the direction
    /// `phi` lies from the start.
    pub fn progress(&self, phi: f64) -> f64 {
        let d = if self.sweep >= 0.0 { phi - self.start } else { self.start - phi };
        d.rem_euclid(TAU)
    }

    /// True if the ray from the centre at angle `phi` meets the arc.
    pub fn spans(&self, phi: f64) -> bool {
        self.progress(phi) <= self.sweep.abs()
    }

    /// Unit tangent in the direction of travel at angle `phi`.
    pub fn tangent_at(&self, phi: f64) -> V2 {
        let t = V2::new(-phi.sin(), phi.cos());
        if self.ccw() { t } else { -t }
    }

    /// The sagitta: largest distance between the arc and its chord (for |sweep| ≤ π).
    pub fn sagitta(&self) -> f64 {
        let half = 0.5 * self.sweep.abs().min(PI);
        self.r * (1.0 - half.cos())
    }
}

/// An arc made ready for many distance queries: its ends and their directions from the centre,
/// so that whether a direction lies within the sweep is told by cross products, not angles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedArc {
    /// Centre.
    pub c: P2,
    /// Radius.
    pub r: f64,
    /// Start and end points.
    pub ends: (P2, P2),
    /// Unit directions from the centre to the start and the end, in counter-clockwise order
    /// (swapped for a clockwise arc).
    dirs: (V2, V2),
    /// The counter-clockwise sweep from `dirs.0` to `dirs.1` (radians, in (0, 2π]).
    sweep: f64,
}

impl PreparedArc {
    /// The arc prepared.
    pub fn new(arc: &Arc2) -> PreparedArc {
        let (s, e) = (arc.start_point(), arc.end_point());
        let (a, b) = (V2::new(arc.start.cos(), arc.start.sin()), {
            let t = arc.start + arc.sweep;
            V2::new(t.cos(), t.sin())
        });
        let dirs = if arc.sweep >= 0.0 { (a, b) } else { (b, a) };
        PreparedArc { c: arc.c, r: arc.r, ends: (s, e), dirs, sweep: arc.sweep.abs() }
    }

    /// True if the direction `v` from the centre meets the arc (the centre itself: true).
    pub fn spans(&self, v: &V2) -> bool {
        if self.sweep >= TAU - 1e-12 || (v.x == 0.0 && v.y == 0.0) {
            return true;
        }
        let (s, e) = self.dirs;
        if self.sweep <= PI {
            cross2(&s, v) >= 0.0 && cross2(v, &e) >= 0.0
        } else {
            // Outside only if strictly inside the complement, which is under half a turn.
            !(cross2(&e, v) > 0.0 && cross2(v, &s) > 0.0)
        }
    }

    /// Distance from `p` to the arc, exactly (as `geom::dist::point_arc`, without angles).
    pub fn distance(&self, p: &P2) -> f64 {
        let v = p - self.c;
        if self.spans(&v) { (v.norm() - self.r).abs() } else { (p - self.ends.0).norm().min((p - self.ends.1).norm()) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The prepared distance is the angle-based one, for arcs of every sweep both ways round and
    /// points everywhere (centre, ends, beyond).
    #[test]
    fn prepared_distance_is_the_exact_one() {
        let mut k = 0u64;
        let mut rand = || {
            k = k.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (k >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let arc = Arc2 {
                c: P2::new(1.0, -2.0),
                r: 0.5 + 3.0 * rand(),
                start: 7.0 * rand() - 3.5,
                sweep: (2.0 * rand() - 1.0) * TAU,
            };
            let prepared = PreparedArc::new(&arc);
            for _ in 0..20 {
                let p = P2::new(1.0 + 10.0 * rand() - 5.0, -2.0 + 10.0 * rand() - 5.0);
                let exact = crate::geom::dist::point_arc(&p, &arc);
                assert!((prepared.distance(&p) - exact).abs() < 1e-12, "{arc:?} {p:?}");
            }
            assert_eq!(prepared.distance(&arc.c), arc.r);
        }
    }

    #[test]
    fn quarter_circle() {
        let a = Arc2::from_centre(P2::origin(), &P2::new(1.0, 0.0), &P2::new(0.0, 1.0), true, false);
        assert!((a.sweep - PI / 2.0).abs() < 1e-15);
        assert!((a.length() - PI / 2.0).abs() < 1e-15);
        assert!(a.spans(PI / 4.0));
        assert!(!a.spans(-PI / 4.0));
        let cw = Arc2::from_centre(P2::origin(), &P2::new(1.0, 0.0), &P2::new(0.0, 1.0), false, false);
        assert!((cw.sweep + 1.5 * PI).abs() < 1e-15);
        assert!(cw.spans(-PI / 4.0));
        assert!(!cw.spans(PI / 4.0));
        let full = Arc2::from_centre(P2::origin(), &P2::new(1.0, 0.0), &P2::new(1.0, 0.0), true, true);
        assert!((full.sweep - TAU).abs() < 1e-15);
    }

    #[test]
    fn through_three_points() {
        let a = Arc2::through(&P2::new(2.0, 1.0), &P2::new(1.0, 2.0), &P2::new(0.0, 1.0)).unwrap();
        assert!((a.c - P2::new(1.0, 1.0)).norm() < 1e-15);
        assert!((a.r - 1.0).abs() < 1e-15);
        assert!(a.ccw());
        assert!((a.end_point() - P2::new(0.0, 1.0)).norm() < 1e-15);
        assert!(Arc2::through(&P2::new(0.0, 0.0), &P2::new(1.0, 1.0), &P2::new(2.0, 2.0)).is_none());
    }
}
