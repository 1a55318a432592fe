//! `rough-sim`: the surface a ball end mill leaves (paper 003), as height maps and figures.

use camkit::cli::{self, IoArgs};
use camkit::doc::Tool;
use camkit::error::{Error, Location, Result};
use camkit::io::{Input, Output, write_atomic};
use camkit::report::Report;
use camkit::table::{self, Col};
use clap::{Args, Parser, Subcommand, ValueEnum};
use rough_sim::budget::{self, Budget, Need};
use rough_sim::cutter::{Cutter, Rotation};
use rough_sim::patch::{Conditions, DEFAULT_MEMORY, Grid, simulate};
use rough_sim::render::Series;
use rough_sim::study::{self, CellFigures};
use rough_sim::{brute, flat, render, zmap};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(
    name = "rough-sim",
    version,
    about = "Geometric simulation of the surface a ball end mill leaves: cusp, feed scallop, uncut remainder at the rotation centre (paper 003).",
    long_about = "Geometric simulation of the surface a ball end mill leaves (paper 003, eq. 1–7). Every flute is a \
meridian of the ball turning with the spindle while the tool feeds; the machined surface is the lower envelope of all edge \
points, computed exactly at every grid node (root finding on monotone pieces, error ≈1e-9 µm at the nodes). Heights are in \
mm above the tool's lowest point (the nominal surface); figures in reports are in µm.",
    after_help = "Exit status: 0 done, 1 a check failed, 2 bad input or usage."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// The paper's surface (straight passes along +y, pick feed in x) on a grid: CSV x,y,h.
    #[command(allow_negative_numbers = true)]
    Patch(PatchArgs),
    /// Figures against feed per tooth, tilt or spindle speed, for one or more radii: CSV table.
    #[command(allow_negative_numbers = true)]
    Sweep(SweepArgs),
    /// The flat tip of eq. 6–7 (r_M, r_N, r0, δ) and, with --simulate, the simulation's own r0.
    #[command(allow_negative_numbers = true)]
    FlatTip(FlatArgs),
    /// The surface left by a toolpath table (3- or 5-axis) on a z-map: CSV x,y,z.
    #[command(allow_negative_numbers = true)]
    Zmap(ZmapArgs),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Lean {
    /// Shank toward +x (eq. 3 as printed with ζ > 0): the tip's trace moves to −x.
    PlusX,
    /// Shank toward −x: the tip's trace moves to +x.
    MinusX,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Sense {
    /// Counter-clockwise seen from the shank (eq. 1).
    Ccw,
    /// Clockwise.
    Cw,
}

/// Cutting conditions shared by patch, sweep and flat-tip.
#[derive(Args, Debug, Clone)]
struct CondArgs {
    /// Tool document (JSON: kind ball, radius, flutes, tip_flat_radius).
    #[arg(value_name = "TOOL")]
    tool: String,
    /// Number of flutes (overrides the document).
    #[arg(long)]
    flutes: Option<u32>,
    /// Tool radius in mm (overrides the document).
    #[arg(long, value_name = "MM")]
    radius: Option<f64>,
    /// Tip flat radius r0 in mm (overrides the document).
    #[arg(long, value_name = "MM")]
    flat_radius: Option<f64>,
    /// Pick feed f (mm).
    #[arg(long, value_name = "MM")]
    pick: f64,
    /// Feed per tooth (mm); or give --feed and --spindle.
    #[arg(long, value_name = "MM")]
    feed_per_tooth: Option<f64>,
    /// Feed F (mm/min), with --spindle.
    #[arg(long, value_name = "MM/MIN")]
    feed: Option<f64>,
    /// Spindle speed N (rpm), with --feed.
    #[arg(long, value_name = "RPM")]
    spindle: Option<f64>,
    /// Tilt ζ of the tool axis from the surface normal, toward the pick direction (degrees, 0 ≤ ζ < 90).
    #[arg(long, default_value_t = 0.0, value_name = "DEG")]
    tilt: f64,
    /// Side the shank leans to.
    #[arg(long, value_enum, default_value_t = Lean::PlusX)]
    lean: Lean,
    /// Sense of rotation seen from the shank.
    #[arg(long, value_enum, default_value_t = Sense::Ccw)]
    rotation: Sense,
    /// Spindle angle of flute 1 at y = 0 advances by this from one pass to the next (degrees).
    #[arg(long, default_value_t = 0.0, value_name = "DEG")]
    pass_phase: f64,
    /// Grid step (mm).
    #[arg(long, default_value_t = 0.002, value_name = "MM")]
    step: f64,
    /// Largest memory (MB: heights and the passes' tracks), estimated before the run; more is refused.
    #[arg(long, default_value_t = DEFAULT_MEMORY / 1_000_000, value_name = "MB")]
    max_memory: u64,
    /// Largest work, in exact edge evaluations (about 1 µs each); larger runs are refused.
    #[arg(long, default_value_t = budget::DEFAULT_WORK, value_name = "N")]
    max_work: f64,
    /// No progress bars, even on a terminal (they never appear in a pipe or a file).
    #[arg(short = 'q', long)]
    quiet: bool,
}

#[derive(Args, Debug)]
struct PatchArgs {
    #[command(flatten)]
    cond: CondArgs,
    /// Write the height map CSV here (default: standard output).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
    /// Write the run's figures as JSON.
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
    /// Patch size across the passes, in pick feeds (one periodic cell by default).
    #[arg(long, default_value_t = 1.0, value_name = "N")]
    picks: f64,
    /// Patch size along the feed, in feeds per tooth.
    #[arg(long, default_value_t = 1.0, value_name = "N")]
    teeth: f64,
    /// Patch size across and along as mm (overrides --picks/--teeth), centred on pass 0.
    #[arg(long, value_name = "MM")]
    size: Option<f64>,
    /// Write an SVG colour map of the heights in mm (colour bar in mm; roughness figures in µm in
    /// the title).
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// Write the cross-feed profile through the highest point and the feed profile through it (CSV).
    #[arg(long, value_name = "FILE")]
    profiles: Option<PathBuf>,
    /// Check against dense brute-force sampling of edge points (slow): fail if any lies below the surface by more than 0.1 µm.
    #[arg(long)]
    verify: bool,
    /// Spacing of the brute-force samples (mm, along the edge and between spindle angles).
    #[arg(long, default_value_t = 0.004, value_name = "MM")]
    verify_spacing: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Vary {
    /// Feed per tooth (mm).
    FeedPerTooth,
    /// Tilt (degrees).
    Tilt,
    /// Spindle speed (rpm) at constant --feed.
    Spindle,
    /// Pass phase (degrees).
    PassPhase,
}

#[derive(Args, Debug)]
struct SweepArgs {
    #[command(flatten)]
    cond: CondArgs,
    /// The swept quantity.
    #[arg(long, value_enum)]
    vary: Vary,
    /// Values, comma separated.
    #[arg(long, value_delimiter = ',', num_args = 1.., required = true)]
    values: Vec<f64>,
    /// Tool radii (mm), comma separated (default: the tool's).
    #[arg(long, value_delimiter = ',')]
    radii: Vec<f64>,
    /// Write the table here (default: standard output).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
    /// Write a plot of the simulated highest point and the classic one against the swept quantity.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// Write the run's figures as JSON.
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
}

#[derive(Args, Debug)]
struct FlatArgs {
    #[command(flatten)]
    cond: CondArgs,
    /// Also find the smallest flat the simulation needs, and simulate the tool with eq. 7's r0.
    #[arg(long)]
    simulate: bool,
    /// Write the table here (default: standard output).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
    /// Write the run's figures as JSON.
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
}

#[derive(Args, Debug)]
struct ZmapArgs {
    #[command(flatten)]
    io: IoArgs,
    /// Tool document (JSON).
    #[arg(long, value_name = "FILE")]
    tool: String,
    /// Number of flutes (overrides the document).
    #[arg(long)]
    flutes: Option<u32>,
    /// Spindle speed N (rpm).
    #[arg(long, value_name = "RPM")]
    spindle: f64,
    /// Feed (mm/min) where the table has no f.
    #[arg(long, value_name = "MM/MIN")]
    feed: Option<f64>,
    /// Sense of rotation seen from the shank.
    #[arg(long, value_enum, default_value_t = Sense::Ccw)]
    rotation: Sense,
    /// Grid step (mm).
    #[arg(long, default_value_t = 0.01, value_name = "MM")]
    step: f64,
    /// Region in XY as X0,X1,Y0,Y1 (mm), as every filter spells it; default: all the tool can reach.
    #[arg(long, allow_hyphen_values = true, value_name = "X0,X1,Y0,Y1", value_parser = cli::region)]
    region: Option<camkit::geom::Region>,
    /// The old spelling X0,Y0,X1,Y1 (corners), read with a warning: use --region.
    #[arg(long, allow_hyphen_values = true, value_name = "X0,Y0,X1,Y1", hide = true, conflicts_with = "region")]
    area: Option<String>,
    /// Largest memory (MB: heights and moves), estimated before the run; more is refused.
    #[arg(long, default_value_t = DEFAULT_MEMORY / 1_000_000, value_name = "MB")]
    max_memory: u64,
    /// Largest work, in exact edge evaluations (about 1 µs each); larger runs are refused.
    #[arg(long, default_value_t = budget::DEFAULT_WORK, value_name = "N")]
    max_work: f64,
    /// Write an SVG colour map of the z-map in mm (colour bar in mm).
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
}

/// Resolution (mm) of the simulated flat radius of `flat-tip --simulate`.
const FLAT_RESOLUTION: f64 = 1e-3;

fn main() -> ExitCode {
    cli::run("rough-sim", || match cli::parse::<Cli>()?.command {
        Command::Patch(a) => patch(a),
        Command::Sweep(a) => sweep(a),
        Command::FlatTip(a) => flat_tip(a),
        Command::Zmap(a) => zmap_cmd(a),
    })
}

fn positive(v: f64, what: &str) -> Result<f64> {
    if v.is_finite() && v > 0.0 { Ok(v) } else { Err(Error::input(format!("{what} must be positive, got {v}"))) }
}

/// The bounds of `--max-memory` (MB) and `--max-work`.
fn budget_of(max_memory: u64, max_work: f64) -> Result<Budget> {
    Ok(Budget { memory: max_memory.saturating_mul(1_000_000) as f64, work: positive(max_work, "--max-work")? })
}

/// The cutter and conditions of the arguments.
fn conditions(a: &CondArgs) -> Result<(Conditions, Option<(f64, f64)>)> {
    let input = Input::open(&a.tool)?;
    let mut doc: Tool = camkit::json::from_input(&input)?;
    if let Some(r) = a.radius {
        doc.radius = r;
    }
    if let Some(r0) = a.flat_radius {
        doc.tip_flat_radius = r0;
    }
    if a.flutes == Some(0) {
        return Err(Error::input("--flutes must be at least 1, got 0"));
    }
    doc.validate(&input.name).map_err(|e| camkit::json::at_value(&input, e))?;
    let mut cutter = Cutter::from_tool(&doc, &input.name, a.flutes).map_err(|e| camkit::json::at_value(&input, e))?;
    budget::check_radius(cutter.radius, if a.radius.is_some() { "--radius" } else { &input.name })?;
    cutter.rotation = if a.rotation == Sense::Ccw { Rotation::Ccw } else { Rotation::Cw };
    let (fz, speeds) = match (a.feed_per_tooth, a.feed, a.spindle) {
        (Some(fz), None, None) => (positive(fz, "--feed-per-tooth")?, None),
        (None, Some(f), Some(n)) => {
            let (f, n) = (positive(f, "--feed")?, positive(n, "--spindle")?);
            (f / (n * cutter.flutes as f64), Some((f, n)))
        }
        _ => return Err(Error::input("give --feed-per-tooth, or --feed and --spindle")),
    };
    if !(a.tilt.is_finite() && (0.0..90.0).contains(&a.tilt)) {
        return Err(Error::input(format!("--tilt must be in [0°, 90°), got {}°", a.tilt)));
    }
    let cond = Conditions {
        cutter,
        pick: a.pick,
        feed_per_tooth: fz,
        tilt: a.tilt.to_radians(),
        lean: if a.lean == Lean::PlusX { 1.0 } else { -1.0 },
        pass_phase: a.pass_phase.to_radians(),
    };
    cond.validate()?;
    positive(a.step, "--step")?;
    Ok((cond, speeds))
}

fn um(v: f64) -> f64 {
    (v * 1e7).round() / 1e4
}

fn set_figures(r: &mut Report, c: &CellFigures) {
    let m = &c.map;
    r.set("cusp_classic_um", um(c.cusp_classic))
        .set("cusp_exact_um", um(c.cusp_exact))
        .set("classic_peak_um", um(c.classic_peak))
        .set("max_height_um", um(m.max_height))
        .set("max_at_mm", [m.max_at.0, m.max_at.1])
        .set("peak_um", um(c.peak.0))
        .set("peak_at_mm", [c.peak.1.0, c.peak.1.1])
        .set("remainder_um", um(c.remainder))
        .set("peak_to_valley_um", um(m.peak_to_valley))
        .set("grid_error_estimate_um", um(m.peak_to_valley - m.peak_to_valley_half))
        .set("cross_feed_rz_um", um(m.cross_rz))
        .set("cross_feed_rz_max_um", um(m.cross_rz_max))
        .set("cross_feed_rz_at_y_mm", m.cross_rz_at)
        .set("cross_feed_ra_um", um(m.cross_ra))
        .set("feed_rz_um", um(m.feed_rz))
        .set("feed_rz_max_um", um(m.feed_rz_max))
        .set("feed_rz_at_x_mm", m.feed_rz_at)
        .set("feed_ra_um", um(m.feed_ra))
        .set("down_cut_max_um", um(m.down_cut_max))
        .set("up_cut_max_um", um(m.up_cut_max))
        .set("down_cut_feed_rz_um", um(m.down_cut_feed_rz))
        .set("up_cut_feed_rz_um", um(m.up_cut_feed_rz));
}

fn set_conditions(r: &mut Report, cond: &Conditions) {
    r.set("radius_mm", cond.cutter.radius)
        .set("flutes", cond.cutter.flutes)
        .set("flat_radius_mm", cond.cutter.flat_radius)
        .set("pick_mm", cond.pick)
        .set("feed_per_tooth_mm", cond.feed_per_tooth)
        .set("tilt_deg", cond.tilt.to_degrees())
        .set("lean", if cond.lean > 0.0 { "plus-x" } else { "minus-x" })
        .set("pass_phase_deg", cond.pass_phase.to_degrees())
        .set("down_cut_side", if cond.cutter.rotation == Rotation::Ccw { "-x" } else { "+x" });
}

fn patch(a: PatchArgs) -> Result<()> {
    let (cond, _) = conditions(&a.cond)?;
    let started = Instant::now();
    let step = a.cond.step;
    let (w, l) = match a.size {
        Some(s) => (positive(s, "--size")?, s),
        None => (positive(a.picks, "--picks")? * cond.pick, positive(a.teeth, "--teeth")? * cond.feed_per_tooth),
    };
    let grid = Grid::covering(-w / 2.0, w / 2.0, 0.0, l, step);
    let bounds = budget_of(a.cond.max_memory, a.cond.max_work)?;
    budget::patch(&cond, &grid)
        .check(&bounds, &format!("a {} × {} patch (--step, --pick, --feed-per-tooth)", grid.nx, grid.ny))?;
    let spacing = positive(a.verify_spacing, "--verify-spacing")?;
    let progress = cli::progress(a.cond.quiet, 0, "simulating the patch");
    let map = simulate(&cond, &grid);
    progress.finish();
    let simulate_seconds = started.elapsed().as_secs_f64();
    let figs = study::cell_figures(&cond, &map);
    let seconds = started.elapsed().as_secs_f64();
    let mut report = Report::new("rough-sim");
    report.set("command", "patch");
    set_conditions(&mut report, &cond);
    report.set("grid_step_mm", step).set("nodes", grid.nx * grid.ny);
    set_figures(&mut report, &figs);
    report
        .set("seconds", seconds)
        .set("simulate_seconds", simulate_seconds)
        .set("nodes_per_second", (grid.nx * grid.ny) as f64 / simulate_seconds.max(1e-9));
    if a.verify {
        let area = (-cond.pick / 2.0, cond.pick / 2.0, 0.0, cond.feed_per_tooth);
        let max_radial = (2.0 * cond.cutter.radius * (figs.map.max_height + 0.01)).sqrt().min(cond.cutter.radius);
        let dtheta = brute::angle_step(max_radial, cond.feed_per_radian(), spacing);
        budget::verify(&cond, area, dtheta, spacing, max_radial).check(&bounds, "--verify (--verify-spacing)")?;
        let (worst, samples) = brute::worst_below(&cond, area, dtheta, spacing, max_radial);
        report.set("verify_samples", samples).set("verify_worst_below_um", um(worst));
        if worst > rough_sim::STATED_ERROR {
            return Err(Error::check(format!(
                "an edge point passes {:.4} µm below the computed surface (bound 0.1 µm)",
                worst * 1e3
            )));
        }
    }
    if let Some(path) = &a.svg {
        let title = format!(
            "r {} mm, f {} mm, fz {:.3} mm, ζ {}°",
            cond.cutter.radius, cond.pick, cond.feed_per_tooth, a.cond.tilt
        );
        write_atomic(
            path,
            render::colour_map(&map, &title, "h: height above the nominal surface (mm)", Some(&figs.map)).as_bytes(),
        )?;
    }
    if let Some(path) = &a.profiles {
        write_atomic(path, &profiles_csv(&map, figs.map.max_at))?;
    }
    if let Some(path) = &a.report {
        report.write(path)?;
    }
    let mut out = Output::new(a.output.as_deref());
    out.buf = render::csv(&map, "h");
    out.commit()
}

/// The cross-feed (constant y) and feed (constant x) profiles through a point, as CSV.
fn profiles_csv(map: &rough_sim::patch::HeightMap, at: (f64, f64)) -> Vec<u8> {
    let g = &map.grid;
    let i0 = (((at.0 - g.x0) / g.step).round() as usize).min(g.nx - 1);
    let j0 = (((at.1 - g.y0) / g.step).round() as usize).min(g.ny - 1);
    let mut s = String::from("direction,x,y,h\n");
    for i in 0..g.nx {
        s.push_str(&format!("cross-feed,{:.6},{:.6},{:.7}\n", g.x(i), g.y(j0), map.at(i, j0)));
    }
    for j in 0..g.ny {
        s.push_str(&format!("feed,{:.6},{:.6},{:.7}\n", g.x(i0), g.y(j), map.at(i0, j)));
    }
    s.into_bytes()
}

fn sweep(a: SweepArgs) -> Result<()> {
    let (base, speeds) = conditions(&a.cond)?;
    if a.vary == Vary::Spindle && speeds.is_none() {
        return Err(Error::input("--vary spindle needs --feed and --spindle (the feed is kept)"));
    }
    let radii = if a.radii.is_empty() { vec![base.cutter.radius] } else { a.radii.clone() };
    // Every cell's conditions first, so the whole sweep is estimated before it starts.
    let mut cells = Vec::new();
    let mut need = Need::default();
    for &r in &radii {
        positive(r, "--radii")?;
        budget::check_radius(r, "--radii")?;
        for &v in &a.values {
            let mut cond = Conditions { cutter: Cutter { radius: r, ..base.cutter }, ..base };
            let mut spindle = speeds.map(|s| s.1);
            match a.vary {
                Vary::FeedPerTooth => cond.feed_per_tooth = v,
                Vary::Tilt => {
                    if !(v.is_finite() && (0.0..90.0).contains(&v)) {
                        return Err(Error::input(format!("tilt values must be in [0°, 90°), got {v}°")));
                    }
                    cond.tilt = v.to_radians();
                }
                Vary::Spindle => {
                    let n = positive(v, "spindle speed")?;
                    cond.feed_per_tooth = speeds.map_or(0.0, |s| s.0) / (n * cond.cutter.flutes as f64);
                    spindle = Some(n);
                }
                Vary::PassPhase => cond.pass_phase = v.to_radians(),
            }
            cond.validate()?;
            need = need.then(budget::cell(&cond, a.cond.step));
            cells.push((r, v, cond, spindle));
        }
    }
    let bounds = budget_of(a.cond.max_memory, a.cond.max_work)?;
    need.check(&bounds, &format!("a sweep of {} cells (--values, --radii, --step)", cells.len()))?;
    let started = Instant::now();
    let mut rows = vec![study::HEADER.to_string()];
    let mut series = Vec::new();
    let progress = cli::progress(a.cond.quiet, cells.len() as u64, "sweeping");
    for (ri, per_radius) in cells.chunks(a.values.len()).enumerate() {
        let r = per_radius[0].0;
        let (mut pts_max, mut pts_classic) = (Vec::new(), Vec::new());
        for &(_, v, cond, spindle) in per_radius {
            let (_, figs) = study::cell(&cond, a.cond.step);
            rows.push(study::row(&cond, spindle, &figs));
            pts_max.push((v, figs.peak.0 * 1e3));
            pts_classic.push((v, figs.classic_peak * 1e3));
            progress.inc(1);
        }
        series.push(Series { name: format!("r = {r} mm: simulated peak"), pts: pts_max, colour: ri, dashed: false });
        series.push(Series {
            name: format!("r = {r} mm: classic (cusp + feed scallop)"),
            pts: pts_classic,
            colour: ri,
            dashed: true,
        });
    }
    progress.finish();
    let x_label = match a.vary {
        Vary::FeedPerTooth => "feed per tooth (mm)",
        Vary::Tilt => "tilt (°)",
        Vary::Spindle => "spindle speed (rpm)",
        Vary::PassPhase => "pass phase (°)",
    };
    if let Some(path) = &a.svg {
        let svg =
            render::chart(&format!("roughness (highest point) against {x_label}"), x_label, "height (µm)", &series);
        write_atomic(path, svg.as_bytes())?;
    }
    if let Some(path) = &a.report {
        let mut r = Report::new("rough-sim");
        r.set("command", "sweep").set("points", rows.len() - 1).set("seconds", started.elapsed().as_secs_f64());
        r.write(path)?;
    }
    let mut out = Output::new(a.output.as_deref());
    out.buf = (rows.join("\n") + "\n").into_bytes();
    out.commit()
}

fn flat_tip(a: FlatArgs) -> Result<()> {
    let (cond, _) = conditions(&a.cond)?;
    let z = cond.cutter.flutes;
    let per_rev = cond.feed_per_tooth * z as f64;
    let t = flat::eq7(cond.cutter.radius, z, cond.pick, per_rev);
    let mut rows = vec![
        ("r_m_mm", t.r_m),
        ("r_n_mm", t.r_n),
        ("tau_n_rad", t.tau_n),
        ("r_n_with_tool_radius_mm", t.r_n_tool_radius),
        ("r0_mm", t.r0),
        ("delta_um", t.delta * 1e3),
    ];
    let mut report = Report::new("rough-sim");
    report.set("command", "flat-tip");
    set_conditions(&mut report, &cond);
    if a.simulate {
        let step = a.cond.step;
        let plain = Conditions { cutter: Cutter { flat_radius: 0.0, ..cond.cutter }, ..cond };
        let with = Conditions { cutter: Cutter { flat_radius: t.r0, ..cond.cutter }, ..cond };
        let one = budget::cell(&plain, step);
        let cells = 2.0 + budget::flat_cells(cond.cutter.radius, FLAT_RESOLUTION);
        Need { memory: one.memory, work: one.work * cells }
            .check(&budget_of(a.cond.max_memory, a.cond.max_work)?, "flat-tip --simulate (--step, --pick)")?;
        let (_, f_plain) = study::cell(&plain, step);
        // Eq. 7 may ask for a flat as wide as the ball or wider (a large feed on a small tool):
        // no such tool exists to simulate, and the row says so with NaN.
        let with_height =
            if with.cutter.validate().is_ok() { study::cell(&with, step).1.map.max_height } else { f64::NAN };
        rows.push(("max_height_plain_um", f_plain.map.max_height * 1e3));
        rows.push(("max_height_with_r0_um", with_height * 1e3));
        let progress = cli::progress(a.cond.quiet, 0, "simulating the flat tip");
        let sim = flat::simulated_r0(&plain, step, rough_sim::STATED_ERROR, FLAT_RESOLUTION).unwrap_or(f64::NAN);
        progress.finish();
        rows.push(("r0_simulated_mm", sim));
        rows.push(("delta_simulated_um", (cond.cutter.radius - (cond.cutter.radius.powi(2) - sim * sim).sqrt()) * 1e3));
    }
    let mut text = String::from("figure,value\n");
    for (k, v) in &rows {
        text.push_str(&format!("{k},{:.6}\n", v));
        report.set(k, (v * 1e6).round() / 1e6);
    }
    if let Some(path) = &a.report {
        report.write(path)?;
    }
    let mut out = Output::new(a.output.as_deref());
    out.write_all(text.as_bytes()).map_err(|e| Error::io(e, "output"))?;
    out.commit()
}

fn zmap_cmd(a: ZmapArgs) -> Result<()> {
    let tool_input = Input::open(&a.tool)?;
    let doc: Tool = camkit::json::checked(&tool_input, Tool::validate)?;
    if a.flutes == Some(0) {
        return Err(Error::input("--flutes must be at least 1, got 0"));
    }
    let mut cutter =
        Cutter::from_tool(&doc, &tool_input.name, a.flutes).map_err(|e| camkit::json::at_value(&tool_input, e))?;
    budget::check_radius(cutter.radius, &tool_input.name)?;
    cutter.rotation = if a.rotation == Sense::Ccw { Rotation::Ccw } else { Rotation::Cw };
    let spindle = positive(a.spindle, "--spindle")?;
    if let Some(f) = a.feed {
        positive(f, "--feed")?;
    }
    positive(a.step, "--step")?;
    let started = Instant::now();
    let input = Input::open(&a.io.input)?;
    let t = table::read(&input, &[Col::X, Col::Y])?;
    if t.rows.is_empty() {
        return Err(Error::input("no rows: a toolpath is needed").at(Location::file(&input.name)));
    }
    let bounds = budget_of(a.max_memory, a.max_work)?;
    let max_moves = (bounds.memory / budget::MOVE_BYTES) as usize;
    let moves = zmap::moves(&t, &input.name, &cutter, spindle, a.feed, max_moves)?;
    let (x0, y0, x1, y1) = if let Some(r) = a.region {
        (r.x0, r.y0, r.x1, r.y1)
    } else if let Some(text) = &a.area {
        let v: Vec<f64> = text.split(',').filter_map(|t| camkit::num::parse_finite(t.trim()).ok()).collect();
        match v[..] {
            [x0, y0, x1, y1] if x1 > x0 && y1 > y0 => {
                cli::warn(&format!("--area X0,Y0,X1,Y1 is the old spelling: this is --region {x0},{x1},{y0},{y1}"));
                (x0, y0, x1, y1)
            }
            _ => {
                return Err(Error::input(format!("--area must be X0,Y0,X1,Y1 with X1 > X0 and Y1 > Y0, got {text:?}")));
            }
        }
    } else {
        zmap::extent(&moves, &cutter)
            .ok_or_else(|| Error::input("no feed move to simulate").at(Location::file(&input.name)))?
    };
    let grid = Grid::covering(x0, x1, y0, y1, a.step);
    budget::zmap(&grid, &moves, &cutter)
        .check(&bounds, &format!("a {} × {} z-map of {} moves (--step, --region)", grid.nx, grid.ny, moves.len()))?;
    let progress = a.io.progress(0, "simulating the z-map");
    let map = zmap::simulate(&cutter, &moves, &grid);
    progress.finish();
    let seconds = started.elapsed().as_secs_f64();
    let cut: Vec<f64> = map.h.iter().copied().filter(|v| v.is_finite()).collect();
    let (lo, hi) = cut.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &v| (a.0.min(v), a.1.max(v)));
    let f = rough_sim::figures::figures(&map, f64::INFINITY, None, true);
    if let Some(path) = &a.svg {
        write_atomic(path, render::colour_map(&map, &format!("{}: z-map", input.name), "z (mm)", None).as_bytes())?;
    }
    if let Some(path) = &a.io.report {
        let mut r = Report::new("rough-sim");
        r.set("command", "zmap")
            .set("moves", moves.len())
            .set("nodes", grid.nx * grid.ny)
            .set("nodes_cut", cut.len())
            .set("z_min_mm", lo)
            .set("z_max_mm", hi)
            .set("row_rz_max_um", um(f.cross_rz_max))
            .set("row_ra_mean_um", um(f.cross_ra))
            .set("column_rz_max_um", um(f.feed_rz_max))
            .set("column_ra_mean_um", um(f.feed_ra))
            .set("seconds", seconds);
        r.write(path)?;
    }
    let mut out = Output::new(a.io.output.as_deref());
    out.buf = render::csv(&map, "z");
    out.commit()
}
