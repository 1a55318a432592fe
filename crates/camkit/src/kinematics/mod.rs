//! Kinematic chains of 3-, 4- and 5-axis machines, and the spindle orientation of a
//! non-rotating tool as a sixth axis (papers 002 §4.1–4.3 and 000 §3.2).
//!
//! A chain is written like paper 002's shape-creation function (eq. 1–2), from the workpiece on
//! the left to the tool on the right: `r0 = F · L1 · L2 · … · Ln · rT`, where `rT` is a point in
//! tool coordinates (tip at the origin, axis +Z), each link `Li` is a rotation about a rotary
//! axis, a fixed offset, or the translation by the linear axes `(x, y, z)`, and `F` is the
//! translation of the workpiece frame. Links left of the linear axes ride on the table, links
//! right of them on the head. Paper 002's A/C table machine with its offsets (eq. 2) is
//! `F = (xc, yc, za)`, `[C about z, offset (0, yac, 0), A about x, linear]`, because a
//! translation along Z commutes with a rotation about Z.
//!
//! Rotations are right-handed about the axis direction by `sense × angle`, where `angle` is the
//! value the controller shows (degrees). Forward kinematics maps controller values to the tool
//! tip and axis in the workpiece frame; inverse kinematics returns both orientation branches.

mod select;

pub use select::{Choice, Policy, Solver, Unreachable};

use crate::geom::{P3, V3};
use nalgebra::Matrix3;

/// A 3×3 rotation matrix.
pub type M3 = Matrix3<f64>;

/// One rotary axis of a chain.
#[derive(Clone, Debug, PartialEq)]
pub struct Rotary {
    /// Address letter in the NC program (`A`, `B`, `C`).
    pub address: char,
    /// Unit direction of the axis at the chain's zero position.
    pub dir: V3,
    /// +1 or −1: the chain turns by `sense × angle` right-handed about `dir`.
    pub sense: f64,
    /// Travel limits (degrees), `None` for an axis without limits.
    pub limits: Option<(f64, f64)>,
    /// The axis turns endlessly: no limits, and it may be unwound between passes.
    pub wrap: bool,
    /// Angle at the start of a program (degrees): the first pose is chosen nearest to it.
    pub home: f64,
    /// True if the axis rides on the table side of the chain (left of the linear axes).
    pub on_table: bool,
}

impl Rotary {
    /// True if `angle` (degrees) is within the limits, allowing round-off.
    pub fn admits(&self, angle: f64) -> bool {
        match self.limits {
            Some((lo, hi)) => angle >= lo - LIMIT_SLACK_DEG && angle <= hi + LIMIT_SLACK_DEG,
            None => true,
        }
    }
}

/// Slack (degrees) when a rotary angle is compared with its limits: round-off only.
pub const LIMIT_SLACK_DEG: f64 = 1e-9;

/// One link of a chain.
#[derive(Clone, Debug, PartialEq)]
pub enum Link {
    /// Rotation about the chain's rotary axis with this index.
    Rotary(usize),
    /// A fixed translation (mm).
    Offset(V3),
    /// The translation by the linear axes `(x, y, z)`.
    Linear,
}

/// The structure of a machine, by where its rotary axes ride.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// No rotary axis.
    ThreeAxis,
    /// One rotary axis (a 4-axis machine), on the table or the head.
    FourAxis,
    /// Two rotary axes on the table (trunnion): A/C, B/C.
    TableTable,
    /// Two rotary axes on the head: A/B, B/C.
    HeadHead,
    /// One rotary axis on the table and one on the head.
    HeadTable,
}

impl Family {
    /// Name used in reports and documents.
    pub fn name(self) -> &'static str {
        match self {
            Family::ThreeAxis => "three-axis",
            Family::FourAxis => "four-axis",
            Family::TableTable => "table-table",
            Family::HeadHead => "head-head",
            Family::HeadTable => "head-table",
        }
    }
}

/// Controller values of the axes: linear (mm) and rotary (degrees, in chain order).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Joints {
    /// X, Y, Z (mm).
    pub xyz: V3,
    /// Rotary angles (degrees) in the order of the chain's rotary axes; unused entries are 0.
    pub rot: [f64; 2],
}

/// Tool tip and unit tool axis in the workpiece frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Tool tip (mm).
    pub tip: P3,
    /// Unit tool axis (from the tip towards the spindle).
    pub axis: V3,
}

/// Rotary angles that orient the tool along an axis: up to two branches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orientations {
    /// The branches (degrees, principal values in (−180, 180]); `count` of them are valid.
    pub branch: [[f64; 2]; 2],
    /// Number of valid branches (1 for machines with fewer than two rotary axes).
    pub count: usize,
    /// Angle (radians) between the tool axis and the primary rotary axis (the one nearer the
    /// workpiece), or its opposite: near 0 the primary angle is undetermined (singularity).
    pub off_primary: f64,
}

/// A machine's kinematic chain with its workpiece frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    links: Vec<Link>,
    rotaries: Vec<Rotary>,
    frame: V3,
    /// Index of the linear link.
    linear_at: usize,
}

/// Rotation by `angle` (radians) right-handed about the unit vector `d` (Rodrigues).
pub fn rotation(d: &V3, angle: f64) -> M3 {
    let (s, c) = angle.sin_cos();
    let k = 1.0 - c;
    Matrix3::new(
        c + k * d.x * d.x,
        k * d.x * d.y - s * d.z,
        k * d.x * d.z + s * d.y,
        k * d.y * d.x + s * d.z,
        c + k * d.y * d.y,
        k * d.y * d.z - s * d.x,
        k * d.z * d.x - s * d.y,
        k * d.z * d.y + s * d.x,
        c + k * d.z * d.z,
    )
}

/// `angle` (degrees) reduced to (−180, 180].
pub fn principal_deg(angle: f64) -> f64 {
    // Most angles are principal already: skip the division (a hot path of the post).
    if angle > -180.0 && angle <= 180.0 {
        return angle;
    }
    let a = angle.rem_euclid(360.0);
    if a > 180.0 { a - 360.0 } else { a }
}

/// The reference direction about a tool axis from which the spindle orientation `s` of the
/// toolpath table is measured: the workpiece +X carried to the plane normal to `axis` by the
/// smallest rotation that takes +Z to `axis`. For a vertical tool it is +X, so `s` is the heading
/// of the edge in the XY plane, counter-clockwise seen from above. Undefined only for a tool
/// pointing straight down the −Z axis (upside down), where −Z's own +X is used.
pub fn spindle_reference(axis: &V3) -> V3 {
    let z = V3::z();
    let c = axis.dot(&z);
    if c <= -1.0 + 1e-12 {
        return V3::x();
    }
    // Rotation about z × axis by the angle between them, applied to +X (Rodrigues, simplified).
    let k = z.cross(axis);
    let x = V3::x();
    (x * c + k.cross(&x) + k * (k.dot(&x) / (1.0 + c))).normalize()
}

/// The edge direction in the workpiece frame for spindle orientation `s` (degrees) about `axis`.
pub fn edge_direction(axis: &V3, s_deg: f64) -> V3 {
    let r = spindle_reference(axis);
    let (sn, cs) = s_deg.to_radians().sin_cos();
    r * cs + axis.cross(&r) * sn
}

/// The spindle orientation `s` (degrees, in (−180, 180]) of the edge direction `edge` about `axis`.
pub fn edge_angle(axis: &V3, edge: &V3) -> f64 {
    let r = spindle_reference(axis);
    let y = axis.cross(&r);
    edge.dot(&y).atan2(edge.dot(&r)).to_degrees()
}

impl Chain {
    /// A chain from its links (left to right, workpiece to tool) and rotary axes. Exactly one
    /// linear link, at most two rotary axes, each used once, with unit directions; the rotary
    /// axis nearer the tool must be able to tilt it (not parallel to the tool axis).
    pub fn new(links: Vec<Link>, rotaries: Vec<Rotary>) -> Result<Chain, String> {
        let linear: Vec<usize> =
            links.iter().enumerate().filter(|(_, l)| matches!(l, Link::Linear)).map(|(i, _)| i).collect();
        if linear.len() != 1 {
            return Err(format!("a chain needs exactly one linear link, found {}", linear.len()));
        }
        if rotaries.len() > 2 {
            return Err(format!("at most two rotary axes are supported, found {}", rotaries.len()));
        }
        let used: Vec<usize> =
            links.iter().filter_map(|l| if let Link::Rotary(k) = l { Some(*k) } else { None }).collect();
        for (k, r) in rotaries.iter().enumerate() {
            if used.iter().filter(|&&u| u == k).count() != 1 {
                return Err(format!("rotary axis {} must appear exactly once in the chain", r.address));
            }
        }
        if used.len() != rotaries.len() || used.iter().enumerate().any(|(i, &k)| i != k) {
            return Err("rotary axes must be listed in chain order".into());
        }
        for r in &rotaries {
            if (r.dir.norm() - 1.0).abs() > 1e-9 {
                return Err(format!("axis {} direction is not a unit vector", r.address));
            }
            if r.sense != 1.0 && r.sense != -1.0 {
                return Err(format!("axis {} sense must be 1 or -1", r.address));
            }
        }
        if let Some(last) = rotaries.last()
            && last.dir.cross(&V3::z()).norm() < 1e-9
        {
            return Err(format!(
                "rotary axis {} is the one nearest the tool and parallel to it: it cannot tilt the tool",
                last.address
            ));
        }
        if rotaries.len() == 2 {
            let n1 = rotaries[0].dir;
            let (alpha, beta, _) = invariant_coefficients(&n1, &rotaries[1].dir);
            if alpha.hypot(beta) < 1e-9 {
                return Err(format!(
                    "rotary axes {} and {} are parallel: they cannot orient the tool",
                    rotaries[0].address, rotaries[1].address
                ));
            }
        }
        let mut rotaries = rotaries;
        for (k, r) in rotaries.iter_mut().enumerate() {
            r.on_table = links.iter().position(|l| *l == Link::Rotary(k)).is_some_and(|i| i < linear[0]);
        }
        Ok(Chain { links, rotaries, frame: V3::zeros(), linear_at: linear[0] })
    }

    /// The same chain with the workpiece frame translation `frame` (paper 002's `(xc, yc, za)`).
    pub fn with_frame(mut self, frame: V3) -> Chain {
        self.frame = frame;
        self
    }

    /// The workpiece frame translation.
    pub fn frame(&self) -> V3 {
        self.frame
    }

    /// The rotary axes in chain order.
    pub fn rotaries(&self) -> &[Rotary] {
        &self.rotaries
    }

    /// The links.
    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// The machine's family.
    pub fn family(&self) -> Family {
        let table = self.rotaries.iter().filter(|r| r.on_table).count();
        match (self.rotaries.len(), table) {
            (0, _) => Family::ThreeAxis,
            (1, _) => Family::FourAxis,
            (_, 2) => Family::TableTable,
            (_, 0) => Family::HeadHead,
            _ => Family::HeadTable,
        }
    }

    fn angle_rad(&self, k: usize, rot: &[f64; 2]) -> f64 {
        self.rotaries[k].sense * rot[k].to_radians()
    }

    /// The orientation of the tool frame in the workpiece frame: the product of the chain's
    /// rotations, left to right. The tool axis is its third column.
    pub fn orientation(&self, rot: &[f64; 2]) -> M3 {
        self.orientation_of(&self.rotations(rot))
    }

    /// The rotation of each rotary axis at `rot` (identity for unused entries): computed once per
    /// pose, as trigonometry dominates the cost of the kinematics.
    fn rotations(&self, rot: &[f64; 2]) -> [M3; 2] {
        let mut m = [M3::identity(); 2];
        for (k, r) in self.rotaries.iter().enumerate() {
            m[k] = rotation(&r.dir, self.angle_rad(k, rot));
        }
        m
    }

    fn orientation_of(&self, rots: &[M3; 2]) -> M3 {
        rots[..self.rotaries.len()].iter().fold(M3::identity(), |m, r| m * r)
    }

    /// The table side `(R, t)` (workpiece ← machine: `p_w = R p_m + t`, frame included) and the
    /// tool tip in machine coordinates relative to `(x, y, z)` (the head side applied to the tip).
    fn sides(&self, rots: &[M3; 2]) -> (M3, V3, V3) {
        let mut r = M3::identity();
        let mut t = self.frame;
        for link in &self.links[..self.linear_at] {
            match link {
                Link::Rotary(k) => r *= rots[*k],
                Link::Offset(v) => t += r * v,
                Link::Linear => {}
            }
        }
        let mut h = V3::zeros();
        for link in self.links[self.linear_at + 1..].iter().rev() {
            match link {
                Link::Rotary(k) => h = rots[*k] * h,
                Link::Offset(v) => h += v,
                Link::Linear => {}
            }
        }
        (r, t, h)
    }

    /// Forward kinematics: tool tip and axis in the workpiece frame for controller values.
    pub fn forward(&self, j: &Joints) -> Pose {
        self.forward_oriented(j).0
    }

    /// Forward kinematics with the tool frame's orientation (its third column is the axis), for
    /// callers that also need the spindle angle ([`Chain::spindle_angle_in`]) at the same pose.
    pub fn forward_oriented(&self, j: &Joints) -> (Pose, M3) {
        let rots = self.rotations(&j.rot);
        let (r, t, h) = self.sides(&rots);
        let tip = P3::from(r * (j.xyz + h) + t);
        let m = self.orientation_of(&rots);
        (Pose { tip, axis: m.column(2).into_owned() }, m)
    }

    /// The linear axes that put the tool tip at `tip` (workpiece frame) with rotary angles `rot`:
    /// the inverse of eq. 2 once the angles are known.
    pub fn linear_for(&self, tip: &P3, rot: &[f64; 2]) -> V3 {
        let (r, t, h) = self.sides(&self.rotations(rot));
        r.transpose() * (tip.coords - t) - h
    }

    /// [`Chain::linear_for`] and the tool frame orientation ([`Chain::orientation`]) at `rot`, from
    /// one evaluation of the rotations (for callers that need both, e.g. with a spindle angle).
    pub fn linear_oriented(&self, tip: &P3, rot: &[f64; 2]) -> (V3, M3) {
        let rots = self.rotations(rot);
        let (r, t, h) = self.sides(&rots);
        (r.transpose() * (tip.coords - t) - h, self.orientation_of(&rots))
    }

    /// Rotary angles that turn the tool axis onto `axis` (unit), both branches, principal values.
    /// `None` if no angles reach it (a machine with fewer than two rotary axes, or an axis
    /// outside the reachable cone of a non-orthogonal head).
    pub fn orientations(&self, axis: &V3) -> Option<Orientations> {
        match self.rotaries.len() {
            0 => ((axis - V3::z()).norm() <= 1e-9).then_some(Orientations {
                branch: [[0.0; 2]; 2],
                count: 1,
                off_primary: 0.0,
            }),
            1 => {
                let d = self.rotaries[0].dir;
                let z = V3::z();
                // The component along the axis is kept by the rotation: it must match +Z's.
                if (d.dot(axis) - d.dot(&z)).abs() > 1e-9 {
                    return None;
                }
                let angle = d.dot(&z.cross(axis)).atan2(z.dot(axis) - d.dot(&z) * d.dot(axis));
                let deg = principal_deg(self.rotaries[0].sense * angle.to_degrees());
                // A single rotary axis has no singularity: it cannot be parallel to the tool.
                Some(Orientations { branch: [[deg, 0.0]; 2], count: 1, off_primary: std::f64::consts::FRAC_PI_2 })
            }
            _ => self.orientations2(axis),
        }
    }

    fn orientations2(&self, u: &V3) -> Option<Orientations> {
        let n1 = self.rotaries[0].dir;
        let d2 = self.rotaries[1].dir;
        let z = V3::z();
        let (alpha, beta, gamma) = invariant_coefficients(&n1, &d2);
        let rho = alpha.hypot(beta);
        let h = n1.dot(u) - gamma;
        // sin of (θ2 − φ): for orthogonal axis pairs (every usual machine) it is |n1 × u| exactly,
        // which keeps the angle accurate near the singularity.
        let orthogonal = gamma.abs() < 1e-15 && (rho - 1.0).abs() < 1e-15;
        let s = if orthogonal {
            n1.cross(u).norm()
        } else {
            let q = rho * rho - h * h;
            if q < -1e-9 {
                return None;
            }
            q.max(0.0).sqrt()
        };
        let phi = beta.atan2(alpha);
        let off_primary = n1.cross(u).norm().atan2(n1.dot(u).abs());
        let mut branch = [[0.0; 2]; 2];
        for (b, sign) in [1.0, -1.0].into_iter().enumerate() {
            let t2 = phi + (sign * s).atan2(h);
            let w = rotation(&d2, t2) * z;
            let t1 = n1.dot(&w.cross(u)).atan2(w.dot(u) - n1.dot(&w) * n1.dot(u));
            branch[b] = [
                principal_deg(self.rotaries[0].sense * t1.to_degrees()),
                principal_deg(self.rotaries[1].sense * t2.to_degrees()),
            ];
        }
        Some(Orientations { branch, count: 2, off_primary })
    }

    /// The secondary angle (degrees) that brings the tool axis nearest to `axis` when the primary
    /// angle is held at `primary` (degrees): used near the singularity.
    pub fn secondary_for(&self, axis: &V3, primary: f64) -> f64 {
        let n1 = self.rotaries[0].dir;
        let d2 = self.rotaries[1].dir;
        let z = V3::z();
        let v = rotation(&n1, -self.rotaries[0].sense * primary.to_radians()) * axis;
        // v · R(d2, θ) z = const + cos θ (z·v − (d2·z)(d2·v)) + sin θ ((d2 × z)·v).
        let a = z.dot(&v) - d2.dot(&z) * d2.dot(&v);
        let b = d2.cross(&z).dot(&v);
        principal_deg(self.rotaries[1].sense * b.atan2(a).to_degrees())
    }

    /// Inverse kinematics: every joint solution (principal rotary values) putting the tool tip at
    /// `pose.tip` with axis `pose.axis`.
    pub fn inverse(&self, pose: &Pose) -> Vec<Joints> {
        let Some(o) = self.orientations(&pose.axis) else { return Vec::new() };
        o.branch[..o.count].iter().map(|rot| Joints { xyz: self.linear_for(&pose.tip, rot), rot: *rot }).collect()
    }

    /// The machine spindle angle (degrees, principal) that puts the edge of a non-rotating tool at
    /// spindle orientation `s` (degrees, about the tool axis, see [`spindle_reference`]) when the
    /// rotary axes are at `rot`. The spindle's zero is the tool frame's +X.
    pub fn spindle_angle(&self, rot: &[f64; 2], s_deg: f64) -> f64 {
        Self::spindle_angle_in(&self.orientation(rot), s_deg)
    }

    /// [`Chain::spindle_angle`] for a tool frame orientation `m` already known
    /// ([`Chain::orientation`], [`Chain::forward_oriented`]).
    pub fn spindle_angle_in(m: &M3, s_deg: f64) -> f64 {
        let axis = m.column(2).into_owned();
        let edge = m.transpose() * edge_direction(&axis, s_deg);
        edge.y.atan2(edge.x).to_degrees()
    }

    /// The spindle orientation `s` (degrees, principal) of the edge when the spindle is at `sigma`
    /// degrees and the rotary axes at `rot`: the inverse of [`Chain::spindle_angle`].
    pub fn edge_orientation(&self, rot: &[f64; 2], sigma_deg: f64) -> f64 {
        let m = self.orientation(rot);
        let (sn, cs) = sigma_deg.to_radians().sin_cos();
        let edge = m * V3::new(cs, sn, 0.0);
        edge_angle(&m.column(2).into_owned(), &edge)
    }
}

/// Coefficients of `n1 · R(d2, θ) z = γ + α cos θ + β sin θ`: the part of the tool axis along the
/// primary rotary axis, which the primary rotation keeps, as a function of the secondary angle.
fn invariant_coefficients(n1: &V3, d2: &V3) -> (f64, f64, f64) {
    let z = V3::z();
    let dz = d2.dot(&z);
    let gamma = dz * n1.dot(d2);
    let alpha = n1.dot(&z) - dz * n1.dot(d2);
    let beta = n1.dot(&d2.cross(&z));
    (alpha, beta, gamma)
}

#[cfg(test)]
mod tests;
