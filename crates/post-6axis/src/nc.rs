//! Writing the NC program: header, tool change, spindle and coolant, motion blocks in G0/G1 with
//! inverse-time feed (G93) for blocks that turn a rotary axis and G94 otherwise, arcs as G2/G3 in
//! their plane (G17/G18/G19) with I/J/K from the start as written, the spindle orientation as
//! `M19 R` or a rotary address, footer; fixed decimals per address, optional block numbers, in the
//! ISO/Fanuc or LinuxCNC dialect. The first move never runs diagonally from the tool change: from
//! a known retract height (`program.retract_z`) the other axes move first, then Z comes down;
//! otherwise Z moves first.

use crate::plan::Step;
use camkit::doc::machine::{Coolant, Dialect, Machine, SpindleMode, UnitsDoc};
use camkit::geom::Plane;
use camkit::kinematics::Chain;
use camkit::num::{push_fixed, round_to};

/// What the writer needs besides the machine.
#[derive(Clone, Debug, PartialEq)]
pub struct WriteOptions {
    /// Radius (mm) at which a rotary move counts as path length for inverse-time feed when the
    /// tool tip hardly moves.
    pub rotary_radius: f64,
    /// Lines of the header comment (without parentheses).
    pub comments: Vec<String>,
}

/// Figures of the written program.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Written {
    /// Motion blocks written.
    pub blocks: usize,
    /// Blocks in inverse-time feed (G93).
    pub inverse_time_blocks: usize,
    /// Oriented spindle stops written.
    pub orients: usize,
    /// Blocks dropped because nothing moved once rounded.
    pub dropped: usize,
    /// Arcs written (G2/G3).
    pub arcs: usize,
}

/// A block with no feed: the row it comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NoFeed(pub usize);

struct Out {
    text: Vec<u8>,
    n: Option<(u32, u32)>,
}

impl Out {
    /// Starts a block, with its number if block numbers are on.
    fn block(&mut self) {
        if let Some((next, step)) = &mut self.n {
            self.text.push(b'N');
            self.text.extend_from_slice(itoa::Buffer::new().format(*next).as_bytes());
            self.text.push(b' ');
            *next += *step;
        }
    }

    /// A whole block of text.
    fn line(&mut self, text: &str) {
        self.block();
        self.text.extend_from_slice(text.as_bytes());
        self.text.push(b'\n');
    }

    /// A line outside the block sequence (`%`, comments, program number).
    fn bare(&mut self, text: &str) {
        self.text.extend_from_slice(text.as_bytes());
        self.text.push(b'\n');
    }

    fn word(&mut self, letter: u8, value: f64, decimals: u32) {
        if self.text.last().is_some_and(|c| *c != b' ' && *c != b'\n') {
            self.text.push(b' ');
        }
        self.text.push(letter);
        push_fixed(&mut self.text, value, decimals, true);
    }

    fn end(&mut self) {
        self.text.push(b'\n');
    }
}

/// A comment's text made safe for `( )`.
fn comment(text: &str) -> String {
    format!("({})", text.replace('(', "[").replace(')', "]"))
}

/// Decimals that give `digits` significant digits of `v`.
fn significant(v: f64, digits: u32) -> u32 {
    let mag = v.abs().log10().floor() as i32;
    (digits as i32 - 1 - mag).clamp(0, 8) as u32
}

/// The program written block by block as the planned steps come: the header at the start, only
/// what changes in each block, the footer at the end.
pub struct Writer<'a> {
    machine: &'a Machine,
    opts: &'a WriteOptions,
    o: Out,
    stats: Written,
    letters: Vec<u8>,
    spindle_mode: Option<SpindleMode>,
    spindle_letter: Option<u8>,
    retract: Option<String>,
    state: State,
    prev: Option<Step>,
}

/// Last written values (rounded, program units), to write only what changes, and the modes in
/// effect.
#[derive(Clone, Copy)]
struct State {
    last_lin: [Option<f64>; 3],
    last_rot: [Option<f64>; 2],
    last_spin: Option<f64>,
    last_orient: Option<f64>,
    inverse_time: bool,
    g94_feed: Option<f64>,
    motion: Option<u8>,
    plane: Plane,
}

impl<'a> Writer<'a> {
    /// A writer for `machine`, the header written.
    pub fn new(machine: &'a Machine, chain: &Chain, opts: &'a WriteOptions) -> Writer<'a> {
        let p = &machine.program;
        let d = p.decimals;
        let unit = if p.units == UnitsDoc::Inch { 25.4 } else { 1.0 };
        let mut o = Out { text: Vec::with_capacity(1 << 16), n: p.block_numbers.map(|[a, b]| (a, b)) };
        let stats = Written::default();
        o.bare("%");
        if machine.dialect == Dialect::Fanuc
            && let Some(num) = p.number
        {
            o.bare(&format!("O{num:04} {}", comment(&machine.name)));
        }
        for c in &opts.comments {
            o.bare(&comment(c));
        }
        let units = if p.units == UnitsDoc::Inch { "G20" } else { "G21" };
        o.line(&format!("{units} G17 G40 G49 G80 G90 G94"));
        o.line(&p.work_offset.to_ascii_uppercase());
        let retract = p.retract_z.map(|z| {
            let mut t = Vec::new();
            push_fixed(&mut t, z / unit, d.linear, true);
            format!("G53 G0 Z{}", String::from_utf8_lossy(&t))
        });
        if let Some(r) = &retract {
            o.line(r);
        }
        if let Some(t) = p.tool {
            o.line(&format!("T{t} M6"));
            o.line(&if p.tcp { format!("G43.4 H{t}") } else { format!("G43 H{t}") });
        }
        if let Some(s) = p.spindle_speed {
            let mut t = Vec::new();
            push_fixed(&mut t, s, 0, true);
            o.line(&format!("S{} M3", String::from_utf8_lossy(&t)));
        }
        match p.coolant {
            Coolant::Off => {}
            Coolant::Flood => o.line("M8"),
            Coolant::Mist => o.line("M7"),
        }
        for h in &p.header {
            o.line(h);
        }
        Writer {
            machine,
            opts,
            o,
            stats,
            letters: chain.rotaries().iter().map(|r| r.address as u8).collect(),
            spindle_mode: machine.spindle.as_ref().map(|s| s.mode),
            spindle_letter: machine.spindle_address().map(|c| c as u8),
            retract,
            state: State {
                last_lin: [None; 3],
                last_rot: [None; 2],
                last_spin: None,
                last_orient: None,
                inverse_time: false,
                g94_feed: None,
                motion: None,
                plane: Plane::Xy,
            },
            prev: None,
        }
    }

    /// Writes the block(s) of one step (none where nothing moves once rounded).
    pub fn push(&mut self, step: &Step) -> Result<(), NoFeed> {
        let p = &self.machine.program;
        let d = p.decimals;
        let unit = if p.units == UnitsDoc::Inch { 25.4 } else { 1.0 };
        let (o, stats, opts, retract) = (&mut self.o, &mut self.stats, self.opts, &self.retract);
        let (letters, spindle_mode, spindle_letter) = (&self.letters, self.spindle_mode, self.spindle_letter);
        let State {
            mut last_lin,
            mut last_rot,
            mut last_spin,
            mut last_orient,
            mut inverse_time,
            mut g94_feed,
            mut motion,
            mut plane,
        } = self.state;
        let prev = self.prev;
        let mut written = false;
        'block: {
            let lin: [f64; 3] = std::array::from_fn(|k| round_to(step.joints.xyz[k] / unit, d.linear));
            let rot: [f64; 2] = std::array::from_fn(|k| round_to(step.joints.rot[k], d.rotary));
            let spin = step.spindle.map(|s| round_to(s, d.rotary));
            if prev.is_none() {
                // The first move: Z alone first, or (from a known retract height) everything else
                // first, so that it never runs diagonally down from the tool change position.
                o.block();
                o.text.extend_from_slice(b"G0");
                motion = Some(0);
                if retract.is_some() {
                    o.word(b'X', lin[0], d.linear);
                    o.word(b'Y', lin[1], d.linear);
                    let mut words: Vec<(u8, f64)> = (0..letters.len()).map(|k| (letters[k], rot[k])).collect();
                    if spindle_mode == Some(SpindleMode::Axis)
                        && let (Some(l), Some(sp)) = (spindle_letter, spin)
                    {
                        words.push((l, sp));
                        last_spin = Some(sp);
                    }
                    words.sort_by_key(|w| w.0);
                    for (l, v) in words {
                        o.word(l, v, d.rotary);
                    }
                    last_lin[0] = Some(lin[0]);
                    last_lin[1] = Some(lin[1]);
                    for k in 0..letters.len() {
                        last_rot[k] = Some(rot[k]);
                    }
                } else {
                    o.word(b'Z', lin[2], d.linear);
                    last_lin[2] = Some(lin[2]);
                }
                o.end();
                stats.blocks += 1;
            }
            if spindle_mode == Some(SpindleMode::M19)
                && let Some(s) = spin
            {
                let r = round_to(s.rem_euclid(360.0), d.rotary);
                let r = if r >= 360.0 { 0.0 } else { r };
                if last_orient != Some(r) {
                    o.block();
                    o.text.extend_from_slice(b"M19");
                    o.word(b'R', r, d.rotary);
                    o.end();
                    last_orient = Some(r);
                    stats.orients += 1;
                }
            }
            let lin_changed: [bool; 3] = std::array::from_fn(|k| last_lin[k] != Some(lin[k]));
            let rot_changed: Vec<bool> = (0..letters.len()).map(|k| last_rot[k] != Some(rot[k])).collect();
            let spin_axis = spindle_mode == Some(SpindleMode::Axis);
            let spin_changed = spin_axis && spin.is_some() && last_spin != spin;
            let rapid = step.cl.rapid || prev.is_none();
            let arc = step.arc.filter(|_| !rapid);
            if !lin_changed.iter().any(|c| *c) && !rot_changed.iter().any(|c| *c) && !spin_changed && arc.is_none() {
                stats.dropped += 1;
                break 'block;
            }
            let rotary_moves = rot_changed.iter().any(|c| *c) || spin_changed;
            if let Some(a) = &arc
                && a.plane != plane
            {
                o.line(match a.plane {
                    Plane::Xy => "G17",
                    Plane::Xz => "G18",
                    Plane::Yz => "G19",
                });
                plane = a.plane;
            }
            o.block();
            if rapid {
                o.text.extend_from_slice(b"G0");
                motion = Some(0);
            } else if let Some(a) = &arc {
                if inverse_time {
                    o.text.extend_from_slice(b"G94 ");
                    inverse_time = false;
                    g94_feed = None;
                }
                let g = if a.ccw { 3 } else { 2 };
                if motion != Some(g) {
                    o.text.extend_from_slice(if a.ccw { b"G3" } else { b"G2" });
                    motion = Some(g);
                } else if o.text.last() == Some(&b' ') {
                    o.text.pop();
                }
            } else {
                let want_inverse = rotary_moves && !p.tcp;
                if want_inverse && !inverse_time {
                    o.text.extend_from_slice(b"G93 ");
                    inverse_time = true;
                } else if !want_inverse && inverse_time {
                    o.text.extend_from_slice(b"G94 ");
                    inverse_time = false;
                    g94_feed = None;
                }
                if motion != Some(1) {
                    o.text.extend_from_slice(b"G1");
                    motion = Some(1);
                } else if o.text.last() == Some(&b' ') {
                    o.text.pop();
                }
            }
            for k in 0..3 {
                if lin_changed[k] {
                    o.word(b"XYZ"[k], lin[k], d.linear);
                }
            }
            // Rotary words in address order (A, B, C), the spindle's among them.
            let mut words: Vec<(u8, f64)> =
                (0..letters.len()).filter(|&k| rot_changed[k]).map(|k| (letters[k], rot[k])).collect();
            if spin_changed && let (Some(l), Some(s)) = (spindle_letter, spin) {
                words.push((l, s));
            }
            words.sort_by_key(|w| w.0);
            for (l, v) in words {
                o.word(l, v, d.rotary);
            }
            if let Some(a) = &arc {
                // The centre from the start as written (rounded), in program units.
                let [iu, iv, _] = a.plane.axes();
                let mut centre = [0.0; 3];
                centre[iu] = a.centre.x / unit;
                centre[iv] = a.centre.y / unit;
                let mut ks = [iu, iv];
                ks.sort_unstable();
                for k in ks {
                    let start = last_lin[k].expect("an arc follows a written block");
                    o.word(b"IJK"[k], round_to(centre[k] - start, d.linear), d.linear);
                }
                stats.arcs += 1;
            }
            if !rapid {
                let feed = step.cl.feed.ok_or(NoFeed(step.row))?;
                if inverse_time && arc.is_none() {
                    let a = prev.expect("a feed block follows another block");
                    let tip_len = (step.cl.tip - a.cl.tip).norm();
                    let mut turn = 0.0f64;
                    for k in 0..letters.len() {
                        turn = turn.max((step.joints.rot[k] - a.joints.rot[k]).abs());
                    }
                    if let (Some(x), Some(y)) = (step.spindle, a.spindle) {
                        turn = turn.max((x - y).abs());
                    }
                    let length = tip_len.max(opts.rotary_radius * turn.to_radians());
                    let f = feed / length.max(1e-9);
                    o.word(b'F', f, significant(f, d.inverse_time_digits));
                    stats.inverse_time_blocks += 1;
                } else {
                    let f = round_to(feed / unit, d.feed);
                    if g94_feed != Some(f) {
                        o.word(b'F', f, d.feed);
                        g94_feed = Some(f);
                    }
                }
            }
            o.end();
            stats.blocks += 1;
            for k in 0..3 {
                last_lin[k] = Some(lin[k]);
            }
            for k in 0..letters.len() {
                last_rot[k] = Some(rot[k]);
            }
            if spin_axis {
                last_spin = spin.or(last_spin);
            }
            written = true;
        }
        if written {
            self.prev = Some(*step);
        }
        self.state = State { last_lin, last_rot, last_spin, last_orient, inverse_time, g94_feed, motion, plane };
        Ok(())
    }

    /// Bytes of text written and not yet taken ([`Writer::write_text`]).
    pub fn pending(&self) -> usize {
        self.o.text.len()
    }

    /// Passes the text of the blocks written so far (whole lines) on to `out` and forgets it: a
    /// caller that does so as the blocks come never holds the program.
    pub fn write_text(&mut self, out: &mut impl std::io::Write) -> std::io::Result<()> {
        out.write_all(&self.o.text)?;
        self.o.text.clear();
        Ok(())
    }

    /// Writes the footer: the rest of the program text and its figures.
    pub fn finish(self) -> (Vec<u8>, Written) {
        let p = &self.machine.program;
        let (mut o, stats, retract, inverse_time) = (self.o, self.stats, self.retract, self.state.inverse_time);
        if inverse_time {
            o.line("G94");
        }
        match p.coolant {
            Coolant::Off => {}
            _ => o.line("M9"),
        }
        if p.spindle_speed.is_some() {
            o.line("M5");
        }
        if p.tool.is_some() {
            o.line("G49");
        }
        if let Some(r) = &retract {
            o.line(r);
        }
        for f in &p.footer {
            o.line(f);
        }
        o.line("M30");
        o.bare("%");
        (o.text, stats)
    }
}

/// Writes the program for the planned steps.
pub fn write(
    steps: &[Step],
    machine: &Machine,
    chain: &Chain,
    opts: &WriteOptions,
) -> Result<(Vec<u8>, Written), NoFeed> {
    let mut w = Writer::new(machine, chain, opts);
    for step in steps {
        w.push(step)?;
    }
    Ok(w.finish())
}
