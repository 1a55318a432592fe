//! Fitting a G-code program: runs are consecutive plain G1 blocks with a known start and the same
//! feed, modes and extrusion rate; every other block is written back verbatim, in order.

use crate::fit::{Rounding, Shape};
use crate::segment::{self, Unfittable};
use crate::{FittedRun, Options, Stats, push_distinct};
use camkit::error::Error;
use camkit::gcode::{Block, Decimals, Modes, Motion, MoveBlock, OutMove, StreamBlocks, Writer};
use camkit::geom::{P2, P3};
use camkit::io::Restart;
use camkit::num::round_to;
use std::collections::VecDeque;
use std::io::{BufRead, Write};

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
    /// A program's own precision from the blocks read (their most decimals `seen`, whether any
    /// was in inch): the most decimals its coordinates and E
    /// words use, at least 3 (4 for an inch program) for coordinates; arc centres one more.
    pub fn of(seen: Decimals, inch: bool) -> Format {
        let decimals = seen.xyz.max(if inch { 4 } else { 3 });
        Format { decimals, centre_decimals: decimals + 1, e_decimals: seen.e.max(1) }
    }

    /// With coordinates written to `decimals` places instead (centres one more), if given.
    pub fn with_decimals(self, decimals: Option<u32>) -> Format {
        match decimals {
            Some(d) => Format { decimals: d, centre_decimals: d + 1, ..self },
            None => self,
        }
    }
}

/// Why a program could not be fitted: its text, or a run.
#[derive(Debug)]
pub enum ProgramError {
    /// The text is not a program the reader accepts.
    Read(camkit::error::Error),
    /// A run could not be fitted.
    Fit(GcodeError),
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

/// Lines read to guess the output's precision before the streaming pass.
const GUESS_LINES: usize = 2048;

/// Reads and fits a program in one streaming pass, holding one run at a time, never the whole
/// program, and writes the result to `out` run by run. `open` gives the program's text from its
/// start (it is read a second time when the first guess of the precision was wrong). The
/// output's precision depends on the whole program (its most decimals), so it is guessed from
/// the first lines and checked at the end; a wrong guess, or a run that failed under it, is done
/// again (`out` restarted) with the precision read from the whole program. `decimals` overrides
/// the coordinates'. The fitted runs are returned too when `keep_runs` (for a plot or the lower
/// bound), otherwise their buffers are reused run to run.
pub fn fit_source<R: BufRead>(
    name: &str,
    open: &mut dyn FnMut() -> camkit::error::Result<R>,
    out: &mut dyn Restart,
    opts: &Options,
    decimals: Option<u32>,
    keep_runs: bool,
) -> Result<(Stats, Vec<FittedRun>), ProgramError> {
    let mut lines = StreamBlocks::new(name, open().map_err(ProgramError::Read)?);
    // The first lines are kept, not read again, and fitted first.
    let mut first = VecDeque::with_capacity(GUESS_LINES);
    for b in lines.by_ref().take(GUESS_LINES) {
        first.push_back(b.map_err(ProgramError::Read)?);
    }
    let guess = Format::of(lines.decimals(), lines.inch()).with_decimals(decimals);
    match fit_blocks(&mut lines, first, out, opts, guess, keep_runs) {
        Ok(fitted) if Format::of(lines.decimals(), lines.inch()).with_decimals(decimals) == guess => {
            return Ok(fitted);
        }
        Err(ProgramError::Read(e)) => return Err(ProgramError::Read(e)),
        Ok(_) | Err(ProgramError::Fit(_)) => {}
    }
    // Read to its end for the whole program's precision (a failed run stopped the first pass).
    while let Some(b) = lines.next() {
        b.map_err(ProgramError::Read)?;
        lines.release(usize::MAX);
    }
    let format = Format::of(lines.decimals(), lines.inch()).with_decimals(decimals);
    out.restart().map_err(|e| ProgramError::Read(Error::io(e, "output")))?;
    let mut again = StreamBlocks::new(name, open().map_err(ProgramError::Read)?);
    fit_blocks(&mut again, VecDeque::new(), out, opts, format, keep_runs)
}

/// Fits every run of the blocks `pending` holds and then `lines` reads under `format` and
/// writes the result to `out`, run by run.
fn fit_blocks<R: BufRead>(
    lines: &mut StreamBlocks<'_, R>,
    mut pending: VecDeque<Block>,
    out: &mut dyn Write,
    opts: &Options,
    format: Format,
    keep_runs: bool,
) -> Result<(Stats, Vec<FittedRun>), ProgramError> {
    let mut w = Writer::new(format.decimals, format.centre_decimals, format.e_decimals);
    let mut stats = Stats::default();
    let mut input_moves = pending.iter().filter(|b| matches!(b, Block::Move(_))).count();
    let mut runs = Vec::new();
    // A run's blocks from its head (moves and the comment lines among them), blocks read past a
    // run's end to be looked at again (`pending`), the run's points and the window index of each.
    let mut window: Vec<Block> = Vec::new();
    let mut pts: Vec<P3> = Vec::new();
    let mut from: Vec<usize> = Vec::new();
    let mut scratch = segment::Scratch::default();
    let mut written = 0;
    let flush = |w: &mut Writer, out: &mut dyn Write| {
        out.write_all(&w.out).map_err(|e| ProgramError::Read(Error::io(e, "output")))?;
        w.out.clear();
        Ok::<(), ProgramError>(())
    };
    while let Some(block) = next(&mut pending, lines, &mut input_moves)? {
        // Text before the oldest block still held (this one; `pending` follows it) is not needed.
        lines.release(block.span().start);
        if w.out.len() >= 1 << 16 {
            flush(&mut w, out)?;
        }
        let head = match &block {
            Block::Move(m) if can_start(m) => m.clone(),
            _ => {
                w.verbatim(lines.text(block.span()), &block);
                written += usize::from(matches!(block, Block::Move(_)));
                continue;
            }
        };
        // The run: moves that continue it, with comment-only lines between them carried along.
        window.clear();
        window.push(block);
        let mut end = 0;
        while let Some(next) = next(&mut pending, lines, &mut input_moves)? {
            match &next {
                Block::Other(o) if o.remark_only => {}
                Block::Move(m) if continues(&head, m, opts) => end = window.len(),
                _ => {
                    pending.push_front(next);
                    break;
                }
            }
            window.push(next);
        }
        // Comment lines after the run's last move are read again after it, in order.
        for b in window.drain(end + 1..).rev() {
            pending.push_front(b);
        }
        let run = &window[..];
        pts.clear();
        from.clear();
        pts.push(head.start);
        from.push(0);
        for (i, b) in run.iter().enumerate() {
            let Block::Move(m) = b else { continue };
            if push_distinct(&mut pts, m.end) {
                from.push(i);
            } else {
                stats.dropped_repeats += 1;
            }
        }
        if pts.len() < 2 {
            // Only repeated points: nothing moves, nothing is written.
            continue;
        }
        let rounding = Written { writer: &w, modes: &head.modes };
        let pieces = segment::segment_with(&pts, opts, &rounding, &mut scratch)
            .map_err(|cause| ProgramError::Fit(GcodeError { line: line_of(&run[from[cause.at + 1]]), cause }))?;
        for p in pieces {
            // Blocks covered by the piece: from[p.first + 1] ..= from[p.last] (plus dropped repeats).
            let lo = if p.first == 0 { 0 } else { from[p.first] + 1 };
            let hi = from[p.last];
            let covered = || run[lo..=hi].iter().filter_map(as_move);
            let single =
                covered().count() == 1 && p.shape == Shape::Line && p.end == pts[p.last] && p.start == pts[p.first];
            written += 1;
            if single {
                for b in &run[lo..=hi] {
                    w.verbatim(lines.text(b.span()), b);
                }
                continue;
            }
            let e = head.e.map(|_| {
                if head.modes.e_relative {
                    round_to(covered().filter_map(|m| m.e).sum(), format.e_decimals)
                } else {
                    as_move(&run[hi]).and_then(|m| m.e).unwrap_or(0.0)
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
                n: as_move(&run[hi]).and_then(|m| m.n),
            };
            w.motion(&out, &head.modes);
            // Comment lines among the piece's blocks follow it, in order.
            remarks(&mut w, lines, &run[lo..=hi]);
        }
        stats.points += pts.len();
        stats.add_pieces(pieces);
        if keep_runs {
            runs.push(FittedRun { pts: pts.clone(), pieces: pieces.to_vec(), extrusion: e_rate(&head) });
        }
    }
    flush(&mut w, out)?;
    stats.input_moves = input_moves;
    stats.output_moves = written;
    Ok((stats, runs))
}

/// The next block: one read before and held in `pending`, or a new one from `lines` (counted in
/// `input_moves` if a move).
fn next<R: BufRead>(
    pending: &mut VecDeque<Block>,
    lines: &mut StreamBlocks<'_, R>,
    input_moves: &mut usize,
) -> Result<Option<Block>, ProgramError> {
    if let Some(b) = pending.pop_front() {
        return Ok(Some(b));
    }
    let block = lines.next().transpose().map_err(ProgramError::Read)?;
    *input_moves += usize::from(matches!(block, Some(Block::Move(_))));
    Ok(block)
}

/// The motion block, if `b` is one.
fn as_move(b: &Block) -> Option<&MoveBlock> {
    if let Block::Move(m) = b { Some(m) } else { None }
}

/// Copies the comment-only blocks among `blocks`.
fn remarks<R: BufRead>(w: &mut Writer, lines: &StreamBlocks<'_, R>, blocks: &[Block]) {
    for b in blocks {
        if let Block::Other(o) = b
            && o.remark_only
        {
            w.verbatim(lines.text(b.span()), b);
        }
    }
}

fn line_of(block: &Block) -> u32 {
    match block {
        Block::Move(m) => m.line,
        Block::Other(o) => o.line,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `lines` moves along a zigzag with 3 decimals, then `tail`.
    fn program(lines: usize, tail: &str) -> String {
        let mut text = String::from("G21 G90\nG0 X0 Y0 Z0\nG1 F600\n");
        for k in 1..=lines {
            text += &format!("G1 X{}.125 Y{}\n", k, (k % 2) * 3);
        }
        text + tail
    }

    fn fit(text: &str, opts: &Options, decimals: Option<u32>) -> (String, Stats) {
        let mut out = Vec::new();
        let Ok((stats, _)) = fit_source("t.nc", &mut || Ok(text.as_bytes()), &mut out, opts, decimals, false) else {
            panic!("fit failed")
        };
        (String::from_utf8(out).unwrap(), stats)
    }

    #[test]
    fn precision_seen_only_after_the_guess_is_used_for_the_whole_program() {
        let text = program(GUESS_LINES + 100, "G1 X9000.12345 Y1\nG1 X9001.5 Y2\n");
        let opts = Options::default();
        let (out, stats) = fit(&text, &opts, None);
        // The whole program's precision (5 decimals), as with the decimals given up front.
        assert_eq!(out, fit(&text, &opts, Some(5)).0);
        assert!(out.contains("X9000.12345"), "{}", &out[out.len() - 80..]);
        assert_eq!(stats.input_moves, GUESS_LINES + 103);
        // A short program is guessed whole: the same precision.
        let short = program(10, "G1 X20.12345 Y1\n");
        assert_eq!(fit(&short, &opts, None).0, fit(&short, &opts, Some(5)).0);
    }

    #[test]
    fn a_run_that_fails_only_under_the_guessed_precision_is_fitted_again() {
        // Rounded to the first lines' 3 decimals, 0.00037 mm moves the end farther than --tol.
        let text = program(GUESS_LINES + 10, "G1 X9000.00037 Y0\nG1 X9000.10037 Y0.5\nG1 X9000.20037 Y1\n");
        let opts = Options { tol: 0.0002, ..Options::default() };
        let (out, stats) = fit(&text, &opts, None);
        assert!(out.contains("X9000.00037"), "{}", &out[out.len() - 120..]);
        assert!(stats.largest_deviation <= opts.tol);
        let err = fit_source("t.nc", &mut || Ok(text.as_bytes()), &mut Vec::new(), &opts, Some(3), false).err();
        assert!(
            matches!(err, Some(ProgramError::Fit(GcodeError { line, .. })) if line as usize == GUESS_LINES + 14),
            "{err:?}"
        );
    }

    #[test]
    fn a_bad_word_anywhere_is_the_reader_s_error() {
        let text = program(GUESS_LINES + 10, "G1 X1 Q\n");
        let mut open = || Ok(text.as_bytes());
        let Some(ProgramError::Read(e)) =
            fit_source("t.nc", &mut open, &mut Vec::new(), &Options::default(), None, false).err()
        else {
            panic!("a read error expected")
        };
        assert!(e.to_string().contains(&format!("t.nc:{}", GUESS_LINES + 14)), "{e}");
    }
}
