//! `offset`: gouge-free tool-radius offsets of line/arc contours (paper 004 §3–4, paper 002
//! §4.3). Four modes on the toolpath table:
//!
//! - contour: each pass offset by R to the left or right of travel ([`contour_mode`]);
//! - pocket: closed contours nested into regions with islands, offset at R and every step
//!   beyond as separate passes in machining order ([`pocket_mode`]);
//! - profile: a profile in a vertical plane cut by a ball or square end mill ([`profile_mode`]);
//! - 3D: a 3D contour offset in the plane normal to each row's tool axis ([`space_mode`]).
//!
//! The 2D kernel is `camkit::contour` (cavalier_contours, verified with exact distances).

pub mod budget;
pub mod contours;
pub mod plot;
pub mod profile;
pub mod space;

use camkit::contour::offset::Side;
use camkit::contour::pocket::{self, Passes, PocketOptions};
use camkit::contour::region::Region;
use camkit::contour::table::{self as contour_table, Source};
use camkit::contour::{Contour, OffsetOptions, Seg, offset_contour};
use camkit::error::{Error, Location, Result};
use camkit::geom::{P2, P3, Plane, V3};
use camkit::report::Report;
use camkit::svg::Plot;
use camkit::table::{Col, Move, Row, Table};

/// Name of the column holding each pass's offset distance.
pub const OFFSET_COLUMN: &str = "offset";

/// What a run produced.
pub struct Outcome {
    /// The output table.
    pub table: Table,
    /// Figures of the run.
    pub report: Report,
    /// The picture.
    pub plot: Plot,
    /// Things the user should know (nothing to cut, reoriented loops).
    pub warnings: Vec<String>,
}

/// A number as the shortest text that reads back exactly.
fn number(v: f64) -> String {
    let mut b = Vec::new();
    camkit::num::push_shortest(&mut b, v);
    String::from_utf8(b).unwrap_or_default()
}

fn located(name: &str, line: u64) -> Location {
    Location::file(name).line(line)
}

/// The output table with the `offset` column; returns its index.
fn output_table(input: &Table) -> (Table, usize) {
    let mut t = contours::schema(input);
    let k = t.add_extra_column(OFFSET_COLUMN);
    (t, k)
}

fn push_contour(t: &mut Table, k: usize, c: &Contour, path: i64, z: f64, template: &Row, distance: f64) {
    for mut row in contours::rows(c, path, z, template) {
        row.extra.resize(t.schema.extra_names.len(), String::new());
        row.extra[k] = number(distance);
        t.rows.push(row);
    }
}

fn read_sources(table: &Table, name: &str, report: &mut Report) -> Result<Vec<Source>> {
    let read = contour_table::read(table, name).map_err(with_mode_hint)?;
    if read.sources.is_empty() {
        return Err(Error::input("no contour: the table has no pass with two distinct points").at(Location::file(name)));
    }
    report.set("input_contours", read.sources.len()).set("dropped_zero_length_moves", read.dropped);
    report.set("arc_radius_mismatch_mm", read.arc_mismatch);
    Ok(read.sources)
}

/// A contour that leaves its z or its xy plane may be meant for another mode: say which.
fn with_mode_hint(mut e: Error) -> Error {
    match e.location.as_ref().and_then(|l| l.field.as_deref()) {
        Some("z") => e.message.push_str(" (use --3d for 3D contours)"),
        Some("plane") => e.message.push_str(" (use --profile for a profile in a vertical plane)"),
        _ => {}
    }
    e
}

fn self_crossing_error(name: &str, s: &Source, p: P2) -> Error {
    Error::input(format!(
        "path {} crosses itself at ({:.6}, {:.6}); fix the contour or pass --allow-self-crossing",
        s.path, p.x, p.y
    ))
    .at(located(name, s.line))
}

/// Contour mode: every pass offset by `r` to `side`, verified.
pub fn contour_mode(table: &Table, name: &str, r: f64, side: Side, opts: &OffsetOptions) -> Result<Outcome> {
    let mut report = Report::new("offset");
    report.set("mode", "contour").set("radius_mm", r).set("side", if side == Side::Left { "left" } else { "right" });
    let sources = read_sources(table, name, &mut report)?;
    if !opts.self_crossing_input {
        for s in &sources {
            if let Some(p) = s.contour.self_crossing() {
                return Err(self_crossing_error(name, s, p));
            }
        }
    }
    let (mut out, k) = output_table(table);
    let mut warnings = Vec::new();
    let mut check = camkit::contour::Check::default();
    let (mut attempts, mut cleaned, mut path) = (0, 0, 0i64);
    let mut drawn = Vec::new();
    for s in &sources {
        let o = offset_contour(&s.contour, r, side, opts)
            .map_err(|e| Error::check(format!("path {}: {e}", s.path)).at(located(name, s.line)))?;
        attempts += o.attempts;
        cleaned += usize::from(o.cleaned);
        check = check.merge(&o.check);
        if o.contours.is_empty() {
            warnings.push(format!(
                "path {} (line {}): an offset of {r} mm leaves nothing (the contour is narrower than the tool): nothing to cut",
                s.path, s.line
            ));
        }
        for c in &o.contours {
            push_contour(&mut out, k, c, path, s.z, &table.rows[s.row], r);
            path += 1;
            drawn.push(c.clone());
        }
    }
    report
        .set("output_paths", path)
        .set("verified_pieces", check.pieces)
        .set("largest_deviation_mm", check.deviation())
        .set("kernel_runs", attempts)
        .set("runs_on_cleaned_input", cleaned);
    let inputs: Vec<Contour> = sources.iter().map(|s| s.contour.clone()).collect();
    let plot = plot::passes(
        &format!("{name}: offset {r} mm to the {}", if side == Side::Left { "left" } else { "right" }),
        &inputs,
        &drawn,
    );
    Ok(Outcome { table: out, report, plot, warnings })
}

/// Pocket mode: closed contours as regions with islands, passes at `radius + k·step`.
pub fn pocket_mode(table: &Table, name: &str, opts: &PocketOptions) -> Result<Outcome> {
    let mut report = Report::new("offset");
    report.set("mode", "pocket").set("radius_mm", opts.radius).set("step_mm", opts.step);
    let sources = read_sources(table, name, &mut report)?;
    let (regions, turned) = contour_table::pocket_regions(&sources, name)?;
    let result = pocket::pocket(&regions, opts).map_err(|e| {
        let s = &sources[regions[e.region].outer_source];
        Error::check(format!("pocket of path {} at offset {} mm: {}", s.path, e.distance, e.error))
            .at(located(name, s.line))
    })?;
    let centre = centre_lines(&regions, &result.passes, opts);
    let passes: Vec<&pocket::Pass> = result.passes.iter().chain(&centre).collect();
    let (mut out, k) = output_table(table);
    let mut warnings = Vec::new();
    if passes.is_empty() {
        warnings.push(format!("the tool (radius {} mm) does not fit in any region: nothing to cut", opts.radius));
    }
    if turned > 0 {
        warnings.push(format!(
            "{turned} contours were turned around to match their role (boundary counter-clockwise, island clockwise)"
        ));
    }
    let mut drawn = Vec::new();
    for (path, pass) in passes.iter().enumerate() {
        let s = &sources[regions[pass.region].outer_source];
        push_contour(&mut out, k, &pass.contour, path as i64, s.z, &table.rows[s.row], pass.distance);
        drawn.push(pass.contour.clone());
    }
    let levels = passes.iter().map(|p| p.level + 1).max().unwrap_or(0);
    report
        .set("regions", regions.len())
        .set("islands", regions.iter().map(|r| r.islands.len()).sum::<usize>())
        .set("reoriented_contours", turned)
        .set("passes", passes.len())
        .set("centre_line_passes", centre.len())
        .set("levels", levels)
        .set("clean_up_passes", result.clean_ups)
        .set("verified_pieces", result.check.pieces)
        .set("largest_deviation_mm", result.check.deviation())
        .set("kernel_runs", result.attempts)
        .set("offsets_on_cleaned_input", result.cleaned);
    let title = format!("{name}: {} passes, tool radius {} mm, step {} mm", passes.len(), opts.radius, opts.step);
    let loops: Vec<Contour> = sources.iter().map(|s| s.contour.clone()).collect();
    let plot = plot::passes(&title, &loops, &drawn);
    Ok(Outcome { table: out, report, plot, warnings })
}

/// Passes along the centre line of the regions that have no pass in `passes`: a region at most
/// 2R wide everywhere (a slot exactly 2R wide) has an empty inside at R, the region offset
/// dropping the loop of zero width, while the inward offset of its boundary alone is the centre
/// line, as contour mode cuts it. A centre line is kept only if every piece keeps R (within
/// `OFFSET_TOL`) from every loop of the region, islands included.
fn centre_lines(regions: &[Region], passes: &[pocket::Pass], opts: &PocketOptions) -> Vec<pocket::Pass> {
    let r = opts.radius;
    let mut out = Vec::new();
    for (ri, region) in regions.iter().enumerate() {
        if passes.iter().any(|p| p.region == ri) {
            continue;
        }
        // The boundary runs counter-clockwise: the inside is on its left.
        let Ok(o) = offset_contour(&region.outer, r, Side::Left, &opts.offset) else { continue };
        for c in o.contours {
            let clear = c.segs().all(|s| {
                region.loops().iter().flat_map(|l| l.segs()).all(|b| b.min_distance(&s) >= r - camkit::tol::OFFSET_TOL)
            });
            if clear {
                out.push(pocket::Pass {
                    contour: c,
                    distance: r,
                    level: 0,
                    region: ri,
                    island: false,
                    clean_up: false,
                });
            }
        }
    }
    out
}

/// Which axis points up (along the tool) in profile mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Up {
    /// The tool axis is +y: profiles in the xy plane (as the paper draws them).
    Y,
    /// The tool axis is +z: profiles in the xz or yz plane (as a 3-axis machine cuts them).
    Z,
}

/// Profile mode: each pass is a profile cut from above by `tool` of radius `r`.
pub fn profile_mode(
    table: &Table,
    name: &str,
    tool: profile::Tool,
    r: f64,
    up: Up,
    gouge_tol: f64,
    opts: &OffsetOptions,
) -> Result<Outcome> {
    let mut report = Report::new("offset");
    report
        .set("mode", "profile")
        .set("tool", if tool == profile::Tool::Ball { "ball" } else { "square" })
        .set("radius_mm", r);
    let (mut out, k) = output_table(table);
    out.schema.add(&[Col::Zc, Col::Plane]);
    let mut warnings = Vec::new();
    let mut plot = None;
    let (mut path, mut worst, mut checked) = (0i64, 0.0f64, 0usize);
    for pass in table.passes() {
        let Some(p) = Profile::read(pass, name, up)? else { continue };
        let segs: Vec<Seg> = p.contour.segs().collect();
        profile::check_monotone(&segs).map_err(|e| {
            let piece = match e {
                profile::ProfileError::NotMonotone(i) => Some(&segs[i]),
                _ => None,
            };
            Error::input(
                "the profile turns back along its horizontal axis (an undercut): a tool from above cannot follow it",
            )
            .at(located(name, piece.and_then(|s| p.row_of(pass, s)).unwrap_or(pass[0].line)))
        })?;
        let tip = match tool {
            profile::Tool::Ball => profile::ball(&p.contour, r, opts),
            profile::Tool::Square => profile::square(&segs, r),
        }
        .map_err(|e| {
            Error::check(format!("profile of path {}: {e:?}", pass[0].path)).at(located(name, pass[0].line))
        })?;
        worst = worst.max(tip.deviation);
        checked += tip.checked;
        if tip.pieces.is_empty() {
            warnings.push(format!("path {}: no tip path", pass[0].path));
            continue;
        }
        let un = profile::unoffset_square(&segs, r, 0.01, gouge_tol);
        let deepest = un.gouge.iter().copied().fold(0.0, f64::max);
        let clear: Vec<[f64; 2]> = un.clear.iter().map(|&(a, b)| [a, b]).collect();
        let centres: Vec<f64> = un.clear.iter().map(|&(a, b)| 0.5 * (a + b)).collect();
        report
            .set("unoffset_square_deepest_gouge_mm", deepest)
            .set("unoffset_square_clear_mm", clear)
            .set("unoffset_square_clear_centres_mm", centres);
        let c = Contour::from_segs(&tip.pieces, false);
        for mut row in p.rows(&c, path, &pass[0]) {
            row.extra.resize(out.schema.extra_names.len(), String::new());
            row.extra[k] = number(r);
            out.rows.push(row);
        }
        path += 1;
        if plot.is_none() {
            let title =
                format!("{name}: {} end mill, R = {r} mm", if tool == profile::Tool::Ball { "ball" } else { "square" });
            plot = Some(plot::profile(&title, &segs, tool, r, &tip.pieces, &un));
        }
    }
    if path == 0 {
        return Err(Error::input("no profile: the table has no pass with two distinct points").at(Location::file(name)));
    }
    report.set("output_paths", path).set("largest_deviation_mm", worst).set("checked", checked);
    let mut plot = plot.expect("a profile was drawn");
    let names = ["x", "y", "z"];
    let (u, v) = Profile::axes_of(table, up);
    plot.labels(&format!("{} (mm)", names[u]), &format!("{} (mm)", names[v]));
    Ok(Outcome { table: out, report, plot, warnings })
}

/// A profile read from one pass: 2D in (along, up), and how to map back.
struct Profile {
    contour: Contour,
    along: usize,
    up: usize,
    depth: f64,
    plane: Plane,
    flip: bool,
}

impl Profile {
    /// Axes (along, up) of a table's profiles.
    fn axes_of(table: &Table, up: Up) -> (usize, usize) {
        match up {
            Up::Y => (0, 1),
            Up::Z => {
                let spread = |i: usize| {
                    let v = table.rows.iter().map(|r| r.pos[i]);
                    v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
                };
                if spread(1) > spread(0) { (1, 2) } else { (0, 2) }
            }
        }
    }

    fn read(pass: &[Row], name: &str, up: Up) -> Result<Option<Profile>> {
        let table = Table { schema: Default::default(), rows: pass.to_vec() };
        let (along, upi) = Profile::axes_of(&table, up);
        let depth_axis = 3 - along - upi;
        let plane = match (along, upi) {
            (0, 1) => Plane::Xy,
            (0, 2) => Plane::Xz,
            _ => Plane::Yz,
        };
        let [pu, _, _] = plane.axes();
        let flip = pu != along;
        let depth = pass[0].pos[depth_axis];
        let mut rows = Vec::with_capacity(pass.len());
        for r in pass {
            if (r.pos[depth_axis] - depth).abs() > camkit::tol::POINT_EPS {
                return Err(
                    Error::input("a profile lies in one vertical plane: this row leaves it").at(located(name, r.line))
                );
            }
            if r.mv.is_arc() && r.plane != plane {
                return Err(Error::input(format!(
                    "the profile's arcs lie in the {} plane, this one in {}",
                    plane.name(),
                    r.plane.name()
                ))
                .at(located(name, r.line).field("plane")));
            }
            let q = P3::new(r.pos[along], r.pos[upi], 0.0);
            let centre = r.centre.map(|c| {
                let c3 = plane.join(&c, 0.0);
                P2::new(c3[along], c3[upi])
            });
            let mv = match (r.mv, flip) {
                (Move::Cw, true) => Move::Ccw,
                (Move::Ccw, true) => Move::Cw,
                (m, _) => m,
            };
            rows.push(Row { pos: q, centre, mv, plane: Plane::Xy, ..r.clone() });
        }
        let t = Table { schema: Default::default(), rows };
        let read = contour_table::read(&t, name)?;
        let Some(src) = read.sources.into_iter().next() else { return Ok(None) };
        let mut contour = src.contour;
        if contour.closed {
            return Err(Error::input("a profile is an open curve: this pass is closed").at(located(name, pass[0].line)));
        }
        let first = contour.vertices[0].p.x;
        let last = contour.vertices[contour.vertices.len() - 1].p.x;
        if last < first {
            contour = contour.reversed();
        }
        Ok(Some(Profile { contour, along, up: upi, depth, plane, flip }))
    }

    /// Source line of the row whose move makes `piece` (the row at one of its ends, the row
    /// before at the other), for messages about that piece.
    fn row_of(&self, pass: &[Row], piece: &Seg) -> Option<u64> {
        let at = |r: &Row, q: &P2| (P2::new(r.pos[self.along], r.pos[self.up]) - q).norm() <= camkit::tol::POINT_EPS;
        let (a, b) = (piece.start(), piece.end());
        pass.windows(2)
            .find(|w| (at(&w[0], &a) && at(&w[1], &b)) || (at(&w[0], &b) && at(&w[1], &a)))
            .map(|w| w[1].line)
    }

    /// Rows of a 2D tip path back in the table's coordinates.
    fn rows(&self, c: &Contour, path: i64, template: &Row) -> Vec<Row> {
        let depth_axis = 3 - self.along - self.up;
        let to3 = |q: &P2| {
            let mut p = P3::origin();
            p[self.along] = q.x;
            p[self.up] = q.y;
            p[depth_axis] = self.depth;
            p
        };
        contours::rows(c, path, 0.0, template)
            .into_iter()
            .map(|mut r| {
                let q = P2::new(r.pos.x, r.pos.y);
                r.pos = to3(&q);
                r.plane = self.plane;
                r.centre = r.centre.map(|c| self.plane.split(&to3(&c)).0);
                if self.flip {
                    r.mv = match r.mv {
                        Move::Cw => Move::Ccw,
                        Move::Ccw => Move::Cw,
                        m => m,
                    };
                }
                r
            })
            .collect()
    }
}

/// 3D mode: each pass a 3D contour with a tool axis per row, offset normal to the axis.
///
/// With `grow_window`, a result that gouges its own pass (the look-ahead missed a part of the
/// contour farther along it than the window but near in space) is made again with the window
/// doubled, until the window spans the longest pass.
pub fn space_mode(table: &Table, name: &str, opts: &space::Options, grow_window: bool) -> Result<Outcome> {
    let mut o = *opts;
    loop {
        match space_try(table, name, &o)? {
            Tried::Done(mut outcome) => {
                outcome.report.set("window_doublings", (o.window / opts.window).log2().round() as u32);
                return Ok(*outcome);
            }
            Tried::Gouge { error, own_pass, longest } => {
                if grow_window && own_pass && o.window < longest {
                    o.window *= 2.0;
                    continue;
                }
                return Err(error);
            }
        }
    }
}

/// One try of [`space_mode`] at the window of `opts`.
enum Tried {
    /// A result that passed the gouge check.
    Done(Box<Outcome>),
    /// The gouge check failed: the error, whether an output came too near its own pass, and the
    /// longest pass (mm).
    Gouge { error: Error, own_pass: bool, longest: f64 },
}

/// [`space_mode`] once: every pass offset at the window of `opts`, then the gouge check.
fn space_try(table: &Table, name: &str, opts: &space::Options) -> Result<Tried> {
    let mut report = Report::new("offset");
    report
        .set("mode", "3d")
        .set("radius_mm", opts.radius)
        .set("window_mm", opts.window)
        .set("chord_tol_mm", opts.chord_tol);
    let mut out = contours::schema(table);
    out.schema.remove(&[Col::Xc, Col::Yc]);
    out.schema.add(&[Col::I, Col::J, Col::K, Col::Px, Col::Py, Col::Pz]);
    let k = out.add_extra_column(OFFSET_COLUMN);
    let (mut above, mut below, mut rounded, mut trimmed, mut merged, mut path) = (0.0f64, 0.0f64, 0, 0, 0, 0i64);
    let (mut drawn_in, mut drawn_out) = (Vec::new(), Vec::new());
    // Every pass's input and output (closed ones repeat their first point), for the gouge check.
    let (mut tracks_in, mut tracks_out, mut first_lines) = (Vec::new(), Vec::new(), Vec::new());
    for pass in table.passes() {
        let mut rows: Vec<&Row> = Vec::new();
        for r in pass {
            if r.mv.is_arc() {
                return Err(Error::input("3D mode reads lines only (an arc with a varying tool axis has no plane)")
                    .at(located(name, r.line).field("move")));
            }
            let n = r.axis.norm();
            if (n - 1.0).abs() > camkit::tol::UNIT_VECTOR_SLACK {
                return Err(Error::input(format!("the tool axis must be a unit vector, its length is {n}"))
                    .at(located(name, r.line).field("i,j,k")));
            }
            if rows.last().is_some_and(|l| (l.pos - r.pos).norm() <= camkit::tol::POINT_EPS) {
                continue;
            }
            rows.push(r);
        }
        if rows.len() < 2 {
            continue;
        }
        let closed = (rows[0].pos - rows[rows.len() - 1].pos).norm() <= camkit::tol::POINT_EPS * 1e3;
        if closed {
            rows.pop();
        }
        let pts: Vec<P3> = rows.iter().map(|r| r.pos).collect();
        let axes: Vec<V3> = rows.iter().map(|r| r.axis.normalize()).collect();
        let o = space::offset(&pts, &axes, closed, opts).map_err(|e| {
            let (i, what) = match e {
                space::Error3::AlongAxis(i) => {
                    (i, "the contour runs along the tool axis here: no plane to offset in".to_string())
                }
                space::Error3::Reversal(i) => (i, "the contour turns straight back on itself here".to_string()),
                space::Error3::Offset(i, m) => (i, m),
            };
            Error::input(what).at(located(name, rows[i].line))
        })?;
        above = above.max(o.above);
        below = below.max(o.below);
        rounded += o.rounded;
        trimmed += o.trimmed;
        merged += o.merged;
        let mut first = true;
        let mut ring: Vec<P3> = o.points.iter().map(|p| p.p).collect();
        if closed && let Some(p) = o.points.first() {
            ring.push(p.p);
        }
        let mut list: Vec<(P3, usize)> = o.points.iter().map(|p| (p.p, p.row)).collect();
        if closed && let Some(p) = o.points.first() {
            list.push((p.p, p.row));
        }
        for (p, ri) in list {
            let src = rows[ri];
            let mut row = Row {
                path,
                mv: if first { Move::Rapid } else { Move::Line },
                pos: p,
                centre: None,
                line: 0,
                contact: Some(src.pos),
                ..src.clone()
            };
            row.extra.resize(out.schema.extra_names.len(), String::new());
            row.extra[k] = number(opts.radius);
            out.rows.push(row);
            first = false;
        }
        let mut track_in = pts.clone();
        if closed {
            track_in.push(pts[0]);
        }
        let mut track_axes: Vec<V3> = o.points.iter().map(|p| axes[p.row]).collect();
        if closed && let Some(p) = o.points.first() {
            track_axes.push(axes[p.row]);
        }
        tracks_in.push(track_in);
        tracks_out.push((ring.clone(), track_axes));
        first_lines.push(rows[0].line);
        drawn_in.push(pts.iter().map(|p| P2::new(p.x, p.y)).collect::<Vec<_>>());
        drawn_out.push(ring.iter().map(|p| P2::new(p.x, p.y)).collect::<Vec<_>>());
        path += 1;
    }
    if path == 0 {
        return Err(Error::input("no contour: the table has no pass with two distinct points").at(Location::file(name)));
    }
    let outputs: Vec<space::Track> = tracks_out.iter().map(|(p, a)| space::Track { pts: p, axes: a }).collect();
    let inputs: Vec<&[P3]> = tracks_in.iter().map(Vec::as_slice).collect();
    let gouge = space::gouge(&outputs, &inputs, opts.radius);
    if gouge.depth > opts.chord_tol {
        let (o, k) = gouge.at;
        let longest =
            inputs.iter().map(|p| p.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>()).fold(0.0, f64::max);
        let error = Error::check(format!(
            "the offset of the pass starting at line {} comes {:.4} mm nearer than R = {} mm to the contour of the \
             pass starting at line {} (its move to point {k}): the tool does not fit there (each pass is offset \
             on its own: passes closer than 2R, or bays narrower than 2R, need a smaller tool)",
            first_lines[o], gouge.depth, opts.radius, first_lines[gouge.input]
        ))
        .at(Location::file(name).line(first_lines[o]));
        return Ok(Tried::Gouge { error, own_pass: o == gouge.input, longest });
    }
    report
        .set("output_paths", path)
        .set("largest_gouge_mm", gouge.depth)
        .set("largest_excess_mm", above)
        .set("largest_shortfall_mm", below)
        .set("rounded_corners", rounded)
        .set("trimmed_rows", trimmed)
        .set("merged_points", merged);
    let plot = plot::space(
        &format!("{name}: 3D offset R = {} mm normal to the tool axis", opts.radius),
        &drawn_in,
        &drawn_out,
    );
    Ok(Tried::Done(Box::new(Outcome { table: out, report, plot, warnings: Vec::new() })))
}

/// Passes for [`pocket_mode`] from the command line's choice.
pub fn passes(repeat: Option<usize>, until_empty: bool) -> Passes {
    match (repeat, until_empty) {
        (_, true) => Passes::UntilEmpty,
        (Some(n), false) => Passes::Count(n),
        (None, false) => Passes::Count(1),
    }
}
