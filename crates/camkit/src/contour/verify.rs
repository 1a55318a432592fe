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
use cavalier_contours::static_aabb2d_index::{StaticAABB2DIndex, StaticAABB2DIndexBuilder};
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
    prev: Vec<Option<usize>>,
    next: Vec<Option<usize>>,
    index: Option<StaticAABB2DIndex<f64>>,
}

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
        let index = (!segs.is_empty()).then(|| {
            let mut b = StaticAABB2DIndexBuilder::new(segs.len());
            for s in &segs {
                let (lo, hi) = s.bounds();
                b.add(lo.x, lo.y, hi.x, hi.y);
            }
            b.build().expect("as many boxes as declared")
        });
        SegSet { segs, prev, next, index }
    }

    /// Indices of pieces whose bounds meet the box `lo..hi` grown by `grow`.
    pub fn near(&self, lo: &P2, hi: &P2, grow: f64) -> Vec<usize> {
        match &self.index {
            Some(ix) => ix.query(lo.x - grow, lo.y - grow, hi.x + grow, hi.y + grow),
            None => Vec::new(),
        }
    }

    /// Distance from `p` to the nearest piece, looking no farther than `reach` (∞ beyond it).
    pub fn distance(&self, p: &P2, reach: f64) -> f64 {
        self.near(p, p, reach).into_iter().map(|i| self.segs[i].distance_to(p)).fold(f64::INFINITY, f64::min)
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

/// Measures one output piece: (largest distance above `d`, shortfall below `d`) or a defect.
fn check_piece(input: &SegSet, s: &Seg, d: f64, side: f64, tol: f64, depth: u32) -> Result<(f64, f64), Defect> {
    let (lo, hi) = s.bounds();
    let near = input.near(&lo, &hi, d + tol);
    let mid = s.point_at(0.5);
    let mut clearance = f64::INFINITY;
    for &i in &near {
        clearance = clearance.min(s.min_distance(&input.segs[i]));
    }
    if clearance < d - tol {
        return Err(Defect::Gouge(mid, clearance));
    }
    // The generator: the nearest input pieces first, the first one that covers the piece.
    let mut order: Vec<(f64, usize)> = near.iter().map(|&i| (input.segs[i].distance_to(&mid), i)).collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best = f64::INFINITY;
    for &(dm, i) in &order {
        if dm > d + tol {
            break;
        }
        let far = s.max_distance_to(&input.segs[i]);
        best = best.min(far);
        if far <= d + tol {
            if input.side(i, &mid) * side <= 0.0 {
                return Err(Defect::WrongSide(mid));
            }
            return Ok(((far - d).max(0.0), (d - clearance).max(0.0)));
        }
    }
    if depth < 4 && s.length() > tol {
        let a = check_piece(input, &s.sub(0.0, 0.5), d, side, tol, depth + 1)?;
        let b = check_piece(input, &s.sub(0.5, 1.0), d, side, tol, depth + 1)?;
        return Ok((a.0.max(b.0), a.1.max(b.1)));
    }
    Err(Defect::Stray(mid, best))
}

/// Verifies that `output` is the offset of `input` by `d` (mm, > 0) to `side` (+1 left, −1
/// right of each input piece) within `tol`; `closed` requires every output loop to be closed.
pub(crate) fn verify(
    input: &SegSet,
    output: &[Contour],
    d: f64,
    side: f64,
    closed: bool,
    tol: f64,
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
    let crossing: Option<P2> = (0..output.len())
        .into_par_iter()
        .filter_map(|i| {
            let a = &output[i];
            if let Some(p) = a.self_crossing() {
                return Some(p);
            }
            let (alo, ahi) = a.bounds()?;
            output[i + 1..].iter().find_map(|b| {
                let (blo, bhi) = b.bounds()?;
                let overlap = alo.x <= bhi.x && blo.x <= ahi.x && alo.y <= bhi.y && blo.y <= ahi.y;
                if overlap { a.crossing_with(b) } else { None }
            })
        })
        .find_first(|_| true);
    if let Some(p) = crossing {
        return Err(Defect::Crossing(p));
    }
    Ok(check)
}
