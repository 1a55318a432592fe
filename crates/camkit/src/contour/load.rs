//! Closed contours from a file, whatever a user brings: a DXF drawing (by extension) or the
//! toolpath table; and the pocket regions (boundaries with islands) they make.

use super::region::Region;
use super::table::{self as contour_table, Source};
use crate::contour::Seg;
use crate::error::{Error, Location, Result};
use crate::geom::{P2, P3};
use crate::io::Input;
use crate::table::{self, Col, Move};

/// Contours read from one input, with what was skipped.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Loaded {
    /// The contours in input order.
    pub sources: Vec<Source>,
    /// DXF entities that are not contours: their kind and line.
    pub skipped: Vec<(String, u64)>,
}

/// Reads the contours of `input`: DXF when its name ends in `.dxf`, the toolpath table otherwise.
pub fn contours(input: &Input) -> Result<Loaded> {
    let name = input.name.clone();
    if input.extension() == "dxf" {
        let read = crate::dxf::read(&name, &String::from_utf8_lossy(&input.data))?;
        return Ok(Loaded { sources: read.sources, skipped: read.skipped });
    }
    let t = table::read(input, &[Col::X, Col::Y])?;
    if t.rows.is_empty() {
        return Err(Error::input("no rows: no contour").at(Location::file(&name)));
    }
    Ok(Loaded { sources: contour_table::read(&t, &name)?.sources, skipped: Vec::new() })
}

/// The input as the toolpath table (with the DXF entities skipped): the table itself, or a DXF
/// drawing's closed contours as passes (`path` numbering them, a `line` row at the start, then a
/// `line`, `cw` or `ccw` row per piece; every row on its contour's first DXF line), so that a
/// filter made for tables takes drawings too.
pub fn table(input: &Input) -> Result<(table::Table, Vec<(String, u64)>)> {
    if input.extension() != "dxf" {
        return Ok((table::read(input, &[Col::X, Col::Y])?, Vec::new()));
    }
    let loaded = contours(input)?;
    if loaded.sources.is_empty() {
        return Err(Error::input("no closed contour in the drawing").at(Location::file(&input.name)));
    }
    let mut t = table::Table::default();
    t.schema.add(&[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::Xc, Col::Yc]);
    for s in &loaded.sources {
        let row = |p: P2, mv: Move, centre: Option<P2>| table::Row {
            mv,
            centre,
            line: s.line,
            ..table::Row::at(s.path, P3::new(p.x, p.y, s.z))
        };
        let v = &s.contour.vertices;
        t.rows.push(row(v[0].p, Move::Line, None));
        for i in 0..s.contour.seg_count() {
            // Ends at the next vertex as drawn (not recomputed from the arc's angles).
            let end = v[(i + 1) % v.len()].p;
            t.rows.push(match s.contour.seg(i) {
                Seg::Line(..) => row(end, Move::Line, None),
                Seg::Arc(a) => row(end, if a.ccw() { Move::Ccw } else { Move::Cw }, Some(a.c)),
            });
        }
    }
    Ok((t, loaded.skipped))
}

/// The pocket regions of the closed contours in the file `path` (DXF or table): outer boundaries
/// counter-clockwise with their islands clockwise.
pub fn regions(path: &str) -> Result<Vec<Region>> {
    let input = Input::open(path)?;
    let loaded = contours(&input)?;
    if loaded.sources.is_empty() {
        return Err(Error::input("no closed contour in the input").at(Location::file(&input.name)));
    }
    Ok(contour_table::pocket_regions(&loaded.sources, &input.name)?.0)
}
