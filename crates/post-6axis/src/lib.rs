//! `post-6axis`: inverse kinematics and NC output for 3-, 4-, 5- and 6-axis machines (papers 002
//! §4.1–4.3 and 000 §3.2), with a read-back check of every program it writes.
//!
//! CL rows (tool tip, tool axis, spindle orientation, feed) become machine poses through the
//! machine's chain ([`camkit::kinematics`]), blocks are inserted until the controller's linear
//! interpolation stays within tolerance ([`plan`]), the program is written in the machine's
//! dialect ([`nc`]), and read back through the forward kinematics to measure what it really does
//! ([`readback`]).

pub mod branch;
pub mod collision;
pub mod link;
pub mod nc;
pub mod plan;
pub mod plot;
pub mod readback;

use camkit::doc::machine::Machine;
use camkit::error::{Error, Location, Result};
use camkit::io::{Get, Share, Spool, Spooled};
use camkit::kinematics::{Chain, Solver};
use camkit::table::{Col, Move, Row, Schema};
use plan::{Cl, ClArc, SpindleSetup};
use std::io::Write;

/// What the user asks of one run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Largest tip deviation (mm) between blocks.
    pub tol: f64,
    /// Largest axis deviation (degrees) between blocks.
    pub angle_tol: f64,
    /// Largest spindle-orientation error (degrees).
    pub spindle_tol: f64,
    /// Radius (mm) turning a rotary move into path length for inverse-time feed.
    pub rotary_radius: f64,
    /// Feed (mm/min) for rows without one.
    pub feed: Option<f64>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings { tol: 0.005, angle_tol: 0.05, spindle_tol: 0.5, rotary_radius: 10.0, feed: None }
    }
}

/// Largest feed (mm/min) a program carries: 1 km/min, beyond any machine tool. A larger one
/// would be written as a word of dozens of digits (`--feed 1e300`: 300).
pub const MAX_FEED: f64 = 1e6;

/// Largest `--rotary-radius` (mm): 10 m. A larger one makes the inverse-time F of a rotary block
/// so small that it rounds to F0, which no controller reads.
pub const MAX_ROTARY_RADIUS: f64 = 1e4;

/// Feeds (mm/min) a program for `machine` can carry: from the F word's last decimal (in the
/// program's units; at least 0.001 mm/min), below which the feed would be written F0 (or its
/// inverse-time F round to 0), up to [`MAX_FEED`].
pub fn feed_range(machine: &Machine) -> (f64, f64) {
    let unit = if machine.program.units == camkit::doc::machine::UnitsDoc::Inch { 25.4 } else { 1.0 };
    ((unit * 10f64.powi(-(machine.program.decimals.feed as i32))).max(1e-3), MAX_FEED)
}

/// CL rows read one at a time from rows of one schema, checked: a tool axis on multi-axis
/// machines, unit axes (normalised when within 1e-3 of unit, counted in
/// [`ClReader::normalised`]), a feed within [`feed_range`] for every cutting row (`feed`, the
/// default, is the caller's to check), spindle orientations only for a machine that can command
/// them, arcs with a start (not the first row of a pass) and radii at both ends within `arc_tol`
/// (mm) of each other.
pub struct ClReader<'a> {
    file: &'a str,
    machine: &'a Machine,
    feed: Option<f64>,
    arc_tol: f64,
    prev_path: Option<i64>,
    last: Option<Cl>,
    /// Rows read.
    pub rows: usize,
    /// Tool axes normalised.
    pub normalised: usize,
}

impl<'a> ClReader<'a> {
    /// A reader of rows of `schema` (read from `file`) for `machine`; refuses a schema that
    /// lacks what the machine needs.
    pub fn new(
        schema: &Schema,
        file: &'a str,
        chain: &Chain,
        machine: &'a Machine,
        feed: Option<f64>,
        arc_tol: f64,
    ) -> Result<ClReader<'a>> {
        if !chain.rotaries().is_empty() && !schema.has(Col::I) {
            return Err(Error::input("missing columns i, j, k: a multi-axis machine needs the tool axis of every row")
                .at(Location::file(file).line(1)));
        }
        if schema.has(Col::S) && machine.spindle.is_none() {
            return Err(Error::input(
                "the rows carry spindle orientations (column s) but the machine document has no `spindle` to command them",
            )
            .at(Location::file(file).line(1).field("s")));
        }
        Ok(ClReader { file, machine, feed, arc_tol, prev_path: None, last: None, rows: 0, normalised: 0 })
    }

    /// The CL row of one table row.
    pub fn row(&mut self, row: &Row) -> Result<Cl> {
        let at = |line: u64, field: &str| Location::file(self.file).line(line).field(field);
        let n = row.axis.norm();
        if !n.is_finite() || (n - 1.0).abs() > camkit::tol::UNIT_VECTOR_SLACK {
            return Err(Error::input(format!("the tool axis has length {n}, not 1")).at(at(row.line, "i,j,k")));
        }
        if (n - 1.0).abs() > UNIT_EXACT {
            self.normalised += 1;
        }
        let rapid = row.mv == Move::Rapid || self.prev_path != Some(row.path);
        self.prev_path = Some(row.path);
        let arc = match (row.mv, row.centre) {
            (Move::Cw | Move::Ccw, _) if rapid => {
                return Err(Error::input("an arc needs a start: the first row of a pass cannot be cw or ccw")
                    .at(at(row.line, "move")));
            }
            (Move::Cw | Move::Ccw, Some(centre)) => {
                let arc = ClArc { plane: row.plane, centre, ccw: row.mv == Move::Ccw };
                let start = self.last.as_ref().expect("an arc follows a row of its pass");
                let (r0, r1) = arc.radii(&start.tip, &row.pos);
                if (r0 - r1).abs() > self.arc_tol || r0.is_nan() || r0 <= 0.0 {
                    return Err(Error::input(format!(
                        "the arc's ends are {r0:.6} and {r1:.6} mm from its centre: more than {} mm apart, not one circle",
                        self.arc_tol
                    ))
                    .at(at(row.line, "xc,yc")));
                }
                Some(arc)
            }
            (Move::Cw | Move::Ccw, None) => {
                return Err(Error::input("an arc needs its centre").at(at(row.line, "xc,yc")));
            }
            _ => None,
        };
        let (lo, hi) = feed_range(self.machine);
        if let Some(v) = row.f
            && !(lo..=hi).contains(&v)
        {
            let v = if (1e-6..1e9).contains(&v.abs()) { v.to_string() } else { format!("{v:e}") };
            return Err(Error::input(format!("feed must be from {lo} to {hi} mm/min, got {v}")).at(at(row.line, "f")));
        }
        let f = row.f.or(self.feed);
        if f.is_none() && !rapid {
            return Err(Error::input("no feed for this move: give the f column or --feed").at(at(row.line, "f")));
        }
        let cl =
            Cl { tip: row.pos, axis: row.axis / n, s: row.s, feed: f, rapid, reorient: rapid, line: row.line, arc };
        self.last = Some(cl);
        self.rows += 1;
        Ok(cl)
    }
}

/// The planning view of a machine.
pub fn planning<'a>(machine: &Machine, chain: &'a Chain) -> plan::Machine<'a> {
    plan::Machine {
        solver: Solver { chain, policy: machine.policy(), cone: machine.singular_cone.to_radians() },
        travel: [machine.travel.x, machine.travel.y, machine.travel.z],
        spindle: machine.spindle.as_ref().map(|s| SpindleSetup {
            offset: s.offset,
            sense: s.sense,
            interpolated: s.mode == camkit::doc::machine::SpindleMode::Axis,
        }),
    }
}

/// Everything one run of the post produced.
#[derive(Debug)]
pub struct Posted {
    /// The program text, on disk.
    pub program: Spooled,
    /// Planning figures.
    pub plan: plan::Stats,
    /// Writing figures.
    pub written: nc::Written,
    /// The program read back and compared with the rows.
    pub check: readback::Deviation,
    /// Tolerance (mm) linearisation worked to: `tol` less the rounding of the written numbers.
    pub tol_used: f64,
}

/// Largest tip error (mm) that rounding the written numbers can add: linear decimals in 3-D and
/// the rotary decimals at the largest lever arm of the rows.
fn rounding_allowance<R: Get<Cl> + ?Sized>(rows: &R, chain: &Chain, machine: &Machine) -> f64 {
    let d = machine.program.decimals;
    let unit = if machine.program.units == camkit::doc::machine::UnitsDoc::Inch { 25.4 } else { 1.0 };
    let lin = 0.5 * 10f64.powi(-(d.linear as i32)) * unit * 3f64.sqrt();
    let offsets: f64 =
        chain.links().iter().map(|l| if let camkit::kinematics::Link::Offset(v) = l { v.norm() } else { 0.0 }).sum();
    let reach = (0..rows.len()).map(|i| (rows.get(i).tip.coords - chain.frame()).norm()).fold(0.0, f64::max)
        + chain.frame().norm()
        + offsets;
    let rot = 0.5 * 10f64.powi(-(d.rotary as i32));
    lin + rot.to_radians() * reach * chain.rotaries().len() as f64
}

/// A tool axis whose length differs from 1 by more than this was not written as a unit vector
/// (beyond the round-off of its text): it is normalised with a warning.
pub const UNIT_EXACT: f64 = 1e-9;

/// Fraction of `--spindle-tol` that planning works to.
pub const SPINDLE_MARGIN: f64 = 0.8;

/// Fraction of `--angle-tol` that planning works to: planning measures the axis against the arc
/// between the rows' axes, the read-back check at the tip's nearest point of the CL, which may
/// ask a little more.
pub const ANGLE_MARGIN: f64 = 0.8;

/// Samples per block in the read-back check.
pub const CHECK_SAMPLES: usize = 8;

/// What planning works to for `rows` on `machine`: the tolerances less what the program's
/// decimals may add in rounding (refused when that leaves under a quarter of one).
fn plan_options<R: Get<Cl> + ?Sized>(
    rows: &R,
    machine: &Machine,
    chain: &Chain,
    s: &Settings,
) -> Result<plan::Options> {
    let allowance = rounding_allowance(rows, chain, machine);
    let tol_used = s.tol - allowance;
    if tol_used < s.tol / 4.0 {
        return Err(Error::input(format!(
            "--tol {} mm is too small for the program's decimals (rounding alone may move the tip {allowance:.6} mm): \
             raise --tol or program.decimals",
            s.tol
        )));
    }
    // Rounding a rotary value by δ turns the tool axis by at most δ.
    let d = machine.program.decimals;
    let angle_allowance = 0.5 * 10f64.powi(-(d.rotary as i32)) * chain.rotaries().len() as f64;
    let angle_used = s.angle_tol * ANGLE_MARGIN - angle_allowance;
    if angle_used < s.angle_tol / 4.0 {
        return Err(Error::input(format!(
            "--angle-tol {}° is too small for the program's rotary decimals (rounding alone may turn the tool axis \
             {angle_allowance}°): raise --angle-tol or program.decimals",
            s.angle_tol
        )));
    }
    // The spindle orientation comes from the rounded rotary values and the rounded spindle word,
    // measured where the tip is nearest the CL: 0.003° off at 4 rotary decimals on the six-axis
    // machines however many blocks are inserted. Below 100 resolutions it is refused, not tried.
    let spindle_floor = 100.0 * 10f64.powi(-(d.rotary as i32));
    if machine.spindle.is_some() && s.spindle_tol < spindle_floor {
        return Err(Error::input(format!(
            "--spindle-tol {}° is too small for the program's rotary decimals (at least {spindle_floor}°): raise \
             --spindle-tol or program.decimals",
            s.spindle_tol
        )));
    }
    Ok(plan::Options {
        tol: tol_used,
        angle_tol: angle_used.to_radians(),
        // The check measures the spindle against the CL at the tip's nearest point, planning at the
        // block's own parameter: keep a margin between the two.
        spindle_tol: s.spindle_tol * SPINDLE_MARGIN,
        tcp: machine.program.tcp,
        interpolate_singular: machine.singular == camkit::doc::machine::SingularRule::Interpolate,
    })
}

/// Plans, writes and reads back the program for CL rows (in memory, or on disk as
/// [`camkit::io::Records`]): the program goes to disk as it is written, and is read back from
/// there a block at a time.
pub fn post<R: Share<Cl> + ?Sized>(
    rows: &R,
    file: &str,
    machine: &Machine,
    chain: &Chain,
    s: &Settings,
    comments: Vec<String>,
) -> Result<Posted> {
    let view = rows.view();
    let opts = plan_options(&view, machine, chain, s)?;
    let m = planning(machine, chain);
    // Blocks are written as they are planned; a move without a feed is refused once planning
    // has found nothing worse (as when the whole plan came first).
    let wopts = nc::WriteOptions { rotary_radius: s.rotary_radius, comments };
    let mut writer = nc::Writer::new(machine, chain, &wopts);
    let spool_error = |e: std::io::Error| Error::runtime(format!("the program cannot be spooled: {e}"));
    let mut spool = Spool::new().map_err(spool_error)?;
    let mut no_feed = None;
    let mut failed = None;
    let stats = plan::plan_each(&view, &m, &opts, &mut |step| {
        if no_feed.is_none() {
            no_feed = writer.push(step).err();
        }
        if failed.is_none() && writer.pending() >= SPOOL_BYTES {
            failed = writer.write_text(&mut spool).err();
        }
    })
    .map_err(|e| {
        let loc = Location::file(file).line(view.get(e.row).line).field("i,j,k");
        if e.unreachable { Error::input(e.message).at(loc) } else { Error::check(e.message).at(loc) }
    })?;
    if let Some(nc::NoFeed(row)) = no_feed {
        return Err(Error::input("no feed for this move: give the f column or --feed")
            .at(Location::file(file).line(view.get(row).line).field("f")));
    }
    if let Some(e) = failed {
        return Err(spool_error(e));
    }
    let (text, written) = writer.finish();
    spool.write_all(&text).map_err(spool_error)?;
    let program = spool.finish().map_err(spool_error)?;
    let check = check_program(&program, rows, machine, chain, s)?;
    judge(&check, &view, machine, s)?;
    Ok(Posted { program, plan: stats, written, check, tol_used: opts.tol })
}

/// Bytes of program text the writer holds before they go to the spool.
const SPOOL_BYTES: usize = 1 << 16;

/// The verdict on a program read back: a check failure (exit 1) naming where it misses if the tip,
/// the axis (anywhere, also in the singular cone) or the spindle orientation is beyond its
/// tolerance.
pub fn judge<R: Get<Cl> + ?Sized>(
    check: &readback::Deviation,
    rows: &R,
    machine: &Machine,
    s: &Settings,
) -> Result<()> {
    if !camkit::tol::within(check.tip, s.tol) || !camkit::tol::within(check.coverage, s.tol) {
        return Err(Error::check(format!(
            "read back, the program deviates {:.6} mm from the CL (at NC line {}; rows {:.6} mm, at input line {}): more than --tol {} mm",
            check.tip,
            check.tip_line,
            check.coverage,
            rows.get(check.coverage_row).line,
            s.tol
        )));
    }
    if readback::axis_beyond(check.axis_deg, s.angle_tol) {
        return Err(Error::check(format!(
            "read back, the tool axis deviates {:.5}° from the CL (NC line {}, rows at input lines {}): more than \
             --angle-tol {}°",
            check.axis_deg,
            check.axis_line,
            lines_of(rows, &check.axis_rows),
            s.angle_tol
        )));
    }
    if machine.spindle.is_some() && check.spindle_deg > s.spindle_tol * (1.0 + 1e-6) + 1e-9 {
        return Err(Error::check(format!(
            "read back, the spindle orientation deviates {:.4}° from the CL: more than --spindle-tol {}°",
            check.spindle_deg, s.spindle_tol
        )));
    }
    Ok(())
}

/// Input lines of rows (indices), as a short list: the first few and how many more.
fn lines_of<R: Get<Cl> + ?Sized>(rows: &R, at: &[usize]) -> String {
    let shown: Vec<String> = at.iter().take(8).map(|&i| rows.get(i).line.to_string()).collect();
    match at.len() {
        n if n > shown.len() => format!("{} and {} more", shown.join(", "), n - shown.len()),
        _ => shown.join(", "),
    }
}

/// Reads a written program back from its spool and compares it with the rows.
pub fn check_program<R: Share<Cl> + ?Sized>(
    program: &Spooled,
    rows: &R,
    machine: &Machine,
    chain: &Chain,
    s: &Settings,
) -> Result<readback::Deviation> {
    let open = || Box::new(program.reader()) as Box<dyn std::io::BufRead + '_>;
    let program = readback::Program { open: &open, name: "written program" };
    let reading = readback::Reading::new(machine, chain);
    readback::verify(rows, program, &reading, CHECK_SAMPLES, s.tol, s.angle_tol)
        .map_err(|e| Error::runtime(format!("the written program does not read back: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use camkit::gcode::read_axes;
    use camkit::geom::{P3, V3};
    use proptest::prelude::*;
    use std::io::Read;

    /// The text of a posted program.
    fn text_of(p: &Posted) -> String {
        let mut text = String::new();
        p.program.reader().read_to_string(&mut text).unwrap();
        text
    }

    /// [`readback::verify`] on a program's text (--angle-tol 0.05°).
    fn verify_text(rows: &[Cl], text: &str, r: &readback::Reading, samples: usize, tol: f64) -> readback::Deviation {
        let open = || Box::new(text.as_bytes()) as Box<dyn std::io::BufRead + '_>;
        readback::verify(rows, readback::Program { open: &open, name: "t" }, r, samples, tol, 0.05).unwrap()
    }

    fn machine(name: &str) -> (Machine, Chain) {
        let path = format!("{}/../../data/post-6axis/{name}", env!("CARGO_MANIFEST_DIR"));
        Machine::read(&path).expect("machine document")
    }

    /// A smooth pass: the tip on a wavy curve, the axis tilting and turning along it.
    fn pass(n: usize, tilt: f64, turn: f64, wave: f64, with_s: bool) -> Vec<Cl> {
        (0..n)
            .map(|k| {
                let t = k as f64 / (n - 1) as f64;
                let tip = P3::new(-20.0 + 40.0 * t, 10.0 * (wave * t).sin(), 5.0 * (2.0 * wave * t).cos());
                let (th, ph) = ((tilt * (0.3 + 0.7 * t)).to_radians(), (turn * t).to_radians());
                let axis = V3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                let s = with_s.then_some(90.0 * t);
                Cl { tip, axis, s, feed: Some(600.0), rapid: k == 0, reorient: k == 0, line: k as u64 + 2, arc: None }
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

        /// Whatever the path, a program that is delivered reads back within the tolerances (the
        /// axis within --angle-tol, also near the singular cone), by the post's own check and by a
        /// four times denser one.
        #[test]
        fn delivered_programs_read_back_within_tolerance(
            tilt in 0.0f64..60.0, turn in -200.0f64..200.0, wave in 0.0f64..6.0, which in 0usize..6,
        ) {
            let names = ["paper002-ac.json", "paper002-ac-fanuc-tcp.json", "paper000-sixaxis-b.json", "paper000-sixaxis-m19.json", "head-bc.json", "head-table-cb.json"];
            let (m, chain) = machine(names[which]);
            let rows = pass(60, tilt, turn, wave, m.spindle.is_some());
            let s = Settings { tol: 0.002, ..Settings::default() };
            let posted = post(&rows, "t", &m, &chain, &s, vec![]).expect("posts");
            prop_assert!(posted.check.tip <= 0.002 && posted.check.coverage <= 0.002, "{:?}", posted.check);
            let reading = readback::Reading::new(&m, &chain);
            let dense = verify_text(&rows, &text_of(&posted), &reading, 4 * CHECK_SAMPLES, 0.002);
            prop_assert!(dense.tip <= 0.002 * (1.0 + 1e-9), "dense check {:?}", dense);
            prop_assert!(dense.axis_deg <= 0.05 * (1.0 + 1e-6) + 1e-9, "{:?}", dense);
        }
    }

    /// A pass a random seed found on the head-bc machine: the program was delivered with the tool
    /// axis 0.0539° off the CL by the four times denser read-back (tolerance 0.05°). Planned to a
    /// margin of the tolerance, it reads back within it by both checks.
    #[test]
    fn head_bc_wavy_pass_holds_the_angle_tolerance() {
        let (m, chain) = machine("head-bc.json");
        let rows = pass(60, 54.5, 152.0, 5.73, false);
        let s = Settings { tol: 0.002, ..Settings::default() };
        let posted = post(&rows, "t", &m, &chain, &s, vec![]).expect("posts");
        let reading = readback::Reading::new(&m, &chain);
        let dense = verify_text(&rows, &text_of(&posted), &reading, 4 * CHECK_SAMPLES, 0.002);
        assert!(
            posted.check.axis_deg <= 0.05 && dense.axis_deg <= 0.05,
            "{} {}",
            posted.check.axis_deg,
            dense.axis_deg
        );
    }

    /// Four passes on the six-axis machine, each turning the edge a further 350° with the feed: the
    /// spindle orientation (B) stays continuous within a pass and is unwound where the next pass
    /// starts (it once wound on to 1 400°, four turns).
    #[test]
    fn spindle_orientation_is_unwound_between_passes() {
        let (m, chain) = machine("paper000-sixaxis-b.json");
        let t = 10f64.to_radians();
        let mut rows = Vec::new();
        for pass in 0..4 {
            for k in 0..=35 {
                rows.push(Cl {
                    tip: P3::new(-17.5 + k as f64, 5.0 * pass as f64, 10.0),
                    axis: V3::new(0.0, t.sin(), t.cos()),
                    s: Some(10.0 * k as f64),
                    feed: Some(500.0),
                    rapid: k == 0,
                    reorient: k == 0,
                    line: (pass * 36 + k) as u64 + 2,
                    arc: None,
                });
            }
        }
        let posted = post(&rows, "t", &m, &chain, &Settings::default(), vec![]).expect("posts");
        let program = read_axes("t", &text_of(&posted)).unwrap();
        let b_max = program.moves.iter().map(|mv| mv.pos[4].abs()).fold(0.0, f64::max);
        assert!(b_max > 350.0 && b_max < 720.0, "B continuous within a pass, unwound between: {b_max}");
        assert_eq!(posted.plan.spindle_unwinds, 3, "{:?}", posted.plan);
        assert!(posted.check.spindle_deg <= 0.5, "{:?}", posted.check);
    }

    /// Rounding the rotary values to 0.0001° may turn the tool axis by 0.0001° on a two-rotary
    /// machine: planning keeps that share of --angle-tol free, and a tolerance it would leave
    /// too little of is refused as bad input. A program read back beyond --angle-tol is refused as
    /// a check failure naming the NC line and the rows it misses.
    #[test]
    fn the_angle_tolerance_allows_for_rounding_and_a_miss_names_the_rows() {
        let (m, chain) = machine("paper002-ac.json");
        let rows = pass(40, 40.0, 120.0, 2.0, false);
        let s = Settings { angle_tol: 0.0001, ..Settings::default() };
        let Err(e) = post(&rows, "t", &m, &chain, &s, vec![]) else { panic!("delivered") };
        assert_eq!(e.kind, camkit::error::ErrorKind::Input, "{e}");
        assert!(e.to_string().contains("too small for the program's rotary decimals"), "{e}");
        let s = Settings { angle_tol: 0.0006, ..Settings::default() };
        let posted = post(&rows, "t", &m, &chain, &s, vec![]).expect("posts");
        assert!(posted.check.axis_deg <= 0.0006, "{:?}", posted.check);
        let mut off = posted.check.clone();
        off.axis_deg = 0.3;
        off.axis_line = 42;
        off.axis_rows = vec![3, 4, 9];
        let e = judge(&off, &rows, &m, &s).unwrap_err();
        assert_eq!(e.kind, camkit::error::ErrorKind::Check, "{e}");
        assert!(e.to_string().contains("NC line 42, rows at input lines 5, 6, 11"), "{e}");
    }

    /// The post writes each block as planning hands it over (never the whole plan held): the text
    /// is byte for byte that of the whole plan written at once, on passes that insert blocks, on
    /// every machine of the property test above.
    #[test]
    fn blocks_written_as_planned_are_the_whole_plan_written() {
        let names = ["paper002-ac.json", "paper000-sixaxis-b.json", "paper000-sixaxis-m19.json", "head-bc.json"];
        for name in names {
            let (m, chain) = machine(name);
            let mut rows = pass(50, 40.0, 150.0, 4.0, m.spindle.is_some());
            rows.extend(pass(30, 20.0, -90.0, 2.0, m.spindle.is_some()));
            let s = Settings { tol: 0.002, ..Settings::default() };
            let posted = post(&rows, "t", &m, &chain, &s, vec!["c".into()]).expect("posts");
            let opts = plan_options(&rows, &m, &chain, &s).unwrap();
            let (steps, stats) = plan::plan(&rows, &planning(&m, &chain), &opts).expect("plans");
            assert!(stats.inserted > 0, "{name}: {stats:?}");
            let wopts = nc::WriteOptions { rotary_radius: s.rotary_radius, comments: vec!["c".into()] };
            let (whole, _) = nc::write(&steps, &m, &chain, &wopts).expect("writes");
            assert!(
                text_of(&posted).as_bytes() == whole,
                "{name}: the streamed program differs from the whole plan written"
            );
            assert_eq!(posted.plan, stats, "{name}");
        }
    }

    /// The read-back check runs chunks in parallel: the same figures on one thread as on four,
    /// over more blocks than one chunk holds.
    #[test]
    fn read_back_is_the_same_for_any_thread_count() {
        let (m, chain) = machine("paper000-sixaxis-b.json");
        let rows = pass(readback::CHUNK * 2 + 100, 30.0, 90.0, 2.0, true);
        let posted = post(&rows, "t", &m, &chain, &Settings::default(), vec![]).expect("posts");
        assert!(posted.check.blocks > 2 * readback::CHUNK, "{:?}", posted.check);
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| check_program(&posted.program, &rows, &m, &chain, &Settings::default()).unwrap())
        };
        assert_eq!(on(1), posted.check);
        assert_eq!(on(4), posted.check);
    }

    /// Rows on disk post as the same rows in memory do: the same program byte for byte and the
    /// same read-back figures, over more rows than a page of records and a chunk of the check
    /// hold (the records read back bit for bit).
    #[test]
    fn rows_on_disk_post_as_rows_in_memory() {
        let (m, chain) = machine("paper000-sixaxis-b.json");
        let rows = pass(readback::CHUNK + 700, 30.0, 90.0, 2.0, true);
        let mut spool = camkit::io::RecordSpool::new();
        for r in &rows {
            spool.push(r);
        }
        let disk = spool.finish();
        assert!(disk.iter().zip(&rows).all(|(a, b)| a == *b) && disk.len() == rows.len());
        let s = Settings::default();
        let (a, b) =
            (post(&rows, "t", &m, &chain, &s, vec![]).unwrap(), post(&disk, "t", &m, &chain, &s, vec![]).unwrap());
        assert!(text_of(&a) == text_of(&b), "the programs differ");
        assert!(a.program.len() > 1 << 17, "{} bytes", a.program.len());
        assert_eq!((a.check, a.plan, a.written), (b.check, b.plan, b.written));
    }

    #[test]
    fn arcs_and_slerp() {
        let (a, b) = (V3::x(), V3::y());
        let mid = plan::slerp(&a, &b, 0.5);
        assert!((mid - V3::new(1.0, 1.0, 0.0).normalize()).norm() < 1e-15);
        assert!(plan::vector_arc(&mid, &a, &b) < 1e-15);
        // Above the arc's plane by 0.1 rad, inside its wedge; beyond its end, the angle to the end.
        let up = (mid + V3::z() * 0.1f64.tan()).normalize();
        assert!((plan::vector_arc(&up, &a, &b) - 0.1).abs() < 1e-12);
        let beyond = V3::new(-1.0, 1.0, 0.0).normalize();
        assert!((plan::vector_arc(&beyond, &a, &b) - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
    }

    #[test]
    fn inverse_time_feed_is_the_tip_path_over_the_feed() {
        let (m, chain) = machine("paper002-ac.json");
        let rows = pass(30, 30.0, 90.0, 1.0, false);
        let posted = post(&rows, "t", &m, &chain, &Settings::default(), vec![]).expect("posts");
        let text = text_of(&posted);
        let program = read_axes("t", &text).unwrap();
        let reading = readback::Reading::new(&m, &chain);
        let table = readback::reverse(&readback::poses(&program, &reading), &reading);
        // Every G93 block's F times its tip chord gives back the 600 mm/min of the rows.
        let mut seen = 0;
        for (mv, row) in program.moves.iter().zip(&table.rows) {
            if mv.inverse_time && mv.motion == camkit::gcode::Motion::Line {
                let f = row.f.expect("feed");
                // To 0.1 %: the chord is measured on the rounded positions read back.
                assert!((f - 600.0).abs() < 600.0 * 1e-3, "line {}: {f}", mv.line);
                seen += 1;
            }
        }
        assert!(seen > 20, "{seen} inverse-time blocks");
    }

    /// The axis turning 2° with the tip standing still: the tip's nearest CL parameter says nothing
    /// about where along the turn the tool is, so the check measures the axis against the turn's
    /// arc (it once took the first segment's end axis: 1.0° off mid-turn). A program whose axes
    /// are off is still refused.
    #[test]
    fn axis_turn_on_the_spot_reads_back_along_its_arc() {
        let (m, chain) = machine("paper002-ac.json");
        let tilt = |deg: f64| V3::new(0.0, deg.to_radians().sin(), deg.to_radians().cos());
        let row = |x: f64, deg: f64, k: u64| Cl {
            tip: P3::new(x, 0.0, 20.0),
            axis: tilt(deg),
            s: None,
            feed: Some(500.0),
            rapid: k == 0,
            reorient: k == 0,
            line: k + 2,
            arc: None,
        };
        let rows = [row(0.0, 20.0, 0), row(10.0, 20.0, 1), row(10.0, 22.0, 2), row(20.0, 22.0, 3)];
        let posted = post(&rows, "t", &m, &chain, &Settings::default(), vec![]).expect("posts");
        assert!(posted.check.axis_deg < 1e-3, "{:?}", posted.check);
        let mut off = rows;
        off[2].axis = tilt(23.0);
        off[3].axis = tilt(23.0);
        let check = check_program(&posted.program, &off, &m, &chain, &Settings::default()).unwrap();
        assert!((check.axis_deg - 1.0).abs() < 0.01, "{check:?}");
    }

    /// Three full turns around a latitude circle, one pass each: C keeps turning within a pass
    /// and is unwound at each pass start once past a full turn; inch output reads back the same.
    #[test]
    fn wrapping_axis_is_unwound_between_passes_and_inch_reads_back() {
        let (mut m, chain) = machine("paper002-ac.json");
        let mut rows = Vec::new();
        for pass in 0..3 {
            for k in 0..=72 {
                let lon = (k as f64 * 5.0).to_radians();
                let lat = 50.0f64.to_radians();
                let axis = V3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin());
                rows.push(Cl {
                    tip: P3::from(axis * 25.0),
                    axis,
                    s: None,
                    feed: Some(500.0),
                    rapid: k == 0,
                    reorient: k == 0,
                    line: (pass * 73 + k) as u64 + 2,
                    arc: None,
                });
            }
        }
        let posted = post(&rows, "t", &m, &chain, &Settings::default(), vec![]).expect("posts");
        // C turns −360° per pass (sense −1): from 90° to −270°, −270° to −630°, then unwound to 90°.
        assert_eq!(posted.plan.unwinds, 1, "{:?}", posted.plan);
        let program = read_axes("t", &text_of(&posted)).unwrap();
        let c_max = program.moves.iter().map(|mv| mv.pos[5].abs()).fold(0.0, f64::max);
        assert!(c_max > 600.0 && c_max < 720.0, "C stays continuous within a pass, unwound between: {c_max}");
        m.program.units = camkit::doc::machine::UnitsDoc::Inch;
        m.program.decimals.linear = 5;
        let inch = post(&rows, "t", &m, &chain, &Settings::default(), vec![]).expect("posts in inches");
        assert!(text_of(&inch).contains("G20 "));
        assert!(inch.check.tip <= 0.005, "{:?}", inch.check);
    }
}
