//! Contours back into the toolpath table (reading them is `camkit::contour::table`'s job).

use camkit::contour::{Contour, Seg};
use camkit::geom::{P3, Plane};
use camkit::table::{Col, Move, Row, Table};

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
