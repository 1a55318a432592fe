//! `stylus-trace`: copy-simulation CL data on a defined model.

use camkit::cli::{self, IoArgs, positive};
use camkit::error::{Error, Location, Result};
use camkit::geom::P3;
use camkit::io::{Input, Output, write_atomic};
use camkit::model::Model;
use camkit::num::round_to;
use camkit::report::Report;
use camkit::svg::relief;
use camkit::table::{self, Col, WriteOptions};
use clap::{Parser, ValueEnum};
use std::path::PathBuf;
use std::time::Instant;
use stylus_trace::budget::{self, Budget};
use stylus_trace::coverage::{self, Coverage, Tolerances};
use stylus_trace::curve::{Steps, Stylus};
use stylus_trace::scan::Scan;
use stylus_trace::two_surface::TwoSurface;
use stylus_trace::{Mode, Options, Region, output};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum ModeArg {
    /// Scanning lines: vertical motion planes along --angle, --pick apart.
    Scan,
    /// Contour lines: motion plane z = const at each level.
    Contour,
    /// Two-surface contact: the stylus touches --surfaces A and B at once.
    TwoSurface,
}

#[derive(Parser, Debug)]
#[command(
    name = "stylus-trace",
    version,
    allow_negative_numbers = true,
    about = "Copy simulation: a virtual stylus traces a defined model and yields CL data with no offset surface.",
    long_about = "Copy simulation (paper 000 §3.1-3.2): a virtual stylus, a sphere of radius r, traces a defined \
model (a model JSON document, an STL file or a STEP file's trimmed faces). L runs from the nearest point of the whole model to the stylus centre; \
ΔR = (r − |L|)·L/|L| is corrected inside the motion plane until |ΔR| ≤ --contact-tol, then the stylus steps on, \
each step as long as keeps the chord within --chord-tol of the true CL curve. Every CL point is measured again \
against the whole model before anything is written: no point is closer than r − --contact-tol to any part of it.",
    after_help = after_help()
)]
pub(crate) struct Args {
    #[command(flatten)]
    io: IoArgs,
    /// Mode.
    #[arg(long, value_enum, default_value_t = ModeArg::Scan)]
    mode: ModeArg,
    /// Stylus radius r (mm); or give --tool.
    #[arg(short = 'r', long, value_name = "MM", required_unless_present = "tool", conflicts_with = "tool")]
    radius: Option<f64>,
    /// Fixed-axis cutter mode: the tool document (JSON, kind flat, ball, bull or cone) whose cutter
    /// is dropped exactly onto the model along --axis at points --max-step apart on the scan
    /// lines; writes tool tips, the axis in i,j,k, the contact and the normal.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["svg", "levels", "z_step", "surfaces", "start"])]
    tool: Option<String>,
    /// The fixed tool axis I,J,K with --tool (normalised; default 0,0,1). --region, --angle and
    /// --pick are in the plane across it (the model's x,y turned by the shortest rotation taking
    /// the axis to +z).
    #[arg(long, value_name = "I,J,K", allow_hyphen_values = true, requires = "tool")]
    axis: Option<String>,
    /// Region in XY as X0,X1,Y0,Y1 (mm); default: the model's bounding box.
    #[arg(long, value_name = "X0,X1,Y0,Y1", allow_hyphen_values = true, value_parser = cli::region)]
    region: Option<Region>,
    /// Scan direction, degrees from +x towards +y.
    #[arg(long, default_value_t = 0.0, value_name = "DEG")]
    angle: f64,
    /// Pick feed between scan lines (mm).
    #[arg(long, default_value_t = 1.0, value_name = "MM")]
    pick: f64,
    /// Scan alternate lines in opposite directions (default one-way).
    #[arg(long)]
    zigzag: bool,
    /// Contour levels: heights of the stylus centre, Z1,Z2,... (mm).
    #[arg(long, value_name = "Z,..", allow_hyphen_values = true)]
    levels: Option<String>,
    /// Contour levels every MM from the top of the model down (centre heights).
    #[arg(long, value_name = "MM")]
    z_step: Option<f64>,
    /// Two-surface mode: surfaces A,B by name or index (default: the model's two surfaces).
    #[arg(long, value_name = "A,B")]
    surfaces: Option<String>,
    /// Two-surface mode: a stylus centre X,Y,Z near the concave line to start from.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    start: Option<String>,
    /// Trace contours and the concave line the other way round.
    #[arg(long)]
    reverse: bool,
    /// Largest distance between a chord of consecutive CL points and the true CL curve (mm).
    #[arg(long, default_value_t = 0.001, value_name = "MM")]
    chord_tol: f64,
    /// Contact tolerance: largest |ΔR| left at a CL point (mm).
    #[arg(long, default_value_t = 1e-4, value_name = "MM")]
    contact_tol: f64,
    /// Longest step between CL points (mm).
    #[arg(long, default_value_t = 2.0, value_name = "MM")]
    max_step: f64,
    /// Shortest step (mm): where the stylus cannot go on with it, the run fails.
    #[arg(long, default_value_t = 1e-4, value_name = "MM")]
    min_step: f64,
    /// Fixed decimals for positions (default: exact shortest round-trip numbers).
    #[arg(long, value_name = "N")]
    decimals: Option<u32>,
    /// Write an SVG of the traced stylus centres: isometric, top and side views coloured by height
    /// (thinned to the picture's resolution).
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// Worker threads (default: all cores, at most 256); the output is the same for any number.
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Refuse an STL file with zero-area or repeated facets (default: they are left out, with a warning).
    #[arg(long)]
    strict: bool,
    /// A STEP model's faces on surfaces or edges the reader does not take are left out, with a
    /// warning each (default: the first is refused, naming the entity and its #id).
    #[arg(long)]
    skip_unsupported: bool,
    /// Largest memory (MB: CL points, their rows, the scan lines), estimated before the run; more is refused.
    #[arg(long, default_value_t = budget::DEFAULT_MEMORY_MB, value_name = "MB")]
    max_memory: u64,
    /// Largest work in CL points and stylus drops (a few µs each; ×50 on B-spline surfaces), estimated before the run; more is refused.
    #[arg(long, default_value_t = budget::DEFAULT_POINTS, value_name = "N")]
    max_points: f64,
}

fn after_help() -> String {
    let mut s = String::from(
        "Input: a model JSON document (docs/formats.md, `model`), an STL file (binary or ASCII), or a STEP file\n\
(.step/.stp, AP203/AP214/AP242 B-rep: planes, cylinders, cones, spheres, tori and B-spline surfaces, exact and\n\
trimmed by their edges).\n\n",
    );
    s.push_str(&table::columns::help_text(
        &[],
        &[Col::Path, Col::X, Col::Y, Col::Z, Col::Px, Col::Py, Col::Pz, Col::Nx, Col::Ny, Col::Nz, Col::Tag],
    ));
    s.push_str("  surface                   name of the model surface touched\n");
    s.push_str("two-surface mode adds p2x,p2y,p2z n2x,n2y,n2z surface2 (second contact) and bx,by,bz (bisector).\n");
    s.push_str("  point, stylus_radius     `stylus-centre` and r: what x,y,z is (tool-attitude turns it into tips)\n");
    s.push_str("x,y,z is the stylus centre; nx,ny,nz is L/|L|, from the contact towards the centre.\n");
    s.push_str(
        "\nWith --tool (fixed-axis cutter, scan mode only): x,y,z the tool tip, i,j,k the axis, px,py,pz the\n\
         contact, nx,ny,nz the model's unit normal there, tag `drop`, surface, point `tip`. The drop is exact\n\
         on STL meshes (facet, vertex and edge tests; the bull-nose edge within 1e-10 mm), planes,\n\
         spheres and cylinders across the axis (endless) or along it (the upper rim), tori and cones\n\
         along it; on B-spline patches, trimmed STEP faces and every other analytic surface to 1e-9 mm\n\
         (a branch-and-bound over exact rational Bezier pieces; docs/formats.md). Planes along the axis\n\
         and endless cylinders along it (no top) are refused.\n",
    );
    s.push_str(
        "\nScan mode checks every line against an independent drop of the stylus: a stretch with the model under it\n\
         that no pass covers (longer than --chord-tol) or a CL point below the stylus's upper envelope (deeper than\n\
         --contact-tol plus the rounding) is named on stderr; the output is written and the exit status is 1.\n",
    );
    s.push_str("\nExit status: 0 done, 1 a check failed (no convergence, |ΔR| over tolerance, coverage), 2 bad input or usage.");
    s
}

mod fixed;

fn main() -> std::process::ExitCode {
    cli::run("stylus-trace", || run(cli::parse::<Args>()?))
}

pub(crate) fn usage(message: impl Into<String>) -> Error {
    Error::input(message)
}

/// Comma-separated finite numbers, exactly `n` of them when `n` is given.
pub(crate) fn numbers(text: &str, what: &str, n: Option<usize>) -> Result<Vec<f64>> {
    let v: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| usage(format!("{what} must be comma-separated numbers, got {text:?}")))?;
    if n.is_some_and(|n| v.len() != n) || v.is_empty() {
        return Err(usage(format!("{what} needs {} numbers, got {text:?}", n.unwrap_or(1))));
    }
    Ok(v)
}

fn region(args: &Args, model: &Model, contact_tol: f64) -> Result<Region> {
    if let Some(r) = args.region {
        budget::check_round_off(&[r.x0, r.x1, r.y0, r.y1], contact_tol, "--region")?;
        return Ok(r);
    }
    let b = model.bounds();
    if !b.is_bounded() {
        return Err(usage("the model is unbounded (a plane or an endless cylinder): give --region X0,X1,Y0,Y1"));
    }
    Ok(Region { x0: b.min.x, x1: b.max.x, y0: b.min.y, y1: b.max.y })
}

/// Most worker threads: more only cost memory (a stack each).
const MAX_THREADS: usize = 256;

fn options(args: &Args, model: &Model, input: &Input) -> Result<Options> {
    let radius = positive(args.radius.unwrap_or(f64::NAN), "--radius")?;
    let stylus = Stylus { radius, contact_tol: positive(args.contact_tol, "--contact-tol")? };
    budget::check_round_off(&[radius], stylus.contact_tol, "--radius")?;
    let steps = Steps {
        chord_tol: positive(args.chord_tol, "--chord-tol")?,
        max_step: positive(args.max_step, "--max-step")?,
        min_step: positive(args.min_step, "--min-step")?,
    };
    if steps.min_step >= steps.max_step {
        return Err(usage("--min-step must be below --max-step"));
    }
    let bounds = Budget {
        memory: args.max_memory.saturating_mul(1_000_000) as f64,
        points: positive(args.max_points, "--max-points")?,
        weight: model.query_weight(),
    };
    let region = region(args, model, stylus.contact_tol)?;
    let b = model.bounds();
    let misses = || {
        Error::input(format!(
            "the region x {}..{}, y {}..{} misses the model (x {}..{}, y {}..{})",
            region.x0, region.x1, region.y0, region.y1, b.min.x, b.max.x, b.min.y, b.max.y
        ))
        .at(Location::file(&input.name))
    };
    let Some(area) = budget::traced_area(&region, &b, radius) else {
        return Err(misses());
    };
    // The stylus centre's heights: over the model's top down to its bottom.
    let heights = if b.is_bounded() { [b.min.z - radius, b.max.z + radius + 1.0] } else { [0.0, 0.0] };
    let source = if args.region.is_some() { "--region" } else { "the model's bounding box (the default --region)" };
    budget::check_round_off(
        &[area.x0, area.x1, area.y0, area.y1, heights[0], heights[1]],
        stylus.contact_tol,
        &format!("{}: the area traced within {source}", input.name),
    )?;
    budget::check_min_step(steps.min_step, &[area.x0, area.x1, area.y0, area.y1, heights[0], heights[1]])?;
    let within = format!("x {}..{}, y {}..{}", area.x0, area.x1, area.y0, area.y1);
    let mode = match args.mode {
        ModeArg::Scan => {
            if !(args.angle.is_finite() && args.angle.abs() <= 360.0) {
                return Err(usage(format!("--angle must be a number of degrees from -360 to 360, got {}", args.angle)));
            }
            let pick = positive(args.pick, "--pick")?;
            let lines = budget::scan_lines(&region, args.angle, pick);
            budget::scan(lines, &region, &area, heights[1] - heights[0], args.angle, pick, &stylus, &steps).check(
                &bounds,
                &format!(
                    "scan mode at --pick {pick} ({lines:.3e} lines) over {within} (--region, --chord-tol, --max-step)"
                ),
            )?;
            Mode::Scan(Scan { region, angle: args.angle, pick, zigzag: args.zigzag })
        }
        ModeArg::Contour => {
            let levels = match (&args.levels, args.z_step) {
                (Some(text), None) => {
                    let levels = numbers(text, "--levels", None)?;
                    budget::check_round_off(&levels, stylus.contact_tol, "--levels")?;
                    levels
                }
                (None, Some(dz)) => {
                    let dz = positive(dz, "--z-step")?;
                    if !b.is_bounded() {
                        return Err(usage("--z-step needs a bounded model: give --levels"));
                    }
                    // Counted before any is made: a tiny step would make billions.
                    let count = ((b.max.z - b.min.z) / dz).floor() + 1.0;
                    budget::contour(count, &region, &area, &stylus, &steps)
                        .check(&bounds, &format!("contour mode at --z-step {dz} ({count:.3e} levels) over {within}"))?;
                    // From just below the top of the centre's range down to the model's bottom.
                    let top = b.max.z + radius;
                    let n = count as usize - 1;
                    (1..=n + 1).map(|k| top - k as f64 * dz).filter(|z| *z >= b.min.z).collect()
                }
                (Some(_), Some(_)) => return Err(usage("give either --levels or --z-step, not both")),
                (None, None) => return Err(usage("contour mode needs --levels Z1,Z2,.. or --z-step MM")),
            };
            if levels.is_empty() {
                return Err(usage("no contour level lies within the model's height"));
            }
            budget::contour(levels.len() as f64, &region, &area, &stylus, &steps).check(
                &bounds,
                &format!("contour mode at {} levels over {within} (--levels, --chord-tol, --max-step)", levels.len()),
            )?;
            Mode::Contour { region, levels }
        }
        ModeArg::TwoSurface => {
            let surfaces = match &args.surfaces {
                Some(text) => {
                    let names: Vec<&str> = text.split(',').map(str::trim).collect();
                    if names.len() != 2 {
                        return Err(usage(format!("--surfaces needs two surfaces A,B, got {text:?}")));
                    }
                    let find = |n: &str| {
                        model.surface_index(n).ok_or_else(|| {
                            let known: Vec<&str> = model.surfaces.iter().map(|s| s.name.as_str()).collect();
                            usage(format!("--surfaces: no surface {n:?} in the model (it has {})", known.join(", ")))
                        })
                    };
                    [find(names[0])?, find(names[1])?]
                }
                None if model.surfaces.len() == 2 => [0, 1],
                None => {
                    return Err(usage("two-surface mode needs --surfaces A,B (the model has more or fewer than two)"));
                }
            };
            if surfaces[0] == surfaces[1] {
                return Err(usage("--surfaces must name two different surfaces"));
            }
            let start = match &args.start {
                Some(text) => {
                    let v = numbers(text, "--start", Some(3))?;
                    budget::check_round_off(&v, stylus.contact_tol, "--start")?;
                    Some(P3::new(v[0], v[1], v[2]))
                }
                None => None,
            };
            budget::two_surface(&area, heights[1] - heights[0], &steps)
                .check(&bounds, &format!("two-surface mode over {within} (--chord-tol, --max-step)"))?;
            Mode::TwoSurface(TwoSurface { surfaces, start, reverse: args.reverse, region })
        }
    };
    Ok(Options { stylus, steps, mode })
}

fn run(args: Args) -> Result<()> {
    if let Some(n) = args.threads {
        if n == 0 || n > MAX_THREADS {
            return Err(usage(format!("--threads must be from 1 to {MAX_THREADS}, got {n}")));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| Error::runtime(format!("cannot start {n} threads: {e}")))?;
    }
    if args.decimals.is_some_and(|d| d > 12) {
        return Err(usage("--decimals must be at most 12"));
    }
    let started = Instant::now();
    let input = Input::open(&args.io.input)?;
    let model = Model::load_with(&input, args.skip_unsupported)?;
    model.check_dropped(args.strict)?;
    let loaded = started.elapsed().as_secs_f64();
    if let Some(tool) = &args.tool {
        return fixed::run(&args, tool, &model, &input, started, loaded);
    }
    let opts = options(&args, &model, &input)?;
    let progress = args.io.progress(opts.mode.units() as u64, opts.mode.tag());
    let traced_at = Instant::now();
    let paths = stylus_trace::trace(&model, &opts, &|| progress.inc(1))
        .map_err(|f| Error::check(format!("the stylus stopped at ({}, {}, {}): {}", f.at.x, f.at.y, f.at.z, f.what)))?;
    progress.finish();
    let trace_seconds = traced_at.elapsed().as_secs_f64();
    if paths.is_empty() {
        return Err(Error::input(
            "the stylus touched the model nowhere in the region: the scan region misses the model",
        )
        .at(Location::file(&input.name)));
    }
    let two = match &opts.mode {
        Mode::TwoSurface(ts) => Some(ts.surfaces),
        _ => None,
    };
    let verified = stylus_trace::verify(&model, &opts.stylus, &paths, two).map_err(|rej| {
        Error::check(format!("CL point in row {} (line {} of the output): {}", rej.row + 1, rej.row + 2, rej.what))
    })?;
    let coverage = match &opts.mode {
        Mode::Scan(scan) => Some(check_coverage(&model, &opts, scan, &paths, args.decimals)),
        _ => None,
    };
    let interrupted = paths.iter().filter(|p| p.interrupted).count();
    if interrupted > 0 {
        cli::warn(&format!(
            "{interrupted} passes end where neither copying nor drops could follow the envelope (a jump); the next pass starts --chord-tol/2 on"
        ));
    }
    let tag = opts.mode.tag();
    let t = output::table(&model, &paths, tag, two.is_some(), opts.stylus.radius);
    let mut out = Output::new(args.io.output.as_deref());
    table::write(&mut out, &t, &WriteOptions { decimals: args.decimals })?;
    let seconds = started.elapsed().as_secs_f64();
    if let Some(path) = &args.svg {
        let title = format!(
            "{}: {} mode, r = {} mm, {} passes, {} CL points",
            input.name,
            tag,
            opts.stylus.radius,
            paths.len(),
            verified.points
        );
        let centres = paths.iter().flat_map(|p| p.points.iter().map(|q| &q.centre));
        let under = relief::grid_under(&model, centres);
        write_atomic(path, output::plot(&paths, &title, &under).to_svg(1200.0).as_bytes())?;
    }
    if let Some(path) = &args.io.report {
        let iterations: Vec<u32> = paths.iter().flat_map(|p| p.points.iter().map(|q| q.iterations)).collect();
        let mut r = Report::new("stylus-trace");
        r.set("mode", tag)
            .set("radius_mm", opts.stylus.radius)
            .set("contact_tol_mm", opts.stylus.contact_tol)
            .set("chord_tol_mm", opts.steps.chord_tol)
            .set("surfaces", model.surfaces.len())
            .set("triangles", model.triangles())
            .set("degenerate_facets_dropped", model.dropped_counts().0)
            .set("duplicate_facets_dropped", model.dropped_counts().1)
            .set("units", opts.mode.units())
            .set("paths", paths.len())
            .set("interrupted_passes", interrupted)
            .set("points", verified.points)
            .set(
                "newton_iterations_mean",
                iterations.iter().map(|&i| i as f64).sum::<f64>() / iterations.len().max(1) as f64,
            )
            .set("newton_iterations_max", iterations.iter().copied().max().unwrap_or(0))
            .set("largest_residual_mm", verified.largest_residual)
            .set("min_clearance_mm", verified.min_clearance)
            .set("largest_chord_deviation_mm", paths.iter().map(|p| p.deviation).fold(0.0, f64::max))
            .set("load_seconds", loaded)
            .set("trace_seconds", trace_seconds)
            .set("seconds", seconds)
            .set("points_per_second", verified.points as f64 / trace_seconds.max(1e-9))
            .set("threads", rayon::current_num_threads());
        if let Some((c, tol)) = &coverage {
            r.set("coverage_lines", c.lines)
                .set("coverage_drops", c.drops)
                .set("coverage_gap_tol_mm", tol.gap)
                .set("largest_coverage_gap_mm", c.largest_gap)
                .set("envelope_tol_mm", tol.below)
                .set("points_below_envelope", c.points_below)
                .set("largest_below_envelope_mm", c.largest_below)
                .set("chord_tol_below_envelope_mm", tol.chord)
                .set("chord_samples", c.chord_samples)
                .set("chord_samples_below_envelope", c.chords_below)
                .set("largest_chord_below_envelope_mm", c.largest_chord_below)
                .set("lines_not_covered", lines_failing(c));
        }
        r.write(path)?;
    }
    out.commit()?;
    match &coverage {
        Some((c, _)) if !c.defects.is_empty() => Err(Error::check(format!(
            "{} of {} scan lines fail the coverage check (largest gap {:.4} mm, {} points below the envelope by up to {:.4} mm, chords at {} positions by up to {:.4} mm)",
            lines_failing(c),
            c.lines,
            c.largest_gap,
            c.points_below,
            c.largest_below,
            c.chords_below,
            c.largest_chord_below
        ))),
        _ => Ok(()),
    }
}

/// Number of scan lines with a defect.
fn lines_failing(c: &Coverage) -> usize {
    let mut lines: Vec<usize> = c.defects.iter().map(|d| d.line).collect();
    lines.dedup();
    lines.len()
}

/// Most defects named one by one on stderr.
const SHOWN_DEFECTS: usize = 20;

/// The coverage check of scan mode on what is written (positions rounded to `decimals`); every
/// failing stretch is warned about with its line and range.
fn check_coverage(
    model: &Model,
    opts: &Options,
    scan: &Scan,
    paths: &[stylus_trace::TracedPath],
    decimals: Option<u32>,
) -> (Coverage, Tolerances) {
    let unit = decimals.map_or(0.0, |d| 10f64.powi(-(d as i32)));
    let tol = Tolerances {
        // Rounding moves each end of a hole by up to half a unit.
        gap: opts.steps.chord_tol + unit,
        below: opts.stylus.contact_tol + unit,
        chord: opts.steps.chord_tol + opts.stylus.contact_tol + unit,
        spacing: stylus_trace::scan::sample_spacing(&opts.stylus, &opts.steps),
    };
    let round = |v: f64| decimals.map_or(v, |d| round_to(v, d));
    let c = coverage::check(model, opts.stylus.radius, scan, paths, &tol, &round);
    for d in c.defects.iter().take(SHOWN_DEFECTS) {
        cli::warn(&format!(
            "scan line {} from ({}, {}) to ({}, {}): {}",
            d.line + 1,
            round_to(d.from.x, 3),
            round_to(d.from.y, 3),
            round_to(d.to.x, 3),
            round_to(d.to.y, 3),
            d.what
        ));
    }
    if c.defects.len() > SHOWN_DEFECTS {
        cli::warn(&format!("{} more stretches fail the coverage check", c.defects.len() - SHOWN_DEFECTS));
    }
    (c, tol)
}
