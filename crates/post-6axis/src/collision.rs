//! The collision check of a written program, before it is delivered: every block read back
//! through the forward kinematics and followed in the workpiece frame, in program order.
//!
//! - Rapids against the material: the stock less what the program's feed moves have cut so far
//!   (the material map, [`camkit::collide::material`]). Every rapid keeps the setup's approach
//!   distance above the material under the tool's footprint and its holder's, except a retract:
//!   a rapid straight up the tool axis moves the body into the column it stands in, which its
//!   own cut has emptied (checked against the part only).
//! - Rapids and feeds against the part: a 2.5-D part's walls and floor exactly
//!   ([`camkit::collide::walls`]); a 3-D part ([`camkit::collide::solid`]) by casting the body
//!   along each straight move with the tool's orientation held where the body allows it (a ball
//!   end mill and its holder: exact), by the clearance at samples along the move otherwise
//!   (every `sample` mm of tip travel and half a degree of axis turn); every move keeps the
//!   promised clearance (the allowance) less the setup's tolerance.
//!
//! Blocks whose start is unknown (the first move after the tool change, a move after a G53 block)
//! cannot be followed: they are counted, not checked.

use crate::readback::{NcPose, Reading};
use camkit::collide::material::{Cutter, Material};
use camkit::collide::solid::{Body, Placement, Solid};
use camkit::collide::walls::{Column, Walls};
use camkit::contour::Seg;
use camkit::doc::Job;
use camkit::error::{Error, Result};
use camkit::geom::{P2, P3, V3};
use rayon::prelude::*;

/// How the program measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Outcome {
    /// Rapid blocks checked.
    pub rapid_blocks: usize,
    /// Feed blocks checked.
    pub feed_blocks: usize,
    /// Blocks whose start is unknown.
    pub unchecked_blocks: usize,
    /// Smallest height of a rapid (not a retract) above the material (mm), and its NC line.
    pub rapid_clearance: Option<(f64, u32)>,
    /// Rapids straight up the tool axis (retracts).
    pub retracts: usize,
    /// Smallest clearance of a rapid from the part (mm), and its NC line.
    pub rapid_part_clearance: Option<(f64, u32)>,
    /// Smallest clearance of a feed move from the part (mm), and its NC line.
    pub feed_clearance: Option<(f64, u32)>,
    /// Rapid blocks that come nearer the material than they may.
    pub rapids_into_material: usize,
    /// Blocks (rapid or feed) that come nearer the part than the allowance less the tolerance.
    pub part_collisions: usize,
    /// Feed moves with a tilted tool axis, not taken off the material map (it stays higher).
    pub tilted_cuts: usize,
    /// The first violation: NC line and what happened.
    pub first: Option<(u32, String)>,
}

impl Outcome {
    /// True if nothing came too near.
    pub fn clean(&self) -> bool {
        self.first.is_none()
    }
}

fn least(slot: &mut Option<(f64, u32)>, v: f64, line: u32) {
    if slot.is_none_or(|(b, _)| v < b) {
        *slot = Some((v, line));
    }
}

/// A stretch of a block in the workpiece frame: its XY path (a line, or an arc where the block is
/// a G2/G3 in the workpiece's XY plane), the tip's heights at its ends (linear between), the tool
/// axis.
struct Piece {
    seg: Seg,
    z0: f64,
    z1: f64,
    axis: V3,
}

impl Piece {
    fn line(a: &P3, b: &P3, axis: V3) -> Piece {
        Piece { seg: Seg::Line(xy(a), xy(b)), z0: a.z, z1: b.z, axis }
    }
}

/// The stretches of the controller's move from `a` to `b`: one when the rotary axes stand still
/// (the linear axes then move the tip on a straight line, or on a circle for G2/G3 — an arc
/// for the workpiece's XY plane, chords within a tenth of `step` of it otherwise), else samples of
/// the joint interpolation spaced so that the tip moves at most `step` and the axis 0.5° between
/// them.
fn pieces(r: &Reading, a: &NcPose, b: &NcPose, step: f64) -> Vec<Piece> {
    let (ta, xa) = r.at(&a.joints);
    let tb = r.at(&b.joints).0;
    if let Some(arc) = &b.arc {
        let (start, end) = (P3::from(a.joints.xyz), P3::from(b.joints.xyz));
        let (plane_arc, _, _) = arc.in_plane(&start, &end);
        let tip_of = |t: f64| r.at(&crate::readback::joints_at(a, b, t)).0;
        // In the workpiece's XY plane (the tip's height linear along it): exact arcs, each at
        // most half a turn.
        let parts = ((plane_arc.sweep.abs() / std::f64::consts::PI).ceil() as usize).max(1);
        let flat = (0..=8 * parts).all(|k| {
            let t = k as f64 / (8 * parts) as f64;
            (tip_of(t).z - (ta.z + (tb.z - ta.z) * t)).abs() <= 1e-9
        });
        let exact: Option<Vec<Piece>> = flat
            .then(|| {
                (0..parts)
                    .map(|i| {
                        let (t0, t1) = (i as f64 / parts as f64, (i + 1) as f64 / parts as f64);
                        let (p0, pm, p1) = (tip_of(t0), tip_of(0.5 * (t0 + t1)), tip_of(t1));
                        let arc = camkit::geom::Arc2::through(&xy(&p0), &xy(&pm), &xy(&p1))?;
                        // The circle through three of its points must hold the others too.
                        let on = (1..8).all(|k| {
                            let q = tip_of(t0 + (t1 - t0) * k as f64 / 8.0);
                            camkit::geom::dist::point_arc(&xy(&q), &arc) <= 1e-9
                        });
                        on.then_some(Piece { seg: Seg::Arc(arc), z0: p0.z, z1: p1.z, axis: xa })
                    })
                    .collect()
            })
            .flatten();
        if let Some(exact) = exact {
            return exact;
        }
        let sag = (0.1 * step).min(plane_arc.r);
        let n = ((plane_arc.sweep.abs() / (2.0 * (1.0 - sag / plane_arc.r).acos())).ceil() as usize).clamp(1, 100_000);
        let mut out = Vec::with_capacity(n);
        let mut prev = ta;
        for k in 1..=n {
            let now = tip_of(k as f64 / n as f64);
            out.push(Piece::line(&prev, &now, xa));
            prev = now;
        }
        return out;
    }
    if a.joints.rot == b.joints.rot {
        return vec![Piece::line(&ta, &tb, xa)];
    }
    let turn = (0..2).map(|k| (b.joints.rot[k] - a.joints.rot[k]).abs()).fold(0.0, f64::max);
    // The tip's path can bulge beyond its chord: bound the steps by the chord and the turn.
    let n = (((tb - ta).norm() / step).max(turn / 0.5).ceil() as usize).clamp(1, 100_000);
    let mut out = Vec::with_capacity(n);
    let mut prev = (ta, xa);
    for k in 1..=n {
        let now = r.at(&crate::readback::joints_at(a, b, k as f64 / n as f64));
        // The lower of the two axes' dips stands for the piece.
        let axis = if now.1.z < prev.1.z { now.1 } else { prev.1 };
        out.push(Piece::line(&prev.0, &now.0, axis));
        prev = now;
    }
    out
}

/// True if the piece runs up its tool axis (to the rounding of the written words).
fn along_axis(p: &Piece) -> bool {
    let Seg::Line(a, b) = p.seg else { return false };
    let d = V3::new(b.x - a.x, b.y - a.y, p.z1 - p.z0);
    let up = d.dot(&p.axis);
    up > 0.0 && (d - p.axis * up).norm() <= ROUNDING
}

/// How far a written position may be from the one planned (mm): the rounding of 4 decimals in
/// three axes, with a margin.
const ROUNDING: f64 = 2e-4;

/// What the check compares the moves with.
pub struct Check<'a> {
    /// The job.
    pub job: &'a Job,
    /// The part's walls, if the part is given by contours.
    pub walls: Option<&'a Walls>,
    /// The part as a solid, if it is given by a model, and the tool's body.
    pub solid: Option<(&'a Solid, &'a Body)>,
}

/// How a program measured against a 3-D part.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolidOutcome {
    /// Smallest clearance of a rapid (mm) and its NC line.
    pub rapid: Option<(f64, u32)>,
    /// Smallest clearance of a feed move (mm) and its NC line.
    pub feed: Option<(f64, u32)>,
    /// Blocks nearer the part than allowed: count, and the first (NC line, rapid, clearance).
    pub collisions: usize,
    /// The first of them.
    pub first: Option<(u32, bool, f64)>,
    /// Blocks decided by an exact cast; blocks sampled, and the samples taken.
    pub cast: usize,
    /// Blocks checked at samples.
    pub sampled: usize,
    /// Samples taken.
    pub samples: usize,
}

fn xy(p: &P3) -> P2 {
    P2::new(p.x, p.y)
}

/// Blocks measured against a 3-D part at once, in parallel.
pub const SOLID_CHUNK: usize = 16_384;

/// How far beyond the allowance and the tolerance clearances from a 3-D part are measured (mm).
pub const SOLID_BAND: f64 = 0.1;

/// One block measured against a 3-D part.
struct BlockSolid {
    /// Smallest clearance seen (mm): at the block's end when cast, over the samples otherwise.
    least: f64,
    /// The clearance of a block nearer the part than allowed.
    bad: Option<f64>,
    rapid: bool,
    line: u32,
    /// Samples taken (`None`: cast exactly).
    samples: Option<usize>,
}

/// One block against a 3-D part: cast exactly where the body and the block allow, sampled
/// otherwise.
#[allow(clippy::too_many_arguments)]
fn block_solid(
    solid: &Solid,
    body: &Body,
    r: &Reading,
    a: &NcPose,
    b: &NcPose,
    limit: f64,
    reach: f64,
    step: f64,
) -> BlockSolid {
    let sig = |p: &NcPose| p.sigma;
    let fixed = a.joints.rot == b.joints.rot && a.sigma == b.sigma && b.arc.is_none();
    if fixed && body.sweeps_exactly() {
        let from = placement(r, &a.joints, sig(a));
        let to = placement(r, &b.joints, sig(b));
        let hit = solid.first_within(body, &from, &to.tip, limit).is_some();
        let end = solid.clearance(body, &to, reach);
        return BlockSolid {
            least: end,
            bad: hit.then_some(end.min(limit)),
            rapid: b.rapid,
            line: b.line,
            samples: None,
        };
    }
    // Samples: along the block, every `step` of tip travel and 0.5° of turn.
    let (ta, _) = r.at(&a.joints);
    let (tb, _) = r.at(&b.joints);
    let turn = (0..2).map(|k| (b.joints.rot[k] - a.joints.rot[k]).abs()).fold(0.0, f64::max);
    let sweep = b.arc.map_or(0.0, |arc| {
        arc.in_plane(&camkit::geom::P3::from(a.joints.xyz), &camkit::geom::P3::from(b.joints.xyz)).0.length()
    });
    let n = (((tb - ta).norm().max(sweep) / step).max(turn / 0.5).ceil() as usize).clamp(1, 100_000);
    let mut least = f64::INFINITY;
    for k in 1..=n {
        let t = k as f64 / n as f64;
        let q = crate::readback::joints_at(a, b, t);
        let s = match (a.sigma, b.sigma) {
            (Some(x), Some(y)) => Some(x + (y - x) * t),
            (_, y) => y,
        };
        least = least.min(solid.clearance(body, &placement(r, &q, s), reach));
    }
    BlockSolid { least, bad: (least < limit - 1e-9).then_some(least), rapid: b.rapid, line: b.line, samples: Some(n) }
}

/// The tool's placement in the workpiece frame for controller values `q`: tip, axis, and the
/// edge of the spindle orientation where the program commands one.
fn placement(r: &Reading, q: &camkit::kinematics::Joints, sigma: Option<f64>) -> Placement {
    let (tip, axis) = r.at(q);
    let edge = sigma.and_then(|s| r.s_of(&q.rot, s)).map(|s| camkit::kinematics::edge_direction(&axis, s));
    Placement { tip, axis, edge }
}

impl Check<'_> {
    /// Every block against the 3-D part, in parallel (the part does not change): exact casts
    /// where the body and the block allow them, samples every `step` mm otherwise. The poses are
    /// read as they come, [`SOLID_CHUNK`] blocks at a time.
    pub fn run_solid(
        &self,
        poses: impl Iterator<Item = Result<Option<NcPose>>>,
        r: &Reading,
        step: f64,
        tick: &(dyn Fn() + Sync),
    ) -> Result<SolidOutcome> {
        let mut o = SolidOutcome::default();
        let Some((solid, body)) = self.solid else { return Ok(o) };
        let job = self.job;
        let limit = job.allowance - job.tolerance;
        // Clearances are measured in a band 0.1 mm beyond the allowance and the tolerance (farther
        // ones are reported as the band's edge): the fewer triangles a query meets, the faster.
        let reach = job.allowance.max(0.0) + job.tolerance + SOLID_BAND;
        let mut pairs = Vec::with_capacity(SOLID_CHUNK);
        let mut prev: Option<NcPose> = None;
        let mut measure = |pairs: &mut Vec<(NcPose, NcPose)>| {
            let each: Vec<BlockSolid> = pairs
                .par_iter()
                .map(|(a, b)| {
                    tick();
                    block_solid(solid, body, r, a, b, limit, reach, step)
                })
                .collect();
            pairs.clear();
            for b in each {
                least(if b.rapid { &mut o.rapid } else { &mut o.feed }, b.least, b.line);
                match b.samples {
                    None => o.cast += 1,
                    Some(n) => {
                        o.sampled += 1;
                        o.samples += n;
                    }
                }
                if let Some(c) = b.bad {
                    o.collisions += 1;
                    if o.first.is_none() {
                        o.first = Some((b.line, b.rapid, c));
                    }
                }
            }
        };
        for pose in poses {
            let pose = pose?;
            if let (Some(b), Some(a)) = (pose, prev) {
                pairs.push((a, b));
                if pairs.len() == SOLID_CHUNK {
                    measure(&mut pairs);
                }
            }
            prev = pose;
        }
        measure(&mut pairs);
        Ok(o)
    }

    /// Follows the program's blocks and measures every one; `tick` once per block.
    pub fn run(
        &self,
        poses: impl Iterator<Item = Result<Option<NcPose>>>,
        reading: &Reading,
        tick: &dyn Fn(),
    ) -> Result<Outcome> {
        let job = self.job;
        let tool = &job.tool;
        let cutter = Cutter::of(tool);
        let mut map = Material::new(&job.stock, job.resolution, crate::link::MAX_NODES)
            .map_err(|n| Error::runtime(format!("the material map would have {n} nodes")))?;
        let length = tool.length.unwrap_or(6.0 * tool.radius);
        let column = Column { radius: tool.radius, length, holder_radius: 0.5 * tool.holder_diameter.unwrap_or(0.0) };
        let tol = job.tolerance;
        let mut o = Outcome::default();
        let mut prev: Option<NcPose> = None;
        for pose in poses {
            tick();
            let Some(b) = pose? else {
                prev = None;
                continue;
            };
            let Some(a) = prev else {
                o.unchecked_blocks += 1;
                prev = Some(b);
                continue;
            };
            prev = Some(b);
            let (a, b) = (&a, &b);
            let rapid = b.rapid;
            if rapid {
                o.rapid_blocks += 1;
            } else {
                o.feed_blocks += 1;
            }
            let mut into_material = false;
            let mut into_part = false;
            for p in pieces(reading, a, b, 0.5 * job.resolution) {
                let seg = p.seg;
                let vertical = (p.axis - V3::z()).norm() <= crate::link::VERTICAL;
                let sin = (1.0 - p.axis.z * p.axis.z).max(0.0).sqrt();
                let dip = -(cutter.radius - cutter.corner) * sin - cutter.corner * (1.0 - p.axis.z);
                if rapid && along_axis(&p) {
                    o.retracts += 1;
                } else if rapid {
                    let reach = if vertical {
                        cutter.radius - tol
                    } else {
                        let height = job.stock.top() + job.approach - (p.z0.min(p.z1) + dip);
                        cutter.radius + height.max(0.0) * sin / p.axis.z.max(1e-9)
                    };
                    let mut c = map.clearance(&seg, p.z0 + dip, p.z1 + dip, reach.max(0.0)).map(|c| c.0);
                    if let (Some(d), Some(l)) = (tool.holder_diameter, tool.length) {
                        let h = map.clearance(&seg, p.z0 + l * p.axis.z, p.z1 + l * p.axis.z, 0.5 * d).map(|c| c.0);
                        c = match (c, h) {
                            (Some(x), Some(y)) => Some(x.min(y)),
                            (x, y) => x.or(y),
                        };
                    }
                    if let Some(c) = c {
                        least(&mut o.rapid_clearance, c, b.line);
                        if c < job.approach - tol - 1e-9 && !into_material {
                            into_material = true;
                            o.rapids_into_material += 1;
                            if o.first.is_none() {
                                let what = if c < 0.0 {
                                    format!("comes {:.4} mm into material the program has not cut", -c)
                                } else {
                                    format!(
                                        "passes {c:.4} mm above material, within the approach distance {}",
                                        job.approach
                                    )
                                };
                                o.first = Some((b.line, format!("a rapid (G0) {what}")));
                            }
                        }
                    }
                }
                if let Some(w) = self.walls
                    && vertical
                {
                    let c = w.clearance(&column, &seg, p.z0, p.z1).mm;
                    least(if rapid { &mut o.rapid_part_clearance } else { &mut o.feed_clearance }, c, b.line);
                    if c < job.allowance - tol - 1e-9 && !into_part {
                        into_part = true;
                        o.part_collisions += 1;
                        if o.first.is_none() {
                            let kind = if rapid { "a rapid (G0)" } else { "a feed move" };
                            o.first = Some((
                                b.line,
                                format!(
                                    "{kind} comes {c:.4} mm from the part's walls or floor, less than the allowance {} mm (tolerance {tol} mm)",
                                    job.allowance
                                ),
                            ));
                        }
                    }
                }
                if !rapid {
                    if vertical {
                        map.cut(&cutter, &seg, p.z0, p.z1);
                    } else {
                        o.tilted_cuts += 1;
                    }
                }
            }
        }
        Ok(o)
    }
}
