//! G-code to toolpath table and back.

use super::{Block, Modes, Motion, OutMove, Program, Writer};
use crate::error::{Error, Location, Result};
use crate::geom::V3;
use crate::table::{Col, Move, Row, Schema, Table};
use crate::tol;

impl From<Motion> for Move {
    fn from(m: Motion) -> Move {
        match m {
            Motion::Rapid => Move::Rapid,
            Motion::Line => Move::Line,
            Motion::Cw => Move::Cw,
            Motion::Ccw => Move::Ccw,
        }
    }
}

impl From<Move> for Motion {
    fn from(m: Move) -> Motion {
        match m {
            Move::Rapid => Motion::Rapid,
            Move::Line => Motion::Line,
            Move::Cw => Motion::Cw,
            Move::Ccw => Motion::Ccw,
        }
    }
}

/// The program's moves as a table (mm). A rapid, or a move whose start is unknown, starts a new
/// `path`; the first row of a path is where it starts. Returns the table and the number of
/// non-motion blocks that a table cannot carry.
pub fn program_to_table(program: &Program) -> (Table, usize) {
    let mut rows = Vec::new();
    let mut path = 0i64;
    let mut skipped = 0;
    let mut any = false;
    for block in &program.blocks {
        let m = match block {
            Block::Move(m) => m,
            Block::Other(_) => {
                if !program.text(block).trim().is_empty() {
                    skipped += 1;
                }
                continue;
            }
        };
        if any && (m.motion == Motion::Rapid || !m.start_known) {
            path += 1;
        }
        if !m.start_known && m.motion != Motion::Rapid {
            // Nothing to draw from: the row marks where the pass begins.
            let mut r = Row::at(path, m.end);
            r.mv = Move::Rapid;
            r.line = u64::from(m.line);
            rows.push(r);
            any = true;
            continue;
        }
        let mut r = Row::at(path, m.end);
        r.mv = m.motion.into();
        r.centre = m.centre;
        r.plane = m.modes.plane;
        r.f = if m.motion == Motion::Rapid { None } else { m.modes.feed };
        r.line = u64::from(m.line);
        rows.push(r);
        any = true;
    }
    let mut schema = Schema::of(&[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::F]);
    if rows.iter().any(|r| r.mv.is_arc()) {
        schema.add(&[Col::Xc, Col::Yc]);
        if rows.iter().any(|r| r.mv.is_arc() && r.plane != crate::geom::Plane::Xy) {
            schema.add(&[Col::Zc, Col::Plane]);
        }
    }
    (Table { schema, rows }, skipped)
}

/// A 3-axis program (G21, G90) for a table: G0 for rapids, G1, G2/G3 with I/J/K, F when it
/// changes. Rows with a tool axis other than +Z cannot be written by a 3-axis writer.
pub fn table_to_program(table: &Table, name: &str, decimals: u32) -> Result<Vec<u8>> {
    let mut w = Writer::new(decimals, decimals, 5);
    w.raw("G21 G90 G17");
    let modes = Modes::default();
    let mut prev: Option<crate::geom::P3> = None;
    let mut feed: Option<f64> = None;
    for row in &table.rows {
        if (row.axis - V3::z()).norm() > tol::UNIT_VECTOR_SLACK {
            return Err(Error::input("tool axis is not 0,0,1: a 3-axis program cannot hold it (use post-6axis)")
                .at(Location::file(name).line(row.line).field("i,j,k")));
        }
        let motion: Motion = row.mv.into();
        let first = prev.is_none();
        let write_feed = motion != Motion::Rapid && row.f.is_some() && row.f != feed;
        if write_feed {
            feed = row.f;
        }
        let out = OutMove {
            motion: if first && motion.is_arc() { Motion::Line } else { motion },
            start: prev,
            end: row.pos,
            centre: if first { None } else { row.centre },
            plane: row.plane,
            feed: if write_feed { row.f } else { None },
            e: None,
            n: None,
        };
        w.motion(&out, &modes);
        prev = Some(row.pos);
    }
    Ok(w.out)
}

#[cfg(test)]
mod tests {
    use super::super::read;
    use super::*;

    #[test]
    fn program_table_program_keeps_every_position() {
        let src = "G21 G90\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10 Y0 F500\nG3 X10 Y10 I0 J5\nG2 X20 Y10 R5\nG0 Z5\n";
        let p = read("a.nc", src.into()).unwrap();
        let (t, skipped) = program_to_table(&p);
        assert_eq!(skipped, 1);
        assert_eq!(t.rows.len(), 6);
        assert_eq!(t.rows[3].mv, Move::Ccw);
        let text = table_to_program(&t, "t", 4).unwrap();
        let back = read("b.nc", String::from_utf8(text).unwrap()).unwrap();
        let (t2, _) = program_to_table(&back);
        assert_eq!(t2.rows.len(), t.rows.len());
        for (a, b) in t.rows.iter().zip(&t2.rows) {
            assert!((a.pos - b.pos).norm() < 1e-12, "{:?} vs {:?}", a.pos, b.pos);
            assert_eq!(a.mv, b.mv);
            match (a.centre, b.centre) {
                (Some(c1), Some(c2)) => assert!((c1 - c2).norm() < 1e-4),
                (None, None) => {}
                _ => panic!("centre lost"),
            }
        }
    }
}
