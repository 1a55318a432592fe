//! `medial-trochoid`: engagement of contour-parallel pocketing, danger regions on the medial
//! axis, trochoids first (paper 001).

use camkit::cli::{self, IoArgs, positive};
use camkit::contour::Seg;
use camkit::contour::region::Region;
use camkit::contour::table as contour_table;
use camkit::doc::Setup;
use camkit::doc::setup::{Job, Part};
use camkit::error::{Error, Location, Result};
use camkit::geom::{P2, P3};
use camkit::io::{Input, Output, write_atomic};
use camkit::report::Report;
use camkit::table::{self, Col, Move, Row, Schema, Table, WriteOptions};
use clap::{Parser, ValueEnum};
use medial_trochoid::breakdown::Breakdown;
use medial_trochoid::feed::FeedModel;
use medial_trochoid::medial::MedialOptions;
use medial_trochoid::program::{Entry, Tag};
use medial_trochoid::{Analysed, ENGAGEMENT_ROUNDOFF_DEG, Settings, plan, plan_leaving_uncut, plot};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Ramp angle of the helical entries without --ramp-angle or a setup's (degrees): FreeCAD's
/// adaptive clearing's default helix angle.
const DEFAULT_RAMP_DEG: f64 = 5.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Which {
    /// Trochoids along the danger regions first, then the offset passes.
    Trochoid,
    /// The contour-parallel passes alone (the reference).
    Offset,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Strategy {
    /// Paper 001: offset passes with trochoids along the medial axis's danger regions first.
    Trochoid,
    /// Adaptive clearing: passes whose every step's heading is chosen by the exact engagement
    /// simulation so that the engagement is the threshold (a helical entry at the largest
    /// inscribed circle, climb, links through cleared ground).
    Adaptive,
}

#[derive(Parser, Debug)]
#[command(
    name = "medial-trochoid",
    version,
    allow_negative_numbers = true,
    about = "Engagement of contour-parallel pocketing, danger regions on the medial axis, trochoidal clearing first (paper 001).",
    long_about = "Reads closed contours (outer boundaries and islands; lines and arcs) from the toolpath table, a DXF or an SVG drawing, makes \
contour-parallel pocket passes, simulates the material removal to get the exact 2D engagement angle along them, finds \
where passes over the threshold meet the medial axis (segment Voronoi diagram without the edges at reflex vertices), \
clears those stretches first with constant-radius trochoidal loops, re-simulates the whole program and estimates both \
programs' machining time.",
    after_help = after_help()
)]
struct Args {
    #[command(flatten)]
    io: IoArgs,
    #[command(flatten)]
    contours: camkit::contour::load::ContourArgs,
    /// Tool radius R (mm); default the radius of the setup's tool.
    #[arg(long, value_name = "MM", required_unless_present = "setup")]
    radius: Option<f64>,
    /// The job's setup document (docs/formats.md#setup): the tool's radius, and the layers from
    /// the stock top down to the part's floor (`part.floor` of a part given by contours, else the
    /// contour's z) in equal steps of at most --layer-depth (one layer without it). A cone tool
    /// is refused: the engagement model is a flat end mill's.
    #[arg(long, value_name = "FILE", conflicts_with = "layers")]
    setup: Option<String>,
    /// Radial step over between passes (mm); default R(1 − cos threshold), the side cut at the
    /// threshold. After a pass with arcs round the pocket (radius ρ ≥ R/8) the step is at most
    /// the one whose concave side cut acos(1 − s/R − s/ρ + s²/(2ρR)) holds the threshold.
    #[arg(long, value_name = "MM")]
    step: Option<f64>,
    /// Engagement threshold (degrees).
    #[arg(long, default_value_t = 40.0, value_name = "DEG")]
    threshold: f64,
    /// Trochoid loop radius (mm); default R/2.
    #[arg(long, value_name = "MM")]
    trochoid_radius: Option<f64>,
    /// Trochoid pitch (mm); default the largest whose simulated engagement holds the threshold.
    #[arg(long, value_name = "MM")]
    pitch: Option<f64>,
    /// Material left on walls and islands (mm).
    #[arg(long, default_value_t = 0.0, value_name = "MM")]
    allowance: f64,
    /// Radius of the tangent arcs that replace the wall passes' sharp inside corners (mm; 0 keeps
    /// them sharp); default: each corner's smallest radius that holds the threshold in the
    /// simulation. A round tool at a sharp inside corner has the whole corner in material (≥ 90°
    /// at 90°): the rounded corners leave that rest to finishing (named in the report).
    #[arg(long, value_name = "MM")]
    corner_radius: Option<f64>,
    /// Engagement sample spacing along the path (mm); every move's end is also sampled.
    #[arg(long, default_value_t = 0.5, value_name = "MM")]
    sample: f64,
    /// Number of layers (each the same 2D program, one layer depth lower; default 1).
    #[arg(long, value_name = "N")]
    layers: Option<usize>,
    /// Depth of each layer (mm): layer k is cut at z − k·depth, the contour's z being the first
    /// layer's bottom; with --setup, the most a layer may be.
    #[arg(long, default_value_t = 0.0, value_name = "MM")]
    layer_depth: f64,
    /// Ramp angle of the helical entries (degrees, over 0 and under 90): an entry loop descends
    /// the layer's depth at this angle over as many loops as that takes, then one more loop is
    /// cut at the layer's depth (none descends without a layer depth); default the setup's
    /// plunge.ramp_angle, else 5.
    #[arg(long, value_name = "DEG")]
    ramp_angle: Option<f64>,
    /// Which program to write.
    #[arg(long, value_enum, default_value_t = Which::Trochoid)]
    program: Which,
    /// The clearing strategy: the paper's (trochoids first) or adaptive clearing held at the
    /// threshold by the exact engagement simulation (the written program is the adaptive one;
    /// --program, --step, --trochoid-radius, --pitch and --corner-radius do not apply).
    #[arg(long, value_enum, default_value_t = Strategy::Trochoid)]
    strategy: Strategy,
    /// Write the trochoids-first program even where its re-simulation goes over the threshold
    /// (a warning; the places are listed in the report). Without it that is a failed check:
    /// the report and plots are written, the program is not, exit status 1.
    #[arg(long)]
    allow_over_threshold: bool,
    /// Refuse (exit status 1) where the trochoids-first program goes over the threshold, instead
    /// of leaving uncut what the tool cannot reach under it. By default such a pocket is opened
    /// by the first of the radii (R + allowance) × 1.1, 1.25, 1.5, 2, 3 whose plan holds the
    /// threshold: a disk of that radius rolled inside it rounds its inside corners and drops
    /// gaps narrower than twice the radius; both programs are made in the opened pocket, the
    /// gouge check stays against the given walls, and the material left is named in the report
    /// (uncut, uncut_radius_mm, uncut_area_mm2; apart from unreachable_area_mm2, what no tool of
    /// radius R + allowance reaches at all) and in a warning.
    #[arg(long)]
    no_leave_uncut: bool,
    /// Snap grid of the Voronoi input (mm).
    #[arg(long, default_value_t = 1e-6, value_name = "MM")]
    resolution: f64,
    /// Largest sagitta of the chords that replace arcs in the Voronoi input (mm).
    #[arg(long, default_value_t = 1e-3, value_name = "MM")]
    sagitta: f64,
    /// Spindle speed for the time estimate (1/min).
    #[arg(long, default_value_t = 4800.0, value_name = "RPM")]
    spindle: f64,
    /// Number of teeth.
    #[arg(long, default_value_t = 6.0, value_name = "N")]
    teeth: f64,
    /// Largest chip thickness (mm): a tooth at angle β from the travel cuts fz·cos β, so the feed
    /// per tooth is at most chip / (the largest cos β over the material arcs ahead): chip / sin φ
    /// for a side cut of engagement φ ≤ 90°.
    #[arg(long, default_value_t = 0.03, value_name = "MM")]
    chip: f64,
    /// Largest feed per tooth of the tool (mm).
    #[arg(long, default_value_t = 0.1, value_name = "MM")]
    fz_max: f64,
    /// The force limit of the feed model (paper 001: feeds that keep the cutting force nearly
    /// constant): the engagement (degrees; default the threshold) of the straight side cut whose
    /// mean cutting force at its chip-limited feed is the most the tool takes. Heavier cuts run
    /// proportionally slower (a slot at 1/6.8 of the 40° side cut's feed). The report gives times
    /// and ratios with it and with the chip limit alone.
    #[arg(long, value_name = "DEG")]
    force_at: Option<f64>,
    /// Time with the chip-thickness limit alone (no force limit).
    #[arg(long, conflicts_with = "force_at")]
    no_force_limit: bool,
    /// Decimals of written positions (exact by default). The plan keeps 1.5·√2·10^-N mm more
    /// from the walls and is made under the threshold by what that rounding may add, so that the
    /// written rows keep R + allowance and the threshold (the report is the written program's).
    #[arg(long, value_name = "N")]
    decimals: Option<u32>,
    /// SVG of the written program: contours, medial axis, danger regions, passes coloured by
    /// engagement on a colour bar in degrees.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// SVG of the other program (offset-only when writing trochoids, and the reverse).
    #[arg(long, value_name = "FILE")]
    svg_other: Option<PathBuf>,
    /// Analyse this given toolpath table (another program's, e.g. FreeCAD's adaptive clearing)
    /// in the pocket of INPUT instead of planning: its lowest z is the layer, its engagement is
    /// re-simulated at --sample and timed by the same feed model; writes it with the
    /// engagement column.
    #[arg(long, value_name = "FILE")]
    analyse: Option<PathBuf>,
    /// Largest memory a plan may hold (MB), estimated from the pocket, --step, --sample,
    /// --pitch, --sagitta and the layers before planning; larger plans are refused (exit 2).
    #[arg(long, default_value_t = camkit::budget::DEFAULT_MEMORY_MB, value_name = "MB")]
    max_memory: u64,
    /// Largest work of a plan or an --analyse run in engagement samples (60 to 190 µs of CPU
    /// each on the demo pockets), estimated from the pocket, --step, --sample and --pitch (or
    /// the given toolpath's length over --sample) before any simulation; more is refused (exit 2).
    #[arg(long, default_value_t = medial_trochoid::budget::DEFAULT_WORK, value_name = "N")]
    max_work: f64,
}

fn after_help() -> String {
    let mut s = table::columns::help_text(
        &[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::Xc, Col::Yc, Col::Plane],
        &[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::Xc, Col::Yc, Col::F, Col::Tag],
    );
    s.push_str("  engagement deg            engagement angle at the row's end (material-removal simulation)\n");
    s.push_str("Each input path is one closed contour; nesting decides outer boundaries and islands.\n");
    s.push_str(&camkit::contour::load::help_text());
    s.push('\n');
    s.push_str(
        "Output rows are samples along the tool-centre path (at most --sample mm apart); tag is entry (helical\n",
    );
    s.push_str(
        "entry: loops down one layer at --ramp-angle, then one at depth), trochoid, contour or link; each chain\n",
    );
    s.push_str("starts with a rapid row.\n");
    s.push_str(
        "--strategy adaptive writes entry (helix), contour (the adaptive passes, straight steps) and link rows;\n",
    );
    s.push_str("its report keys: see docs/formats.md (adaptive_minutes, uncut_area_mm2, plan_seconds, ...).\n");
    s.push_str(
        "Material the tool cannot reach under the threshold is left uncut (see --no-leave-uncut): report keys uncut\n",
    );
    s.push_str(
        "(per stretch: loop = path id, from, to, length_mm, thickness_mm, thickest_at), uncut_radius_mm, uncut_area_mm2;\n",
    );
    s.push_str(
        "unreachable_area_mm2 is what no tool of radius R + allowance reaches at all (corner fillets, acute tips).\n",
    );
    s.push_str("\nExit status: 0 done, 1 a check failed, 2 bad input or usage.");
    s
}

fn main() -> ExitCode {
    cli::run("medial-trochoid", || run(cli::parse::<Args>()?))
}

/// The first layer's bottom, the number of layers and their depth: from the stock top down to
/// the floor (the part's, else `contour_z`) with the setup, from the contour's z otherwise.
fn layering(job: Option<&Job>, contour_z: f64, layers: Option<usize>, depth: f64) -> Result<(f64, usize, f64)> {
    let Some(job) = job else { return Ok((contour_z, layers.unwrap_or(1), depth)) };
    let top = job.stock.top();
    let floor = match &job.part {
        Some(Part::Walls { floor, .. }) => *floor,
        _ => contour_z,
    };
    if floor >= top {
        return Err(job.error("stock", format!("the pocket floor {floor} is not below the stock top {top}")));
    }
    let n = if depth > 0.0 { ((top - floor) / depth - 1e-9).ceil().max(1.0) as usize } else { 1 };
    let step = (top - floor) / n as f64;
    Ok((top - step, n, step))
}

fn run(args: Args) -> Result<()> {
    let started = Instant::now();
    let job = args.setup.as_deref().map(Setup::read).transpose()?;
    if let Some(j) = job.as_ref().filter(|j| j.tool.kind == camkit::doc::ToolKind::Cone) {
        // The engagement and material-removal model is a disc of radius R cutting each layer
        // to its floor, a flat end mill's: a cone is R wide only at its top.
        return Err(j.error(
            "tool",
            format!(
                "{} is a cone cutter: the engagement model is a flat end mill's (a disc of the tool's radius cutting the whole layer), and a cone cuts a V; use a flat, ball or bull-nose end mill",
                j.tool_file
            ),
        ));
    }
    let r = match (args.radius, &job) {
        (Some(r), Some(j)) if (r - j.tool.radius).abs() > 1e-12 => {
            return Err(Error::input(format!(
                "--radius {r} disagrees with the radius {} of the setup's tool {}",
                j.tool.radius, j.tool_file
            )));
        }
        (Some(r), _) => positive(r, "--radius")?,
        (None, Some(j)) => j.tool.radius,
        (None, None) => unreachable!("clap requires --radius without --setup"),
    };
    let threshold = positive(args.threshold, "--threshold")?;
    if threshold >= 180.0 {
        return Err(Error::input("--threshold must be under 180 degrees"));
    }
    if args.decimals.is_some_and(|d| d > 12) {
        return Err(Error::input("--decimals must be at most 12"));
    }
    // Planned under the threshold by what rounding to --decimals may add, so that the written
    // program holds it (checked below on the rounded rows).
    let slack = rounding_slack_deg(args.decimals, r, threshold);
    if slack > 0.25 * threshold {
        return Err(Error::input(format!(
            "--decimals {} rounds positions by up to {:.3} mm, which may raise the engagement by {slack:.3}°: too coarse for R {r} and a threshold of {threshold}°; write more decimals",
            args.decimals.unwrap_or_default(),
            rounding_reach(args.decimals)
        )));
    }
    let planned_threshold = threshold - slack;
    let step = positive(args.step.unwrap_or(medial_trochoid::default_step(r, planned_threshold)), "--step")?;
    let rt = positive(args.trochoid_radius.unwrap_or(0.5 * r), "--trochoid-radius")?;
    if let Some(p) = args.pitch {
        positive(p, "--pitch")?;
    }
    if !(args.allowance.is_finite() && args.allowance >= 0.0) {
        return Err(Error::input(format!("--allowance must be zero or more, got {}", args.allowance)));
    }
    if !(args.layer_depth.is_finite() && args.layer_depth >= 0.0) || args.layers == Some(0) {
        return Err(Error::input("--layers must be at least 1 and --layer-depth zero or more"));
    }
    // Chords finer than the snap grid are lost in the snapping, and there would be unboundedly
    // many of them (a run at --sagitta 1e-9 on a 60 × 40 square did not end).
    if args.sagitta < args.resolution {
        return Err(Error::input(format!(
            "--sagitta {} mm is below the Voronoi snap grid (--resolution {} mm): chords that fine are lost in the snapping",
            cli::short(args.sagitta),
            cli::short(args.resolution)
        )));
    }
    let ramp_deg = args.ramp_angle.or(job.as_ref().and_then(|j| j.ramp_angle)).unwrap_or(DEFAULT_RAMP_DEG);
    if !(ramp_deg > 0.0 && ramp_deg < 90.0) {
        return Err(Error::input(format!("--ramp-angle must be over 0 and under 90 degrees, got {ramp_deg}")));
    }
    let mut settings = Settings {
        radius: r,
        step,
        threshold,
        trochoid_radius: rt,
        pitch: args.pitch,
        allowance: args.allowance,
        corner_radius: match args.corner_radius {
            Some(r) if !(r.is_finite() && r >= 0.0) => {
                return Err(Error::input(format!("--corner-radius must be zero or more, got {r}")));
            }
            r => r,
        },
        sample: positive(args.sample, "--sample")?,
        medial: MedialOptions {
            resolution: positive(args.resolution, "--resolution")?,
            sagitta: positive(args.sagitta, "--sagitta")?,
            chord_error: positive(args.sagitta, "--sagitta")?,
        },
        feed: FeedModel {
            spindle: positive(args.spindle, "--spindle")?,
            teeth: positive(args.teeth, "--teeth")?,
            chip: positive(args.chip, "--chip")?,
            fz_max: positive(args.fz_max, "--fz-max")?,
            force_at: match args.force_at.unwrap_or(threshold) {
                _ if args.no_force_limit => None,
                deg if deg > 0.0 && deg <= 180.0 => Some(deg),
                deg => {
                    return Err(Error::input(format!("--force-at must be over 0 and at most 180 degrees, got {deg}")));
                }
            },
        },
        // Set from the layers below, once they are known.
        entry: Entry::FLAT,
    };
    let contour_opts = args.contours.options(false)?;
    let input = Input::open(&args.io.input)?;
    let name = input.name.clone();
    let loaded = camkit::contour::load::contours(&input, &contour_opts)?;
    if let Some((kind, line)) = loaded.skipped.first() {
        cli::warn(&format!(
            "{name}: {} entities that are not contours skipped (the first: {kind} at line {line})",
            loaded.skipped.len()
        ));
    }
    let sources = loaded.sources;
    if sources.is_empty() {
        return Err(Error::input("no closed contour in the input").at(Location::file(&name)));
    }
    for src in &sources {
        let far =
            src.contour.bounds().map_or(0.0, |(lo, hi)| lo.x.abs().max(lo.y.abs()).max(hi.x.abs()).max(hi.y.abs()));
        if far.is_nan() || far > medial_trochoid::COORD_LIMIT {
            return Err(Error::input(format!(
                "path {} reaches {far:e} mm, beyond ±{:e} mm where round-off undoes the engagement simulation's 1e-6 mm margins: move the pocket towards the origin",
                src.path,
                medial_trochoid::COORD_LIMIT
            ))
            .at(Location::file(&name).line(src.line)));
        }
    }
    let (regions, _turned) = contour_table::pocket_regions(&sources, &name)?;
    if let Some(given) = &args.analyse {
        return analyse_given(given, &regions, &settings, &args, started);
    }
    let chorded = medial_trochoid::chords::drawn_with_chords(&regions, r);
    if let Some(&(first, run)) = chorded.first() {
        let src = &sources[first];
        cli::warn(&format!(
            "{name}:{}: path {} is a curve drawn with chords ({run} shallow joints of lines shorter than R in a row; {} such loops): every pass along it gets a corner at each joint, all cleared by trochoids; fitted to arcs first (curve-fit-arcs --tol a little over the chords' sagitta | medial-trochoid -) it is cut by concentric passes",
            src.line,
            src.path,
            chorded.len()
        ));
    }
    let (z0, layer_count, layer_depth) = layering(job.as_ref(), sources[0].z, args.layers, args.layer_depth)?;
    settings.entry = Entry { drop: layer_depth, ramp_deg };
    // The plan's spacings as both bounds name them (`mid` after the sample, `tail` at the end).
    let plan_named = |mid: &str, tail: &str| {
        format!(
            "the plan (--step {} mm, --sample {} mm{mid}, --trochoid-radius {} mm{}{tail})",
            cli::short(step),
            cli::short(settings.sample),
            cli::short(rt),
            args.pitch.map(|p| format!(", --pitch {} mm", cli::short(p))).unwrap_or_default(),
        )
    };
    camkit::budget::check_memory(
        medial_trochoid::budget::memory(&regions, &settings, layer_count),
        camkit::budget::bytes_of(args.max_memory),
        &plan_named(&format!(", {layer_count} layers"), &format!(", --sagitta {} mm", cli::short(args.sagitta))),
        "coarsen --step, --sample, --pitch or --sagitta, use fewer layers",
    )?;
    camkit::budget::check_work(
        medial_trochoid::budget::work(&regions, &settings),
        positive(args.max_work, "--max-work")?,
        "engagement samples",
        &plan_named("", ""),
        "coarsen --step, --sample or --pitch",
    )?;
    if args.strategy == Strategy::Adaptive {
        let planning = Settings {
            allowance: settings.allowance + rounding_reach(args.decimals),
            threshold: planned_threshold,
            ..settings
        };
        let layering = (z0, layer_count, layer_depth);
        let outer = &sources[regions[0].outer_source];
        let place = (outer.path, outer.line);
        return run_adaptive(&args, &regions, &settings, &planning, layering, (&name, place), started);
    }
    let leave_uncut = !(args.no_leave_uncut || args.allow_over_threshold);
    // Planned that much farther from the walls that the written program, rounded to
    // --decimals, still keeps R + allowance; checked below on the rounded rows.
    let planning = Settings {
        allowance: settings.allowance + rounding_reach(args.decimals),
        threshold: planned_threshold,
        ..settings
    };
    let progress = args.io.progress(0, "planning the passes");
    let planned = if leave_uncut { plan_leaving_uncut(&regions, &planning) } else { plan(&regions, &planning) };
    let plan = planned.map_err(|e| match e {
        medial_trochoid::PlanError::Pocket(_) => Error::check(e.to_string()),
        // The tool fits no region, or cuts none of it under the threshold: name the first
        // region's boundary, where the pocket starts.
        medial_trochoid::PlanError::NoPasses | medial_trochoid::PlanError::TooLarge(_) => {
            let outer = &sources[regions[0].outer_source];
            Error::input(format!("path {}: {e} (R + allowance = {} mm)", outer.path, r + args.allowance))
                .at(Location::file(&name).line(outer.line))
        }
        _ => Error::input(e.to_string()).at(Location::file(&name)),
    })?;
    let chosen = if args.program == Which::Trochoid { &plan.trochoidal } else { &plan.offset_only };
    let out_table = to_table(chosen, z0, layer_count, layer_depth);
    // The program as written (rounded to --decimals) read back and simulated again: the
    // report's figures of the written program are this check's, as --analyse gives them.
    let mut text = Vec::new();
    table::write(&mut text, &out_table, &WriteOptions { decimals: args.decimals })?;
    progress.stage(0, "simulating the written program again");
    let written = written_check(&text, &name, &regions, &settings)
        .map_err(|e| Error::check(format!("the written program does not read back: {e}")))?;
    progress.finish();
    let w = &written.analysed;
    let troch_main = args.program == Which::Trochoid;
    if !plan.uncleared.is_empty() {
        cli::warn(&format!(
            "{} dangerous stretches of the medial axis are too narrow for the smallest trochoid loop ({:.3} mm, the given {rt} mm shrunk): left to the passes",
            plan.uncleared.len(),
            rt * medial_trochoid::SMALLEST_LOOP
        ));
    }
    // The trochoids-first program's own check: over the threshold is a failed check unless the
    // user asked for the program anyway.
    let over = (!plan.left_over.is_empty()).then(|| {
        let (p, e) = plan.left_over.iter().fold(plan.left_over[0], |w, x| if x.1 > w.1 { *x } else { w });
        let openings = match (plan.openings_tried.first(), plan.openings_tried.last()) {
            (Some(a), Some(b)) => format!(" (nor did the pocket opened by {a:.3} to {b:.3} mm, to leave uncut what the tool cannot reach)"),
            _ => String::new(),
        };
        // A step whose straight side cut is over the threshold cannot hold it wherever a pass
        // follows another: say so, it is the likely cause.
        let side_cut = medial_trochoid::side_cut_deg(r, step);
        let hint = if side_cut > threshold + medial_trochoid::ENGAGEMENT_ROUNDOFF_DEG {
            format!(
                "; --step {step} mm side-cuts straight walls at {side_cut:.3}°, at most R(1 − cos threshold) = {:.4} mm holds the threshold",
                medial_trochoid::default_step(r, threshold)
            )
        } else {
            String::new()
        };
        format!(
            "{} samples still over the threshold after {} repair rounds{openings} (the worst {e:.3}° at ({:.3}, {:.3})): listed in the report{hint}",
            plan.left_over.len(),
            plan.repair_rounds,
            p.x,
            p.y
        )
    });
    // What no tool of radius R reaches at all (the R-opening's rest: acute tips, the inside
    // corners' fillets) apart from what the threshold strategy leaves.
    let unreachable = medial_trochoid::uncut::unreachable_area(&regions, r + args.allowance);
    let uncut_area = plan.uncut.as_ref().map_or(0.0, |u| (u.area - unreachable.unwrap_or(0.0)).max(0.0));
    if let Some(u) = &plan.uncut {
        let thickest = u.stretches.iter().max_by(|a, b| a.thickness.total_cmp(&b.thickness));
        let (t, at) = thickest.map_or((0.0, P2::origin()), |s| (s.thickness, s.thickest_at));
        cli::warn(&format!(
            "left uncut: {} stretches, {:.3} mm² (besides {:.3} mm² no tool of this radius reaches), thickest {t:.3} mm at ({:.3}, {:.3}): the tool cannot reach them under the threshold ({:.3} mm opening); named in the report",
            u.stretches.len(),
            uncut_area,
            unreachable.unwrap_or(0.0),
            at.x,
            at.y,
            u.rho
        ));
    }
    // The written program's own figures: cutting moves or links over the threshold fail the
    // check too.
    let (written_over, written_links_over) = written.over(threshold);
    let over = over.or_else(|| {
        (troch_main && written_over + written_links_over > 0).then(|| {
            format!(
                "the program as written has {written_over} cutting and {written_links_over} link samples over the threshold (largest {:.3}° cutting, {:.3}° on links)",
                w.max_cutting, w.max_link
            )
        })
    });
    let failed = over.as_ref().filter(|_| args.program == Which::Trochoid && !args.allow_over_threshold);
    if let Some(over) = over.as_ref().filter(|_| failed.is_none()) {
        cli::warn(over);
    }
    let wall_needed = r + args.allowance - camkit::tol::OFFSET_TOL;
    let gouge = (w.wall_clearance < wall_needed).then(|| {
        format!(
            "the program as written comes {:.6} mm from the walls, under R + allowance = {} mm",
            w.wall_clearance,
            r + args.allowance
        )
    });
    let mut out = Output::new(args.io.output.as_deref());
    std::io::Write::write_all(&mut out, &text).map_err(|e| Error::io(e, "output"))?;
    let title = |a: &Analysed, what: &str| {
        format!(
            "{name}: {what}, largest engagement {:.1}° (threshold {threshold}°), {:.2} min per layer",
            a.max_cutting, a.minutes
        )
    };
    let (main_t, other_t) = if args.program == Which::Trochoid {
        (title(&plan.trochoidal, "trochoids first"), title(&plan.offset_only, "offset passes only"))
    } else {
        (title(&plan.offset_only, "offset passes only"), title(&plan.trochoidal, "trochoids first"))
    };
    if let Some(path) = &args.svg {
        write_atomic(path, plot::plan_plot(&main_t, &plan, troch_main).to_svg(1000.0).as_bytes())?;
    }
    if let Some(path) = &args.svg_other {
        write_atomic(path, plot::plan_plot(&other_t, &plan, !troch_main).to_svg(1000.0).as_bytes())?;
    }
    if let Some(path) = &args.io.report {
        let layers = layer_count as f64;
        let (a, b) = (&plan.offset_only, &plan.trochoidal);
        let medial_edges: usize = plan.medial.iter().map(|m| m.edges.len()).sum();
        let mut rep = pocket_report(
            if troch_main { "trochoid" } else { "offset" },
            &settings,
            (z0, layer_count, layer_depth),
            &regions,
        );
        rep.set("step_mm", step)
            .set("passes_per_layer", plan.passes.len())
            .set("voronoi_segments", plan.medial.iter().map(|m| m.segments).sum::<usize>())
            .set("voronoi_resolution_mm", settings.medial.resolution)
            .set("arc_sagitta_mm", settings.medial.sagitta)
            .set("medial_edges", medial_edges)
            .set("medial_equidistance_error_mm", plan.medial.iter().map(|m| m.equidistance_error).fold(0.0, f64::max))
            .set("chord_drawn_paths", chorded.iter().map(|&(k, _)| sources[k].path).collect::<Vec<_>>())
            .set("danger_samples", plan.danger_samples)
            .set("danger_stretches", plan.danger.len())
            .set("trochoid_runs", plan.runs.len())
            .set("uncleared_stretches", plan.uncleared.len())
            .set("trochoid_radius_mm", rt)
            .set("trochoid_radius_range_mm", range(plan.runs.iter().flat_map(|r| r.radii.iter().copied())))
            .set("trochoid_pitch_range_mm", range(plan.runs.iter().flat_map(|r| r.pitches.iter().copied())))
            .set("offset_only_largest_engagement_deg", if troch_main { a.max_cutting } else { w.max_cutting })
            .set("offset_only_link_engagement_deg", if troch_main { a.max_link } else { w.max_link })
            .set("largest_engagement_deg", if troch_main { w.max_cutting } else { b.max_cutting })
            .set("link_engagement_deg", if troch_main { w.max_link } else { b.max_link })
            .set("entry_engagement_deg", if troch_main { w.max_entry } else { b.max_entry })
            .set("threshold_held", written_over + written_links_over == 0)
            .set("planned_threshold_deg", planned_threshold)
            .set("offset_only_samples_over_threshold", if troch_main { a.over } else { written_over })
            .set("samples_over_threshold", if troch_main { written_over } else { b.over })
            .set("link_samples_over_threshold", if troch_main { written_links_over } else { b.over_links })
            .set("repair_rounds", plan.repair_rounds)
            .set("repair_material_points", plan.repair_points)
            .set("over_threshold_at", plan.left_over.iter().map(|(p, e)| vec![p.x, p.y, *e]).collect::<Vec<_>>())
            .set(
                "over_threshold_reason",
                (!plan.left_over.is_empty()).then(|| {
                    format!(
                        "still over after {} repair rounds: {}",
                        plan.repair_rounds,
                        if plan.repairs_exhausted {
                            "the rounds ran out"
                        } else {
                            "no trochoid loop fits within R of the material met there"
                        }
                    )
                }),
            )
            .set("uncut_radius_mm", plan.uncut.as_ref().map(|u| u.rho))
            .set("uncut_radii_tried_mm", &plan.openings_tried)
            .set("uncut_area_mm2", uncut_area)
            .set("unreachable_area_mm2", unreachable)
            .set("opened_regions", plan.uncut.as_ref().map(|_| plan.regions.len()))
            .set(
                "uncut",
                plan.uncut.as_ref().map_or(Vec::new(), |u| {
                    u.stretches
                        .iter()
                        .map(|st| {
                            let (a, b) = (st.points[0], st.points[st.points.len() - 1]);
                            serde_json::json!({
                                "loop": sources[st.source].path,
                                "from": [a.x, a.y],
                                "to": [b.x, b.y],
                                "length_mm": st.length,
                                "thickness_mm": st.thickness,
                                "thickest_at": [st.thickest_at.x, st.thickest_at.y],
                            })
                        })
                        .collect()
                }),
            )
            .set("relinked", plan.relinks.len())
            .set("relinked_by_retract", plan.relinks.iter().filter(|l| l.retract).count())
            .set("relink_standing_engagement_deg", plan.relinks.iter().map(|l| l.standing_deg).collect::<Vec<_>>())
            .set("entries_on_cleared_ground", plan.idle_entries)
            .set("samples", w.samples.len())
            .set("smallest_wall_clearance_mm", w.wall_clearance)
            .set("no_gouge", gouge.is_none())
            .set("rounding_reach_mm", rounding_reach(args.decimals))
            .set("offset_only_minutes", a.minutes_constant * layers)
            .set("offset_only_variable_feed_minutes", a.minutes * layers)
            .set("trochoidal_minutes", b.minutes * layers)
            .set("trochoidal_constant_feed_minutes", b.minutes_constant * layers)
            .set("time_ratio", b.minutes / a.minutes_constant)
            .set("force_limit_at_deg", settings.feed.force_at)
            .set("offset_only_chip_only_minutes", a.minutes_constant_chip_only * layers)
            .set("trochoidal_chip_only_minutes", b.minutes_chip_only * layers)
            .set("time_ratio_chip_only", b.minutes_chip_only / a.minutes_constant_chip_only)
            .set("corner_rests", plan.rests.len())
            .set("corner_radii_mm", plan.rests.iter().map(|c| c.rho).collect::<Vec<_>>())
            .set("corner_rest_thickness_mm", plan.rests.iter().map(|c| c.thickness()).collect::<Vec<_>>())
            .set("corner_rest_area_mm2", plan.rests.iter().map(|c| c.area()).collect::<Vec<_>>())
            .set("corner_rest_at_mm", plan.rests.iter().map(|c| vec![c.corner.x, c.corner.y]).collect::<Vec<_>>())
            .set("corner_rest_largest_thickness_mm", plan.rests.iter().map(|c| c.thickness()).fold(0.0, f64::max))
            .set(
                "corners_unfitted",
                plan.rests
                    .iter()
                    .filter(|c| c.fitted_deg.is_some_and(|e| e > threshold + medial_trochoid::ENGAGEMENT_ROUNDOFF_DEG))
                    .count(),
            )
            .set("offset_only_length_mm", a.program.moves.iter().map(|m| m.seg.length()).sum::<f64>() * layers)
            .set("trochoid_length_mm", (b.program.length(Tag::Trochoid) + b.program.length(Tag::Entry)) * layers)
            .set("contour_length_mm", b.program.length(Tag::Contour) * layers)
            .set("offset_only_feed_mm_min", s_feed(a, Tag::Contour))
            .set("trochoid_feed_min_mm_min", s_feed(b, Tag::Trochoid))
            .set("contour_feed_mm_min", s_feed(b, Tag::Contour))
            .set("output_rows", out_table.rows.len())
            .set("seconds", started.elapsed().as_secs_f64());
        rep.write(path)?;
    }
    if let Some(g) = gouge {
        return Err(Error::check(format!("the program is not written: {g}")));
    }
    if let Some(over) = failed {
        return Err(Error::check(format!(
            "the trochoids-first program is not written: {over}; --allow-over-threshold writes it anyway"
        )));
    }
    out.commit()
}

/// The report keys both strategies share: the program, the tool and threshold, the layers and
/// the pocket's regions.
fn pocket_report(
    program: &str,
    settings: &Settings,
    (z0, layers, depth): (f64, usize, f64),
    regions: &[Region],
) -> Report {
    let mut rep = Report::new("medial-trochoid");
    rep.set("program", program)
        .set("radius_mm", settings.radius)
        .set("threshold_deg", settings.threshold)
        .set("allowance_mm", settings.allowance)
        .set("sample_mm", settings.sample)
        .set("layers", layers)
        .set("layer_depth_mm", depth)
        .set("first_layer_z", z0)
        .set("regions", regions.len())
        .set("islands", regions.iter().map(|g| g.islands.len()).sum::<usize>());
    rep
}

/// The `--strategy adaptive` mode: the adaptive program planned under `planning`, written,
/// read back and simulated again (the report is the written program's).
fn run_adaptive(
    args: &Args,
    regions: &[Region],
    settings: &Settings,
    planning: &Settings,
    (z0, layer_count, layer_depth): (f64, usize, f64),
    (name, (outer_path, outer_line)): (&str, (i64, u64)),
    started: Instant,
) -> Result<()> {
    let r = settings.radius;
    let threshold = settings.threshold;
    let progress = args.io.progress(0, "planning the adaptive passes");
    let planned_at = Instant::now();
    // No pass holds the target anywhere (or the tool fits nowhere): name the first region's boundary.
    let plan =
        medial_trochoid::adaptive::plan_adaptive(regions, planning, args.decimals.map(|d| 10f64.powi(-(d as i32))))
            .map_err(|_| {
                Error::input(format!(
            "path {outer_path}: no adaptive pass holds the threshold anywhere: the tool is too large for the pocket (R + allowance = {} mm)",
            r + settings.allowance
        ))
                    .at(Location::file(name).line(outer_line))
            })?;
    let plan_seconds = planned_at.elapsed().as_secs_f64();
    let a = medial_trochoid::analyse(plan.program.clone(), planning, regions);
    let out_table = to_table(&a, z0, layer_count, layer_depth);
    let mut text = Vec::new();
    table::write(&mut text, &out_table, &WriteOptions { decimals: args.decimals })?;
    progress.stage(0, "simulating the written program again");
    let written = written_check(&text, name, regions, settings)
        .map_err(|e| Error::check(format!("the written program does not read back: {e}")))?;
    progress.finish();
    let w = &written.analysed;
    let (over, links_over) = written.over(threshold);
    let gouge = w.wall_clearance < r + settings.allowance - camkit::tol::OFFSET_TOL;
    let unreachable = medial_trochoid::uncut::unreachable_area(regions, r + settings.allowance);
    if plan.uncut_area > 0.0 {
        cli::warn(&format!(
            "left uncut: about {:.3} mm² ({} grid points) the passes do not reach under the threshold; named in the report",
            plan.uncut_area,
            plan.uncut.len()
        ));
    }
    let mut out = Output::new(args.io.output.as_deref());
    std::io::Write::write_all(&mut out, &text).map_err(|e| Error::io(e, "output"))?;
    if let Some(path) = &args.svg {
        let title = format!(
            "{name}: adaptive, largest engagement {:.1}° (threshold {threshold}°), {:.2} min per layer",
            w.max_cutting, w.minutes
        );
        write_atomic(path, plot::given_plot(&title, regions, w).to_svg(1000.0).as_bytes())?;
    }
    if let Some(path) = &args.io.report {
        let layers = layer_count as f64;
        let len = |t: Tag| w.program.length(t) * layers;
        let mut rep = pocket_report("adaptive", settings, (z0, layer_count, layer_depth), regions);
        rep.set("passes_per_layer", plan.passes)
            .set("retracts_per_layer", plan.retracts)
            .set("largest_engagement_deg", w.max_cutting)
            .set("link_engagement_deg", w.max_link)
            .set("entry_engagement_deg", w.max_entry)
            .set("threshold_held", over + links_over == 0)
            .set("planned_threshold_deg", planning.threshold)
            .set("samples_over_threshold", over)
            .set("link_samples_over_threshold", links_over)
            .set("samples", w.samples.len())
            .set("smallest_wall_clearance_mm", w.wall_clearance)
            .set("no_gouge", !gouge)
            .set("rounding_reach_mm", rounding_reach(args.decimals))
            .set("adaptive_minutes", w.minutes * layers)
            .set("adaptive_constant_feed_minutes", w.minutes_constant * layers)
            .set("adaptive_chip_only_minutes", w.minutes_chip_only * layers)
            .set("adaptive_constant_feed_chip_only_minutes", w.minutes_constant_chip_only * layers)
            .set("time_by_kind", Breakdown::of(w, threshold).to_json(layers))
            .set("force_limit_at_deg", settings.feed.force_at)
            .set("length_mm", w.program.moves.iter().map(|m| m.seg.length()).sum::<f64>() * layers)
            .set("contour_length_mm", len(Tag::Contour))
            .set("link_length_mm", len(Tag::Link))
            .set("entry_length_mm", len(Tag::Entry))
            .set("contour_feed_mm_min", s_feed(w, Tag::Contour))
            .set("uncut_area_mm2", plan.uncut_area)
            .set("uncut_points", plan.uncut.len())
            .set(
                "uncut_at",
                plan.uncut
                    .iter()
                    .step_by(plan.uncut.len().div_ceil(50).max(1))
                    .map(|p| vec![p.x, p.y])
                    .collect::<Vec<_>>(),
            )
            .set("unreachable_area_mm2", unreachable)
            .set("output_rows", out_table.rows.len())
            .set("plan_seconds", plan_seconds)
            .set("seconds", started.elapsed().as_secs_f64());
        rep.write(path)?;
    }
    if gouge {
        return Err(Error::check(format!(
            "the program is not written: the program as written comes {:.6} mm from the walls, under R + allowance = {} mm",
            w.wall_clearance,
            r + settings.allowance
        )));
    }
    if over + links_over > 0 && !args.allow_over_threshold {
        return Err(Error::check(format!(
            "the adaptive program is not written: as written it has {over} cutting and {links_over} link samples over the threshold (largest {:.3}° cutting, {:.3}° on links); --allow-over-threshold writes it anyway",
            w.max_cutting, w.max_link
        )));
    }
    out.commit()
}

/// The `--analyse` mode: the given toolpath re-simulated in `regions`, written with its
/// engagement, and its figures in the report.
fn analyse_given(
    path: &std::path::Path,
    regions: &[Region],
    s: &Settings,
    args: &Args,
    started: Instant,
) -> Result<()> {
    let input = Input::open(&path.to_string_lossy())?;
    let name = input.name.clone();
    let table = table::read(&input, &[Col::X, Col::Y, Col::Z])?;
    let given = medial_trochoid::given::read(&table, &name)?;
    if given.program.moves.is_empty() {
        return Err(
            Error::input("no feed move at the toolpath's lowest z: nothing to analyse").at(Location::file(&name))
        );
    }
    let samples = medial_trochoid::budget::given_samples(&given.program, s.sample);
    let what = format!("the analysis of {name} (--sample {} mm)", cli::short(s.sample));
    camkit::budget::check_memory(
        medial_trochoid::budget::given_memory(samples),
        camkit::budget::bytes_of(args.max_memory),
        &what,
        "coarsen --sample",
    )?;
    camkit::budget::check_work(
        samples,
        positive(args.max_work, "--max-work")?,
        "engagement samples",
        &what,
        "coarsen --sample",
    )?;
    let progress = args.io.progress(0, "simulating the given toolpath");
    let a = medial_trochoid::analyse(given.program.clone(), s, regions);
    progress.finish();
    let out_table = to_table(&a, given.depth, 1, 0.0);
    let mut out = Output::new(args.io.output.as_deref());
    table::write(&mut out, &out_table, &WriteOptions { decimals: args.decimals })?;
    if let Some(svg) = &args.svg {
        let title = format!(
            "{name}: given toolpath, largest engagement {:.1}° (threshold {}°), {:.2} min",
            a.max_cutting, s.threshold, a.minutes
        );
        write_atomic(svg, plot::given_plot(&title, regions, &a).to_svg(1000.0).as_bytes())?;
    }
    if let Some(report) = &args.io.report {
        let mut rep = Report::new("medial-trochoid");
        rep.set("program", "given")
            .set("analysed", name.as_str())
            .set("radius_mm", s.radius)
            .set("threshold_deg", s.threshold)
            .set("allowance_mm", s.allowance)
            .set("sample_mm", s.sample)
            .set("depth_mm", given.depth)
            .set("moves", a.program.moves.len())
            .set("chains", given.chains)
            .set("samples", a.samples.len())
            .set("largest_engagement_deg", a.max_cutting)
            .set("link_engagement_deg", a.max_link)
            .set("entry_engagement_deg", a.max_entry)
            .set("samples_over_threshold", a.over)
            .set("link_samples_over_threshold", a.over_links)
            .set("threshold_held", a.over + a.over_links == 0)
            .set("length_mm", a.program.moves.iter().map(|m| m.seg.length()).sum::<f64>())
            .set("entry_length_mm", a.program.length(Tag::Entry))
            .set("air_length_mm", given.air_length)
            .set("smallest_wall_clearance_mm", a.wall_clearance)
            .set("no_gouge", a.wall_clearance >= s.radius + s.allowance - camkit::tol::OFFSET_TOL)
            .set("minutes", a.minutes)
            .set("constant_feed_minutes", a.minutes_constant)
            .set("force_limit_at_deg", s.feed.force_at)
            .set("chip_only_minutes", a.minutes_chip_only)
            .set("constant_feed_chip_only_minutes", a.minutes_constant_chip_only)
            .set("time_by_kind", Breakdown::of(&a, s.threshold).to_json(1.0))
            .set("output_rows", out_table.rows.len())
            .set("seconds", started.elapsed().as_secs_f64());
        rep.write(report)?;
    }
    out.commit()
}

/// How far (mm) rounding to `decimals` may move a written path: a point by half a unit in x and
/// in y (√2/2 units), an arc by three times that (its centre moved, its radius taken from its
/// moved start). Zero when positions are written exactly.
fn rounding_reach(decimals: Option<u32>) -> f64 {
    decimals.map_or(0.0, |d| 1.5 * std::f64::consts::SQRT_2 * 10f64.powi(-(d as i32)))
}

/// How much (degrees) rounding to `decimals` may raise an engagement near the threshold θ: a
/// side cut's engagement acos(1 − s/R) changes by ds/(R sin θ) with its step over s, which the
/// rounding of this path and of the one before changes by up to twice [`rounding_reach`]. The
/// plan is made under the threshold by this much.
fn rounding_slack_deg(decimals: Option<u32>, r: f64, threshold: f64) -> f64 {
    let sin = threshold.to_radians().sin().max(0.1);
    (2.0 * rounding_reach(decimals) / (r * sin)).to_degrees()
}

/// A written program read back and simulated again.
struct Written {
    /// The simulation of the written program's (lowest) layer.
    analysed: Analysed,
}

impl Written {
    /// Samples of cutting moves (trochoids and passes) and of links over `limit` (degrees).
    fn over(&self, limit: f64) -> (usize, usize) {
        let a = &self.analysed;
        let count = |tags: &[Tag]| {
            a.samples
                .iter()
                .zip(&a.engagement)
                .filter(|((i, _), e)| tags.contains(&a.program.moves[*i].tag) && **e > limit + ENGAGEMENT_ROUNDOFF_DEG)
                .count()
        };
        (count(&[Tag::Trochoid, Tag::Contour]), count(&[Tag::Link]))
    }
}

/// The written table `text` read back as `--analyse` reads a given toolpath and simulated in
/// `regions` (the input's: the gouge check is against its walls).
fn written_check(text: &[u8], name: &str, regions: &[Region], s: &Settings) -> Result<Written> {
    let input = Input { name: format!("{name} (the written program)"), data: text.to_vec() };
    let table = table::read(&input, &[Col::X, Col::Y, Col::Z])?;
    let given = medial_trochoid::given::read(&table, &input.name)?;
    Ok(Written { analysed: medial_trochoid::analyse(given.program, s, regions) })
}

/// Slowest feed of the samples of moves with `tag` (0 if none).
fn s_feed(a: &Analysed, tag: Tag) -> f64 {
    a.samples
        .iter()
        .zip(&a.feeds)
        .filter(|((i, _), _)| a.program.moves[*i].tag == tag)
        .map(|(_, f)| *f)
        .reduce(f64::min)
        .unwrap_or(0.0)
}

/// Smallest and largest of `v` (empty if none).
fn range(v: impl Iterator<Item = f64>) -> Vec<f64> {
    let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
    if lo <= hi { vec![lo, hi] } else { Vec::new() }
}

/// For each move, where it starts along its helical entry's descent and how much of the descent
/// it is (fractions of the descent's length; zeros for other moves). An entry of several loops
/// (a chain of entry moves that comes back to its start before its end: [`Entry::loops`])
/// descends over all but its last loop, which is cut at the layer's depth (fraction 1, none).
fn helix_fractions(a: &Analysed) -> Vec<(f64, f64)> {
    let moves = &a.program.moves;
    let mut out = vec![(0.0, 0.0); moves.len()];
    let mut i = 0;
    while i < moves.len() {
        if moves[i].tag != Tag::Entry {
            i += 1;
            continue;
        }
        let mut j = i + 1;
        while j < moves.len() && moves[j].tag == Tag::Entry && !moves[j].retract_before {
            j += 1;
        }
        let start = moves[i].seg.start();
        let per_loop =
            (i..j).position(|k| (moves[k].seg.end() - start).norm() <= camkit::tol::POINT_EPS).map_or(j - i, |k| k + 1);
        let down = if j - i > per_loop { j - per_loop } else { j };
        let total: f64 = moves[i..down].iter().map(|m| m.seg.length()).sum();
        let mut cum = 0.0;
        for k in i..down {
            let l = moves[k].seg.length() / total;
            out[k] = (cum, l);
            cum += l;
        }
        out[down..j].iter_mut().for_each(|f| *f = (1.0, 0.0));
        i = j;
    }
    out
}

/// The program as table rows: one row per sample, a rapid row where a chain starts, repeated
/// for every layer.
fn to_table(a: &Analysed, z0: f64, layers: usize, depth: f64) -> Table {
    let mut t = Table {
        schema: Schema::of(&[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::Xc, Col::Yc, Col::F, Col::Tag]),
        rows: Vec::new(),
    };
    let k = t.add_extra_column("engagement");
    let helix = helix_fractions(a);
    let mut path = 0i64;
    for layer in 0..layers {
        let z = z0 - layer as f64 * depth;
        let mut last_t = 0.0;
        let mut last_i = usize::MAX;
        for (k_sample, (&(i, tt), &e)) in a.samples.iter().zip(&a.engagement).enumerate() {
            let m = &a.program.moves[i];
            if i != last_i {
                last_t = 0.0;
                if m.retract_before {
                    path += 1;
                    let s = m.seg.start();
                    let top = if m.tag == Tag::Entry { z + depth } else { z };
                    let mut row = Row::at(path, P3::new(s.x, s.y, top));
                    row.mv = Move::Rapid;
                    row.tag = m.tag.name().into();
                    row.extra = vec![String::new(); k + 1];
                    t.rows.push(row);
                }
                last_i = i;
            }
            let piece = m.seg.sub(last_t, tt);
            let q = piece.end();
            let (f0, df) = helix[i];
            // The descent's share still to go, exactly 0 at its end (not the sum's roundoff).
            let to_go = 1.0 - f0 - df * tt;
            let zq = if m.tag == Tag::Entry && to_go > 1e-9 { z + depth * to_go } else { z };
            let mut row = Row::at(path, P3::new(q.x, q.y, zq));
            if let Seg::Arc(arc) = piece {
                row.mv = if arc.ccw() { Move::Ccw } else { Move::Cw };
                row.centre = Some(P2::new(arc.c.x, arc.c.y));
            }
            row.f = Some(a.feeds[k_sample]);
            row.tag = m.tag.name().into();
            row.extra = vec![String::new(); k + 1];
            row.extra[k] = format!("{e:.3}");
            t.rows.push(row);
            last_t = tt;
        }
    }
    t
}
