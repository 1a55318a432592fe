//! `offset`: gouge-free tool-radius offsets of line/arc contours.

use camkit::cli::{self, IoArgs, Kind, positive};
use camkit::contour::OffsetOptions;
use camkit::contour::load::{ContourArgs, InputKind};
use camkit::contour::offset::Side;
use camkit::contour::pocket::{Direction, PocketOptions};
use camkit::error::{Error, Location, Result};
use camkit::io::{Input, Output, write_atomic};
use camkit::table::{self, Col, WriteOptions};
use clap::{Parser, ValueEnum};
use offset::profile::Tool;
use offset::{Outcome, Up, space};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ToolArg {
    /// Ball end mill: tip = normal offset by R, lowered by R.
    Ball,
    /// Square (flat) end mill: flat bottom lowered onto the profile.
    Square,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum UpArg {
    /// Tool axis +y (profile in xy, as the paper draws it).
    Y,
    /// Tool axis +z (profile in xz or yz, as a 3-axis machine cuts it).
    Z,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum DirArg {
    /// Material on the right of travel (spindle M3): boundaries counter-clockwise.
    Climb,
    /// The reverse.
    Conventional,
}

#[derive(Parser, Debug)]
#[command(
    name = "offset",
    version,
    allow_negative_numbers = true,
    about = "Gouge-free tool-radius offsets of line/arc contours: pockets with islands, tool-shape profiles, 3D contours.",
    long_about = "Offset line/arc contours by the tool radius (papers 004 §3-4 and 002 §4.3). Arcs stay arcs; \
invalid loops are removed. Every result is verified with exact distances: each output point lies within 1e-6 mm of \
distance R from the input, none closer, on the requested side, with nothing valid missing. Modes: contour (default, \
--side), pocket (--repeat N / --until-empty, with --step), profile (--profile ball|square), 3D (--3d).",
    after_help = after_help()
)]
struct Args {
    #[command(flatten)]
    io: IoArgs,
    /// Tool radius R (mm).
    #[arg(long, value_name = "MM")]
    radius: f64,
    /// Side of the direction of travel: left (G41, the paper's -1) or right (G42, +1).
    #[arg(long, value_name = "SIDE")]
    side: Option<String>,
    /// Pocket: this many contour-parallel passes (1 = the tool-radius offset of the regions).
    #[arg(long, value_name = "N")]
    repeat: Option<usize>,
    /// Pocket: passes until nothing is left, with a clean-up pass where a centre stays uncut.
    #[arg(long)]
    until_empty: bool,
    /// Pocket: step over between passes (mm); default the tool radius.
    #[arg(long, value_name = "MM")]
    step: Option<f64>,
    /// Pocket: cutting direction.
    #[arg(long, value_enum, default_value_t = DirArg::Climb)]
    direction: DirArg,
    /// Profile mode: the profile is cut from above by this tool.
    #[arg(long, value_enum, value_name = "TOOL")]
    profile: Option<ToolArg>,
    /// Profile mode: the axis pointing up along the tool.
    #[arg(long, value_enum, default_value_t = UpArg::Z)]
    up: UpArg,
    /// Profile mode: depth (mm) beyond which the unoffset square end mill counts as cutting through.
    #[arg(long, default_value_t = 0.01, value_name = "MM")]
    gouge_tol: f64,
    /// 3D mode: offset normal to each row's tool axis (i,j,k).
    #[arg(long = "3d")]
    three_d: bool,
    /// 3D mode: look-ahead along the contour on each side of a row (mm); default 4 R, doubled
    /// while the result comes nearer than R to its own contour (up to the contour's length).
    #[arg(long, value_name = "MM")]
    window: Option<f64>,
    /// 3D mode: largest distance beyond R of a point around a convex corner (mm).
    #[arg(long, default_value_t = 0.001, value_name = "MM")]
    chord_tol: f64,
    /// Accept self-crossing contours (contour mode): the kernel resolves the crossings; a closed
    /// one gives what the tool can cut on that side (loops, and open stretches that end where
    /// they would gouge).
    #[arg(long)]
    allow_self_crossing: bool,
    #[command(flatten)]
    contours: ContourArgs,
    /// Output format: the table (the only one: `offset | post-6axis --setup` makes the program,
    /// with linked, collision-checked passes).
    #[arg(long, value_enum, default_value_t = Kind::Table)]
    to: Kind,
    /// Feed (mm/min) for rows that have none.
    #[arg(long, value_name = "MM/MIN")]
    feed: Option<f64>,
    /// Decimals of written positions (table: exact by default; G-code: 4).
    #[arg(long, value_name = "N")]
    decimals: Option<u32>,
    /// Write an SVG of the input and the offset.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// Largest memory a run may hold (MB), estimated from the input and --step, --repeat or
    /// --chord-tol before offsetting; larger runs are refused (exit 2).
    #[arg(long, default_value_t = camkit::budget::DEFAULT_MEMORY_MB, value_name = "MB")]
    max_memory: u64,
}

fn after_help() -> String {
    let mut s = table::columns::help_text(
        &[
            Col::Path,
            Col::Move,
            Col::X,
            Col::Y,
            Col::Z,
            Col::Xc,
            Col::Yc,
            Col::Zc,
            Col::Plane,
            Col::I,
            Col::J,
            Col::K,
            Col::F,
            Col::Tag,
        ],
        &[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::Xc, Col::Yc, Col::Px, Col::Py, Col::Pz],
    );
    s.push_str("  offset mm                 the pass's offset distance from the input\n");
    s.push_str(
        "Each path is one contour (closed when it ends where it starts); a rapid row inside a path starts a new one.\n",
    );
    s.push_str(
        "Other columns pass through from the first row of the contour (3D mode: from the row each point comes from).\n",
    );
    s.push_str(&camkit::contour::load::help_text());
    s.push('\n');
    s.push_str("\nExit status: 0 done (also when an offset leaves nothing: a warning says so), 1 a check failed, 2 bad input or usage.");
    s
}

fn main() -> ExitCode {
    cli::run("offset", || run(cli::parse::<Args>()?))
}

fn side(args: &Args, needed: bool) -> Result<Side> {
    match args.side.as_deref().map(|s| s.trim().to_ascii_lowercase()) {
        None if needed => {
            Err(Error::input("--side is needed: left (G41, -1) or right (G42, +1) of the direction of travel"))
        }
        None => Ok(Side::Left),
        Some(s) => match s.as_str() {
            "left" | "l" | "-1" | "g41" => Ok(Side::Left),
            "right" | "r" | "+1" | "1" | "g42" => Ok(Side::Right),
            other => Err(Error::input(format!("--side must be left, right, -1 or +1, got {other}"))),
        },
    }
}

fn run(args: Args) -> Result<()> {
    let started = Instant::now();
    let r = positive(args.radius, "--radius")?;
    if args.to == Kind::Gcode {
        return Err(Error::input(
            "offset writes the toolpath table: post it for a machine with `offset ... | post-6axis --machine M --setup S`, which links the passes (retract, traverse, approach, plunge) and checks the program against the stock and the part",
        ));
    }
    if let Some(f) = args.feed {
        positive(f, "--feed")?;
    }
    if args.decimals.is_some_and(|d| d > 12) {
        return Err(Error::input("--decimals must be at most 12"));
    }
    let pocketing = args.repeat.is_some() || args.until_empty;
    let modes = usize::from(pocketing) + usize::from(args.profile.is_some()) + usize::from(args.three_d);
    if modes > 1 {
        return Err(Error::input("choose one mode: pocket (--repeat/--until-empty), --profile or --3d"));
    }
    if args.repeat == Some(0) {
        return Err(Error::input("--repeat must be at least 1"));
    }
    let contour_opts = args.contours.options(true)?;
    let input = Input::open(&args.io.input)?;
    let mut table = if contour_opts.from.resolve(&input) == InputKind::Gcode {
        let text = input.text()?.to_string();
        if text.trim().is_empty() {
            return Err(Error::input("empty input: no G-code").at(Location::file(&input.name)));
        }
        camkit::gcode::program_to_table(&camkit::gcode::read(&input.name, text)?).0
    } else {
        let (table, skipped) = camkit::contour::load::table(&input, &contour_opts)?;
        if let Some((kind, line)) = skipped.first() {
            cli::warn(&format!(
                "{}: {} entities that are not contours skipped (the first: {kind} at line {line})",
                input.name,
                skipped.len()
            ));
        }
        table
    };
    if table.rows.is_empty() {
        return Err(Error::input("no rows: nothing to offset").at(Location::file(&input.name)));
    }
    if let Some(f) = args.feed {
        for row in table.rows.iter_mut().filter(|r| r.f.is_none()) {
            row.f = Some(f);
        }
        table.schema.add(&[Col::F]);
    }
    let opts = OffsetOptions { self_crossing_input: args.allow_self_crossing, ..OffsetOptions::default() };
    let name = input.name.clone();
    let progress = args.io.progress(0, "offsetting and verifying");
    let outcome: Outcome = if pocketing {
        let step = positive(args.step.unwrap_or(r), "--step")?;
        if step > 2.0 * r {
            cli::warn(&format!("--step {step} mm is more than the tool's diameter: material stays between passes"));
        }
        let direction = if args.direction == DirArg::Climb { Direction::Climb } else { Direction::Conventional };
        let p = PocketOptions {
            radius: r,
            step,
            passes: offset::passes(args.repeat, args.until_empty),
            direction,
            offset: opts,
        };
        camkit::budget::check_memory(
            offset::budget::pocket(&table, &p),
            camkit::budget::bytes_of(args.max_memory),
            &format!("the pocket at --step {} mm", cli::short(step)),
            "coarsen --step, ask fewer passes (--repeat)",
        )?;
        offset::pocket_mode(&table, &name, &p)?
    } else if let Some(tool) = args.profile {
        let tool = if tool == ToolArg::Ball { Tool::Ball } else { Tool::Square };
        let up = if args.up == UpArg::Y { Up::Y } else { Up::Z };
        offset::profile_mode(&table, &name, tool, r, up, positive(args.gouge_tol, "--gouge-tol")?, &opts)?
    } else if args.three_d {
        let window = positive(args.window.unwrap_or(4.0 * r), "--window")?;
        let o = space::Options {
            radius: r,
            side: side(&args, true)?,
            window,
            chord_tol: positive(args.chord_tol, "--chord-tol")?,
            offset: opts,
        };
        camkit::budget::check_memory(
            offset::budget::space(table.rows.len(), &o),
            camkit::budget::bytes_of(args.max_memory),
            &format!("the 3D offset at --chord-tol {} mm", cli::short(o.chord_tol)),
            "raise --chord-tol",
        )?;
        offset::space_mode(&table, &name, &o, args.window.is_none())?
    } else {
        offset::contour_mode(&table, &name, r, side(&args, true)?, &opts)?
    };
    progress.finish();
    for w in &outcome.warnings {
        cli::warn(w);
    }
    let mut out = Output::new(args.io.output.as_deref());
    table::write(&mut out, &outcome.table, &WriteOptions { decimals: args.decimals })?;
    if let Some(path) = &args.svg {
        write_atomic(path, outcome.plot.to_svg(1000.0).as_bytes())?;
    }
    if let Some(path) = &args.io.report {
        let mut report = outcome.report;
        report.set("seconds", started.elapsed().as_secs_f64()).set("output_rows", outcome.table.rows.len());
        report.write(path)?;
    }
    out.commit()
}
