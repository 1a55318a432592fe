//! Writing the toolpath table: the schema's columns in order, numbers either shortest
//! round-trip or fixed decimals.

use super::{Col, Field, Row, Schema, Table};
use crate::error::{Error, Result};
use crate::geom::Plane;
use crate::num::{push_fixed, push_shortest};
use std::io::Write;

/// How numbers are written.
#[derive(Clone, Copy, Debug, Default)]
pub struct WriteOptions {
    /// Fixed decimals for positions and centres (trailing zeros trimmed); `None` writes the
    /// shortest text that reads back exactly.
    pub decimals: Option<u32>,
}

/// Writes the table, header first.
pub fn write(out: &mut dyn Write, table: &Table, opts: &WriteOptions) -> Result<()> {
    let mut w = RowWriter::new(&table.schema, *opts);
    for row in &table.rows {
        w.row(out, row)?;
    }
    w.finish(out)
}

/// A table written row by row as the rows are made, so that they need not be held: the header
/// first, then each row, through a buffer of 64 kB.
pub struct RowWriter {
    schema: Schema,
    opts: WriteOptions,
    buf: Vec<u8>,
}

impl RowWriter {
    /// A writer of rows of `schema`, its header buffered.
    pub fn new(schema: &Schema, opts: WriteOptions) -> RowWriter {
        let mut buf: Vec<u8> = Vec::with_capacity(1 << 16);
        for (n, field) in schema.fields.iter().enumerate() {
            if n > 0 {
                buf.push(b',');
            }
            match field {
                Field::Known(c) => buf.extend_from_slice(super::columns::spec(*c).name.as_bytes()),
                Field::Extra(i) => push_text(&mut buf, &schema.extra_names[*i]),
            }
        }
        buf.push(b'\n');
        RowWriter { schema: schema.clone(), opts, buf }
    }

    /// Writes one row (to `out` once the buffer is full).
    pub fn row(&mut self, out: &mut dyn Write, row: &Row) -> Result<()> {
        let buf = &mut self.buf;
        for (n, field) in self.schema.fields.iter().enumerate() {
            if n > 0 {
                buf.push(b',');
            }
            match field {
                Field::Known(c) => push_value(buf, row, *c, &self.opts),
                Field::Extra(i) => push_text(buf, row.extra.get(*i).map_or("", String::as_str)),
            }
        }
        buf.push(b'\n');
        if buf.len() >= 1 << 16 {
            out.write_all(buf).map_err(|e| Error::io(e, "output"))?;
            buf.clear();
        }
        Ok(())
    }

    /// Writes what the buffer still holds.
    pub fn finish(self, out: &mut dyn Write) -> Result<()> {
        out.write_all(&self.buf).map_err(|e| Error::io(e, "output"))
    }
}

fn push_num(buf: &mut Vec<u8>, v: f64, decimals: Option<u32>) {
    match decimals {
        Some(d) => push_fixed(buf, v, d, true),
        None => push_shortest(buf, v),
    }
}

fn push_opt(buf: &mut Vec<u8>, v: Option<f64>, decimals: Option<u32>) {
    if let Some(v) = v {
        push_num(buf, v, decimals);
    }
}

/// A free-text field, quoted when it holds a separator, a quote or a line break.
fn push_text(buf: &mut Vec<u8>, text: &str) {
    if text.bytes().any(|b| matches!(b, b',' | b'"' | b'\n' | b'\r')) || text.starts_with('#') {
        buf.push(b'"');
        for b in text.bytes() {
            if b == b'"' {
                buf.push(b'"');
            }
            buf.push(b);
        }
        buf.push(b'"');
    } else {
        buf.extend_from_slice(text.as_bytes());
    }
}

fn push_value(buf: &mut Vec<u8>, row: &Row, col: Col, opts: &WriteOptions) {
    let d = opts.decimals;
    // The arc centre's coordinates by table column, depending on the plane.
    let centre = |axis: usize| -> Option<f64> {
        let c = row.centre?;
        let [u, v, _] = row.plane.axes();
        if axis == u {
            Some(c.x)
        } else if axis == v {
            Some(c.y)
        } else {
            None
        }
    };
    match col {
        Col::Path => buf.extend_from_slice(itoa::Buffer::new().format(row.path).as_bytes()),
        Col::Move => buf.extend_from_slice(row.mv.name().as_bytes()),
        Col::X => push_num(buf, row.pos.x, d),
        Col::Y => push_num(buf, row.pos.y, d),
        Col::Z => push_num(buf, row.pos.z, d),
        Col::Xc => push_opt(buf, centre(0), d),
        Col::Yc => push_opt(buf, centre(1), d),
        Col::Zc => push_opt(buf, centre(2), d),
        Col::Plane => {
            if row.mv.is_arc() || row.plane != Plane::Xy {
                buf.extend_from_slice(row.plane.name().as_bytes());
            }
        }
        Col::I => push_num(buf, row.axis.x, None),
        Col::J => push_num(buf, row.axis.y, None),
        Col::K => push_num(buf, row.axis.z, None),
        Col::S => push_opt(buf, row.s, None),
        Col::F => push_opt(buf, row.f, None),
        Col::Px => push_opt(buf, row.contact.map(|p| p.x), d),
        Col::Py => push_opt(buf, row.contact.map(|p| p.y), d),
        Col::Pz => push_opt(buf, row.contact.map(|p| p.z), d),
        Col::Nx => push_opt(buf, row.normal.map(|n| n.x), None),
        Col::Ny => push_opt(buf, row.normal.map(|n| n.y), None),
        Col::Nz => push_opt(buf, row.normal.map(|n| n.z), None),
        Col::Tag => push_text(buf, &row.tag),
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Move, Schema, read};
    use super::*;
    use crate::geom::{P2, P3};
    use crate::io::Input;

    fn text(table: &Table, opts: &WriteOptions) -> String {
        let mut out = Vec::new();
        write(&mut out, table, opts).unwrap();
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn round_trip_keeps_values_and_extras_in_order() {
        let src = "y,note,x,move,xc,yc,tag\n1.5,\"a, b\",2,line,,,\n0.25,c,3,ccw,1,0.1,\"q\"\"x\"\n";
        let input = Input { name: "t".into(), data: src.as_bytes().to_vec() };
        let t = read(&input, &[Col::X, Col::Y]).unwrap();
        let out = text(&t, &WriteOptions::default());
        assert_eq!(out, "y,note,x,move,xc,yc,tag\n1.5,\"a, b\",2.0,line,,,\n0.25,c,3.0,ccw,1.0,0.1,\"q\"\"x\"\n");
        let again = read(&Input { name: "t".into(), data: out.into_bytes() }, &[]).unwrap();
        let strip = |rows: &[Row]| rows.iter().map(|r| Row { line: 0, ..r.clone() }).collect::<Vec<_>>();
        assert_eq!(strip(&again.rows), strip(&t.rows));
    }

    #[test]
    fn schema_add_keeps_canonical_neighbourhood() {
        let mut s = Schema::of(&[Col::X, Col::Y, Col::Tag]);
        s.add(&[Col::Move, Col::Xc, Col::Yc]);
        assert_eq!(s, Schema::of(&[Col::Move, Col::X, Col::Y, Col::Xc, Col::Yc, Col::Tag]));
        let mut t = Table { schema: Schema::of(&[Col::X, Col::Y, Col::Move, Col::Xc, Col::Yc]), rows: vec![] };
        let mut r = Row::at(0, P3::new(1.0, 2.0, 0.0));
        r.mv = Move::Cw;
        r.centre = Some(P2::new(0.5, 0.125));
        t.rows.push(r);
        assert_eq!(text(&t, &WriteOptions { decimals: Some(3) }), "x,y,move,xc,yc\n1,2,cw,0.5,0.125\n");
    }
}
