//! `post-6axis`: CL rows to NC for a machine described in JSON, checked by reading the NC back.

use camkit::cli::{self, IoArgs, positive};
use camkit::collide::solid::{Body, Solid};
use camkit::collide::walls::Walls;
use camkit::doc::Frame;
use camkit::doc::Setup;
use camkit::doc::machine::Machine;
use camkit::doc::setup::{Job, Part};
use camkit::error::{Error, Location, Result};
use camkit::gcode::{AxisBlocks, read_axes};
use camkit::io::{Input, Output, RecordSpool, Records, Source, Spooled, Stream, write_atomic};
use camkit::kinematics::Chain;
use camkit::report::Report;
use camkit::table::meaning::{self, Meaning};
use camkit::table::{self, Col, WriteOptions};
use clap::Parser;
use post_6axis::plan::Cl;
use post_6axis::readback::{NcPose, Program};
use post_6axis::{ClReader, Settings, collision, judge, link, plot, post, readback};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(
    name = "post-6axis",
    version,
    allow_negative_numbers = true,
    about = "Post-process CL rows (tool tip, tool axis, spindle orientation) into NC for a 3-, 5- or 6-axis machine.",
    long_about = "Post-process CL rows (tool tip x,y,z, tool axis i,j,k, spindle orientation s, feed f) into NC \
for the machine described by --machine (papers 002 §4 and 000 §3.2). Each row's pose is solved by inverse \
kinematics (both branches; over the whole program, the sequence inside the limits with the least rotary \
move that keeps to one branch within each pass), blocks are inserted until \
the controller's linear interpolation keeps the tip within --tol of the straight CL segment and the axis \
within --angle-tol, and the written program is read back through the forward kinematics before it is \
delivered: a program that fails the check is not written. --verify compares an existing program with the \
rows; --reverse turns a program back into the toolpath table. A stream of stylus centres (column point = \
stylus-centre, as stylus-trace -r writes) is refused: tool-attitude turns it into tips.",
    after_help = after_help()
)]
struct Args {
    #[command(flatten)]
    io: IoArgs,
    /// The machine document (JSON): chain, limits, spindle, dialect.
    #[arg(long, short = 'm', value_name = "FILE")]
    machine: String,
    /// The workpiece frame document (JSON, `xc, yc, za`), e.g. from surf-probe-fit; overrides the
    /// machine document's `frame`.
    #[arg(long, value_name = "FILE")]
    frame: Option<String>,
    /// Largest distance (mm) of the interpolated tool tip from the straight CL segment.
    #[arg(long, default_value_t = 0.005, value_name = "MM")]
    tol: f64,
    /// Largest angle (degrees) of the interpolated tool axis from the CL axis.
    #[arg(long, default_value_t = 0.05, value_name = "DEG")]
    angle_tol: f64,
    /// Largest error (degrees) of the spindle orientation of a non-rotating tool.
    #[arg(long, default_value_t = 0.5, value_name = "DEG")]
    spindle_tol: f64,
    /// Feed (mm/min) for rows without an f value.
    #[arg(long, value_name = "MM/MIN")]
    feed: Option<f64>,
    /// Radius (mm) at which a rotary move counts as path length for inverse-time feed.
    #[arg(long, default_value_t = 10.0, value_name = "MM")]
    rotary_radius: f64,
    /// Compare the program FILE with the CL rows of INPUT: largest tip, axis and spindle
    /// deviations, written as JSON on standard output. Exit 1 if beyond the tolerances.
    #[arg(long, value_name = "NC", conflicts_with = "reverse")]
    verify: Option<String>,
    /// INPUT is an NC program: write it back as the toolpath table.
    #[arg(long)]
    reverse: bool,
    /// The job's setup document (JSON: stock, part, heights, plunge, leads, tool): the passes are
    /// linked (retract, traverse, approach, plunge or ramp, lead arcs), the header takes the tool's number, spindle speed
    /// and feeds, and the written program is checked for collisions before it is delivered.
    #[arg(long, value_name = "FILE")]
    setup: Option<String>,
    /// Check the program FILE (any NC this machine's reader reads) for collisions against
    /// --setup, as the post checks its own: the report (JSON) on standard output, exit 1 naming
    /// the first block that comes too near the material or the part. INPUT is not read.
    #[arg(long, value_name = "NC", requires = "setup", conflicts_with_all = ["verify", "reverse"])]
    check: Option<String>,
    /// Write an SVG of the program (the one written, or with --reverse the one read): the tool
    /// tip of every block read back, top view and side views, rapids dashed, plunges/ramps,
    /// leads, links at feed and cuts in their own colours, G2/G3 as arcs in their plane's view.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["verify", "check"])]
    svg: Option<PathBuf>,
    /// Write the program even when the collision check finds a rapid into material or a move
    /// nearer the part than allowed (a warning; the report names them).
    #[arg(long, requires = "setup")]
    allow_collision: bool,
}

fn after_help() -> String {
    let mut s = table::columns::help_text(
        &[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::I, Col::J, Col::K, Col::S, Col::F],
        &[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::I, Col::J, Col::K, Col::S, Col::F],
    );
    s.push_str("(--reverse writes the table; otherwise the output is NC.)\n\n");
    s.push_str("Machine document: docs/formats.md#post-6axis; examples in data/post-6axis/.\n");
    s.push_str(
        "\nExit status: 0 done, 1 the read-back check failed, 2 bad input (a pose outside the limits included).",
    );
    s
}

fn main() -> ExitCode {
    cli::run("post-6axis", || run(cli::parse::<Args>()?))
}

/// A number as typed for a message: plain, or in exponent form when plain would run to dozens of
/// digits.
fn short(v: f64) -> String {
    if v != 0.0 && !(1e-6..1e9).contains(&v.abs()) { format!("{v:e}") } else { v.to_string() }
}

fn load_machine(args: &Args) -> Result<(Machine, Chain)> {
    let (machine, mut chain) = Machine::read(&args.machine)?;
    if let Some(path) = &args.frame {
        let frame = Frame::read(path)?;
        chain = chain.with_frame(frame.offset());
    }
    Ok((machine, chain))
}

/// The machine's program header made to the job: the tool's number (required), spindle speed
/// and the setup's coolant.
fn with_job(mut machine: Machine, job: &Job) -> Result<Machine> {
    let Some(number) = job.tool.number else {
        let e = Error::input("the tool has no `number`: the program needs it for T and H")
            .at(Location::file(&job.tool_file).field("number"));
        // Where the tool's object begins (the field is missing): file:line:col as for any value.
        return Err(match camkit::io::Input::open(&job.tool_file) {
            Ok(input) => camkit::json::at_value(&input, e),
            Err(_) => e,
        });
    };
    machine.program.tool = Some(number);
    machine.program.spindle_speed = job.tool.spindle_speed;
    machine.program.coolant = job.coolant;
    Ok(machine)
}

fn run(args: Args) -> Result<()> {
    let started = Instant::now();
    let job = args.setup.as_deref().map(Setup::read).transpose()?;
    if let Some(j) = job.as_ref().filter(|j| j.tool.kind == camkit::doc::ToolKind::Cone) {
        // The stock model cuts as a flat end mill would: it would count a cone's V groove as a
        // full-width slot and pass rapids through stock still standing.
        return Err(j.error(
            "tool",
            format!(
                "{} is a cone cutter: linking and the collision check model the stock a flat, ball or bull-nose end mill leaves, not a cone's; post its passes without --setup (they are not linked) or with one of those tools",
                j.tool_file
            ),
        ));
    }
    let (machine, chain) = load_machine(&args)?;
    let within = |v: f64, (lo, hi): (f64, f64), what: &str| {
        positive(v, what).and_then(|v| match v {
            v if (lo..=hi).contains(&v) => Ok(v),
            _ => Err(Error::input(format!("{what} must be from {lo} to {hi}, got {}", short(v)))),
        })
    };
    let feed_range = post_6axis::feed_range(&machine);
    let settings = Settings {
        tol: positive(args.tol, "--tol")?,
        angle_tol: positive(args.angle_tol, "--angle-tol")?,
        spindle_tol: positive(args.spindle_tol, "--spindle-tol")?,
        rotary_radius: within(args.rotary_radius, (0.0, post_6axis::MAX_ROTARY_RADIUS), "--rotary-radius")?,
        feed: match args.feed {
            Some(f) => Some(within(f, feed_range, "--feed")?),
            None => match job.as_ref().and_then(|j| Some((j, j.tool.cutting_feed()?))) {
                Some((j, f)) => Some(
                    within(f, feed_range, "the tool's cutting feed").map_err(|e| e.at(Location::file(&j.tool_file)))?,
                ),
                None => None,
            },
        },
    };
    if let Some(j) = &job {
        // The setup's plunge feed (or the tool's) is written too: F0 below the range.
        within(j.plunge_feed, feed_range, "the plunge feed").map_err(|e| j.error("plunge.feed", e.message))?;
    }
    let machine = match &job {
        Some(j) => with_job(machine, j)?,
        None => machine,
    };
    let mut out = Output::new(args.io.output.as_deref());
    let mut report = Report::new("post-6axis");
    report
        .set("machine", &machine.name)
        .set("family", chain.family().name())
        .set("dialect", format!("{:?}", machine.dialect).to_lowercase());
    if let (Some(nc), Some(j)) = (&args.check, &job) {
        let nc_input = Input::open(nc)?;
        let text = nc_input.text()?;
        for block in AxisBlocks::new(&nc_input.name, text.as_bytes()) {
            block?;
        }
        report.set("program", &nc_input.name);
        let walls = walls_of(j);
        let solid = solid_of(j)?;
        let parts = (walls.as_ref(), solid.as_ref().map(|(s, b)| (s, b)));
        let open = || Box::new(text.as_bytes()) as Box<dyn std::io::BufRead + '_>;
        let program = Program { open: &open, name: &nc_input.name };
        let failed = collide(program, &machine, &chain, j, parts, &args, &mut report);
        out.buf = report.to_json().into_bytes();
        finish(out, &args, report)?;
        return failed;
    }
    if args.reverse {
        let input = Input::open(&args.io.input)?;
        let text = input.text()?;
        let program = read_axes(&input.name, text)?;
        let reading = readback::Reading::new(&machine, &chain);
        let poses = readback::poses(&program, &reading);
        let t = readback::reverse(&poses, &reading);
        if t.rows.is_empty() {
            return Err(Error::input("no motion blocks in the program").at(Location::file(&input.name)));
        }
        report.set("blocks", program.moves.len()).set("rows", t.rows.len());
        if let Some(path) = &args.svg {
            let title = format!("{}: {} blocks on {}", input.name, program.moves.len(), machine.name);
            write_atomic(path, plot::plot(&title, &poses, &reading).to_svg(1200.0).as_bytes())?;
        }
        table::write(&mut out, &t, &WriteOptions::default())?;
        return finish(out, &args, report);
    }
    // The first reading: the rows checked as CL rows as they come from the file (standard input
    // copied to a temporary file), neither the table's rows nor its text held; the rows kept, on
    // disk, only where no linking follows (that reads them again).
    let input = Source::open(&args.io.input)?;
    let keep = job.is_none() || args.verify.is_some();
    let mut given = RecordSpool::<Cl>::new();
    let mut outside = None;
    let mut passes = 0;
    let mut meaning = None;
    let mut reader = None;
    let schema = table::read_each_source(&input, &[Col::X, Col::Y], |schema, row| {
        let check = meaning.get_or_insert_with(|| meaning::Check::new(schema));
        check.row(&row, &input.name)?;
        if let Meaning::StylusCentre(r) = check.meaning() {
            return Err(Error::input(format!(
                "the stream's x,y,z are the centres of a stylus of radius {r} mm (column point = stylus-centre), not tool tips: the program would cut {r} mm in the air; run tool-attitude on it first"
            ))
            .at(Location::file(&input.name).line(row.line).field(meaning::POINT)));
        }
        let r = match &mut reader {
            Some(r) => r,
            None => reader.insert(ClReader::new(schema, &input.name, &chain, &machine, settings.feed, settings.tol)?),
        };
        let cl = r.row(&row)?;
        if let Some(j) = &job
            && outside.is_none()
        {
            outside = link::outside_stock(j, &input.name, &cl);
        }
        passes += usize::from(cl.rapid);
        if keep {
            given.push(&cl);
        }
        Ok(())
    })?;
    let (normalised, count) = match reader {
        Some(r) => (r.normalised, r.rows),
        None => {
            ClReader::new(&schema, &input.name, &chain, &machine, settings.feed, settings.tol)?;
            return Err(Error::input("no rows: nothing to post").at(Location::file(&input.name)));
        }
    };
    if normalised > 0 {
        cli::warn(&format!("{normalised} tool axes were not unit vectors (within 1e-3): normalised"));
    }
    let given = given.finish();
    if let Some(nc) = &args.verify {
        let nc_input = Input::open(nc)?;
        let text = nc_input.text()?;
        let open = || Box::new(text.as_bytes()) as Box<dyn std::io::BufRead + '_>;
        let program = Program { open: &open, name: &nc_input.name };
        let reading = readback::Reading::new(&machine, &chain);
        let mut any = false;
        for pose in program.poses(&reading) {
            any |= pose?.is_some();
        }
        if !any {
            // Nothing to compare: every row would be "missed" by an infinite distance.
            return Err(Error::input("the program has no motion blocks (in workpiece coordinates, every axis known)")
                .at(Location::file(&nc_input.name)));
        }
        let d = readback::verify(&given, program, &reading, 32, settings.tol, settings.angle_tol)?;
        deviation_keys(&mut report, &d);
        report.set("rows", count).set("tol_mm", settings.tol).set("angle_tol_deg", settings.angle_tol);
        out.buf = report.to_json().into_bytes();
        finish(out, &args, report)?;
        return judge(&d, &given.view(), &machine, &settings).map_err(|e| Error::check(format!("{nc}: {}", e.message)));
    }
    let mut comments = vec![
        format!("post-6axis {}: {}", env!("CARGO_PKG_VERSION"), machine.name),
        format!("{} machine, {} rows from {}", chain.family().name(), count, input.name),
        format!("tolerance {} mm, {} deg", settings.tol, settings.angle_tol),
    ];
    let walls = job.as_ref().and_then(walls_of);
    let solid = job.as_ref().map(solid_of).transpose()?.flatten();
    let solid_ref = solid.as_ref().map(|(s, b)| (s, b));
    let link_started = Instant::now();
    let progress = args.io.progress(0, "linking the passes");
    let rows = match &job {
        Some(j) => {
            let linker = link::Linker::new(j, walls.as_ref(), solid_ref, &input.name)?;
            if let Some(e) = outside {
                return Err(e);
            }
            let (linked, stats) = link_rows(&input, linker, &chain, &machine, &settings)?;
            report.set("link_seconds", link_started.elapsed().as_secs_f64());
            comments.push(format!(
                "setup {}: tool T{} from {}, clearance Z{} safe Z{} approach {} mm",
                j.file,
                j.tool.number.unwrap_or(0),
                j.tool_file,
                j.clearance_height,
                j.safe_height,
                j.approach
            ));
            link_keys(&mut report, &stats);
            linked
        }
        None => given,
    };
    let post_started = Instant::now();
    progress.stage(0, "writing the program");
    let posted = post(&rows, &input.name, &machine, &chain, &settings, comments)?;
    progress.finish();
    report.set("post_seconds", post_started.elapsed().as_secs_f64());
    // The collision check and the plot read the written program: the rows are done with.
    let row_count = rows.len();
    drop(rows);
    if job.is_none() && passes > 1 {
        cli::warn(&format!(
            "{passes} passes joined by straight G0 moves as given, not linked or checked against the stock: give --setup"
        ));
    }
    let open = || Box::new(posted.program.reader()) as Box<dyn std::io::BufRead + '_>;
    let program = Program { open: &open, name: "written program" };
    if let Some(j) = &job {
        collide(program, &machine, &chain, j, (walls.as_ref(), solid_ref), &args, &mut report)?;
    }
    if let Some(path) = &args.svg {
        let reading = readback::Reading::new(&machine, &chain);
        let poses = program.poses(&reading).collect::<Result<Vec<Option<NcPose>>>>()?;
        let title = format!("{} posted for {}: {} blocks", input.name, machine.name, poses.len());
        write_atomic(path, plot::plot(&title, &poses, &reading).to_svg(1200.0).as_bytes())?;
    }
    if posted.plan.singular_rows > 0 {
        cli::warn(&format!(
            "{} rows lie within {}° of the primary rotary axis: its angle was {} there (largest axis error {:.4}°)",
            posted.plan.singular_rows,
            machine.singular_cone,
            if machine.singular == camkit::doc::machine::SingularRule::Interpolate { "interpolated" } else { "held" },
            posted.plan.pose_axis_error.to_degrees()
        ));
    }
    let seconds = started.elapsed().as_secs_f64();
    report
        .set("rows", row_count)
        .set("normalised_axes", normalised)
        .set("blocks", posted.written.blocks)
        .set("inserted_blocks", posted.plan.inserted)
        .set("inverse_time_blocks", posted.written.inverse_time_blocks)
        .set("spindle_orients", posted.written.orients)
        .set("dropped_blocks", posted.written.dropped)
        .set("singular_rows", posted.plan.singular_rows)
        .set("singular_rule", format!("{:?}", machine.singular).to_lowercase())
        .set("singular_axis_error_deg", posted.plan.pose_axis_error.to_degrees())
        .set("unwinds", posted.plan.unwinds)
        .set("spindle_unwinds", posted.plan.spindle_unwinds)
        .set("tol_mm", settings.tol)
        .set("tol_used_mm", posted.tol_used)
        .set("angle_tol_deg", settings.angle_tol);
    deviation_keys(&mut report, &posted.check);
    report.set("seconds", seconds).set("rows_per_second", row_count as f64 / seconds.max(1e-9));
    deliver(&posted.program, &args, report)
}

/// The second reading: the rows read again and linked as they come, the linked rows onto disk.
/// A pass that starts inside the part is refused (the first) before any fault of linking.
fn link_rows(
    input: &Source,
    mut linker: link::Linker,
    chain: &Chain,
    machine: &Machine,
    settings: &Settings,
) -> Result<(Records<Cl>, link::Stats)> {
    let mut linked = RecordSpool::<Cl>::new();
    let mut reader = None;
    let (mut unreachable, mut failed) = (None, None);
    table::read_each_source(input, &[Col::X, Col::Y], |schema, row| {
        let r = match &mut reader {
            Some(r) => r,
            None => reader.insert(ClReader::new(schema, &input.name, chain, machine, settings.feed, settings.tol)?),
        };
        let cl = r.row(&row)?;
        if unreachable.is_none() {
            unreachable = linker.reachable(&cl).err();
        }
        if failed.is_none() {
            match linker.push(cl) {
                Ok(()) => linker.take().for_each(|row| linked.push(&row)),
                Err(e) => failed = Some(e),
            }
        }
        Ok(())
    })?;
    if let Some(e) = unreachable.or(failed) {
        return Err(e);
    }
    let stats = linker.finish()?;
    linker.take().for_each(|row| linked.push(&row));
    Ok((linked.finish(), stats))
}

/// Delivers the written program (copied from its spool into the output) and the report.
fn deliver(program: &Spooled, args: &Args, report: Report) -> Result<()> {
    if let Some(path) = &args.io.report {
        report.write(path)?;
    }
    let mut out = Stream::new(args.io.output.as_deref())?;
    std::io::copy(&mut program.reader(), &mut out).map_err(|e| Error::io(e, "cannot write the program"))?;
    out.commit()
}

fn link_keys(report: &mut Report, s: &link::Stats) {
    report
        .set("links", s.links)
        .set("traverses_at_clearance", s.at_clearance)
        .set("plunges", s.plunges)
        .set("plunge_mm", s.plunge_mm)
        .set("ramps", s.ramps)
        .set("starts_reached_by_rapid", s.direct)
        .set("lead_ins", s.lead_ins)
        .set("lead_outs", s.lead_outs)
        .set("leads_not_clear", s.leads_not_clear);
}

/// Runs the collision check on the written program; a program that fails it is not delivered
/// (exit 1) unless --allow-collision.
/// The part's walls, when the setup gives the part by contours: distances measured up to the
/// tool radius plus the larger of the approach and 5 mm.
fn walls_of(job: &Job) -> Option<Walls> {
    let reach = job.tool.radius + job.approach.max(5.0);
    match &job.part {
        Some(Part::Walls { regions, floor, top }) => Some(Walls::new(regions, *floor, *top, reach)),
        _ => None,
    }
}

/// The part as a solid and the tool's body, when the setup gives the part by a model: patches
/// tessellated within a quarter of the tolerance (at most 2 µm).
fn solid_of(job: &Job) -> Result<Option<(Solid, Body)>> {
    let Some(Part::Model(model)) = &job.part else { return Ok(None) };
    model.check_dropped(false)?;
    let solid = Solid::of(model, (0.25 * job.tolerance).min(0.002)).map_err(|e| job.error("part.model", e))?;
    for name in solid.open_meshes() {
        cli::warn(&format!(
            "part.model: surface {name} is an open or non-manifold mesh: the tool's clearance to its triangles is checked, but a tool wholly inside it is not seen (that needs a closed mesh)"
        ));
    }
    Ok(Some((solid, Body::of(&job.tool))))
}

/// The parts a program is checked against: walls, or a solid with the tool's body.
type Parts<'a> = (Option<&'a Walls>, Option<(&'a Solid, &'a Body)>);

fn collide(
    program: Program,
    machine: &Machine,
    chain: &Chain,
    job: &Job,
    (walls, solid): Parts,
    args: &Args,
    report: &mut Report,
) -> Result<()> {
    let reading = readback::Reading::new(machine, chain);
    let mut blocks = 0u64;
    for pose in program.poses(&reading) {
        pose?;
        blocks += 1;
    }
    let check = collision::Check { job, walls, solid };
    let started = Instant::now();
    let progress = args.io.progress(blocks, "checking against the stock");
    let mut o = check.run(program.poses(&reading), &reading, &|| progress.inc(1))?;
    report.set("material_check_seconds", started.elapsed().as_secs_f64());
    let started = Instant::now();
    progress.stage(if solid.is_some() { blocks } else { 0 }, "checking against the part");
    let so = check.run_solid(program.poses(&reading), &reading, job.resolution, &|| progress.inc(1))?;
    progress.finish();
    report.set("part_check_seconds", started.elapsed().as_secs_f64());
    let low = |a: Option<(f64, u32)>, b: Option<(f64, u32)>| match (a, b) {
        (Some(x), Some(y)) => Some(if y.0 < x.0 { y } else { x }),
        (x, y) => x.or(y),
    };
    o.feed_clearance = low(o.feed_clearance, so.feed);
    o.rapid_part_clearance = low(o.rapid_part_clearance, so.rapid);
    o.part_collisions += so.collisions;
    if let Some((line, rapid, c)) = so.first
        && o.first.as_ref().is_none_or(|(l, _)| line < *l)
    {
        let kind = if rapid { "a rapid (G0)" } else { "a feed move" };
        o.first = Some((
            line,
            format!(
                "{kind} comes {c:.4} mm from the part's model, less than the allowance {} mm (tolerance {} mm)",
                job.allowance, job.tolerance
            ),
        ));
    }
    let pair = |v: Option<(f64, u32)>| v.map(|(c, _)| c);
    let line = |v: Option<(f64, u32)>| v.map(|(_, l)| l);
    report
        .set("collision_checked", true)
        .set("material_resolution_mm", job.resolution)
        .set("rapid_blocks", o.rapid_blocks)
        .set("retracts", o.retracts)
        .set("rapids_into_material", o.rapids_into_material)
        .set("smallest_rapid_clearance_mm", pair(o.rapid_clearance))
        .set("smallest_rapid_clearance_line", line(o.rapid_clearance))
        .set("smallest_rapid_part_clearance_mm", pair(o.rapid_part_clearance))
        .set("feed_blocks", o.feed_blocks)
        .set("smallest_feed_clearance_mm", pair(o.feed_clearance))
        .set("smallest_feed_clearance_line", line(o.feed_clearance))
        .set("part_collisions", o.part_collisions)
        .set("unchecked_blocks", o.unchecked_blocks)
        .set("tilted_cuts_not_mapped", o.tilted_cuts)
        .set(
            "part_checked",
            match (walls.is_some(), solid.is_some()) {
                (true, _) => "walls".to_string(),
                (_, true) if so.sampled == 0 => "model: every move cast exactly".to_string(),
                (_, true) if so.cast == 0 => {
                    format!("model: the clearance every {} mm along the moves", job.resolution)
                }
                (_, true) => format!(
                    "model: straight moves cast exactly, arcs and turning moves at samples every {} mm",
                    job.resolution
                ),
                _ => "none".to_string(),
            },
        )
        .set("part_blocks_cast", so.cast)
        .set("part_blocks_sampled", so.sampled)
        .set("part_samples", so.samples)
        .set("model_chord_error_mm", solid.map(|(s, _)| s.chord_error()));
    if let Some(Part::Model(m)) = &job.part {
        let (degenerate, duplicate) = m.dropped_counts();
        report.set("degenerate_facets_dropped", degenerate).set("duplicate_facets_dropped", duplicate);
    }
    if let Some((nc_line, what)) = &o.first {
        let message = format!(
            "collision check: NC line {nc_line}: {what} ({} rapids into material, {} moves too near the part)",
            o.rapids_into_material, o.part_collisions
        );
        if args.check.is_some() {
            return Err(Error::check(message));
        }
        if args.allow_collision {
            cli::warn(&format!("{message}; written anyway (--allow-collision)"));
        } else {
            if let Some(path) = &args.io.report {
                report.write(path)?;
            }
            return Err(Error::check(format!("{message}: the program is not written (--allow-collision writes it)")));
        }
    }
    Ok(())
}

fn deviation_keys(report: &mut Report, d: &readback::Deviation) {
    report
        .set("largest_tip_deviation_mm", d.tip)
        .set("largest_tip_deviation_line", d.tip_line)
        .set("largest_row_distance_mm", d.coverage)
        .set("largest_axis_deviation_deg", d.axis_deg)
        .set("largest_spindle_deviation_deg", d.spindle_deg)
        .set("blocks_checked", d.blocks)
        .set("points_checked", d.samples);
}

fn finish(out: Output, args: &Args, report: Report) -> Result<()> {
    if let Some(path) = &args.io.report {
        report.write(path)?;
    }
    out.commit()
}
