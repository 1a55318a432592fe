//! G-code for the 3-axis subset: G0/G1/G2/G3 (I/J/K or R), G17/G18/G19, G90/G91, G90.1/G91.1,
//! G20/G21, F, E, N words, `( )` and `;` comments, modal state. Every block the reader does not
//! interpret (M, S, T words, other G codes) is kept, in order, as an opaque block that a filter
//! writes back verbatim.

mod axes;
mod read;
mod table;
mod write;

pub use axes::{AXIS_LETTERS, AxisArc, AxisBlocks, AxisMove, AxisProgram, read_axes};
pub use read::{Blocks, Decimals, StreamBlocks, read};
pub use table::{program_to_table, table_to_program};
pub use write::{OutMove, Writer};

use crate::geom::{P2, P3, Plane};
use std::ops::Range;

/// Motion modes of group 1 that the reader models.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Motion {
    /// G0.
    Rapid,
    /// G1.
    Line,
    /// G2.
    Cw,
    /// G3.
    Ccw,
}

impl Motion {
    /// The G number.
    pub fn gcode(self) -> u8 {
        match self {
            Motion::Rapid => 0,
            Motion::Line => 1,
            Motion::Cw => 2,
            Motion::Ccw => 3,
        }
    }

    /// True for G2/G3.
    pub fn is_arc(self) -> bool {
        matches!(self, Motion::Cw | Motion::Ccw)
    }
}

/// Length unit of the program text (G20/G21). Positions in [`Block`]s are always mm.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Units {
    /// G21.
    #[default]
    Mm,
    /// G20.
    Inch,
}

impl Units {
    /// Millimetres per program unit.
    pub fn mm(self) -> f64 {
        match self {
            Units::Mm => 1.0,
            Units::Inch => 25.4,
        }
    }
}

/// The modal state in effect for a block (after the block's own modal words).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Modes {
    /// Group-1 motion mode, `None` before any or after G80.
    pub motion: Option<Motion>,
    /// Arc plane.
    pub plane: Plane,
    /// Units of the text.
    pub units: Units,
    /// G91 in effect.
    pub relative: bool,
    /// G90.1 in effect (I/J/K are absolute centres).
    pub absolute_arc_centres: bool,
    /// G93 inverse-time feed in effect.
    pub inverse_time: bool,
    /// E words are increments (M83, or G91 with Marlin's semantics).
    pub e_relative: bool,
    /// Feed in effect, mm/min (`None` before any F word).
    pub feed: Option<f64>,
}

impl Default for Modes {
    fn default() -> Self {
        Modes {
            motion: None,
            plane: Plane::Xy,
            units: Units::Mm,
            relative: false,
            absolute_arc_centres: false,
            inverse_time: false,
            e_relative: false,
            feed: None,
        }
    }
}

/// A motion block: where it goes, in mm, and whether a filter may merge it into others.
#[derive(Clone, Debug, PartialEq)]
pub struct MoveBlock {
    /// 1-based source line.
    pub line: u32,
    /// The line's text in the program source (without the line break).
    pub span: Range<usize>,
    /// Motion of this block.
    pub motion: Motion,
    /// True if the block has its own G0..G3 word (false for modal moves).
    pub explicit: bool,
    /// Start position (mm); meaningful only if `start_known`.
    pub start: P3,
    /// False after a block that moved the machine in a way the reader does not model (G28, G92,
    /// tool length offsets): the start is then unknown.
    pub start_known: bool,
    /// End position (mm, absolute; in G91 files relative to the first known position).
    pub end: P3,
    /// Arc centre in plane coordinates (mm), for G2/G3.
    pub centre: Option<P2>,
    /// Whole turns of a G2/G3 `P` word beyond the first (0 when absent).
    pub turns: u32,
    /// Modes in effect.
    pub modes: Modes,
    /// The block has an F word.
    pub has_f: bool,
    /// E word value as written (increment or absolute, per `modes.e_relative`).
    pub e: Option<f64>,
    /// Extrusion of this block (the increment), when it is known: always for relative E, for
    /// absolute E once an earlier E or a G92 E gave the reference.
    pub e_delta: Option<f64>,
    /// N block number.
    pub n: Option<u64>,
    /// True if the block holds nothing but the motion, its coordinates, F, E, N: a filter may
    /// replace it. False if it also carries words the reader does not model (M, S, T, A/B/C,
    /// other G codes), a comment, or a checksum; such a block is written back verbatim.
    pub plain: bool,
}

/// A block the reader does not interpret as motion: written back verbatim.
#[derive(Clone, Debug, PartialEq)]
pub struct OtherBlock {
    /// 1-based source line.
    pub line: u32,
    /// The line's text in the program source.
    pub span: Range<usize>,
    /// Modes in effect after the block.
    pub modes: Modes,
    /// The block has a group-1 word (G0..G3, G80) that sets the modal motion.
    pub motion_word: bool,
    /// The block has no words at all: blank, or only a comment.
    pub remark_only: bool,
}

/// One line of a program.
#[derive(Clone, Debug, PartialEq)]
pub enum Block {
    /// G0..G3 with coordinates.
    Move(MoveBlock),
    /// Anything else: comments, blank lines, M/S/T words, other G codes, modal-only lines.
    Other(OtherBlock),
}

impl Block {
    /// The source line's text range.
    pub fn span(&self) -> Range<usize> {
        match self {
            Block::Move(m) => m.span.clone(),
            Block::Other(o) => o.span.clone(),
        }
    }

    /// Modes in effect after the block.
    pub fn modes(&self) -> &Modes {
        match self {
            Block::Move(m) => &m.modes,
            Block::Other(o) => &o.modes,
        }
    }
}

/// A parsed program: its source text and one block per line.
#[derive(Clone, Debug)]
pub struct Program {
    /// The program text.
    pub source: String,
    /// Blocks in order, one per source line.
    pub blocks: Vec<Block>,
    /// Most decimals seen per kind of word, to write numbers back with the same precision.
    pub decimals: Decimals,
}

impl Program {
    /// The text of a block's line.
    pub fn text(&self, block: &Block) -> &str {
        &self.source[block.span()]
    }

    /// Number of motion blocks by kind: (G0, G1, G2+G3).
    pub fn move_counts(&self) -> (usize, usize, usize) {
        let mut n = (0, 0, 0);
        for b in &self.blocks {
            if let Block::Move(m) = b {
                match m.motion {
                    Motion::Rapid => n.0 += 1,
                    Motion::Line => n.1 += 1,
                    Motion::Cw | Motion::Ccw => n.2 += 1,
                }
            }
        }
        n
    }
}
