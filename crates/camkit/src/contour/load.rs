//! The front door of every filter that reads contours: the toolpath table, a DXF or an SVG
//! drawing (G-code where the filter reads it), chosen by the file's extension or `--from`; a
//! drawing becomes the toolpath table first, so that every kind of input reaches a filter the
//! same way. A file that does not read as the table it was taken for is told by what it looks
//! like (a DXF, SVG, STL, JSON or G-code file), not by the table reader's complaint.

use super::region::Region;
use super::table::{self as contour_table, Source};
use crate::contour::Seg;
use crate::error::{Error, Location, Result};
use crate::geom::{P2, P3};
use crate::io::Input;
use crate::table::{self, Col, Move};

/// What a contour input is, as `--from` names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum InputKind {
    /// By the file's extension: .dxf, .svg, G-code (.nc .ngc .gcode .gco .g .tap .cnc), else the table.
    Auto,
    /// The toolpath table (CSV).
    Table,
    /// An ASCII DXF drawing.
    Dxf,
    /// An SVG drawing.
    Svg,
    /// G-code (filters that read it).
    Gcode,
}

impl InputKind {
    /// `Auto` decided by the name of `input`; the others as they are.
    pub fn resolve(self, input: &Input) -> InputKind {
        self.resolve_name(&input.name)
    }

    /// `Auto` decided by a file name's extension (any case); the others as they are.
    pub fn resolve_name(self, name: &str) -> InputKind {
        let extension = std::path::Path::new(name).extension().and_then(|e| e.to_str()).unwrap_or("");
        match (self, extension.to_ascii_lowercase().as_str()) {
            (InputKind::Auto, "dxf") => InputKind::Dxf,
            (InputKind::Auto, "svg") => InputKind::Svg,
            (InputKind::Auto, "nc" | "ngc" | "gcode" | "gco" | "g" | "tap" | "cnc") => InputKind::Gcode,
            (InputKind::Auto, _) => InputKind::Table,
            (k, _) => k,
        }
    }
}

/// The command-line options of every filter that reads contours (flattened into its `Args`).
#[derive(Clone, Debug, clap::Args)]
pub struct ContourArgs {
    /// Input kind: auto (by the extension: .dxf, .svg, .csv/other = the table; .nc .ngc .gcode
    /// .gco .g .tap .cnc = G-code where this filter reads it), table, dxf, svg or gcode (for
    /// standard input).
    #[arg(long, value_enum, default_value_t = InputKind::Auto)]
    pub from: InputKind,
    /// Drawings: largest distance (mm) between a curve (an SVG Bézier or elliptical arc, a DXF
    /// ELLIPSE or SPLINE) and the lines and arcs it is read as, proven both ways (1e-6 to 10).
    #[arg(long, alias = "dxf-tol", default_value_t = crate::tol::CURVE_TOL, value_name = "MM")]
    pub curve_tol: f64,
    /// Drawings: read only this layer (a DXF layer; an SVG Inkscape layer's label or a group's
    /// id); repeat for several. Default: every layer.
    #[arg(long = "layer", id = "drawing_layers", value_name = "NAME")]
    pub drawing_layers: Vec<String>,
}

/// The input kinds as every contour filter's `--help` tells them.
pub fn help_text() -> String {
    [
        "Contour inputs (by extension, or --from for standard input):",
        "  *.csv, other   the toolpath table: each path one contour (line/cw/ccw rows with xc,yc)",
        "  *.dxf          ASCII DXF: LINE, ARC, CIRCLE, LWPOLYLINE and POLYLINE (bulges), ELLIPSE, SPLINE",
        "                 (control points) on the --layer(s) asked for, chained end to end (gaps up to",
        "                 1e-4 mm; an open chain is refused naming the gap), in mm, z from the entities",
        "  *.svg          path, rect, circle, ellipse, polygon, polyline, line with their transforms; mm from",
        "                 the root's width/height (96 dpi user units without), y up from the viewBox's",
        "                 bottom-left corner; --layer picks Inkscape layers (label) or groups (id)",
        "  Lines stay lines and circular arcs arcs; Béziers, ellipses and splines become lines and arcs",
        "  within --curve-tol (default 0.001 mm), proven both ways. A drawing's contours are numbered",
        "  by path in the order they appear. Another kind of file given as a table is named as such.",
    ]
    .join("\n")
}

/// How a contour input is read.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// The kind asked for (`Auto` decides by the extension).
    pub from: InputKind,
    /// The drawing options: curve tolerance and layers.
    pub drawing: crate::dxf::Options,
    /// True if the filter reads G-code (then a G-code file taken for a table says so).
    pub gcode: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options { from: InputKind::Auto, drawing: crate::dxf::Options::default(), gcode: false }
    }
}

impl ContourArgs {
    /// The options, checked; `gcode` says whether the filter reads G-code.
    pub fn options(&self, gcode: bool) -> Result<Options> {
        // Finer than a nanometre, the proof's halvings would multiply past any use.
        let tol = crate::cli::within(self.curve_tol, 1e-6, 10.0, "--curve-tol", " mm")?;
        if self.from == InputKind::Gcode && !gcode {
            return Err(Error::input(format!(
                "--from gcode: {} reads contours from the table, a DXF or an SVG drawing",
                crate::cli::program()
            )));
        }
        Ok(Options {
            from: self.from,
            drawing: crate::dxf::Options { tol, layers: self.drawing_layers.clone() },
            gcode,
        })
    }
}

/// Contours read from one input, with what was skipped.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Loaded {
    /// The contours in input order.
    pub sources: Vec<Source>,
    /// Drawing entities or elements that are not contours: their kind and line.
    pub skipped: Vec<(String, u64)>,
}

/// Reads the closed contours of `input` as `opts` says (through the toolpath table, see
/// [`table`]).
pub fn contours(input: &Input, opts: &Options) -> Result<Loaded> {
    let (t, skipped) = table(input, opts)?;
    if t.rows.is_empty() {
        return Err(Error::input("no rows: no contour").at(Location::file(&input.name)));
    }
    Ok(Loaded { sources: contour_table::read(&t, &input.name)?.sources, skipped })
}

/// The input as the toolpath table (with the drawing's entities skipped): the table itself, or
/// a drawing's closed contours as passes (`path` numbering them, a `line` row at the start, then
/// a `line`, `cw` or `ccw` row per piece; every row on its contour's first line in the drawing),
/// so that a filter made for tables takes drawings too. G-code is the caller's to read.
pub fn table(input: &Input, opts: &Options) -> Result<(table::Table, Vec<(String, u64)>)> {
    let mut rows = Vec::new();
    let (schema, skipped) = table_each(input, opts, |_, row| {
        rows.push(row);
        Ok(())
    })?;
    Ok((table::Table { schema, rows }, skipped))
}

/// [`table`] row by row: each row goes to `on_row` as it is read (a table file is never held as
/// rows; a drawing is small and made whole first); returns the schema and what was skipped.
pub fn table_each(
    input: &Input,
    opts: &Options,
    mut on_row: impl FnMut(&table::Schema, table::Row) -> Result<()>,
) -> Result<(table::Schema, Vec<(String, u64)>)> {
    let kind = opts.from.resolve(input);
    let read = match kind {
        InputKind::Dxf => crate::dxf::read(&input.name, &String::from_utf8_lossy(&input.data), &opts.drawing)?,
        InputKind::Svg => super::svg_in::read(&input.name, input.text()?, &opts.drawing)?,
        InputKind::Gcode if !opts.gcode => {
            return Err(Error::input(format!(
                "{} reads contours from the table, a DXF or an SVG drawing, not G-code",
                crate::cli::program()
            ))
            .at(Location::file(&input.name)));
        }
        _ => {
            return table::read_each(input, &[Col::X, Col::Y], on_row)
                .map(|schema| (schema, Vec::new()))
                .map_err(|e| sniffed(input, opts.gcode).unwrap_or(e));
        }
    };
    if read.sources.is_empty() {
        let on = if opts.drawing.layers.is_empty() {
            String::new()
        } else {
            format!(" on the layers {} (the drawing's: {})", opts.drawing.layers.join(", "), read.layers.join(", "))
        };
        let has = if kind == InputKind::Svg {
            "a path, rect, circle, ellipse, polygon, polyline or line element"
        } else {
            "a LINE, ARC, CIRCLE, LWPOLYLINE, POLYLINE, ELLIPSE or SPLINE entity"
        };
        return Err(Error::input(format!("no closed contour in the drawing{on}: it needs {has}"))
            .at(Location::file(&input.name)));
    }
    let t = drawing_table(&read.sources);
    for row in t.rows {
        on_row(&t.schema, row)?;
    }
    Ok((t.schema, read.skipped))
}

/// A drawing's contours as the toolpath table.
fn drawing_table(sources: &[Source]) -> table::Table {
    let mut t = table::Table::default();
    t.schema.add(&[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::Xc, Col::Yc]);
    for s in sources {
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
    t
}

/// What a file that did not read as the toolpath table looks like, as the error to give instead
/// of the table reader's; `None` when it looks like no other kind.
fn sniffed(input: &Input, gcode: bool) -> Option<Error> {
    let what = looks_like(&input.data)?;
    let hint = match what {
        Looks::Dxf => "name it *.dxf or give --from dxf".to_string(),
        Looks::Svg => "name it *.svg or give --from svg".to_string(),
        Looks::Gcode if gcode => "name it *.nc or give --from gcode".to_string(),
        Looks::Gcode => format!("{} reads contours from the table, a DXF or an SVG drawing", crate::cli::program()),
        Looks::Stl => "a mesh is a model, not contours: give the contours as the table, a DXF or an SVG".to_string(),
        Looks::Json => "a JSON document (a setup, tool, model or report) holds no contours".to_string(),
        Looks::Binary => "it is not text".to_string(),
    };
    Some(
        Error::input(format!(
            "this looks like {}, not the toolpath table (CSV with a header row): {hint}",
            what.name()
        ))
        .at(Location::file(&input.name)),
    )
}

/// The kinds of file a table reader may be handed by mistake.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Looks {
    Dxf,
    Svg,
    Gcode,
    Stl,
    Json,
    Binary,
}

impl Looks {
    fn name(self) -> &'static str {
        match self {
            Looks::Dxf => "a DXF drawing",
            Looks::Svg => "an SVG drawing",
            Looks::Gcode => "G-code",
            Looks::Stl => "an STL mesh",
            Looks::Json => "a JSON document",
            Looks::Binary => "a binary file",
        }
    }
}

/// What the first bytes of `data` look like, if something other than a table.
fn looks_like(data: &[u8]) -> Option<Looks> {
    let head = &data[..data.len().min(4096)];
    let text = String::from_utf8_lossy(head);
    let trimmed = text.trim_start_matches('\u{feff}').trim_start();
    let lines: Vec<&str> = trimmed.lines().map(str::trim).filter(|l| !l.is_empty()).take(4).collect();
    if trimmed.starts_with("AutoCAD Binary DXF")
        || (lines.len() >= 2 && matches!(lines[0], "0" | "999") && (lines[1] == "SECTION" || lines[0] == "999"))
    {
        return Some(Looks::Dxf);
    }
    if trimmed.starts_with('<') && text.contains("<svg") {
        return Some(Looks::Svg);
    }
    if trimmed.starts_with("solid") && text.contains("facet") {
        return Some(Looks::Stl);
    }
    if data.len() >= 84 {
        let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as usize;
        if n > 0 && data.len() == 84 + 50 * n {
            return Some(Looks::Stl);
        }
    }
    if trimmed.starts_with('{') || trimmed.starts_with('[') {
        return Some(Looks::Json);
    }
    let gcode_line = |l: &str| {
        let mut c = l.chars();
        matches!(c.next(), Some('%' | '(' | ';'))
            || (l.starts_with(|ch: char| matches!(ch.to_ascii_uppercase(), 'G' | 'M' | 'N' | 'T' | 'O'))
                && c.next().is_some_and(|d| d.is_ascii_digit())
                && !l.contains(','))
    };
    if !lines.is_empty() && lines.iter().all(|l| gcode_line(l)) {
        return Some(Looks::Gcode);
    }
    if head.contains(&0) {
        return Some(Looks::Binary);
    }
    None
}

/// The pocket regions of the closed contours in the file `path` (the table or a drawing, by its
/// extension): outer boundaries counter-clockwise with their islands clockwise.
pub fn regions(path: &str) -> Result<Vec<Region>> {
    let input = Input::open(path)?;
    let loaded = contours(&input, &Options::default())?;
    if loaded.sources.is_empty() {
        return Err(Error::input("no closed contour in the input").at(Location::file(&input.name)));
    }
    Ok(contour_table::pocket_regions(&loaded.sources, &input.name)?.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(name: &str, text: &str) -> Input {
        Input { name: name.into(), data: text.as_bytes().to_vec() }
    }

    #[test]
    fn other_kinds_given_as_a_table_are_named() {
        let cases = [
            ("0\nSECTION\n2\nENTITIES\n0\nENDSEC\n0\nEOF\n", "a DXF drawing", "--from dxf"),
            ("<?xml version=\"1.0\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\"/>\n", "an SVG drawing", "--from svg"),
            ("solid part\nfacet normal 0 0 1\n", "an STL mesh", "a model"),
            ("{\"radius\": 5}\n", "a JSON document", "no contours"),
            ("%\nG21 G90\nG1 X10 Y0 F500\n", "G-code", "reads contours"),
        ];
        for (text, what, hint) in cases {
            let e = table(&input("stdin", text), &Options::default()).unwrap_err();
            let m = e.to_string();
            assert!(m.contains(what) && m.contains(hint) && !m.contains("missing column"), "{m}");
            assert_eq!(e.exit_status(), 2);
        }
        let g = Options { gcode: true, ..Options::default() };
        let m = table(&input("stdin", "G1 X1 Y2\n"), &g).unwrap_err().to_string();
        assert!(m.contains("--from gcode"), "{m}");
        // A real table is read, and a bad one keeps the table reader's message.
        assert_eq!(table(&input("t.csv", "x,y\n1,2\n"), &Options::default()).unwrap().0.rows.len(), 1);
        let m = table(&input("t.csv", "a,b\n1,2\n"), &Options::default()).unwrap_err().to_string();
        assert!(m.contains("missing column `x`"), "{m}");
    }

    #[test]
    fn kinds_by_extension() {
        let kind = |name: &str| InputKind::Auto.resolve(&input(name, ""));
        assert_eq!(
            [kind("a.DXF"), kind("a.svg"), kind("a.ngc"), kind("a.csv"), kind("stdin")],
            [InputKind::Dxf, InputKind::Svg, InputKind::Gcode, InputKind::Table, InputKind::Table]
        );
        assert_eq!(InputKind::Svg.resolve(&input("a.csv", "")), InputKind::Svg);
    }
}
