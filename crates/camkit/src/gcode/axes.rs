//! A reader for multi-axis programs (X Y Z A B C), separate from the 3-axis reader so that reader
//! keeps returning what it always did. It understands what 5- and 6-axis posts write: G0/G1,
//! G2/G3 in G17/G18/G19 (I/J/K centres, incremental or with G90.1 absolute, R radii, P turns; the
//! rotary axes standing still), G20/G21, G90/G91, G93/G94 with F, G53 (machine coordinates for
//! one block), G43/G43.4/G49 (tool length and tool-centre-point modes), work offsets, `M19 R`
//! (oriented spindle stop), N, T, S, H, D words, `%`, a Fanuc `O` number, `( )` and `;` comments.
//! Parameters, subroutines and any G code it does not know are refused with the line and the
//! word: a program it cannot read exactly is not read at all.

use super::{Motion, Units};
use crate::error::{Error, Location, Result};
use crate::geom::{Arc2, P2, P3, Plane};

/// Index of each address in [`AxisMove::pos`].
pub const AXIS_LETTERS: [u8; 6] = [b'X', b'Y', b'Z', b'A', b'B', b'C'];

/// The circle of a G2/G3 block: plane, centre (mm, in the plane's coordinates), direction and
/// whole turns beyond the first (P − 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisArc {
    /// G17, G18 or G19.
    pub plane: Plane,
    /// Centre in the plane's (u, v) coordinates (mm).
    pub centre: P2,
    /// G3.
    pub ccw: bool,
    /// Extra full turns.
    pub turns: u32,
}

impl AxisArc {
    /// The arc in plane coordinates from `a` to `b` (X, Y, Z), turns included, and the normal
    /// coordinates at both ends.
    pub fn in_plane(&self, a: &P3, b: &P3) -> (Arc2, f64, f64) {
        let (pa, wa) = self.plane.split(a);
        let (pb, wb) = self.plane.split(b);
        let mut arc = Arc2::from_centre(self.centre, &pa, &pb, self.ccw, true);
        arc.sweep += arc.sweep.signum() * std::f64::consts::TAU * f64::from(self.turns);
        (arc, wa, wb)
    }

    /// X, Y, Z at fraction `t` of the move from `a` to `b` (the normal coordinate linear).
    pub fn point(&self, a: &P3, b: &P3, t: f64) -> P3 {
        let (arc, wa, wb) = self.in_plane(a, b);
        self.plane.join(&arc.point_at_fraction(t), wa + (wb - wa) * t)
    }
}

/// One motion block of a multi-axis program.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisMove {
    /// 1-based source line.
    pub line: u32,
    /// G0, G1, G2 or G3.
    pub motion: Motion,
    /// The circle of a G2/G3 block.
    pub arc: Option<AxisArc>,
    /// X, Y, Z (mm) and A, B, C (degrees) after the block, as programmed (work coordinates, or
    /// machine coordinates when `machine_coords`).
    pub pos: [f64; 6],
    /// Which of `pos` have been given by some block so far.
    pub known: [bool; 6],
    /// Which addresses this block names.
    pub named: [bool; 6],
    /// G53 on this block: `pos` are machine coordinates for this block only.
    pub machine_coords: bool,
    /// G93 in effect: `feed` is inverse time (1/min).
    pub inverse_time: bool,
    /// F in effect: mm/min (G94) or 1/min (G93); `None` before any F or, in G93, when the block
    /// has no F word.
    pub feed: Option<f64>,
    /// G43.4 (tool-centre-point mode) in effect.
    pub tcp: bool,
    /// Angle of the last `M19 R` before this block (degrees), if any.
    pub orient: Option<f64>,
    /// N block number.
    pub n: Option<u64>,
}

/// A multi-axis program: its motion blocks and the oriented spindle stops between them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AxisProgram {
    /// Motion blocks in order.
    pub moves: Vec<AxisMove>,
    /// Number of `M19` blocks.
    pub orients: usize,
    /// Number of lines.
    pub lines: usize,
}

struct Word {
    letter: u8,
    value: f64,
    start: usize,
    end: usize,
}

fn err(name: &str, line: u32, col: usize, word: &str, message: &str) -> Error {
    Error::input(message).at(Location::file(name).line(u64::from(line)).column(col as u64 + 1).field(word))
}

/// Splits a line into words; comments are dropped.
fn words(name: &str, line_no: u32, line: &str) -> Result<Vec<Word>> {
    let b = line.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        match c {
            b' ' | b'\t' => i += 1,
            b'(' => match line[i..].find(')') {
                Some(k) => i += k + 1,
                None => return Err(err(name, line_no, i, &line[i..], "comment is not closed with `)`")),
            },
            b';' => break,
            _ if c.is_ascii_alphabetic() => {
                let letter = c.to_ascii_uppercase();
                let mut j = i + 1;
                while j < b.len() && (b[j] == b' ' || b[j] == b'\t') {
                    j += 1;
                }
                let start = j;
                if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
                    j += 1;
                }
                while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'.') {
                    j += 1;
                }
                let text = &line[start..j];
                let end_word = |from: usize| {
                    from + line[from..]
                        .find(|ch: char| ch.is_whitespace() || ch == '(' || ch == ';')
                        .unwrap_or(line.len() - from)
                };
                if matches!(b.get(start), Some(b'#' | b'[')) {
                    return Err(err(
                        name,
                        line_no,
                        i,
                        &line[i..end_word(start)],
                        "parameters and expressions are not supported",
                    ));
                }
                let value = crate::num::parse_finite(text)
                    .ok()
                    .filter(|_| text.bytes().any(|d| d.is_ascii_digit()) && text.matches('.').count() <= 1)
                    .ok_or_else(|| {
                        err(
                            name,
                            line_no,
                            i,
                            &line[i..end_word(start)],
                            "malformed word: a letter must be followed by a number",
                        )
                    })?;
                if let Some(&next) = b.get(j)
                    && !(next.is_ascii_alphabetic() || matches!(next, b' ' | b'\t' | b'(' | b';'))
                {
                    return Err(err(name, line_no, i, &line[i..end_word(j)], "malformed word"));
                }
                out.push(Word { letter, value, start: i, end: j });
                i = j;
            }
            _ => {
                let end = i + line[i..].find(char::is_whitespace).unwrap_or(line.len() - i);
                return Err(err(name, line_no, i, &line[i..end], "unknown word"));
            }
        }
    }
    Ok(out)
}

/// Reads a multi-axis program. `name` is used in error messages.
pub fn read_axes(name: &str, text: &str) -> Result<AxisProgram> {
    let mut blocks = AxisBlocks::new(name, text.as_bytes());
    let moves = blocks.by_ref().collect::<Result<Vec<AxisMove>>>()?;
    Ok(AxisProgram { moves, orients: blocks.orients, lines: blocks.lines })
}

/// The modes and positions in effect between blocks.
#[derive(Clone, Copy, Debug)]
struct State {
    units: Units,
    relative: bool,
    inverse_time: bool,
    tcp: bool,
    motion: Option<Motion>,
    plane: Plane,
    absolute_centres: bool,
    feed: Option<f64>,
    pos: [f64; 6],
    known: [bool; 6],
    orient: Option<f64>,
}

/// The motion blocks of a multi-axis program read from a stream one at a time, as
/// [`read_axes`] reads them (the same blocks and the same errors at the same lines), holding one
/// line: a program of any length is read back in constant memory. Text that is not UTF-8 is an
/// error naming its line.
#[derive(Debug)]
pub struct AxisBlocks<'a, R> {
    name: &'a str,
    src: R,
    state: State,
    buf: Vec<u8>,
    failed: bool,
    /// `M19` blocks read so far.
    pub orients: usize,
    /// Lines read so far.
    pub lines: usize,
}

impl<'a, R: std::io::BufRead> AxisBlocks<'a, R> {
    /// A reader of `src`; `name` is used in error messages.
    pub fn new(name: &'a str, src: R) -> AxisBlocks<'a, R> {
        AxisBlocks {
            name,
            src,
            state: State {
                units: Units::Mm,
                relative: false,
                inverse_time: false,
                tcp: false,
                motion: None,
                plane: Plane::Xy,
                absolute_centres: false,
                feed: None,
                pos: [0.0; 6],
                known: [false; 6],
                orient: None,
            },
            buf: Vec::new(),
            failed: false,
            orients: 0,
            lines: 0,
        }
    }

    /// The block of one line, if it moves.
    fn line(&mut self, line_no: u32, raw: &str) -> Result<Option<AxisMove>> {
        let name = self.name;
        let mut st = self.state;
        let block = self.step(&mut st, name, line_no, raw);
        self.state = st;
        block
    }

    fn step(&mut self, st: &mut State, name: &str, line_no: u32, raw: &str) -> Result<Option<AxisMove>> {
        self.lines += 1;
        let line = raw.trim_end_matches('\r');
        let trimmed = line.trim_start();
        if trimmed.is_empty() || trimmed.starts_with('%') || trimmed.starts_with('/') {
            return Ok(None);
        }
        let ws = words(name, line_no, line)?;
        let word_text = |w: &Word| line[w.start..w.end].to_string();
        let mut seen = [false; 26];
        for w in &ws {
            let k = usize::from(w.letter - b'A');
            if !matches!(w.letter, b'G' | b'M') && seen[k] {
                return Err(err(name, line_no, w.start, &word_text(w), "word appears twice in one block"));
            }
            seen[k] = true;
        }
        if ws.first().is_some_and(|w| w.letter == b'O') {
            if ws.len() == 1 {
                return Ok(None); // Fanuc program number.
            }
            return Err(err(
                name,
                line_no,
                ws[0].start,
                &word_text(&ws[0]),
                "o-codes (subroutines, loops) are not supported",
            ));
        }
        let (mut block_motion, mut g53, mut m19) = (None, false, false);
        for w in &ws {
            let code = (w.value * 10.0).round() as i64;
            match w.letter {
                b'G' => match code {
                    0 | 10 | 20 | 30 => {
                        if block_motion.is_some() {
                            return Err(err(name, line_no, w.start, &word_text(w), "two motion codes in one block"));
                        }
                        block_motion = Some(match code {
                            0 => Motion::Rapid,
                            10 => Motion::Line,
                            20 => Motion::Cw,
                            _ => Motion::Ccw,
                        });
                    }
                    170 => st.plane = Plane::Xy,
                    180 => st.plane = Plane::Xz,
                    190 => st.plane = Plane::Yz,
                    901 => st.absolute_centres = true,
                    911 => st.absolute_centres = false,
                    200 => st.units = Units::Inch,
                    210 => st.units = Units::Mm,
                    900 => st.relative = false,
                    910 => st.relative = true,
                    930 => st.inverse_time = true,
                    940 => st.inverse_time = false,
                    530 => g53 = true,
                    434 => st.tcp = true,
                    490 => st.tcp = false,
                    800 => st.motion = None,
                    // Cutter compensation off, tool length offset, exact stop and path modes, work
                    // offsets: nothing that moves or scales a position.
                    400 | 430 | 610 | 611 | 640 | 150 | 690 | 540..=590 | 591..=593 => {}
                    _ => {
                        return Err(err(
                            name,
                            line_no,
                            w.start,
                            &word_text(w),
                            "G code not read by the multi-axis reader",
                        ));
                    }
                },
                b'M' if code == 190 => m19 = true,
                b'U' | b'V' | b'W' | b'E' => {
                    return Err(err(name, line_no, w.start, &word_text(w), "axis not read by the multi-axis reader"));
                }
                _ => {}
            }
        }
        if m19 {
            let r = ws.iter().find(|w| w.letter == b'R').map_or(0.0, |w| w.value);
            st.orient = Some(r);
            self.orients += 1;
        }
        if let Some(w) = ws.iter().find(|w| w.letter == b'F') {
            if w.value <= 0.0 {
                return Err(err(name, line_no, w.start, &word_text(w), "feed must be positive"));
            }
            st.feed = Some(if st.inverse_time { w.value } else { w.value * st.units.mm() });
        }
        if let Some(m) = block_motion {
            st.motion = Some(m);
        }
        let named: [bool; 6] = std::array::from_fn(|k| ws.iter().any(|w| w.letter == AXIS_LETTERS[k]));
        // A full circle names no axis: its centre words make it a move.
        let circle =
            st.motion.is_some_and(Motion::is_arc) && ws.iter().any(|w| matches!(w.letter, b'I' | b'J' | b'K' | b'R'));
        if !named.iter().any(|n| *n) && !circle {
            if g53 {
                return Err(err(name, line_no, 0, line, "G53 without coordinates"));
            }
            if st.inverse_time && block_motion.is_none() {
                // A G93 F word that is not on a motion block does not carry to the next block.
                st.feed = None;
            }
            return Ok(None);
        }
        let Some(m) = st.motion else {
            return Err(err(name, line_no, 0, line, "coordinates without a motion mode (G0 or G1)"));
        };
        if g53 && st.relative {
            return Err(err(name, line_no, 0, line, "G53 in incremental mode (G91)"));
        }
        if m == Motion::Line && st.feed.is_none() {
            let what = if st.inverse_time {
                "a G1 block in inverse-time mode (G93) needs its own F word"
            } else {
                "G1 without a feed rate (F)"
            };
            return Err(err(name, line_no, 0, line, what));
        }
        let mut block_pos = st.pos;
        for w in &ws {
            if let Some(k) = AXIS_LETTERS.iter().position(|&l| l == w.letter) {
                let v = if k < 3 { w.value * st.units.mm() } else { w.value };
                block_pos[k] = if st.relative && !g53 {
                    if !st.known[k] {
                        return Err(err(
                            name,
                            line_no,
                            w.start,
                            &word_text(w),
                            "incremental move from an unknown position",
                        ));
                    }
                    st.pos[k] + v
                } else {
                    v
                };
            }
        }
        let n = ws.iter().find(|w| w.letter == b'N').map(|w| w.value as u64);
        let arc = if m.is_arc() {
            Some(arc_of(
                name,
                line_no,
                line,
                &ws,
                m,
                st.plane,
                st.absolute_centres,
                st.units,
                &st.pos,
                &st.known,
                &block_pos,
            )?)
        } else {
            if let Some(w) = ws.iter().find(|w| matches!(w.letter, b'I' | b'J' | b'K') || (w.letter == b'R' && !m19)) {
                return Err(err(name, line_no, w.start, &word_text(w), "I, J, K and R belong to arcs (G2, G3)"));
            }
            None
        };
        let mut block_known = st.known;
        for k in 0..6 {
            block_known[k] |= named[k];
        }
        let block = AxisMove {
            line: line_no,
            motion: m,
            arc,
            pos: block_pos,
            known: block_known,
            named,
            machine_coords: g53,
            inverse_time: st.inverse_time,
            feed: st.feed,
            tcp: st.tcp,
            orient: st.orient,
            n,
        };
        if g53 {
            // After a move in machine coordinates the work position of the named axes is not known.
            for (known, named) in st.known.iter_mut().zip(named) {
                if named {
                    *known = false;
                }
            }
        } else {
            st.pos = block_pos;
            st.known = block_known;
        }
        if st.inverse_time {
            st.feed = None;
        }
        Ok(Some(block))
    }
}

impl<R: std::io::BufRead> Iterator for AxisBlocks<'_, R> {
    type Item = Result<AxisMove>;

    fn next(&mut self) -> Option<Result<AxisMove>> {
        while !self.failed {
            self.buf.clear();
            let read = self.src.read_until(b'\n', &mut self.buf);
            let line_no = self.lines as u32 + 1;
            let at = || Location::file(self.name).line(u64::from(line_no));
            let text = match read {
                Ok(0) => return None,
                Ok(_) => match std::str::from_utf8(&self.buf) {
                    Ok(t) => Ok(t.strip_suffix('\n').unwrap_or(t).to_string()),
                    Err(_) => Err(Error::input("text is not valid UTF-8").at(at())),
                },
                Err(e) => Err(Error::io(e, self.name)),
            };
            let block = match text {
                Ok(text) => self.line(line_no, &text),
                Err(e) => Err(e),
            };
            match block {
                Ok(None) => {}
                Ok(Some(b)) => return Some(Ok(b)),
                Err(e) => {
                    self.failed = true;
                    return Some(Err(e));
                }
            }
        }
        None
    }
}

/// The circle of a G2/G3 block: from the centre words I/J/K (offsets from the start, or absolute
/// with G90.1) or the radius R (positive: at most half a turn; negative: more), and P turns.
#[allow(clippy::too_many_arguments)]
fn arc_of(
    name: &str,
    line_no: u32,
    line: &str,
    ws: &[Word],
    m: Motion,
    plane: Plane,
    absolute_centres: bool,
    units: Units,
    pos: &[f64; 6],
    known: &[bool; 6],
    end: &[f64; 6],
) -> Result<AxisArc> {
    let word_text = |w: &Word| line[w.start..w.end].to_string();
    let whole = |message: &str| err(name, line_no, 0, line, message);
    if !known[..3].iter().all(|k| *k) {
        return Err(whole("an arc from an unknown position"));
    }
    if let Some(w) = ws.iter().find(|w| matches!(w.letter, b'A' | b'B' | b'C')) {
        return Err(err(name, line_no, w.start, &word_text(w), "an arc with a rotary axis moving is not read"));
    }
    let [iu, iv, iw] = plane.axes();
    let letter = |k: usize| b"IJK"[k];
    if let Some(w) = ws.iter().find(|w| w.letter == letter(iw)) {
        return Err(err(
            name,
            line_no,
            w.start,
            &word_text(w),
            "a centre word across the arc's plane (G17: I J, G18: I K, G19: J K)",
        ));
    }
    let start = P3::new(pos[0], pos[1], pos[2]);
    let stop = P3::new(end[0], end[1], end[2]);
    let (a, _) = plane.split(&start);
    let (b, _) = plane.split(&stop);
    let ccw = m == Motion::Ccw;
    let turns = match ws.iter().find(|w| w.letter == b'P') {
        None => 0,
        Some(w) if w.value >= 1.0 && w.value.fract() == 0.0 => w.value as u32 - 1,
        Some(w) => {
            return Err(err(name, line_no, w.start, &word_text(w), "P of an arc is a whole number of turns ≥ 1"));
        }
    };
    let centre_words: Vec<&Word> = ws.iter().filter(|w| w.letter == letter(iu) || w.letter == letter(iv)).collect();
    let radius = ws.iter().find(|w| w.letter == b'R');
    let centre = match (radius, centre_words.is_empty()) {
        (Some(w), true) => {
            let r = w.value * units.mm();
            let d = (b - a).norm();
            if d == 0.0 || d > 2.0 * r.abs() * (1.0 + 1e-9) {
                return Err(err(
                    name,
                    line_no,
                    w.start,
                    &word_text(w),
                    "no arc of this radius joins the start and the end",
                ));
            }
            let h = (r * r - 0.25 * d * d).max(0.0).sqrt();
            let mid = P2::from((a.coords + b.coords) * 0.5);
            let left = crate::geom::V2::new(a.y - b.y, b.x - a.x) / d;
            // The centre on the side that makes the arc the shorter one for R > 0.
            let side = if ccw == (r > 0.0) { 1.0 } else { -1.0 };
            mid + left * (side * h)
        }
        (Some(w), false) => {
            return Err(err(name, line_no, w.start, &word_text(w), "an arc has a radius R or centre words, not both"));
        }
        (None, _) => {
            let offset = |k: usize| ws.iter().find(|w| w.letter == letter(k)).map_or(0.0, |w| w.value * units.mm());
            let (ou, ov) = (offset(iu), offset(iv));
            if centre_words.is_empty() {
                return Err(whole("an arc needs its centre (I, J, K) or radius (R)"));
            }
            if absolute_centres { P2::new(ou, ov) } else { P2::new(a.x + ou, a.y + ov) }
        }
    };
    let (r0, r1) = ((a - centre).norm(), (b - centre).norm());
    if r0 == 0.0 || (r0 - r1).abs() > ARC_RADIUS_SLACK.max(r0 * 1e-6) {
        return Err(whole(&format!("the arc's ends are {r0:.6} and {r1:.6} mm from its centre: not one circle")));
    }
    Ok(AxisArc { plane, centre, ccw, turns })
}

/// How far apart the start and end radii of an arc read may be (mm): the rounding of the words
/// of a written program, with margin.
pub const ARC_RADIUS_SLACK: f64 = 0.002;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_rotary_words_modes_and_orientation() {
        let text = "%\nO0001 (demo)\nG21 G90 G54\nG0 X1 Y2 Z3 A4 C5\nM19 R45.5\nG93 G1 X2 A10 C20 F100\nG1 X3 F50\nG94 G1 X4 F500\nG53 G0 Z0\nG20 G91 G1 X1 C90\nM30\n%\n";
        let p = read_axes("t.nc", text).unwrap();
        assert_eq!(p.moves.len(), 6);
        assert_eq!(p.orients, 1);
        assert_eq!(p.moves[0].pos, [1.0, 2.0, 3.0, 4.0, 0.0, 5.0]);
        assert_eq!(p.moves[0].known, [true, true, true, true, false, true]);
        assert_eq!(p.moves[0].orient, None);
        let m = &p.moves[1];
        assert!(m.inverse_time && m.feed == Some(100.0) && m.orient == Some(45.5));
        assert_eq!(m.pos, [2.0, 2.0, 3.0, 10.0, 0.0, 20.0]);
        assert_eq!(p.moves[3].feed, Some(500.0));
        assert!(p.moves[4].machine_coords);
        assert_eq!(p.moves[4].pos[2], 0.0);
        assert_eq!(p.moves[5].pos[0], 4.0 + 25.4);
        assert_eq!(p.moves[5].pos[5], 110.0);
        let e = read_axes("t.nc", "G0 X0\nG91 G0 B1\n").unwrap_err();
        assert!(e.to_string().contains("unknown position"), "{e}");
    }

    /// Arcs in each plane by centre words, absolute centres, radii of both signs and turns: the
    /// centre and the points along them as RS274 defines them.
    #[test]
    fn reads_arcs() {
        let text = "G0 X10 Y0 Z0\nG3 X0 Y10 I-10 J0 F100\nG2 X10 Y0 R-10\nG2 I-10 P2 Z-3\n\
                    G18 G3 X0 Z7 I-10 K0\nG90.1 G19 G2 Y2 Z5 J0 K5\n";
        let p = read_axes("t.nc", text).unwrap();
        let arcs: Vec<AxisArc> = p.moves.iter().filter_map(|m| m.arc).collect();
        assert_eq!(arcs.len(), 5);
        let at = |k: usize| {
            let (a, b) = (&p.moves[k], &p.moves[k + 1]);
            let p3 = |m: &AxisMove| P3::new(m.pos[0], m.pos[1], m.pos[2]);
            (p3(a), p3(b), b.arc.unwrap())
        };
        // G3 a quarter: through (10/√2, 10/√2).
        let (a, b, arc) = at(0);
        assert!((arc.point(&a, &b, 0.5) - P3::new(50f64.sqrt(), 50f64.sqrt(), 0.0)).norm() < 1e-12);
        // G2 R−10 back to (10, 0): the long way, three quarters about (10, 10).
        let (a, b, arc) = at(1);
        assert!((arc.centre - P2::new(10.0, 10.0)).norm() < 1e-12, "{arc:?}");
        assert!((arc.in_plane(&a, &b).0.sweep + 1.5 * std::f64::consts::PI).abs() < 1e-12);
        // A full circle twice down 3 mm: half-way is the start, 1.5 mm down.
        let (a, b, arc) = at(2);
        assert_eq!(arc.turns, 1);
        assert!((arc.point(&a, &b, 0.5) - P3::new(10.0, 0.0, -1.5)).norm() < 1e-9);
        // G18: (u, v) = (z, x); from (10, 0, −3) about (z, x) = (−3, 0) to (0, 0, 7).
        let (_, _, arc) = at(3);
        assert_eq!((arc.plane, arc.centre), (Plane::Xz, P2::new(-3.0, 0.0)));
        let (_, _, arc) = at(4);
        assert_eq!((arc.plane, arc.centre, arc.ccw), (Plane::Yz, P2::new(0.0, 5.0), false));
    }

    /// Read from a stream a line at a time, a program gives the blocks, counts and errors of the
    /// whole text read at once, CRLF and a last line without its end included; text that stops
    /// being UTF-8 is refused naming its line.
    #[test]
    fn streamed_blocks_are_the_whole_reading() {
        let text = "%\r\nG21 G90\r\nG0 X1 Y2 Z3 A4 C5\nM19 R45.5\nG93 G1 X2 A10 C20 F100\n\nG94 G1 X4 F500\n\
                    G0 X10 Y0 Z0\nG3 X0 Y10 I-10 J0 F100\nG53 G0 Z0\nG1 X3 F50";
        let whole = read_axes("t.nc", text).unwrap();
        let mut blocks = AxisBlocks::new("t.nc", std::io::BufReader::with_capacity(7, text.as_bytes()));
        let moves: Vec<AxisMove> = blocks.by_ref().map(|b| b.unwrap()).collect();
        assert_eq!(moves, whole.moves);
        assert_eq!((blocks.orients, blocks.lines), (whole.orients, whole.lines));
        assert_eq!((whole.moves.len(), whole.lines), (7, 11));
        let bad = "G0 X0\nG1 X1 F10\nG1 X1 X2\nG1 X3\n";
        let streamed: Vec<Result<AxisMove>> = AxisBlocks::new("t.nc", bad.as_bytes()).collect();
        assert_eq!(streamed.len(), 3, "reading stops at the error");
        let e = streamed[2].as_ref().unwrap_err();
        assert_eq!(e.to_string(), read_axes("t.nc", bad).unwrap_err().to_string());
        let e = AxisBlocks::new("t.nc", &b"G0 X0\nG0 X\xff\n"[..]).find_map(|b| b.err()).unwrap();
        assert!(e.to_string().starts_with("t.nc:2") && e.to_string().contains("UTF-8"), "{e}");
    }

    #[test]
    fn refuses_what_it_cannot_read_exactly() {
        let e = read_axes("t.nc", "G0 X0 Y0 Z0\nG2 X1 Y1 I2 J0 F100\n").unwrap_err();
        assert!(e.to_string().contains("not one circle"), "{e}");
        let e = read_axes("t.nc", "G0 X0 Y0 Z0\nG2 X1 Y1 A3 I1 F100\n").unwrap_err();
        assert!(e.to_string().contains("rotary axis moving"), "{e}");
        let e = read_axes("t.nc", "G0 X0 Y0 Z0\nG1 X1 Y1 I1 F100\n").unwrap_err();
        assert!(e.to_string().contains("belong to arcs"), "{e}");
        let e = read_axes("t.nc", "G93\nG1 X1 F10\nG1 X2\n").unwrap_err();
        assert!(e.to_string().contains("needs its own F word"), "{e}");
        let e = read_axes("t.nc", "X1\n").unwrap_err();
        assert!(e.to_string().contains("without a motion mode"), "{e}");
        let e = read_axes("t.nc", "G1 X1\n").unwrap_err();
        assert!(e.to_string().contains("without a feed rate"), "{e}");
        let e = read_axes("t.nc", "G0 X1 A#1\n").unwrap_err();
        assert!(e.to_string().contains("parameters"), "{e}");
        let e = read_axes("t.nc", "G0 X1 X2\n").unwrap_err();
        assert!(e.to_string().contains("twice"), "{e}");
        let e = read_axes("t.nc", "G68 X0 Y0 R30\n").unwrap_err();
        assert!(e.to_string().contains("G68"), "{e}");
        let e = read_axes("t.nc", "G0 X1.2.3\n").unwrap_err();
        assert!(e.to_string().contains("malformed"), "{e}");
    }
}
