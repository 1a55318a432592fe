//! Reading the toolpath table: header by name in any order, `#` comments, defaults, and errors
//! that name file, line, field number and column.

use super::{Col, Field, Move, Row, Schema, Table, columns};
use crate::error::{Error, Location, Result};
use crate::geom::{P2, P3, Plane, V3};
use crate::io::Input;
use crate::num::parse_finite;

/// Where each typed column sits in a record (field index), if present.
struct Layout {
    at: [Option<usize>; 21],
    extras: Vec<usize>,
}

impl Layout {
    fn get(&self, col: Col) -> Option<usize> {
        self.at[col as usize]
    }
}

/// Reads a whole table from `input`. `required` columns must be in the header.
pub fn read(input: &Input, required: &[Col]) -> Result<Table> {
    let mut rows = Vec::new();
    let schema = read_each(input, required, |_, row| {
        rows.push(row);
        Ok(())
    })?;
    Ok(Table { schema, rows })
}

/// Reads `input` row by row, handing each row to `on_row` as it is parsed (with the schema), so
/// that a filter working run by run need not hold the table's rows; returns the schema. An error
/// of `on_row` stops the reading and is returned.
pub fn read_each(
    input: &Input,
    required: &[Col],
    mut on_row: impl FnMut(&Schema, Row) -> Result<()>,
) -> Result<Schema> {
    let data = normalise(&input.data);
    let mut reader =
        csv::ReaderBuilder::new().comment(Some(b'#')).trim(csv::Trim::All).flexible(false).from_reader(&data[..]);
    let loc = |line: u64| Location::file(&input.name).line(line);
    let mut lines = LineCounter { data: &data, byte: 0, line: 1 };
    let header = reader.byte_headers().map_err(|e| csv_error(e, &input.name, &mut lines))?.clone();
    if header.is_empty() || header.iter().all(|h| h.is_empty()) {
        return Err(Error::input("empty input: expected a header row naming the columns (e.g. x,y,z)")
            .at(Location::file(&input.name)));
    }
    let header_line = header.position().map_or(1, |p| lines.at(p.byte()));
    let (schema, layout) = parse_header(&header, &input.name, header_line)?;
    for &col in required {
        if !schema.has(col) {
            return Err(Error::input(format!("missing column `{}`", columns::spec(col).name)).at(loc(header_line)));
        }
    }
    let mut record = csv::ByteRecord::new();
    loop {
        match reader.read_byte_record(&mut record) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => return Err(csv_error(e, &input.name, &mut lines)),
        }
        let line = record.position().map_or(0, |p| lines.at(p.byte()));
        on_row(&schema, parse_row(&record, &layout, &schema, &input.name, line)?)?;
    }
    Ok(schema)
}

/// The text with old Mac line ends (a lone CR) made LF and lines of only spaces and tabs made
/// comments, byte for byte, so that the csv reader skips them as it skips empty lines and offsets
/// stay those of the input. Borrowed when there is nothing to change.
fn normalise(data: &[u8]) -> std::borrow::Cow<'_, [u8]> {
    let lone_cr = |k: usize| data[k] == b'\r' && data.get(k + 1) != Some(&b'\n');
    let blank_at = |k: usize| {
        let rest = &data[k..];
        let n = rest.iter().take_while(|b| matches!(b, b' ' | b'\t')).count();
        n > 0 && matches!(rest.get(n), None | Some(b'\n' | b'\r'))
    };
    let starts = || std::iter::once(0).chain(memchr::memchr2_iter(b'\n', b'\r', data).map(|k| k + 1));
    if !memchr::memchr_iter(b'\r', data).any(lone_cr) && !starts().any(|k| k < data.len() && blank_at(k)) {
        return std::borrow::Cow::Borrowed(data);
    }
    let mut out = data.to_vec();
    for k in memchr::memchr_iter(b'\r', data).filter(|&k| lone_cr(k)) {
        out[k] = b'\n';
    }
    for k in starts().filter(|&k| k < data.len() && blank_at(k)) {
        out[k] = b'#';
    }
    std::borrow::Cow::Owned(out)
}

/// Line numbers from byte offsets (the csv crate does not count `#` comment lines).
struct LineCounter<'a> {
    data: &'a [u8],
    byte: usize,
    line: u64,
}

impl LineCounter<'_> {
    /// 1-based line of the record the csv reader says starts at `byte`: that offset may point
    /// at comment or blank lines it skipped first. Offsets must not decrease between calls.
    fn at(&mut self, byte: u64) -> u64 {
        let mut byte = (byte as usize).min(self.data.len());
        while matches!(self.data.get(byte), Some(b'#' | b'\n' | b'\r')) {
            byte = memchr::memchr(b'\n', &self.data[byte..]).map_or(self.data.len(), |k| byte + k + 1);
        }
        let byte = byte.min(self.data.len());
        self.line += memchr::memchr_iter(b'\n', &self.data[self.byte..byte]).count() as u64;
        self.byte = byte;
        self.line
    }
}

fn csv_error(e: csv::Error, file: &str, lines: &mut LineCounter) -> Error {
    let line = e.position().map(|p| lines.at(p.byte()));
    let message = match e.kind() {
        csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
            format!("expected {expected_len} fields like the header, found {len}")
        }
        csv::ErrorKind::Utf8 { .. } => "text is not valid UTF-8".to_string(),
        csv::ErrorKind::Io(io) => return Error::io(std::io::Error::new(io.kind(), io.to_string()), file),
        _ => e.to_string(),
    };
    let mut loc = Location::file(file);
    loc.line = line;
    Error::input(message).at(loc)
}

fn parse_header(header: &csv::ByteRecord, file: &str, line: u64) -> Result<(Schema, Layout)> {
    let mut schema = Schema::default();
    let mut layout = Layout { at: [None; 21], extras: Vec::new() };
    for (i, raw) in header.iter().enumerate() {
        let name = std::str::from_utf8(raw)
            .map_err(|_| Error::input("header is not valid UTF-8").at(Location::file(file).line(line)))?;
        let at = || Location::file(file).line(line).column(i as u64 + 1);
        if name.is_empty() {
            return Err(Error::input("empty column name in the header").at(at()));
        }
        match columns::by_name(&name.to_ascii_lowercase()) {
            Some(col) => {
                if layout.at[col as usize].is_some() {
                    return Err(Error::input(format!("column `{name}` appears twice")).at(at()));
                }
                layout.at[col as usize] = Some(i);
                schema.fields.push(Field::Known(col));
            }
            None => {
                if schema.extra_names.iter().any(|n| n == name) {
                    return Err(Error::input(format!("column `{name}` appears twice")).at(at()));
                }
                schema.fields.push(Field::Extra(schema.extra_names.len()));
                schema.extra_names.push(name.to_string());
                layout.extras.push(i);
            }
        }
    }
    let groups: [&[Col]; 3] = [&[Col::Px, Col::Py, Col::Pz], &[Col::Nx, Col::Ny, Col::Nz], &[Col::I, Col::J, Col::K]];
    for group in groups {
        let present: Vec<_> = group.iter().filter(|c| schema.has(**c)).collect();
        if !present.is_empty() && present.len() < group.len() {
            let names: Vec<_> = group.iter().map(|c| columns::spec(*c).name).collect();
            return Err(Error::input(format!("columns {} go together: some are missing", names.join(", ")))
                .at(Location::file(file).line(line)));
        }
    }
    Ok((schema, layout))
}

/// Reads the fields of one record into a row.
struct Fields<'a> {
    record: &'a csv::ByteRecord,
    layout: &'a Layout,
    file: &'a str,
    line: u64,
}

impl Fields<'_> {
    fn loc(&self, index: usize, name: &str) -> Location {
        Location::file(self.file).line(self.line).column(index as u64 + 1).field(name)
    }

    fn text(&self, col: Col) -> Result<Option<(usize, &str)>> {
        let Some(i) = self.layout.get(col) else { return Ok(None) };
        let raw = &self.record[i];
        let text = std::str::from_utf8(raw)
            .map_err(|_| Error::input("text is not valid UTF-8").at(self.loc(i, columns::spec(col).name)))?;
        Ok(Some((i, text)))
    }

    /// The number in `col`, `None` if the column is absent or the field empty.
    fn opt(&self, col: Col) -> Result<Option<f64>> {
        match self.text(col)? {
            None => Ok(None),
            Some((_, "")) => Ok(None),
            Some((i, t)) => {
                let v =
                    parse_finite(t).map_err(|e| Error::input(e.message(t)).at(self.loc(i, columns::spec(col).name)))?;
                let position =
                    matches!(col, Col::X | Col::Y | Col::Z | Col::Xc | Col::Yc | Col::Zc | Col::Px | Col::Py | Col::Pz);
                if position && v.abs() > crate::tol::COORD_LIMIT {
                    return Err(Error::input(format!(
                        "{v:e} mm is beyond ±{:e} mm, where the micrometre tolerances fall below the floating-point resolution",
                        crate::tol::COORD_LIMIT
                    ))
                    .at(self.loc(i, columns::spec(col).name)));
                }
                Ok(Some(v))
            }
        }
    }

    /// The number in `col`, or `default` when absent or empty.
    fn num(&self, col: Col, default: f64) -> Result<f64> {
        Ok(self.opt(col)?.unwrap_or(default))
    }

    /// The number in `col`, which must be there.
    fn need(&self, col: Col, why: &str) -> Result<f64> {
        match self.opt(col)? {
            Some(v) => Ok(v),
            None => {
                let name = columns::spec(col).name;
                Err(match self.layout.get(col) {
                    Some(i) => {
                        Error::input(format!("expected a number{why}, found an empty field")).at(self.loc(i, name))
                    }
                    None => Error::input(format!("missing column `{name}`{why}"))
                        .at(Location::file(self.file).line(self.line).field(name)),
                })
            }
        }
    }

    fn triple(&self, cols: [Col; 3]) -> Result<Option<[f64; 3]>> {
        let v = [self.opt(cols[0])?, self.opt(cols[1])?, self.opt(cols[2])?];
        match v {
            [Some(a), Some(b), Some(c)] => Ok(Some([a, b, c])),
            [None, None, None] => Ok(None),
            _ => {
                let missing = cols.iter().zip(v).find(|(_, x)| x.is_none()).map(|(c, _)| *c).unwrap_or(cols[0]);
                Err(Error::input("empty field where its companions have values")
                    .at(self.loc(self.layout.get(missing).unwrap_or(0), columns::spec(missing).name)))
            }
        }
    }
}

fn parse_row(record: &csv::ByteRecord, layout: &Layout, schema: &Schema, file: &str, line: u64) -> Result<Row> {
    let f = Fields { record, layout, file, line };
    let path = match f.text(Col::Path)? {
        None | Some((_, "")) => 0,
        Some((i, t)) => t
            .parse::<i64>()
            .map_err(|_| Error::input(format!("expected an integer path id, found \"{t}\"")).at(f.loc(i, "path")))?,
    };
    let mv = match f.text(Col::Move)? {
        None => Move::Line,
        Some((i, t)) => Move::parse(t).ok_or_else(|| {
            Error::input(format!("expected rapid, line, cw or ccw, found \"{t}\"")).at(f.loc(i, "move"))
        })?,
    };
    let plane = match f.text(Col::Plane)? {
        None | Some((_, "")) => Plane::Xy,
        Some((i, t)) => Plane::parse(t)
            .ok_or_else(|| Error::input(format!("expected xy, xz or yz, found \"{t}\"")).at(f.loc(i, "plane")))?,
    };
    let pos = P3::new(f.need(Col::X, "")?, f.need(Col::Y, "")?, f.num(Col::Z, 0.0)?);
    let centre = if mv.is_arc() {
        let why = " (arc centre of a cw/ccw move)";
        let (xc, yc, zc) = (Col::Xc, Col::Yc, Col::Zc);
        Some(match plane {
            Plane::Xy => P2::new(f.need(xc, why)?, f.need(yc, why)?),
            Plane::Xz => P2::new(f.need(zc, why)?, f.need(xc, why)?),
            Plane::Yz => P2::new(f.need(yc, why)?, f.need(zc, why)?),
        })
    } else {
        None
    };
    let axis = f.triple([Col::I, Col::J, Col::K])?.map_or(V3::z(), V3::from);
    let contact = f.triple([Col::Px, Col::Py, Col::Pz])?.map(P3::from);
    let normal = f.triple([Col::Nx, Col::Ny, Col::Nz])?.map(V3::from);
    let tag = match f.text(Col::Tag)? {
        Some((_, t)) => t.to_string(),
        None => String::new(),
    };
    let mut extra = Vec::with_capacity(layout.extras.len());
    for (k, &i) in layout.extras.iter().enumerate() {
        let text = std::str::from_utf8(&record[i])
            .map_err(|_| Error::input("text is not valid UTF-8").at(f.loc(i, &schema.extra_names[k])))?;
        extra.push(text.to_string());
    }
    Ok(Row {
        path,
        mv,
        pos,
        centre,
        plane,
        axis,
        s: f.opt(Col::S)?,
        f: f.opt(Col::F)?,
        contact,
        normal,
        tag,
        extra,
        line,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(text: &str) -> Input {
        Input { name: "in.csv".into(), data: text.as_bytes().to_vec() }
    }

    #[test]
    fn any_order_comments_defaults_and_extras() {
        let t =
            read(&input("# a comment\nz,speed,y,x\n1,fast,2,3\n# another\n4,slow,5,6\n"), &[Col::X, Col::Y]).unwrap();
        assert_eq!(t.rows.len(), 2);
        assert_eq!(t.rows[0].pos, P3::new(3.0, 2.0, 1.0));
        assert_eq!(t.rows[1].extra, vec!["slow".to_string()]);
        assert_eq!(t.rows[1].line, 5);
        assert_eq!(t.rows[0].axis, V3::z());
        assert_eq!(t.rows[0].mv, Move::Line);
        assert_eq!(t.schema.extra_names, vec!["speed".to_string()]);
    }

    #[test]
    fn bad_number_names_line_column_and_field() {
        let e = read(&input("x,y,z\n1,2,3\n1,2,\"1,2x\"\n"), &[Col::X, Col::Y]).unwrap_err();
        assert_eq!(e.to_string(), "in.csv:3:3 (z): expected a number, found \"1,2x\"");
        assert_eq!(e.exit_status(), 2);
        let e = read(&input("x,y\n1,1e12\n"), &[Col::X, Col::Y]).unwrap_err();
        assert!(e.to_string().starts_with("in.csv:2:2 (y): 1e12 mm is beyond ±1e9 mm"), "{e}");
        let e = read(&input("x,y\n1,NaN\n"), &[Col::X, Col::Y]).unwrap_err();
        assert_eq!(e.to_string(), "in.csv:2:2 (y): expected a finite number, found \"NaN\"");
    }

    #[test]
    fn missing_column_and_empty_file() {
        let e = read(&input("x,z\n1,2\n"), &[Col::X, Col::Y]).unwrap_err();
        assert_eq!(e.to_string(), "in.csv:1: missing column `y`");
        let e = read(&input(""), &[Col::X]).unwrap_err();
        assert!(e.to_string().starts_with("in.csv: empty input"), "{e}");
        let e = read(&input("x,y\n# note\n1,2,3\n"), &[Col::X]).unwrap_err();
        assert_eq!(e.to_string(), "in.csv:3: expected 2 fields like the header, found 3");
    }

    /// Lines of spaces are skipped like empty ones, old Mac line ends (CR alone) read like LF
    /// after a comment too, a BOM is dropped; line numbers stay those of the text.
    #[test]
    fn blank_lines_lone_cr_and_bom() {
        let t = read(&input("x,y\n0,0\n   \n\t\n1,1\n"), &[Col::X, Col::Y]).unwrap();
        assert_eq!((t.rows.len(), t.rows[1].line), (2, 5));
        let t = read(&input("# a sine\rx,y\r0,0\r  \r1,2\r"), &[Col::X, Col::Y]).unwrap();
        assert_eq!(t.rows.iter().map(|r| (r.pos.y, r.line)).collect::<Vec<_>>(), vec![(0.0, 3), (2.0, 5)]);
        let e = read(&input("x,y\r1,2\r1\r"), &[Col::X, Col::Y]).unwrap_err();
        assert_eq!(e.to_string(), "in.csv:3: expected 2 fields like the header, found 1");
        let t = read(&input("\u{feff}x,y\n1,2\n"), &[Col::X, Col::Y]).unwrap();
        assert_eq!(t.rows[0].pos.y, 2.0);
    }

    #[test]
    fn arcs_need_centres() {
        let e = read(&input("x,y,move\n1,2,cw\n"), &[Col::X, Col::Y]).unwrap_err();
        assert_eq!(e.to_string(), "in.csv:2 (xc): missing column `xc` (arc centre of a cw/ccw move)");
        let t = read(&input("x,y,z,move,xc,zc,plane\n1,2,3,ccw,0.5,0.25,xz\n"), &[]).unwrap();
        assert_eq!(t.rows[0].centre, Some(P2::new(0.25, 0.5)));
        assert_eq!(t.rows[0].plane, Plane::Xz);
    }
}
