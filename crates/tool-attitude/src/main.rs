//! `tool-attitude`: the clap CLI round the library: reads the contact stream, the tool and the
//! model, solves every row in parallel, checks the poses, writes the toolpath table.

use camkit::cli::{self, IoArgs};
use camkit::doc::{Tool, ToolKind};
use camkit::error::{Error, Location, Result};
use camkit::geom::{P3, V3};
use camkit::io::{Input, Stream, write_atomic};
use camkit::json::{at_value, field_error};
use camkit::model::Model;
use camkit::report::Report;
use camkit::svg::relief;
use camkit::table::meaning::{self, Meaning};
use camkit::table::{self, Col, Field, Schema, Table, WriteOptions};
use clap::{Parser, ValueEnum};
use rayon::prelude::*;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use tool_attitude::flat_type::Edge;
use tool_attitude::gouge::Part;
use tool_attitude::{Attitude, Contact, RowError, Setup, Shape, attitude, edge, pose};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum TiltPlane {
    /// Toward the feed (lead angle).
    Feed,
    /// Across the feed, to its right seen from above the surface (paper 003's ζ).
    Side,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ControlPoint {
    /// P1 on the first surface (`px..`, `nx..`).
    P1,
    /// P3 on the second surface (`p2x..`, `n2x..`).
    P3,
}

#[derive(Parser, Debug)]
#[command(
    name = "tool-attitude",
    version,
    allow_negative_numbers = true,
    about = "Tool tip, tool axis and spindle orientation from contact data (the stream stylus-trace writes).",
    long_about = "Tool tip, tool axis and spindle orientation from contact data (the stream stylus-trace \
writes: contact point, unit normal, stylus centre; the feed is the direction between consecutive rows of a \
path). Tools (--tool JSON, `kind`): cylindrical-nonrotating (paper 000 §3.2(1): axis = normal tilted by θ \
toward the feed in the plane of normal and feed, tip = bottom-face centre R behind the cutting point, edge \
facing the feed; R' of eq. 1 per row), flat-nonrotating (000 §3.2(2): tip P2 at the two-surface stylus \
centre, axis from the bisector of both normals corrected until the control stylus at P1/P3 touches its \
surface), ball (003 §3.1: tilt ζ; tip = ball centre − r·axis), flat (002 §4.2: axis = normal, machine \
angles [a, c] of eq. 3–4). With --model every pose's tool body is tested against the model; where the tilted \
tool cuts in, the tilt is moved inside the tool's range to the nearest clear one, and rows that stay \
gouging fail the run (exit 1) unless --allow-gouge. A ball's radius must be that of the stylus the stream \
records (column stylus_radius; else exit 2); the output's rows say point = tip.",
    after_help = after_help()
)]
struct Args {
    #[command(flatten)]
    io: IoArgs,
    /// The tool document (JSON: kind, radius, ...).
    #[arg(short = 't', long, value_name = "FILE")]
    tool: String,
    /// A fixed tool axis I,J,K (e.g. 0,0,1 for a 3-axis machine; normalised) for a ball end mill:
    /// the tip is the stylus centre less R along it (the stylus must have the tool's radius: a
    /// stream recording another is refused), the axis columns this vector; with --model the ball
    /// and shank are gouge-checked. Flat, bull-nose and cone cutters: stylus-trace --tool.
    #[arg(long, value_name = "I,J,K", allow_hyphen_values = true, conflicts_with_all = ["tilt", "edge_radius"])]
    axis: Option<String>,
    /// Tilt (degrees): θ of the cylindrical tool (paper's sign: negative leans toward the feed;
    /// default −5), ζ of the ball end mill (default 0).
    #[arg(long, value_name = "DEG", conflicts_with = "edge_radius")]
    tilt: Option<f64>,
    /// Choose θ of the cylindrical tool so that eq. 1 gives this R' (mm).
    #[arg(long, value_name = "MM")]
    edge_radius: Option<f64>,
    /// Depth of cut T of eq. 1 (mm); 0 takes the limit T → 0, R' = R / sin|θ|.
    #[arg(long, default_value_t = 0.0, value_name = "MM")]
    cut_depth: f64,
    /// Plane of the ball end mill's tilt.
    #[arg(long, value_enum, default_value_t = TiltPlane::Side)]
    tilt_plane: TiltPlane,
    /// Control stylus of the flat-type tool.
    #[arg(long, value_enum, default_value_t = ControlPoint::P1)]
    control: ControlPoint,
    /// The model (JSON document, STL or STEP file) for gouge checks and the flat-type correction.
    #[arg(long, value_name = "FILE")]
    model: Option<String>,
    /// Refuse a model's STL file with zero-area or repeated facets (default: left out, with a warning).
    #[arg(long)]
    strict: bool,
    /// A STEP model's faces on surfaces or edges the reader does not take are left out, with a
    /// warning each (default: the first is refused, naming the entity and its #id).
    #[arg(long, requires = "model")]
    skip_unsupported: bool,
    /// Penetration (mm) of the tool body into the model tolerated before a pose gouges.
    #[arg(long, default_value_t = 0.001, value_name = "MM")]
    gouge_tol: f64,
    /// Write the table even when rows gouge (they are reported; exit 0).
    #[arg(long)]
    allow_gouge: bool,
    /// Decimals of written positions (default: shortest exact text).
    #[arg(long, value_name = "N")]
    decimals: Option<u32>,
    /// Write an SVG of the tool tip paths: isometric, top and side views coloured by the tool
    /// axis's tilt from +z (degrees; by z for one fixed axis), the axis drawn at evenly spaced rows.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// Rows placed at a time (whole passes in the tilt modes): a test knob, the output is the
    /// same for any value.
    #[arg(long, hide = true, default_value_t = CHUNK, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
    chunk_rows: usize,
}

fn after_help() -> String {
    let mut s = table::columns::help_text(
        &[Col::Path, Col::X, Col::Y, Col::Z, Col::Px, Col::Py, Col::Pz, Col::Nx, Col::Ny, Col::Nz],
        &[Col::X, Col::Y, Col::Z, Col::I, Col::J, Col::K, Col::S],
    );
    s.push_str("  two-surface streams also: p2x p2y p2z n2x n2y n2z (second contact), surface, surface2\n");
    s.push_str("  written by name: tilt (deg), r_edge (mm, cylinder), ac_a ac_c (deg, flat end mill),\n");
    s.push_str("  flank_gap (deg, flat-type), gouge (mm, with --model)\n");
    s.push_str("Other columns pass through.\n\nExit status: 0 done, 1 a check failed (gouge), 2 bad input or usage.");
    s
}

fn main() -> ExitCode {
    cli::run("tool-attitude", || run(cli::parse::<Args>()?))
}

/// The stable tilt range of paper 000 for the cylindrical tool, and paper 003's studied tilts.
const CYLINDER_RANGE: [f64; 2] = [-20.0, 0.0];
const BALL_RANGE: [f64; 2] = [0.0, 15.0];

fn setup(args: &Args, tool: &Tool, tool_file: &str) -> Result<Setup> {
    let usage = |m: String| Error::input(m);
    if !(args.gouge_tol.is_finite() && args.gouge_tol >= 0.0) {
        return Err(usage(format!("--gouge-tol must be a number ≥ 0, got {}", args.gouge_tol)));
    }
    if !(args.cut_depth.is_finite() && args.cut_depth >= 0.0) {
        return Err(usage(format!("--cut-depth must be a number ≥ 0, got {}", args.cut_depth)));
    }
    if args.decimals.is_some_and(|d| d > 12) {
        return Err(usage("--decimals must be at most 12".into()));
    }
    let r = tool.radius;
    let (shape, default_tilt, default_range) = match tool.kind {
        ToolKind::CylindricalNonrotating => {
            (Shape::Cylinder { radius: r, cut_depth: args.cut_depth }, -5.0, CYLINDER_RANGE)
        }
        ToolKind::Ball => (Shape::Ball { radius: r, side: args.tilt_plane == TiltPlane::Side }, 0.0, BALL_RANGE),
        ToolKind::Flat => (Shape::FlatMill { radius: r }, 0.0, [0.0, 0.0]),
        ToolKind::FlatNonrotating => {
            let missing = |f: &str| field_error(tool_file, f, format!("a flat-nonrotating tool needs `{f}`"));
            let included = tool.included_angle.ok_or_else(|| missing("included_angle"))?;
            let flank = tool.flank_length.ok_or_else(|| missing("flank_length"))?;
            let edge = Edge { included: included.to_radians(), flank };
            (Shape::FlatType { edge, control_second: args.control == ControlPoint::P3 }, 0.0, [0.0, 0.0])
        }
        ToolKind::Bull | ToolKind::Cone => {
            return Err(field_error(
                tool_file,
                "kind",
                "tool-attitude takes ball, flat, cylindrical-nonrotating or flat-nonrotating tools: bull-nose and cone cutters on a fixed axis are dropped onto the model by stylus-trace --tool",
            ));
        }
    };
    let range = tool.tilt_range.unwrap_or(default_range);
    let free = matches!(shape, Shape::Cylinder { .. } | Shape::Ball { .. });
    let mut tilt = args.tilt.unwrap_or(default_tilt);
    if let Some(re) = args.edge_radius {
        let Shape::Cylinder { radius, cut_depth } = shape else {
            return Err(usage("--edge-radius applies to the cylindrical-nonrotating tool".into()));
        };
        let theta = edge::tilt_for_edge_radius(radius, cut_depth, re).ok_or_else(|| {
            usage(format!(
                "--edge-radius {re}: eq. 1 gives R' from R = {radius} up to {} mm for this tool and --cut-depth",
                edge::largest_edge_radius(radius, cut_depth)
            ))
        })?;
        tilt = theta.to_degrees();
    }
    if !free && args.tilt.is_some() {
        return Err(usage("--tilt applies to the cylindrical-nonrotating and ball tools".into()));
    }
    if free && !(tilt >= range[0] - 1e-9 && tilt <= range[1] + 1e-9) {
        let source = args.edge_radius.map(|re| format!("--edge-radius {re} needs ")).unwrap_or_default();
        return Err(usage(format!(
            "{source}tilt {tilt}° is outside the tool's range [{}, {}]° (tool `tilt_range`, paper 000: −20..0 for the cylindrical tool)",
            range[0], range[1]
        )));
    }
    Ok(Setup {
        shape,
        tilt: tilt.to_radians(),
        range: (range[0].to_radians(), range[1].to_radians()),
        length: tool.length.unwrap_or(4.0 * r),
        gouge_tol: args.gouge_tol,
    })
}

/// Column number (1-based) and name of a column of `schema`, for error locations.
fn column_of(schema: &Schema, name: &str) -> u64 {
    schema
        .fields
        .iter()
        .position(|f| match f {
            Field::Known(c) => table::columns::spec(*c).name == name,
            Field::Extra(i) => schema.extra_names[*i] == name,
        })
        .map_or(0, |p| p as u64 + 1)
}

/// Reads the unit normal of a row from typed or named columns; refuses zero or non-unit ones.
fn unit_normal(v: V3, schema: &Schema, file: &str, line: u64, col: &str) -> Result<V3> {
    let len = v.norm();
    if (len - 1.0).abs() > camkit::tol::UNIT_VECTOR_SLACK {
        return Err(Error::input(format!(
            "the normal ({}, {}, {}) is not a unit vector (length {len})",
            v.x, v.y, v.z
        ))
        .at(Location::file(file).line(line).column(column_of(schema, col)).field(col)));
    }
    Ok(v / len)
}

/// Names of the second contact's columns in a two-surface stream.
const SECOND: [&str; 6] = ["p2x", "p2y", "p2z", "n2x", "n2y", "n2z"];

/// Reads the contacts of rows of one schema (feed still zero): where the columns are.
struct ContactReader {
    schema: Schema,
    second: Option<[usize; 6]>,
    surfaces: (Option<usize>, Option<usize>),
}

impl ContactReader {
    /// The reader for rows of `schema`; the flat-type tool (`needs_second`) needs the two-surface
    /// columns.
    fn new(schema: &Schema, file: &str, needs_second: bool) -> Result<ContactReader> {
        let idx: Vec<Option<usize>> = SECOND.iter().map(|n| schema.extra_index(n)).collect();
        let second = if needs_second {
            if let Some(k) = idx.iter().position(Option::is_none) {
                return Err(Error::input(format!(
                    "missing column `{}`: the flat-type tool needs the two-surface stream (stylus-trace --mode two-surface)",
                    SECOND[k]
                ))
                .at(Location::file(file).line(1)));
            }
            Some(std::array::from_fn(|k| idx[k].expect("checked above")))
        } else {
            None
        };
        let surfaces = (schema.extra_index("surface"), schema.extra_index("surface2"));
        Ok(ContactReader { schema: schema.clone(), second, surfaces })
    }

    /// The contact of one row (feed zero).
    fn contact(&self, row: &table::Row, file: &str, model: Option<&Model>) -> Result<Contact> {
        let col = |name: &str| column_of(&self.schema, name);
        let (Some(point), Some(n)) = (row.contact, row.normal) else {
            let name = if row.contact.is_none() { "px" } else { "nx" };
            return Err(Error::input("empty contact point or normal: every row needs px..pz and nx..nz")
                .at(Location::file(file).line(row.line).column(col(name)).field(name)));
        };
        let normal = unit_normal(n, &self.schema, file, row.line, "nx")?;
        let second = match &self.second {
            Some(idx) => {
                let mut v = [0.0; 6];
                for (k, slot) in v.iter_mut().enumerate() {
                    let text = row.extra.get(idx[k]).map_or("", String::as_str);
                    *slot = camkit::num::parse_finite(text).map_err(|e| {
                        Error::input(e.message(text))
                            .at(Location::file(file).line(row.line).column(col(SECOND[k])).field(SECOND[k]))
                    })?;
                }
                let n2 = unit_normal(V3::new(v[3], v[4], v[5]), &self.schema, file, row.line, "n2x")?;
                Some((P3::new(v[0], v[1], v[2]), n2))
            }
            None => None,
        };
        let surface =
            |i: Option<usize>| model.zip(i).and_then(|(m, i)| row.extra.get(i).and_then(|name| m.surface_index(name)));
        Ok(Contact {
            centre: row.pos,
            point,
            normal,
            second,
            surfaces: (surface(self.surfaces.0), surface(self.surfaces.1)),
            feed: V3::zeros(),
        })
    }
}

/// Sets the feed directions of one pass's contacts from consecutive stylus centres (`rows`, the
/// pass's rows, name the line of a row that has none).
fn set_feed(contacts: &mut [Contact], rows: &[table::Row], file: &str) -> Result<()> {
    let centres: Vec<P3> = contacts.iter().map(|c| c.centre).collect();
    match pose::feed_directions(&centres) {
        Ok(f) => {
            contacts.iter_mut().zip(f).for_each(|(c, d)| c.feed = d);
            Ok(())
        }
        Err(k) => {
            let what = if rows.len() < 2 {
                format!("path {} has {} row: the feed direction needs at least two", rows[0].path, rows.len())
            } else {
                "this row repeats the previous position: no feed direction".into()
            };
            Err(Error::input(what).at(Location::file(file).line(rows[k].line)))
        }
    }
}

/// The fixed tool axis of `--axis`, unit; a zero, malformed or non-finite vector is a usage error.
fn fixed_axis(text: &str) -> Result<V3> {
    let parts: Vec<f64> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| Error::input(format!("--axis takes three numbers I,J,K, got `{text}`")))?;
    let v = match parts[..] {
        [i, j, k] => V3::new(i, j, k),
        _ => return Err(Error::input(format!("--axis takes three numbers I,J,K, got `{text}`"))),
    };
    let n = v.norm();
    if !(n.is_finite() && n > 1e-9) {
        return Err(Error::input(format!("--axis must be a nonzero direction, got `{text}`")));
    }
    Ok(v / n)
}

/// `--axis`: tips of a ball end mill on a fixed axis from the stylus centres, streamed: rows are
/// read, placed (in parallel, [`CHUNK`] rows at a time) and written as they come, never the table
/// held as rows (but with --svg, which draws them all).
fn run_fixed(args: &Args, tool: &Tool, tool_file: &str, axis: V3, started: Instant) -> Result<()> {
    if tool.kind != ToolKind::Ball {
        return Err(field_error(
            tool_file,
            "kind",
            "--axis (a fixed axis) takes a ball end mill: the stylus centre is its ball's centre; flat, bull-nose and cone cutters on a fixed axis need a drop-cutter, which tool-attitude does not do",
        ));
    }
    let input = Input::open(&args.io.input)?;
    let r = tool.radius;
    let length = tool.length.unwrap_or(4.0 * r);
    let part = load_part(args, tool, length)?;
    let mut out = Stream::new(args.io.output.as_deref())?;
    let progress = args.io.progress(0, "placing tips");
    let mut placed = Placed { kept: args.svg.is_some().then(Vec::new), ..Placed::default() };
    let mut stream: Option<FixedStream> = None;
    let mut chunk = Vec::with_capacity(args.chunk_rows.min(CHUNK));
    table::read_each(&input, &[Col::X, Col::Y, Col::Z], |schema, row| {
        let s = match &mut stream {
            Some(s) => s,
            None => stream.insert(FixedStream::new(
                schema,
                Tips { axis, r, part: part.as_ref(), gouge_tol: args.gouge_tol },
                args.decimals,
            )),
        };
        s.check.row(&row, &input.name)?;
        if placed.rows == 0 {
            if s.check.says() && s.check.meaning() == Meaning::Tip {
                return Err(Error::input(
                    "the stream's rows are tool tips already (`point` = tip): --axis takes the stylus centres stylus-trace -r writes",
                )
                .at(Location::file(&input.name)));
            }
            check_stylus(s.check.meaning(), &input.name, tool, tool_file)?;
        }
        placed.rows += 1;
        chunk.push(row);
        if chunk.len() == args.chunk_rows {
            s.place(&mut chunk, &mut placed, &mut out)?;
            progress.inc(args.chunk_rows as u64);
        }
        Ok(())
    })?;
    let Some(mut s) = stream else {
        return Err(Error::input("no rows").at(Location::file(&input.name)));
    };
    s.place(&mut chunk, &mut placed, &mut out)?;
    s.writer.finish(&mut out)?;
    progress.finish();
    let mut report = Report::new("tool-attitude");
    if let Some(m) = part.as_ref().map(|p| &p.model) {
        let (degenerate, duplicate) = m.dropped_counts();
        report.set("degenerate_facets_dropped", degenerate).set("duplicate_facets_dropped", duplicate);
    }
    report
        .set("tool", tool)
        .set("fixed_axis", [axis.x, axis.y, axis.z])
        .set("rows", placed.rows)
        .set("paths", placed.paths)
        .set("gouge_rows", placed.gouge_rows)
        .set("gouge_tol_mm", args.gouge_tol)
        .set("largest_gouge_mm", placed.largest)
        .set("gouge_chord_mm", part.as_ref().map(Part::chord_error))
        .set("seconds", started.elapsed().as_secs_f64());
    if let Some(path) = &args.io.report {
        report.write(path)?;
    }
    let model = part.as_ref().map(|p| &p.model);
    let gouging = placed.first_gouge.map(|line| (line, placed.gouge_rows));
    refuse_gouges(args, &input.name, gouging, args.gouge_tol, placed.largest)?;
    if let (Some(path), Some(rows)) = (&args.svg, placed.kept) {
        let t = Table { schema: s.marker.schema.clone(), rows };
        plot(path, &t, &input.name, model)?;
    }
    out.commit()
}

/// Rows placed at a time (in parallel within a chunk) by default.
const CHUNK: usize = 1 << 14;

/// How the fixed-axis stream places a tip: the axis, the ball's radius, the part checked for
/// gouges (if any) and the gouge tolerance.
#[derive(Clone, Copy)]
struct Tips<'p> {
    axis: V3,
    r: f64,
    part: Option<&'p Part>,
    gouge_tol: f64,
}

/// The fixed-axis stream's output: the meaning check, the columns added and the writer.
struct FixedStream<'p> {
    tips: Tips<'p>,
    check: meaning::Check,
    gouge: Option<usize>,
    marker: meaning::TipMarker,
    writer: table::RowWriter,
}

/// What the fixed-axis stream has placed so far.
#[derive(Default)]
struct Placed {
    rows: usize,
    paths: usize,
    last_path: Option<i64>,
    gouge_rows: usize,
    first_gouge: Option<u64>,
    largest: f64,
    /// The rows written, for --svg.
    kept: Option<Vec<table::Row>>,
}

impl<'p> FixedStream<'p> {
    fn new(schema: &table::Schema, tips: Tips<'p>, decimals: Option<u32>) -> FixedStream<'p> {
        let mut out = schema.clone();
        out.add(&[Col::I, Col::J, Col::K]);
        let gouge = tips.part.is_some().then(|| out.add_extra("gouge"));
        let marker = meaning::TipMarker::new(&out);
        let writer = table::RowWriter::new(&marker.schema, WriteOptions { decimals });
        FixedStream { tips, check: meaning::Check::new(schema), gouge, marker, writer }
    }

    /// Places the rows of `chunk` (emptied): tips and, with a part, their gouges (in parallel),
    /// then writes them in order.
    fn place(&mut self, chunk: &mut Vec<table::Row>, placed: &mut Placed, out: &mut Stream) -> Result<()> {
        let Tips { axis, r, part, gouge_tol } = self.tips;
        let placed_tips: Vec<(P3, f64)> = chunk
            .par_iter()
            .map(|row| {
                let tip = tool_attitude::fixed_axis_ball_tip(&row.pos, &axis, r);
                (tip, part.map_or(0.0, |p| p.penetration(&tool_attitude::pose::Pose { tip, axis, edge: None })))
            })
            .collect();
        for (mut row, (tip, g)) in chunk.drain(..).zip(placed_tips) {
            if placed.last_path != Some(row.path) {
                placed.paths += 1;
                placed.last_path = Some(row.path);
            }
            row.pos = tip;
            row.axis = axis;
            if let Some(i) = self.gouge {
                row.extra.resize(i + 1, String::new());
                row.extra[i] = num(g);
                if g > gouge_tol {
                    placed.gouge_rows += 1;
                    placed.first_gouge.get_or_insert(row.line);
                }
            }
            placed.largest = placed.largest.max(g);
            self.marker.row(&mut row);
            self.writer.row(out, &row)?;
            if let Some(kept) = &mut placed.kept {
                kept.push(row);
            }
        }
        Ok(())
    }
}

/// The shortest text of `v` that reads back exactly.
fn num(v: f64) -> String {
    let mut b = Vec::new();
    camkit::num::push_shortest(&mut b, v);
    String::from_utf8(b).expect("ascii")
}

fn run(args: Args) -> Result<()> {
    let started = Instant::now();
    let tool_input = Input::open(&args.tool)?;
    let tool: Tool = camkit::json::checked(&tool_input, Tool::validate)?;
    if let Some(text) = &args.axis {
        if args.decimals.is_some_and(|d| d > 12) {
            return Err(Error::input("--decimals must be at most 12"));
        }
        if !(args.gouge_tol.is_finite() && args.gouge_tol >= 0.0) {
            return Err(Error::input(format!("--gouge-tol must be a number ≥ 0, got {}", args.gouge_tol)));
        }
        let axis = fixed_axis(text)?;
        return run_fixed(&args, &tool, &tool_input.name, axis, started).map_err(|e| at_value(&tool_input, e));
    }
    let setup = setup(&args, &tool, &tool_input.name).map_err(|e| at_value(&tool_input, e))?;
    let part = load_part(&args, &tool, setup.length)?;
    let model = part.as_ref().map(|p| &p.model);
    let input = Input::open(&args.io.input)?;
    let needs_second = matches!(setup.shape, Shape::FlatType { .. });
    let ctx =
        Tilting { setup: &setup, part: part.as_ref(), model, file: &input.name, ball: tool.kind == ToolKind::Ball };
    let progress = args.io.progress(0, "solving attitudes");
    let mut out = Stream::new(args.io.output.as_deref())?;
    let mut stream: Option<TiltStream> = None;
    let mut kept = args.svg.is_some().then(Vec::new);
    table::read_each(
        &input,
        &[Col::X, Col::Y, Col::Z, Col::Px, Col::Py, Col::Pz, Col::Nx, Col::Ny, Col::Nz],
        |schema, row| {
            let first = stream.is_none();
            let s = match &mut stream {
                Some(s) => s,
                None => stream.insert(TiltStream::new(schema, &ctx, needs_second, &args, kept.take())?),
            };
            if ctx.ball {
                s.check.row(&row, ctx.file)?;
                if first {
                    check_stylus(s.check.meaning(), ctx.file, &tool, &tool_input.name)
                        .map_err(|e| at_value(&tool_input, e))?;
                }
            }
            let before = s.solved.rows;
            s.push(row, &ctx, &mut out)?;
            progress.inc((s.solved.rows - before) as u64);
            Ok(())
        },
    )?;
    let Some(mut s) = stream else {
        return Err(Error::input("no rows: the feed direction needs at least two rows of a path")
            .at(Location::file(&input.name)));
    };
    s.end_pass(&ctx)?;
    s.solve(&ctx, &mut out)?;
    progress.finish();
    let TiltStream { solved: d, writer, marker, .. } = s;
    writer.finish(&mut out)?;
    if d.checks.worst() > POSE_CHECK {
        return Err(Error::check(format!("a pose failed its own check by {:e} (a bug)", d.checks.worst())));
    }
    if needs_second && model.is_some() && d.unnamed_surfaces {
        cli::warn("rows without `surface`/`surface2` names of the model: their flat-type axis uses the tangent planes");
    }
    let mut report = Report::new("tool-attitude");
    if let Some(m) = &model {
        let (degenerate, duplicate) = m.dropped_counts();
        report.set("degenerate_facets_dropped", degenerate).set("duplicate_facets_dropped", duplicate);
    }
    report
        .set("tool", &tool)
        .set("rows", d.rows)
        .set("paths", d.paths)
        .set("tilt_deg", setup.tilt.to_degrees())
        .set("tilt_range_deg", [setup.range.0.to_degrees(), setup.range.1.to_degrees()])
        .set("adjusted_rows", d.adjusted)
        .set("gouge_rows", d.gouge_rows)
        .set("gouge_lines", &d.gouge_lines)
        .set("gouge_tol_mm", setup.gouge_tol)
        .set("largest_gouge_mm", d.largest_gouge)
        .set("gouge_check", part.as_ref().map(|_| "body"))
        .set("gouge_chord_mm", part.as_ref().map(Part::chord_error))
        .set("largest_axis_unit_error", d.checks.unit)
        .set("largest_tilt_error_rad", d.checks.tilt)
        .set("largest_tip_distance_error_mm", d.checks.tip)
        .set("seconds", started.elapsed().as_secs_f64())
        .set("solve_seconds", d.solve_seconds)
        .set("rows_per_second", d.rows as f64 / d.solve_seconds.max(1e-9))
        .set("threads", rayon::current_num_threads());
    if let Some((lo, hi)) = d.edges {
        report.set("r_edge_min_mm", lo);
        report.set("r_edge_max_mm", hi);
    }
    if let Some(gap) = d.least_gap {
        report.set("flank_gap_min_deg", gap.to_degrees());
        report.set("largest_axis_from_bisector_deg", d.largest_correction.to_degrees());
    }
    if let Some(path) = &args.io.report {
        report.write(path)?;
    }
    let first = d.gouge_lines.first().map(|&line| (line, d.gouge_rows));
    refuse_gouges(&args, &input.name, first, setup.gouge_tol, d.largest_gouge)?;
    if let (Some(path), Some(rows)) = (&args.svg, d.kept) {
        plot(path, &Table { schema: marker.schema, rows }, &input.name, model)?;
    }
    out.commit()
}

/// What the tilt modes' stream solves with: the setup, the part (gouge checks), the model
/// (surface names), the input's name, and whether the tool is a ball (stylus radius checked).
struct Tilting<'a> {
    setup: &'a Setup,
    part: Option<&'a Part>,
    model: Option<&'a Model>,
    file: &'a str,
    ball: bool,
}

/// The tilt modes' stream: rows gathered pass by pass (a row's feed direction needs its
/// neighbours), whole passes solved in parallel once `chunk` rows are waiting, written in order.
struct TiltStream {
    reader: ContactReader,
    check: meaning::Check,
    /// The rows and contacts of the pass being read.
    pass: Vec<table::Row>,
    contacts: Vec<Contact>,
    /// Whole passes waiting to be solved, their feed directions set.
    ready: Vec<table::Row>,
    ready_contacts: Vec<Contact>,
    chunk: usize,
    cols: OutColumns,
    marker: meaning::TipMarker,
    writer: table::RowWriter,
    solved: Solved,
}

/// Where the written values go in a row of the output schema.
struct OutColumns {
    extras: usize,
    nonrotating: bool,
    tilt: usize,
    edge: Option<usize>,
    ac: Option<(usize, usize)>,
    gap: Option<usize>,
    gouge: Option<usize>,
}

/// The stream's figures so far.
#[derive(Default)]
struct Solved {
    rows: usize,
    paths: usize,
    adjusted: usize,
    gouge_rows: usize,
    /// Lines of the first 20 rows that gouge.
    gouge_lines: Vec<u64>,
    largest_gouge: f64,
    checks: Checks,
    edges: Option<(f64, f64)>,
    least_gap: Option<f64>,
    largest_correction: f64,
    unnamed_surfaces: bool,
    solve_seconds: f64,
    /// The rows written, for --svg.
    kept: Option<Vec<table::Row>>,
}

impl TiltStream {
    fn new(
        schema: &Schema,
        ctx: &Tilting,
        needs_second: bool,
        args: &Args,
        kept: Option<Vec<table::Row>>,
    ) -> Result<TiltStream> {
        let reader = ContactReader::new(schema, ctx.file, needs_second)?;
        let shape = ctx.setup.shape;
        let nonrotating = matches!(shape, Shape::Cylinder { .. } | Shape::FlatType { .. });
        let mut out = schema.clone();
        out.add(&[Col::I, Col::J, Col::K]);
        if nonrotating {
            out.add(&[Col::S]);
        }
        let tilt = out.add_extra("tilt");
        let edge = matches!(shape, Shape::Cylinder { .. }).then(|| out.add_extra("r_edge"));
        let ac = matches!(shape, Shape::FlatMill { .. }).then(|| (out.add_extra("ac_a"), out.add_extra("ac_c")));
        let gap = needs_second.then(|| out.add_extra("flank_gap"));
        let gouge = ctx.part.is_some().then(|| out.add_extra("gouge"));
        let cols = OutColumns { extras: out.extra_names.len(), nonrotating, tilt, edge, ac, gap, gouge };
        let marker = meaning::TipMarker::new(&out);
        let writer = table::RowWriter::new(&marker.schema, WriteOptions { decimals: args.decimals });
        Ok(TiltStream {
            reader,
            check: meaning::Check::new(schema),
            pass: Vec::new(),
            contacts: Vec::new(),
            ready: Vec::new(),
            ready_contacts: Vec::new(),
            chunk: args.chunk_rows,
            cols,
            marker,
            writer,
            solved: Solved { kept, ..Solved::default() },
        })
    }

    /// Takes one row: its contact read, its pass ended where a new path starts, the waiting
    /// passes solved once `chunk` rows wait.
    fn push(&mut self, row: table::Row, ctx: &Tilting, out: &mut Stream) -> Result<()> {
        if self.pass.last().is_some_and(|r| r.path != row.path) {
            self.end_pass(ctx)?;
            if self.ready.len() >= self.chunk {
                self.solve(ctx, out)?;
            }
        }
        self.contacts.push(self.reader.contact(&row, ctx.file, ctx.model)?);
        self.pass.push(row);
        Ok(())
    }

    /// Ends the pass being read: its feed directions set, it waits to be solved.
    fn end_pass(&mut self, ctx: &Tilting) -> Result<()> {
        if self.pass.is_empty() {
            return Ok(());
        }
        set_feed(&mut self.contacts, &self.pass, ctx.file)?;
        self.solved.paths += 1;
        self.ready.append(&mut self.pass);
        self.ready_contacts.append(&mut self.contacts);
        Ok(())
    }

    /// Solves the waiting passes (in parallel), checks and writes them in order.
    fn solve(&mut self, ctx: &Tilting, out: &mut Stream) -> Result<()> {
        let started = Instant::now();
        let results: Vec<std::result::Result<Attitude, RowError>> =
            self.ready_contacts.par_iter().map(|c| attitude(ctx.setup, c, ctx.part)).collect();
        self.solved.solve_seconds += started.elapsed().as_secs_f64();
        let mut poses = Vec::with_capacity(results.len());
        for (k, r) in results.into_iter().enumerate() {
            match r {
                Ok(a) => poses.push(a),
                Err(e) => {
                    let loc = Location::file(ctx.file).line(self.ready[k].line);
                    return Err(match e {
                        RowError::Flat(tool_attitude::flat_type::FlatError::NoContact) => {
                            Error::check(e.to_string()).at(loc)
                        }
                        _ => Error::input(e.to_string()).at(loc),
                    });
                }
            }
        }
        let d = &mut self.solved;
        d.checks.add(&self_check(ctx.setup, &self.ready_contacts, &poses));
        d.unnamed_surfaces |= self.ready_contacts.iter().any(|c| c.surfaces.0.is_none() || c.surfaces.1.is_none());
        let c = &self.cols;
        for (mut row, a) in self.ready.drain(..).zip(&poses) {
            row.pos = a.pose.tip;
            row.axis = a.pose.axis;
            row.s = if c.nonrotating { a.pose.spindle() } else { None };
            row.extra.resize(c.extras, String::new());
            row.extra[c.tilt] = num(a.tilt.to_degrees());
            if let Some(i) = c.edge {
                row.extra[i] = a.edge_radius.map(num).unwrap_or_default();
            }
            if let (Some((ia, ic)), Some((va, vc))) = (c.ac, a.machine) {
                row.extra[ia] = num(va);
                row.extra[ic] = num(vc);
            }
            if let (Some(i), Some(g)) = (c.gap, a.flank_gap) {
                row.extra[i] = num(g.to_degrees());
            }
            if let (Some(i), Some(g)) = (c.gouge, a.gouge) {
                row.extra[i] = num(g);
                if g > ctx.setup.gouge_tol {
                    d.gouge_rows += 1;
                    if d.gouge_lines.len() < 20 {
                        d.gouge_lines.push(row.line);
                    }
                }
            }
            d.rows += 1;
            d.adjusted += usize::from(a.adjusted);
            d.largest_gouge = d.largest_gouge.max(a.gouge.unwrap_or(0.0));
            if let Some(e) = a.edge_radius {
                d.edges = Some(d.edges.map_or((e, e), |(lo, hi)| (lo.min(e), hi.max(e))));
            }
            if let Some(g) = a.flank_gap {
                d.least_gap = Some(d.least_gap.map_or(g, |l| l.min(g)));
            }
            d.largest_correction = d.largest_correction.max(a.tilt.abs());
            self.marker.row(&mut row);
            self.writer.row(out, &row)?;
            if let Some(kept) = &mut d.kept {
                kept.push(row);
            }
        }
        self.ready_contacts.clear();
        Ok(())
    }
}

/// The part of `--model` (none without): the model, the tool body of `length` and the model as
/// a solid, its tessellated surfaces within a quarter of --gouge-tol (at least
/// 1e-6 mm, at most 2 µm).
fn load_part(args: &Args, tool: &Tool, length: f64) -> Result<Option<Part>> {
    let Some(file) = &args.model else { return Ok(None) };
    let model = Model::load_with(&Input::open(file)?, args.skip_unsupported)?;
    // Its STL files' dropped facets warned about (or refused with --strict).
    model.check_dropped(args.strict)?;
    let chord = (0.25 * args.gouge_tol).clamp(1e-6, 0.002);
    Part::new(model, tool, length, chord).map(Some).map_err(|e| Error::input(e).at(Location::file(file)))
}

/// A ball's centre is the stylus centre only if both have one radius: a stream that records a
/// stylus of another radius is refused (naming both), one that records none is taken as given.
fn check_stylus(meaning: Meaning, file: &str, tool: &Tool, tool_file: &str) -> Result<()> {
    if let Meaning::StylusCentre(rs) = meaning {
        if (rs - tool.radius).abs() > 1e-9 * rs.max(1.0) {
            return Err(field_error(
                tool_file,
                "radius",
                format!(
                    "the tool's radius {} mm differs from the radius {rs} mm of the stylus that traced {file} (column stylus_radius): the ball would not touch where the stylus did; trace again with stylus-trace -r {}",
                    tool.radius, tool.radius
                ),
            ));
        }
    }
    Ok(())
}

/// Rows that gouge (the first's line and their count, the deepest `largest` mm) fail the run
/// (exit 1, the first row named) or, with --allow-gouge, are warned of.
fn refuse_gouges(args: &Args, input: &str, gouging: Option<(u64, usize)>, tol: f64, largest: f64) -> Result<()> {
    if let Some((line, count)) = gouging {
        let msg = format!("{count} row(s) gouge the model by more than {tol} mm (deepest {largest:.6} mm)");
        let loc = Location::file(input).line(line);
        if !args.allow_gouge {
            return Err(Error::check(msg).at(loc));
        }
        cli::warn(&format!("{loc}: {msg}"));
    }
    Ok(())
}

/// The tips and axes of `t` drawn to `path`, over the model's height grid.
fn plot(path: &std::path::Path, t: &Table, input: &str, model: Option<&Model>) -> Result<()> {
    let title = format!("{input}: {} rows, tool tip and axis", t.rows.len());
    let under = model.map_or_else(Vec::new, |m| relief::grid_under(m, t.rows.iter().map(|r| &r.pos)));
    write_atomic(path, tool_attitude::plot::plot(t, &title, &under).to_svg(1200.0).as_bytes())
}

/// A pose's measured deviation from its definition above this fails the run (a bug, exit 1).
const POSE_CHECK: f64 = 1e-9;

/// Largest deviations of the written poses from what they promise, measured again.
#[derive(Default)]
struct Checks {
    unit: f64,
    tilt: f64,
    tip: f64,
}

impl Checks {
    /// The larger figures of both.
    fn add(&mut self, other: &Checks) {
        self.unit = self.unit.max(other.unit);
        self.tilt = self.tilt.max(other.tilt);
        self.tip = self.tip.max(other.tip);
    }

    /// The largest deviation; acos near 0 loses half the digits, so tiny tilts are left to the
    /// sine-based tip check.
    fn worst(&self) -> f64 {
        self.unit.max(self.tip).max(if self.tilt < 1e-7 { 0.0 } else { self.tilt })
    }
}

/// Measures every pose: axis of unit length; for the cylinder and ball the angle between axis
/// and normal equal to |tilt| and the tip R (or the ball geometry) from the contact.
fn self_check(setup: &Setup, cs: &[Contact], poses: &[Attitude]) -> Checks {
    let mut c = Checks::default();
    for (ct, a) in cs.iter().zip(poses) {
        let axis = a.pose.axis;
        c.unit = c.unit.max((axis.norm() - 1.0).abs());
        let angle = axis.dot(&ct.normal).clamp(-1.0, 1.0).acos();
        match setup.shape {
            Shape::Cylinder { radius, .. } => {
                c.tilt = c.tilt.max((angle - a.tilt.abs()).abs());
                let d = a.pose.tip - ct.point;
                c.tip = c.tip.max((d.norm() - radius).abs()).max(d.dot(&axis).abs());
            }
            Shape::Ball { radius, .. } => {
                c.tilt = c.tilt.max((angle - a.tilt.abs()).abs());
                let centre = a.pose.tip + axis * radius;
                c.tip = c.tip.max(((centre - ct.point).norm() - radius).abs());
            }
            Shape::FlatMill { .. } => c.tilt = c.tilt.max(angle),
            Shape::FlatType { .. } => {}
        }
    }
    c
}
