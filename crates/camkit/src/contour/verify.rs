//! The proof of an offset: every output piece measured against the input with exact distances.
//!
//! For each output piece: no input piece comes closer than `d − tol` (no gouge); some input piece
//! (its generator) is within `d + tol` of every point of it (it lies on the offset, not beside
//! it), after splitting the piece if no single generator covers it; it lies on the requested side
//! of its generator. Then the input is probed for stretches the output missed: the raw offset
//! point of every input piece's middle that is a valid offset point must lie on the output.
//! Finally the output loops must not cross themselves or each other; they may touch at a vertex
//! of both (the loops of two parts of the input exactly 2R apart meet there and part again).
//!
//! Speed without weakening: every search goes through a spatial index of the pieces' boxes with
//! a reused traversal stack (one search for a group of consecutive output pieces, or nearest
//! first for each piece where the group's box holds too much of the input), and only
//! pieces whose bounding circles come within reach are measured exactly, by closed forms that
//! test an arc's span with cross products instead of angles. Output pieces are checked in fixed blocks along their loops, each piece
//! trying its predecessor's generator and that generator's neighbours first (a consecutive
//! offset piece nearly always comes from the same or the next input piece), and an output arc
//! that lies within `d + tol` of an end of an input piece by the triangle inequality
//! (`|centre − end| + radius`, the case of every round corner) needs no exact maximum. Blocks
//! and their results are fixed by the input alone, so the figures do not depend on the number of
//! threads.

use super::{Contour, Seg};
use crate::geom::dist::{point_segment, segment_segment_min};
use crate::geom::{Arc2, P2, V2, cross2};
use crate::tol;
use cavalier_contours::static_aabb2d_index::{
    Control, NeighborPriorityQueue, StaticAABB2DIndex, StaticAABB2DIndexBuilder,
};
use rayon::prelude::*;
use std::f64::consts::TAU;

/// What the verification of an offset measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Check {
    /// The offset distance (mm, positive).
    pub distance: f64,
    /// Largest distance of an output point from the input beyond `distance` (mm, ≥ 0).
    pub above: f64,
    /// Largest shortfall of an output point's distance from the input below `distance` (mm, ≥ 0).
    pub below: f64,
    /// Output pieces measured.
    pub pieces: usize,
}

impl Check {
    /// Largest |distance from the input − offset distance| over every output point (mm).
    pub fn deviation(&self) -> f64 {
        self.above.max(self.below)
    }

    /// The worse of two checks (for several passes).
    pub fn merge(&self, other: &Check) -> Check {
        Check {
            distance: self.distance.max(other.distance),
            above: self.above.max(other.above),
            below: self.below.max(other.below),
            pieces: self.pieces + other.pieces,
        }
    }
}

/// Why an offset was rejected.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Defect {
    /// An output loop is open where the input is closed.
    Open(P2),
    /// An output piece comes closer to the input than the offset distance (mm of clearance).
    Gouge(P2, f64),
    /// An output piece strays from the offset (its distance from the input, mm).
    Stray(P2, f64),
    /// An output piece lies on the wrong side of the input.
    WrongSide(P2),
    /// A valid stretch of the offset is missing from the output.
    Missing(P2),
    /// Output loops cross.
    Crossing(P2),
    /// The kernel stopped on one of its own internal checks (a debug assertion of
    /// cavalier_contours) and gave no result.
    Kernel,
}

impl Defect {
    /// One line for messages.
    pub fn describe(&self) -> String {
        let at = |p: &P2| format!("({:.6}, {:.6})", p.x, p.y);
        match self {
            Defect::Open(p) => format!("an offset loop is open at {}", at(p)),
            Defect::Gouge(p, c) => format!("an offset piece at {} comes within {c:.9} mm of the input", at(p)),
            Defect::Stray(p, d) => format!("an offset piece at {} lies {d:.9} mm from the input", at(p)),
            Defect::WrongSide(p) => format!("an offset piece at {} is on the wrong side", at(p)),
            Defect::Missing(p) => format!("the offset misses the valid point {}", at(p)),
            Defect::Crossing(p) => format!("offset loops cross at {}", at(p)),
            Defect::Kernel => "the offset kernel stopped on one of its internal checks".into(),
        }
    }
}

/// Pieces of several contours with a spatial index and their neighbours along each contour.
pub struct SegSet {
    /// The pieces, contour by contour in order.
    pub segs: Vec<Seg>,
    /// Start and end point of each piece (computed once: an arc's cost a sine and a cosine).
    ends: Vec<(P2, P2)>,
    /// Bounds (min, max) of each piece.
    bounds: Vec<(P2, P2)>,
    /// Each piece prepared for fast distances.
    fast: Vec<Fast>,
    /// A circle around each piece (centre, radius): a cheap lower bound of distances.
    circles: Vec<(P2, f64)>,
    prev: Vec<Option<usize>>,
    next: Vec<Option<usize>>,
    /// Spatial index of the pieces' bounds.
    index: Option<StaticAABB2DIndex<f64>>,
}

/// Reused buffers of one worker: the index's traversal stack, the input pieces near a group of
/// output pieces, and the generator's candidates.
#[derive(Default)]
struct Scratch {
    stack: Vec<usize>,
    queue: NeighborPriorityQueue<f64>,
    near: Vec<usize>,
    /// One piece's own candidates, when the group's are too many.
    own: Vec<usize>,
    cands: Vec<(f64, usize)>,
    /// The input piece that showed the last completeness probe invalid.
    hit: Option<usize>,
}

/// Output pieces per block of the piece checks: each block starts without a generator hint.
const BLOCK: usize = 64;

/// Consecutive output pieces that share one search of the index (their boxes' union grown by
/// d + tol); each then filters the list by its own circle.
const GROUP: usize = 8;

/// A group's candidates beyond which each piece searches nearest first on its own.
const CROWD: usize = 512;

impl SegSet {
    /// The pieces of `contours`.
    pub fn new<'a>(contours: impl IntoIterator<Item = &'a Contour>) -> SegSet {
        let (mut segs, mut prev, mut next) = (Vec::new(), Vec::new(), Vec::new());
        for c in contours {
            let base = segs.len();
            let n = c.seg_count();
            for i in 0..n {
                segs.push(c.seg(i));
                prev.push(if i > 0 {
                    Some(base + i - 1)
                } else if c.closed {
                    Some(base + n - 1)
                } else {
                    None
                });
                next.push(if i + 1 < n {
                    Some(base + i + 1)
                } else if c.closed {
                    Some(base)
                } else {
                    None
                });
            }
        }
        let ends: Vec<(P2, P2)> = segs.iter().map(|s| (s.start(), s.end())).collect();
        let bounds: Vec<(P2, P2)> = segs.iter().map(Seg::bounds).collect();
        let circles: Vec<(P2, f64)> = segs.iter().zip(&bounds).map(|(s, b)| circle_of(s, b)).collect();
        let index = (!segs.is_empty()).then(|| {
            let mut b = StaticAABB2DIndexBuilder::new(bounds.len());
            for (lo, hi) in &bounds {
                b.add(lo.x, lo.y, hi.x, hi.y);
            }
            b.build().expect("as many boxes as declared")
        });
        let fast = segs.iter().map(Fast::new).collect();
        SegSet { segs, ends, bounds, fast, circles, prev, next, index }
    }

    /// True if pieces `i` and `j` follow each other along their contour.
    pub fn adjacent(&self, i: usize, j: usize) -> bool {
        self.next[i] == Some(j) || self.prev[i] == Some(j)
    }

    /// Calls `f` with every piece whose box meets the box `lo..hi` grown by `grow`, until `f`
    /// returns true; returns whether it did.
    fn visit(&self, lo: &P2, hi: &P2, grow: f64, stack: &mut Vec<usize>, mut f: impl FnMut(usize) -> bool) -> bool {
        let Some(ix) = &self.index else { return false };
        let mut visitor = |i: usize| if f(i) { Control::Break(()) } else { Control::Continue };
        let c: Control<()> =
            ix.visit_query_with_stack(lo.x - grow, lo.y - grow, hi.x + grow, hi.y + grow, &mut visitor, stack);
        matches!(c, Control::Break(()))
    }

    /// Calls `f` with every piece whose box comes within `reach` of `p`, nearest first: a disc
    /// rather than a box, which matters when `reach` is large against the pieces.
    fn visit_nearest(&self, p: &P2, reach: f64, queue: &mut NeighborPriorityQueue<f64>, mut f: impl FnMut(usize)) {
        let Some(ix) = &self.index else { return };
        let limit = reach * reach;
        let mut visitor = |i: usize, d2: f64| {
            if d2 > limit {
                return Control::Break(());
            }
            f(i);
            Control::Continue
        };
        let _: Control<()> = ix.visit_neighbors_with_queue(p.x, p.y, &mut visitor, queue);
    }

    /// True if the circle around piece `i` comes within `reach` of the circle `(c, r)`.
    fn circle_within(&self, i: usize, c: &P2, r: f64, reach: f64) -> bool {
        let (ci, ri) = self.circles[i];
        let lim = reach + r + ri;
        lim >= 0.0 && (ci - c).norm_squared() <= lim * lim
    }

    /// Indices of pieces that may come within `grow` of the box `lo..hi` (by their circles).
    pub fn near(&self, lo: &P2, hi: &P2, grow: f64) -> Vec<usize> {
        let c = P2::from((lo.coords + hi.coords) * 0.5);
        let r = 0.5 * (hi - lo).norm();
        let mut out = Vec::new();
        self.visit(lo, hi, grow, &mut Vec::new(), |i| {
            if self.circle_within(i, &c, r, grow) {
                out.push(i);
            }
            false
        });
        out.sort_unstable();
        out
    }

    /// The least of `within` and the distances from `s` to the pieces, exactly: only the pieces
    /// the index finds within `within` of `s` are measured, so a running minimum over many
    /// segments (`within` the least so far) costs about the pieces near each, not all of them.
    pub fn distance_within(&self, s: &Seg, within: f64) -> f64 {
        let (lo, hi) = s.bounds();
        self.near(&lo, &hi, within).into_iter().map(|i| self.segs[i].min_distance(s)).fold(within, f64::min)
    }

    /// First point where two pieces that do not follow each other meet: a crossing or a touch.
    pub fn first_crossing(&self) -> Option<P2> {
        self.first_meeting(0.0)
    }

    /// First point where two pieces that do not follow each other meet, except where they touch
    /// at a vertex of both (ends within `touch` mm) and nowhere else: loops that come together at
    /// one point and part again, as the offsets of two parts of a contour exactly 2R apart do.
    pub fn first_meeting(&self, touch: f64) -> Option<P2> {
        // One search of the index per group of consecutive pieces (the union of their circles'
        // boxes); a piece that meets piece `i` has a box that meets `i`'s, so it is in the list.
        let n = self.segs.len();
        let groups: Vec<usize> = (0..n).step_by(GROUP).collect();
        first_of(groups, n < SERIAL_BELOW, |(stack, near): &mut (Vec<usize>, Vec<usize>), start| {
            let group = start..(start + GROUP).min(n);
            let boxes = group.clone().map(|i| {
                let (c, r) = self.circles[i];
                (P2::new(c.x - r, c.y - r), P2::new(c.x + r, c.y + r))
            });
            let (lo, hi) = boxes.reduce(|(lo, hi), (a, b)| {
                (P2::new(lo.x.min(a.x), lo.y.min(a.y)), P2::new(hi.x.max(b.x), hi.y.max(b.y)))
            })?;
            near.clear();
            self.visit(&lo, &hi, 0.0, stack, |j| {
                near.push(j);
                false
            });
            group.into_iter().find_map(|i| {
                let s = &self.segs[i];
                let (cs, rs) = self.circles[i];
                let first = near
                    .iter()
                    .copied()
                    .filter(|&j| {
                        j > i
                            && !self.adjacent(i, j)
                            && self.circle_within(j, &cs, rs, 0.0)
                            && s.min_distance(&self.segs[j]) == 0.0
                            && !(touch > 0.0 && self.touch_at_vertex(i, j, touch))
                    })
                    .min();
                first.map(|j| meeting_point(s, &self.segs[j]))
            })
        })
    }

    /// True if pieces `i` and `j` have ends within `touch` of each other and, without the
    /// stretch of `2·touch` at that end of either, do not meet.
    fn touch_at_vertex(&self, i: usize, j: usize, touch: f64) -> bool {
        let ((a0, a1), (b0, b1)) = (self.ends[i], self.ends[j]);
        let (s, t) = (&self.segs[i], &self.segs[j]);
        for (ea, at_end_a) in [(a0, false), (a1, true)] {
            for (eb, at_end_b) in [(b0, false), (b1, true)] {
                if (ea - eb).norm() <= touch {
                    let apart = |p: &Seg, at_end: bool, q: &Seg| {
                        let k = 2.0 * touch / p.length();
                        k >= 1.0 || {
                            let rest = if at_end { p.sub(0.0, 1.0 - k) } else { p.sub(k, 1.0) };
                            rest.min_distance(q) > 0.0
                        }
                    };
                    return apart(s, at_end_a, t) && apart(t, at_end_b, s);
                }
            }
        }
        false
    }

    /// True if some piece lies within `reach` of `p` (at most `reach` if `inclusive`, else
    /// closer), trying the pieces `first` before searching the index.
    fn any_within(&self, p: &P2, reach: f64, inclusive: bool, first: &[Option<usize>], stack: &mut Vec<usize>) -> bool {
        let hit = |i: usize| {
            let d = self.fast[i].point(p);
            if inclusive { d <= reach } else { d < reach }
        };
        if first.iter().flatten().any(|&i| hit(i)) {
            return true;
        }
        self.visit(p, p, reach, stack, |i| self.circle_within(i, p, 0.0, reach) && hit(i))
    }

    /// A piece closer than `reach` to `p`, if any: the pieces `first`, then the index.
    fn closer(&self, p: &P2, reach: f64, first: &[Option<usize>], stack: &mut Vec<usize>) -> Option<usize> {
        let hit = |i: usize| self.fast[i].point(p) < reach;
        if let Some(&i) = first.iter().flatten().find(|&&i| hit(i)) {
            return Some(i);
        }
        let mut found = None;
        self.visit(p, p, reach, stack, |i| {
            let yes = self.circle_within(i, p, 0.0, reach) && hit(i);
            if yes {
                found = Some(i);
            }
            yes
        });
        found
    }

    /// Distance from `p` to the nearest piece, searched nearest first; the search stops at the
    /// first piece closer than `enough` (then the result is that piece's distance, not the least).
    fn nearest(&self, p: &P2, enough: f64, queue: &mut NeighborPriorityQueue<f64>) -> f64 {
        let Some(ix) = &self.index else { return f64::INFINITY };
        let mut best = f64::INFINITY;
        let mut visitor = |i: usize, d2: f64| {
            if d2 >= best * best {
                return Control::Break(());
            }
            best = best.min(self.fast[i].point(p));
            if best < enough { Control::Break(()) } else { Control::Continue }
        };
        let _: Control<()> = ix.visit_neighbors_with_queue(p.x, p.y, &mut visitor, queue);
        best
    }

    /// The spatial index of the pieces' boxes (entry `i` is piece `i`), if there are pieces.
    pub fn index(&self) -> Option<&StaticAABB2DIndex<f64>> {
        self.index.as_ref()
    }

    /// The box around every piece, if any.
    pub fn extent(&self) -> Option<(P2, P2)> {
        let first = *self.bounds.first()?;
        Some(self.bounds.iter().fold(first, |(lo, hi), (a, b)| {
            (P2::new(lo.x.min(a.x), lo.y.min(a.y)), P2::new(hi.x.max(b.x), hi.y.max(b.y)))
        }))
    }

    /// True if every point of the box around the pieces lies closer than `reach` to one of them,
    /// shown by cells of a quadtree (split deepest first) each of whose centre is nearer to a
    /// piece than `reach` less the cell's half diagonal; false as soon as a cell's centre is
    /// `reach` or more from every piece, or after `budget` cells. Then no point of the box can
    /// be `reach` or more from the pieces: an inward offset by more than `reach` is empty.
    pub fn covers(&self, reach: f64, budget: usize) -> bool {
        let Some((lo, hi)) = self.extent() else { return false };
        let mut queue = NeighborPriorityQueue::new();
        // Cells (centre, half sizes); those to split wait deepest centre first (a distance is
        // positive, so its bits order as the number does).
        let mut cells = vec![(P2::from((lo.coords + hi.coords) * 0.5), 0.5 * (hi - lo))];
        let mut open = std::collections::BinaryHeap::new();
        let mut fresh = 0..1;
        loop {
            for k in fresh.clone() {
                let (c, half) = cells[k];
                let h = half.norm();
                let dist = self.nearest(&c, reach - h, &mut queue);
                if dist >= reach || cells.len() > budget {
                    return false;
                }
                if dist >= reach - h {
                    open.push((dist.to_bits(), k));
                }
            }
            let Some((_, k)) = open.pop() else { return true };
            let (c, half) = cells[k];
            let q = 0.5 * half;
            fresh = cells.len()..cells.len() + 4;
            for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
                cells.push((P2::new(c.x + sx * q.x, c.y + sy * q.y), q));
            }
        }
    }

    /// Side of `q` relative to piece `i` (positive left), deciding at a corner by both pieces
    /// that meet there.
    fn side(&self, i: usize, q: &P2) -> f64 {
        let s = &self.segs[i];
        if let Some(v) = s.side_of(q) {
            return v;
        }
        let (start, end) = self.ends[i];
        let (ds, de) = ((q - start).norm(), (q - end).norm());
        let (v, t_in, t_out) = if de <= ds {
            (end, Some(s.tangent_at(1.0)), self.next[i].map(|j| self.segs[j].tangent_at(0.0)))
        } else {
            (start, self.prev[i].map(|j| self.segs[j].tangent_at(1.0)), Some(s.tangent_at(0.0)))
        };
        let w: V2 = q - v;
        t_in.iter().chain(t_out.iter()).map(|t| cross2(t, &w)).sum()
    }

    /// An upper bound of the largest distance from a point of `s` to piece `i` found cheaply if it
    /// is at most `limit` (see [`arc_bound`]), else the exact one-sided maximum.
    fn max_distance(&self, s: &Seg, i: usize, limit: f64, shortcuts: bool) -> f64 {
        if shortcuts
            && let Seg::Arc(a) = s
            && let Some(bound) = arc_bound(a, &self.segs[i], self.ends[i])
            && bound <= limit
        {
            return bound;
        }
        s.max_distance_to(&self.segs[i])
    }
}

/// An upper bound, by the triangle inequality, of the largest distance from a point of arc `a`
/// to the piece `t` with ends `(e0, e1)`: `|centre − e| + radius` for an end `e` (the round corner
/// about a vertex), and for an arc `t` about nearly the same centre, `|Δcentre| + |Δradius| +
/// radius·overhang`, where the overhang is the angle by which `a` reaches beyond the directions
/// `t` spans (a point beyond them is compared with `t`'s nearer end, at most that angle away).
/// `None` if neither applies.
fn arc_bound(a: &Arc2, t: &Seg, (e0, e1): (P2, P2)) -> Option<f64> {
    let corner = (a.c - e0).norm().min((a.c - e1).norm()) + a.r;
    let Seg::Arc(b) = t else { return Some(corner) };
    let span = b.sweep.abs();
    let len = a.sweep.abs();
    // Where `a`'s directions begin, in `b`'s progress (negative: before `b`'s start).
    let first = if (a.sweep > 0.0) == (b.sweep > 0.0) { a.start } else { a.start + a.sweep };
    let mut p0 = b.progress(first);
    if p0 > span + 0.5 * (TAU - span) {
        p0 -= TAU;
    }
    let overhang = (-p0).max(p0 + len - span).max(0.0);
    Some(corner.min((a.c - b.c).norm() + (a.r - b.r).abs() + a.r * overhang))
}

/// Where two pieces that meet do so: the exact crossing of two lines, else the point of `s`
/// nearest to `t` found by sampling and golden-section refinement (for messages).
pub(crate) fn meeting_point(s: &Seg, t: &Seg) -> P2 {
    if let (Seg::Line(a, b), Seg::Line(c, d)) = (s, t) {
        let (u, v) = (b - a, d - c);
        let den = cross2(&u, &v);
        if den != 0.0 {
            let k = (cross2(&(c - a), &v) / den).clamp(0.0, 1.0);
            return a + u * k;
        }
    }
    const SAMPLES: usize = 64;
    let f = |k: f64| t.distance_to(&s.point_at(k));
    let best = (0..=SAMPLES).map(|i| i as f64 / SAMPLES as f64).min_by(|a, b| f(*a).total_cmp(&f(*b))).unwrap_or(0.5);
    let (mut lo, mut hi) = ((best - 1.0 / SAMPLES as f64).max(0.0), (best + 1.0 / SAMPLES as f64).min(1.0));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if f(x1) <= f(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    s.point_at(0.5 * (lo + hi))
}

/// A circle around a piece with bounds `b`: the middle and half the length of a line; the box's
/// for an arc.
fn circle_of(s: &Seg, (lo, hi): &(P2, P2)) -> (P2, f64) {
    match s {
        Seg::Line(a, b) => (P2::from((a.coords + b.coords) * 0.5), 0.5 * (b - a).norm()),
        Seg::Arc(_) => (P2::from((lo.coords + hi.coords) * 0.5), 0.5 * (hi - lo).norm()),
    }
}

/// A piece prepared for fast distances: an arc's end directions as unit vectors, so that whether
/// it spans a direction is two cross products rather than an `atan2` and a remainder. The
/// distances below follow [`crate::geom::dist`]'s closed forms step for step (property test:
/// `fast_distances_match_the_exact_routines`).
#[derive(Clone, Copy, Debug)]
enum Fast {
    Line(P2, P2),
    Arc(FastArc),
}

/// An arc for [`Fast`]: running counter-clockwise from direction `a` to `b` (whatever its own
/// direction), `big` if it sweeps more than a half turn, `full` for a whole circle.
#[derive(Clone, Copy, Debug)]
struct FastArc {
    c: P2,
    r: f64,
    p0: P2,
    p1: P2,
    a: V2,
    b: V2,
    big: bool,
    full: bool,
}

impl Fast {
    fn new(s: &Seg) -> Fast {
        match s {
            Seg::Line(a, b) => Fast::Line(*a, *b),
            Seg::Arc(q) => {
                let end = q.start + q.sweep;
                let (u0, u1) = (V2::new(q.start.cos(), q.start.sin()), V2::new(end.cos(), end.sin()));
                let (a, b) = if q.sweep >= 0.0 { (u0, u1) } else { (u1, u0) };
                Fast::Arc(FastArc {
                    c: q.c,
                    r: q.r,
                    p0: q.c + q.r * u0,
                    p1: q.c + q.r * u1,
                    a,
                    b,
                    big: q.sweep.abs() > std::f64::consts::PI,
                    full: q.sweep.abs() >= TAU,
                })
            }
        }
    }

    /// Distance from `p`.
    fn point(&self, p: &P2) -> f64 {
        match self {
            Fast::Line(a, b) => point_segment(p, a, b),
            Fast::Arc(q) => q.point(p),
        }
    }

    /// Smallest distance between two pieces (0 where they meet).
    fn min(&self, other: &Fast) -> f64 {
        match (self, other) {
            (Fast::Line(a, b), Fast::Line(c, d)) => segment_segment_min(a, b, c, d),
            (Fast::Line(a, b), Fast::Arc(q)) | (Fast::Arc(q), Fast::Line(a, b)) => q.segment_min(a, b),
            (Fast::Arc(p), Fast::Arc(q)) => p.arc_min(q),
        }
    }
}

impl FastArc {
    /// True if the ray from the centre along `v` meets the arc.
    fn spans(&self, v: &V2) -> bool {
        let (a, b) = (&self.a, &self.b);
        if self.full {
            true
        } else if self.big {
            !(cross2(b, v) > 0.0 && cross2(v, a) > 0.0)
        } else {
            // Under a quarter turn, also on the side of the bisector: an arc so short that its
            // ends' cross product rounds to zero must not span the opposite direction.
            cross2(a, v) >= 0.0 && cross2(v, b) >= 0.0 && (a.dot(b) <= 0.0 || v.dot(&(a + b)) >= 0.0)
        }
    }

    fn point(&self, p: &P2) -> f64 {
        let v = p - self.c;
        let rho = v.norm();
        if rho == 0.0 || self.spans(&v) { (rho - self.r).abs() } else { (p - self.p0).norm().min((p - self.p1).norm()) }
    }

    /// As [`crate::geom::dist::segment_arc_min`].
    fn segment_min(&self, a: &P2, b: &P2) -> f64 {
        let d = b - a;
        let len2 = d.norm_squared();
        if len2 > 0.0 {
            let u = d / len2.sqrt();
            let n = V2::new(-u.y, u.x);
            let h = n.dot(&(self.c - a));
            if h.abs() <= self.r {
                let foot = self.c - n * h;
                let half = (self.r * self.r - h * h).max(0.0).sqrt();
                for x in [foot + u * half, foot - u * half] {
                    let t = (x - a).dot(&d) / len2;
                    if (0.0..=1.0).contains(&t) && self.spans(&(x - self.c)) {
                        return 0.0;
                    }
                }
            }
        }
        let mut best = self.point(a).min(self.point(b));
        best = best.min(point_segment(&self.p0, a, b)).min(point_segment(&self.p1, a, b));
        if len2 > 0.0 {
            let n = V2::new(-d.y, d.x) / len2.sqrt();
            for dir in [n, -n] {
                if self.spans(&dir) {
                    best = best.min(point_segment(&(self.c + dir * self.r), a, b));
                }
            }
        }
        best
    }

    /// As [`crate::geom::dist::arc_arc_min`].
    fn arc_min(&self, q: &FastArc) -> f64 {
        let dc = q.c - self.c;
        let dist = dc.norm();
        if dist > 0.0 {
            let a = (self.r * self.r - q.r * q.r + dist * dist) / (2.0 * dist);
            let h2 = self.r * self.r - a * a;
            if h2 >= 0.0 {
                let u = dc / dist;
                let n = V2::new(-u.y, u.x);
                let base = self.c + u * a;
                let h = h2.sqrt();
                for x in [base + n * h, base - n * h] {
                    if self.spans(&(x - self.c)) && q.spans(&(x - q.c)) {
                        return 0.0;
                    }
                }
            }
        }
        let mut best = q.point(&self.p0).min(q.point(&self.p1));
        best = best.min(self.point(&q.p0)).min(self.point(&q.p1));
        if dist > 0.0 {
            let u = dc / dist;
            for sp in [1.0, -1.0] {
                if !self.spans(&(u * sp)) {
                    continue;
                }
                for sq in [1.0, -1.0] {
                    if q.spans(&(u * sq)) {
                        best = best.min((self.c + u * (sp * self.r) - (q.c + u * (sq * q.r))).norm());
                    }
                }
            }
        } else if self.spans(&(q.p0 - q.c)) || q.spans(&(self.p0 - self.c)) {
            best = best.min((self.r - q.r).abs());
        }
        best
    }
}

/// Pieces below which a check runs on the calling thread: handing a millisecond of work to the
/// pool (waking its threads, waiting for the last) costs more than sharing it saves when the
/// cores are busy. The results are the same either way.
const SERIAL_BELOW: usize = 2048;

/// `f(scratch, item)` for every item, in order; on the thread pool unless `serial`, with one
/// scratch `S` per worker.
fn map_of<S: Default, T: Send>(
    items: Vec<usize>,
    serial: bool,
    f: impl Fn(&mut S, usize) -> T + Sync + Send,
) -> Vec<T> {
    if serial {
        let mut scratch = S::default();
        items.into_iter().map(|i| f(&mut scratch, i)).collect()
    } else {
        items.into_par_iter().map_init(S::default, f).collect()
    }
}

/// The first `Some` of `f(scratch, item)` in the items' order, as [`map_of`].
fn first_of<S: Default, T: Send>(
    items: Vec<usize>,
    serial: bool,
    f: impl Fn(&mut S, usize) -> Option<T> + Sync + Send,
) -> Option<T> {
    if serial {
        let mut scratch = S::default();
        items.into_iter().find_map(|i| f(&mut scratch, i))
    } else {
        items.into_par_iter().map_init(S::default, f).find_first(Option::is_some).flatten()
    }
}

/// What the checks of one block of output pieces found: the largest distance above `d`, the
/// largest shortfall below it, and the generator of each piece.
type Block = (f64, f64, Vec<usize>);

/// The settings of one verification.
#[derive(Clone, Copy)]
struct Spec {
    d: f64,
    side: f64,
    tol: f64,
    /// Use the generator hints and the arc bound (false: every piece by the full search and the
    /// exact maxima, for tests that compare both).
    shortcuts: bool,
}

/// An output piece with what its checks need (computed once).
struct Piece {
    seg: Seg,
    /// Circle around it.
    c: P2,
    r: f64,
    /// Its middle point and the largest distance from that to any of its points.
    mid: P2,
    reach: f64,
    fast: Fast,
}

impl Piece {
    fn new(seg: Seg, (c, r): (P2, f64)) -> Piece {
        let reach = match &seg {
            Seg::Line(a, b) => 0.5 * (b - a).norm(),
            Seg::Arc(a) => 2.0 * a.r * (0.25 * a.sweep.abs()).sin(),
        };
        Piece { mid: seg.point_at(0.5), fast: Fast::new(&seg), seg, c, r, reach }
    }

    fn of(seg: Seg) -> Piece {
        let c = circle_of(&seg, &seg.bounds());
        Piece::new(seg, c)
    }
}

/// Measures one output piece: (largest distance above `d`, shortfall below `d`, its generator)
/// or a defect. `hint` is the generator of the piece before it.
fn check_piece(
    input: &SegSet,
    p: &Piece,
    spec: &Spec,
    hint: Option<usize>,
    depth: u32,
    scratch: &mut Scratch,
) -> Result<(f64, f64, usize), Defect> {
    let Spec { d, side, tol, shortcuts } = *spec;
    let (s, mid) = (&p.seg, p.mid);
    let limit = d + tol;
    // A cheap bound is taken only within round-off of d, so that it never inflates the figures.
    let bound_limit = d + tol.min(tol::ROUNDOFF_ABS);
    // The generator: first the previous piece's and its neighbours (by the cheap bounds of
    // arcs, then exactly where the middle is within reach), later every piece within reach.
    let mut generator: Option<(usize, f64)> = None;
    if shortcuts && let Some(g) = hint {
        let next = input.next[g];
        let tries = [Some(g), next, input.prev[g], next.and_then(|k| input.next[k])];
        let tries = tries.iter().enumerate().filter_map(|(k, t)| t.filter(|_| !tries[..k].contains(t)));
        if let Seg::Arc(a) = s {
            generator = tries.clone().find_map(|i| {
                arc_bound(a, &input.segs[i], input.ends[i]).filter(|b| *b <= bound_limit).map(|b| (i, b))
            });
        }
        if generator.is_none() {
            generator = tries.filter(|&i| input.fast[i].point(&mid) <= limit).find_map(|i| {
                let far = s.max_distance_to(&input.segs[i]);
                (far <= limit).then_some((i, far))
            });
        }
    }
    // No gouge: every input piece that may come closer than d (by its circle, then by its
    // distance from the middle less the piece's reach) is measured exactly. Without a generator
    // yet, the pieces within d + tol of the middle are its candidates.
    let mut clearance = f64::INFINITY;
    let Scratch { near, cands, .. } = scratch;
    cands.clear();
    let grow = if generator.is_some() { d } else { limit };
    for &i in near.iter() {
        if input.circle_within(i, &p.c, p.r, grow) {
            let t = &input.segs[i];
            let dm = if shortcuts { input.fast[i].point(&mid) } else { t.distance_to(&mid) };
            if dm - p.reach < d && input.circle_within(i, &p.c, p.r, d) {
                let m = if shortcuts { p.fast.min(&input.fast[i]) } else { s.min_distance(t) };
                clearance = clearance.min(m);
            }
            if generator.is_none() && dm <= limit {
                cands.push((dm, i));
            }
        }
    }
    if clearance < d - tol {
        return Err(Defect::Gouge(mid, clearance));
    }
    let below = (d - clearance.min(d)).max(0.0);
    let found = |(i, far): (usize, f64)| -> Result<(f64, f64, usize), Defect> {
        if input.side(i, &mid) * side <= 0.0 { Err(Defect::WrongSide(mid)) } else { Ok(((far - d).max(0.0), below, i)) }
    };
    if let Some(g) = generator {
        return found(g);
    }
    cands.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut best = f64::INFINITY;
    for &(_, i) in cands.iter() {
        let far = input.max_distance(s, i, bound_limit, shortcuts);
        best = best.min(far);
        if far <= limit {
            return found((i, far));
        }
    }
    if depth < 4 && s.length() > tol {
        let a = check_piece(input, &Piece::of(s.sub(0.0, 0.5)), spec, hint, depth + 1, scratch)?;
        let b = check_piece(input, &Piece::of(s.sub(0.5, 1.0)), spec, Some(a.2), depth + 1, scratch)?;
        return Ok((a.0.max(b.0), a.1.max(b.1), b.2));
    }
    Err(Defect::Stray(mid, best))
}

/// How far, in tolerances, along an input piece the completeness probe looks on either side for
/// valid offset points before it counts a lone valid one as a point the offset shrank to.
const ISOLATED: f64 = 2.0;

/// Verifies that `output` is the offset of `input` by `d` (mm, > 0) to `side` (+1 left, −1
/// right of each input piece) within `tol`; `closed` requires every output loop to be closed.
/// `crossing_input` lets output loops cross (the offset of a self-crossing input crosses too).
/// Only the part of the offset inside `scope` (loops oriented as a region; none: all of it) must
/// be on `output`: the clean-up pass of one piece of a pocket level is the offset of the region
/// inside that piece only.
#[allow(clippy::too_many_arguments)]
pub(crate) fn verify(
    input: &SegSet,
    output: &[Contour],
    d: f64,
    side: f64,
    closed: bool,
    tol: f64,
    crossing_input: bool,
    scope: &[&Contour],
) -> Result<Check, Defect> {
    verify_with(input, output, &Spec { d, side, tol, shortcuts: true }, closed, crossing_input, scope)
}

/// [`verify`] with its settings spelled out.
fn verify_with(
    input: &SegSet,
    output: &[Contour],
    spec: &Spec,
    closed: bool,
    crossing_input: bool,
    scope: &[&Contour],
) -> Result<Check, Defect> {
    let (d, tol) = (spec.d, spec.tol);
    for c in output {
        if closed && !c.closed {
            return Err(Defect::Open(c.vertices.first().map_or(P2::origin(), |v| v.p)));
        }
    }
    let out = SegSet::new(output);
    let starts: Vec<usize> = (0..out.segs.len()).step_by(BLOCK).collect();
    let blocks: Vec<Result<Block, Defect>> =
        map_of(starts, out.segs.len() < SERIAL_BELOW, |scratch: &mut Scratch, start| {
            let (mut above, mut below, mut hint) = (0.0f64, 0.0f64, None);
            let mut generators = Vec::with_capacity(BLOCK);
            for i in start..(start + BLOCK).min(out.segs.len()) {
                if (i - start) % GROUP == 0 {
                    let group = &out.bounds[i..(i + GROUP).min(start + BLOCK).min(out.segs.len())];
                    let (lo, hi) = group.iter().fold(group[0], |(lo, hi), (a, b)| {
                        (P2::new(lo.x.min(a.x), lo.y.min(a.y)), P2::new(hi.x.max(b.x), hi.y.max(b.y)))
                    });
                    let Scratch { stack, near, .. } = scratch;
                    near.clear();
                    input.visit(&lo, &hi, d + tol, stack, |j| {
                        near.push(j);
                        false
                    });
                }
                let p = Piece::new(out.segs[i], out.circles[i]);
                // Far from the input (a deep pocket level) the group's box holds much of it,
                // while the disc of reach around this piece holds only the pieces nearest to it:
                // the piece is checked against those instead.
                let crowded = scratch.near.len() > CROWD;
                if crowded {
                    let Scratch { queue, own, .. } = scratch;
                    own.clear();
                    input.visit_nearest(&p.c, d + tol + p.r, queue, |j| own.push(j));
                    std::mem::swap(&mut scratch.near, &mut scratch.own);
                }
                let checked = check_piece(input, &p, spec, hint, 0, scratch);
                if crowded {
                    std::mem::swap(&mut scratch.near, &mut scratch.own);
                }
                let (a, b, g) = checked?;
                above = above.max(a);
                below = below.max(b);
                hint = Some(g);
                generators.push(g);
            }
            Ok((above, below, generators))
        });
    let mut check = Check { distance: d, pieces: out.segs.len(), ..Check::default() };
    // The first and last output piece each input piece generated: where the completeness probe
    // of that input piece looks before searching the output's index.
    let mut made: Vec<[Option<usize>; 2]> = vec![[None, None]; input.segs.len()];
    let mut k = 0;
    for block in blocks {
        let (above, below, generators) = block?;
        check.above = check.above.max(above);
        check.below = check.below.max(below);
        for g in generators {
            made[g][0].get_or_insert(k);
            made[g][1] = Some(k);
            k += 1;
        }
    }
    // Completeness: valid raw offset points of the input's pieces lie on the output (tested in
    // the cheaper order: a point on the output needs no validity test).
    let missing: Option<P2> =
        first_of((0..input.segs.len()).collect(), input.segs.len() < SERIAL_BELOW, |scratch: &mut Scratch, i| {
            let t = &input.segs[i];
            if t.length() <= tol {
                return None;
            }
            let raw = |at: f64| {
                let tangent = t.tangent_at(at);
                t.point_at(at) + V2::new(-tangent.y, tangent.x) * (spec.side * d)
            };
            let c = raw(0.5);
            if out.any_within(&c, tol, true, &made[i], &mut scratch.stack) {
                return None;
            }
            // The piece that showed the previous probe invalid nearly always shows this one too
            // (the probes of a deep offset lie far from their own pieces).
            let mut invalid_at = |p: &P2| {
                let hit =
                    input.closer(p, d - 0.25 * tol, &[input.prev[i], input.next[i], scratch.hit], &mut scratch.stack);
                scratch.hit = hit.or(scratch.hit);
                hit.is_some()
            };
            if invalid_at(&c) {
                return None;
            }
            // A valid probe whose raw offset is invalid `ISOLATED · tol` along the piece on both
            // sides lies where the offset shrinks to a point: round-off, as a loop no longer than
            // the tolerance is (a pocket level exactly as deep as the region).
            let step = ISOLATED * tol / t.length();
            if step < 0.5 && invalid_at(&raw(0.5 - step)) && invalid_at(&raw(0.5 + step)) {
                return None;
            }
            let outside = !scope.is_empty() && scope.iter().map(|l| l.winding_number(&c)).sum::<i32>() == 0;
            (!outside).then_some(c)
        });
    if let Some(c) = missing {
        return Err(Defect::Missing(c));
    }
    // No output loop crosses itself or another (touching at a vertex of both is not crossing).
    if !crossing_input && let Some(p) = out.first_meeting(tol) {
        return Err(Defect::Crossing(p));
    }
    Ok(check)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::Vertex;
    use crate::contour::offset::{OffsetOptions, Side, offset_contour};
    use proptest::prelude::*;

    /// A star-shaped closed contour, counter-clockwise, pieces of the given bulges (0 = line).
    fn star(radii: &[f64], bulges: &[f64]) -> Contour {
        let n = radii.len();
        let vertices = (0..n)
            .map(|k| {
                let a = TAU * k as f64 / n as f64;
                Vertex { p: P2::new(radii[k] * a.cos(), radii[k] * a.sin()), bulge: bulges[k] }
            })
            .collect();
        Contour { vertices, closed: true }
    }

    fn star_parts() -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
        (8usize..64).prop_flat_map(|n| {
            (
                prop::collection::vec(20.0f64..40.0, n),
                prop::collection::vec(prop_oneof![3 => Just(0.0), 1 => -0.25f64..0.25], n),
            )
        })
    }

    fn arc() -> impl Strategy<Value = Arc2> {
        let half = std::f64::consts::PI;
        let sweep = prop_oneof![-6.2f64..-0.01, 0.01f64..6.2, Just(half), Just(-half), Just(TAU), Just(1e-9)];
        (-5.0f64..5.0, -5.0f64..5.0, 0.1f64..5.0, -3.2f64..3.2, sweep).prop_map(|(x, y, r, start, sweep)| Arc2 {
            c: P2::new(x, y),
            r,
            start,
            sweep,
        })
    }

    fn piece() -> impl Strategy<Value = Seg> {
        prop_oneof![
            (-6.0f64..6.0, -6.0f64..6.0, -6.0f64..6.0, -6.0f64..6.0)
                .prop_map(|(a, b, c, d)| Seg::Line(P2::new(a, b), P2::new(c, d))),
            arc().prop_map(Seg::Arc),
        ]
    }

    #[test]
    fn covers_proves_a_deep_inward_offset_empty_and_nothing_less() {
        // A circle of radius 10: its centre is 10 from it, every other point of its box nearer.
        let circle = Contour::circle(P2::new(3.0, -2.0), 10.0, 0.4, true);
        let set = SegSet::new([&circle]);
        assert!(!set.covers(10.0 - 1e-6, 4096));
        assert!(set.covers(10.0 + 1e-6, 4096));
        // A 40 × 20 rectangle: its midline is 10 from the long sides. A ridge needs cells as
        // small as the margin all along it: too few cells give no proof, not a wrong one.
        let rect =
            Contour::polygon(&[P2::new(0.0, 0.0), P2::new(40.0, 0.0), P2::new(40.0, 20.0), P2::new(0.0, 20.0)], true);
        let set = SegSet::new([&rect]);
        assert!(!set.covers(10.0, 4096));
        assert!(set.covers(10.5, 4096));
        assert!(!set.covers(10.0 + 1e-3, 4096));
        assert!(!set.covers(10.5, 4));
    }

    #[test]
    fn deep_offsets_search_nearest_first_and_still_find_every_defect() {
        // A 1200-gon of circumradius 50 and its inward offset by 45 in closed form (the same
        // polygon, circumradius 50 − 45 / cos(π/n)): every group's box holds much of the input
        // (more than CROWD pieces), so each piece searches nearest first.
        let n = 1200;
        let gon = |r: f64| {
            let pts: Vec<P2> =
                (0..n).map(|k| TAU * k as f64 / n as f64).map(|a| P2::new(r * a.cos(), r * a.sin())).collect();
            Contour::polygon(&pts, true)
        };
        let (c, d) = (gon(50.0), 45.0);
        let out = [gon(50.0 - d / (std::f64::consts::PI / n as f64).cos())];
        let input = SegSet::new([&c]);
        let check = verify(&input, &out, d, 1.0, true, 1e-6, false, &[]).unwrap();
        assert!(check.deviation() < 1e-9, "{check:?}");
        for (d, want) in [(d - 1e-5, "stray"), (d + 1e-5, "gouge")] {
            match (verify(&input, &out, d, 1.0, true, 1e-6, false, &[]), want) {
                (Err(Defect::Stray(..)), "stray") | (Err(Defect::Gouge(..)), "gouge") => {}
                (r, _) => panic!("{want}: {r:?}"),
            }
        }
    }

    #[test]
    fn loops_touching_at_a_vertex_do_not_cross() {
        let square = |x: f64, y: f64| {
            Contour::polygon(
                &[P2::new(x, y), P2::new(x + 2.0, y), P2::new(x + 2.0, y + 2.0), P2::new(x, y + 2.0)],
                true,
            )
        };
        // Corner to corner at (2, 2): a touch, reported only by the strict test.
        let (a, b) = (square(0.0, 0.0), square(2.0, 2.0));
        let set = SegSet::new([&a, &b]);
        assert_eq!(set.first_crossing(), Some(P2::new(2.0, 2.0)));
        assert_eq!(set.first_meeting(1e-6), None);
        // Overlapping by 1 mm: their edges cross at (2, 1) and (1, 2), away from any corner.
        let c = square(1.0, 1.0);
        let x = SegSet::new([&a, &c]).first_meeting(1e-6).expect("a crossing");
        assert!((x - P2::new(2.0, 1.0)).norm() < 1e-12 || (x - P2::new(1.0, 2.0)).norm() < 1e-12, "{x}");
        // A corner on the other's edge: no shared vertex, a meeting.
        let d = square(2.0, 1.0);
        assert!(SegSet::new([&a, &d]).first_meeting(1e-6).is_some());
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

        /// The arc bounds never fall below the exact largest distance, and are exact for a round
        /// corner about a piece's end and for an arc concentric with a piece inside its span.
        #[test]
        fn arc_bound_is_an_upper_bound(a in arc(), t in piece(), k in 0.0f64..1.0, dr in -2.0f64..2.0) {
            let exact = Seg::Arc(a).max_distance_to(&t);
            let bound = arc_bound(&a, &t, (t.start(), t.end())).unwrap();
            prop_assert!(bound >= exact - 1e-12, "bound {bound} < exact {exact}");
            // A corner about an end of `t`.
            let corner = Arc2 { c: t.end(), ..a };
            let exact = Seg::Arc(corner).max_distance_to(&t);
            let bound = arc_bound(&corner, &t, (t.start(), t.end())).unwrap();
            prop_assert!(bound >= exact - 1e-12 && bound <= corner.r + 1e-12, "{bound} {exact}");
            // A concentric sub-arc.
            if let Seg::Arc(b) = t && b.r + dr > 0.05 {
                let sub = Arc2 { r: b.r + dr, start: b.start + k * 0.5 * b.sweep, sweep: 0.5 * b.sweep, c: b.c };
                let exact = Seg::Arc(sub).max_distance_to(&t);
                let bound = arc_bound(&sub, &t, (t.start(), t.end())).unwrap();
                prop_assert!(bound >= exact - 1e-12, "{bound} < {exact}");
                prop_assert!(bound - exact < 1e-9, "concentric bound {bound} vs exact {exact}");
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

        /// Where `covers` holds, every point of the box (a grid, by brute force over every piece)
        /// lies nearer than the reach, and the kernel's own verified offset is empty: the proof
        /// replaces the kernel run exactly.
        #[test]
        fn covers_agrees_with_brute_force_and_the_kernel((radii, bulges) in star_parts(), d in 15.0f64..45.0) {
            let c = star(&radii, &bulges);
            let set = SegSet::new([&c]);
            let reach = d - 1e-6;
            if set.covers(reach, 4096) {
                let (lo, hi) = set.extent().unwrap();
                for i in 0..=24 {
                    for j in 0..=24 {
                        let q = P2::new(lo.x + (hi.x - lo.x) * i as f64 / 24.0, lo.y + (hi.y - lo.y) * j as f64 / 24.0);
                        let near = set.segs.iter().map(|s| s.distance_to(&q)).fold(f64::INFINITY, f64::min);
                        prop_assert!(near < reach, "{q} is {near} from the star");
                    }
                }
                if let Ok(o) = offset_contour(&c, d, Side::Left, &OffsetOptions::default()) {
                    prop_assert!(o.contours.is_empty(), "the kernel found {} loops", o.contours.len());
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

        /// A pocket computes no level beyond the first one its cheap proof shows empty, and that
        /// changes no pass: the first such level is empty by the full offset too, and the pocket's
        /// passes per level are those of the region's offsets made level by level up to the first
        /// empty one.
        #[test]
        fn pocket_skips_only_empty_levels((radii, bulges) in star_parts(), radius in 0.5f64..3.0, step in 1.0f64..6.0) {
            use crate::contour::offset::{RegionPieces, offset_region};
            use crate::contour::pocket::{Direction, Passes, PocketOptions, pocket};
            let c = star(&radii, &bulges);
            // A spike's arc can leave its tip on the wrong side of the other flank: no region.
            prop_assume!(c.self_crossing().is_none());
            let (rs, _) = crate::contour::region::regions(std::slice::from_ref(&c)).unwrap();
            let opts = OffsetOptions::default();
            let distances: Vec<f64> = (0..48).map(|k| radius + k as f64 * step).collect();
            let mut levels: Vec<(usize, f64)> = Vec::new();
            for &d in &distances {
                let o = offset_region(&rs[0], d, &opts).unwrap_or_else(|e| panic!("{e}"));
                if o.contours.is_empty() {
                    break;
                }
                levels.push((o.contours.len(), o.contours.iter().map(Contour::area).sum()));
            }
            let first = RegionPieces::new(&rs[0]).first_empty_level(&distances, &opts);
            if let Some(k) = first {
                prop_assert!(k >= levels.len(), "level {k} proved empty, {} levels are not", levels.len());
                prop_assert!(offset_region(&rs[0], distances[k], &opts).unwrap().contours.is_empty());
            }
            let po = PocketOptions { radius, step, passes: Passes::UntilEmpty, direction: Direction::Climb, offset: opts };
            let p = pocket(&rs, &po).unwrap_or_else(|e| panic!("{e:?}"));
            for (k, (count, area)) in levels.iter().enumerate() {
                let at: Vec<&crate::contour::pocket::Pass> =
                    p.passes.iter().filter(|q| !q.clean_up && q.level == k).collect();
                prop_assert_eq!(at.len(), *count, "level {}", k);
                let sum: f64 = at.iter().map(|q| q.contour.area()).sum();
                prop_assert!((sum - area).abs() < 1e-9, "level {k}: area {sum} vs {area}");
            }
            prop_assert!(p.passes.iter().all(|q| q.clean_up || q.level < levels.len()));
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 2048, ..ProptestConfig::default() })]

        /// The fast distances (arc spans by cross products) equal the exact routines of
        /// `geom::dist` up to round-off, for every pair of pieces and every point.
        #[test]
        fn fast_distances_match_the_exact_routines(s in piece(), t in piece(), x in -8.0f64..8.0, y in -8.0f64..8.0,
                                                   touch in any::<bool>()) {
            // Also pieces that meet at an end, where the spans' edges decide.
            let t = if touch { match t { Seg::Line(_, b) => Seg::Line(s.end(), b), arc => arc } } else { t };
            let (fs, ft) = (Fast::new(&s), Fast::new(&t));
            let (fast, exact) = (fs.min(&ft), s.min_distance(&t));
            prop_assert!((fast - exact).abs() <= 1e-9, "min {fast} vs {exact}: {s:?} {t:?}");
            let p = P2::new(x, y);
            prop_assert!((fs.point(&p) - s.distance_to(&p)).abs() <= 1e-12, "point {p}: {s:?}");
            let end = s.end();
            prop_assert!((fs.point(&end) - s.distance_to(&end)).abs() <= 1e-12);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

        /// With the hints, arc bounds and fast distances and without them (every piece by the full
        /// search and `geom::dist`'s routines) the verification accepts and rejects the same
        /// offsets, with the same figures (`above` to round-off: another generator or a bound within round-off of d).
        #[test]
        fn shortcuts_agree_with_the_full_check((radii, bulges) in star_parts(), d in 0.5f64..6.0,
                                              left in any::<bool>(), skew in prop_oneof![Just(0.0), -3e-6f64..3e-6]) {
            let c = star(&radii, &bulges);
            let side = if left { Side::Left } else { Side::Right };
            let Ok(o) = offset_contour(&c, d, side, &OffsetOptions::default()) else { return Ok(()) };
            let input = SegSet::new([&c]);
            let spec = |shortcuts| Spec { d: d + skew, side: side.sign(), tol: 1e-6, shortcuts };
            let fast = verify_with(&input, &o.contours, &spec(true), true, false, &[]);
            let full = verify_with(&input, &o.contours, &spec(false), true, false, &[]);
            match (fast, full) {
                (Ok(f), Ok(g)) => {
                    prop_assert!((f.below - g.below).abs() <= tol::ROUNDOFF_ABS, "below {} vs {}", f.below, g.below);
                    prop_assert_eq!(f.pieces, g.pieces);
                    prop_assert!((f.above - g.above).abs() <= tol::ROUNDOFF_ABS, "above {} vs {}", f.above, g.above);
                }
                (Err(f), Err(g)) => prop_assert_eq!(std::mem::discriminant(&f), std::mem::discriminant(&g)),
                (f, g) => prop_assert!(false, "shortcuts {f:?} full {g:?}"),
            }
        }
    }
}
