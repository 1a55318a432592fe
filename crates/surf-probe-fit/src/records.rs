//! Raw sensor records — the machine's axis positions (X, Y, Z and the rotary axes) and the laser
//! reading — turned into measured points in table coordinates through the machine's kinematic
//! chain (`camkit::kinematics`, the chain `post-6axis` posts with), and the inverse: the axis
//! positions that put the sensor at a planned pose.

use crate::sensor::point_of;
use camkit::geom::{P3, V3};
use camkit::kinematics::{Chain, Joints, Solver, Unreachable};

/// One raw record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record {
    /// Controller values of the axes (mm, degrees).
    pub joints: Joints,
    /// The sensor's reading (mm).
    pub reading: f64,
}

/// The measured point of a record in table coordinates: the chain's forward kinematics with the
/// workpiece frame at zero gives the sensor's reference point and beam axis.
pub fn to_point(chain: &Chain, r: &Record) -> P3 {
    let pose = chain.forward(&r.joints);
    point_of(&pose.tip, &pose.axis, r.reading)
}

/// The axis positions of a sequence of poses (sensor tip and axis in table coordinates), each
/// continuous with the previous one and inside the limits.
pub fn joints_for(chain: &Chain, poses: &[(P3, V3)], cone: f64) -> Result<Vec<Joints>, (usize, Unreachable)> {
    let solver = Solver { chain, policy: Default::default(), cone };
    let mut prev = [chain.rotaries().first().map_or(0.0, |r| r.home), chain.rotaries().get(1).map_or(0.0, |r| r.home)];
    let mut out = Vec::with_capacity(poses.len());
    for (i, (tip, axis)) in poses.iter().enumerate() {
        let choice = solver.choose(axis, &prev).map_err(|e| (i, e))?;
        prev = choice.rot;
        out.push(Joints { xyz: chain.linear_for(tip, &choice.rot), rot: choice.rot });
    }
    Ok(out)
}
