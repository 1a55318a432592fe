//! The proof of an offset: every output piece measured against the input with exact distances.
//!
//! For each output piece: no input piece comes closer than `d − tol` (no gouge); some input piece
//! (its generator) is within `d + tol` of every point of it (it lies on the offset, not beside
//! it), after splitting the piece if no single generator covers it; it lies on the requested side
//! of its generator. Then the input is probed for stretches the output missed: the raw offset
//! point of every input piece's middle that is a valid offset point must lie on the output.
//! Finally the output loops must not cross themselves or each other.

use super::{Contour, Seg};
use crate::geom::{P2, V2, cross2};
use cavalier_contours::static_aabb2d_index::{Control, StaticAABB2DIndex, StaticAABB2DIndexBuilder};
use rayon::prelude::*;

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
        }
    }
}

/// Pieces of several contours with a spatial index and their neighbours along each contour.
pub(crate) struct SegSet {
    pub segs: Vec<Seg>,
    /// A circle around each piece (centre, radius): a cheap lower bound of distances.
    circles: Vec<(P2, f64)>,
    prev: Vec<Option<usize>>,
    next: Vec<Option<usize>>,
    /// Runs of consecutive pieces: (circle around them, first piece, one past the last).
    chunks: Vec<(P2, f64, usize, usize)>,
    /// Spatial index of the runs' bounds.
    index: Option<StaticAABB2DIndex<f64>>,
}

/// Pieces per run of the index: runs far from a query are passed over by one circle test.
const CHUNK: usize = 16;

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
        let circles: Vec<(P2, f64)> = segs.iter().map(circle_of).collect();
        // Runs never cross from one contour to the next.
        let mut chunks = Vec::new();
        let mut bounds = Vec::new();
        let mut start = 0;
        while start < segs.len() {
            let mut end = start + 1;
            while end < segs.len() && end - start < CHUNK && prev[end] == Some(end - 1) {
                end += 1;
            }
            let (mut lo, mut hi) = segs[start].bounds();
            for s in &segs[start + 1..end] {
                let (a, b) = s.bounds();
                lo = P2::new(lo.x.min(a.x), lo.y.min(a.y));
                hi = P2::new(hi.x.max(b.x), hi.y.max(b.y));
            }
            let c = P2::from((lo.coords + hi.coords) * 0.5);
            chunks.push((c, 0.5 * (hi - lo).norm(), start, end));
            bounds.push((lo, hi));
            start = end;
        }
        let index = (!chunks.is_empty()).then(|| {
            let mut b = StaticAABB2DIndexBuilder::new(bounds.len());
            for (lo, hi) in &bounds {
                b.add(lo.x, lo.y, hi.x, hi.y);
            }
            b.build().expect("as many boxes as declared")
        });
        SegSet { segs, circles, prev, next, chunks, index }
    }

    /// True if pieces `i` and `j` follow each other along their contour.
    pub fn adjacent(&self, i: usize, j: usize) -> bool {
        self.next[i] == Some(j) || self.prev[i] == Some(j)
    }

    /// First point where two pieces that do not follow each other meet: a crossing or a touch.
    pub fn first_crossing(&self) -> Option<P2> {
        (0..self.segs.len())
            .into_par_iter()
            .filter_map(|i| {
                let s = &self.segs[i];
                let (lo, hi) = s.bounds();
                let (cs, rs) = self.circles[i];
                self.near(&lo, &hi, 0.0).into_iter().find_map(|j| {
                    if j <= i || self.adjacent(i, j) {
                        return None;
                    }
                    let (ct, rt) = self.circles[j];
                    if (cs - ct).norm() > rs + rt {
                        return None;
                    }
                    let t = &self.segs[j];
                    (s.min_distance(t) == 0.0).then(|| meeting_point(s, t))
                })
            })
            .find_first(|_| true)
    }

    /// Indices of pieces that may come within `grow` of the box `lo..hi` (by their circles).
    pub fn near(&self, lo: &P2, hi: &P2, grow: f64) -> Vec<usize> {
        let mut out = Vec::new();
        let Some(ix) = &self.index else { return out };
        let c = P2::from((lo.coords + hi.coords) * 0.5);
        let r = 0.5 * (hi - lo).norm() + grow;
        for k in ix.query(lo.x - grow, lo.y - grow, hi.x + grow, hi.y + grow) {
            let (cc, rc, a, b) = self.chunks[k];
            if (cc - c).norm() > r + rc {
                continue;
            }
            out.extend((a..b).filter(|&i| {
                let (ci, ri) = self.circles[i];
                (ci - c).norm() <= r + ri
            }));
        }
        out
    }

    /// Distance from `p` to the nearest piece, looking no farther than `reach` (∞ beyond it).
    /// Runs are visited nearest first and the search stops at the first run farther than the best
    /// distance so far: a probe near one part of a large contour never walks the rest of it.
    pub fn distance(&self, p: &P2, reach: f64) -> f64 {
        let mut best = f64::INFINITY;
        let Some(ix) = &self.index else { return best };
        let _: Control<()> = ix.visit_neighbors(p.x, p.y, &mut |k: usize, d2: f64| {
            if d2.sqrt() > reach.min(best) {
                return Control::Break(());
            }
            let (_, _, a, b) = self.chunks[k];
            for i in a..b {
                let (c, r) = self.circles[i];
                if (p - c).norm() - r < best {
                    best = best.min(self.segs[i].distance_to(p));
                }
            }
            Control::Continue
        });
        best
    }

    /// Side of `q` relative to piece `i` (positive left), deciding at a corner by both pieces
    /// that meet there.
    fn side(&self, i: usize, q: &P2) -> f64 {
        let s = &self.segs[i];
        if let Some(v) = s.side_of(q) {
            return v;
        }
        let (ds, de) = ((q - s.start()).norm(), (q - s.end()).norm());
        let (v, t_in, t_out) = if de <= ds {
            (s.end(), Some(s.tangent_at(1.0)), self.next[i].map(|j| self.segs[j].tangent_at(0.0)))
        } else {
            (s.start(), self.prev[i].map(|j| self.segs[j].tangent_at(1.0)), Some(s.tangent_at(0.0)))
        };
        let w: V2 = q - v;
        t_in.iter().chain(t_out.iter()).map(|t| cross2(t, &w)).sum()
    }
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

/// A circle around a piece: the middle and half the length of a line; the box's for an arc.
fn circle_of(s: &Seg) -> (P2, f64) {
    match s {
        Seg::Line(a, b) => (P2::from((a.coords + b.coords) * 0.5), 0.5 * (b - a).norm()),
        Seg::Arc(_) => {
            let (lo, hi) = s.bounds();
            (P2::from((lo.coords + hi.coords) * 0.5), 0.5 * (hi - lo).norm())
        }
    }
}

/// Measures one output piece: (largest distance above `d`, shortfall below `d`) or a defect.
fn check_piece(input: &SegSet, s: &Seg, d: f64, side: f64, tol: f64, depth: u32) -> Result<(f64, f64), Defect> {
    let (lo, hi) = s.bounds();
    let mid = s.point_at(0.5);
    let (cs, rs) = circle_of(s);
    let mut clearance = f64::INFINITY;
    // Candidates for the generator: (distance from the middle, index).
    let mut cands: Vec<(f64, usize)> = Vec::new();
    for i in input.near(&lo, &hi, d + tol) {
        let (ct, rt) = input.circles[i];
        let bound = (cs - ct).norm() - rs - rt;
        if bound > d + tol {
            continue;
        }
        let t = &input.segs[i];
        if bound < d - tol {
            clearance = clearance.min(s.min_distance(t));
        }
        cands.push((t.distance_to(&mid), i));
    }
    if clearance < d - tol {
        return Err(Defect::Gouge(mid, clearance));
    }
    let clearance = clearance.min(d);
    let mut best = f64::INFINITY;
    // The nearest first: nearly always the generator.
    if let Some(&(_, i)) = cands.iter().min_by(|a, b| a.0.total_cmp(&b.0)) {
        let far = s.max_distance_to(&input.segs[i]);
        best = far;
        if far <= d + tol {
            return sided(input, i, &mid, side).map(|_| ((far - d).max(0.0), (d - clearance).max(0.0)));
        }
    }
    cands.sort_by(|a, b| a.0.total_cmp(&b.0));
    for &(dm, i) in cands.iter().skip(1) {
        if dm > d + tol {
            break;
        }
        let far = s.max_distance_to(&input.segs[i]);
        best = best.min(far);
        if far <= d + tol {
            return sided(input, i, &mid, side).map(|_| ((far - d).max(0.0), (d - clearance).max(0.0)));
        }
    }
    if depth < 4 && s.length() > tol {
        let a = check_piece(input, &s.sub(0.0, 0.5), d, side, tol, depth + 1)?;
        let b = check_piece(input, &s.sub(0.5, 1.0), d, side, tol, depth + 1)?;
        return Ok((a.0.max(b.0), a.1.max(b.1)));
    }
    Err(Defect::Stray(mid, best))
}

/// Checks that `q` lies on `side` of its generator, piece `i`.
fn sided(input: &SegSet, i: usize, q: &P2, side: f64) -> Result<(), Defect> {
    if input.side(i, q) * side <= 0.0 { Err(Defect::WrongSide(*q)) } else { Ok(()) }
}

/// Verifies that `output` is the offset of `input` by `d` (mm, > 0) to `side` (+1 left, −1
/// right of each input piece) within `tol`; `closed` requires every output loop to be closed.
/// `crossing_input` lets output loops cross (the offset of a self-crossing input crosses too).
pub(crate) fn verify(
    input: &SegSet,
    output: &[Contour],
    d: f64,
    side: f64,
    closed: bool,
    tol: f64,
    crossing_input: bool,
) -> Result<Check, Defect> {
    for c in output {
        if closed && !c.closed {
            return Err(Defect::Open(c.vertices.first().map_or(P2::origin(), |v| v.p)));
        }
    }
    let pieces: Vec<Seg> = output.iter().flat_map(|c| c.segs()).collect();
    let measured: Vec<Result<(f64, f64), Defect>> =
        pieces.par_iter().map(|s| check_piece(input, s, d, side, tol, 0)).collect();
    let mut check = Check { distance: d, pieces: pieces.len(), ..Check::default() };
    for m in measured {
        let (above, below) = m?;
        check.above = check.above.max(above);
        check.below = check.below.max(below);
    }
    // Completeness: valid raw offset points of the input's pieces lie on the output.
    let out = SegSet::new(output);
    let missing: Option<P2> = (0..input.segs.len())
        .into_par_iter()
        .filter_map(|i| {
            let t = &input.segs[i];
            if t.length() <= tol {
                return None;
            }
            let tangent = t.tangent_at(0.5);
            let c = t.point_at(0.5) + V2::new(-tangent.y, tangent.x) * (side * d);
            let valid = input.distance(&c, d) >= d - 0.25 * tol;
            (valid && out.distance(&c, tol) > tol).then_some(c)
        })
        .find_first(|_| true);
    if let Some(c) = missing {
        return Err(Defect::Missing(c));
    }
    // No output loop crosses itself or another.
    if !crossing_input && let Some(p) = out.first_crossing() {
        return Err(Defect::Crossing(p));
    }
    Ok(check)
}
