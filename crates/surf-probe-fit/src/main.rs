//! `surf-probe-fit`: on-machine measurement of a workpiece's shape and pose (paper 002 §2–4).

use camkit::cli::{self, IoArgs, positive, within};
use camkit::doc::machine::Machine;
use camkit::error::{Error, Location, Result};
use camkit::geom::{P3, V3};
use camkit::io::{Input, Output, Stream};
use camkit::kinematics::{Chain, Joints, Link};
use camkit::report::Report;
use camkit::table::{self, Col, Field, Move, Row, RowWriter, Schema, Table, WriteOptions};
use clap::{Parser, Subcommand, ValueEnum};
use std::collections::HashMap;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use surf_probe_fit::document::read_shape;
use surf_probe_fit::records::{self, Record};
use surf_probe_fit::reference::{self, Spec};
use surf_probe_fit::rng::Rng;
use surf_probe_fit::rough::{self, Probe};
use surf_probe_fit::sensor::Sensor;
use surf_probe_fit::{FitError, Kind, Options, Ransac, Robust, Shape, frame, globe, heightfield, shapes};

#[derive(Parser, Debug)]
#[command(
    name = "surf-probe-fit",
    version,
    allow_negative_numbers = true,
    about = "Measure a workpiece on the machine and fit its shape and pose: the workpiece frame for post-6axis.",
    long_about = "Measure a workpiece on the machine and fit its shape and pose (paper 002 §2-4): a 3-axis \
raster with a laser displacement sensor (`raster`, `simulate`), a rough Delaunay surface of it and the 5-axis \
measuring plan along its normals (`plan`, a toolpath table post-6axis posts), raw records turned into points \
through the machine's kinematics (`points`), and the geometric least-squares fit of a sphere, plane, circle or \
cylinder written as the workpiece frame document post-6axis reads with --frame (`fit`). `reference` writes \
point sets with known least-squares solutions (ISO 10360-6 style).",
    after_help = "Formats: docs/formats.md#surf-probe-fit. Exit status: 0 done, 1 the fit did not converge, 2 bad input."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Fit an element to measured points (x,y,z) or raw sensor records (axes + reading); write the
    /// workpiece frame document (JSON) with the fit in it.
    #[command(allow_negative_numbers = true)]
    Fit(FitArgs),
    /// Write a 3-axis raster of sensor poses (tool axis +Z) as a toolpath table.
    #[command(allow_negative_numbers = true)]
    Raster(RasterArgs),
    /// Simulate the laser sensor over a known element along the poses of a toolpath table: raw
    /// records (axis positions, reading).
    #[command(allow_negative_numbers = true)]
    Simulate(SimulateArgs),
    /// Turn raw sensor records into measured points through the machine's kinematics.
    #[command(allow_negative_numbers = true)]
    Points(PointsArgs),
    /// The 5-axis measuring plan: sensor poses along the normals of the rough surface (Delaunay
    /// triangulation of the points) or of a fitted sphere, at the stand-off, as a toolpath table.
    #[command(allow_negative_numbers = true)]
    Plan(PlanArgs),
    /// Write a reference point set with a known least-squares solution (ISO 10360-6 style).
    #[command(allow_negative_numbers = true)]
    Reference(ReferenceArgs),
    /// Fit a bicubic B-spline height field z(x, y) to points or raw records (free-form parts);
    /// write it as a model document (a `bspline` surface) that stylus-trace reads.
    #[command(allow_negative_numbers = true)]
    Surface(SurfaceArgs),
    /// Map outlines given by longitude and latitude (JSON) onto the fitted sphere of a frame
    /// document: a contour table in workpiece coordinates with the tool axis along the normal.
    #[command(allow_negative_numbers = true)]
    Map(MapArgs),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ShapeArg {
    Sphere,
    Plane,
    Circle,
    Cylinder,
}

impl ShapeArg {
    fn kind(self) -> Kind {
        match self {
            ShapeArg::Sphere => Kind::Sphere,
            ShapeArg::Plane => Kind::Plane,
            ShapeArg::Circle => Kind::Circle,
            ShapeArg::Cylinder => Kind::Cylinder,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum RobustArg {
    /// Plain least squares.
    None,
    /// Huber weights (iteratively reweighted).
    Huber,
    /// RANSAC on minimal samples, then least squares on the inliers.
    Ransac,
}

#[derive(clap::Args, Debug)]
struct FitArgs {
    #[command(flatten)]
    io: IoArgs,
    /// Element to fit.
    #[arg(long, value_enum, default_value_t = ShapeArg::Sphere)]
    shape: ShapeArg,
    /// Machine document (JSON) for raw records (a `reading` column); without it records are
    /// 3-axis (beam along −Z).
    #[arg(long, short = 'm', value_name = "FILE")]
    machine: Option<String>,
    /// Robust weighting against outliers.
    #[arg(long, value_enum, default_value_t = RobustArg::None)]
    robust: RobustArg,
    /// Huber threshold in robust standard deviations.
    #[arg(long, default_value_t = 1.345, value_name = "K", value_parser = cli::finite)]
    huber_k: f64,
    /// RANSAC inlier threshold on the orthogonal distance (mm); default k(n) robust standard
    /// deviations of the inliers (k(n): the Gaussian quantile any of n clean points exceeds with
    /// probability 1 %, at least 3.5), so clean data give the plain fit.
    #[arg(long, value_name = "MM", value_parser = cli::finite)]
    ransac_threshold: Option<f64>,
    /// RANSAC: wanted probability that some sample is free of outliers (sets the number of samples).
    #[arg(long, default_value_t = Ransac::default().confidence, value_name = "P", value_parser = cli::finite)]
    confidence: f64,
    /// RANSAC: seed of the samples (the same seed gives the same fit).
    #[arg(long, default_value_t = Ransac::default().seed)]
    seed: u64,
    /// RANSAC: most samples drawn.
    #[arg(long, default_value_t = Ransac::default().max_hypotheses, value_name = "N")]
    max_hypotheses: usize,
    /// Noise amplification above which a parameter is reported as poorly determined.
    #[arg(long, default_value_t = shapes::DEFAULT_MAX_AMPLIFICATION, value_name = "FACTOR", value_parser = cli::finite)]
    max_amplification: f64,
    /// The true element (a shape or frame document): its errors go into the report.
    #[arg(long, value_name = "FILE")]
    truth: Option<String>,
    /// Write the input rows with each point's `residual` (signed orthogonal distance from the
    /// fitted element, mm) and, with --robust ransac, `outlier` (1 for points left out) to FILE.
    #[arg(long, value_name = "FILE")]
    residuals: Option<PathBuf>,
}

#[derive(clap::Args, Debug)]
struct OutArgs {
    /// Write the output to FILE (whole or not at all) instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
    /// Write figures of the run to FILE as JSON.
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
}

/// The work bound of the sub-commands that generate rows: the rows are estimated from the options
/// before anything is allocated, and a run past the bound is refused (exit 2) naming the option.
#[derive(clap::Args, Debug)]
struct LimitArgs {
    /// Refuse (exit 2) a run whose output would have more than N rows (estimated from the options
    /// before any work; each row costs about 200 bytes of memory). At most 10 000 000.
    #[arg(long, default_value_t = DEFAULT_MAX_POINTS, value_name = "N")]
    max_points: usize,
}

/// Default of `--max-points`.
const DEFAULT_MAX_POINTS: usize = 1_000_000;

/// Largest `--max-points` (about 2 GB of rows).
const MAX_POINTS_CAP: usize = 10_000_000;

/// Largest coordinate or length on the command line (mm, 1 km): a machine's workspace, with room.
const MAX_MM: f64 = 1e6;

impl LimitArgs {
    /// Refuses `estimate` rows past the bound; `what` names the options that set it.
    fn check(&self, estimate: f64, what: &str) -> Result<()> {
        if self.max_points > MAX_POINTS_CAP {
            return Err(Error::input(format!(
                "--max-points must be at most {MAX_POINTS_CAP}, got {}",
                self.max_points
            )));
        }
        if estimate > self.max_points as f64 {
            return Err(Error::input(format!(
                "{what} would give {estimate:.4e} rows, more than --max-points {}",
                self.max_points
            )));
        }
        Ok(())
    }
}

/// A coordinate or length option within ±[`MAX_MM`].
fn mm(v: f64, what: &str) -> Result<f64> {
    within(v, -MAX_MM, MAX_MM, what, " mm")
}

/// A positive length option up to [`MAX_MM`].
fn positive_mm(v: f64, what: &str) -> Result<f64> {
    within(positive(v, what)?, 0.0, MAX_MM, what, " mm")
}

#[derive(clap::Args, Debug)]
struct RasterArgs {
    #[command(flatten)]
    out: OutArgs,
    #[command(flatten)]
    limit: LimitArgs,
    /// The rectangle rastered, X0,X1,Y0,Y1 (mm), as every filter spells it.
    #[arg(long, value_name = "X0,X1,Y0,Y1", allow_hyphen_values = true, value_parser = cli::region, required_unless_present_all = ["x", "y"])]
    region: Option<camkit::geom::Region>,
    /// The older spelling of the region's X range `MIN,MAX` (mm), with --y.
    #[arg(long, value_name = "MIN,MAX", value_delimiter = ',', allow_hyphen_values = true, value_parser = cli::finite, hide = true, requires = "y", conflicts_with = "region")]
    x: Vec<f64>,
    /// The older spelling of the region's Y range `MIN,MAX` (mm), with --x.
    #[arg(long, value_name = "MIN,MAX", value_delimiter = ',', allow_hyphen_values = true, value_parser = cli::finite, hide = true, requires = "x", conflicts_with = "region")]
    y: Vec<f64>,
    /// Spacing of the raster in X and Y (mm).
    #[arg(long, default_value_t = 2.0, value_name = "MM", value_parser = cli::finite)]
    step: f64,
    /// Height of the sensor's reference point (mm).
    #[arg(long, value_name = "MM", value_parser = cli::finite)]
    z: f64,
}

#[derive(clap::Args, Debug)]
struct SensorArgs {
    /// Sensor stand-off (mm): nominal distance from its reference point to the surface.
    #[arg(long, default_value_t = Sensor::default().standoff, value_name = "MM", value_parser = cli::finite)]
    standoff: f64,
    /// Half measuring range about the stand-off (mm).
    #[arg(long, default_value_t = Sensor::default().range, value_name = "MM", value_parser = cli::finite)]
    range: f64,
    /// Reading noise at normal incidence, standard deviation (mm).
    #[arg(long, default_value_t = Sensor::default().noise, value_name = "MM", value_parser = cli::finite)]
    noise: f64,
    /// Systematic error coefficient (mm): readings are longer by it × (1/cos θ − 1).
    #[arg(long, default_value_t = Sensor::default().slope_error, value_name = "MM", value_parser = cli::finite)]
    slope_error: f64,
    /// Largest incidence angle that returns a reading (degrees).
    #[arg(long, default_value_t = Sensor::default().max_incidence, value_name = "DEG", value_parser = cli::finite)]
    max_incidence: f64,
}

#[derive(clap::Args, Debug)]
struct SimulateArgs {
    #[command(flatten)]
    io: IoArgs,
    /// The true element in table coordinates (shape document, JSON).
    #[arg(long, value_name = "FILE")]
    shape: String,
    /// Machine document: records carry its axis positions (default: 3-axis).
    #[arg(long, short = 'm', value_name = "FILE")]
    machine: Option<String>,
    #[command(flatten)]
    sensor: SensorArgs,
    /// Random seed of the noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

#[derive(clap::Args, Debug)]
struct PointsArgs {
    #[command(flatten)]
    io: IoArgs,
    /// Machine document of the records (default: 3-axis).
    #[arg(long, short = 'm', value_name = "FILE")]
    machine: Option<String>,
}

#[derive(clap::Args, Debug)]
struct PlanArgs {
    #[command(flatten)]
    io: IoArgs,
    #[command(flatten)]
    limit: LimitArgs,
    /// Plan on this fitted sphere (a frame or shape document) instead of the rough surface.
    #[arg(long, value_name = "FILE")]
    fit: Option<String>,
    /// Sensor stand-off (mm): the pose's tip is this far from the surface along the normal.
    #[arg(long, default_value_t = Sensor::default().standoff, value_name = "MM", value_parser = cli::finite)]
    standoff: f64,
    /// Rough surface: probe every N-th point.
    #[arg(long, default_value_t = 1, value_name = "N")]
    every: usize,
    /// Rough surface: facets steeper than this are dropped (degrees).
    #[arg(long, default_value_t = 80.0, value_name = "DEG", value_parser = cli::finite)]
    max_slope: f64,
    /// Sphere: largest angle from the top (degrees).
    #[arg(long, default_value_t = 80.0, value_name = "DEG", value_parser = cli::finite)]
    max_polar: f64,
    /// Sphere: spacing of rings and of points along them (degrees).
    #[arg(long, default_value_t = 10.0, value_name = "DEG", value_parser = cli::finite)]
    ring_step: f64,
}

#[derive(clap::Args, Debug)]
struct ReferenceArgs {
    #[command(flatten)]
    out: OutArgs,
    #[command(flatten)]
    limit: LimitArgs,
    /// Element.
    #[arg(long, value_enum, default_value_t = ShapeArg::Sphere)]
    shape: ShapeArg,
    /// Centre (sphere, circle) or axis point (cylinder) or plane point `X,Y,Z`.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, default_values_t = [0.0, 0.0, 0.0], value_parser = cli::finite)]
    centre: Vec<f64>,
    /// Normal (plane, circle) or axis (cylinder) `X,Y,Z`.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, default_values_t = [0.0, 0.0, 1.0], value_parser = cli::finite)]
    axis: Vec<f64>,
    /// Radius (mm).
    #[arg(long, default_value_t = 25.0, value_parser = cli::finite)]
    radius: f64,
    /// Sphere: cap half-angle (deg); cylinder: length (mm); plane: half-width (mm); circle: arc (deg).
    #[arg(long, default_value_t = 180.0, value_parser = cli::finite)]
    extent: f64,
    /// Number of points.
    #[arg(long, default_value_t = 1000)]
    points: usize,
    /// Residual amplitude (mm).
    #[arg(long, default_value_t = 0.01, value_parser = cli::finite)]
    amplitude: f64,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

#[derive(clap::Args, Debug)]
struct SurfaceArgs {
    #[command(flatten)]
    io: IoArgs,
    /// Machine document of raw records (default: 3-axis).
    #[arg(long, short = 'm', value_name = "FILE")]
    machine: Option<String>,
    /// Control points along x and y (each at least 4).
    #[arg(long, value_delimiter = ',', default_values_t = [10, 10], value_name = "NU,NV")]
    net: Vec<usize>,
}

fn run_surface(args: SurfaceArgs) -> Result<()> {
    if args.net.len() != 2 || args.net.iter().any(|&n| !(4..=60).contains(&n)) {
        return Err(Error::input("--net takes two counts NU,NV from 4 to 60"));
    }
    let input = Input::open(&args.io.input)?;
    let (_, pts) = read_points(&input, args.machine.as_deref())?;
    if pts.len() < args.net[0] * args.net[1] {
        return Err(Error::input(format!(
            "{} points: a {}x{} net needs at least {}",
            pts.len(),
            args.net[0],
            args.net[1],
            args.net[0] * args.net[1]
        ))
        .at(Location::file(&input.name)));
    }
    let h = heightfield::fit(&pts, args.net[0], args.net[1])
        .ok_or_else(|| Error::input("the points span no area in x and y").at(Location::file(&input.name)))?;
    let doc =
        serde_json::json!({"surfaces": [{"type": "bspline", "name": "measured", "control_points": h.control_points}]});
    let mut out = Output::new(args.io.output.as_deref());
    out.buf = serde_json::to_vec_pretty(&doc).map_err(|e| Error::runtime(e.to_string()))?;
    out.buf.push(b'\n');
    let mut report = Report::new("surf-probe-fit");
    report
        .set("command", "surface")
        .set("points", pts.len())
        .set("net", &args.net)
        .set("rms_mm", h.rms)
        .set("largest_residual_mm", h.largest_residual)
        .set("orthogonal_rms_mm", h.orthogonal_rms)
        .set("largest_orthogonal_mm", h.largest_orthogonal);
    if let Some(path) = &args.io.report {
        report.write(path)?;
    }
    out.commit()
}

#[derive(clap::Args, Debug)]
struct MapArgs {
    #[command(flatten)]
    io: IoArgs,
    #[command(flatten)]
    limit: LimitArgs,
    /// The frame document of a sphere fit (its radius is used; the workpiece origin is the centre).
    #[arg(long, value_name = "FILE")]
    frame: String,
    /// Longitude (degrees) that faces +X.
    #[arg(long, default_value_t = 0.0, value_name = "DEG", value_parser = cli::finite)]
    lon0: f64,
    /// Largest arc (degrees) between consecutive points along an edge.
    #[arg(long, default_value_t = 0.5, value_name = "DEG", value_parser = cli::finite)]
    step: f64,
    /// Depth (mm) of the tool tip below the surface, along the normal.
    #[arg(long, default_value_t = 0.0, value_name = "MM", value_parser = cli::finite)]
    depth: f64,
}

/// The outlines document: `{"parts": [[[lon, lat], ...], ...]}` (degrees), with free `source`;
/// other fields and duplicate keys are refused.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Outlines {
    parts: Vec<Vec<[f64; 2]>>,
    #[serde(default)]
    source: Option<String>,
}

fn run_map(args: MapArgs) -> Result<()> {
    let Shape::Sphere { radius, .. } = read_shape(&args.frame)? else {
        return Err(Error::input("--frame must hold a sphere fit").at(Location::file(&args.frame)));
    };
    within(positive(args.step, "--step")?, 0.0, 180.0, "--step", "°")?;
    within(args.lon0, -360.0, 360.0, "--lon0", "°")?;
    if !(args.depth >= 0.0 && args.depth < radius) {
        return Err(Error::input(format!(
            "--depth must be from 0 to the sphere's radius {radius} mm, got {}",
            args.depth
        )));
    }
    let input = Input::open(&args.io.input)?;
    let doc: Outlines = camkit::json::from_input(&input)?;
    for (k, part) in doc.parts.iter().enumerate() {
        if part.len() < 2 || part.iter().flatten().any(|v| !v.is_finite()) {
            return Err(camkit::json::at_value(
                &input,
                camkit::json::field_error(
                    &input.name,
                    &format!("parts[{k}]"),
                    "an outline needs at least two finite [lon, lat] points",
                ),
            ));
        }
        if let Some(j) = part.iter().position(|p| p[0].abs() > 360.0 || p[1].abs() > 90.0) {
            return Err(camkit::json::at_value(
                &input,
                camkit::json::field_error(
                    &input.name,
                    &format!("parts[{k}][{j}]"),
                    format!("[lon, lat] must lie within ±360° and ±90°, got {:?}", part[j]),
                ),
            ));
        }
    }
    let estimate: f64 = doc.parts.iter().map(|part| globe::outline_points(part, args.lon0, args.step)).sum();
    args.limit.check(estimate, &format!("--step {}° along the outlines", args.step))?;
    let mut t = pose_table(&[]);
    for (k, part) in doc.parts.iter().enumerate() {
        for (j, (p, n)) in globe::map_outline(part, radius, args.lon0, args.step).iter().enumerate() {
            let mut row = Row::at(k as i64, p - n * args.depth);
            row.mv = if j == 0 { Move::Rapid } else { Move::Line };
            row.axis = *n;
            row.tag = "coastline".into();
            t.rows.push(row);
        }
    }
    let mut report = Report::new("surf-probe-fit");
    report
        .set("command", "map")
        .set("source", &doc.source)
        .set("outlines", doc.parts.len())
        .set("points", t.rows.len())
        .set("radius_mm", radius);
    write_table(&t, &OutArgs { output: args.io.output, report: args.io.report }, &report)
}

fn main() -> ExitCode {
    cli::run("surf-probe-fit", || match cli::parse::<Cli>()?.command {
        Command::Fit(a) => run_fit(a),
        Command::Raster(a) => run_raster(a),
        Command::Simulate(a) => run_simulate(a),
        Command::Points(a) => run_points(a),
        Command::Plan(a) => run_plan(a),
        Command::Reference(a) => run_reference(a),
        Command::Map(a) => run_map(a),
        Command::Surface(a) => run_surface(a),
    })
}

/// The chain in table coordinates (frame at zero): the machine's, or a 3-axis machine.
fn table_chain(machine: Option<&str>) -> Result<(Chain, f64)> {
    match machine {
        Some(path) => {
            let (m, chain) = Machine::read(path)?;
            Ok((chain.with_frame(V3::zeros()), m.singular_cone.to_radians()))
        }
        None => Ok((Chain::new(vec![Link::Linear], vec![]).map_err(Error::runtime)?, 0.0)),
    }
}

/// Column position (1-based) of the extra column `i` in the header.
fn extra_column(schema: &Schema, i: usize) -> u64 {
    schema.fields.iter().position(|f| *f == Field::Extra(i)).map_or(0, |p| p as u64 + 1)
}

/// The extra column `name` matched without regard to case, as the table reader matches its known
/// columns (`READING` is `reading`); two columns that differ only in case are refused.
fn extra_index(t: &Table, name: &str, file: &str) -> Result<Option<usize>> {
    let mut found = t.schema.extra_names.iter().enumerate().filter(|(_, n)| n.eq_ignore_ascii_case(name));
    let first = found.next();
    if let (Some((_, a)), Some((_, b))) = (first, found.next()) {
        return Err(
            Error::input(format!("columns `{a}` and `{b}` are the same column `{name}`")).at(Location::file(file))
        );
    }
    Ok(first.map(|(i, _)| i))
}

fn extra_number(t: &Table, row: &Row, name: &str, file: &str) -> Result<Option<f64>> {
    let Some(i) = extra_index(t, name, file)? else { return Ok(None) };
    let text = row.extra[i].as_str();
    camkit::num::parse_finite(text).map(Some).map_err(|e| {
        Error::input(e.message(text))
            .at(Location::file(file).line(row.line).column(extra_column(&t.schema, i)).field(name))
    })
}

/// Raw records of a table: axis positions `x, y, z`, the chain's rotary addresses (lower case,
/// 0 when absent) and `reading`.
fn read_records(t: &Table, chain: &Chain, file: &str) -> Result<Vec<Record>> {
    let names: Vec<String> = chain.rotaries().iter().map(|r| r.address.to_ascii_lowercase().to_string()).collect();
    t.rows
        .iter()
        .map(|row| {
            let reading = extra_number(t, row, "reading", file)?
                .ok_or_else(|| Error::input("missing column `reading`").at(Location::file(file).line(row.line)))?;
            let mut rot = [0.0; 2];
            for (k, n) in names.iter().enumerate() {
                rot[k] = extra_number(t, row, n, file)?.unwrap_or(0.0);
            }
            Ok(Record { joints: Joints { xyz: row.pos.coords, rot }, reading })
        })
        .collect()
}

/// Points of a table: raw records through the kinematics when it has a `reading` column, the
/// `x, y, z` columns otherwise. Duplicate points are refused.
fn read_points(input: &Input, machine: Option<&str>) -> Result<(Table, Vec<P3>)> {
    let t = table::read(input, &[Col::X, Col::Y])?;
    let pts: Vec<P3> = if extra_index(&t, "reading", &input.name)?.is_some() {
        let (chain, _) = table_chain(machine)?;
        read_records(&t, &chain, &input.name)?.iter().map(|r| records::to_point(&chain, r)).collect()
    } else {
        t.rows.iter().map(|r| r.pos).collect()
    };
    let mut seen: HashMap<[u64; 3], u64> = HashMap::with_capacity(pts.len());
    for (p, row) in pts.iter().zip(&t.rows) {
        let key = [p.x, p.y, p.z].map(|v| (v + 0.0).to_bits());
        if let Some(first) = seen.insert(key, row.line) {
            return Err(Error::input(format!("duplicate point: the same as line {first}"))
                .at(Location::file(&input.name).line(row.line)));
        }
    }
    Ok((t, pts))
}

fn run_fit(args: FitArgs) -> Result<()> {
    let started = Instant::now();
    let input = Input::open(&args.io.input)?;
    let (t, pts) = read_points(&input, args.machine.as_deref())?;
    // Every option is checked, used or not: a wrong one is never silently ignored.
    let huber_k = positive(args.huber_k, "--huber-k")?;
    let threshold = args.ransac_threshold.map(|t| positive_mm(t, "--ransac-threshold")).transpose()?;
    if !(args.confidence > 0.0 && args.confidence < 1.0) {
        return Err(Error::input(format!("--confidence must be between 0 and 1 (exclusive), got {}", args.confidence)));
    }
    if !(1..=MAX_HYPOTHESES).contains(&args.max_hypotheses) {
        return Err(Error::input(format!(
            "--max-hypotheses must be from 1 to {MAX_HYPOTHESES}, got {}",
            args.max_hypotheses
        )));
    }
    let opts = Options {
        max_amplification: positive(args.max_amplification, "--max-amplification")?,
        robust: match args.robust {
            RobustArg::None => Robust::None,
            RobustArg::Huber => Robust::Huber(huber_k),
            RobustArg::Ransac => Robust::Ransac(Ransac {
                threshold,
                confidence: args.confidence,
                seed: args.seed,
                max_hypotheses: args.max_hypotheses,
            }),
        },
    };
    let truth = args.truth.as_deref().map(read_shape).transpose()?;
    let kind = args.shape.kind();
    let fit_started = Instant::now();
    let result = surf_probe_fit::fit(kind, &pts, &opts);
    let fit_seconds = fit_started.elapsed().as_secs_f64();
    let f = result.map_err(|e| match e {
        FitError::Undetermined(m) => Error::input(m).at(Location::file(&input.name)),
        FitError::NotConverged(m) => Error::check(format!("{}: {m}", input.name)),
    })?;
    if let Some(w) = f.warning() {
        cli::warn(&w);
    }
    let doc =
        frame::frame_of(&f, format!("surf-probe-fit: {} fit of {} points from {}", kind.name(), pts.len(), input.name));
    let mut out = Output::new(args.io.output.as_deref());
    out.buf = serde_json::to_vec_pretty(&doc).map_err(|e| Error::runtime(e.to_string()))?;
    out.buf.push(b'\n');
    let mut report = Report::new("surf-probe-fit");
    report
        .set("command", "fit")
        .set("shape", kind.name())
        .set("points", pts.len())
        .set("rows", t.rows.len())
        .set("rms_mm", f.rms)
        .set("largest_residual_mm", f.largest_residual)
        .set("largest_residual_line", t.rows[f.largest_residual_index].line)
        .set("iterations", f.iterations)
        .set("parameters", &f.parameters)
        .set("poorly_determined", &f.poorly_determined)
        .set("frame", [doc.xc, doc.yc, doc.za]);
    if let Some(r) = &f.robust {
        report.set("robust", r);
        if r.method == "ransac" {
            let lines: Vec<u64> = r.outlier_indices.iter().take(OUTLIER_LINES).map(|&k| t.rows[k].line).collect();
            report
                .set("inliers", r.inliers)
                .set("outliers", r.outliers)
                .set("threshold_mm", r.threshold)
                .set("hypotheses", r.hypotheses)
                .set("outlier_lines", lines);
        }
    }
    if let Some((truth, path)) = truth.as_ref().zip(args.truth.as_deref()) {
        let errors =
            surf_probe_fit::truth::errors(&f.shape, truth).map_err(|m| Error::input(m).at(Location::file(path)))?;
        for (key, v) in errors {
            report.set(key, v);
        }
    }
    report.set("fit_seconds", fit_seconds).set("seconds", started.elapsed().as_secs_f64());
    let residuals = args.residuals.as_deref().map(|path| -> Result<Output> {
        let mut r = Output::new(Some(path));
        table::write(&mut r, &residual_table(t, &pts, &f), &WriteOptions::default())?;
        Ok(r)
    });
    let residuals = residuals.transpose()?;
    if let Some(path) = &args.io.report {
        report.write(path)?;
    }
    if let Some(r) = residuals {
        r.commit()?;
    }
    out.commit()
}

/// The input rows with the `residual` of each point from the fitted element and, for RANSAC, the
/// `outlier` flag.
fn residual_table(mut t: Table, pts: &[P3], f: &surf_probe_fit::Fit) -> Table {
    let r = t.add_extra_column("residual");
    let outliers = f.robust.as_ref().filter(|i| i.method == "ransac").map(|i| &i.outlier_indices);
    let o = outliers.map(|_| t.add_extra_column("outlier"));
    let mut flagged = vec![false; pts.len()];
    for &k in outliers.into_iter().flatten() {
        flagged[k] = true;
    }
    for ((row, p), out) in t.rows.iter_mut().zip(pts).zip(flagged) {
        row.extra[r] = format!("{:.*}", RESIDUAL_DECIMALS, f.shape.distance(p));
        if let Some(o) = o {
            row.extra[o] = if out { "1" } else { "0" }.into();
        }
    }
    t
}

/// Largest `--max-hypotheses` (the work bound of RANSAC: hypotheses × points distances).
const MAX_HYPOTHESES: usize = 1_000_000;

/// Decimals of the `residual` column (0.1 nm).
const RESIDUAL_DECIMALS: usize = 7;

/// Outlier lines named in the report (the first ones).
const OUTLIER_LINES: usize = 20;

fn pose_table(extra: &[&str]) -> Table {
    let mut t = Table {
        schema: Schema::of(&[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::I, Col::J, Col::K, Col::Tag]),
        rows: Vec::new(),
    };
    for name in extra {
        t.add_extra_column(name);
    }
    t
}

fn write_table(t: &Table, out: &OutArgs, report: &Report) -> Result<()> {
    let mut o = Output::new(out.output.as_deref());
    table::write(&mut o, t, &WriteOptions::default())?;
    if let Some(path) = &out.report {
        report.write(path)?;
    }
    o.commit()
}

fn run_raster(args: RasterArgs) -> Result<()> {
    let step = positive_mm(args.step, "--step")?;
    let (x0, x1, y0, y1) = match args.region {
        Some(r) => {
            for v in [r.x0, r.x1, r.y0, r.y1] {
                mm(v, "--region")?;
            }
            (r.x0, r.x1, r.y0, r.y1)
        }
        None => {
            if args.x.len() != 2 || args.y.len() != 2 {
                return Err(Error::input("--x and --y take two numbers: MIN,MAX"));
            }
            for (v, what) in args.x.iter().map(|v| (v, "--x")).chain(args.y.iter().map(|v| (v, "--y"))) {
                mm(*v, what)?;
            }
            if !(args.x[0] < args.x[1] && args.y[0] < args.y[1]) {
                return Err(Error::input("--x and --y must be ranges MIN,MAX with MIN < MAX"));
            }
            (args.x[0], args.x[1], args.y[0], args.y[1])
        }
    };
    mm(args.z, "--z")?;
    // Counted in floating point: the product of two huge counts must not wrap.
    let (fx, fy) = (((x1 - x0) / step).floor(), ((y1 - y0) / step).floor());
    args.limit.check((fx + 1.0) * (fy + 1.0), &format!("the raster of --region at --step {step}"))?;
    let (nx, ny) = (fx as usize, fy as usize);
    // Written row by row as made: the raster is never held.
    let t = pose_table(&[]);
    let mut out = Stream::new(args.out.output.as_deref())?;
    let mut w = RowWriter::new(&t.schema, WriteOptions::default());
    let mut row = Row::at(0, P3::origin());
    row.tag = "raster".into();
    for j in 0..=ny {
        let y = y0 + j as f64 * step;
        for k in 0..=nx {
            let i = if j % 2 == 0 { k } else { nx - k };
            row.path = j as i64;
            row.pos = P3::new(x0 + i as f64 * step, y, args.z);
            row.mv = if k == 0 { Move::Rapid } else { Move::Line };
            w.row(&mut out, &row)?;
        }
    }
    w.finish(&mut out)?;
    let mut report = Report::new("surf-probe-fit");
    report.set("command", "raster").set("poses", (nx + 1) * (ny + 1)).set("lines", ny + 1);
    if let Some(path) = &args.out.report {
        report.write(path)?;
    }
    out.commit()
}

fn run_simulate(args: SimulateArgs) -> Result<()> {
    let shape = read_shape(&args.shape)?;
    let s = &args.sensor;
    let sensor = Sensor {
        standoff: positive_mm(s.standoff, "--standoff")?,
        range: positive_mm(s.range, "--range")?,
        noise: within(s.noise, 0.0, MAX_MM, "--noise", " mm")?,
        slope_error: mm(s.slope_error, "--slope-error")?,
        max_incidence: within(positive(s.max_incidence, "--max-incidence")?, 0.0, 90.0, "--max-incidence", "°")?,
    };
    let input = Input::open(&args.io.input)?;
    let t = table::read(&input, &[Col::X, Col::Y])?;
    let (chain, cone) = table_chain(args.machine.as_deref())?;
    let poses: Vec<(P3, V3)> = t.rows.iter().map(|r| (r.pos, r.axis.normalize())).collect();
    let joints = records::joints_for(&chain, &poses, cone).map_err(|(i, e)| {
        Error::input(format!("pose cannot be reached: {}", e.0)).at(Location::file(&input.name).line(t.rows[i].line))
    })?;
    let rotaries: Vec<String> = chain.rotaries().iter().map(|r| r.address.to_ascii_lowercase().to_string()).collect();
    let mut names: Vec<&str> = rotaries.iter().map(String::as_str).collect();
    names.extend(["reading", "incidence"]);
    let mut out_t = Table { schema: Schema::of(&[Col::Path, Col::X, Col::Y, Col::Z]), rows: Vec::new() };
    for n in &names {
        out_t.add_extra_column(n);
    }
    let mut rng = Rng::new(args.seed);
    let (mut lost, mut worst) = (0usize, 0.0f64);
    for ((row, (tip, axis)), j) in t.rows.iter().zip(&poses).zip(&joints) {
        let Some(r) = sensor.read(&shape, tip, axis, &mut rng) else {
            lost += 1;
            continue;
        };
        worst = worst.max(r.incidence);
        let mut rec = Row::at(row.path, P3::from(j.xyz));
        rec.extra = j.rot[..rotaries.len()].iter().map(|a| a.to_string()).collect();
        rec.extra.push(r.value.to_string());
        rec.extra.push(format!("{:.3}", r.incidence));
        out_t.rows.push(rec);
    }
    if out_t.rows.is_empty() {
        return Err(Error::input("no pose returned a reading: the beam misses the element or is out of range")
            .at(Location::file(&input.name)));
    }
    if lost > 0 {
        cli::warn(&format!(
            "{lost} of {} poses returned no reading (missed, out of range or too oblique)",
            t.rows.len()
        ));
    }
    let mut report = Report::new("surf-probe-fit");
    report
        .set("command", "simulate")
        .set("poses", t.rows.len())
        .set("readings", out_t.rows.len())
        .set("lost", lost)
        .set("largest_incidence_deg", worst);
    write_table(&out_t, &OutArgs { output: args.io.output, report: args.io.report }, &report)
}

fn run_points(args: PointsArgs) -> Result<()> {
    let input = Input::open(&args.io.input)?;
    let t = table::read(&input, &[Col::X, Col::Y])?;
    let (chain, _) = table_chain(args.machine.as_deref())?;
    let recs = read_records(&t, &chain, &input.name)?;
    let mut out = Table { schema: Schema::of(&[Col::Path, Col::X, Col::Y, Col::Z]), rows: Vec::new() };
    for (row, r) in t.rows.iter().zip(&recs) {
        out.rows.push(Row::at(row.path, records::to_point(&chain, r)));
    }
    let mut report = Report::new("surf-probe-fit");
    report.set("command", "points").set("points", out.rows.len());
    write_table(&out, &OutArgs { output: args.io.output, report: args.io.report }, &report)
}

fn run_plan(args: PlanArgs) -> Result<()> {
    let standoff = positive_mm(args.standoff, "--standoff")?;
    within(args.max_slope, 0.0, 90.0, "--max-slope", "°")?;
    within(args.max_polar, 0.0, 180.0, "--max-polar", "°")?;
    within(positive(args.ring_step, "--ring-step")?, 0.0, 180.0, "--ring-step", "°")?;
    if args.every == 0 {
        return Err(Error::input("--every must be at least 1"));
    }
    let mut report = Report::new("surf-probe-fit");
    report.set("command", "plan");
    let probes: Vec<Probe> = if let Some(path) = &args.fit {
        let Shape::Sphere { centre, radius } = read_shape(path)? else {
            return Err(Error::input("--fit must hold a sphere").at(Location::file(path)));
        };
        let rings = (args.max_polar / args.ring_step).floor();
        let estimate = 1.0 + rings * (360.0 / args.ring_step + 1.0).max(3.0);
        args.limit
            .check(estimate, &format!("--ring-step {}° up to --max-polar {}°", args.ring_step, args.max_polar))?;
        report.set("from", "sphere");
        rough::plan_on_sphere(&P3::from(centre), radius, args.max_polar, args.ring_step)
    } else {
        let input = Input::open(&args.io.input)?;
        let t = table::read(&input, &[Col::X, Col::Y])?;
        let pts: Vec<P3> = t.rows.iter().map(|r| r.pos).collect();
        let paths: Vec<i64> = t.rows.iter().map(|r| r.path).collect();
        let surface =
            rough::triangulate(&pts, args.max_slope).map_err(|m| Error::input(m).at(Location::file(&input.name)))?;
        report.set("from", "rough surface").set("points", pts.len()).set("facets", surface.facets.len());
        rough::plan_from_surface(&pts, &paths, &surface, args.every)
    };
    let mut t = pose_table(&[]);
    t.schema.add(&[Col::Px, Col::Py, Col::Pz, Col::Nx, Col::Ny, Col::Nz]);
    // Each pose is its own pass, positioned by a rapid move: the sensor reads standing still, and
    // poses on either side of the top would otherwise make the table swing through C's singularity.
    for (k, p) in probes.iter().enumerate() {
        let mut row = Row::at(k as i64, p.tip(standoff));
        row.mv = Move::Rapid;
        row.axis = p.normal;
        row.contact = Some(p.point);
        row.normal = Some(p.normal);
        row.tag = "probe".into();
        t.rows.push(row);
    }
    let tilt = probes.iter().map(|p| p.normal.z.clamp(-1.0, 1.0).acos().to_degrees()).fold(0.0, f64::max);
    report.set("probes", probes.len()).set("largest_tilt_deg", tilt).set("standoff_mm", standoff);
    write_table(&t, &OutArgs { output: args.io.output, report: args.io.report }, &report)
}

fn run_reference(args: ReferenceArgs) -> Result<()> {
    if args.centre.len() != 3 || args.axis.len() != 3 {
        return Err(Error::input("--centre and --axis take three numbers: X,Y,Z"));
    }
    for v in &args.centre {
        mm(*v, "--centre")?;
    }
    for v in &args.axis {
        mm(*v, "--axis")?;
    }
    let c = [args.centre[0], args.centre[1], args.centre[2]];
    let a = V3::new(args.axis[0], args.axis[1], args.axis[2]);
    if a.norm() == 0.0 {
        return Err(Error::input("--axis must be a non-zero vector"));
    }
    let a: [f64; 3] = a.normalize().into();
    let r = positive_mm(args.radius, "--radius")?;
    let extent = match args.shape {
        ShapeArg::Sphere => within(args.extent, 0.0, 180.0, "--extent (a sphere's cap half-angle)", "°"),
        ShapeArg::Circle => within(args.extent, 0.0, 360.0, "--extent (a circle's arc)", "°"),
        ShapeArg::Plane | ShapeArg::Cylinder => mm(args.extent, "--extent"),
    };
    let extent = positive(extent?, "--extent")?;
    let amplitude = within(args.amplitude, 0.0, MAX_MM, "--amplitude", " mm")?;
    args.limit.check(args.points as f64, "--points")?;
    let shape = match args.shape {
        ShapeArg::Sphere => Shape::Sphere { centre: c, radius: r },
        ShapeArg::Plane => Shape::Plane { point: c, normal: a },
        ShapeArg::Circle => Shape::Circle { centre: c, normal: a, radius: r },
        ShapeArg::Cylinder => Shape::Cylinder { point: c, axis: a, radius: r },
    };
    let kind = args.shape.kind();
    if args.points < kind.parameters() + 1 {
        return Err(Error::input(format!("--points must be at least {}", kind.parameters() + 1)));
    }
    let set =
        reference::generate(&Spec { shape: shape.clone(), points: args.points, amplitude, extent, seed: args.seed });
    let mut t = Table { schema: Schema::of(&[Col::X, Col::Y, Col::Z]), rows: Vec::new() };
    t.rows.extend(set.points.iter().map(|p| Row::at(0, *p)));
    let mut report = Report::new("surf-probe-fit");
    report.set("command", "reference").set("truth", &shape).set("points", set.points.len());
    write_table(&t, &args.out, &report)
}
