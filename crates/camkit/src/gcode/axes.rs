//! A reader for multi-axis programs (X Y Z A B C), separate from the 3-axis reader so that reader
//! keeps returning what it always did. It understands what 5- and 6-axis posts write: G0/G1,
//! G20/G21, G90/G91, G93/G94 with F, G53 (machine coordinates for one block), G43/G43.4/G49 (tool
//! length and tool-centre-point modes), work offsets, `M19 R` (oriented spindle stop), N, T, S, H,
//! D words, `%`, a Fanuc `O` number, `( )` and `;` comments. Arcs, parameters, subroutines and
//! any G code it does not know are refused with the line and the word: a program it cannot read
//! exactly is not read at all.

use super::{Motion, Units};
use crate::error::{Error, Location, Result};

/// Index of each address in [`AxisMove::pos`].
pub const AXIS_LETTERS: [u8; 6] = [b'X', b'Y', b'Z', b'A', b'B', b'C'];

/// One motion block of a multi-axis program.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisMove {
    /// 1-based source line.
    pub line: u32,
    /// G0 or G1.
    pub motion: Motion,
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
    let mut prog = AxisProgram::default();
    let mut units = Units::Mm;
    let (mut relative, mut inverse_time, mut tcp) = (false, false, false);
    let mut motion: Option<Motion> = None;
    let mut feed: Option<f64> = None;
    let mut pos = [0.0; 6];
    let mut known = [false; 6];
    let mut orient: Option<f64> = None;
    for (idx, raw) in text.lines().enumerate() {
        let line_no = idx as u32 + 1;
        prog.lines += 1;
        let line = raw.trim_end_matches('\r');
        let trimmed = line.trim_start();
        if trimmed.is_empty() || trimmed.starts_with('%') || trimmed.starts_with('/') {
            continue;
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
                continue; // Fanuc program number.
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
                    0 | 10 => {
                        if block_motion.is_some() {
                            return Err(err(name, line_no, w.start, &word_text(w), "two motion codes in one block"));
                        }
                        block_motion = Some(if code == 0 { Motion::Rapid } else { Motion::Line });
                    }
                    20 | 30 => {
                        return Err(err(
                            name,
                            line_no,
                            w.start,
                            &word_text(w),
                            "arcs are not read by the multi-axis reader",
                        ));
                    }
                    200 => units = Units::Inch,
                    210 => units = Units::Mm,
                    900 => relative = false,
                    910 => relative = true,
                    930 => inverse_time = true,
                    940 => inverse_time = false,
                    530 => g53 = true,
                    434 => tcp = true,
                    490 => tcp = false,
                    800 => motion = None,
                    // Planes, cutter compensation off, tool length offset, exact stop and path
                    // modes, arc centre modes, work offsets: nothing that moves or scales a position.
                    170 | 180 | 190 | 400 | 430 | 610 | 611 | 640 | 901 | 911 | 150 | 690 | 540..=590 | 591..=593 => {}
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
                b'I' | b'J' | b'K' => {
                    return Err(err(
                        name,
                        line_no,
                        w.start,
                        &word_text(w),
                        "arcs are not read by the multi-axis reader",
                    ));
                }
                b'U' | b'V' | b'W' | b'E' => {
                    return Err(err(name, line_no, w.start, &word_text(w), "axis not read by the multi-axis reader"));
                }
                _ => {}
            }
        }
        if m19 {
            let r = ws.iter().find(|w| w.letter == b'R').map_or(0.0, |w| w.value);
            orient = Some(r);
            prog.orients += 1;
        } else if let Some(w) = ws.iter().find(|w| w.letter == b'R') {
            return Err(err(name, line_no, w.start, &word_text(w), "R is read only with M19"));
        }
        if let Some(w) = ws.iter().find(|w| w.letter == b'F') {
            if w.value <= 0.0 {
                return Err(err(name, line_no, w.start, &word_text(w), "feed must be positive"));
            }
            feed = Some(if inverse_time { w.value } else { w.value * units.mm() });
        }
        if let Some(m) = block_motion {
            motion = Some(m);
        }
        let named: [bool; 6] = std::array::from_fn(|k| ws.iter().any(|w| w.letter == AXIS_LETTERS[k]));
        if !named.iter().any(|n| *n) {
            if g53 {
                return Err(err(name, line_no, 0, line, "G53 without coordinates"));
            }
            if inverse_time && block_motion.is_none() {
                // A G93 F word that is not on a motion block does not carry to the next block.
                feed = None;
            }
            continue;
        }
        let Some(m) = motion else {
            return Err(err(name, line_no, 0, line, "coordinates without a motion mode (G0 or G1)"));
        };
        if g53 && relative {
            return Err(err(name, line_no, 0, line, "G53 in incremental mode (G91)"));
        }
        if m == Motion::Line && feed.is_none() {
            let what = if inverse_time {
                "a G1 block in inverse-time mode (G93) needs its own F word"
            } else {
                "G1 without a feed rate (F)"
            };
            return Err(err(name, line_no, 0, line, what));
        }
        let mut block_pos = pos;
        for w in &ws {
            if let Some(k) = AXIS_LETTERS.iter().position(|&l| l == w.letter) {
                let v = if k < 3 { w.value * units.mm() } else { w.value };
                block_pos[k] = if relative && !g53 {
                    if !known[k] {
                        return Err(err(
                            name,
                            line_no,
                            w.start,
                            &word_text(w),
                            "incremental move from an unknown position",
                        ));
                    }
                    pos[k] + v
                } else {
                    v
                };
            }
        }
        let n = ws.iter().find(|w| w.letter == b'N').map(|w| w.value as u64);
        let mut block_known = known;
        for k in 0..6 {
            block_known[k] |= named[k];
        }
        prog.moves.push(AxisMove {
            line: line_no,
            motion: m,
            pos: block_pos,
            known: block_known,
            named,
            machine_coords: g53,
            inverse_time,
            feed,
            tcp,
            orient,
            n,
        });
        if g53 {
            // After a move in machine coordinates the work position of the named axes is not known.
            for k in 0..6 {
                if named[k] {
                    known[k] = false;
                }
            }
        } else {
            pos = block_pos;
            known = block_known;
        }
        if inverse_time {
            feed = None;
        }
    }
    Ok(prog)
}

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

    #[test]
    fn refuses_what_it_cannot_read_exactly() {
        let e = read_axes("t.nc", "G0 X0 Y0\nG2 X1 Y1 I1 J0\n").unwrap_err();
        assert_eq!(e.to_string(), "t.nc:2:1 (G2): arcs are not read by the multi-axis reader");
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
