//! Cutting a run of points into pieces: the fewest-moves search, and paper 004's curvature
//! grouping for comparison.

use crate::fit::{self, Job, Piece, Rounding, Tangent};
use crate::{Method, Options};
use camkit::geom::{P3, circle};

/// Why a run could not be cut within the tolerance.
#[derive(Clone, Debug, PartialEq)]
pub struct Unfittable {
    /// Index of the point whose chord alone exceeds the tolerance once rounded.
    pub at: usize,
    /// That chord's deviation (mm).
    pub deviation: f64,
}

/// Cuts `pts` (one run, no repeated points) into pieces that each stay within `opts.tol`.
pub fn segment(pts: &[P3], opts: &Options, rounding: &dyn Rounding) -> Result<Vec<Piece>, Unfittable> {
    let mut scratch = Scratch::default();
    segment_with(pts, opts, rounding, &mut scratch)?;
    Ok(scratch.pieces)
}

/// Buffers of a segmentation, kept between runs: a program of many short runs otherwise spends
/// a tenth of its time allocating and freeing them.
#[derive(Debug, Default)]
pub struct Scratch {
    corners: Vec<bool>,
    written: Vec<P3>,
    next_stop: Vec<usize>,
    pieces: Vec<Piece>,
}

/// [`segment`] into `scratch`'s buffers; the pieces are borrowed from it until the next call.
pub fn segment_with<'s>(
    pts: &[P3],
    opts: &Options,
    rounding: &dyn Rounding,
    scratch: &'s mut Scratch,
) -> Result<&'s [Piece], Unfittable> {
    scratch.pieces.clear();
    if pts.len() < 2 {
        return Ok(&scratch.pieces);
    }
    corners(pts, opts.corner, opts.tol, &mut scratch.corners);
    scratch.written.clear();
    scratch.written.extend(pts.iter().map(|p| rounding.point(p)));
    let run = Run { pts, written: &scratch.written, corners: &scratch.corners };
    match opts.method {
        Method::Fewest => fewest(&run, opts, rounding, &mut scratch.next_stop, &mut scratch.pieces)?,
        Method::Paper => paper(&run, opts, rounding, &mut scratch.pieces)?,
    }
    Ok(&scratch.pieces)
}

/// A run's points, as given and as written, and where it turns a corner.
struct Run<'a> {
    pts: &'a [P3],
    written: &'a [P3],
    corners: &'a [bool],
}

/// `true` at the interior points where the path turns by more than `limit` radians between
/// two chords longer than `tol`: a corner seen at the tolerance's scale. (A jog of a few microns
/// in a noisy program turns sharply too, but it is noise a fit may smooth within `tol`.)
fn corners(pts: &[P3], limit: f64, tol: f64, out: &mut Vec<bool>) {
    let cos_limit = limit.cos();
    out.clear();
    out.resize(pts.len(), false);
    for k in 1..pts.len() - 1 {
        let a = pts[k] - pts[k - 1];
        let b = pts[k + 1] - pts[k];
        let (la, lb) = (a.norm(), b.norm());
        // The turn exceeds `limit` when cos(turn) = a·b / (|a| |b|) is below cos(limit).
        out[k] = la > tol && lb > tol && a.dot(&b) < cos_limit * la * lb;
    }
}

/// The tangent the piece after `prev` must follow.
fn tangent_after(prev: Option<&Piece>, corners: &[bool], opts: &Options) -> Option<Tangent> {
    let max_angle = opts.tangent?;
    let prev = prev?;
    if corners[prev.last] {
        return None;
    }
    let plane = opts.planes[0];
    let dir = prev.end_tangent(plane)?;
    Some(Tangent { dir, max_angle, plane })
}

/// Where the piece after `prev` starts, as written.
fn start_after(prev: Option<&Piece>, run: &Run) -> P3 {
    prev.map_or(run.written[0], |p| p.end)
}

/// The shortest single move from `first`: one chord to the next point, as a line.
fn single(run: &Run, first: usize, start: P3, opts: &Options) -> Result<Piece, Unfittable> {
    let relaxed = Options { tol: f64::INFINITY, ..opts.clone() };
    let (pts, written) = (run.pts, run.written);
    let job = Job { pts, written, first, last: first + 1, start, tangent: None, thorough: false };
    let piece = fit::line(&job, &relaxed).ok_or(Unfittable { at: first, deviation: f64::INFINITY })?;
    if piece.deviation > opts.tol {
        return Err(Unfittable { at: first, deviation: piece.deviation });
    }
    Ok(piece)
}

/// Greedy longest valid piece from each start. A cheap probe ([`fit::probe`]) finds the farthest
/// end that seems to fit (a first try at the previous piece's length, then galloping and binary
/// search); that end is measured exactly, and if the measure disagrees an exact binary search
/// runs below it. Then a short look past the end, measured exactly with minimax centres too
/// (validity is not always monotone in the end index). When validity is monotone (any piece
/// inside a valid one is valid), greedy longest-first is optimal for the number of pieces.
/// `next_stop` is a buffer; the pieces are appended to `pieces`.
fn fewest(
    run: &Run,
    opts: &Options,
    rounding: &dyn Rounding,
    next_stop: &mut Vec<usize>,
    pieces: &mut Vec<Piece>,
) -> Result<(), Unfittable> {
    const LOOK_PAST: usize = 3;
    let (pts, written, corners) = (run.pts, run.written, run.corners);
    let n = pts.len();
    // A piece never spans a corner: the first corner (or the end) after each point.
    next_stop.clear();
    next_stop.resize(n, n - 1);
    for k in (1..n - 1).rev() {
        next_stop[k - 1] = if corners[k] { k } else { next_stop[k] };
    }
    let mut first = 0;
    while first < n - 1 {
        let limit = next_stop[first];
        let tangent = tangent_after(pieces.last(), corners, opts);
        let start = start_after(pieces.last(), run);
        let job = |last: usize, thorough: bool| Job { pts, written, first, last, start, tangent, thorough };
        let exact = |last: usize, thorough: bool| fit::best(&job(last, thorough), opts, rounding);
        let probe = |last: usize| fit::probe(&job(last, false), opts);
        let guess = pieces.last().map(|p| first + (p.last - p.first));
        let reach = farthest(first + 1, limit, guess, probe);
        // Measure the probe's answer; if it does not hold, search below it exactly.
        let mut good = match exact(reach, false) {
            Some(p) => p,
            None => {
                let floor = match exact(first + 1, false) {
                    Some(p) => p,
                    // Tangent continuity cannot hold here (a turn below the corner angle): start afresh.
                    None => single(run, first, start, opts)?,
                };
                let (mut lo, mut hi, mut good) = (first + 1, reach, floor);
                while hi - lo > 1 {
                    let mid = lo + (hi - lo) / 2;
                    match exact(mid, false) {
                        Some(p) => {
                            good = p;
                            lo = mid;
                        }
                        None => hi = mid,
                    }
                }
                good
            }
        };
        // Look past the end: a few points further, and the next point with a minimax centre.
        let lo = good.last;
        let further = (lo + 2..=(lo + 1 + LOOK_PAST).min(limit)).rev().find_map(|j| exact(j, false));
        if let Some(p) = further.or_else(|| (lo < limit).then(|| exact(lo + 1, true)).flatten()) {
            good = p;
        }
        first = good.last;
        pieces.push(good);
    }
    Ok(())
}

/// The largest `j` in `lo..=limit` for which `fits(j)` holds, assuming it holds at `lo` and is
/// mostly monotone: a first try at `guess`, then galloping and binary search.
fn farthest(lo: usize, limit: usize, guess: Option<usize>, fits: impl Fn(usize) -> bool) -> usize {
    let (mut lo, mut hi) = (lo, None);
    if let Some(g) = guess.map(|g| g.min(limit)).filter(|&g| g > lo) {
        if fits(g) {
            lo = g;
        } else {
            hi = Some(g);
        }
    }
    let mut step = 1;
    while hi.is_none() && lo < limit {
        let j = (lo + step).min(limit);
        if fits(j) {
            lo = j;
            step *= 2;
        } else {
            hi = Some(j);
        }
    }
    if let Some(mut hi) = hi {
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if fits(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
    }
    lo
}

/// Paper 004 §2: the curvature of each point from the circle through it and its neighbours;
/// consecutive points at or over the threshold are grouped and approximated by arcs, those under
/// it by lines; a group is split where a point strays beyond the tolerance. The pieces are
/// appended to `pieces`.
fn paper(run: &Run, opts: &Options, rounding: &dyn Rounding, pieces: &mut Vec<Piece>) -> Result<(), Unfittable> {
    let (pts, written, corners) = (run.pts, run.written, run.corners);
    let n = pts.len();
    let plane = opts.planes[0];
    let flat: Vec<_> = pts.iter().map(|p| plane.split(p).0).collect();
    let mut curved = vec![false; n];
    for k in 1..n - 1 {
        curved[k] = circle::curvature(&flat[k - 1], &flat[k], &flat[k + 1]).abs() >= opts.curvature_threshold;
    }
    if n > 2 {
        curved[0] = curved[1];
        curved[n - 1] = curved[n - 2];
    }
    let mut first = 0;
    while first < n - 1 {
        // The group: points of the same class as `first`, up to a corner.
        let mut end = first + 1;
        while end < n - 1 && curved[end] == curved[first] && !corners[end] {
            end += 1;
        }
        let tangent = tangent_after(pieces.last(), corners, opts);
        let start = start_after(pieces.last(), run);
        // The paper's pieces run through the points: every end is a point.
        let try_fit = |last: usize| {
            let job = Job { pts, written, first, last, start, tangent, thorough: true };
            if curved[first] { fit::arc(&job, plane, opts, rounding) } else { fit::line(&job, opts) }
        };
        let mut good = match try_fit(first + 1) {
            Some(p) => p,
            None => single(run, first, start, opts)?,
        };
        for last in first + 2..=end {
            match try_fit(last) {
                Some(p) => good = p,
                None => break,
            }
        }
        first = good.last;
        pieces.push(good);
    }
    Ok(())
}
