//! Reading NC back: every block through the forward kinematics to the tool tip, axis and spindle
//! orientation in the workpiece frame; the controller's linear interpolation sampled between
//! blocks and compared with the CL rows both ways (`--verify`), or written out as the toolpath
//! table (`--reverse`).

use crate::plan::{Cl, point_segment, slerp, vector_arc};
use camkit::doc::machine::{Machine, SpindleMode};
use camkit::error::Result;
use camkit::gcode::{AXIS_LETTERS, AxisArc, AxisBlocks, AxisMove, AxisProgram, Motion};
use camkit::geom::arc::PreparedArc;
use camkit::geom::{P2, P3, Plane, V3};
use camkit::io::{Get, RecordSpool, Share};
use camkit::kinematics::{Chain, Joints, principal_deg};
use camkit::table::{Col, Move, Row, Schema, Table};
use rayon::prelude::*;
use std::cell::RefCell;
use std::collections::HashMap;
use std::io::BufRead;

/// How to read a program for one machine.
#[derive(Clone, Debug)]
pub struct Reading<'a> {
    /// The chain with the workpiece frame.
    pub chain: &'a Chain,
    /// X, Y, Z are the tool tip in the workpiece frame (G43.4).
    pub tcp: bool,
    /// Index into [`AXIS_LETTERS`] of each rotary axis.
    pub rotary_at: Vec<usize>,
    /// The spindle orientation: mode, index of its address (axis mode), offset, sense.
    pub spindle: Option<(SpindleMode, Option<usize>, f64, f64)>,
}

impl<'a> Reading<'a> {
    /// The reading for a machine document and its chain.
    pub fn new(machine: &Machine, chain: &'a Chain) -> Reading<'a> {
        let at = |c: char| AXIS_LETTERS.iter().position(|&l| l == c as u8).expect("A, B or C");
        Reading {
            chain,
            tcp: machine.program.tcp,
            rotary_at: chain.rotaries().iter().map(|r| at(r.address)).collect(),
            spindle: machine.spindle.as_ref().map(|s| (s.mode, machine.spindle_address().map(at), s.offset, s.sense)),
        }
    }
}

/// One motion block read back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NcPose {
    /// Source line.
    pub line: u32,
    /// G0.
    pub rapid: bool,
    /// The circle of a G2/G3 block (controller X, Y, Z).
    pub arc: Option<AxisArc>,
    /// Controller values.
    pub joints: Joints,
    /// Controller spindle angle, if commanded so far.
    pub sigma: Option<f64>,
    /// G93 in effect.
    pub inverse_time: bool,
    /// F in effect.
    pub feed: Option<f64>,
}

/// Turns motion blocks into poses one at a time: `None` for blocks in machine coordinates (G53)
/// or before every axis the machine needs has a known position.
#[derive(Clone, Debug, Default)]
pub struct PoseOf {
    sigma_axis_seen: bool,
}

impl PoseOf {
    /// The pose of the next block.
    pub fn pose(&mut self, m: &AxisMove, r: &Reading) -> Option<NcPose> {
        let needed = (0..3).chain(r.rotary_at.iter().copied());
        if m.machine_coords || needed.clone().any(|k| !m.known[k]) {
            return None;
        }
        let mut rot = [0.0; 2];
        for (k, &at) in r.rotary_at.iter().enumerate() {
            rot[k] = m.pos[at];
        }
        let sigma = match r.spindle {
            Some((SpindleMode::Axis, Some(at), ..)) => {
                self.sigma_axis_seen |= m.known[at];
                self.sigma_axis_seen.then_some(m.pos[at])
            }
            Some((SpindleMode::M19, ..)) => m.orient,
            _ => None,
        };
        Some(NcPose {
            line: m.line,
            rapid: m.motion == Motion::Rapid,
            arc: m.arc,
            joints: Joints { xyz: V3::new(m.pos[0], m.pos[1], m.pos[2]), rot },
            sigma,
            inverse_time: m.inverse_time,
            feed: m.feed,
        })
    }
}

/// The motion blocks of a program as poses ([`PoseOf`]).
pub fn poses(prog: &AxisProgram, r: &Reading) -> Vec<Option<NcPose>> {
    let mut of = PoseOf::default();
    prog.moves.iter().map(|m| of.pose(m, r)).collect()
}

/// A program read back from its text, as often as asked: `open` gives a reader from its start
/// (a spooled program, a file, text in memory), `name` names it in messages.
#[derive(Clone, Copy)]
pub struct Program<'a> {
    /// A reader of the program from its start.
    pub open: &'a dyn Fn() -> Box<dyn BufRead + 'a>,
    /// Its name in messages.
    pub name: &'a str,
}

impl<'a> Program<'a> {
    /// The poses of its motion blocks in order, read a block at a time.
    pub fn poses<'r>(self, r: &'r Reading) -> impl Iterator<Item = Result<Option<NcPose>>> + 'r
    where
        'a: 'r,
    {
        let mut of = PoseOf::default();
        AxisBlocks::new(self.name, (self.open)()).map(move |m| m.map(|m| of.pose(&m, r)))
    }
}

/// Controller values at fraction `t` of the block from `a` to `b`: every axis linearly, or the
/// linear axes along the block's circle.
pub fn joints_at(a: &NcPose, b: &NcPose, t: f64) -> Joints {
    let xyz = match &b.arc {
        Some(arc) => arc.point(&P3::from(a.joints.xyz), &P3::from(b.joints.xyz), t).coords,
        None => a.joints.xyz + (b.joints.xyz - a.joints.xyz) * t,
    };
    Joints {
        xyz,
        rot: [
            a.joints.rot[0] + (b.joints.rot[0] - a.joints.rot[0]) * t,
            a.joints.rot[1] + (b.joints.rot[1] - a.joints.rot[1]) * t,
        ],
    }
}

/// Samples a block needs: `base`, or more for an arc (one every π/64 of its sweep).
pub fn samples_of(a: &NcPose, b: &NcPose, base: usize) -> usize {
    match &b.arc {
        Some(arc) => {
            let sweep = arc.in_plane(&P3::from(a.joints.xyz), &P3::from(b.joints.xyz)).0.sweep.abs();
            base.max((sweep / (std::f64::consts::PI / 64.0)).ceil() as usize)
        }
        None => base,
    }
}

/// The CL arc between two rows, made ready for many distances: the planar arc the second row
/// arrives along (prepared in its plane), or a helix.
#[derive(Clone, Copy, Debug)]
enum ClPath {
    Planar(camkit::geom::Plane, PreparedArc, f64),
    Helix(crate::plan::ClArc, P3, P3, PreparedArc),
}

impl ClPath {
    fn of(arc: &crate::plan::ClArc, a: &P3, b: &P3) -> ClPath {
        let (plane_arc, wa, wb) = arc.in_plane(a, b);
        if wa == wb {
            ClPath::Planar(arc.plane, PreparedArc::new(&plane_arc), wa)
        } else {
            ClPath::Helix(*arc, *a, *b, PreparedArc::new(&plane_arc))
        }
    }

    /// Distance from `p` (exact; a helix's within 1e-9).
    fn distance(&self, p: &P3) -> f64 {
        match self {
            ClPath::Planar(plane, arc, w) => {
                let (q, pw) = plane.split(p);
                arc.distance(&q).hypot(pw - w)
            }
            ClPath::Helix(arc, a, b, _) => arc.distance(p, a, b),
        }
    }

    /// A lower bound of [`ClPath::distance`], cheap for a helix: the distance in its plane.
    fn lower_bound(&self, p: &P3) -> f64 {
        match self {
            ClPath::Helix(arc, _, _, prepared) => prepared.distance(&arc.plane.split(p).0),
            _ => self.distance(p),
        }
    }
}

/// The CL segments, read through views of the rows (in memory or on disk) and of the segments'
/// ends (the index of the row each ends at, a feed row; it starts at the row before): a line is
/// measured from its two rows, an arc prepared once and kept while this thread's search is near
/// it (a cache cleared when it grows past [`ARC_CACHE`] arcs).
struct Paths<C, S> {
    cl: C,
    segs: S,
    curved: RefCell<HashMap<usize, Box<ClPath>>>,
}

/// Arcs a [`Paths`] keeps prepared at most.
const ARC_CACHE: usize = 1 << 14;

impl<C: Get<Cl>, S: Get<u64>> Paths<C, S> {
    fn new(cl: C, segs: S) -> Paths<C, S> {
        Paths { cl, segs, curved: RefCell::new(HashMap::new()) }
    }

    fn len(&self) -> usize {
        self.segs.len()
    }

    /// The rows segment `k` runs between.
    fn ends(&self, k: usize) -> (usize, usize) {
        let b = self.segs.get(k) as usize;
        (b - 1, b)
    }

    /// Distance of segment `k` from `p` ([`ClPath::distance`]).
    fn distance(&self, k: usize, p: &P3) -> f64 {
        self.measure(k, p, false)
    }

    /// A lower bound of [`Paths::distance`] ([`ClPath::lower_bound`]).
    fn lower_bound(&self, k: usize, p: &P3) -> f64 {
        self.measure(k, p, true)
    }

    fn measure(&self, k: usize, p: &P3, bound: bool) -> f64 {
        let (a, b) = self.ends(k);
        let (ra, rb) = (self.cl.get(a), self.cl.get(b));
        let Some(arc) = rb.arc else { return point_segment(p, &ra.tip, &rb.tip) };
        let mut curved = self.curved.borrow_mut();
        if curved.len() >= ARC_CACHE && !curved.contains_key(&k) {
            curved.clear();
        }
        let path = curved.entry(k).or_insert_with(|| Box::new(ClPath::of(&arc, &ra.tip, &rb.tip)));
        if bound { path.lower_bound(p) } else { path.distance(p) }
    }
}

impl Reading<'_> {
    /// Tip and axis in the workpiece frame for controller values.
    pub fn at(&self, q: &Joints) -> (P3, V3) {
        if self.tcp {
            (P3::from(q.xyz), self.chain.orientation(&q.rot).column(2).into_owned())
        } else {
            let p = self.chain.forward(q);
            (p.tip, p.axis)
        }
    }

    /// The CL spindle orientation `s` for a controller spindle angle.
    pub fn s_of(&self, rot: &[f64; 2], sigma: f64) -> Option<f64> {
        let (_, _, offset, sense) = self.spindle?;
        Some(self.chain.edge_orientation(rot, (sigma - offset) * sense))
    }
}

/// Largest deviations of a program from its CL rows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Deviation {
    /// Largest distance (mm) of the interpolated tool tip from the CL polyline.
    pub tip: f64,
    /// NC line where it occurs.
    pub tip_line: u32,
    /// Largest distance (mm) of a CL row from the program's path (every row is cut).
    pub coverage: f64,
    /// Index of that CL row.
    pub coverage_row: usize,
    /// Largest angle (degrees) between the interpolated tool axis and the CL axis there.
    pub axis_deg: f64,
    /// NC line where it occurs.
    pub axis_line: u32,
    /// The rows (indices, in order) where a sample nearest the CL segment ending there has the
    /// axis beyond the angle tolerance ([`axis_beyond`]): which rows a program misses.
    pub axis_rows: Vec<usize>,
    /// Largest error (degrees) of the spindle orientation.
    pub spindle_deg: f64,
    /// Feed blocks compared.
    pub blocks: usize,
    /// Points sampled.
    pub samples: usize,
}

/// True if an axis deviation of `deg` degrees is beyond `--angle-tol` `tol` (degrees), with the
/// slack of round-off.
pub fn axis_beyond(deg: f64, tol: f64) -> bool {
    deg > tol * (1.0 + 1e-6) + 1e-9
}

/// Index of the segment nearest `p`, searched near `hint` first.
fn nearest<C: Get<Cl>, S: Get<u64>>(p: &P3, paths: &Paths<C, S>, hint: usize, far: f64) -> (usize, f64) {
    let lo = hint.saturating_sub(2);
    let hi = (hint + 16).min(paths.len());
    let mut best = (hint.min(paths.len().saturating_sub(1)), f64::INFINITY);
    for k in lo..hi {
        if paths.lower_bound(k, p) >= best.1 {
            continue;
        }
        let d = paths.distance(k, p);
        if d < best.1 {
            best = (k, d);
        }
    }
    if best.1 > far {
        for k in 0..paths.len() {
            if paths.lower_bound(k, p) >= best.1 {
                continue;
            }
            let d = paths.distance(k, p);
            if d < best.1 {
                best = (k, d);
            }
        }
    }
    best
}

/// Parameter of the point of segment `a`–`b` nearest `p`.
fn param(p: &P3, a: &P3, b: &P3) -> f64 {
    let d = b - a;
    let l2 = d.norm_squared();
    if l2 > 0.0 { ((p - a).dot(&d) / l2).clamp(0.0, 1.0) } else { 0.0 }
}

/// Blocks (and CL rows) per chunk of the parallel check: fixed, so that the figures do not depend
/// on the number of threads. Each chunk but the first starts its nearest-segment search with a
/// full search. A windowed search can only over-report a distance (it is to a real segment), never
/// under-report it.
pub const CHUNK: usize = 8192;

/// Compares a program with the CL rows it was made from: every feed block sampled
/// `samples_per_block` times along the controller's linear interpolation of every axis against
/// the CL polyline (tip, axis, spindle orientation), and every CL row against the program's path.
/// `tol` is the tip tolerance: a windowed nearest-segment answer beyond it is searched again in
/// full (a pass that closes or crosses itself can send the window to the wrong visit), so every
/// distance above `tol` is exact; and the CL points within `tol` of the tip are where the tool
/// may be for the axis check. Rows whose axis is beyond `angle_tol` (degrees) are listed.
/// Chunks of blocks and of rows run in parallel; the result is the same for any thread count.
///
/// Nothing grows with the program in memory: the program is read a block at a time, a few
/// chunks of its feed blocks at once; the segments' ends and the program's path go to disk and
/// are read back through views (the rows may be on disk too), each thread with its own.
pub fn verify<R: Share<Cl> + ?Sized>(
    cl: &R,
    program: Program,
    r: &Reading,
    samples_per_block: usize,
    tol: f64,
    angle_tol: f64,
) -> Result<Deviation> {
    let far = tol;
    let rows = cl.view();
    let mut segs = RecordSpool::<u64>::new();
    for i in 1..rows.len() {
        if !rows.get(i).rapid {
            segs.push(&(i as u64));
        }
    }
    let segs = segs.finish();
    // Feed blocks as (start, end) poses in program order, a chunk at a time (a G53 block or an
    // unknown position breaks the chain); the program's path on disk as it is read.
    let mut path = RecordSpool::<P3>::new();
    let mut last_known: Option<NcPose> = None;
    let mut prev: Option<NcPose> = None;
    let mut dev = Deviation::default();
    let batch = rayon::current_num_threads().max(1);
    let mut chunks: Vec<Vec<(NcPose, NcPose)>> = Vec::new();
    let mut chunk = Vec::new();
    let mut done = 0;
    let check = |chunks: &mut Vec<Vec<(NcPose, NcPose)>>, done: &mut usize, dev: &mut Deviation| {
        if segs.is_empty() {
            chunks.clear();
            return;
        }
        // The first chunk starts its search at the first segment, as a sequential check would.
        let parts: Vec<(Deviation, Vec<usize>)> = chunks
            .par_iter()
            .enumerate()
            .map(|(c, chunk)| {
                let paths = Paths::new(cl.view(), segs.view());
                let first = (*done + c == 0).then_some(0);
                check_blocks(&paths, chunk, first, r, samples_per_block, far, angle_tol)
            })
            .collect();
        *done += chunks.len();
        chunks.clear();
        for (p, beyond) in parts {
            if p.tip > dev.tip {
                (dev.tip, dev.tip_line) = (p.tip, p.tip_line);
            }
            if p.axis_deg > dev.axis_deg {
                (dev.axis_deg, dev.axis_line) = (p.axis_deg, p.axis_line);
            }
            dev.spindle_deg = dev.spindle_deg.max(p.spindle_deg);
            dev.blocks += p.blocks;
            dev.samples += p.samples;
            dev.axis_rows.extend(beyond);
        }
    };
    for pose in program.poses(r) {
        let Some(b) = pose? else {
            prev = None;
            continue;
        };
        push_path(&mut path, last_known.as_ref(), &b, r, tol);
        last_known = Some(b);
        if let Some(a) = prev.filter(|_| !b.rapid) {
            chunk.push((a, b));
            if chunk.len() == CHUNK {
                chunks.push(std::mem::take(&mut chunk));
                if chunks.len() == batch {
                    check(&mut chunks, &mut done, &mut dev);
                }
            }
        }
        prev = Some(b);
    }
    if !chunk.is_empty() {
        chunks.push(chunk);
    }
    check(&mut chunks, &mut done, &mut dev);
    dev.axis_rows.sort_unstable();
    dev.axis_rows.dedup();
    // Coverage: every CL row lies on the program's path.
    let path = path.finish();
    if path.is_empty() {
        dev.coverage = f64::INFINITY;
        return Ok(dev);
    }
    let parts: Vec<(f64, usize)> = (0..rows.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let (rows, path) = (cl.view(), path.view());
            let mut worst = (0.0, c * CHUNK);
            let mut j = (c == 0).then_some(0);
            for i in c * CHUNK..((c + 1) * CHUNK).min(rows.len()) {
                let (k, d) = nearest_on_path(&rows.get(i).tip, &path, j, far);
                j = Some(k);
                if d > worst.0 {
                    worst = (d, i);
                }
            }
            worst
        })
        .collect();
    for (d, i) in parts {
        if d > dev.coverage {
            (dev.coverage, dev.coverage_row) = (d, i);
        }
    }
    Ok(dev)
}

/// Appends to the program's path in the workpiece frame the block ending at `b` (after the known
/// block `a`): points along an arc close enough that the chords stay within a twentieth of `tol`
/// of it, and the block's end.
fn push_path(path: &mut RecordSpool<P3>, a: Option<&NcPose>, b: &NcPose, r: &Reading, tol: f64) {
    if let (Some(arc), Some(a)) = (&b.arc, a) {
        let (plane_arc, _, _) = arc.in_plane(&P3::from(a.joints.xyz), &P3::from(b.joints.xyz));
        let sag = (tol / 20.0).min(plane_arc.r);
        let step = 2.0 * (1.0 - sag / plane_arc.r).acos();
        let n = ((plane_arc.sweep.abs() / step).ceil() as usize).clamp(1, 1_000_000);
        for k in 1..n {
            path.push(&r.at(&joints_at(a, b, k as f64 / n as f64)).0);
        }
    }
    path.push(&r.at(&b.joints).0);
}

/// Index of the program path's segment (or last point) nearest `p` and its distance: searched
/// near `hint` first, everywhere when there is no hint or nothing within `far` near it.
fn nearest_on_path<G: Get<P3>>(p: &P3, path: &G, hint: Option<usize>, far: f64) -> (usize, f64) {
    let scan = |lo: usize, hi: usize, best: &mut (usize, f64)| {
        let mut here = (lo < hi).then(|| path.get(lo));
        for k in lo..hi {
            let a = here.expect("a point before the end");
            let next = (k + 1 < path.len()).then(|| path.get(k + 1));
            let d = match next {
                Some(b) => point_segment(p, &a, &b),
                None => (p - a).norm(),
            };
            if d < best.1 {
                *best = (k, d);
            }
            here = next;
        }
    };
    let mut best = (hint.unwrap_or(0), f64::INFINITY);
    match hint {
        Some(j) => {
            scan(j.saturating_sub(2), (j + 64).min(path.len()), &mut best);
            if best.1 > far {
                scan(0, path.len(), &mut best);
            }
        }
        None => scan(0, path.len(), &mut best),
    }
    best
}

/// Segments [`axis_deviation`] looks at each way from where the previous sample's axis matched.
const AXIS_WALK: usize = 64;

/// Angle (radians) of the tool axis from the CL axis where the tool is, and the segment it is
/// nearest on: over the CL points within `tol` of the tip on segment `seg` (at distance `d`) and
/// its neighbours, and on the run of segments joined to `from` (where the previous sample's axis
/// matched; `seg` without one) that stay within `tol` of the tip, up to [`AXIS_WALK`] each way,
/// the least angle to the axis arc there. A short segment that turns the axis with the tip
/// (nearly) still, or a pass closing on its start, leaves the tip's nearest parameter undefined:
/// every axis along the turn is then where the tool may be, as planning measures it. A turn on
/// the spot is a run of zero-length segments all as near as the segment leaving it, and the tip's
/// nearest may be any of them (it once took the one leaving a 20° turn and measured the turn's
/// first block against the turn's last 10°): the samples follow the turn in order from `from`,
/// a bounded walk however many rows the turn has.
fn axis_deviation<C: Get<Cl>, S: Get<u64>>(
    tip: &P3,
    axis: &V3,
    paths: &Paths<C, S>,
    (seg, d): (usize, f64),
    from: Option<usize>,
    tol: f64,
) -> (f64, usize) {
    let cl = &paths.cl;
    let at = |k: usize, dk: f64| {
        let (a, b) = paths.ends(k);
        let (ra, rb) = (cl.get(a), cl.get(b));
        let len = (rb.tip - ra.tip).norm();
        let u = param(tip, &ra.tip, &rb.tip);
        let half = if len > 0.0 { (tol * tol - dk * dk).max(0.0).sqrt() / len } else { 1.0 };
        let (lo, hi) = ((u - half).max(0.0), (u + half).min(1.0));
        vector_arc(axis, &slerp(&ra.axis, &rb.axis, lo), &slerp(&ra.axis, &rb.axis, hi))
    };
    let near = |k: usize| Some(paths.distance(k, tip)).filter(|&dk| dk <= tol);
    let mut best = (at(seg, d), seg);
    let mut take = |k: usize, dk: f64| {
        let a = at(k, dk);
        if a < best.0 {
            best = (a, k);
        }
    };
    let back = |k: usize| k.checked_sub(1).filter(|&p| paths.ends(p).1 == paths.ends(k).0);
    let ahead = |k: usize| Some(k + 1).filter(|&n| n < paths.len() && paths.ends(n).0 == paths.ends(k).1);
    for k in [back(seg), ahead(seg)].into_iter().flatten() {
        if let Some(dk) = near(k) {
            take(k, dk);
        }
    }
    let centre = match from.filter(|&f| f != seg).and_then(|f| Some((f, near(f)?))) {
        Some((f, df)) => {
            take(f, df);
            f
        }
        None => seg,
    };
    for step in [&back as &dyn Fn(usize) -> Option<usize>, &ahead] {
        let mut k = centre;
        for _ in 0..AXIS_WALK {
            let Some((next, dk)) = step(k).and_then(|n| Some((n, near(n)?))) else { break };
            take(next, dk);
            k = next;
        }
    }
    best
}

/// The block part of [`verify`] for one chunk of consecutive feed blocks, the nearest-segment
/// search starting at `hint` (none: a full search); with the rows near which a sample has the
/// axis beyond `angle_tol` (degrees), in order of the samples.
fn check_blocks<C: Get<Cl>, S: Get<u64>>(
    paths: &Paths<C, S>,
    blocks: &[(NcPose, NcPose)],
    mut hint: Option<usize>,
    r: &Reading,
    samples_per_block: usize,
    far: f64,
    angle_tol: f64,
) -> (Deviation, Vec<usize>) {
    let cl = &paths.cl;
    let mut dev = Deviation::default();
    let mut beyond: Vec<usize> = Vec::new();
    let mut axis_hint = None;
    for (a, b) in blocks {
        dev.blocks += 1;
        let samples = samples_of(a, b, samples_per_block);
        for k in 0..=samples {
            let t = k as f64 / samples as f64;
            let q = joints_at(a, b, t);
            let (tip, axis) = r.at(&q);
            // Without a hint (a chunk but the first), a full search (a negative `far`).
            let (seg, d) = match hint {
                Some(h) => nearest(&tip, paths, h, far),
                None => nearest(&tip, paths, 0, -1.0),
            };
            hint = Some(seg);
            dev.samples += 1;
            if d > dev.tip {
                dev.tip = d;
                dev.tip_line = b.line;
            }
            let (da, matched) = axis_deviation(&tip, &axis, paths, (seg, d), axis_hint, far);
            axis_hint = Some(matched);
            let da = da.to_degrees();
            let (i0, i1) = paths.ends(seg);
            let (r0, r1) = (cl.get(i0), cl.get(i1));
            let u = param(&tip, &r0.tip, &r1.tip);
            if da > dev.axis_deg {
                dev.axis_deg = da;
                dev.axis_line = b.line;
            }
            // Consecutive samples near one row merged.
            if axis_beyond(da, angle_tol) && beyond.last() != Some(&i1) {
                beyond.push(i1);
            }
            let sigma = match (r.spindle, a.sigma, b.sigma) {
                (Some((SpindleMode::Axis, ..)), Some(x), Some(y)) => Some(x + (y - x) * t),
                (Some((SpindleMode::M19, ..)), _, y) => y,
                _ => None,
            };
            if let (Some(sig), Some(s0), Some(s1)) = (sigma, r0.s, r1.s) {
                let want_s = s0 + principal_deg(s1 - s0) * u;
                if let Some(have) = r.s_of(&q.rot, sig) {
                    dev.spindle_deg = dev.spindle_deg.max(principal_deg(have - want_s).abs());
                }
            }
        }
    }
    (dev, beyond)
}

/// The program as a toolpath table: tool tip, axis, spindle orientation and feed (mm/min) per
/// block; a new `path` after every run of rapids. Arcs become `cw`/`ccw` rows (split where they
/// turn more than once) in the workpiece plane the controller's plane maps onto, or lines along
/// them (chords within 1 µm) where it maps onto none.
pub fn reverse(poses: &[Option<NcPose>], r: &Reading) -> Table {
    let mut rows = Vec::new();
    let mut path = 0i64;
    let mut last: Option<(P3, bool)> = None;
    let mut prev: Option<&NcPose> = None;
    let has_s = r.spindle.is_some();
    let mut planes = Vec::new();
    for pose in poses.iter() {
        let Some(pose) = pose else {
            prev = None;
            continue;
        };
        let (tip, axis) = r.at(&pose.joints);
        if pose.rapid && last.is_some_and(|(_, rapid)| !rapid) {
            path += 1;
        }
        let row_at = |tip: P3| {
            let mut row = Row::at(path, tip);
            row.mv = if pose.rapid { Move::Rapid } else { Move::Line };
            row.axis = axis;
            row.s = pose.sigma.and_then(|s| r.s_of(&pose.joints.rot, s));
            row.line = u64::from(pose.line);
            row
        };
        let feed = match (pose.rapid, pose.inverse_time, pose.feed, last) {
            (true, ..) => None,
            (false, false, f, _) => f,
            (false, true, Some(f), Some((p, _))) => Some(f * (tip - p).norm()),
            _ => None,
        };
        match (&pose.arc, prev) {
            (Some(arc), Some(a)) if !pose.rapid => {
                for mut row in arc_rows(arc, a, pose, r) {
                    let t = row.pos;
                    row.axis = axis;
                    row.s = pose.sigma.and_then(|s| r.s_of(&pose.joints.rot, s));
                    row.line = u64::from(pose.line);
                    row.path = path;
                    row.f = feed;
                    planes.push(row.plane);
                    rows.push(row);
                    last = Some((t, false));
                }
            }
            _ => {
                let mut row = row_at(tip);
                row.f = feed;
                last = Some((tip, pose.rapid));
                rows.push(row);
            }
        }
        prev = Some(pose);
    }
    let mut schema = Schema::of(&[Col::Path, Col::Move, Col::X, Col::Y, Col::Z, Col::I, Col::J, Col::K, Col::F]);
    if rows.iter().any(|r| r.mv.is_arc()) {
        schema.add(&[Col::Xc, Col::Yc]);
        if planes.iter().any(|p| *p != Plane::Xy) {
            schema.add(&[Col::Zc, Col::Plane]);
        }
    }
    if has_s {
        schema.add(&[Col::S]);
    }
    Table { schema, rows }
}

/// The rows of a G2/G3 block from `a` to `b` in the workpiece frame (position, move, centre,
/// plane set; the caller fills the rest).
fn arc_rows(arc: &AxisArc, a: &NcPose, b: &NcPose, r: &Reading) -> Vec<Row> {
    let rot = b.joints.rot;
    let tip_of = |xyz: V3| r.at(&Joints { xyz, rot }).0;
    let normal = arc.plane.join(&P2::origin(), 1.0).coords;
    let image = tip_of(b.joints.xyz + normal) - tip_of(b.joints.xyz);
    let (start, end) = (P3::from(a.joints.xyz), P3::from(b.joints.xyz));
    let pieces = arc.turns as usize + 1;
    let found = [Plane::Yz, Plane::Xz, Plane::Xy].into_iter().enumerate().find_map(|(k, plane)| {
        let e = V3::ith(k, 1.0);
        if (image - e).norm() <= 1e-9 {
            Some((plane, true))
        } else if (image + e).norm() <= 1e-9 {
            Some((plane, false))
        } else {
            None
        }
    });
    let Some((plane, sign)) = found else {
        // No workpiece plane holds it: lines along it, chords within 1 µm.
        let (p, _, _) = arc.in_plane(&start, &end);
        let step = 2.0 * (1.0 - (0.001f64).min(p.r) / p.r).acos();
        let n = ((p.sweep.abs() / step).ceil() as usize).clamp(1, 1_000_000);
        return (1..=n)
            .map(|k| {
                let mut row = Row::at(0, tip_of(arc.point(&start, &end, k as f64 / n as f64).coords));
                row.mv = Move::Line;
                row
            })
            .collect();
    };
    let (_, w0) = arc.plane.split(&start);
    let centre = plane.split(&tip_of(arc.plane.join(&arc.centre, w0).coords)).0;
    (1..=pieces)
        .map(|k| {
            let mut row = Row::at(0, tip_of(arc.point(&start, &end, k as f64 / pieces as f64).coords));
            row.mv = if arc.ccw == sign { Move::Ccw } else { Move::Cw };
            row.centre = Some(centre);
            row.plane = plane;
            row
        })
        .collect()
}
