//! `curve-fit-arcs`: point streams and G-code to lines and arcs within a proven tolerance.

use camkit::cli::{self, IoArgs, Kind, positive};
use camkit::contour::load::{ContourArgs, InputKind};
use camkit::error::{Error, Location, Result};
use camkit::geom::Plane;
use camkit::io::{Input, Output, Restart, Source, Stream, write_atomic};
use camkit::report::Report;
use camkit::table::{self, Col, WriteOptions};
use clap::{Parser, ValueEnum};
use curve_fit_arcs::gcode_runs::{self, ProgramError};
use curve_fit_arcs::table_runs::{Fitter, Written};
use curve_fit_arcs::{Method, Options, Stats, Sweep, plot, table_runs};
use std::io::BufRead;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum MethodArg {
    /// Longest piece that fits from each start: fewest moves.
    Fewest,
    /// Paper 004's curvature grouping (for comparison).
    Paper,
}

#[derive(Parser, Debug)]
#[command(
    name = "curve-fit-arcs",
    version,
    allow_negative_numbers = true,
    about = "Compress point sequences and G-code into lines and arcs (G1/G2/G3) within a guaranteed tolerance.",
    long_about = "Compress point sequences and G-code into lines and arcs (G1/G2/G3) within a guaranteed \
tolerance (paper 004 §2). Every input point and chord lies within --tol of the output and every output \
point within --tol of the input, measured exactly after rounding to the output's decimals. Moves are never \
merged across a change of path, rapid moves, feed, tool axis, spindle orientation or tag, nor across G-code \
blocks the filter does not model (they are written back verbatim, in order).",
    after_help = after_help()
)]
struct Args {
    #[command(flatten)]
    io: IoArgs,
    #[command(flatten)]
    contours: ContourArgs,
    /// Output format (auto: the input's; the table for a drawing).
    #[arg(long, value_enum, default_value_t = Kind::Auto)]
    to: Kind,
    /// Tolerance (mm): largest distance between output and input, both ways.
    #[arg(long, default_value_t = 0.01, value_name = "MM")]
    tol: f64,
    /// Segmentation method.
    #[arg(long, value_enum, default_value_t = MethodArg::Fewest)]
    method: MethodArg,
    /// Plane of arcs: xy, xz, yz, or auto (each run in whichever plane fits).
    #[arg(long, default_value = "xy", value_name = "PLANE")]
    plane: String,
    /// Smallest arc radius (mm).
    #[arg(long, default_value_t = 0.0, value_name = "MM")]
    min_radius: f64,
    /// Largest arc radius (mm); flatter stretches become lines.
    #[arg(long, default_value_t = 10_000.0, value_name = "MM")]
    max_radius: f64,
    /// Largest sweep of one arc (degrees, below 360).
    #[arg(long, default_value_t = 350.0, value_name = "DEG")]
    max_sweep: f64,
    /// Keep tangent continuity between pieces: largest change of direction at a joint (degrees).
    #[arg(long, value_name = "DEG")]
    tangent: Option<f64>,
    /// Turning angle (degrees) above which a point is a corner, kept sharp.
    #[arg(long, default_value_t = 60.0, value_name = "DEG")]
    corner: f64,
    /// Curvature threshold (1/mm) of the paper method: at or above it points group into arcs.
    #[arg(long, default_value_t = 1e-3, value_name = "1/MM")]
    curvature_threshold: f64,
    /// Largest relative difference of extrusion per mm between G-code moves merged into one.
    #[arg(long, default_value_t = 0.05, value_name = "FRACTION")]
    e_rate_tol: f64,
    /// Tool axes (i,j,k) of table rows this close (degrees) count as one axis, so that round-off
    /// from an earlier stage does not split a run; the merged row keeps its own.
    #[arg(long, default_value_t = 1e-7, value_name = "DEG")]
    axis_tol: f64,
    /// Decimals of written positions (default: G-code keeps the input's, at least 3 (mm) or 4
    /// (inch); tables are written exactly).
    #[arg(long, value_name = "N")]
    decimals: Option<u32>,
    /// Also prove a lower bound on the moves of any segmentation of the same runs within --tol,
    /// joints anywhere (report key moves_lower_bound; slower than the fit itself).
    #[arg(long)]
    lower_bound: bool,
    /// Write an SVG of the input points and the fitted lines and arcs; a layered program (three
    /// heights or more, e.g. a print) as isometric, top and side views coloured by height, travel
    /// dashed apart from extrusion.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
}

fn after_help() -> String {
    let mut s = table::columns::help_text(
        &[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::I, Col::J, Col::K, Col::S, Col::F, Col::Tag],
        &[Col::Move, Col::X, Col::Y, Col::Z, Col::Xc, Col::Yc, Col::Zc, Col::Plane],
    );
    s.push_str("Other columns pass through; a merged row keeps the values of the input row it ends at.\n\n");
    s.push_str("G-code: G0/G1/G2/G3 (I/J/K or R), G17/G18/G19, G20/G21, G90/G91, G90.1/G91.1, F, E (M82/M83), N,\n");
    s.push_str("( ) and ; comments, modal moves. E is summed over merged moves (relative) or carried (absolute).\n");
    s.push_str(&camkit::contour::load::help_text());
    s.push('\n');
    s.push_str("\nExit status: 0 done, 1 a check failed, 2 bad input or usage.");
    s
}

fn main() -> ExitCode {
    cli::run("curve-fit-arcs", || run(cli::parse::<Args>()?))
}

fn usage(message: String) -> Error {
    Error::input(message)
}

fn options(args: &Args) -> Result<Options> {
    let tol = positive(args.tol, "--tol")?;
    let planes = match args.plane.as_str() {
        "auto" => vec![Plane::Xy, Plane::Xz, Plane::Yz],
        p => vec![Plane::parse(p).ok_or_else(|| usage(format!("--plane must be xy, xz, yz or auto, got {p}")))?],
    };
    if !(args.min_radius >= 0.0 && args.max_radius > args.min_radius && args.max_radius.is_finite()) {
        return Err(usage("--min-radius and --max-radius must satisfy 0 ≤ min < max".into()));
    }
    if !(args.max_sweep > 0.0 && args.max_sweep < 360.0) {
        return Err(usage("--max-sweep must be between 0 and 360 degrees".into()));
    }
    if let Some(t) = args.tangent {
        if !(0.0..90.0).contains(&t) {
            return Err(usage("--tangent must be an angle from 0 to 90 degrees".into()));
        }
        if planes.len() > 1 {
            return Err(usage("--tangent needs one arc plane, not --plane auto".into()));
        }
    }
    if args.decimals.is_some_and(|d| d > 12) {
        return Err(usage("--decimals must be at most 12".into()));
    }
    Ok(Options {
        tol,
        method: match args.method {
            MethodArg::Fewest => Method::Fewest,
            MethodArg::Paper => Method::Paper,
        },
        planes,
        min_radius: args.min_radius,
        max_radius: args.max_radius,
        max_sweep: Sweep::degrees(args.max_sweep),
        tangent: args.tangent.map(f64::to_radians),
        corner: positive(args.corner, "--corner")?.to_radians(),
        curvature_threshold: positive(args.curvature_threshold, "--curvature-threshold")?,
        e_rate_tol: positive(args.e_rate_tol, "--e-rate-tol")?,
        axis_tol: positive(args.axis_tol, "--axis-tol")?.to_radians(),
    })
}

fn run(args: Args) -> Result<()> {
    let opts = options(&args)?;
    let contour_opts = args.contours.options(true)?;
    let from =
        if contour_opts.from.resolve_name(&args.io.input) == InputKind::Gcode { Kind::Gcode } else { Kind::Table };
    let to = if args.to == Kind::Auto { from } else { args.to };
    if from == Kind::Gcode && to == Kind::Gcode {
        return run_gcode(&args, &opts);
    }
    if from == Kind::Table && to == Kind::Table {
        return run_table(&args, &opts, &contour_opts);
    }
    let started = Instant::now();
    let mut input = Input::open(&args.io.input)?;
    let bytes_in = input.data.len();
    let mut out = Output::new(args.io.output.as_deref());
    let progress = args.io.progress(0, "fitting arcs");
    let (stats, runs) = if from == Kind::Gcode {
        let source = input.take_text()?;
        if source.trim().is_empty() {
            return Err(Error::input("empty input: no G-code").at(Location::file(&input.name)));
        }
        let program = camkit::gcode::read(&input.name, source)?;
        let (t, skipped) = camkit::gcode::program_to_table(&program);
        if skipped > 0 {
            cli::warn(&format!(
                "{skipped} non-motion blocks (comments, M/S/T words, other G codes) are not carried into the table"
            ));
        }
        fit_to_table(&t, &opts, &args, &input, &mut out)?
    } else {
        let (t, skipped) = camkit::contour::load::table(&input, &contour_opts)?;
        warn_skipped(&input.name, &skipped);
        let moved = t.rows.windows(2).any(|w| moves(&w[0].pos, &w[1].pos));
        two_points(&input.name, t.rows.len(), moved)?;
        let d = args.decimals.unwrap_or(4);
        let (fitted, stats, runs) = table_runs::fit_table(&t, &opts, Some(d))
            .map_err(|e| unfittable(&input.name, e.line, e.cause.deviation, &opts))?;
        out.buf = camkit::gcode::table_to_program(&fitted, &input.name, d)?;
        (stats, runs)
    };
    progress.finish();
    let bytes_out = out.buf.len();
    finish(&args, &opts, &input.name, &stats, &runs, started, bytes_in, bytes_out)?;
    out.commit()
}

/// Table to table, streamed: rows read, fitted run by run and written as they come, never the
/// table held as rows (only the input's text). The header depends on what the fit writes (centre
/// columns for arcs, plane columns for arcs off XY): it is guessed (arcs, all in XY) and the table
/// is fitted and written again, with the right header, in the rare run where that was wrong.
fn run_table(args: &Args, opts: &Options, contours: &camkit::contour::load::Options) -> Result<()> {
    let started = Instant::now();
    let input = Input::open(&args.io.input)?;
    let mut out = Stream::new(args.io.output.as_deref())?;
    let progress = args.io.progress(0, "fitting arcs");
    let keep_runs = args.svg.is_some() || args.lower_bound;
    let wopts = WriteOptions { decimals: args.decimals };
    let mut guess = Written { arcs: true, other_planes: false };
    let mut warned = false;
    loop {
        let mut fitter = Fitter::new(opts, args.decimals, keep_runs);
        let mut writer: Option<table::RowWriter> = None;
        let (mut rows, mut moved, mut last) = (0usize, false, None::<camkit::geom::P3>);
        let (schema, skipped) = camkit::contour::load::table_each(&input, contours, |schema, row| {
            rows += 1;
            moved |= last.is_some_and(|p| moves(&p, &row.pos));
            last = Some(row.pos);
            fitter.push(row).map_err(|e| unfittable(&input.name, e.line, e.cause.deviation, opts))?;
            let w = writer.get_or_insert_with(|| table::RowWriter::new(&guess.schema(schema), wopts));
            fitter.ready.drain(..).try_for_each(|r| w.row(&mut out, &r))
        })?;
        if !warned {
            warn_skipped(&input.name, &skipped);
            warned = true;
        }
        two_points(&input.name, rows, moved)?;
        fitter.flush().map_err(|e| unfittable(&input.name, e.line, e.cause.deviation, opts))?;
        let mut w = writer.expect("rows were read");
        fitter.ready.drain(..).try_for_each(|r| w.row(&mut out, &r))?;
        w.finish(&mut out)?;
        let (stats, runs, written) = fitter.into_results();
        if written.schema(&schema) != guess.schema(&schema) {
            guess = written;
            out.restart().map_err(|e| Error::io(e, "output"))?;
            continue;
        }
        progress.finish();
        finish(args, opts, &input.name, &stats, &runs, started, input.data.len(), out.len() as usize)?;
        return out.commit();
    }
}

/// True when two consecutive input points are distinct.
fn moves(a: &camkit::geom::P3, b: &camkit::geom::P3) -> bool {
    (a - b).norm() > camkit::tol::POINT_EPS
}

/// Refuses input of `rows` points that never `moved`: a fit needs two distinct points.
fn two_points(name: &str, rows: usize, moved: bool) -> Result<()> {
    if moved {
        return Ok(());
    }
    let what = if rows == 0 { "no points" } else { "a single point" };
    Err(Error::input(format!("{what}: at least two distinct points are needed")).at(Location::file(name)))
}

/// Warns of a drawing's entities that are not contours.
fn warn_skipped(name: &str, skipped: &[(String, u64)]) {
    if let Some((kind, line)) = skipped.first() {
        cli::warn(&format!(
            "{name}: {} drawing entities that are not contours skipped (the first: {kind} at line {line})",
            skipped.len()
        ));
    }
}

/// G-code to G-code, streamed: read, fitted and written run by run, never the whole program in
/// memory (but the runs, for --svg or --lower-bound).
fn run_gcode(args: &Args, opts: &Options) -> Result<()> {
    let started = Instant::now();
    let source = Source::open(&args.io.input)?;
    if blank(source.reader()?).map_err(|e| Error::io(e, &source.name))? {
        return Err(Error::input("empty input: no G-code").at(Location::file(&source.name)));
    }
    let mut out = Stream::new(args.io.output.as_deref())?;
    let progress = args.io.progress(0, "fitting arcs");
    let keep_runs = args.svg.is_some() || args.lower_bound;
    let (stats, runs) =
        gcode_runs::fit_source(&source.name, &mut || source.reader(), &mut out, opts, args.decimals, keep_runs)
            .map_err(|e| match e {
                ProgramError::Read(e) => e,
                ProgramError::Fit(e) => unfittable(&source.name, u64::from(e.line), e.cause.deviation, opts),
            })?;
    progress.finish();
    finish(args, opts, &source.name, &stats, &runs, started, source.len()? as usize, out.len() as usize)?;
    out.commit()
}

/// True if `text` holds nothing but white space.
fn blank(mut text: impl BufRead) -> std::io::Result<bool> {
    loop {
        let chunk = text.fill_buf()?;
        if chunk.is_empty() {
            return Ok(true);
        }
        if !chunk.iter().all(u8::is_ascii_whitespace) {
            return Ok(false);
        }
        let n = chunk.len();
        text.consume(n);
    }
}

/// Checks the tolerance held, then writes the plot and the report.
#[allow(clippy::too_many_arguments)]
fn finish(
    args: &Args,
    opts: &Options,
    name: &str,
    stats: &Stats,
    runs: &[curve_fit_arcs::FittedRun],
    started: Instant,
    bytes_in: usize,
    bytes_out: usize,
) -> Result<()> {
    if !camkit::tol::within(stats.largest_deviation, opts.tol) {
        return Err(Error::check(format!(
            "largest deviation {:.6} mm exceeds --tol {} mm",
            stats.largest_deviation, opts.tol
        )));
    }
    let seconds = started.elapsed().as_secs_f64();
    if let Some(path) = &args.svg {
        let plane = opts.planes[0];
        let title = format!("{}: {} moves → {} (tol {} mm)", name, stats.input_moves, stats.output_moves, opts.tol);
        write_atomic(path, plot::svg(runs, plane, &title, 1200.0).as_bytes())?;
    }
    if let Some(path) = &args.io.report {
        let mut r = report(stats, opts, seconds, bytes_in, bytes_out);
        if args.lower_bound {
            r.set("moves_lower_bound", curve_fit_arcs::moves_lower_bound(stats, runs, opts));
        }
        r.write(path)?;
    }
    Ok(())
}

fn fit_to_table(
    t: &table::Table,
    opts: &Options,
    args: &Args,
    input: &Input,
    out: &mut Output,
) -> Result<(Stats, Vec<curve_fit_arcs::FittedRun>)> {
    let (fitted, stats, runs) = table_runs::fit_table(t, opts, args.decimals)
        .map_err(|e| unfittable(&input.name, e.line, e.cause.deviation, opts))?;
    table::write(out, &fitted, &WriteOptions { decimals: args.decimals })?;
    Ok((stats, runs))
}

fn unfittable(file: &str, line: u64, deviation: f64, opts: &Options) -> Error {
    Error::input(format!(
        "a single move deviates {deviation:.6} mm from the input once rounded, more than --tol {} mm: write more --decimals",
        opts.tol
    ))
    .at(Location::file(file).line(line))
}

fn report(stats: &Stats, opts: &Options, seconds: f64, bytes_in: usize, bytes_out: usize) -> Report {
    let mut r = Report::new("curve-fit-arcs");
    r.set("method", format!("{:?}", opts.method).to_lowercase())
        .set("tol_mm", opts.tol)
        .set("input_moves", stats.input_moves)
        .set("output_moves", stats.output_moves)
        .set("compression_ratio", stats.ratio())
        .set("lines", stats.lines)
        .set("arcs", stats.arcs)
        .set("largest_deviation_mm", stats.largest_deviation)
        .set("points", stats.points)
        .set("dropped_repeats", stats.dropped_repeats)
        .set("seconds", seconds)
        .set("points_per_second", stats.points as f64 / seconds.max(1e-9))
        .set("bytes_in", bytes_in)
        .set("bytes_out", bytes_out)
        .set("mb_per_second", bytes_in as f64 / 1e6 / seconds.max(1e-9));
    r
}
