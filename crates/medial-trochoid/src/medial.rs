//! The medial axis of a region with islands (paper 001 §2): the segment Voronoi diagram of its
//! boundary (`boostvoronoi`, a port of Boost.Polygon's exact builder) without the secondary
//! edges (those between a segment and its own end point, i.e. the ones touching reflex
//! vertices), kept where finite and inside the material, with the clearance radius (distance to
//! the nearest boundary element) along every edge.
//!
//! Input is integer: coordinates are snapped to `resolution` (default 1e-6 mm) about the
//! region's centre, within ±2^30 grid steps (±1073 mm at 1e-6 mm), then shifted by whole steps so
//! that the lowest is 0 (see [`Frame`]). Arcs are flattened into chords within `sagitta`;
//! parabolic edges (point–segment) are discretised within `chord_error`.

use boostvoronoi::prelude::{Builder, CellIndex, Line, Point, SourceCategory, Vertex};
use camkit::contour::Seg;
use camkit::contour::region::Region;
use camkit::geom::{P2, V2, cross2};
use std::time::Instant;

/// `1 − cos` of the largest turn between two pieces that still counts as smooth (about 0.1°).
const SMOOTH: f64 = 2e-6;

/// Settings of the medial axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MedialOptions {
    /// Snap grid of the integer input (mm).
    pub resolution: f64,
    /// Largest distance between an arc and its chords (mm).
    pub sagitta: f64,
    /// Largest distance between a parabolic edge and its chords (mm).
    pub chord_error: f64,
}

impl Default for MedialOptions {
    fn default() -> Self {
        MedialOptions { resolution: 1e-6, sagitta: 1e-3, chord_error: 1e-3 }
    }
}

/// One edge of the medial axis as a polyline with the clearance radius at each point.
#[derive(Clone, Debug, PartialEq)]
pub struct MedialEdge {
    /// Points along the edge (mm).
    pub points: Vec<P2>,
    /// Distance from each point to the nearest boundary element (mm).
    pub clearance: Vec<f64>,
}

/// The medial axis and what building it took.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Medial {
    /// Edges kept.
    pub edges: Vec<MedialEdge>,
    /// Boundary segments given to the Voronoi builder.
    pub segments: usize,
    /// Time the Voronoi builder took (s).
    pub build_seconds: f64,
    /// Largest distance from a kept point to its two nearest sites' mean (mm): how equidistant
    /// the edges are (0 up to round-off on the snapped boundary).
    pub equidistance_error: f64,
}

/// Why the medial axis could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum MedialError {
    /// A coordinate does not fit the integer range at the resolution.
    Range(f64),
    /// The Voronoi builder refused the input.
    Builder(String),
}

impl std::fmt::Display for MedialError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MedialError::Range(v) => write!(f, "coordinate {v} mm is outside the snapped integer range"),
            MedialError::Builder(e) => write!(f, "Voronoi builder: {e}"),
        }
    }
}

/// The builder's integer frame: a point p is at (p − centre) / resolution, rounded, plus `shift`.
///
/// The grid is the region's centre's; the shift (whole grid steps, so the snapped boundary is the
/// same) makes every coordinate 0 or more. Boost's exact fall-backs cost less then than with
/// mixed signs about the centre: 19 % fewer instructions for the bench's 1 000-segment star,
/// 13 % at 10 000, 17–30 % on N-gons with an island; Boost.Voronoi itself gains about as much
/// (docs/benchmarks.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Centre of the outer boundary's box (mm).
    pub centre: P2,
    /// Grid step (mm).
    pub resolution: f64,
    /// Whole grid steps added to every snapped coordinate.
    pub shift: (i32, i32),
}

impl Frame {
    /// A point in grid steps (not rounded).
    pub fn to_grid(&self, p: &P2) -> (f64, f64) {
        let (x, y) = ((p.x - self.centre.x) / self.resolution, (p.y - self.centre.y) / self.resolution);
        (x + f64::from(self.shift.0), y + f64::from(self.shift.1))
    }

    /// A point given in grid steps (mm).
    pub fn from_grid(&self, x: f64, y: f64) -> P2 {
        let (x, y) = (x - f64::from(self.shift.0), y - f64::from(self.shift.1));
        P2::new(self.centre.x + x * self.resolution, self.centre.y + y * self.resolution)
    }
}

/// A snapped vertex of a boundary loop and whether the contour runs on smoothly through it.
type Joint = ((i32, i32), bool);

/// The boundary loops of `region` snapped to the grid about its centre (consecutive repeats
/// dropped), and the frame that shifts them to coordinates of 0 or more.
fn snap_loops(region: &Region, opts: &MedialOptions) -> Result<(Frame, Vec<Vec<Joint>>), MedialError> {
    let (lo, hi) = region.outer.bounds().expect("a region has a boundary");
    let centre = P2::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y));
    let snap = |p: &P2| -> Result<(i32, i32), MedialError> {
        let f = |v: f64, o: f64| {
            let k = ((v - o) / opts.resolution).round();
            if k.abs() < f64::from(i32::MAX / 2) { Ok(k as i32) } else { Err(MedialError::Range(v)) }
        };
        Ok((f(p.x, centre.x)?, f(p.y, centre.y)?))
    };
    let mut rings = Vec::new();
    for c in region.loops() {
        let mut pts: Vec<(P2, bool)> = Vec::new();
        let segs: Vec<Seg> = c.segs().collect();
        for (i, s) in segs.iter().enumerate() {
            // A vertex where the contour runs on smoothly (tangent continuous) is no corner.
            let before = segs[(i + segs.len() - 1) % segs.len()].tangent_at(1.0);
            let smooth = before.dot(&s.tangent_at(0.0)) > 1.0 - SMOOTH;
            match *s {
                Seg::Line(a, _) => pts.push((a, smooth)),
                Seg::Arc(q) => {
                    let step = 2.0 * (1.0 - opts.sagitta / q.r).max(-1.0).acos();
                    let n = (q.sweep.abs() / step).ceil().max(1.0) as usize;
                    pts.extend((0..n).map(|k| (q.point_at_fraction(k as f64 / n as f64), k > 0 || smooth)));
                }
            }
        }
        let mut ring: Vec<Joint> = Vec::new();
        for (p, j) in &pts {
            let s = snap(p)?;
            if ring.last().is_none_or(|l| l.0 != s) {
                ring.push((s, *j));
            }
        }
        while ring.len() > 1 && ring[0].0 == ring[ring.len() - 1].0 {
            ring.pop();
        }
        rings.push(ring);
    }
    // |k| < 2^30 about the centre, so k + shift lies in [0, 2^31): in i32, and differences stay
    // under 2^31 as the builder's 64-bit cross products need.
    let low = |f: fn(&Joint) -> i32| rings.iter().flatten().map(f).min().unwrap_or(0);
    let shift = (-low(|j| j.0.0), -low(|j| j.0.1));
    let shifted =
        rings.iter().map(|r| r.iter().map(|&((x, y), j)| ((x + shift.0, y + shift.1), j)).collect()).collect();
    Ok((Frame { centre, resolution: opts.resolution, shift }, shifted))
}

/// The boundary segments exactly as the Voronoi builder gets them, and their frame: for
/// comparing with another builder on the same integers.
pub fn builder_input(region: &Region, opts: &MedialOptions) -> Result<(Frame, Vec<[i32; 4]>), MedialError> {
    let (frame, rings) = snap_loops(region, opts)?;
    let segments = rings
        .iter()
        .flat_map(|r| (0..r.len()).map(|k| (r[k].0, r[(k + 1) % r.len()].0)))
        .map(|(a, b)| [a.0, a.1, b.0, b.1])
        .collect();
    Ok((frame, segments))
}

/// A boundary site: the snapped segment (mm).
struct Site {
    a: P2,
    b: P2,
    /// Turn at `a` and at `b` (cross product of the pieces in and out; negative at a reflex
    /// vertex, material being on the left).
    turn_a: f64,
    turn_b: f64,
}

/// The medial axis of `region`.
pub fn medial_axis(region: &Region, opts: &MedialOptions) -> Result<Medial, MedialError> {
    let (frame, rings) = snap_loops(region, opts)?;
    let unsnap = |x: f64, y: f64| frame.from_grid(x, y);
    let mut sites: Vec<Site> = Vec::new();
    let mut lines: Vec<Line<i32>> = Vec::new();
    let mut joints: std::collections::HashSet<(i64, i64)> = std::collections::HashSet::new();
    for ring in &rings {
        let n = ring.len();
        let turn = |k: usize| {
            let (p, q, r) = (ring[(k + n - 1) % n].0, ring[k].0, ring[(k + 1) % n].0);
            let (ux, uy) = (f64::from(q.0) - f64::from(p.0), f64::from(q.1) - f64::from(p.1));
            let (vx, vy) = (f64::from(r.0) - f64::from(q.0), f64::from(r.1) - f64::from(q.1));
            ux * vy - uy * vx
        };
        for k in 0..ring.len() {
            let (a, b) = (ring[k].0, ring[(k + 1) % ring.len()].0);
            lines.push(Line::new(Point { x: a.0, y: a.1 }, Point { x: b.0, y: b.1 }));
            if ring[k].1 {
                joints.insert((i64::from(ring[k].0.0), i64::from(ring[k].0.1)));
            }
            sites.push(Site {
                a: unsnap(f64::from(a.0), f64::from(a.1)),
                b: unsnap(f64::from(b.0), f64::from(b.1)),
                turn_a: turn(k),
                turn_b: turn((k + 1) % n),
            });
        }
    }
    let started = Instant::now();
    let diagram = Builder::<i32>::default()
        .with_segments(lines.iter().copied())
        .and_then(|b| b.build())
        .map_err(|e| MedialError::Builder(e.to_string()))?;
    // A site of a cell: a segment, or one end point of a segment.
    let site_of = |cell: CellIndex| -> Option<(usize, SourceCategory)> {
        let c = diagram.cell(cell).ok()?;
        Some((c.source_index().usize(), c.source_category()))
    };
    let mut out = Medial { segments: sites.len(), build_seconds: started.elapsed().as_secs_f64(), ..Medial::default() };
    for e in diagram.edges() {
        let id = e.id();
        let Ok(twin) = e.twin() else { continue };
        if twin.usize() < id.usize() || !e.is_primary() {
            continue;
        }
        let (Some(v0), Ok(Some(v1))) = (e.vertex0(), diagram.edge_get_vertex1(id)) else { continue };
        let (Ok(v0), Ok(v1)) = (diagram.vertex(v0), diagram.vertex(v1)) else { continue };
        let (p0, p1) = (unsnap(v0.x(), v0.y()), unsnap(v1.x(), v1.y()));
        let (Ok(c0), Ok(c1)) = (e.cell(), diagram.edge_get_cell(twin)) else { continue };
        let (Some(s0), Some(s1)) = (site_of(c0), site_of(c1)) else { continue };
        // Skip the fans from smooth joints (of flattened arcs): not part of the true medial axis.
        let at_joint = |v: &Vertex| joints.contains(&(v.x().round() as i64, v.y().round() as i64));
        if at_joint(v0) || at_joint(v1) {
            continue;
        }
        let geo0 = geometry(&sites, s0);
        let geo1 = geometry(&sites, s1);
        let points = match (geo0, geo1) {
            (Geo::Point(f), Geo::Seg(a, b)) | (Geo::Seg(a, b), Geo::Point(f)) if e.is_curved() => {
                parabola(&f, &a, &b, &p0, &p1, opts.chord_error)
            }
            _ => vec![p0, p1],
        };
        let mid = points[points.len() / 2].coords.lerp(&points[(points.len() - 1) / 2].coords, 0.5);
        let probe = if points.len() == 2 { P2::from((p0.coords + p1.coords) * 0.5) } else { P2::from(mid) };
        // Inside the material: left of a segment site (boundaries run counter-clockwise,
        // islands clockwise); between two point sites, by winding number.
        let inside = match (geo0, geo1) {
            (Geo::Seg(a, b), _) | (_, Geo::Seg(a, b)) => cross2(&(b - a), &(probe - a)) > 0.0,
            // Two vertices: their cells lie inside at reflex vertices, outside at convex ones.
            _ => match (turn_of(&sites, s0), turn_of(&sites, s1)) {
                (a, b) if a < 0.0 && b < 0.0 => true,
                (a, b) if a > 0.0 || b > 0.0 => false,
                _ => region.contains(&probe),
            },
        };
        if !inside {
            continue;
        }
        let clearance: Vec<f64> = points.iter().map(|p| geo0.distance(p)).collect();
        for p in &points {
            out.equidistance_error = out.equidistance_error.max((geo0.distance(p) - geo1.distance(p)).abs());
        }
        out.edges.push(MedialEdge { points, clearance });
    }
    Ok(out)
}

#[derive(Clone, Copy, Debug)]
enum Geo {
    Point(P2),
    Seg(P2, P2),
}

impl Geo {
    fn distance(&self, p: &P2) -> f64 {
        match self {
            Geo::Point(q) => (p - q).norm(),
            Geo::Seg(a, b) => camkit::geom::dist::point_segment(p, a, b),
        }
    }
}

/// Turn at the vertex a point site stands for (0 for a segment site).
fn turn_of(sites: &[Site], (i, cat): (usize, SourceCategory)) -> f64 {
    match cat {
        SourceCategory::SegmentStart | SourceCategory::SinglePoint => sites[i].turn_a,
        SourceCategory::SegmentEnd => sites[i].turn_b,
        SourceCategory::Segment => 0.0,
    }
}

fn geometry(sites: &[Site], (i, cat): (usize, SourceCategory)) -> Geo {
    match cat {
        SourceCategory::SegmentStart => Geo::Point(sites[i].a),
        SourceCategory::SegmentEnd => Geo::Point(sites[i].b),
        SourceCategory::SinglePoint => Geo::Point(sites[i].a),
        SourceCategory::Segment => Geo::Seg(sites[i].a, sites[i].b),
    }
}

/// Points of the parabola equidistant from focus `f` and the line through `a`, `b`, between
/// `p0` and `p1`: feet spaced `sqrt(8 d ε)` apart keep chords within `eps` of the curve (its
/// curvature is at most 1/d, d the focus's distance to the line).
fn parabola(f: &P2, a: &P2, b: &P2, p0: &P2, p1: &P2, eps: f64) -> Vec<P2> {
    let t = (b - a).normalize();
    let mut n = V2::new(-t.y, t.x);
    let d = (f - a).dot(&n);
    if d < 0.0 {
        n = -n;
    }
    let d = d.abs();
    if d <= 0.0 {
        return vec![*p0, *p1];
    }
    let (u0, u1) = ((p0 - a).dot(&t), (p1 - a).dot(&t));
    let step = (8.0 * d * eps).sqrt();
    let k = ((u1 - u0).abs() / step).ceil().max(1.0) as usize;
    let fu = (f - a).dot(&t);
    let mut out = vec![*p0];
    for j in 1..k {
        let u = u0 + (u1 - u0) * j as f64 / k as f64;
        // Foot F = a + u t; X = F + h n with |X − f| = h: h = ((u − fu)² + d²) / (2 d).
        let h = ((u - fu).powi(2) + d * d) / (2.0 * d);
        out.push(a + t * u + n * h);
    }
    out.push(*p1);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use camkit::contour::Contour;
    use camkit::contour::region::regions;

    fn region_of(loops: &[Contour]) -> Region {
        regions(loops).expect("valid").0.remove(0)
    }

    #[test]
    fn rectangle_medial_axis_is_its_exact_skeleton() {
        // 100 × 60: the four 45° bisectors from the corners meet the centre line y = 30 at
        // x = 30 and x = 70.
        let r = region_of(&[Contour::polygon(
            &[P2::new(0.0, 0.0), P2::new(100.0, 0.0), P2::new(100.0, 60.0), P2::new(0.0, 60.0)],
            true,
        )]);
        let m = medial_axis(&r, &MedialOptions::default()).unwrap();
        assert_eq!(m.edges.len(), 5, "{:?}", m.edges);
        let exact = |p: &P2| {
            let on_centre = (p.y - 30.0).abs() < 1e-6 && p.x >= 30.0 - 1e-6 && p.x <= 70.0 + 1e-6;
            let on_bisector = [(0.0, 0.0), (100.0, 0.0), (100.0, 60.0), (0.0, 60.0)]
                .iter()
                .any(|&(cx, cy)| ((p.x - cx).abs() - (p.y - cy).abs()).abs() < 1e-6 && (p.x - cx).abs() <= 30.0 + 1e-6);
            on_centre || on_bisector
        };
        for e in &m.edges {
            for (p, c) in e.points.iter().zip(&e.clearance) {
                assert!(exact(p), "{p}");
                let d = p.x.min(100.0 - p.x).min(p.y).min(60.0 - p.y);
                assert!((c - d).abs() < 1e-6, "{c} vs {d}");
            }
        }
        assert!(m.equidistance_error < 1e-6);
    }

    #[test]
    fn builder_input_is_the_centred_grid_shifted_to_non_negative_coordinates() {
        // A pocket with an island and an arc, off the origin: every snapped vertex within half a
        // grid step (per axis) of the contour's, the lowest coordinate 0 on each axis, and the
        // frame's two conversions inverse to each other.
        let outer = Contour::polygon(
            &[P2::new(-30.3, 12.1), P2::new(70.7, 12.1), P2::new(70.7, 80.9), P2::new(-30.3, 80.9)],
            true,
        );
        let island = Contour::circle(P2::new(20.0, 45.0), 7.3, 0.0, false);
        let r = region_of(&[outer, island]);
        let opts = MedialOptions { resolution: 1e-5, ..MedialOptions::default() };
        let (frame, segments) = builder_input(&r, &opts).unwrap();
        assert!((frame.centre - P2::new(20.2, 46.5)).norm() < 1e-12, "{}", frame.centre);
        let lowest = |f: fn(&[i32; 4]) -> i32| segments.iter().map(f).min().unwrap();
        assert_eq!((lowest(|s| s[0]), lowest(|s| s[1])), (0, 0));
        assert!(segments.iter().all(|s| s.iter().all(|&c| c >= 0)));
        for s in &segments {
            let p = frame.from_grid(f64::from(s[0]), f64::from(s[1]));
            let (x, y) = frame.to_grid(&p);
            assert!((x - f64::from(s[0])).abs() < 1e-6 && (y - f64::from(s[1])).abs() < 1e-6);
            let d = r
                .loops()
                .iter()
                .map(|c| c.segs().map(|g| g.distance_to(&p)).fold(f64::MAX, f64::min))
                .fold(f64::MAX, f64::min);
            assert!(d <= 0.5 * opts.resolution * 2f64.sqrt() + 1e-12, "{p}: {d}");
        }
        // The medial axis built in this frame: every kept point equidistant from its two sites.
        let m = medial_axis(&r, &opts).unwrap();
        assert!(!m.edges.is_empty() && m.equidistance_error < 1e-9, "{}", m.equidistance_error);
    }

    #[test]
    fn circle_medial_axis_is_its_centre() {
        let r = region_of(&[Contour::circle(P2::new(3.0, 4.0), 20.0, 0.0, true)]);
        let opts = MedialOptions::default();
        let m = medial_axis(&r, &opts).unwrap();
        // Every joint fan is dropped; what is left lies within the sagitta's reach of the centre.
        for e in &m.edges {
            for p in &e.points {
                assert!((p - P2::new(3.0, 4.0)).norm() < 0.5, "{p}");
            }
        }
    }

    #[test]
    fn island_gives_parabolic_edges_equidistant_from_both_sites() {
        let outer =
            Contour::polygon(&[P2::new(0.0, 0.0), P2::new(60.0, 0.0), P2::new(60.0, 40.0), P2::new(0.0, 40.0)], true);
        let island = Contour::polygon(
            &[P2::new(25.0, 15.0), P2::new(35.0, 15.0), P2::new(35.0, 25.0), P2::new(25.0, 25.0)],
            true,
        );
        let r = region_of(&[outer, island]);
        let m = medial_axis(&r, &MedialOptions::default()).unwrap();
        assert!(m.edges.iter().any(|e| e.points.len() > 2), "curved edges around the island's corners");
        assert!(m.equidistance_error < 1e-5, "{}", m.equidistance_error);
        for e in &m.edges {
            for (p, c) in e.points.iter().zip(&e.clearance) {
                assert!(r.contains(p) || *c < 1e-6, "{p}");
            }
        }
    }
}
