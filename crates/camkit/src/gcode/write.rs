//! The G-code writer: verbatim blocks and new motion blocks in the program's own units and
//! distance mode, keeping the written program's modal state right (a modal line copied after a
//! new G2 gets its G1 back; a plane changed for an arc is restored).

use super::{Block, Modes, Motion, Units};
use crate::geom::{P2, P3, Plane};
use crate::num::{push_fixed, round_to};

/// A motion block to write. Positions are in mm, absolute.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutMove {
    /// G0..G3.
    pub motion: Motion,
    /// Where the move starts (the previous block's end as written); `None` when unknown (the
    /// first move of a program): every coordinate is then written, and it cannot be an arc.
    pub start: Option<P3>,
    /// Where it ends.
    pub end: P3,
    /// Arc centre in plane coordinates, for G2/G3.
    pub centre: Option<P2>,
    /// Arc plane.
    pub plane: Plane,
    /// Feed to write (mm/min), if the block must carry an F word.
    pub feed: Option<f64>,
    /// E word to write, as is.
    pub e: Option<f64>,
    /// N number to write.
    pub n: Option<u64>,
}

/// Writes a program block by block.
#[derive(Debug)]
pub struct Writer {
    /// The text written so far.
    pub out: Vec<u8>,
    /// Decimals of X, Y, Z in program units.
    pub decimals: u32,
    /// Decimals of I, J, K.
    pub centre_decimals: u32,
    /// Decimals of E.
    pub e_decimals: u32,
    motion: Option<Motion>,
    plane: Plane,
}

impl Writer {
    /// A writer with the given decimals.
    pub fn new(decimals: u32, centre_decimals: u32, e_decimals: u32) -> Writer {
        Writer { out: Vec::new(), decimals, centre_decimals, e_decimals, motion: None, plane: Plane::Xy }
    }

    /// Position `v` (mm) as the written program reads it back (mm), in `units`.
    pub fn readback(&self, v: f64, units: Units) -> f64 {
        round_to(v / units.mm(), self.decimals) * units.mm()
    }

    /// `p` as the written program reads it back.
    pub fn readback3(&self, p: &P3, units: Units) -> P3 {
        p.map(|v| self.readback(v, units))
    }

    /// Arc centre as the written program reads it back, given the start as written.
    pub fn readback_centre(&self, centre: &P2, start: &P2, modes: &Modes) -> P2 {
        let u = modes.units.mm();
        let r = |v: f64| round_to(v / u, self.centre_decimals) * u;
        if modes.absolute_arc_centres {
            P2::new(r(centre.x), r(centre.y))
        } else {
            P2::new(start.x + r(centre.x - start.x), start.y + r(centre.y - start.y))
        }
    }

    /// Copies a block of the source program. A modal motion block whose mode differs from the
    /// one now in effect in the written program gets its G word; a plane changed by an earlier
    /// written arc is restored first.
    pub fn verbatim(&mut self, text: &str, block: &Block) {
        let modes = block.modes();
        if self.plane != modes.plane {
            self.out.extend_from_slice(format!("G{}\n", modes.plane.gcode()).as_bytes());
            self.plane = modes.plane;
        }
        match block {
            Block::Move(m) => {
                if !m.explicit && self.motion != Some(m.motion) {
                    let at = after_line_number(text);
                    self.out.extend_from_slice(&text.as_bytes()[..at]);
                    self.out.extend_from_slice(format!("G{} ", m.motion.gcode()).as_bytes());
                    self.out.extend_from_slice(&text.as_bytes()[at..]);
                } else {
                    self.out.extend_from_slice(text.as_bytes());
                }
                self.motion = Some(m.motion);
            }
            Block::Other(o) => {
                self.out.extend_from_slice(text.as_bytes());
                if o.motion_word {
                    self.motion = o.modes.motion;
                }
            }
        }
        self.out.push(b'\n');
    }

    /// Writes a new motion block in the program's `modes` (units, G90/G91, arc centre mode).
    pub fn motion(&mut self, m: &OutMove, modes: &Modes) {
        let u = modes.units.mm();
        let o = &mut self.out;
        if let Some(n) = m.n {
            o.push(b'N');
            o.extend_from_slice(itoa::Buffer::new().format(n).as_bytes());
            o.push(b' ');
        }
        if m.motion.is_arc() && self.plane != m.plane {
            o.extend_from_slice(format!("G{} ", m.plane.gcode()).as_bytes());
            self.plane = m.plane;
        }
        // Always an explicit G word: some controllers (Marlin) do not read modal moves.
        o.push(b'G');
        o.extend_from_slice(itoa::Buffer::new().format(m.motion.gcode()).as_bytes());
        self.motion = Some(m.motion);
        let d = self.decimals;
        let start = m.start.map(|s| s.map(|v| round_to(v / u, d)));
        let end = m.end.map(|v| round_to(v / u, d));
        for (k, letter) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
            let value = match start {
                None => end[k],
                Some(s) if end[k] == s[k] && !(m.motion.is_arc() && m.plane.axes()[..2].contains(&k)) => continue,
                Some(s) if modes.relative => round_to(end[k] - s[k], d),
                Some(_) => end[k],
            };
            push_word(o, letter, value, d);
        }
        if let (Some(c), Some(start)) = (m.centre, m.start) {
            let (s, _) = m.plane.split(&start);
            let cd = self.centre_decimals;
            let [iu, iv, _] = m.plane.axes();
            let letters = [b'I', b'J', b'K'];
            let (cu, cv) =
                if modes.absolute_arc_centres { (c.x / u, c.y / u) } else { ((c.x - s.x) / u, (c.y - s.y) / u) };
            push_word(o, letters[iu], round_to(cu, cd), cd);
            push_word(o, letters[iv], round_to(cv, cd), cd);
        }
        if let Some(e) = m.e {
            push_word(o, b'E', e, self.e_decimals);
        }
        if let Some(f) = m.feed {
            push_word(o, b'F', f / u, 3);
        }
        if o.last() == Some(&b' ') {
            o.pop();
        }
        o.push(b'\n');
    }

    /// Writes a line of text as it is (headers, comments).
    pub fn raw(&mut self, text: &str) {
        self.out.extend_from_slice(text.as_bytes());
        self.out.push(b'\n');
    }

    /// Restores the plane of the source program after written arcs changed it.
    pub fn restore_plane(&mut self, plane: Plane) {
        if self.plane != plane {
            self.out.extend_from_slice(format!("G{}\n", plane.gcode()).as_bytes());
            self.plane = plane;
        }
    }
}

/// Byte offset just after a leading N word (and its spaces) of a block, 0 if there is none.
fn after_line_number(text: &str) -> usize {
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() && b[i].is_ascii_whitespace() {
        i += 1;
    }
    if i < b.len() && (b[i] == b'N' || b[i] == b'n') {
        i += 1;
        while i < b.len() && (b[i].is_ascii_digit() || b[i] == b' ') {
            i += 1;
        }
        return i;
    }
    0
}

fn push_word(o: &mut Vec<u8>, letter: u8, value: f64, decimals: u32) {
    if o.last().is_some_and(|c| *c != b' ' && *c != b'\n') {
        o.push(b' ');
    }
    o.push(letter);
    push_fixed(o, value, decimals, true);
    o.push(b' ');
}

#[cfg(test)]
mod tests {
    use super::super::read;
    use super::*;

    #[test]
    fn modal_line_after_written_arc_gets_its_g1() {
        let p = read("t", "G0 X0 Y0 Z0\nG1 X1 Y1\nN5 X2 Y2\n".into()).unwrap();
        let mut w = Writer::new(3, 3, 5);
        w.verbatim(p.text(&p.blocks[0]), &p.blocks[0]);
        let modes = *p.blocks[1].modes();
        w.motion(
            &OutMove {
                motion: Motion::Ccw,
                start: Some(P3::new(0.0, 0.0, 0.0)),
                end: P3::new(1.0, 1.0, 0.0),
                centre: Some(P2::new(0.0, 1.0)),
                plane: Plane::Xy,
                feed: None,
                e: None,
                n: None,
            },
            &modes,
        );
        w.verbatim(p.text(&p.blocks[2]), &p.blocks[2]);
        assert_eq!(String::from_utf8(w.out).unwrap(), "G0 X0 Y0 Z0\nG3 X1 Y1 I0 J1\nN5 G1 X2 Y2\n");
    }

    #[test]
    fn inch_and_relative_output() {
        let p = read("t", "G20 G91\nG1 X1 Y0\n".into()).unwrap();
        let Block::Move(m) = &p.blocks[1] else { panic!() };
        let mut w = Writer::new(4, 4, 5);
        w.motion(
            &OutMove {
                motion: Motion::Line,
                start: Some(m.end),
                end: m.end + crate::geom::V3::new(25.4, 12.7, 0.0),
                centre: None,
                plane: Plane::Xy,
                feed: Some(254.0),
                e: None,
                n: None,
            },
            &m.modes,
        );
        assert_eq!(String::from_utf8(w.out).unwrap(), "G1 X1 Y0.5 F10\n");
    }
}
