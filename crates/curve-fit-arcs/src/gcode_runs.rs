//! Fitting a G-code program: runs are consecutive plain G1 blocks with a known start and the same
//! feed, modes and extrusion rate; every other block is written back verbatim, in order.

use crate::fit::{Rounding, Shape};
use crate::segment::{self, Unfittable};
use crate::{FittedRun, Options, Stats, push_distinct};
use camkit::gcode::{Block, Modes, Motion, MoveBlock, OutMove, Program, Units, Writer};
use camkit::geom::{P2, P3};
use camkit::num::round_to;

/// How the program is written back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Format {
    /// Decimals of X, Y, Z (program units).
    pub decimals: u32,
    /// Decimals of I, J, K.
    pub centre_decimals: u32,
    /// Decimals of E.
    pub e_decimals: u32,
}

impl Format {
    /// The program's own precision: the most decimals its coordinates and E words use, at least
    /// 3 (4 for an inch program) for coordinates; arc centres one more.
    pub fn of(program: &Program) -> Format {
        let inch = program.blocks.iter().any(|b| b.modes().units == Units::Inch);
        let decimals = program.decimals.xyz.max(if inch { 4 } else { 3 });
        Format { decimals, centre_decimals: decimals + 1, e_decimals: program.decimals.e.max(1) }
    }
}

/// Rounding as the writer does it, in a run's modes.
struct Written<'a> {
    writer: &'a Writer,
    modes: &'a Modes,
}

impl Rounding for Written<'_> {
    fn point(&self, p: &P3) -> P3 {
        self.writer.readback3(p, self.modes.units)
    }
    fn centre(&self, c: &P2, start: &P2) -> P2 {
        self.writer.readback_centre(c, start, self.modes)
    }
}

/// A run that could not be fitted: the source line where it failed.
#[derive(Clone, Debug, PartialEq)]
pub struct GcodeError {
    /// Source line.
    pub line: u32,
    /// What failed.
    pub cause: Unfittable,
}

/// A block that may start a run.
fn can_start(m: &MoveBlock) -> bool {
    m.motion == Motion::Line && m.plain && m.start_known && m.e.is_none() == m.e_delta.is_none()
}

/// Extrusion per mm of a block.
fn e_rate(m: &MoveBlock) -> Option<f64> {
    let len = (m.end - m.start).norm();
    m.e_delta.filter(|_| len > 0.0).map(|e| e / len)
}

/// True if `m` may join the run whose first block is `head`.
fn continues(head: &MoveBlock, m: &MoveBlock, opts: &Options) -> bool {
    if !can_start(m) || m.modes != head.modes {
        return false;
    }
    // A zero-length block (a repeated point) joins only if it carries nothing.
    if (m.end - m.start).norm() <= camkit::tol::POINT_EPS {
        return m.e_delta.is_none_or(|e| e == 0.0);
    }
    match (e_rate(head), e_rate(m)) {
        (None, None) => head.e.is_none() && m.e.is_none(),
        (Some(a), Some(b)) => (a - b).abs() <= opts.e_rate_tol * a.abs().max(b.abs()),
        _ => false,
    }
}

/// Fits every run of `program` and writes the result; the fitted runs are returned too when
/// `keep_runs` (for a plot or the lower bound), otherwise their buffers are reused run to run.
pub fn fit_program(
    program: &Program,
    opts: &Options,
    format: Format,
    keep_runs: bool,
) -> Result<(Vec<u8>, Stats, Vec<FittedRun>), GcodeError> {
    let mut w = Writer::new(format.decimals, format.centre_decimals, format.e_decimals);
    w.out.reserve(program.source.len());
    let blocks = &program.blocks;
    let moves: Vec<Option<&MoveBlock>> =
        blocks.iter().map(|b| if let Block::Move(m) = b { Some(m) } else { None }).collect();
    let mut stats = Stats { input_moves: moves.iter().flatten().count(), ..Stats::default() };
    let mut runs = Vec::new();
    // Points of a run and the block index of each (buffers for all runs).
    let mut pts: Vec<P3> = Vec::new();
    let mut from: Vec<usize> = Vec::new();
    let mut scratch = segment::Scratch::default();
    let mut written = 0;
    let mut k = 0;
    while k < blocks.len() {
        let Some(head) = moves[k].filter(|m| can_start(m)) else {
            w.verbatim(program.text(&blocks[k]), &blocks[k]);
            written += usize::from(moves[k].is_some());
            k += 1;
            continue;
        };
        // The run: moves that continue it, with comment-only lines between them carried along.
        let mut end = k;
        let mut probe = k + 1;
        while probe < blocks.len() {
            match &blocks[probe] {
                Block::Other(o) if o.remark_only => probe += 1,
                Block::Move(m) if continues(head, m, opts) => {
                    end = probe;
                    probe += 1;
                }
                _ => break,
            }
        }
        pts.clear();
        from.clear();
        pts.push(head.start);
        from.push(k);
        for (i, m) in moves.iter().enumerate().take(end + 1).skip(k) {
            let Some(m) = m else { continue };
            if push_distinct(&mut pts, m.end) {
                from.push(i);
            } else {
                stats.dropped_repeats += 1;
            }
        }
        if pts.len() < 2 {
            // Only repeated points: nothing moves, nothing is written.
            k = end + 1;
            continue;
        }
        let rounding = Written { writer: &w, modes: &head.modes };
        let pieces = segment::segment_with(&pts, opts, &rounding, &mut scratch)
            .map_err(|cause| GcodeError { line: line_of(program, from[cause.at + 1]), cause })?;
        for p in pieces {
            // Blocks covered by the piece: from[p.first + 1] ..= from[p.last] (plus dropped repeats).
            let lo = if p.first == 0 { k } else { from[p.first] + 1 };
            let hi = from[p.last];
            let single = (lo..=hi).filter(|&i| moves[i].is_some()).count() == 1
                && p.shape == Shape::Line
                && p.end == pts[p.last]
                && p.start == pts[p.first];
            written += 1;
            if single {
                for b in &blocks[lo..=hi] {
                    w.verbatim(program.text(b), b);
                }
                continue;
            }
            let covered = || (lo..=hi).filter_map(|i| moves[i]);
            let e = head.e.map(|_| {
                if head.modes.e_relative {
                    round_to(covered().filter_map(|m| m.e).sum(), format.e_decimals)
                } else {
                    moves[hi].and_then(|m| m.e).unwrap_or(0.0)
                }
            });
            let (motion, centre, plane) = match p.shape {
                Shape::Line => (Motion::Line, None, head.modes.plane),
                Shape::Arc { centre, plane, ccw } => (if ccw { Motion::Ccw } else { Motion::Cw }, Some(centre), plane),
            };
            let out = OutMove {
                motion,
                start: Some(p.start),
                end: p.end,
                centre,
                plane,
                feed: covered().find(|m| m.has_f).and(head.modes.feed),
                e,
                n: moves[hi].and_then(|m| m.n),
            };
            w.motion(&out, &head.modes);
            // Comment lines among the piece's blocks follow it, in order.
            remarks(&mut w, program, lo, hi);
        }
        stats.points += pts.len();
        stats.add_pieces(pieces);
        if keep_runs {
            runs.push(FittedRun { pts: pts.clone(), pieces: pieces.to_vec() });
        }
        k = end + 1;
    }
    stats.output_moves = written;
    Ok((w.out, stats, runs))
}

/// Copies the comment-only blocks among `from..=to`.
fn remarks(w: &mut Writer, program: &Program, from: usize, to: usize) {
    for b in &program.blocks[from..=to] {
        if let Block::Other(o) = b
            && o.remark_only
        {
            w.verbatim(program.text(b), b);
        }
    }
}

fn line_of(program: &Program, block: usize) -> u32 {
    match &program.blocks[block] {
        Block::Move(m) => m.line,
        Block::Other(o) => o.line,
    }
}
