//! Linking: the moves between passes that a job's setup asks for. Every pass start (a `rapid`
//! row, a new `path`, the program start) becomes: retract along the tool axis to the safe height
//! (or the clearance height where a traverse at the safe height would come within the approach
//! distance of material), a rapid traverse at that height (multi-axis re-orientation happens
//! here), a rapid down the tool axis to the approach distance above the material under the tool,
//! and a plunge (or a ramp along the pass) at the plunge feed to the pass start. The program ends
//! with a retract to the clearance height.
//!
//! "The material under the tool" is the stock less what the program has cut so far, tracked on
//! the material map ([`camkit::collide::material`]) as the rows are linked; the collision check
//! later measures the written program again, independently.

use crate::plan::{Cl, ClArc};
use camkit::collide::material::{Cutter, Material};
use camkit::collide::solid::{Body, Placement, Solid};
use camkit::collide::walls::{Column, Walls};
use camkit::contour::Seg;
use camkit::doc::Job;
use camkit::error::{Error, Location, Result};
use camkit::geom::{P2, P3, Plane, V2, V3};

/// The most nodes the material map may have (about 160 MB).
pub const MAX_NODES: usize = 20_000_000;

/// A tool axis tilted less than this from +Z (radians) counts as vertical: the material map
/// follows its cuts exactly; a tilted tool's cuts are not taken off the map (it stays higher,
/// the safe side).
pub const VERTICAL: f64 = 1e-6;

/// The shortest stretch a ramp runs along (mm).
pub const RAMP_LEAST: f64 = 0.01;

/// The most rows of a pass a ramp runs along.
pub const RAMP_ROWS: usize = 10_000;

/// The smallest Z component of a tool axis the post retracts and approaches along.
pub const LEAST_AXIS_Z: f64 = 0.1;

/// What linking did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Links made (pass starts, the program start included).
    pub links: usize,
    /// Traverses raised to the clearance height because the safe height was not clear.
    pub at_clearance: usize,
    /// Plunges (feed moves into material down the tool axis).
    pub plunges: usize,
    /// Their total length (mm).
    pub plunge_mm: f64,
    /// Ramps made instead of plunges.
    pub ramps: usize,
    /// Pass starts reached by rapid alone (already above the material by the approach).
    pub direct: usize,
    /// Lead-in arcs made.
    pub lead_ins: usize,
    /// Lead-out arcs made.
    pub lead_outs: usize,
    /// Lead arcs left out because neither side kept clear of the part.
    pub leads_not_clear: usize,
}

/// The linked rows.
#[derive(Clone, Debug)]
pub struct Linked {
    /// Rows with the links in place.
    pub rows: Vec<Cl>,
    /// Figures.
    pub stats: Stats,
}

/// Everything linking needs besides the rows, and the rows on their way through: linking takes
/// the rows one at a time ([`Linker::push`]), holds the [`RAMP_ROWS`] after the one it links (a
/// ramp's stretch), and hands the linked rows over as it makes them ([`Linker::take`]).
pub struct Linker<'a> {
    job: &'a Job,
    walls: Option<&'a Walls>,
    solid: Option<(&'a Solid, &'a Body)>,
    cutter: Cutter,
    map: Material,
    file: &'a str,
    stats: Stats,
    /// Linked rows not yet taken.
    out: Vec<Cl>,
    /// The last two rows linked (the last one last).
    tail: [Option<Cl>; 2],
    /// Rows waiting for the rows after them.
    ahead: std::collections::VecDeque<Cl>,
    /// Rows linked so far.
    seen: usize,
}

fn xy(p: &P3) -> P2 {
    P2::new(p.x, p.y)
}

fn vertical(axis: &V3) -> bool {
    (axis - V3::z()).norm() <= VERTICAL
}

/// The XY pieces of the move from `prev` to `row` with the tip's heights at their ends: a line, an
/// arc in the XY plane exactly, chords within 0.01 mm of an arc in another plane.
pub fn cut_pieces(prev: &P3, row: &Cl) -> Vec<(Seg, f64, f64)> {
    match &row.arc {
        None => vec![(Seg::Line(xy(prev), xy(&row.tip)), prev.z, row.tip.z)],
        Some(arc) if arc.plane == Plane::Xy => {
            let (a, _, _) = arc.in_plane(prev, &row.tip);
            vec![(Seg::Arc(a), prev.z, row.tip.z)]
        }
        Some(arc) => {
            let (a, _, _) = arc.in_plane(prev, &row.tip);
            let sag = CHORD_SAGITTA.min(a.r);
            let n = ((a.sweep.abs() / (2.0 * (1.0 - sag / a.r).acos())).ceil() as usize).clamp(1, 100_000);
            let mut last = *prev;
            (1..=n)
                .map(|k| {
                    let p = arc.point(prev, &row.tip, k as f64 / n as f64);
                    let piece = (Seg::Line(xy(&last), xy(&p)), last.z, p.z);
                    last = p;
                    piece
                })
                .collect()
        }
    }
}

/// The unit XY direction of travel of the move from `prev` to `row` at its start (`at_end`: at
/// its end), if the move is a level line or XY arc of some length.
fn level_direction(prev: &P3, row: &Cl, at_end: bool) -> Option<V2> {
    if (row.tip.z - prev.z).abs() > 1e-9 {
        return None;
    }
    match &row.arc {
        None => {
            let d = xy(&row.tip) - xy(prev);
            (d.norm() > 1e-9).then(|| d.normalize())
        }
        Some(arc) if arc.plane == Plane::Xy => {
            let (a, _, _) = arc.in_plane(prev, &row.tip);
            (a.length() > 1e-9).then(|| a.tangent_at(if at_end { a.start + a.sweep } else { a.start }))
        }
        Some(_) => None,
    }
}

/// The lead arc of radius `r` and sweep `angle` (radians) tangent to direction `d` at `p`, its
/// centre on the left of `d` if `left`: arriving at `p` if `into`, else leaving it. Returns the
/// arc's other end (at `p`'s height) and the arc as it is run.
pub fn lead_arc(p: &P3, d: &V2, r: f64, angle: f64, left: bool, into: bool) -> (P3, ClArc) {
    let side = if left { 1.0 } else { -1.0 };
    let centre = xy(p) + V2::new(-d.y, d.x) * (side * r);
    // Turning about the centre: counter-clockwise with the centre on the left; back from `p` for
    // a lead-in.
    let turn = side * if into { -angle } else { angle };
    let v = xy(p) - centre;
    let (s, c) = turn.sin_cos();
    let q = centre + V2::new(c * v.x - s * v.y, s * v.x + c * v.y);
    (P3::new(q.x, q.y, p.z), ClArc { plane: Plane::Xy, centre, ccw: left })
}

/// Sagitta of the chords that stand for an arc outside the XY plane on the material map (mm):
/// below half a cell's diagonal at any resolution the map allows, so the map stays conservative.
const CHORD_SAGITTA: f64 = 0.01;

impl<'a> Linker<'a> {
    /// A linker for `job` (with the part's walls or solid, if it has them); `file` names the rows
    /// in messages.
    pub fn new(
        job: &'a Job,
        walls: Option<&'a Walls>,
        solid: Option<(&'a Solid, &'a Body)>,
        file: &'a str,
    ) -> Result<Linker<'a>> {
        let map = Material::new(&job.stock, job.resolution, MAX_NODES).map_err(|n| {
            job.error(
                "resolution",
                format!(
                    "the material map at {} mm would have {n} nodes (at most {MAX_NODES}): raise the resolution",
                    job.resolution
                ),
            )
        })?;
        Ok(Linker {
            job,
            walls,
            solid,
            cutter: Cutter::of(&job.tool),
            map,
            file,
            stats: Stats::default(),
            out: Vec::new(),
            tail: [None; 2],
            ahead: std::collections::VecDeque::new(),
            seen: 0,
        })
    }

    /// Appends a linked row.
    fn emit(&mut self, row: Cl) {
        self.tail = [self.tail[1], Some(row)];
        self.out.push(row);
    }

    /// The last row linked.
    fn last(&self) -> Option<Cl> {
        self.tail[1]
    }

    fn at(&self, row: &Cl) -> Location {
        Location::file(self.file).line(row.line)
    }

    /// The lowest point of the tool body at `row`, relative to its tip (≤ 0): a tilted flat
    /// bottom dips by R·sin(tilt).
    fn dip(&self, axis: &V3) -> f64 {
        let sin = (1.0 - axis.z * axis.z).max(0.0).sqrt();
        -(self.cutter.radius - self.cutter.corner) * sin - self.cutter.corner * (1.0 - axis.z)
    }

    /// Radius round the tip's XY that holds the tool body up to `height` above its lowest point.
    fn reach(&self, axis: &V3, height: f64) -> f64 {
        let tan = (1.0 - axis.z * axis.z).max(0.0).sqrt() / axis.z;
        self.cutter.radius + height.max(0.0) * tan
    }

    /// Highest material under the tool at `row`'s XY (−∞ if none); a footprint that touches the
    /// side of a cut (within the setup's tolerance) does not count the material beyond it.
    fn material_under(&self, tip: &P3, axis: &V3) -> f64 {
        let r = (self.reach(axis, 0.0) - self.job.tolerance).max(0.0);
        let mut top = self.map.highest_within(&xy(tip), r);
        if !vertical(axis) {
            // A tilted body reaches further at the height of the material: widen until stable.
            for _ in 0..3 {
                let low = tip.z + self.dip(axis);
                let r = self.reach(axis, top + self.job.approach - low) - self.job.tolerance;
                top = self.map.highest_within(&xy(tip), r.max(0.0));
            }
        }
        top
    }

    /// The point up the axis from `tip` whose body clears `top` by the approach distance (the tip
    /// itself if it already does).
    fn approach_point(&self, tip: &P3, axis: &V3, top: f64) -> P3 {
        let need = top + self.job.approach - (tip.z + self.dip(axis));
        if need <= 0.0 { *tip } else { tip + axis * (need / axis.z) }
    }

    /// The point up the axis from `tip` at height `h` (the tip if it is higher).
    fn up_to(tip: &P3, axis: &V3, h: f64) -> P3 {
        if tip.z >= h { *tip } else { tip + axis * ((h - tip.z) / axis.z) }
    }

    /// True if a straight traverse between `a` and `b` keeps the body the approach distance
    /// above the material (by the map) with its footprint and its holder's.
    fn clear_traverse(&self, a: &P3, b: &P3, axis_a: &V3, axis_b: &V3) -> bool {
        let piece = Seg::Line(xy(a), xy(b));
        let dip = self.dip(axis_a).min(self.dip(axis_b));
        let tilt = axis_a.z.min(axis_b.z);
        let tilted = V3::new((1.0 - tilt * tilt).max(0.0).sqrt(), 0.0, tilt);
        let top = self.job.stock.top();
        let r = self.reach(&tilted, top + self.job.approach - (a.z.min(b.z) + dip));
        let body = self.map.clearance(&piece, a.z + dip, b.z + dip, r);
        let ok = |c: Option<(f64, P2)>| c.is_none_or(|(c, _)| c >= self.job.approach - 1e-9);
        let holder = match (self.job.tool.holder_diameter, self.job.tool.length) {
            (Some(d), Some(l)) => self.map.clearance(&piece, a.z + l * tilt, b.z + l * tilt, 0.5 * d),
            _ => None,
        };
        ok(body) && ok(holder)
    }

    fn row(&self, tip: P3, from: &Cl, rapid: bool, feed: Option<f64>) -> Cl {
        Cl { tip, axis: from.axis, s: from.s, feed, rapid, reorient: false, line: from.line, arc: None }
    }

    /// The zigzag ramp down to `start` along the first stretch of its pass (`rest`: the rows after
    /// it), for a vertical tool on a level pass: legs to and fro along the pass's own path (its
    /// lines and XY arcs, arcs run backwards on the way back), the stretch as long as two legs at
    /// the setup's ramp angle need from the material under the start (shorter where the pass stops
    /// being level; at most [`RAMP_ROWS`] rows), descending from the approach distance above the
    /// material under the stretch. `None` where there is no such stretch or nothing to descend.
    fn ramp(&self, start: &Cl, rest: impl Iterator<Item = Cl>) -> Option<(P3, Vec<Cl>)> {
        let angle = self.job.ramp_angle?;
        if !vertical(&start.axis) {
            return None;
        }
        let tan = angle.to_radians().tan();
        let r = (self.cutter.radius - self.job.tolerance).max(0.0);
        let mut top = self.map.highest_within(&xy(&start.tip), r);
        // The stretch two legs at the angle need from the material under the start.
        let want = (top + self.job.approach - start.tip.z) / (2.0 * tan);
        // Pieces of the stretch: (from, to, arc), level at the start's height.
        let mut stretch: Vec<(P3, P3, Option<ClArc>)> = Vec::new();
        let mut length = 0.0;
        let mut from = start.tip;
        for row in rest.take(RAMP_ROWS).take_while(|n| !n.rapid && vertical(&n.axis)) {
            let level = (row.tip.z - start.tip.z).abs() <= 1e-9 && row.arc.is_none_or(|a| a.plane == Plane::Xy);
            if !level || length >= want {
                break;
            }
            for (seg, ..) in cut_pieces(&from, &row) {
                top = top.max(self.map.highest_along(&seg, r));
                length += seg.length();
            }
            stretch.push((from, row.tip, row.arc));
            from = row.tip;
        }
        let top = top + self.job.approach;
        let drop = top - start.tip.z;
        if length < RAMP_LEAST || drop <= 0.0 {
            return None;
        }
        let run = drop / tan;
        // An even number of legs, so that the ramp ends where the pass starts.
        let legs = ((run / length).ceil() as usize).max(1).div_ceil(2) * 2;
        let leg = run / legs as f64;
        // One leg out: the stretch cut at length `leg` (the last piece in part).
        let mut out_leg: Vec<(P3, P3, Option<ClArc>)> = Vec::new();
        let mut done = 0.0;
        for &(a, b, arc) in &stretch {
            let l = cut_pieces(&a, &Cl { tip: b, arc, ..*start }).iter().map(|(s, ..)| s.length()).sum::<f64>();
            if done + l >= leg {
                let t = (leg - done) / l;
                let end = match &arc {
                    Some(c) => c.point(&a, &b, t),
                    None => a + (b - a) * t,
                };
                out_leg.push((a, end, arc));
                break;
            }
            done += l;
            out_leg.push((a, b, arc));
        }
        let back: Vec<(P3, P3, Option<ClArc>)> =
            out_leg.iter().rev().map(|&(a, b, arc)| (b, a, arc.map(|c| ClArc { ccw: !c.ccw, ..c }))).collect();
        // Heights by distance run: `drop` over `legs` legs.
        let mut rows = Vec::new();
        let mut ran = 0.0;
        for _ in 0..legs / 2 {
            for &(a, b, arc) in out_leg.iter().chain(&back) {
                ran += cut_pieces(&a, &Cl { tip: b, arc, ..*start }).iter().map(|(s, ..)| s.length()).sum::<f64>();
                let z = top - drop * (ran / run).min(1.0);
                rows.push(Cl {
                    tip: P3::new(b.x, b.y, z),
                    arc,
                    ..self.row(b, start, false, Some(self.job.plunge_feed))
                });
            }
        }
        if let Some(last) = rows.last_mut() {
            last.tip = start.tip;
        }
        Some((P3::new(start.tip.x, start.tip.y, top), rows))
    }

    /// Appends the link from the last row written (or the program start) to the pass that starts
    /// with `start` (`rest`: the rows after it).
    fn link_to(&mut self, start: &Cl, rest: impl Iterator<Item = Cl>) -> Result<()> {
        self.stats.links += 1;
        if start.axis.z < LEAST_AXIS_Z {
            return Err(Error::input(format!(
                "the pass starts with the tool axis {:.1}° from vertical: it cannot be approached along its axis from above",
                start.axis.z.acos().to_degrees()
            ))
            .at(self.at(start).field("i,j,k")));
        }
        let ramp = self.ramp(start, rest);
        let approach = match &ramp {
            Some((top, _)) => *top,
            None => self.approach_point(&start.tip, &start.axis, self.material_under(&start.tip, &start.axis)),
        };
        let prev = self.last();
        let (safe, clear) = (self.job.safe_height, self.job.clearance_height);
        let mut height = safe;
        if let Some(end) = &prev {
            let (a, b) = (Self::up_to(&end.tip, &end.axis, safe), Self::up_to(&approach, &start.axis, safe));
            if !self.clear_traverse(&a, &b, &end.axis, &start.axis) {
                height = clear;
                self.stats.at_clearance += 1;
            }
        } else {
            height = clear;
        }
        if let Some(end) = &prev {
            if end.axis.z < LEAST_AXIS_Z {
                return Err(Error::input(format!(
                    "the pass ends with the tool axis {:.1}° from vertical: it cannot retract along its axis",
                    end.axis.z.acos().to_degrees()
                ))
                .at(self.at(end).field("i,j,k")));
            }
            let up = Self::up_to(&end.tip, &end.axis, height);
            if up != end.tip {
                self.emit(self.row(up, end, true, None));
            }
        }
        let above = Self::up_to(&approach, &start.axis, height);
        let mut traverse = self.row(above, start, true, None);
        traverse.reorient = true;
        self.emit(traverse);
        if approach != above {
            self.emit(self.row(approach, start, true, None));
        }
        if approach == start.tip {
            self.stats.direct += 1;
            return Ok(());
        }
        let rows = match ramp {
            Some((_, rows)) => {
                self.stats.ramps += 1;
                rows
            }
            None => {
                self.stats.plunges += 1;
                self.stats.plunge_mm += (approach - start.tip).norm();
                vec![self.row(start.tip, start, false, Some(self.job.plunge_feed))]
            }
        };
        for row in rows {
            self.feed(&row);
        }
        Ok(())
    }

    /// Appends a feed row, taking its cut off the map.
    fn feed(&mut self, row: &Cl) {
        if let Some(prev) = self.last()
            && vertical(&row.axis)
            && vertical(&prev.axis)
        {
            for (seg, z0, z1) in cut_pieces(&prev.tip, row) {
                self.map.cut(&self.cutter, &seg, z0, z1);
            }
        }
        self.emit(Cl { rapid: false, reorient: false, ..*row });
    }

    /// The vertical tool body measured against the part's walls.
    fn column(&self) -> Column {
        Column {
            radius: self.cutter.radius,
            length: self.job.tool.length.unwrap_or(6.0 * self.cutter.radius),
            holder_radius: 0.0,
        }
    }

    /// Smallest clearance from the part (walls or model) of the tool running the arc from `a` to
    /// `b` (+∞ where the setup names no part).
    fn arc_clearance(&self, a: &P3, b: &P3, arc: &ClArc) -> f64 {
        let mut least = f64::INFINITY;
        if let Some(walls) = self.walls {
            let (a2, _, _) = arc.in_plane(a, b);
            least = least.min(walls.clearance(&self.column(), &Seg::Arc(a2), a.z, b.z).mm);
        }
        if let Some((solid, body)) = self.solid {
            let (a2, _, _) = arc.in_plane(a, b);
            let n = ((a2.length() / self.job.resolution).ceil() as usize).clamp(2, 10_000);
            for k in 0..=n {
                let tip = arc.point(a, b, k as f64 / n as f64);
                least = least.min(solid.clearance(body, &Placement { tip, axis: V3::z(), edge: None }, 1.0));
            }
        }
        least
    }

    /// The lead arc at `p` along `d` (left, climb milling's side away from the wall, if it keeps
    /// clear of the part, else right), if the setup asks for leads and a side is clear: its other
    /// end and the arc.
    fn lead(&mut self, p: &P3, d: &V2, into: bool) -> Option<(P3, ClArc)> {
        let lead = self.job.lead?;
        let least = self.job.allowance - self.job.tolerance;
        for left in [true, false] {
            let (q, arc) = lead_arc(p, d, lead.radius, lead.angle.to_radians(), left, into);
            let (a, b) = if into { (q, *p) } else { (*p, q) };
            if self.arc_clearance(&a, &b, &arc) >= least {
                return Some((q, arc));
            }
        }
        self.stats.leads_not_clear += 1;
        None
    }

    /// The lead-in to the pass that starts with `start` and goes on with `next`: a start row at
    /// the arc's far end and the arc to `start`, for a vertical tool on a level first move.
    fn lead_in(&mut self, start: &Cl, next: Option<&Cl>) -> Option<(Cl, Cl)> {
        let next = next.filter(|n| !n.rapid && vertical(&n.axis) && vertical(&start.axis))?;
        let d = level_direction(&start.tip, next, false)?;
        let (q, arc) = self.lead(&start.tip, &d, true)?;
        self.stats.lead_ins += 1;
        let feed = next.feed.or(start.feed);
        Some((Cl { tip: q, ..*start }, Cl { feed, rapid: false, reorient: false, arc: Some(arc), ..*start }))
    }

    /// The lead-out from the pass just written, if its last move is level with a vertical tool.
    fn lead_out(&mut self) {
        let [Some(prev), Some(end)] = self.tail else { return };
        if prev.rapid || end.rapid || !vertical(&end.axis) || !vertical(&prev.axis) {
            return;
        }
        let Some(d) = level_direction(&prev.tip, &end, true) else { return };
        if let Some((q, arc)) = self.lead(&end.tip, &d, false) {
            self.stats.lead_outs += 1;
            self.feed(&Cl { tip: q, arc: Some(arc), ..end });
        }
    }

    /// Refuses a pass that starts inside the part: the post cannot reach it safely. Rows that
    /// start no pass pass.
    pub fn reachable(&self, row: &Cl) -> Result<()> {
        if !row.rapid {
            return Ok(());
        }
        if let Some((solid, body)) = self.solid {
            let edge = row.s.map(|s| camkit::kinematics::edge_direction(&row.axis, s));
            let c = solid.clearance(body, &Placement { tip: row.tip, axis: row.axis, edge }, 1.0);
            if c < self.job.allowance - self.job.tolerance {
                return Err(self.job.error(
                    "part",
                    format!(
                        "the pass starting at {}:{} ({:.4}, {:.4}, {:.4}) cannot be reached safely: the tool there comes {c:.4} mm from the part's model (allowance {} mm)",
                        self.file, row.line, row.tip.x, row.tip.y, row.tip.z, self.job.allowance
                    ),
                ));
            }
        }
        let Some(walls) = self.walls.filter(|_| vertical(&row.axis)) else { return Ok(()) };
        let p = xy(&row.tip);
        let c = walls.clearance(&self.column(), &Seg::Line(p, p), row.tip.z, row.tip.z).mm;
        if c < self.job.allowance - self.job.tolerance {
            return Err(self.job.error(
                "part",
                format!(
                    "the pass starting at {}:{} ({:.4}, {:.4}, {:.4}) cannot be reached safely: the tool there comes {c:.4} mm from the part's walls or floor (allowance {} mm)",
                    self.file, row.line, row.tip.x, row.tip.y, row.tip.z, self.job.allowance
                ),
            ));
        }
        Ok(())
    }

    /// Takes the next row (pass starts are the rows marked `rapid`): linked once the
    /// [`RAMP_ROWS`] after it have come (or [`Linker::finish`]).
    pub fn push(&mut self, row: Cl) -> Result<()> {
        self.ahead.push_back(row);
        if self.ahead.len() > RAMP_ROWS {
            self.link_next()?;
        }
        Ok(())
    }

    /// Links the first row waiting.
    fn link_next(&mut self) -> Result<()> {
        let ahead = std::mem::take(&mut self.ahead);
        let done = self.link_front(&ahead);
        self.ahead = ahead;
        self.ahead.pop_front();
        self.seen += 1;
        done
    }

    fn link_front(&mut self, ahead: &std::collections::VecDeque<Cl>) -> Result<()> {
        let row = ahead[0];
        let rest = || ahead.iter().skip(1).copied();
        if row.rapid || self.last().is_none() {
            if self.seen > 0 {
                self.lead_out();
            }
            match self.lead_in(&row, ahead.get(1)) {
                Some((start, arc)) => {
                    // The ramp, if any, runs along the lead-in and on into the pass.
                    self.link_to(&start, std::iter::once(arc).chain(rest().take(RAMP_ROWS)))?;
                    self.feed(&arc);
                }
                None => self.link_to(&row, rest())?,
            }
        } else {
            self.feed(&row);
        }
        Ok(())
    }

    /// The linked rows made so far, taken out.
    pub fn take(&mut self) -> std::vec::Drain<'_, Cl> {
        self.out.drain(..)
    }

    /// Links the rows still waiting, leads out of the last pass and retracts to the clearance
    /// height; the figures.
    pub fn finish(&mut self) -> Result<Stats> {
        while !self.ahead.is_empty() {
            self.link_next()?;
        }
        if self.seen > 0 {
            self.lead_out();
        }
        if let Some(end) = self.last() {
            let up = Self::up_to(&end.tip, &end.axis, self.job.clearance_height);
            if up != end.tip {
                self.emit(self.row(up, &end, true, None));
            }
        }
        Ok(self.stats)
    }

    /// Links all `rows` at once: refused if one cuts outside the stock ([`outside_stock`]), then
    /// if a pass starts inside the part ([`Linker::reachable`]), each the first such row.
    pub fn link(mut self, rows: &[Cl]) -> Result<Linked> {
        if let Some(e) = rows.iter().find_map(|row| outside_stock(self.job, self.file, row)) {
            return Err(e);
        }
        for row in rows {
            self.reachable(row)?;
        }
        let mut out = Vec::new();
        for row in rows {
            self.push(*row)?;
            out.extend(self.take());
        }
        let stats = self.finish()?;
        out.extend(self.take());
        Ok(Linked { rows: out, stats })
    }
}

/// The refusal of a row that cuts outside the stock (`file` names the rows): below its bottom,
/// or beyond its outline by more than the tool radius. Rapid rows are not cuts.
pub fn outside_stock(job: &Job, file: &str, row: &Cl) -> Option<Error> {
    if row.rapid {
        return None;
    }
    let (lo, hi) = job.stock.extent();
    let r = job.tool.radius;
    let p = row.tip;
    let outside = p.x < lo[0] - r || p.x > hi[0] + r || p.y < lo[1] - r || p.y > hi[1] + r;
    (outside || p.z < job.stock.bottom()).then(|| {
        job.error(
            "stock",
            format!(
                "the stock does not contain the toolpath: {file}:{} cuts at ({:.4}, {:.4}, {:.4}), {} the stock (x {}..{}, y {}..{}, z {}..{})",
                row.line,
                p.x,
                p.y,
                p.z,
                if outside { "outside" } else { "below" },
                lo[0],
                hi[0],
                lo[1],
                hi[1],
                job.stock.bottom(),
                job.stock.top()
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use camkit::doc::setup::{Job, Lead, Stock};
    use camkit::doc::tool::Tool;

    fn tool() -> Tool {
        let text = r#"{"kind": "flat", "radius": 4, "number": 1, "plunge_feed": 200}"#;
        camkit::json::from_input(&camkit::io::Input { name: "t.json".into(), data: text.as_bytes().to_vec() }).unwrap()
    }

    fn job(stock_top: f64, safe: f64, ramp: Option<f64>) -> Job {
        Job {
            file: "s.json".into(),
            source: String::new(),
            tool: tool(),
            tool_file: "t.json".into(),
            stock: Stock::Box { min: P3::new(0.0, 0.0, -30.0), max: P3::new(100.0, 60.0, stock_top) },
            part: None,
            part_top: 0.0,
            clearance_height: 30.0,
            safe_height: safe,
            approach: 1.0,
            plunge_feed: 200.0,
            ramp_angle: ramp,
            lead: None::<Lead>,
            allowance: 0.0,
            tolerance: 0.01,
            coolant: Default::default(),
            resolution: 0.5,
        }
    }

    fn cl(x: f64, y: f64, z: f64, rapid: bool) -> Cl {
        Cl {
            tip: P3::new(x, y, z),
            axis: V3::z(),
            s: None,
            feed: Some(800.0),
            rapid,
            reorient: rapid,
            line: 2,
            arc: None,
        }
    }

    /// Two slots at −5: the first reached from the clearance height, the second by a retract to
    /// the safe height, a traverse, a rapid down to 1 mm above the stock and a plunge at 200.
    #[test]
    fn two_passes_are_linked_through_the_safe_height() {
        let j = job(0.0, 5.0, None);
        let rows = [
            cl(10.0, 10.0, -5.0, true),
            cl(90.0, 10.0, -5.0, false),
            cl(10.0, 50.0, -5.0, true),
            cl(90.0, 50.0, -5.0, false),
        ];
        let l = Linker::new(&j, None, None, "t.csv").unwrap().link(&rows).unwrap();
        let got: Vec<(f64, f64, f64, bool, Option<f64>)> =
            l.rows.iter().map(|r| (r.tip.x, r.tip.y, r.tip.z, r.rapid, if r.rapid { None } else { r.feed })).collect();
        let want = vec![
            (10.0, 10.0, 30.0, true, None),
            (10.0, 10.0, 1.0, true, None),
            (10.0, 10.0, -5.0, false, Some(200.0)),
            (90.0, 10.0, -5.0, false, Some(800.0)),
            (90.0, 10.0, 5.0, true, None),
            (10.0, 50.0, 5.0, true, None),
            (10.0, 50.0, 1.0, true, None),
            (10.0, 50.0, -5.0, false, Some(200.0)),
            (90.0, 50.0, -5.0, false, Some(800.0)),
            (90.0, 50.0, 30.0, true, None),
        ];
        assert_eq!(got, want);
        assert_eq!(l.rows.iter().filter(|r| r.reorient).count(), 2, "re-orientation only at the traverses");
        assert_eq!((l.stats.links, l.stats.plunges, l.stats.plunge_mm, l.stats.at_clearance), (2, 2, 12.0, 0));
    }

    /// The second pass starts inside the first one's slot: the rapid comes down to 1 mm above its
    /// floor, not the stock top; a pass over material taller than the safe height is reached at
    /// the clearance height.
    #[test]
    fn approach_follows_the_cut_material_and_tall_stock_raises_the_traverse() {
        let j = job(0.0, 5.0, None);
        let rows = [
            cl(10.0, 10.0, -5.0, true),
            cl(90.0, 10.0, -5.0, false),
            cl(50.0, 10.0, -8.0, true),
            cl(60.0, 10.0, -8.0, false),
        ];
        let l = Linker::new(&j, None, None, "t.csv").unwrap().link(&rows).unwrap();
        assert!(l.rows.iter().any(|r| r.rapid && r.tip == P3::new(50.0, 10.0, -4.0)), "{:?}", l.rows);
        assert_eq!(l.stats.plunge_mm, 6.0 + 4.0);
        // Stock 8 mm above the part (and the safe height): a traverse along the cut slot stays at
        // the safe height, one across uncut stock goes over at the clearance height.
        let mut tall = job(8.0, 5.0, None);
        tall.part_top = 0.0;
        let l = Linker::new(&tall, None, None, "t.csv").unwrap().link(&rows).unwrap();
        assert_eq!(l.stats.at_clearance, 0, "{:?}", l.rows);
        let across = [rows[0], rows[1], cl(50.0, 40.0, -8.0, true), cl(60.0, 40.0, -8.0, false)];
        let l = Linker::new(&tall, None, None, "t.csv").unwrap().link(&across).unwrap();
        assert_eq!(l.stats.at_clearance, 1);
        let traverse = l.rows.iter().find(|r| r.reorient && r.tip.x == 50.0).unwrap();
        assert_eq!(traverse.tip.z, 30.0);
    }

    /// A ramp descends along the pass at the setup's angle (its legs' slope, to rounding), never
    /// leaves the pass's path, and ends at the pass start.
    #[test]
    fn ramps_descend_at_the_angle_along_the_pass() {
        let j = job(0.0, 5.0, Some(3.0));
        let rows = [cl(10.0, 10.0, -5.0, true), cl(20.0, 10.0, -5.0, false), cl(20.0, 30.0, -5.0, false)];
        let l = Linker::new(&j, None, None, "t.csv").unwrap().link(&rows).unwrap();
        assert_eq!((l.stats.ramps, l.stats.plunges), (1, 0));
        let start = l.rows.iter().position(|r| !r.rapid).unwrap();
        let ramp: Vec<&Cl> =
            l.rows[start - 1..].iter().take_while(|r| r.tip.z > -5.0 || r.tip == P3::new(10.0, 10.0, -5.0)).collect();
        assert_eq!(ramp[0].tip, P3::new(10.0, 10.0, 1.0));
        let last = ramp.last().unwrap();
        assert_eq!(last.tip, P3::new(10.0, 10.0, -5.0));
        let tan = 3f64.to_radians().tan();
        for w in ramp.windows(2) {
            let run = (w[1].tip.xy() - w[0].tip.xy()).norm();
            let drop = w[0].tip.z - w[1].tip.z;
            assert!(drop > 0.0 && (drop - run * tan).abs() < 1e-9, "{:?} {:?}", w[0].tip, w[1].tip);
            assert!(w[1].tip.y == 10.0 || w[1].tip.x == 20.0, "off the pass: {:?}", w[1].tip);
            assert_eq!(w[1].feed, Some(200.0));
        }
    }

    /// Lead arcs of R3 into and out of a level slot along +X, with no part named: on the left,
    /// quarter circles tangent to the slot, the plunge at the lead-in's start.
    #[test]
    fn lead_arcs_enter_and_leave_a_level_pass_tangentially() {
        let mut j = job(0.0, 5.0, None);
        j.lead = Some(Lead { radius: 3.0, angle: 90.0 });
        let rows = [cl(10.0, 10.0, -5.0, true), cl(90.0, 10.0, -5.0, false)];
        let l = Linker::new(&j, None, None, "t.csv").unwrap().link(&rows).unwrap();
        let got: Vec<(P3, bool, Option<ClArc>)> = l.rows.iter().map(|r| (r.tip, r.rapid, r.arc)).collect();
        let ccw = |x: f64, y: f64| Some(ClArc { plane: Plane::Xy, centre: P2::new(x, y), ccw: true });
        let want = vec![
            (P3::new(7.0, 13.0, 30.0), true, None),
            (P3::new(7.0, 13.0, 1.0), true, None),
            (P3::new(7.0, 13.0, -5.0), false, None),
            (P3::new(10.0, 10.0, -5.0), false, ccw(10.0, 13.0)),
            (P3::new(90.0, 10.0, -5.0), false, None),
            (P3::new(93.0, 13.0, -5.0), false, ccw(90.0, 13.0)),
            (P3::new(93.0, 13.0, 30.0), true, None),
        ];
        assert_eq!(got.len(), want.len(), "{got:?}");
        for (g, w) in got.iter().zip(&want) {
            assert!((g.0 - w.0).norm() < 1e-12 && g.1 == w.1, "{g:?} != {w:?}");
            assert_eq!(g.2.map(|a| a.ccw), w.2.map(|a| a.ccw));
            if let (Some(a), Some(b)) = (g.2, w.2) {
                assert!((a.centre - b.centre).norm() < 1e-12, "{g:?}");
            }
        }
        assert_eq!(l.rows[3].feed, Some(800.0), "the lead-in at the pass's feed");
        assert_eq!((l.stats.lead_ins, l.stats.lead_outs, l.stats.leads_not_clear), (1, 1, 0));
    }

    /// A slot along a wall on its left: the leads go right, away from the wall; a slot between
    /// two walls too near for either side gets none, and says so.
    #[test]
    fn lead_arcs_keep_to_the_side_clear_of_the_walls() {
        use camkit::contour::Contour;
        use camkit::contour::region::regions;
        let pocket = |h: f64| {
            let outer =
                Contour::polygon(&[P2::new(0.0, 0.0), P2::new(100.0, 0.0), P2::new(100.0, h), P2::new(0.0, h)], true);
            let (r, _) = regions(&[outer]).unwrap();
            Walls::new(&r, -12.0, 0.0, 10.0)
        };
        let mut j = job(0.0, 5.0, None);
        j.lead = Some(Lead { radius: 3.0, angle: 90.0 });
        // The wall y = 20 is 4 mm (R) to the slot's left.
        let walls = pocket(20.0);
        let rows = [cl(10.0, 16.0, -5.0, true), cl(90.0, 16.0, -5.0, false)];
        let l = Linker::new(&j, Some(&walls), None, "t.csv").unwrap().link(&rows).unwrap();
        let arcs: Vec<&Cl> = l.rows.iter().filter(|r| r.arc.is_some()).collect();
        assert_eq!(arcs.len(), 2);
        assert!(arcs.iter().all(|r| !r.arc.unwrap().ccw && r.arc.unwrap().centre.y == 13.0), "{arcs:?}");
        assert!(l.rows.iter().all(|r| r.tip.y <= 16.0 + 1e-12), "{:?}", l.rows);
        // A slot 8 mm wide (the tool's width): no room for a lead on either side.
        let walls = pocket(8.0);
        let rows = [cl(10.0, 4.0, -5.0, true), cl(90.0, 4.0, -5.0, false)];
        let l = Linker::new(&j, Some(&walls), None, "t.csv").unwrap().link(&rows).unwrap();
        assert!(l.rows.iter().all(|r| r.arc.is_none()));
        assert_eq!((l.stats.lead_ins, l.stats.lead_outs, l.stats.leads_not_clear), (0, 0, 2));
    }

    proptest::proptest! {
        /// A lead arc has the lead's radius and sweep, meets the pass at its point with the pass's
        /// direction, and has its centre on the side asked for.
        #[test]
        fn lead_arcs_are_tangent(a in 0.0..std::f64::consts::TAU, r in 0.1..20.0f64, sweep in 1.0..180.0f64,
                                 left: bool, into: bool) {
            let (p, d) = (P3::new(3.0, -2.0, -4.0), V2::new(a.cos(), a.sin()));
            let (q, arc) = lead_arc(&p, &d, r, sweep.to_radians(), left, into);
            let (from, to) = if into { (q, p) } else { (p, q) };
            let (a2, w0, w1) = arc.in_plane(&from, &to);
            proptest::prop_assert!((a2.r - r).abs() < 1e-9 && w0 == -4.0 && w1 == -4.0);
            proptest::prop_assert!((a2.sweep.abs() - sweep.to_radians()).abs() < 1e-9);
            let t = a2.tangent_at(if into { a2.start + a2.sweep } else { a2.start });
            proptest::prop_assert!((t - d).norm() < 1e-9, "tangent {t:?} vs {d:?}");
            let c = a2.c - xy(&p);
            proptest::prop_assert!((d.x * c.y - d.y * c.x > 0.0) == left);
        }
    }

    #[test]
    fn toolpaths_outside_the_stock_are_refused() {
        let j = job(0.0, 5.0, None);
        let rows = [cl(10.0, 10.0, -5.0, true), cl(120.0, 10.0, -5.0, false)];
        let e = Linker::new(&j, None, None, "t.csv").unwrap().link(&rows).unwrap_err();
        assert!(e.to_string().starts_with("s.json (stock): the stock does not contain the toolpath: t.csv:2"), "{e}");
        let rows = [cl(10.0, 10.0, -5.0, true), cl(20.0, 10.0, -31.0, false)];
        let e = Linker::new(&j, None, None, "t.csv").unwrap().link(&rows).unwrap_err();
        assert!(e.to_string().contains("below the stock"), "{e}");
        let mut tilted = cl(10.0, 10.0, -5.0, true);
        tilted.axis = V3::new(1.0, 0.0, 0.05).normalize();
        let e = Linker::new(&j, None, None, "t.csv").unwrap().link(&[tilted]).unwrap_err();
        assert!(e.to_string().contains("cannot be approached along its axis"), "{e}");
    }
}
