//! 3D mode (paper 002 §4.3, fig. 4): a 3D contour with a tool axis on every row, cut on its side
//! by a flat end mill. At each row the contour around it (a look-ahead window along the contour)
//! is projected onto the plane through the row perpendicular to the tool axis, offset there by
//! R, and the offset point is mapped back into space in that plane.
//!
//! Where the corner offset of a row (the meeting point of its two neighbouring pieces' offsets)
//! clears the window by R it is the row's point; a convex corner that would leave more than
//! `chord_tol` beyond R gets several points of a polygon around the corner arc (never inside
//! it, so no chord cuts the corner); where the window comes closer (a tight concave stretch or a
//! neck), the point is taken from the verified 2D offset of the window.

use camkit::contour::offset::Side;
use camkit::contour::{Contour, OffsetOptions, offset_contour};
use camkit::geom::{P2, P3, V2, V3, cross2};
use rayon::prelude::*;

/// Settings of the 3D mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Tool radius R (mm).
    pub radius: f64,
    /// Side of travel, seen from the tool (looking down the axis at the work).
    pub side: Side,
    /// Look-ahead: contour length (mm) taken on each side of a row.
    pub window: f64,
    /// Largest distance beyond R that a corner point may lie (mm).
    pub chord_tol: f64,
    /// Verification of the 2D offsets.
    pub offset: OffsetOptions,
}

/// One output point: where, and which input row it belongs to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Tool tip.
    pub p: P3,
    /// Index of the input row.
    pub row: usize,
}

/// The offset contour and its figures.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Offset3 {
    /// Points in order.
    pub points: Vec<Point>,
    /// Largest shortfall of an output point's distance from its window below R, in its plane (mm).
    pub below: f64,
    /// Largest distance of an output point from its window beyond R (mm).
    pub above: f64,
    /// Corners that got more than one point.
    pub rounded: usize,
    /// Rows whose point came from a 2D offset of the window (loops removed).
    pub trimmed: usize,
    /// Output points dropped because they repeated the one before.
    pub merged: usize,
}

/// Why a row has no offset point.
#[derive(Clone, Debug, PartialEq)]
pub enum Error3 {
    /// The contour runs along the tool axis at this row.
    AlongAxis(usize),
    /// The contour turns back on itself at this row.
    Reversal(usize),
    /// The 2D offset at this row failed verification or left nothing.
    Offset(usize, String),
}

/// The plane through `p` perpendicular to `axis`: in-plane coordinates with u along the
/// projected travel direction `t`, v = axis × u.
struct Frame {
    o: P3,
    u: V3,
    v: V3,
}

impl Frame {
    fn new(o: P3, axis: &V3, t: &V3) -> Option<Frame> {
        let a = axis.normalize();
        let u = (t - a * t.dot(&a)).try_normalize(1e-12)?;
        Some(Frame { o, u, v: a.cross(&u) })
    }

    /// A frame of the plane through `o` perpendicular to `axis` (a unit vector), any rotation.
    fn across(o: P3, axis: &V3) -> Frame {
        let helper = if axis.x.abs() < 0.9 { V3::x() } else { V3::y() };
        let u = axis.cross(&helper).normalize();
        Frame { o, u, v: axis.cross(&u) }
    }

    fn flat(&self, p: &P3) -> P2 {
        let d = p - self.o;
        P2::new(d.dot(&self.u), d.dot(&self.v))
    }

    fn lift(&self, q: &P2) -> P3 {
        self.o + self.u * q.x + self.v * q.y
    }
}

/// Indices of the window around row `i`: contour each way up to the first row `w` mm or more
/// away (the whole contour if it is shorter; at least the neighbours), in order, and whether that is the whole closed contour.
fn window(pts: &[P3], closed: bool, i: usize, w: f64) -> (Vec<usize>, bool) {
    let n = pts.len();
    let step = |k: usize, fwd: bool| -> Option<usize> {
        match (fwd, closed) {
            (true, _) if k + 1 < n => Some(k + 1),
            (true, true) => Some(0),
            (false, _) if k > 0 => Some(k - 1),
            (false, true) => Some(n - 1),
            _ => None,
        }
    };
    let mut back = Vec::new();
    let (mut k, mut len) = (i, 0.0);
    while let Some(j) = step(k, false) {
        if j == i || back.len() + 1 >= n {
            break;
        }
        back.push(j);
        len += (pts[k] - pts[j]).norm();
        if len >= w {
            break;
        }
        k = j;
    }
    let mut fwd = Vec::new();
    let (mut k, mut len) = (i, 0.0);
    while let Some(j) = step(k, true) {
        if j == i || back.len() + fwd.len() + 2 > n || back.contains(&j) {
            break;
        }
        fwd.push(j);
        len += (pts[k] - pts[j]).norm();
        if len >= w {
            break;
        }
        k = j;
    }
    let whole = closed && back.len() + fwd.len() + 1 == n;
    let mut out: Vec<usize> = back.into_iter().rev().collect();
    out.push(i);
    out.extend(fwd);
    (out, whole)
}

/// The pieces of the window polyline `poly`, with the closing one if `closed`.
fn pieces(poly: &[P2], closed: bool) -> impl Iterator<Item = (P2, P2)> + '_ {
    let close = (closed && poly.len() > 2).then(|| (poly[poly.len() - 1], poly[0]));
    poly.windows(2).map(|w| (w[0], w[1])).chain(close)
}

/// Smallest distance from the move `a`–`b` to the polyline `poly` (closed if `closed`).
fn move_distance(a: &P2, b: &P2, poly: &[P2], closed: bool) -> f64 {
    pieces(poly, closed)
        .map(|(p, q)| camkit::geom::dist::segment_segment_min(a, b, &p, &q))
        .fold(f64::INFINITY, f64::min)
}

/// Distance from `q` to the polyline `poly` (closed if `closed`).
fn poly_distance(q: &P2, poly: &[P2], closed: bool) -> f64 {
    pieces(poly, closed).map(|(a, b)| camkit::geom::dist::point_segment(q, &a, &b)).fold(f64::INFINITY, f64::min)
}

/// Nearest distance (mm) from the window at which a point counts as R from it: R less its
/// round-off.
fn clear_at(r: f64) -> f64 {
    r - 1e-9 * r.max(1.0)
}

/// Offsets a 3D contour (points with a tool axis each).
pub fn offset(pts: &[P3], axes: &[V3], closed: bool, opts: &Options) -> Result<Offset3, Error3> {
    let n = pts.len();
    let r = opts.radius;
    let s = opts.side.sign();
    let mut out = Offset3::default();
    let (mut worst_above, mut worst_below) = (0.0f64, f64::INFINITY);
    let per_row: Vec<Result<RowOffset, Error3>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let prev = if i > 0 {
                Some(i - 1)
            } else if closed {
                Some(n - 1)
            } else {
                None
            };
            let next = if i + 1 < n {
                Some(i + 1)
            } else if closed {
                Some(0)
            } else {
                None
            };
            let t = pts[next.unwrap_or(i)] - pts[prev.unwrap_or(i)];
            let frame = Frame::new(pts[i], &axes[i], &t).ok_or(Error3::AlongAxis(i))?;
            let (idx, whole) = window(pts, closed, i, opts.window);
            let poly: Vec<P2> = idx.iter().map(|&j| frame.flat(&pts[j])).collect();
            let at = idx.iter().position(|&j| j == i).expect("the row is in its window");
            let dir = |a: &P2, b: &P2| (b - a).try_normalize(1e-15);
            let din = if at > 0 { dir(&poly[at - 1], &poly[at]) } else { None };
            let dout = if at + 1 < poly.len() { dir(&poly[at], &poly[at + 1]) } else { None };
            let din = din.or(dout).ok_or(Error3::AlongAxis(i))?;
            let dout = dout.unwrap_or(din);
            let left = |d: &V2| V2::new(-d.y, d.x);
            let (n_in, n_out) = (left(&din) * s, left(&dout) * s);
            let bis = (n_in + n_out).try_normalize(1e-9).ok_or(Error3::Reversal(i))?;
            let half = 0.5 * n_in.angle(&n_out);
            let convex = s * cross2(&din, &dout) < 0.0;
            let mut points = Vec::new();
            let corner = r / half.cos();
            if convex && corner - r > opts.chord_tol {
                // A polygon around the corner arc, its vertices at most chord_tol beyond R.
                let step = 2.0 * (r / (r + opts.chord_tol)).acos();
                let m = ((2.0 * half / step).ceil() as usize).max(1);
                let delta = 2.0 * half / m as f64;
                let turn = if cross2(&n_in, &n_out) >= 0.0 { 1.0 } else { -1.0 };
                for k in 0..m {
                    let phi = turn * (k as f64 + 0.5) * delta;
                    let (c, sn) = (phi.cos(), phi.sin());
                    let d = V2::new(n_in.x * c - n_in.y * sn, n_in.x * sn + n_in.y * c);
                    points.push(P2::origin() + d * (r / (0.5 * delta).cos()));
                }
            } else {
                points.push(P2::origin() + bis * corner);
            }
            // Clear: the corner points, and the moves from the offsets of the two pieces' middles
            // to them (the neighbours' moves meet these there), keep R from the window.
            let lim = clear_at(r);
            let moves = [
                (mid_offset(&poly, whole, at, false, s, r), points.first()),
                (mid_offset(&poly, whole, at, true, s, r), points.last()),
            ];
            let clear = points.iter().all(|q| poly_distance(q, &poly, whole) >= lim)
                && moves.iter().all(|(mid, end)| match (mid, end) {
                    (Some(a), Some(b)) => move_distance(a, b, &poly, whole) >= lim,
                    _ => true,
                });
            let mut trimmed = false;
            if !clear {
                // Loops to remove: the verified offset of the window, nearest its corner point.
                let c = Contour::polygon(&poly, whole);
                let off =
                    offset_contour(&c, r, opts.side, &opts.offset).map_err(|e| Error3::Offset(i, e.to_string()))?;
                if off.contours.is_empty() {
                    return Err(Error3::Offset(i, "the window's offset is empty: the tool does not fit here".into()));
                }
                points = owned_stretch(&off.contours, &poly, whole, at, s, r, opts.chord_tol);
                trimmed = true;
            }
            let gaps: Vec<f64> = points.iter().map(|q| poly_distance(q, &poly, whole) - r).collect();
            let above = gaps.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let below = gaps.iter().copied().fold(f64::INFINITY, f64::min);
            Ok(RowOffset { points, frame, trimmed, above, below })
        })
        .collect();
    for (i, row) in per_row.into_iter().enumerate() {
        let RowOffset { points, frame, trimmed, above, below } = row?;
        out.rounded += usize::from(points.len() > 1);
        out.trimmed += usize::from(trimmed);
        worst_above = worst_above.max(above);
        worst_below = worst_below.min(below);
        for q in &points {
            let p = frame.lift(q);
            if out.points.last().is_some_and(|l| (l.p - p).norm() <= camkit::tol::POINT_EPS) {
                out.merged += 1;
                continue;
            }
            out.points.push(Point { p, row: i });
        }
    }
    out.above = worst_above.max(0.0);
    out.below = (-worst_below).max(0.0);
    Ok(out)
}

/// The offset points of one row in its plane.
struct RowOffset {
    points: Vec<P2>,
    frame: Frame,
    trimmed: bool,
    above: f64,
    below: f64,
}

/// The neighbour of window point `at` before it (`fwd` false) or after it, if any.
fn neighbour(m: usize, whole: bool, at: usize, fwd: bool) -> Option<usize> {
    match fwd {
        true if at + 1 < m => Some(at + 1),
        false if at > 0 => Some(at - 1),
        _ if whole && m > 2 => Some(if fwd { 0 } else { m - 1 }),
        _ => None,
    }
}

/// The offset by `r` to side `s` of the middle of the piece between window point `at` and its
/// neighbour before it (`fwd` false) or after it: where the moves of two neighbouring rows meet.
fn mid_offset(poly: &[P2], whole: bool, at: usize, fwd: bool, s: f64, r: f64) -> Option<P2> {
    let k = neighbour(poly.len(), whole, at, fwd)?;
    let (a, b) = if fwd { (poly[at], poly[k]) } else { (poly[k], poly[at]) };
    let d = (b - a).try_normalize(1e-15)?;
    Some(P2::from((a.coords + b.coords) * 0.5) + V2::new(-d.y, d.x) * (s * r))
}

/// The part of the window's verified offset `loops` (of the window polyline `poly`, closed if
/// `whole`) that window point `at` owns: the offset points whose nearest point of `poly` lies on
/// its two pieces no farther than their middles, ordered as the path runs (by that nearest
/// point, and around the corner by angle), from the offset of the first middle to that of the
/// second where those are valid. Arcs become polygons around them (vertices `chord_tol` or less
/// beyond the arc, so no chord cuts it). One point per row is not enough where the offset bends
/// between rows (round a reflex corner next to a trimmed one): the move between two such points
/// cut the corner. Empty if the row owns no point of the offset.
fn owned_stretch(loops: &[Contour], poly: &[P2], whole: bool, at: usize, s: f64, r: f64, chord_tol: f64) -> Vec<P2> {
    let m = poly.len();
    let v = poly[at];
    let (prev, next) = (neighbour(m, whole, at, false), neighbour(m, whole, at, true));
    let half = |k: Option<usize>| k.map_or(0.0, |k| 0.5 * (poly[k] - v).norm());
    let reach = half(prev).max(half(next)) + r + chord_tol;
    // Where along the row's two half pieces the nearest window point of `q` lies: −1/2 … 0 on
    // the piece before, 0 … 1/2 on the piece after; None if elsewhere.
    let key = |q: &P2| -> Option<f64> {
        if (q - v).norm() > reach {
            return None;
        }
        let d = poly_distance(q, poly, whole);
        let along = |k: usize, fwd: bool| {
            let w = poly[k] - v;
            let t = ((q - v).dot(&w) / w.norm_squared()).clamp(0.0, 1.0);
            let foot = v + w * t;
            ((q - foot).norm() <= d * (1.0 + 1e-12) && t <= 0.5).then_some(if fwd { t } else { -t })
        };
        prev.and_then(|k| along(k, false)).or_else(|| next.and_then(|k| along(k, true)))
    };
    // Around the corner (nearest point the corner itself) the path turns from the normal of
    // the piece before to that of the piece after.
    let normal = |k: usize, fwd: bool| {
        let d = if fwd { poly[k] - v } else { v - poly[k] };
        V2::new(-d.y, d.x) * s
    };
    let n_in = prev.map(|k| normal(k, false)).or_else(|| next.map(|k| normal(k, true)));
    let turn = |q: &P2| {
        n_in.map_or(0.0, |n| {
            let w = q - v;
            let a = n.angle(&w);
            let out = next.map_or(n, |k| normal(k, true));
            if cross2(&n, &out) * cross2(&n, &w) >= 0.0 { a } else { -a }
        })
    };
    let mut owned: Vec<(f64, f64, P2)> = Vec::new();
    let mut take = |q: P2| {
        if let Some(k) = key(&q) {
            owned.push((k, if k == 0.0 { turn(&q) } else { 0.0 }, q));
        }
    };
    for c in loops {
        for seg in c.segs() {
            match seg {
                camkit::contour::Seg::Line(a, b) => {
                    take(a);
                    take(b);
                }
                camkit::contour::Seg::Arc(arc) => {
                    let step = 2.0 * (arc.r / (arc.r + chord_tol)).acos();
                    let k = ((arc.sweep.abs() / step).ceil() as usize).max(1);
                    let delta = arc.sweep / k as f64;
                    take(arc.start_point());
                    for j in 0..k {
                        let phi = arc.start + (j as f64 + 0.5) * delta;
                        take(arc.c + V2::new(phi.cos(), phi.sin()) * (arc.r / (0.5 * delta).cos()));
                    }
                    take(arc.end_point());
                }
            }
        }
    }
    if owned.is_empty() {
        // Nothing of the offset comes from this row's pieces (a spike narrower than 2R): the
        // neighbours' stretches meet at the junction.
        return Vec::new();
    }
    owned.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut out: Vec<P2> = Vec::with_capacity(owned.len() + 2);
    let valid = |q: &P2| poly_distance(q, poly, whole) >= clear_at(r);
    let ends = [mid_offset(poly, whole, at, false, s, r), mid_offset(poly, whole, at, true, s, r)];
    for q in
        ends[0].iter().filter(|q| valid(q)).chain(owned.iter().map(|o| &o.2)).chain(ends[1].iter().filter(|q| valid(q)))
    {
        if out.last().is_none_or(|l: &P2| (l - q).norm() > camkit::tol::POINT_EPS) {
            out.push(*q);
        }
    }
    out
}

/// The worst place where the straight moves of the offset paths come near an input contour.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Gouge {
    /// Largest depth by which a move comes closer than R to an input contour (mm; 0 if none).
    pub depth: f64,
    /// Output path and index of the move's end point where it happens.
    pub at: (usize, usize),
    /// Input path it comes near.
    pub input: usize,
}

/// A contour as the check sees it: points in order (closed ones repeat their first at the end)
/// with the tool axis of each point.
pub struct Track<'a> {
    /// Points.
    pub pts: &'a [P3],
    /// Unit tool axis per point.
    pub axes: &'a [V3],
}

/// The gouge check of a whole 3D result: every move between consecutive output points against
/// every input segment of every pass (the per-row windows see only the contour near their own
/// row, not a neighbouring island or the far side of a narrow bay), measured exactly as the
/// distance between the two segments in the plane perpendicular to the tool axis at either end
/// of the move (the smaller of the two). Input segments farther than R + the move's length from
/// the move's start in space are skipped: the tool works near its move, and a projection of a far
/// part of a curved part is not material under the tool.
pub fn gouge(outputs: &[Track], inputs: &[&[P3]], r: f64) -> Gouge {
    let moves: Vec<(usize, usize)> =
        outputs.iter().enumerate().flat_map(|(o, t)| (1..t.pts.len()).map(move |k| (o, k))).collect();
    moves
        .par_iter()
        .map(|&(o, k)| {
            let t = &outputs[o];
            let (a, b) = (t.pts[k - 1], t.pts[k]);
            let reach = r + (b - a).norm();
            let mut best = Gouge { depth: 0.0, at: (o, k), input: 0 };
            for (n, inp) in inputs.iter().enumerate() {
                for w in inp.windows(2) {
                    if camkit::geom::dist::point_segment(&a, &w[0], &w[1]) > reach {
                        continue;
                    }
                    for axis in [t.axes[k - 1], t.axes[k]] {
                        let f = Frame::across(a, &axis);
                        let d = camkit::geom::dist::segment_segment_min(
                            &f.flat(&a),
                            &f.flat(&b),
                            &f.flat(&w[0]),
                            &f.flat(&w[1]),
                        );
                        if r - d > best.depth {
                            best = Gouge { depth: r - d, at: (o, k), input: n };
                        }
                    }
                }
            }
            best
        })
        .reduce(Gouge::default, |x, y| if y.depth > x.depth || (y.depth == x.depth && y.at < x.at) { y } else { x })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A star of `n` vertices at radii 15–30 mm (counter-clockwise, z = 0), from `seed`.
    fn star(seed: u64, n: usize) -> Vec<P3> {
        let mut x = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (0..n)
            .map(|k| {
                x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                let r = 15.0 + 15.0 * (x >> 11) as f64 / (1u64 << 53) as f64;
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                P3::new(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect()
    }

    /// Flat stars (one tool axis) with spikes narrower than 2R beside reflex corners: offset with
    /// the whole contour in every window, the 3D result follows the verified 2D offset within
    /// the chord tolerance both ways (every output point near the 2D path, every point of the 2D
    /// path near the output polyline), and no move comes nearer than R to the contour. Found by
    /// fuzzing: one point per trimmed row cut the corner between rows by up to 1.4 mm.
    #[test]
    fn flat_stars_follow_the_verified_2d_offset() {
        let tol = 1e-3;
        let mut trimmed = 0;
        for (seed, n) in [(1, 29), (2, 22), (3, 25), (4, 14), (5, 30), (6, 18)] {
            let pts = star(seed, n);
            let axes = vec![V3::z(); n];
            let flat: Vec<P2> = pts.iter().map(|p| P2::new(p.x, p.y)).collect();
            for side in [Side::Left, Side::Right] {
                let opts = Options { radius: 5.0, side, window: 1e4, chord_tol: tol, offset: OffsetOptions::default() };
                let o = offset(&pts, &axes, true, &opts).expect("an offset");
                trimmed += o.trimmed;
                let mut ring: Vec<P3> = o.points.iter().map(|p| p.p).collect();
                ring.push(ring[0]);
                let two_d = offset_contour(&Contour::polygon(&flat, true), 5.0, side, &OffsetOptions::default())
                    .expect("the 2D offset");
                let near_2d = |q: &P2| {
                    two_d
                        .contours
                        .iter()
                        .flat_map(|c| c.segs().collect::<Vec<_>>())
                        .map(|s| s.distance_to(q))
                        .fold(f64::INFINITY, f64::min)
                };
                for p in &ring {
                    let d = near_2d(&P2::new(p.x, p.y));
                    assert!(d <= tol + 1e-9, "seed {seed} {side:?}: output point {p} is {d} from the 2D offset");
                }
                let flat_ring: Vec<P2> = ring.iter().map(|p| P2::new(p.x, p.y)).collect();
                for c in &two_d.contours {
                    for seg in c.segs() {
                        for k in 0..=20 {
                            let q = seg.point_at(k as f64 / 20.0);
                            let d = camkit::geom::dist::point_polyline(&q, &flat_ring);
                            assert!(
                                d <= tol + 1e-9,
                                "seed {seed} {side:?}: the 2D offset at {q} is {d} from the output"
                            );
                        }
                    }
                }
                let mut input = pts.clone();
                input.push(pts[0]);
                let track_axes = vec![V3::z(); ring.len()];
                let g = gouge(&[Track { pts: &ring, axes: &track_axes }], &[&input], 5.0);
                assert!(g.depth <= 1e-9, "seed {seed} {side:?}: a move {} mm nearer than R", g.depth);
            }
        }
        assert!(trimmed > 20, "rows taken from the 2D offset: {trimmed}");
    }

    /// A move `dy` beside the x axis at height `dz`, with tool axis `axis`, against R = 1.
    fn depth(dy: f64, dz: f64, axis: V3) -> Gouge {
        let input = [P3::new(0.0, 0.0, 0.0), P3::new(10.0, 0.0, 0.0)];
        let pts = [P3::new(2.0, dy, dz), P3::new(8.0, dy, dz)];
        let axes = [axis, axis];
        gouge(&[Track { pts: &pts, axes: &axes }], &[&input], 1.0)
    }

    #[test]
    fn gouge_is_measured_across_the_tool_axis() {
        // Beside the line in the plane across the axis: R minus the distance.
        assert!((depth(0.5, 0.0, V3::z()).depth - 0.5).abs() < 1e-12);
        assert_eq!(depth(1.0, 0.0, V3::z()).depth, 0.0);
        assert_eq!(depth(3.0, 0.0, V3::z()).depth, 0.0);
        // Straight above the line along the axis: the tool's side runs through it.
        assert!((depth(0.0, 1.0, V3::z()).depth - 1.0).abs() < 1e-12);
        // The same place with the axis along y: 1 mm away across the axis, no gouge.
        assert_eq!(depth(0.0, 1.0, V3::y()).depth, 0.0);
        // Axis tilted 60° from z toward y: the offset 1 mm along z is sin 60° across it.
        let tilted = V3::new(0.0, 60f64.to_radians().sin(), 60f64.to_radians().cos());
        assert!((depth(0.0, 1.0, tilted).depth - (1.0 - 60f64.to_radians().sin())).abs() < 1e-12);
    }
}
