//! The G-code reader: one pass over the bytes, words parsed to exact decimals, modal state
//! tracked, every line kept as a block.

use super::{Block, Modes, Motion, MoveBlock, OtherBlock, Program, Units};
use crate::error::{Error, Location, Result};
use crate::geom::{P2, P3, Plane, V2};

/// Most decimals seen in the program's words, per kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Decimals {
    /// X, Y, Z, I, J, K, R.
    pub xyz: u32,
    /// E.
    pub e: u32,
}

/// One word of a block: letter, value, where it sits in the line.
#[derive(Clone, Copy, Debug)]
struct Word {
    letter: u8,
    value: f64,
    decimals: u32,
    start: usize,
    end: usize,
}

/// How far apart (mm) an arc's start and end radii may be, as LinuxCNC allows (0.002 inch), when
/// they also differ by more than 0.1 %.
const ARC_RADIUS_SLACK_MM: f64 = 0.0508;

/// Exact powers of ten.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20,
    1e21, 1e22,
];

/// Parses a G-code number at `line[i..]`: optional sign, digits, at most one point. Returns the
/// value (correctly rounded), the index after it and its number of decimals.
fn parse_number(line: &[u8], mut i: usize) -> Option<(f64, usize, u32)> {
    let start = i;
    let neg = match line.get(i) {
        Some(b'-') => {
            i += 1;
            true
        }
        Some(b'+') => {
            i += 1;
            false
        }
        _ => false,
    };
    // `frac` counts decimals kept in the mantissa, `decimals` all digits after the point.
    let (mut mantissa, mut digits, mut frac, mut decimals, mut dot) = (0u64, 0u32, 0u32, 0u32, false);
    while let Some(&c) = line.get(i) {
        if c.is_ascii_digit() {
            if digits < 19 {
                mantissa = mantissa * 10 + u64::from(c - b'0');
                if dot {
                    frac += 1;
                }
            }
            digits += 1;
            if dot {
                decimals += 1;
            }
        } else if c == b'.' && !dot {
            dot = true;
        } else {
            break;
        }
        i += 1;
    }
    if digits == 0 {
        return None;
    }
    let value = if digits <= 19 && mantissa < (1u64 << 53) && (frac as usize) < POW10.len() {
        mantissa as f64 / POW10[frac as usize]
    } else {
        std::str::from_utf8(&line[start..i]).ok()?.parse::<f64>().ok()?.abs()
    };
    Some((if neg { -value } else { value }, i, decimals))
}

/// True for a line that is only a program number: `O` and digits, then nothing but spaces and
/// comments (the first line of a Fanuc program after `%`).
fn program_number(line: &[u8]) -> bool {
    let s = String::from_utf8_lossy(line);
    let t = s.trim_start();
    let Some(rest) = t.strip_prefix(['O', 'o']) else { return false };
    let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
    let tail = rest[digits..].trim();
    digits > 0 && (tail.is_empty() || (tail.starts_with('(') && tail.ends_with(')') && tail.matches('(').count() == 1))
}

/// The M code of a block that starts with an M word (after an optional N word).
fn m_led(line: &[u8]) -> Option<u32> {
    let mut i = 0;
    let skip_space = |i: &mut usize| {
        while *i < line.len() && line[*i].is_ascii_whitespace() {
            *i += 1;
        }
    };
    skip_space(&mut i);
    if i < line.len() && line[i].eq_ignore_ascii_case(&b'N') {
        i += 1;
        while i < line.len() && line[i].is_ascii_digit() {
            i += 1;
        }
        skip_space(&mut i);
    }
    if i < line.len() && line[i].eq_ignore_ascii_case(&b'M') {
        let digits: String = line[i + 1..].iter().take_while(|c| c.is_ascii_digit()).map(|&c| c as char).collect();
        return digits.parse().ok();
    }
    None
}

/// Reads a whole program. `name` is used in error messages.
pub fn read(name: &str, source: String) -> Result<Program> {
    let mut lines = Blocks::new(name, &source);
    let mut blocks = Vec::with_capacity(source.len() / 24 + 1);
    for block in lines.by_ref() {
        blocks.push(block?);
    }
    let decimals = lines.decimals();
    Ok(Program { source, blocks, decimals })
}

/// The blocks of a program text, one per line, read as they are asked for: a filter that
/// streams need not hold them all (a block is 176 bytes; a 2 MB printer file has 90 000).
/// The first error ends the sequence.
pub struct Blocks<'a> {
    reader: Reader<'a>,
    bytes: &'a [u8],
    line_start: usize,
    line_no: u32,
    words: Vec<Word>,
    decimals: Decimals,
    inch: bool,
    failed: bool,
}

impl<'a> Blocks<'a> {
    /// Blocks of `source`; `name` is used in error messages.
    pub fn new(name: &'a str, source: &'a str) -> Blocks<'a> {
        Blocks {
            reader: Reader::new(name),
            bytes: source.as_bytes(),
            // A byte order mark some editors put first is not part of the program.
            line_start: if source.starts_with('\u{feff}') { 3 } else { 0 },
            line_no: 0,
            words: Vec::with_capacity(16),
            decimals: Decimals::default(),
            inch: false,
            failed: false,
        }
    }

    /// Most decimals seen in the blocks read so far.
    pub fn decimals(&self) -> Decimals {
        self.decimals
    }

    /// True if any block read so far is in inch (G20).
    pub fn inch(&self) -> bool {
        self.inch
    }
}

impl Iterator for Blocks<'_> {
    type Item = Result<Block>;

    fn next(&mut self) -> Option<Result<Block>> {
        let bytes = self.bytes;
        if self.failed || self.line_start >= bytes.len() {
            return None;
        }
        self.line_no += 1;
        let start = self.line_start;
        let nl = memchr::memchr(b'\n', &bytes[start..]).map_or(bytes.len(), |k| start + k);
        let mut end = nl;
        if end > start && bytes[end - 1] == b'\r' {
            end -= 1;
        }
        self.line_start = nl + 1;
        let block =
            self.reader.block(&bytes[start..end], start..end, self.line_no, &mut self.words, &mut self.decimals);
        self.failed = block.is_err();
        self.inch |= self.reader.modes.units == Units::Inch;
        Some(block)
    }
}

/// The blocks of a program read line by line from a stream: only the text not yet released is
/// held (a filter that streams keeps the lines of one run), so a program of any size is read in
/// the memory of its longest run. Spans are byte offsets from the start of the stream, as
/// [`Blocks`] gives them; [`StreamBlocks::text`] shows a held block's line. The first error ends
/// the sequence.
pub struct StreamBlocks<'a, R> {
    reader: Reader<'a>,
    src: R,
    /// Held text: the stream's bytes from offset `base` on.
    text: Vec<u8>,
    base: usize,
    line_no: u32,
    words: Vec<Word>,
    decimals: Decimals,
    inch: bool,
    failed: bool,
}

impl<'a, R: std::io::BufRead> StreamBlocks<'a, R> {
    /// Blocks read from `src`; `name` is used in error messages.
    pub fn new(name: &'a str, src: R) -> StreamBlocks<'a, R> {
        StreamBlocks {
            reader: Reader::new(name),
            src,
            text: Vec::with_capacity(1 << 16),
            base: 0,
            line_no: 0,
            words: Vec::with_capacity(16),
            decimals: Decimals::default(),
            inch: false,
            failed: false,
        }
    }

    /// The text of a held block's `span` (a line, without its line break).
    pub fn text(&self, span: std::ops::Range<usize>) -> &str {
        // Every line was checked to be UTF-8 when it was read.
        std::str::from_utf8(&self.text[span.start - self.base..span.end - self.base]).unwrap_or_default()
    }

    /// Forgets the text before offset `upto`: no span before it is asked for again.
    pub fn release(&mut self, upto: usize) {
        let cut = upto.saturating_sub(self.base).min(self.text.len());
        // Moved down only once the released part is large, so that it costs O(1) per byte.
        if cut >= 1 << 16 && 2 * cut >= self.text.len() {
            self.text.drain(..cut);
            self.base += cut;
        }
    }

    /// Most decimals seen in the blocks read so far.
    pub fn decimals(&self) -> Decimals {
        self.decimals
    }

    /// True if any block read so far is in inch (G20).
    pub fn inch(&self) -> bool {
        self.inch
    }
}

impl<R: std::io::BufRead> Iterator for StreamBlocks<'_, R> {
    type Item = Result<Block>;

    fn next(&mut self) -> Option<Result<Block>> {
        if self.failed {
            return None;
        }
        let at = self.text.len();
        let read = self.src.read_until(b'\n', &mut self.text);
        let n = match read {
            Ok(0) => return None,
            Ok(n) => n,
            Err(e) => {
                self.failed = true;
                return Some(Err(Error::io(e, self.reader.name)));
            }
        };
        self.line_no += 1;
        let name = self.reader.name;
        let mut start = at;
        let mut end = at + n;
        if self.text[end - 1] == b'\n' {
            end -= 1;
        }
        if end > start && self.text[end - 1] == b'\r' {
            end -= 1;
        }
        // A byte order mark some editors put first is not part of the program.
        if self.base + start == 0 && self.text[start..end].starts_with("\u{feff}".as_bytes()) {
            start += 3;
        }
        if std::str::from_utf8(&self.text[start..at + n]).is_err() {
            self.failed = true;
            let loc = Location::file(name).line(u64::from(self.line_no));
            return Some(Err(Error::input("text is not valid UTF-8").at(loc)));
        }
        let span = self.base + start..self.base + end;
        let block = self.reader.block(&self.text[start..end], span, self.line_no, &mut self.words, &mut self.decimals);
        self.failed = block.is_err();
        self.inch |= self.reader.modes.units == Units::Inch;
        Some(block)
    }
}

struct Reader<'a> {
    name: &'a str,
    modes: Modes,
    /// Current position (mm).
    pos: [f64; 3],
    /// Which coordinates of `pos` are known.
    known: [bool; 3],
    /// `pos` was made up (a G91 program starting at an unknown place): relative geometry only.
    virtual_frame: bool,
    /// M83 in effect.
    e_mode_relative: bool,
    /// Absolute extruder position, when known.
    e_abs: Option<f64>,
}

/// What the G words of a block ask for, beyond modal settings.
#[derive(Default)]
struct GEffects {
    motion: Option<Motion>,
    /// G codes other than the motion word: the block cannot be replaced.
    extra_g: bool,
    /// A G code that moves the machine or shifts coordinates in a way not modelled.
    moves_unmodelled: bool,
    /// G92 (coordinate shift); harmless for positions when it only names E.
    g92: bool,
}

impl<'a> Reader<'a> {
    /// A reader at the start of a program.
    fn new(name: &'a str) -> Reader<'a> {
        Reader {
            name,
            modes: Modes::default(),
            pos: [0.0; 3],
            known: [false; 3],
            virtual_frame: false,
            e_mode_relative: false,
            e_abs: None,
        }
    }

    fn err(&self, line: u32, col: usize, word: &[u8], message: &str) -> Error {
        let word = String::from_utf8_lossy(word).into_owned();
        Error::input(message).at(Location::file(self.name).line(u64::from(line)).column(col as u64 + 1).field(word))
    }

    /// Splits a line into words; `Ok(true)` if it had a comment or checksum.
    fn words(&self, line: &[u8], line_no: u32, words: &mut Vec<Word>) -> Result<bool> {
        words.clear();
        let mut remark = false;
        let mut i = 0;
        while i < line.len() {
            let c = line[i];
            match c {
                b' ' | b'\t' => i += 1,
                b'(' => {
                    remark = true;
                    match memchr::memchr(b')', &line[i..]) {
                        Some(k) => i += k + 1,
                        None => return Err(self.err(line_no, i, &line[i..], "comment is not closed with `)`")),
                    }
                }
                b';' | b'*' => return Ok(true),
                _ if c.is_ascii_alphabetic() => {
                    let letter = c.to_ascii_uppercase();
                    let mut j = i + 1;
                    while j < line.len() && (line[j] == b' ' || line[j] == b'\t') {
                        j += 1;
                    }
                    let word_end = |from: usize| {
                        from + line[from..]
                            .iter()
                            .position(|b| b.is_ascii_whitespace() || *b == b'(' || *b == b';')
                            .unwrap_or(line.len() - from)
                    };
                    if matches!(line.get(j), Some(b'#' | b'[')) {
                        return Err(self.err(
                            line_no,
                            i,
                            &line[i..word_end(j)],
                            "parameters and expressions are not supported",
                        ));
                    }
                    let Some((value, end, decimals)) = parse_number(line, j) else {
                        return Err(self.err(
                            line_no,
                            i,
                            &line[i..word_end(j)],
                            "malformed word: a letter must be followed by a number",
                        ));
                    };
                    if !value.is_finite() {
                        let shown = &line[i..end.min(i + 24)];
                        return Err(self.err(line_no, i, shown, "number out of range (beyond ±1.8e308)"));
                    }
                    if let Some(&next) = line.get(end)
                        && !(next.is_ascii_alphabetic() || matches!(next, b' ' | b'\t' | b'(' | b';' | b'*'))
                    {
                        return Err(self.err(line_no, i, &line[i..word_end(end)], "malformed word"));
                    }
                    if letter == b'O' {
                        return Err(self.err(
                            line_no,
                            i,
                            &line[i..end],
                            "o-codes (subroutines, loops) are not supported",
                        ));
                    }
                    if !matches!(letter, b'G' | b'M') && words.iter().any(|w| w.letter == letter) {
                        return Err(self.err(line_no, i, &line[i..end], "word appears twice in one block"));
                    }
                    words.push(Word { letter, value, decimals, start: i, end });
                    i = end;
                }
                _ => {
                    let end = i + line[i..].iter().position(|b| b.is_ascii_whitespace()).unwrap_or(line.len() - i);
                    return Err(self.err(line_no, i, &line[i..end], "unknown word"));
                }
            }
        }
        Ok(remark)
    }

    /// Applies the modal G and M words of a block; returns what else they ask for.
    fn apply_modal(&mut self, words: &[Word], line: &[u8], line_no: u32) -> Result<GEffects> {
        let mut fx = GEffects::default();
        for w in words {
            // G and M codes to one decimal (G90.1 is 901); other letters carry no code.
            let code = || (w.value * 10.0).round() as i64;
            match w.letter {
                b'G' => {
                    let code = code();
                    match code {
                        0 | 10 | 20 | 30 => {
                            if fx.motion.is_some() {
                                return Err(self.err(
                                    line_no,
                                    w.start,
                                    &line[w.start..w.end],
                                    "two motion codes in one block",
                                ));
                            }
                            fx.motion = Some(match code {
                                0 => Motion::Rapid,
                                10 => Motion::Line,
                                20 => Motion::Cw,
                                _ => Motion::Ccw,
                            });
                            continue;
                        }
                        170 => self.modes.plane = Plane::Xy,
                        180 => self.modes.plane = Plane::Xz,
                        190 => self.modes.plane = Plane::Yz,
                        200 => self.modes.units = Units::Inch,
                        210 => self.modes.units = Units::Mm,
                        900 => {
                            self.modes.relative = false;
                            if self.virtual_frame {
                                self.known = [false; 3];
                                self.virtual_frame = false;
                            }
                        }
                        910 => self.modes.relative = true,
                        901 => self.modes.absolute_arc_centres = true,
                        911 => self.modes.absolute_arc_centres = false,
                        930 => self.modes.inverse_time = true,
                        940 => self.modes.inverse_time = false,
                        800 => self.modes.motion = None,
                        // Modal settings and dwell that do not move the machine.
                        40
                        | 400
                        | 490
                        | 500
                        | 610
                        | 611
                        | 640
                        | 641
                        | 950
                        | 960
                        | 970
                        | 990
                        | 980
                        | 150
                        | 160
                        | 540..=599 => {}
                        920 => fx.g92 = true,
                        _ => fx.moves_unmodelled = true,
                    }
                    fx.extra_g = true;
                }
                b'M' => match code() {
                    820 => self.e_mode_relative = false,
                    830 => self.e_mode_relative = true,
                    _ => {}
                },
                _ => {}
            }
        }
        self.modes.e_relative = self.e_mode_relative || self.modes.relative;
        Ok(fx)
    }

    fn block(
        &mut self,
        line: &[u8],
        span: std::ops::Range<usize>,
        line_no: u32,
        words: &mut Vec<Word>,
        decimals: &mut Decimals,
    ) -> Result<Block> {
        let first = line.iter().position(|b| !b.is_ascii_whitespace());
        // Blank lines, block delete and tape marks are not interpreted.
        if first.is_none_or(|i| matches!(line[i], b'/' | b'%')) {
            let remark_only = first.is_none();
            return Ok(Block::Other(OtherBlock {
                line: line_no,
                span,
                modes: self.modes,
                motion_word: false,
                remark_only,
            }));
        }
        let m = m_led(line);
        if m.is_some() || program_number(line) {
            // An M block (Marlin's M84 X Y E, M117 free text...): its parameters are not
            // coordinates and need not be numbers; only the extruder mode is read from it. A
            // Fanuc program number (`O1234`, maybe with a comment) is no block to interpret.
            match m {
                Some(82) => self.e_mode_relative = false,
                Some(83) => self.e_mode_relative = true,
                _ => {}
            }
            self.modes.e_relative = self.e_mode_relative || self.modes.relative;
            return Ok(Block::Other(OtherBlock {
                line: line_no,
                span,
                modes: self.modes,
                motion_word: false,
                remark_only: false,
            }));
        }
        let remark = self.words(line, line_no, words)?;
        let fx = self.apply_modal(words, line, line_no)?;
        let motion_word =
            fx.motion.is_some() || words.iter().any(|w| w.letter == b'G' && (w.value * 10.0).round() as i64 == 800);
        let remark_only = words.is_empty();
        let other = |span, modes| Ok(Block::Other(OtherBlock { line: line_no, span, modes, motion_word, remark_only }));
        if words.is_empty() {
            return other(span, self.modes);
        }
        let scale = self.modes.units.mm();
        let (mut axes, mut ijk) = ([None; 3], [None; 3]);
        let (mut r, mut f, mut e, mut n, mut p) = (None, None, None, None, None);
        let mut unmodelled_word = false;
        for w in words.iter() {
            match w.letter {
                b'X' | b'Y' | b'Z' => {
                    axes[usize::from(w.letter - b'X')] = Some(w.value * scale);
                    decimals.xyz = decimals.xyz.max(w.decimals);
                }
                b'I' | b'J' | b'K' => {
                    ijk[usize::from(w.letter - b'I')] = Some(w.value * scale);
                    decimals.xyz = decimals.xyz.max(w.decimals);
                }
                b'R' => r = Some((w.value * scale, w)),
                b'F' => f = Some(w.value),
                b'E' => {
                    e = Some(w.value);
                    decimals.e = decimals.e.max(w.decimals);
                }
                b'N' => n = Some(w.value as u64),
                b'P' => p = Some(w.value),
                b'G' | b'M' => {}
                _ => unmodelled_word = true,
            }
        }
        if let Some(fv) = f {
            if fv <= 0.0 && !self.modes.inverse_time {
                let w = words.iter().find(|w| w.letter == b'F').expect("F word present");
                return Err(self.err(line_no, w.start, &line[w.start..w.end], "feed must be positive"));
            }
            self.modes.feed = Some(if self.modes.inverse_time { fv } else { fv * scale });
        }
        if let Some(m) = fx.motion {
            self.modes.motion = Some(m);
        }
        let has_axes = axes.iter().any(Option::is_some);
        let g92_only_e = fx.g92 && !has_axes;
        let e_delta = match e {
            Some(v) if fx.g92 => {
                self.e_abs = Some(v);
                None
            }
            Some(v) if self.modes.e_relative => {
                self.e_abs = self.e_abs.map(|a| a + v);
                Some(v)
            }
            Some(v) => self.e_abs.replace(v).map(|prev| v - prev),
            None => None,
        };
        if fx.moves_unmodelled || (fx.g92 && !g92_only_e) {
            // G28, G53, G92 with axes, G43, canned cycles...: where the machine is afterwards is not known.
            self.known = [false; 3];
            return other(span, self.modes);
        }
        let motion = match self.modes.motion {
            Some(m)
                if has_axes
                    || (m.is_arc() && fx.motion.is_some() && (ijk.iter().any(Option::is_some) || r.is_some())) =>
            {
                m
            }
            _ => {
                if has_axes {
                    return Err(self.err(line_no, 0, line, "coordinates without a motion mode (G0, G1, G2 or G3)"));
                }
                return other(span, self.modes);
            }
        };
        if self.modes.relative && self.known.iter().any(|k| !k) {
            // A G91 program that starts at an unknown place: measure from a made-up origin.
            for k in 0..3 {
                if !self.known[k] {
                    self.pos[k] = 0.0;
                    self.known[k] = true;
                }
            }
            self.virtual_frame = true;
        }
        let start_known = self.known.iter().all(|&k| k);
        let start = P3::from(self.pos);
        let mut end = self.pos;
        for k in 0..3 {
            if let Some(v) = axes[k] {
                end[k] = if self.modes.relative { self.pos[k] + v } else { v };
                self.known[k] = true;
            }
        }
        let end = P3::from(end);
        let plane = self.modes.plane;
        let centre = if motion.is_arc() {
            Some(self.arc_centre(&start, &end, plane, ijk, r, motion, line, line_no)?)
        } else {
            None
        };
        let turns = match p {
            Some(v) if motion.is_arc() && v >= 1.0 => v as u32 - 1,
            _ => 0,
        };
        self.pos = [end.x, end.y, end.z];
        let plain = !remark && !fx.extra_g && !unmodelled_word && p.is_none() && !self.modes.inverse_time;
        Ok(Block::Move(MoveBlock {
            line: line_no,
            span,
            motion,
            explicit: fx.motion.is_some(),
            start,
            start_known,
            end,
            centre,
            turns,
            modes: self.modes,
            has_f: f.is_some(),
            e,
            e_delta,
            n,
            plain,
        }))
    }

    /// The centre of an arc block in plane coordinates, from I/J/K or R.
    #[allow(clippy::too_many_arguments)]
    fn arc_centre(
        &self,
        start: &P3,
        end: &P3,
        plane: Plane,
        ijk: [Option<f64>; 3],
        r: Option<(f64, &Word)>,
        motion: Motion,
        line: &[u8],
        line_no: u32,
    ) -> Result<P2> {
        let (s, _) = plane.split(start);
        let (e, _) = plane.split(end);
        let [u, v, _] = plane.axes();
        if let Some((radius, w)) = r {
            let chord = e - s;
            let half = 0.5 * chord.norm();
            let h2 = radius * radius - half * half;
            let slack = 1e-9 * radius.abs().max(1.0);
            if half == 0.0 || h2 < -slack {
                return Err(self.err(
                    line_no,
                    w.start,
                    &line[w.start..w.end],
                    "arc radius is smaller than half the distance between its ends",
                ));
            }
            let h = h2.max(0.0).sqrt();
            let left = V2::new(-chord.y, chord.x) / (2.0 * half);
            // G3 with R > 0 turns left of the chord about a centre on the left; G2 on the right;
            // a negative R asks for the arc over 180° and puts the centre on the other side.
            let side = if (motion == Motion::Ccw) == (radius > 0.0) { 1.0 } else { -1.0 };
            return Ok(P2::from((s.coords + e.coords) * 0.5) + left * (side * h));
        }
        if ijk[u].is_none() && ijk[v].is_none() {
            let text = String::from_utf8_lossy(line);
            return Err(self.err(
                line_no,
                0,
                text.trim().as_bytes(),
                "an arc needs its centre (I, J, K in its plane) or R",
            ));
        }
        let off = |axis: usize| ijk[axis].unwrap_or(0.0);
        let c =
            if self.modes.absolute_arc_centres { P2::new(off(u), off(v)) } else { P2::new(s.x + off(u), s.y + off(v)) };
        // LinuxCNC's rule: the ends may lie at radii differing by 0.05 mm or 0.1 % of the radius.
        let (r0, r1) = ((s - c).norm(), (e - c).norm());
        if (r0 - r1).abs() > ARC_RADIUS_SLACK_MM && (r0 - r1).abs() > 1e-3 * r0.max(r1) {
            let text = String::from_utf8_lossy(line);
            return Err(self.err(
                line_no,
                0,
                text.trim().as_bytes(),
                &format!("the arc's ends are not on one circle about its centre: radii {r0:.6} and {r1:.6} mm"),
            ));
        }
        Ok(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Program> {
        read("t.nc", text.to_string())
    }

    fn moves(p: &Program) -> Vec<&MoveBlock> {
        p.blocks.iter().filter_map(|b| if let Block::Move(m) = b { Some(m) } else { None }).collect()
    }

    #[test]
    fn numbers_are_exact_decimals() {
        assert_eq!(parse_number(b"43.9090", 0), Some((43.909, 7, 4)));
        assert_eq!(parse_number(b"-.5", 0), Some((-0.5, 3, 1)));
        assert_eq!(parse_number(b"10.", 0), Some((10.0, 3, 0)));
        assert_eq!(parse_number(b"+7", 0), Some((7.0, 2, 0)));
        assert_eq!(parse_number(b"x", 0), None);
        assert_eq!(parse_number(b"0.1", 0).unwrap().0, "0.1".parse::<f64>().unwrap());
        assert_eq!(parse_number(b"75.04942656", 0).unwrap().0, 75.04942656);
    }

    #[test]
    fn modal_moves_units_and_numbers() {
        let p = parse("G20 G90\nN10 G1 X1 Y2 F10\nN20 X2\nG21\nY3 ; mm now\n").unwrap();
        let m = moves(&p);
        assert_eq!(m.len(), 3);
        assert!(!m[0].start_known);
        assert_eq!(m[0].end, P3::new(25.4, 50.8, 0.0));
        assert_eq!(m[0].modes.feed, Some(254.0));
        assert_eq!(m[1].motion, Motion::Line);
        assert!(!m[1].explicit);
        assert_eq!(m[1].n, Some(20));
        assert_eq!(m[1].end, P3::new(50.8, 50.8, 0.0));
        assert_eq!(m[2].end, P3::new(50.8, 3.0, 0.0));
        assert!(!m[2].plain, "a commented move is written back verbatim");
    }

    /// What post-6axis writes in the Fanuc dialect reads: `%`, the program number, N words, G53
    /// (the position after it unknown), G43.4, G93 with inverse-time F, M19 R.
    #[test]
    fn reads_a_fanuc_program_the_post_writes() {
        let p = parse(
            "%\nO2002 (Paper 002 machine)\nN10 G21 G17 G90 G94\nN20 G53 G0 Z0\nN30 T1 M6\nN40 G43.4 H1\n\
             N50 G0 X1 Y2 Z3 A4 C5\nN60 M19 R45\nN70 G93 G1 X2 F120.5\nN80 G94 G1 X3 F300\nN90 M30\n%\n",
        )
        .unwrap();
        let m = moves(&p);
        assert_eq!(m.len(), 3);
        assert!(!m[0].start_known && !m[0].plain, "{:?}", m[0]);
        assert_eq!(m[0].end, P3::new(1.0, 2.0, 3.0));
        assert!(m[1].modes.inverse_time && m[1].start_known);
        assert_eq!(m[2].modes.feed, Some(300.0));
        assert!(parse("O12 G0 X1\n").is_err(), "an O word with more on its line is an o-code");
    }

    #[test]
    fn arcs_by_offsets_and_radius() {
        let p = parse("G0 X0 Y0 Z0\nG2 X10 Y0 I5 J0\nG3 X20 Y0 R5\nG2 X30 Y0 R-5\nG18 G3 X40 Z0 K0 I5\n").unwrap();
        let m = moves(&p);
        assert_eq!(m[1].centre, Some(P2::new(5.0, 0.0)));
        assert!(m[1].start_known);
        // G3 from (10,0) to (20,0) with R5: centre on the left of the chord, (15,0) (a half circle).
        assert!((m[2].centre.unwrap() - P2::new(15.0, 0.0)).norm() < 1e-9);
        assert_eq!(m[4].modes.plane, Plane::Xz);
        // Plane xz: coordinates (z, x); centre at x = 30 + 5, z = 0.
        assert_eq!(m[4].centre, Some(P2::new(0.0, 35.0)));
        assert!(!m[4].plain, "G18 on the block makes it verbatim");
    }

    #[test]
    fn relative_mode_and_e() {
        let p = parse("M83\nG91\nG1 X1 Y1 E0.5\nX1 E0.25\nG90\nG1 X5 Y5\n").unwrap();
        let m = moves(&p);
        assert!(m[0].modes.e_relative);
        assert_eq!(m[1].end, P3::new(2.0, 1.0, 0.0));
        assert_eq!(m[1].e, Some(0.25));
        assert_eq!(m[1].e_delta, Some(0.25));
        let p = parse("M82\nG92 E0\nG1 X1 E1.5\nG1 X2 E2.25\nG92 E10\nG1 X3 E11\n").unwrap();
        let d: Vec<_> = moves(&p).iter().map(|m| m.e_delta).collect();
        assert_eq!(d, vec![Some(1.5), Some(0.75), Some(1.0)]);
        assert!(!m[2].start_known, "leaving a made-up G91 frame forgets the position");
    }

    #[test]
    fn opaque_blocks_are_kept_and_unknown_positions_marked() {
        let p = parse(
            "G0 X1 Y1 Z1\nM3 S1000\nG28\nG1 X2 Y2 Z2\nG92 E0\nM201 X500 Y500\nG1 X3\nM84 X Y E\nM117 Hello world\n",
        )
        .unwrap();
        assert_eq!(p.blocks.len(), 9);
        assert!(matches!(p.blocks[5], Block::Other(_)), "M201's X and Y are parameters");
        let m = moves(&p);
        assert!(m[0].plain);
        assert!(!m[1].start_known);
        assert!(m[2].start_known, "G92 E0 does not move the axes");
    }

    #[test]
    fn malformed_words_are_errors_with_line_and_word() {
        let e = parse("G1 X1\nG1 X1.2.3 Y2\n").unwrap_err();
        assert_eq!(e.to_string(), "t.nc:2:4 (X1.2.3): malformed word");
        let e = parse("G1 Xab\n").unwrap_err();
        assert_eq!(e.to_string(), "t.nc:1:4 (Xab): malformed word: a letter must be followed by a number");
        let e = parse("G1 X[1+2]\n").unwrap_err();
        assert!(e.to_string().contains("parameters and expressions"), "{e}");
        let e = parse("G1 X1 @5\n").unwrap_err();
        assert_eq!(e.to_string(), "t.nc:1:7 (@5): unknown word");
        assert_eq!(e.exit_status(), 2);
        let e = parse("G1 X1 X2\n").unwrap_err();
        assert!(e.to_string().contains("twice"), "{e}");
    }
}
