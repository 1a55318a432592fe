//! From CL rows to machine blocks: a pose per row (inverse kinematics, the sequence of solutions
//! [`crate::branch`] chooses, the primary axis held or interpolated near the singularity where that
//! keeps the axis within tolerance, wrapping axes and the spindle orientation unwound between
//! passes), then blocks inserted until the controller's linear interpolation of every axis keeps the
//! tool tip within `tol` of the straight CL segment and the tool axis within `angle_tol` of the CL's.

use crate::branch::Choices;
use camkit::geom::dist::point_arc;
use camkit::geom::{Arc2, P2, P3, Plane, V3};
use camkit::io::spool::{Put, Take};
use camkit::io::{Get, Record};
use camkit::kinematics::{Chain, Joints, M3, Solver, principal_deg};

/// An arc of the toolpath in the workpiece frame: from the previous row's tip to this row's,
/// about `centre` (in the plane's (u, v) coordinates, [`Plane::split`]), turning counter-clockwise
/// in (u, v) if `ccw` (G3); the coordinate along the plane's normal changes linearly (a helix).
/// Ends that coincide make a full circle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClArc {
    /// The arc's plane.
    pub plane: Plane,
    /// Centre, in the plane's coordinates.
    pub centre: P2,
    /// Counter-clockwise in the plane's coordinates.
    pub ccw: bool,
}

impl ClArc {
    /// The arc in plane coordinates from `a` to `b`, and the normal coordinates at both ends.
    pub fn in_plane(&self, a: &P3, b: &P3) -> (Arc2, f64, f64) {
        let (pa, wa) = self.plane.split(a);
        let (pb, wb) = self.plane.split(b);
        (Arc2::from_centre(self.centre, &pa, &pb, self.ccw, true), wa, wb)
    }

    /// The point at fraction `t` of the arc from `a` to `b`.
    pub fn point(&self, a: &P3, b: &P3, t: f64) -> P3 {
        let (arc, wa, wb) = self.in_plane(a, b);
        self.plane.join(&arc.point_at_fraction(t), wa + (wb - wa) * t)
    }

    /// Distance from `p` to the arc from `a` to `b`: exact for a planar arc, within 1e-9 of it for
    /// a helix (samples refined by golden-section search).
    pub fn distance(&self, p: &P3, a: &P3, b: &P3) -> f64 {
        let (arc, wa, wb) = self.in_plane(a, b);
        let (q, w) = self.plane.split(p);
        if wa == wb {
            return point_arc(&q, &arc).hypot(w - wa);
        }
        let at = |t: f64| (self.plane.join(&arc.point_at_fraction(t), wa + (wb - wa) * t) - p).norm();
        let n = 64;
        let k = (0..=n).min_by(|&i, &j| at(i as f64 / n as f64).total_cmp(&at(j as f64 / n as f64))).unwrap_or(0);
        let (mut lo, mut hi) = ((k.max(1) - 1) as f64 / n as f64, ((k + 1).min(n)) as f64 / n as f64);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..60 {
            let (c, d) = (hi - g * (hi - lo), lo + g * (hi - lo));
            if at(c) <= at(d) {
                hi = d;
            } else {
                lo = c;
            }
        }
        at(0.5 * (lo + hi)).min(at(k as f64 / n as f64))
    }

    /// Radius at the start and at the end.
    pub fn radii(&self, a: &P3, b: &P3) -> (f64, f64) {
        ((self.plane.split(a).0 - self.centre).norm(), (self.plane.split(b).0 - self.centre).norm())
    }
}

/// An arc the controller runs (G2/G3): its plane among G17/G18/G19, centre in the controller's
/// plane coordinates, direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepArc {
    /// G17, G18 or G19.
    pub plane: Plane,
    /// Centre in the plane's coordinates (controller X, Y, Z).
    pub centre: P2,
    /// G3.
    pub ccw: bool,
}

/// One CL row as the post needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cl {
    /// Tool tip in the workpiece frame (mm).
    pub tip: P3,
    /// Unit tool axis.
    pub axis: V3,
    /// Spindle orientation of a non-rotating tool (degrees), if commanded.
    pub s: Option<f64>,
    /// Feed (mm/min).
    pub feed: Option<f64>,
    /// The row starts a pass (rapid, or a new `path`): reached by G0.
    pub rapid: bool,
    /// The rotary axes may turn freely on the way to this row (a G0 at a retract height):
    /// wrapping axes are unwound here, and nowhere else.
    pub reorient: bool,
    /// Source line, for messages.
    pub line: u64,
    /// The row is reached along an arc from the previous row.
    pub arc: Option<ClArc>,
}

/// A CL row on disk: every field bit for bit.
impl Record for Cl {
    const SIZE: usize = 6 * 8 + 2 * 9 + 8 + 16 + 3;
    fn put(&self, out: &mut Put) {
        out.f64(self.tip.x).f64(self.tip.y).f64(self.tip.z);
        out.f64(self.axis.x).f64(self.axis.y).f64(self.axis.z);
        out.opt_f64(self.s).opt_f64(self.feed).u64(self.line);
        let arc = self.arc.unwrap_or(ClArc { plane: Plane::Xy, centre: P2::origin(), ccw: false });
        out.f64(arc.centre.x).f64(arc.centre.y);
        let plane = match arc.plane {
            Plane::Xy => 0,
            Plane::Xz => 1,
            Plane::Yz => 2,
        };
        let flags = u8::from(self.rapid) | u8::from(self.reorient) << 1 | u8::from(self.arc.is_some()) << 2;
        out.u8(flags).u8(plane).u8(u8::from(arc.ccw));
    }
    fn take(bytes: &mut Take) -> Self {
        let tip = P3::new(bytes.f64(), bytes.f64(), bytes.f64());
        let axis = V3::new(bytes.f64(), bytes.f64(), bytes.f64());
        let (s, feed, line) = (bytes.opt_f64(), bytes.opt_f64(), bytes.u64());
        let centre = P2::new(bytes.f64(), bytes.f64());
        let (flags, plane, ccw) = (bytes.u8(), bytes.u8(), bytes.u8() != 0);
        let plane = match plane {
            1 => Plane::Xz,
            2 => Plane::Yz,
            _ => Plane::Xy,
        };
        let arc = (flags & 4 != 0).then_some(ClArc { plane, centre, ccw });
        Cl { tip, axis, s, feed, rapid: flags & 1 != 0, reorient: flags & 2 != 0, line, arc }
    }
}

/// How the spindle orientation is commanded, for planning.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpindleSetup {
    /// Controller angle at which the edge faces the tool frame's +X.
    pub offset: f64,
    /// +1 or −1.
    pub sense: f64,
    /// Interpolated with the other axes (true) or set stepwise by M19 before each block (false).
    pub interpolated: bool,
}

/// Planning options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Largest distance (mm) of the interpolated tool tip from the straight CL segment.
    pub tol: f64,
    /// Largest angle (radians) of the interpolated tool axis from the arc between the end axes.
    pub angle_tol: f64,
    /// Largest error (degrees) of the spindle orientation between blocks.
    pub spindle_tol: f64,
    /// Tool-centre-point mode: the control interpolates the tip itself.
    pub tcp: bool,
    /// Interpolate the primary axis through singular runs (else hold it).
    pub interpolate_singular: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            tol: 0.005,
            angle_tol: 0.05f64.to_radians(),
            spindle_tol: 0.5,
            tcp: false,
            interpolate_singular: true,
        }
    }
}

/// One NC motion block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Controller values: X, Y, Z (mm; the tip in the workpiece frame in TCP mode) and rotary
    /// angles, unwound.
    pub joints: Joints,
    /// Controller spindle angle (degrees, unwound), if commanded.
    pub spindle: Option<f64>,
    /// The target this block ends at (interpolated for inserted blocks).
    pub cl: Cl,
    /// Index of the CL row this block ends at or leads to.
    pub row: usize,
    /// Added by linearisation.
    pub inserted: bool,
    /// The primary axis was held or interpolated here (singular cone).
    pub singular: bool,
    /// The controller reaches this block along an arc (G2/G3).
    pub arc: Option<StepArc>,
}

/// Figures of a plan.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// CL rows.
    pub rows: usize,
    /// Blocks inserted by linearisation.
    pub inserted: usize,
    /// Rows inside the singular cone.
    pub singular_rows: usize,
    /// Wrapping axes unwound at a pass start.
    pub unwinds: usize,
    /// Spindle orientations unwound (past a full turn) at a pass start.
    pub spindle_unwinds: usize,
    /// Largest tip deviation (mm) between blocks, as sampled while linearising.
    pub tip_deviation: f64,
    /// Largest axis deviation (radians) between blocks, as sampled while linearising.
    pub axis_deviation: f64,
    /// Largest angle (radians) between a pose's tool axis and its CL row's (singular cone).
    pub pose_axis_error: f64,
    /// Arcs written as G2/G3.
    pub arcs: usize,
    /// Arcs linearised (the rotary axes move over them, or their plane is not one of the
    /// controller's).
    pub arcs_linearised: usize,
}

/// Why planning failed: the row (index) and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanError {
    /// Index of the CL row.
    pub row: usize,
    /// What the user must change.
    pub message: String,
    /// True for a pose no solution reaches (input error); false for a check that failed.
    pub unreachable: bool,
}

/// Travel limits of X, Y, Z.
pub type Travel = [Option<[f64; 2]>; 3];

/// Everything planning needs about the machine.
pub struct Machine<'a> {
    /// Solver with the chain, policy and singular cone.
    pub solver: Solver<'a>,
    /// Linear travel.
    pub travel: Travel,
    /// The sixth axis, if any.
    pub spindle: Option<SpindleSetup>,
}

impl Machine<'_> {
    fn chain(&self) -> &Chain {
        self.solver.chain
    }

    /// Controller linear values for a tip at rotary angles, and the tool frame orientation there.
    fn linear(&self, tip: &P3, rot: &[f64; 2], tcp: bool) -> (V3, M3) {
        if tcp { (tip.coords, self.chain().orientation(rot)) } else { self.chain().linear_oriented(tip, rot) }
    }

    /// Controller spindle angle for CL orientation `s` with the tool frame at orientation `frame`,
    /// near `prev`.
    fn spindle_in(&self, frame: &M3, s: Option<f64>, prev: Option<f64>) -> Option<f64> {
        let sp = self.spindle?;
        let s = s?;
        let a = sp.offset + sp.sense * Chain::spindle_angle_in(frame, s);
        Some(match prev {
            Some(p) => p + principal_deg(a - p),
            None => principal_deg(a),
        })
    }

    fn check_travel(&self, xyz: &V3) -> Result<(), String> {
        for (k, name) in ["X", "Y", "Z"].iter().enumerate() {
            if let Some([lo, hi]) = self.travel[k]
                && (!xyz[k].is_finite() || xyz[k] < lo - 1e-9 || xyz[k] > hi + 1e-9)
            {
                return Err(format!("{name} would be {:.4} mm, outside its travel {lo}..{hi}", xyz[k]));
            }
        }
        Ok(())
    }

    /// Tip, axis and tool frame orientation the controller is at for joints `q`.
    fn at(&self, q: &Joints, tcp: bool) -> (P3, V3, M3) {
        if tcp {
            let m = self.chain().orientation(&q.rot);
            (P3::from(q.xyz), m.column(2).into_owned(), m)
        } else {
            let (p, m) = self.chain().forward_oriented(q);
            (p.tip, p.axis, m)
        }
    }
}

/// Angle between unit vectors (radians), accurate for small angles.
pub fn angle_between(a: &V3, b: &V3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// Distance from `p` to the segment `a`–`b`.
pub fn point_segment(p: &P3, a: &P3, b: &P3) -> f64 {
    let d = b - a;
    let l2 = d.norm_squared();
    let t = if l2 > 0.0 { ((p - a).dot(&d) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + d * t)).norm()
}

/// Angle (radians) from unit vector `v` to the shorter great-circle arc from `a` to `b`.
pub fn vector_arc(v: &V3, a: &V3, b: &V3) -> f64 {
    let n = a.cross(b);
    let nn = n.norm();
    // The angle to the nearer end, computed only where needed (a hot path of the post).
    let ends = || angle_between(v, a).min(angle_between(v, b));
    if nn < 1e-15 {
        return ends();
    }
    let n = n / nn;
    // Project onto the arc's plane; inside the arc's wedge the distance is the angle to the plane.
    let p = v - n * n.dot(v);
    if p.norm() < 1e-15 {
        return ends();
    }
    let inside = a.cross(&p).dot(&n) >= 0.0 && p.cross(b).dot(&n) >= 0.0;
    if inside { n.dot(v).abs().asin() } else { ends() }
}

/// Spherical linear interpolation between unit vectors.
pub fn slerp(a: &V3, b: &V3, t: f64) -> V3 {
    let omega = angle_between(a, b);
    if omega < 1e-12 {
        return (a * (1.0 - t) + b * t).normalize();
    }
    let s = omega.sin();
    (a * (((1.0 - t) * omega).sin() / s) + b * ((t * omega).sin() / s)).normalize()
}

fn lerp_joints(a: &Joints, b: &Joints, t: f64) -> Joints {
    Joints {
        xyz: a.xyz + (b.xyz - a.xyz) * t,
        rot: [a.rot[0] + (b.rot[0] - a.rot[0]) * t, a.rot[1] + (b.rot[1] - a.rot[1]) * t],
    }
}

/// The sequence of solutions [`crate::branch::choose`] finds for every row, the primary angle
/// interpolated through singular runs.
fn choices<R: Get<Cl> + ?Sized>(
    rows: &R,
    m: &Machine,
    opts: &Options,
    stats: &mut Stats,
) -> Result<Choices, PlanError> {
    let chosen = crate::branch::choose(rows, m, opts)?;
    stats.unwinds += chosen.unwinds;
    let mut choices = chosen.choices;
    if m.chain().rotaries().len() == 2 {
        interpolate_singular_runs(rows, m, opts, &mut choices)?;
    }
    Ok(choices)
}

/// The pose of every row in order, before linearisation, handed to `each`: its chosen solution,
/// the spindle orientation continuous within a pass and unwound where the rotary axes may turn
/// freely. Figures are counted in `stats` if given.
fn poses<R: Get<Cl> + ?Sized>(
    rows: &R,
    choices: &mut Choices,
    m: &Machine,
    opts: &Options,
    mut stats: Option<&mut Stats>,
    mut each: impl FnMut(Step) -> Result<(), PlanError>,
) -> Result<(), PlanError> {
    let mut sigma: Option<f64> = None;
    for i in 0..rows.len() {
        let (row, c) = (rows.get(i), choices.get(i));
        let (xyz, frame) = m.linear(&row.tip, &c.rot, opts.tcp);
        m.check_travel(&xyz).map_err(|message| PlanError { row: i, message, unreachable: true })?;
        let joints = Joints { xyz, rot: c.rot };
        sigma = m.spindle_in(&frame, row.s, sigma).or(sigma);
        if row.reorient
            && let Some(sg) = sigma.filter(|sg| sg.abs() >= 360.0)
        {
            sigma = Some(principal_deg(sg));
            if let Some(st) = stats.as_deref_mut() {
                st.spindle_unwinds += 1;
            }
        }
        if c.singular
            && let Some(st) = stats.as_deref_mut()
        {
            st.singular_rows += 1;
            let axis = frame.column(2).into_owned();
            st.pose_axis_error = st.pose_axis_error.max(angle_between(&axis, &row.axis));
        }
        each(Step {
            joints,
            spindle: if row.s.is_some() { sigma } else { None },
            cl: row,
            row: i,
            inserted: false,
            singular: c.singular,
            arc: None,
        })?;
    }
    Ok(())
}

/// Inside each run of singular rows of a pass, the primary angle goes linearly (by tip path
/// length) from its value where the pass enters the cone to its value where it leaves; a run at
/// the start or end of a pass takes the value of its one non-singular neighbour.
fn interpolate_singular_runs<R: Get<Cl> + ?Sized>(
    rows: &R,
    m: &Machine,
    opts: &Options,
    choices: &mut Choices,
) -> Result<(), PlanError> {
    let mut i = 0;
    while i < rows.len() {
        if !choices.get(i).singular {
            i += 1;
            continue;
        }
        let start = i;
        while i < rows.len() && choices.get(i).singular && (i == start || !rows.get(i).rapid) {
            i += 1;
        }
        let end = i; // exclusive
        let before = (start > 0 && !rows.get(start).rapid).then(|| choices.get(start - 1).rot[0]);
        let after =
            (end < rows.len() && !rows.get(end).rapid && !choices.get(end).singular).then(|| choices.get(end).rot[0]);
        let (from, to) = match (before, after) {
            (Some(b), Some(a)) if opts.interpolate_singular => (b, a),
            (Some(b), _) => (b, b),
            (None, Some(a)) => (a, a),
            (None, None) => continue,
        };
        let mut lengths = vec![0.0];
        let first = if before.is_some() { start - 1 } else { start };
        let last = if after.is_some() { end } else { end - 1 };
        for k in first + 1..=last {
            let l = lengths.last().copied().unwrap_or(0.0) + (rows.get(k).tip - rows.get(k - 1).tip).norm();
            lengths.push(l);
        }
        let total = lengths.last().copied().unwrap_or(0.0);
        let mut prev = choices.get(first).rot;
        let mut run = Vec::with_capacity(end - start);
        for k in start..end {
            let t = if total > 0.0 { lengths[k - first] / total } else { 0.5 };
            let primary = from + (to - from) * t;
            // A row the interpolated primary would leave beyond tolerance keeps the run held.
            let Ok(c) = crate::branch::held(m, opts, &rows.get(k).axis, primary, &prev) else { break };
            run.push(c);
            prev = c.rot;
        }
        if run.len() < end - start {
            continue;
        }
        for (k, c) in run.iter().enumerate() {
            choices.set(start + k, c);
        }
        // The row leaving the cone was chosen from the held value; keep it continuous with the
        // interpolated run.
        if after.is_some() {
            let mut c = choices.get(end);
            c.rot[1] = prev[1] + principal_deg(c.rot[1] - prev[1]);
            let limit_ok = m.chain().rotaries()[1].admits(c.rot[1]);
            if !limit_ok {
                return Err(PlanError {
                    row: end,
                    message: "no continuous pose leaving the singular cone within the limits".into(),
                    unreachable: true,
                });
            }
            choices.set(end, &c);
        }
    }
    Ok(())
}

/// Deviations of the controller's path between two blocks: (tip mm, axis rad, spindle deg).
fn segment_deviation(m: &Machine, opts: &Options, a: &Step, b: &Step, samples: &[f64]) -> (f64, f64, f64) {
    // Against the CL's axes, also where a pose holds the primary angle: its own axis error counts.
    let (axis_a, axis_b) = (a.cl.axis, b.cl.axis);
    let chord = b.cl.tip - a.cl.tip;
    let len = chord.norm();
    let (mut dt, mut da, mut ds) = (0.0f64, 0.0f64, 0.0f64);
    for &t in samples {
        let q = lerp_joints(&a.joints, &b.joints, t);
        let (tip, axis, frame) = m.at(&q, opts.tcp);
        let d = point_segment(&tip, &a.cl.tip, &b.cl.tip);
        dt = dt.max(d);
        // As the read-back measures it: against the CL axes where the tip is (the part of the
        // segment within `tol` of it); a segment shorter than that turns the axis on the spot.
        da = da.max(if len > opts.tol {
            let u = ((tip - a.cl.tip).dot(&chord) / (len * len)).clamp(0.0, 1.0);
            let half = (opts.tol * opts.tol - d * d).max(0.0).sqrt() / len;
            let (lo, hi) = ((u - half).max(0.0), (u + half).min(1.0));
            vector_arc(&axis, &slerp(&axis_a, &axis_b, lo), &slerp(&axis_a, &axis_b, hi))
        } else {
            vector_arc(&axis, &axis_a, &axis_b)
        });
        if let (Some(sa), Some(sb), Some(ca), Some(cb)) = (a.spindle, b.spindle, a.cl.s, b.cl.s) {
            let sp = m.spindle.expect("spindle angles need a spindle");
            let want_s = ca + principal_deg(cb - ca) * t;
            let want = m.spindle_in(&frame, Some(want_s), Some(sa + (sb - sa) * t)).unwrap_or(0.0);
            let have = if sp.interpolated { sa + (sb - sa) * t } else { sb };
            ds = ds.max(principal_deg(have - want).abs());
        }
    }
    (dt, da, ds)
}

const FINE: [f64; 15] = [
    1.0 / 16.0,
    2.0 / 16.0,
    3.0 / 16.0,
    4.0 / 16.0,
    5.0 / 16.0,
    6.0 / 16.0,
    7.0 / 16.0,
    8.0 / 16.0,
    9.0 / 16.0,
    10.0 / 16.0,
    11.0 / 16.0,
    12.0 / 16.0,
    13.0 / 16.0,
    14.0 / 16.0,
    15.0 / 16.0,
];

/// Largest rotary move (degrees) below which a segment's deviation is a parabola in t closely
/// enough that its midpoint, with a factor 2 of margin, stands for its maximum.
const SMALL_ROTARY_MOVE_DEG: f64 = 2.0;

/// Deepest halving of one CL segment.
const MAX_DEPTH: u32 = 24;

/// The pose for an inserted block at fraction `t` of the segment `a`–`b`.
fn inserted(m: &Machine, opts: &Options, a: &Step, b: &Step, t: f64) -> Result<Step, PlanError> {
    let tip = a.cl.tip + (b.cl.tip - a.cl.tip) * t;
    pose_at(m, opts, a, b, tip, t)
}

/// The pose for a block at fraction `t` of the move from `a` to `b` with its tip at `tip`: the
/// axis and spindle orientation interpolated, the IK solution nearest `a`'s.
fn pose_at(m: &Machine, opts: &Options, a: &Step, b: &Step, tip: P3, t: f64) -> Result<Step, PlanError> {
    let axis = slerp(&a.cl.axis, &b.cl.axis, t);
    let s = match (a.cl.s, b.cl.s) {
        (Some(x), Some(y)) => Some(x + principal_deg(y - x) * t),
        _ => b.cl.s,
    };
    let cl = Cl { tip, axis, s, feed: b.cl.feed, rapid: false, reorient: false, line: b.cl.line, arc: None };
    let target = lerp_joints(&a.joints, &b.joints, t).rot;
    let c = pose_between(m, opts, &axis, &a.joints.rot, &target, a.singular || b.singular)
        .map_err(|message| PlanError { row: b.row, message, unreachable: true })?;
    let singular = c.singular;
    let (xyz, frame) = m.linear(&tip, &c.rot, opts.tcp);
    m.check_travel(&xyz).map_err(|message| PlanError { row: b.row, message, unreachable: true })?;
    let spindle = m.spindle_in(&frame, s, a.spindle).filter(|_| s.is_some());
    Ok(Step { joints: Joints { xyz, rot: c.rot }, spindle, cl, row: b.row, inserted: true, singular, arc: None })
}

/// The pose for tool axis `axis` on the joint move from `prev` towards `target`: the primary
/// angle held at the target's where the move is singular or the axis lies in the singular cone
/// and the hold keeps the axis within tolerance ([`crate::branch::held`]); otherwise the exact
/// solution (unwound from `prev`) nearest the target, so that a block inserted between two poses
/// stays on their branch.
fn pose_between(
    m: &Machine,
    opts: &Options,
    axis: &V3,
    prev: &[f64; 2],
    target: &[f64; 2],
    singular: bool,
) -> Result<camkit::kinematics::Choice, String> {
    let chain = m.chain();
    let n = chain.rotaries().len();
    let o = chain.orientations(axis);
    let in_cone = o.is_some_and(|o| o.count == 2 && o.off_primary < m.solver.cone);
    if n == 2 && (singular || in_cone) {
        match crate::branch::held(m, opts, axis, target[0], prev) {
            Ok(c) => return Ok(c),
            Err(e) if o.is_none() => return Err(e),
            Err(_) => {}
        }
    }
    let Some(o) = o else { return m.solver.choose(axis, prev).map_err(|e| e.0) };
    let mut best: Option<(f64, camkit::kinematics::Choice)> = None;
    for (b, rot) in o.branch[..o.count].iter().enumerate() {
        let mut out = [0.0; 2];
        let mut ok = true;
        for k in 0..n {
            match m.solver.unwind(k, rot[k], prev[k]) {
                Some(v) => out[k] = v,
                None => ok = false,
            }
        }
        let d: f64 = (0..n).map(|k| (out[k] - target[k]).abs()).sum();
        if ok && best.is_none_or(|(c, _)| d < c) {
            best = Some((d, camkit::kinematics::Choice { rot: out, branch: b, singular: false }));
        }
    }
    match best {
        Some((_, c)) => Ok(c),
        None => m.solver.choose(axis, prev).map_err(|e| e.0),
    }
}

/// The controller's arc for the CL arc from `a` to `b`, when the controller can run it as G2/G3:
/// the rotary axes (and the spindle orientation) stand still over it, and the chain maps the
/// arc's plane onto one of the controller's (in TCP mode X, Y, Z are the tip: always). `None`
/// otherwise.
fn controller_arc(m: &Machine, opts: &Options, a: &Step, b: &Step, arc: &ClArc) -> Option<StepArc> {
    if a.joints.rot != b.joints.rot || a.spindle != b.spindle {
        return None;
    }
    let rot = &b.joints.rot;
    let map = |p: &P3| m.linear(p, rot, opts.tcp).0;
    let normal = arc.plane.join(&P2::origin(), 1.0).coords;
    let image = map(&(b.cl.tip + normal)) - map(&b.cl.tip);
    let (plane, sign) = [Plane::Yz, Plane::Xz, Plane::Xy].into_iter().enumerate().find_map(|(k, plane)| {
        let e = V3::ith(k, 1.0);
        if (image - e).norm() <= PLANE_SLACK {
            Some((plane, true))
        } else if (image + e).norm() <= PLANE_SLACK {
            Some((plane, false))
        } else {
            None
        }
    })?;
    let (_, wa) = arc.plane.split(&a.cl.tip);
    let centre = plane.split(&P3::from(map(&arc.plane.join(&arc.centre, wa)))).0;
    Some(StepArc { plane, centre, ccw: arc.ccw == sign })
}

/// How far from a controller axis the image of an arc's plane normal may be (it is a rotation of
/// a unit vector: round-off only).
const PLANE_SLACK: f64 = 1e-9;

/// Samples of an arc checked against the travel limits.
const ARC_TRAVEL_SAMPLES: usize = 64;

/// Plans the CL arc from `a` to `b`: one G2/G3 block where the controller can run it, else chords
/// whose sagitta is at most half the tolerance, each linearised within the other half.
fn plan_arc(
    m: &Machine,
    opts: &Options,
    a: &Step,
    b: &Step,
    arc: &ClArc,
    out: &mut Vec<Step>,
    stats: &mut Stats,
) -> Result<(), PlanError> {
    if let Some(sa) = controller_arc(m, opts, a, b, arc) {
        for k in 1..ARC_TRAVEL_SAMPLES {
            let p = arc.point(&a.cl.tip, &b.cl.tip, k as f64 / ARC_TRAVEL_SAMPLES as f64);
            m.check_travel(&m.linear(&p, &b.joints.rot, opts.tcp).0).map_err(|message| PlanError {
                row: b.row,
                message,
                unreachable: true,
            })?;
        }
        stats.arcs += 1;
        out.push(Step { arc: Some(sa), ..*b });
        return Ok(());
    }
    stats.arcs_linearised += 1;
    let (plane_arc, _, _) = arc.in_plane(&a.cl.tip, &b.cl.tip);
    let half = 0.5 * opts.tol;
    let step = if plane_arc.r > half { 2.0 * (1.0 - half / plane_arc.r).acos() } else { std::f64::consts::PI };
    let n = ((plane_arc.sweep.abs() / step).ceil() as usize).max(1);
    let chord =
        Options { tol: opts.tol - plane_arc.r * (1.0 - (0.5 * plane_arc.sweep.abs() / n as f64).cos()), ..*opts };
    let mut prev = *a;
    for k in 1..=n {
        let t = k as f64 / n as f64;
        let next = if k == n {
            *b
        } else {
            stats.inserted += 1;
            pose_at(m, opts, a, b, arc.point(&a.cl.tip, &b.cl.tip, t), t)?
        };
        linearise(m, &chord, &prev, &next, 0, out, stats)?;
        prev = *out.last().expect("the chord ends at its block");
    }
    Ok(())
}

fn linearise(
    m: &Machine,
    opts: &Options,
    a: &Step,
    b: &Step,
    depth: u32,
    out: &mut Vec<Step>,
    stats: &mut Stats,
) -> Result<(), PlanError> {
    let rot_move = (0..2).map(|k| (b.joints.rot[k] - a.joints.rot[k]).abs()).fold(0.0, f64::max);
    let spin_move = match (a.spindle, b.spindle) {
        (Some(x), Some(y)) => (y - x).abs(),
        _ => 0.0,
    };
    let small = rot_move <= SMALL_ROTARY_MOVE_DEG && spin_move <= SMALL_ROTARY_MOVE_DEG;
    let (dt, da, ds) = if small {
        let (dt, da, ds) = segment_deviation(m, opts, a, b, &[0.5]);
        if dt <= opts.tol / 2.0 && da <= opts.angle_tol / 2.0 && ds <= opts.spindle_tol / 2.0 {
            (dt * 2.0, da * 2.0, ds * 2.0)
        } else {
            segment_deviation(m, opts, a, b, &FINE)
        }
    } else {
        segment_deviation(m, opts, a, b, &FINE)
    };
    if dt <= opts.tol && da <= opts.angle_tol && ds <= opts.spindle_tol {
        stats.tip_deviation = stats.tip_deviation.max(dt);
        stats.axis_deviation = stats.axis_deviation.max(da);
        out.push(*b);
        return Ok(());
    }
    if depth >= MAX_DEPTH {
        return Err(PlanError {
            row: b.row,
            message: format!(
                "the machine cannot follow the tool between this row and the previous one within the tolerances \
                 (tip {dt:.6} mm, axis {:.4}°, rotary move {rot_move:.3}°): the rotary axes change branch or pass \
                 through the singularity here; split the pass or widen the axis limits",
                da.to_degrees()
            ),
            unreachable: true,
        });
    }
    let mid = inserted(m, opts, a, b, 0.5)?;
    stats.inserted += 1;
    linearise(m, opts, a, &mid, depth + 1, out, stats)?;
    let mid = *out.last().expect("the first half ends at the midpoint");
    linearise(m, opts, &mid, b, depth + 1, out, stats)
}

/// Plans the blocks for CL rows on a machine, handing each to `emit` in order as soon as the
/// next row's blocks no longer depend on it (the last block planned is where linearisation of
/// the next segment starts): never the whole program's blocks at once. Every pose is checked
/// against the travel limits before the first block is planned.
pub fn plan_each<R: Get<Cl> + ?Sized>(
    rows: &R,
    m: &Machine,
    opts: &Options,
    emit: &mut dyn FnMut(&Step),
) -> Result<Stats, PlanError> {
    let mut stats = Stats { rows: rows.len(), ..Stats::default() };
    let mut choices = choices(rows, m, opts, &mut stats)?;
    poses(rows, &mut choices, m, opts, Some(&mut stats), |_| Ok(()))?;
    let mut out: Vec<Step> = Vec::new();
    poses(rows, &mut choices, m, opts, None, |step| {
        match out.last().copied() {
            Some(a) if !step.cl.rapid => match &step.cl.arc {
                Some(arc) => plan_arc(m, opts, &a, &step, arc, &mut out, &mut stats)?,
                None => linearise(m, opts, &a, &step, 0, &mut out, &mut stats)?,
            },
            _ => out.push(step),
        }
        let done = out.len() - 1;
        out.drain(..done).for_each(|s| emit(&s));
        Ok(())
    })?;
    out.iter().for_each(emit);
    Ok(stats)
}

/// Plans the blocks for CL rows on a machine.
pub fn plan<R: Get<Cl> + ?Sized>(rows: &R, m: &Machine, opts: &Options) -> Result<(Vec<Step>, Stats), PlanError> {
    let mut out = Vec::with_capacity(rows.len() + rows.len() / 8);
    let stats = plan_each(rows, m, opts, &mut |s| out.push(*s))?;
    Ok((out, stats))
}
