//! Contours of lines and arcs and their verified offsets: the machinery of contour-parallel
//! machining shared by `offset` and `medial-trochoid`.
//!
//! A [`Contour`] is a chain of vertices, each with the bulge of the piece that leaves it (0 for a
//! line, `tan(sweep/4)` for an arc, positive counter-clockwise), open or closed. Offsets are made
//! with `cavalier_contours` and never returned unverified ([`offset`]): every output piece is
//! measured against the input with the exact distances of [`crate::geom::dist`]. Closed contours
//! nest into [`region::Region`]s (an outer boundary with islands) and [`pocket`] turns regions into
//! contour-parallel passes in machining order.

pub mod curve;
pub mod load;
pub mod offset;
pub mod pocket;
pub mod region;
pub mod svg_in;
pub mod table;
mod verify;

pub use verify::SegSet;

pub use offset::{Offset, OffsetError, OffsetOptions, offset_contour, offset_region};
pub use verify::{Check, Defect};

use crate::geom::dist::{
    arc_arc_max, arc_arc_min, arc_segment_max, point_arc, point_segment, segment_arc_max, segment_arc_min,
    segment_segment_min,
};
use crate::geom::{Arc2, P2, V2, arc::angle_of, cross2};
use crate::tol;
use cavalier_contours::polyline::{PlineCreation, PlineSource, PlineSourceMut, PlineVertex, Polyline};
use std::f64::consts::{FRAC_PI_2, PI};

/// A vertex of a contour: its position and the bulge of the piece that leaves it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vertex {
    /// Position (mm).
    pub p: P2,
    /// `tan(sweep / 4)` of the arc to the next vertex (0 for a line; positive counter-clockwise).
    pub bulge: f64,
}

/// A chain of lines and arcs. A closed contour has a piece from its last vertex back to its first.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Contour {
    /// Vertices in order.
    pub vertices: Vec<Vertex>,
    /// True if the last vertex joins the first.
    pub closed: bool,
}

/// One piece of a contour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Seg {
    /// A straight piece from the first point to the second.
    Line(P2, P2),
    /// A circular piece.
    Arc(Arc2),
}

impl Seg {
    /// The piece from `p` to `q` with `bulge` (a line if the bulge is zero or the ends coincide).
    pub fn from_bulge(p: P2, q: P2, bulge: f64) -> Seg {
        let chord = q - p;
        let len = chord.norm();
        if bulge == 0.0 || len == 0.0 {
            return Seg::Line(p, q);
        }
        let sweep = 4.0 * bulge.atan();
        let m = P2::from((p.coords + q.coords) * 0.5);
        let left = V2::new(-chord.y, chord.x) / len;
        let c = m + left * (0.5 * len * (1.0 - bulge * bulge) / (2.0 * bulge));
        let r = 0.5 * ((p - c).norm() + (q - c).norm());
        Seg::Arc(Arc2 { c, r, start: angle_of(&(p - c)), sweep })
    }

    /// Bulge of this piece.
    pub fn bulge(&self) -> f64 {
        match self {
            Seg::Line(..) => 0.0,
            Seg::Arc(a) => (a.sweep / 4.0).tan(),
        }
    }

    /// Start point.
    pub fn start(&self) -> P2 {
        match self {
            Seg::Line(a, _) => *a,
            Seg::Arc(a) => a.start_point(),
        }
    }

    /// End point.
    pub fn end(&self) -> P2 {
        match self {
            Seg::Line(_, b) => *b,
            Seg::Arc(a) => a.end_point(),
        }
    }

    /// Length (mm).
    pub fn length(&self) -> f64 {
        match self {
            Seg::Line(a, b) => (b - a).norm(),
            Seg::Arc(a) => a.length(),
        }
    }

    /// Point at fraction `t` ∈ [0, 1] of the piece.
    pub fn point_at(&self, t: f64) -> P2 {
        match self {
            Seg::Line(a, b) => a + (b - a) * t,
            Seg::Arc(a) => a.point_at_fraction(t),
        }
    }

    /// Unit tangent in the direction of travel at fraction `t` (zero for a point).
    pub fn tangent_at(&self, t: f64) -> V2 {
        match self {
            Seg::Line(a, b) => (b - a).try_normalize(0.0).unwrap_or_else(V2::zeros),
            Seg::Arc(a) => a.tangent_at(a.start + t * a.sweep),
        }
    }

    /// The piece from fraction `t0` to `t1`.
    pub fn sub(&self, t0: f64, t1: f64) -> Seg {
        match self {
            Seg::Line(..) => Seg::Line(self.point_at(t0), self.point_at(t1)),
            Seg::Arc(a) => Seg::Arc(Arc2 { start: a.start + t0 * a.sweep, sweep: (t1 - t0) * a.sweep, ..*a }),
        }
    }

    /// The piece run backwards.
    pub fn reversed(&self) -> Seg {
        match self {
            Seg::Line(a, b) => Seg::Line(*b, *a),
            Seg::Arc(a) => Seg::Arc(Arc2 { start: a.start + a.sweep, sweep: -a.sweep, ..*a }),
        }
    }

    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> (P2, P2) {
        let (s, e) = (self.start(), self.end());
        let mut lo = P2::new(s.x.min(e.x), s.y.min(e.y));
        let mut hi = P2::new(s.x.max(e.x), s.y.max(e.y));
        if let Seg::Arc(a) = self {
            for k in 0..4 {
                let phi = k as f64 * FRAC_PI_2;
                if a.spans(phi) {
                    let q = a.point_at(phi);
                    lo = P2::new(lo.x.min(q.x), lo.y.min(q.y));
                    hi = P2::new(hi.x.max(q.x), hi.y.max(q.y));
                }
            }
        }
        (lo, hi)
    }

    /// Distance from `p` to the piece, exactly.
    pub fn distance_to(&self, p: &P2) -> f64 {
        match self {
            Seg::Line(a, b) => point_segment(p, a, b),
            Seg::Arc(a) => point_arc(p, a),
        }
    }

    /// Smallest distance between two pieces (0 where they meet), exactly.
    pub fn min_distance(&self, other: &Seg) -> f64 {
        match (self, other) {
            (Seg::Line(a, b), Seg::Line(c, d)) => segment_segment_min(a, b, c, d),
            (Seg::Line(a, b), Seg::Arc(q)) | (Seg::Arc(q), Seg::Line(a, b)) => segment_arc_min(a, b, q),
            (Seg::Arc(p), Seg::Arc(q)) => arc_arc_min(p, q),
        }
    }

    /// Largest distance from a point of this piece to `other` (one-sided Hausdorff), exactly.
    pub fn max_distance_to(&self, other: &Seg) -> f64 {
        match (self, other) {
            // Distance to a convex set is convex along a segment: its maximum is at an end.
            (Seg::Line(a, b), _) if matches!(other, Seg::Line(..)) => other.distance_to(a).max(other.distance_to(b)),
            (Seg::Line(a, b), Seg::Arc(q)) => segment_arc_max(a, b, q),
            (Seg::Arc(p), Seg::Line(a, b)) => arc_segment_max(p, a, b),
            (Seg::Arc(p), Seg::Arc(q)) => arc_arc_max(p, q),
            (Seg::Line(..), Seg::Line(..)) => unreachable!("handled by the first arm"),
        }
    }

    /// Where `p` lies relative to the piece near its closest point: positive on the left of the
    /// direction of travel, negative on the right, `None` when the closest point is an end (the
    /// contour's corner decides) or `p` is on the piece.
    pub fn side_of(&self, p: &P2) -> Option<f64> {
        match self {
            Seg::Line(a, b) => {
                let d = b - a;
                let len2 = d.norm_squared();
                let t = if len2 > 0.0 { (p - a).dot(&d) / len2 } else { 0.0 };
                (t > 0.0 && t < 1.0).then(|| cross2(&d, &(p - a))).filter(|s| *s != 0.0)
            }
            Seg::Arc(a) => {
                let v = p - a.c;
                let phi = angle_of(&v);
                let interior = a.spans(phi) && a.progress(phi) > 0.0 && a.progress(phi) < a.sweep.abs();
                let inside = a.r - v.norm();
                (interior && inside != 0.0).then(|| if a.ccw() { inside } else { -inside })
            }
        }
    }
}

impl Contour {
    /// A contour through `points` joined by lines.
    pub fn polygon(points: &[P2], closed: bool) -> Contour {
        Contour { vertices: points.iter().map(|&p| Vertex { p, bulge: 0.0 }).collect(), closed }
    }

    /// The contour made of `segs` laid end to end (each starts where the previous ends). A closed
    /// contour's last piece ends at its first vertex.
    pub fn from_segs(segs: &[Seg], closed: bool) -> Contour {
        let mut vertices: Vec<Vertex> = segs.iter().map(|s| Vertex { p: s.start(), bulge: s.bulge() }).collect();
        if !closed && let Some(last) = segs.last() {
            vertices.push(Vertex { p: last.end(), bulge: 0.0 });
        }
        Contour { vertices, closed }
    }

    /// A full circle as two half arcs starting at angle `start`, counter-clockwise if `ccw`.
    pub fn circle(c: P2, r: f64, start: f64, ccw: bool) -> Contour {
        let b = if ccw { 1.0 } else { -1.0 };
        let p = |phi: f64| c + r * V2::new(phi.cos(), phi.sin());
        Contour {
            vertices: vec![Vertex { p: p(start), bulge: b }, Vertex { p: p(start + PI), bulge: b }],
            closed: true,
        }
    }

    /// Number of pieces.
    pub fn seg_count(&self) -> usize {
        match self.vertices.len() {
            0 | 1 => 0,
            n if self.closed => n,
            n => n - 1,
        }
    }

    /// Piece `i` (from vertex `i` to the next).
    pub fn seg(&self, i: usize) -> Seg {
        let n = self.vertices.len();
        let v = self.vertices[i];
        Seg::from_bulge(v.p, self.vertices[(i + 1) % n].p, v.bulge)
    }

    /// The pieces in order.
    pub fn segs(&self) -> impl Iterator<Item = Seg> + '_ {
        (0..self.seg_count()).map(|i| self.seg(i))
    }

    /// Total length (mm).
    pub fn length(&self) -> f64 {
        self.segs().map(|s| s.length()).sum()
    }

    /// Signed enclosed area (mm², positive counter-clockwise); 0 for an open contour.
    pub fn area(&self) -> f64 {
        if !self.closed {
            return 0.0;
        }
        self.segs()
            .map(|s| {
                let (a, b) = (s.start(), s.end());
                let chord = 0.5 * (a.x * b.y - b.x * a.y);
                match s {
                    Seg::Line(..) => chord,
                    // The circular segment between chord and arc, signed by the sweep.
                    Seg::Arc(q) => chord + 0.5 * q.r * q.r * (q.sweep - q.sweep.sin()),
                }
            })
            .sum()
    }

    /// True for a closed contour running counter-clockwise.
    pub fn is_ccw(&self) -> bool {
        self.area() > 0.0
    }

    /// Bounds (min, max) of the whole contour.
    pub fn bounds(&self) -> Option<(P2, P2)> {
        let mut it = self.segs().map(|s| s.bounds());
        let first = it.next().or_else(|| self.vertices.first().map(|v| (v.p, v.p)))?;
        Some(it.fold(first, |(lo, hi), (a, b)| {
            (P2::new(lo.x.min(a.x), lo.y.min(a.y)), P2::new(hi.x.max(b.x), hi.y.max(b.y)))
        }))
    }

    /// The contour run backwards.
    pub fn reversed(&self) -> Contour {
        let segs: Vec<Seg> = self.segs().map(|s| s.reversed()).collect::<Vec<_>>().into_iter().rev().collect();
        if segs.is_empty() {
            return self.clone();
        }
        Contour::from_segs(&segs, self.closed)
    }

    /// A closed contour started at vertex `k` (same pieces, same direction).
    pub fn rotated(&self, k: usize) -> Contour {
        let mut c = self.clone();
        if c.closed && !c.vertices.is_empty() {
            c.vertices.rotate_left(k % self.vertices.len());
        }
        c
    }

    /// Winding number of the closed contour around `p` (0 outside, ±1 inside a simple loop).
    pub fn winding_number(&self, p: &P2) -> i32 {
        self.to_pline().winding_number(cavalier_contours::core::math::Vector2::new(p.x, p.y))
    }

    /// A point of the contour (the middle of its first piece), for inside/outside tests of loops
    /// that do not cross.
    pub fn probe_point(&self) -> Option<P2> {
        (self.seg_count() > 0).then(|| self.seg(0).point_at(0.5)).or_else(|| self.vertices.first().map(|v| v.p))
    }

    /// First point where the contour crosses or touches itself, if any (pieces that do not
    /// follow each other meet, or consecutive ones meet away from their joint), by exact
    /// distances.
    pub fn self_crossing(&self) -> Option<P2> {
        verify::SegSet::new([self]).first_crossing().or_else(|| self.folded_joint())
    }

    /// First point where two consecutive pieces meet other than at their joint: a turn back
    /// along the way it came, or an arc that curls across its neighbour. Each piece is measured
    /// without the first and last `POINT_EPS` of its length, where it touches its neighbours.
    fn folded_joint(&self) -> Option<P2> {
        let n = self.seg_count();
        let inner = |i: usize, cut: f64| {
            let s = self.seg(i);
            let k = cut / s.length();
            (k < 0.5).then(|| s.sub(k, 1.0 - k))
        };
        let meet = |i: usize, cut: f64| {
            let (a, b) = (inner(i, cut)?, inner((i + 1) % n, cut)?);
            (a.min_distance(&b) == 0.0).then_some((a, b))
        };
        let joints = if self.closed && n > 1 { n } else { n.saturating_sub(1) };
        (0..joints).find_map(|i| {
            let mut pair = meet(i, tol::POINT_EPS)?;
            // Name the crossing, not the joint next to it: cut away more of the joint while the
            // pieces still meet, so that the nearest points found are those of the crossing.
            for cut in [1e-6, 1e-4, 1e-2, 1.0] {
                match meet(i, cut) {
                    Some(p) => pair = p,
                    None => break,
                }
            }
            Some(verify::meeting_point(&pair.0, &pair.1))
        })
    }

    /// First point where this contour and `other` cross or touch, if any.
    pub fn crossing_with(&self, other: &Contour) -> Option<P2> {
        let theirs = verify::SegSet::new([other]);
        self.segs().find_map(|s| {
            let (lo, hi) = s.bounds();
            theirs.near(&lo, &hi, 0.0).into_iter().find_map(|j| {
                (s.min_distance(&theirs.segs[j]) == 0.0).then(|| verify::meeting_point(&s, &theirs.segs[j]))
            })
        })
    }

    /// The contour as a cavalier_contours polyline.
    /// The contour as a cavalier_contours polyline. Cavalier takes arcs of at most a half
    /// circle (|bulge| ≤ 1), so a larger arc goes in as its two halves.
    pub(crate) fn to_pline(&self) -> Polyline<f64> {
        let mut p = Polyline::with_capacity(self.vertices.len(), self.closed);
        for (k, v) in self.vertices.iter().enumerate() {
            let next = self.vertices.get(k + 1).or(self.closed.then(|| &self.vertices[0]));
            match next {
                Some(n) if v.bulge.abs() > 1.0 => {
                    let half = (0.5 * v.bulge.atan()).tan();
                    let mid = Seg::from_bulge(v.p, n.p, v.bulge).point_at(0.5);
                    p.add(v.p.x, v.p.y, half);
                    p.add(mid.x, mid.y, half);
                }
                _ => p.add(v.p.x, v.p.y, v.bulge),
            }
        }
        p
    }

    /// A contour from a cavalier_contours polyline.
    pub(crate) fn from_pline(p: &Polyline<f64>) -> Contour {
        Contour {
            vertices: p
                .iter_vertexes()
                .map(|v: PlineVertex<f64>| Vertex { p: P2::new(v.x, v.y), bulge: v.bulge })
                .collect(),
            closed: p.is_closed(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// Consecutive pieces that meet away from their joint cross: two arcs of a random star
    /// (found by fuzzing `offset`) that leave their joint 174° apart and curl across each other
    /// just below it, and a line that turns straight back. Smooth and sharp joints that stay
    /// open do not.
    /// A circle drawn as an arc of 349° and one of 11° (as curve-fit-arcs writes a 400-gon):
    /// cavalier takes arcs of at most a half circle, so the large one goes in as two halves and
    /// the winding number is right everywhere (it said 0 at points inside before).
    #[test]
    fn arcs_over_a_half_circle_wind_correctly() {
        let c = P2::new(50.0, 50.0);
        let at = |deg: f64| c + 40.0 * V2::new(deg.to_radians().cos(), deg.to_radians().sin());
        let big = Seg::Arc(crate::geom::arc::Arc2 { c, r: 40.0, start: 0.0, sweep: 349f64.to_radians() });
        let contour = Contour {
            vertices: vec![
                Vertex { p: at(0.0), bulge: big.bulge() },
                Vertex { p: at(349.0), bulge: (11f64.to_radians() / 4.0).tan() },
            ],
            closed: true,
        };
        assert!(contour.vertices[0].bulge > 1.0);
        for deg in (0..360).step_by(15) {
            let inside = c + 39.0 * V2::new(f64::from(deg).to_radians().cos(), f64::from(deg).to_radians().sin());
            let outside = c + 41.0 * V2::new(f64::from(deg).to_radians().cos(), f64::from(deg).to_radians().sin());
            assert_eq!(contour.winding_number(&inside), 1, "{deg}°");
            assert_eq!(contour.winding_number(&outside), 0, "{deg}°");
        }
        assert_eq!(contour.winding_number(&c), 1);
        assert!((contour.area() - std::f64::consts::PI * 1600.0).abs() < 1e-9);
        assert_eq!(contour.to_pline().vertex_data.len(), 3);
    }

    #[test]
    fn consecutive_pieces_that_fold_across_each_other_cross() {
        let v = |x: f64, y: f64, bulge: f64| Vertex { p: P2::new(x, y), bulge };
        #[rustfmt::skip]
        let star = Contour { vertices: vec![
            v(72.245670, 50.000000, 0.0), v(73.412140, 62.287639, -0.256903699), v(57.462055, 60.810653, 0.060706490),
            v(51.702284, 64.019567, -0.378702207), v(40.887603, 74.027415, -0.389164237), v(34.655219, 63.594289, 0.0),
            v(31.714181, 54.507050, 0.0), v(34.679328, 46.223793, 0.0), v(34.444884, 36.219370, 0.0),
            v(40.042799, 23.745018, 0.0), v(52.292193, 31.122094, -0.316331690), v(63.027931, 31.125784, 0.0),
            v(72.852591, 38.006035, 0.0),
        ], closed: true };
        assert!(verify::SegSet::new([&star]).first_crossing().is_none(), "no two pieces apart from each other meet");
        let x = star.self_crossing().expect("the arcs either side of (40.89, 74.03) cross");
        assert!((x - P2::new(40.887603, 74.027415)).norm() > 1e-3, "{x}");
        assert!(star.seg(3).distance_to(&x) < 1e-9 && star.seg(4).distance_to(&x) < 1e-9);
        let mut flat = star.clone();
        flat.vertices[3].bulge = 0.0;
        assert_eq!(flat.self_crossing(), None, "a straight piece there leaves a sharp, open spike");
        let back =
            Contour::polygon(&[P2::new(0.0, 0.0), P2::new(4.0, 0.0), P2::new(2.0, 0.0), P2::new(2.0, 3.0)], true);
        assert!(back.self_crossing().is_some(), "turning back along the line overlaps it");
        let stadium = Contour {
            vertices: vec![v(0.0, 0.0, 0.0), v(4.0, 0.0, 1.0), v(4.0, 2.0, 0.0), v(0.0, 2.0, 1.0)],
            closed: true,
        };
        assert_eq!(stadium.self_crossing(), None);
        assert_eq!(Contour::circle(P2::new(0.0, 0.0), 2.0, 0.3, true).self_crossing(), None);
        // A straight run split at joints printed to 1e-9 mm (found by fuzzing `offset`): its
        // pieces turn by a few nanoradians and do not cross.
        let run = Contour::polygon(
            &[
                P2::new(26.74897854, 46.120090744),
                P2::new(25.689794481, 44.730928318),
                P2::new(24.630610432, 43.341765886),
                P2::new(40.0, 40.0),
            ],
            true,
        );
        assert_eq!(run.self_crossing(), None);
    }

    #[test]
    fn bulge_round_trip_and_area() {
        let c = Contour::circle(P2::new(1.0, 2.0), 3.0, 0.0, true);
        assert!((c.area() - PI * 9.0).abs() < 1e-12);
        assert!((c.length() - TAU * 3.0).abs() < 1e-12);
        let s = c.seg(0);
        let Seg::Arc(a) = s else { panic!("arc") };
        assert!((a.c - P2::new(1.0, 2.0)).norm() < 1e-12 && (a.r - 3.0).abs() < 1e-12);
        assert!((s.bulge() - 1.0).abs() < 1e-12);
        assert!((c.reversed().area() + PI * 9.0).abs() < 1e-12);
        let sq = Contour::polygon(&[P2::new(0.0, 0.0), P2::new(2.0, 0.0), P2::new(2.0, 1.0), P2::new(0.0, 1.0)], true);
        assert!((sq.area() - 2.0).abs() < 1e-15);
        assert_eq!(sq.winding_number(&P2::new(1.0, 0.5)), 1);
        assert_eq!(sq.self_crossing(), None);
        let bow = Contour::polygon(&[P2::new(0.0, 0.0), P2::new(2.0, 1.0), P2::new(2.0, 0.0), P2::new(0.0, 1.0)], true);
        let x = bow.self_crossing().expect("crossing");
        assert!((x - P2::new(1.0, 0.5)).norm() < 1e-12);
    }

    #[test]
    fn bounds_of_arcs_include_their_extremes() {
        let s = Seg::from_bulge(P2::new(1.0, 0.0), P2::new(-1.0, 0.0), 1.0);
        let (lo, hi) = s.bounds();
        assert!((hi.y - 1.0).abs() < 1e-12 && lo.y.abs() < 1e-12, "{lo} {hi}");
        assert_eq!(s.side_of(&P2::new(0.0, 0.5)), Some(0.5));
        assert!(s.side_of(&P2::new(0.0, 1.5)).unwrap() < 0.0);
    }
}
