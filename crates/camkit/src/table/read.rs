//! Reading the toolpath table: header by name in any order, `#` comments, defaults, and errors
//! that name file, line, field number and column.

use super::{Col, Field, Move, Row, Schema, Table, columns};
use crate::error::{Error, Location, Result};
use crate::geom::{P2, P3, Plane, V3};
use crate::io::{Input, Source};
use crate::num::parse_finite;
use std::cell::RefCell;
use std::collections::VecDeque;
use std::io::{BufRead, Read};
use std::rc::Rc;

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
pub fn read_each(input: &Input, required: &[Col], on_row: impl FnMut(&Schema, Row) -> Result<()>) -> Result<Schema> {
    let data = normalise(&input.data);
    let reader = csv_reader(&data[..]);
    each_record(reader, &input.name, &mut LineCounter { data: &data, byte: 0, line: 1 }, required, on_row)
}

/// [`read_each`] from a [`Source`] read as a stream: never the input's text held whole, only the
/// line at hand and what the csv reader buffers. The same rows, and the same errors at the same
/// lines, as [`read_each`] reads from the whole text.
pub fn read_each_source(
    source: &Source,
    required: &[Col],
    on_row: impl FnMut(&Schema, Row) -> Result<()>,
) -> Result<Schema> {
    let lines = Rc::new(RefCell::new(LineStarts::default()));
    let text = Normalising {
        inner: source.reader()?,
        out: Vec::new(),
        at: 0,
        emitted: 0,
        ends_line: false,
        lines: lines.clone(),
    };
    each_record(csv_reader(text), &source.name, &mut StreamLines { lines, line: 1 }, required, on_row)
}

fn csv_reader<R: Read>(r: R) -> csv::Reader<R> {
    csv::ReaderBuilder::new().comment(Some(b'#')).trim(csv::Trim::All).flexible(false).from_reader(r)
}

/// The header and every record of `reader` (normalised text), lines counted by `lines`.
fn each_record<R: Read>(
    mut reader: csv::Reader<R>,
    name: &str,
    lines: &mut dyn LineAt,
    required: &[Col],
    mut on_row: impl FnMut(&Schema, Row) -> Result<()>,
) -> Result<Schema> {
    let loc = |line: u64| Location::file(name).line(line);
    let header = reader.byte_headers().map_err(|e| csv_error(e, name, lines))?.clone();
    if header.is_empty() || header.iter().all(|h| h.is_empty()) {
        return Err(
            Error::input("empty input: expected a header row naming the columns (e.g. x,y,z)").at(Location::file(name))
        );
    }
    let header_line = header.position().map_or(1, |p| lines.at(p.byte()));
    let (schema, layout) = parse_header(&header, name, header_line)?;
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
            Err(e) => return Err(csv_error(e, name, lines)),
        }
        let line = record.position().map_or(0, |p| lines.at(p.byte()));
        on_row(&schema, parse_row(&record, &layout, &schema, name, line)?)?;
    }
    Ok(schema)
}

/// Lines of the normalised text seen so far by a [`Normalising`] reader and not yet passed by
/// the line count: (start offset, first byte; none for the empty line after a last LF), and
/// where the text ended if it has.
#[derive(Default)]
struct LineStarts {
    starts: VecDeque<(u64, Option<u8>)>,
    end: Option<u64>,
}

/// The input normalised as [`normalise`] does, line by line as it is read, recording where each
/// line starts for [`StreamLines`].
struct Normalising<R> {
    inner: R,
    out: Vec<u8>,
    at: usize,
    emitted: u64,
    ends_line: bool,
    lines: Rc<RefCell<LineStarts>>,
}

impl<R: BufRead> Normalising<R> {
    /// Reads the next input line (to LF or the end) into `out`, normalised; false at the end.
    fn refill(&mut self) -> std::io::Result<bool> {
        self.out.clear();
        self.at = 0;
        if self.inner.read_until(b'\n', &mut self.out)? == 0 {
            let mut lines = self.lines.borrow_mut();
            if self.ends_line {
                lines.starts.push_back((self.emitted, None));
            }
            lines.end = Some(self.emitted);
            return Ok(false);
        }
        let n = self.out.len();
        // A CR is lone unless the LF closing this line follows it.
        for k in 0..n {
            if self.out[k] == b'\r' && !(k + 1 < n && self.out[k + 1] == b'\n') {
                self.out[k] = b'\n';
            }
        }
        let mut lines = self.lines.borrow_mut();
        let mut start = 0;
        while start < n {
            let rest = &self.out[start..];
            let blanks = rest.iter().take_while(|b| matches!(b, b' ' | b'\t')).count();
            // A line of only spaces and tabs ends at a line break or at the input's end (the
            // last line read has no LF only there).
            if blanks > 0 && matches!(rest.get(blanks), None | Some(b'\n' | b'\r')) {
                self.out[start] = b'#';
            }
            lines.starts.push_back((self.emitted + start as u64, Some(self.out[start])));
            start = memchr::memchr(b'\n', &self.out[start..]).map_or(n, |k| start + k + 1);
        }
        self.emitted += n as u64;
        self.ends_line = self.out[n - 1] == b'\n';
        Ok(true)
    }
}

impl<R: BufRead> Read for Normalising<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.at == self.out.len() && !self.refill()? {
            return Ok(0);
        }
        let n = buf.len().min(self.out.len() - self.at);
        buf[..n].copy_from_slice(&self.out[self.at..self.at + n]);
        self.at += n;
        Ok(n)
    }
}

/// 1-based line of the record the csv reader says starts at a byte offset: that offset may point
/// at comment or blank lines it skipped first. Offsets must not decrease between calls.
trait LineAt {
    fn at(&mut self, byte: u64) -> u64;
}

/// [`LineAt`] over the line starts a [`Normalising`] reader records: the lines before the
/// offset are dropped as they are counted.
struct StreamLines {
    lines: Rc<RefCell<LineStarts>>,
    line: u64,
}

impl LineAt for StreamLines {
    fn at(&mut self, byte: u64) -> u64 {
        let mut lines = self.lines.borrow_mut();
        let LineStarts { starts, end } = &mut *lines;
        // The line holding `byte`.
        let mut byte = byte.min(end.unwrap_or(u64::MAX));
        while let Some(&(start, _)) = starts.get(1)
            && start <= byte
        {
            starts.pop_front();
            self.line += 1;
        }
        // Comment and blank lines the reader skipped, and the LF of a CRLF (the reader ends a
        // record at its CR): a line that ends at an LF has the next line's start after it.
        while let (Some(&(start, first)), Some(&(next, _))) = (starts.front(), starts.get(1)) {
            let blank = start == byte && matches!(first, Some(b'#' | b'\n' | b'\r'));
            if !blank && byte + 1 != next {
                break;
            }
            starts.pop_front();
            self.line += 1;
            byte = next;
        }
        self.line
    }
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

impl LineAt for LineCounter<'_> {
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

fn csv_error(e: csv::Error, file: &str, lines: &mut dyn LineAt) -> Error {
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

    /// Rows read as (position, line), or the error.
    type Rows = Result<Vec<(P3, u64)>>;

    /// The whole text read and the text streamed from a file: the same rows at the same lines,
    /// or the same error.
    fn both(text: &[u8]) -> (Rows, Rows) {
        let mut file = tempfile::NamedTempFile::new().unwrap();
        std::io::Write::write_all(&mut file, text).unwrap();
        let name = file.path().to_str().unwrap().to_string();
        let rows = |rows: &mut Vec<(P3, u64)>, row: Row| rows.push((row.pos, row.line));
        let mut whole = Vec::new();
        let whole = read_each(&Input { name: name.clone(), data: text.to_vec() }, &[Col::X], |_, r| {
            rows(&mut whole, r);
            Ok(())
        })
        .map(|_| whole);
        let mut streamed = Vec::new();
        let streamed = read_each_source(&Source::open(&name).unwrap(), &[Col::X], |_, r| {
            rows(&mut streamed, r);
            Ok(())
        })
        .map(|_| streamed);
        (whole, streamed)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 400, ..Default::default() })]

        /// Streamed from a file, a table reads as it does whole: comments, blank lines of spaces,
        /// lone CRs, CRLF, a missing last LF, short and long records, bad numbers.
        #[test]
        fn streamed_reads_as_whole(pieces in proptest::collection::vec(0usize..14, 0..24), header in 0usize..3) {
            const PIECES: [&str; 14] =
                ["1,2", "3,4", "1", "1,2,3", "a,b", "# c,d", "  ", "\t", "\n", "\r", "\r\n", "\n", "\n", "\"5\",6"];
            let mut text = ["x,y\n", "# h\r\nx,y\r\n", "  \nx,y\r"][header].to_string();
            text.extend(pieces.iter().map(|&k| PIECES[k]));
            let (whole, streamed) = both(text.as_bytes());
            match (whole, streamed) {
                (Ok(a), Ok(b)) => proptest::prop_assert_eq!(a, b, "{:?}", text),
                (Err(a), Err(b)) => proptest::prop_assert_eq!(a.to_string(), b.to_string(), "{:?}", text),
                (a, b) => proptest::prop_assert!(false, "{:?}: whole {:?}, streamed {:?}", text, a, b),
            }
        }
    }

    #[test]
    fn streamed_empty_and_bom() {
        for text in [&b""[..], b"\n\n", b"\xef\xbb\xbfx,y\n1,2", b"x,y\n1,\xff\n", b"x,y\n# end"] {
            let (a, b) = both(text);
            assert_eq!(format!("{a:?}"), format!("{b:?}"), "{text:?}");
        }
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
