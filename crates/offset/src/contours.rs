//! The toolpath table as contours and back: each pass (`path`) is a chain of lines and arcs in
//! the XY plane at one z, closed when it ends where it starts.

use camkit::contour::{Contour, Seg, Vertex};
use camkit::error::{Error, Location, Result};
use camkit::geom::{Arc2, P2, P3, Plane};
use camkit::table::{Col, Move, Row, Table};
use camkit::tol;

/// A contour read from the table, with what is needed to write its offsets back.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// The contour in XY.
    pub contour: Contour,
    /// Its `path` id.
    pub path: i64,
    /// Its height.
    pub z: f64,
    /// Index of its first row in the table (its pass-through values).
    pub row: usize,
    /// Source line of its first row.
    pub line: u64,
    /// Source line of its last row.
    pub last_line: u64,
}

/// Contours of a table and what reading them found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Read {
    /// The contours in input order.
    pub sources: Vec<Source>,
    /// Zero-length moves dropped.
    pub dropped: usize,
    /// Largest difference between an arc's start and end radius about its centre (mm).
    pub arc_mismatch: f64,
}

/// Reads every pass of `table` as a contour. A `rapid` row inside a pass starts a new contour.
pub fn read(table: &Table, name: &str) -> Result<Read> {
    let mut out = Read::default();
    let mut start = 0;
    while start < table.rows.len() {
        let path = table.rows[start].path;
        let mut end = start + 1;
        while end < table.rows.len() && table.rows[end].path == path && table.rows[end].mv != Move::Rapid {
            end += 1;
        }
        let src = one(&table.rows, start, end, name, &mut out)?;
        out.sources.extend(src);
        start = end;
    }
    Ok(out)
}

fn one(rows: &[Row], start: usize, end: usize, name: &str, out: &mut Read) -> Result<Option<Source>> {
    let at = |r: &Row| Location::file(name).line(r.line);
    let z = rows[start].pos.z;
    let mut pts: Vec<Vertex> = vec![Vertex { p: flat(&rows[start].pos), bulge: 0.0 }];
    for r in &rows[start + 1..end] {
        if (r.pos.z - z).abs() > tol::POINT_EPS {
            return Err(Error::input(format!(
                "a contour lies at one z: this path starts at z = {z} and reaches z = {} (use --3d for 3D contours)",
                r.pos.z
            ))
            .at(at(r).field("z")));
        }
        if r.mv.is_arc() && r.plane != Plane::Xy {
            return Err(Error::input(format!(
                "arcs of a contour lie in the xy plane, this one in {} (use --profile for a profile in a vertical plane)",
                r.plane.name()
            ))
            .at(at(r).field("plane")));
        }
        let p = flat(&r.pos);
        let from = pts.last().expect("a first vertex").p;
        if (p - from).norm() <= tol::POINT_EPS {
            out.dropped += 1;
            continue;
        }
        let bulge = match (r.mv, r.centre) {
            (Move::Cw | Move::Ccw, Some(c)) => {
                let (r0, r1) = ((from - c).norm(), (p - c).norm());
                let mismatch = (r0 - r1).abs();
                if mismatch > tol::ARC_END_MISMATCH {
                    return Err(Error::input(format!(
                        "the arc's ends are not on one circle about its centre: radii {r0:.6} and {r1:.6} mm"
                    ))
                    .at(at(r).field("xc")));
                }
                out.arc_mismatch = out.arc_mismatch.max(mismatch);
                let arc = Arc2::from_centre(c, &from, &p, r.mv == Move::Ccw, false);
                (arc.sweep / 4.0).tan()
            }
            _ => 0.0,
        };
        pts.last_mut().expect("a first vertex").bulge = bulge;
        pts.push(Vertex { p, bulge: 0.0 });
    }
    if pts.len() < 2 {
        out.dropped += usize::from(end - start > 1);
        return Ok(None);
    }
    let closed = (pts[0].p - pts[pts.len() - 1].p).norm() <= tol::POINT_EPS;
    if closed {
        pts.pop();
    }
    // A full circle written as one arc: split it into two halves.
    if closed && pts.len() == 1 {
        let (p, b) = (pts[0].p, pts[0].bulge);
        let Some(Row { centre: Some(c), .. }) = rows[start + 1..end].iter().find(|r| r.mv.is_arc()) else {
            return Ok(None);
        };
        let half = if b >= 0.0 { 1.0 } else { -1.0 };
        pts = vec![Vertex { p, bulge: half }, Vertex { p: c + (c - p), bulge: half }];
    }
    Ok(Some(Source {
        contour: Contour { vertices: pts, closed },
        path: rows[start].path,
        z,
        row: start,
        line: rows[start].line,
        last_line: rows[end - 1].line,
    }))
}

fn flat(p: &P3) -> P2 {
    P2::new(p.x, p.y)
}

/// The rows of `c` at height `z` as pass `path`: a `rapid` row where it starts, then one row per
/// piece; pass-through values come from `template`.
pub fn rows(c: &Contour, path: i64, z: f64, template: &Row) -> Vec<Row> {
    let base = Row {
        path,
        line: 0,
        contact: None,
        normal: None,
        centre: None,
        plane: Plane::Xy,
        mv: Move::Line,
        pos: P3::origin(),
        ..template.clone()
    };
    let mut out = Vec::with_capacity(c.vertices.len() + 1);
    let Some(first) = c.vertices.first() else { return out };
    out.push(Row { mv: Move::Rapid, pos: P3::new(first.p.x, first.p.y, z), ..base.clone() });
    for s in c.segs() {
        let e = s.end();
        let (mv, centre) = match s {
            Seg::Line(..) => (Move::Line, None),
            Seg::Arc(a) => (if a.ccw() { Move::Ccw } else { Move::Cw }, Some(a.c)),
        };
        out.push(Row { mv, centre, pos: P3::new(e.x, e.y, z), ..base.clone() });
    }
    out
}

/// The output table's schema: the input's, with the geometry columns this filter writes and
/// without the contact columns (they describe the input, not the offset).
pub fn schema(input: &Table) -> Table {
    let mut t = Table { schema: input.schema.clone(), rows: Vec::new() };
    t.schema.remove(&[Col::Px, Col::Py, Col::Pz, Col::Nx, Col::Ny, Col::Nz, Col::Zc, Col::Plane]);
    t.schema.add(&[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::Xc, Col::Yc]);
    t
}
