//! `tool-attitude`: tool tip, tool axis and spindle orientation from contact data (the stream
//! `stylus-trace` writes), for the cylindrical non-rotating tool tilted toward the feed (paper 000
//! §2, §3.2(1), eq. 1), the flat-type non-rotating tool (000 §3.2(2)), the ball end mill with a
//! tilt (003 §3.1) and the flat end mill along the normal (002 §4.2), with gouge checks of the
//! whole tool body against the model.
//!
//! [`pose`] holds the closed-form poses, [`edge`] eq. (1), [`flat_type`] the control-stylus
//! correction, [`gouge`] the body check against the part and the tilt search; [`attitude`] puts
//! them together for one row.

pub mod edge;
pub mod flat_type;
pub mod gouge;
pub mod plot;
pub mod pose;

use camkit::geom::{P3, V3};
use gouge::Part;
use pose::Pose;

/// The tool, as `tool-attitude` uses it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// Cylindrical non-rotating tool of `radius`; `cut_depth` is T of eq. (1) (0: the limit).
    Cylinder {
        /// R (mm).
        radius: f64,
        /// T (mm).
        cut_depth: f64,
    },
    /// Flat-type non-rotating tool.
    FlatType {
        /// Edge geometry.
        edge: flat_type::Edge,
        /// True: the control stylus is P3 on the second surface; false: P1 on the first.
        control_second: bool,
    },
    /// Ball end mill of `radius`; `side` tilts across the feed (paper 003) instead of along it.
    Ball {
        /// r (mm).
        radius: f64,
        /// Tilt across the feed.
        side: bool,
    },
    /// Flat end mill of `radius` along the normal.
    FlatMill {
        /// R (mm).
        radius: f64,
    },
}

/// Settings for every row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setup {
    /// The tool.
    pub shape: Shape,
    /// Requested tilt (radians): θ of the cylinder, ζ of the ball; unused otherwise.
    pub tilt: f64,
    /// Allowed tilt range (radians) for gouge avoidance.
    pub range: (f64, f64),
    /// Length of the tool body above the tip that the gouge check takes (mm).
    pub length: f64,
    /// Penetration tolerated before a pose counts as gouging (mm).
    pub gouge_tol: f64,
}

/// One row's contact data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Stylus centre (x, y, z of the stream).
    pub centre: P3,
    /// Contact point.
    pub point: P3,
    /// Unit normal at the contact.
    pub normal: V3,
    /// Second contact (two-surface stream): point and unit normal.
    pub second: Option<(P3, V3)>,
    /// Model surface indices of both contacts, when known (flat-type correction).
    pub surfaces: (Option<usize>, Option<usize>),
    /// Feed direction (unit).
    pub feed: V3,
}

/// One row's result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attitude {
    /// The pose.
    pub pose: Pose,
    /// Tilt used (radians): θ, ζ, or for the flat-type tool the angle of the axis from the
    /// bisector of both normals (the paper's correction, fig. 10), positive away from the
    /// control surface: half the included-angle margin plus the control-stylus correction.
    pub tilt: f64,
    /// R' of eq. (1) (cylinder; `None` where infinite or undefined).
    pub edge_radius: Option<f64>,
    /// Machine angles [a, c] of eq. (3)–(4), degrees (flat end mill).
    pub machine: Option<(f64, f64)>,
    /// Second-flank stand-off (radians, flat-type tool).
    pub flank_gap: Option<f64>,
    /// Penetration into the model at the pose (mm), with a model.
    pub gouge: Option<f64>,
    /// True when the tilt was changed to avoid a gouge.
    pub adjusted: bool,
}

/// Why a row has no attitude.
#[derive(Clone, Debug, PartialEq)]
pub enum RowError {
    /// The feed runs along the normal: no tilt direction.
    FeedAlongNormal,
    /// The flat-type tool needs the second contact (two-surface stream).
    NoSecondContact,
    /// The flat-type correction failed.
    Flat(flat_type::FlatError),
}

impl std::fmt::Display for RowError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RowError::FeedAlongNormal => f.write_str("the feed direction is along the normal: no tilt plane"),
            RowError::NoSecondContact => {
                f.write_str("the flat-type tool needs both contacts (stylus-trace --mode two-surface)")
            }
            RowError::Flat(flat_type::FlatError::NoCorner) => {
                f.write_str("both normals are parallel: no concave corner")
            }
            RowError::Flat(flat_type::FlatError::NoContact) => {
                f.write_str("the control stylus could not be brought onto its surface")
            }
        }
    }
}

/// The tip of a ball end mill of radius `r` held along the fixed unit `axis` whose ball centre is
/// the stylus centre `centre` (a stylus of the same radius traced the model): tip = centre − r·axis.
/// The stylus centre is where the ball's centre must be whatever the axis, so the ball touches the
/// model as the stylus did.
pub fn fixed_axis_ball_tip(centre: &P3, axis: &V3, r: f64) -> P3 {
    centre - axis * r
}

/// The attitude of one row; with a part, the tool body is checked and the tilt adjusted inside
/// the range where the tool has a free tilt (cylinder, ball).
pub fn attitude(setup: &Setup, c: &Contact, part: Option<&Part>) -> Result<Attitude, RowError> {
    let n = c.normal;
    match setup.shape {
        Shape::Cylinder { radius, cut_depth } => {
            let f = pose::tangent_feed(&n, &c.feed).ok_or(RowError::FeedAlongNormal)?;
            let make = |t: f64| pose::cylinder(&c.point, &n, &f, radius, t);
            let (tilt, gouge, adjusted) = tilt_search(setup, part, &make);
            Ok(Attitude {
                pose: make(tilt),
                tilt,
                edge_radius: edge::edge_radius(radius, cut_depth, tilt),
                machine: None,
                flank_gap: None,
                gouge,
                adjusted,
            })
        }
        Shape::Ball { radius, side } => {
            let f = pose::tangent_feed(&n, &c.feed).ok_or(RowError::FeedAlongNormal)?;
            let dir = if side { f.cross(&n) } else { f };
            let make = |t: f64| pose::ball(&c.point, &n, &dir, radius, t);
            let (tilt, gouge, adjusted) = tilt_search(setup, part, &make);
            Ok(Attitude { pose: make(tilt), tilt, edge_radius: None, machine: None, flank_gap: None, gouge, adjusted })
        }
        Shape::FlatMill { .. } => {
            let pose = pose::flat_mill(&c.point, &n);
            Ok(Attitude {
                pose,
                tilt: 0.0,
                edge_radius: None,
                machine: Some(pose::machine_angles(&pose.axis)),
                flank_gap: None,
                gouge: part.map(|p| p.penetration(&pose)),
                adjusted: false,
            })
        }
        Shape::FlatType { edge, control_second } => {
            let model = part.map(|p| &p.model);
            let (p2, n2) = c.second.ok_or(RowError::NoSecondContact)?;
            let (control, other, index) =
                if control_second { ((p2, n2), n, c.surfaces.1) } else { ((c.point, n), n2, c.surfaces.0) };
            let corner = flat_type::Corner { centre: c.centre, control, other };
            let dist = model.zip(index).map(|(m, i)| move |q: &P3| m.nearest_on(q, i).distance);
            let dist_ref = dist.as_ref().map(|d| d as &dyn Fn(&P3) -> f64);
            let fp = flat_type::solve(&corner, &edge, &c.feed, dist_ref).map_err(RowError::Flat)?;
            // The edge is the stylus's offset of the surface: the wedge of both flanks (at the
            // tip, in the plane across the corner line `fp.pose.edge`) keeps the stylus radius off.
            let r = (c.centre - control.0).norm();
            let gouge = part.map(|p| p.penetration_within(&fp.pose, r));
            Ok(Attitude {
                pose: fp.pose,
                tilt: fp.correction + (edge.included - fp.corner_angle) / 2.0,
                edge_radius: None,
                machine: None,
                flank_gap: Some(fp.flank_gap),
                gouge,
                adjusted: false,
            })
        }
    }
}

/// The requested tilt, or with a part the clear tilt nearest it inside the range (the whole body
/// clear, see [`gouge::adjust`]).
fn tilt_search(setup: &Setup, part: Option<&Part>, make: &dyn Fn(f64) -> Pose) -> (f64, Option<f64>, bool) {
    let Some(p) = part else { return (setup.tilt, None, false) };
    let tol = setup.gouge_tol;
    let a = gouge::adjust(
        setup.tilt,
        setup.range.0,
        setup.range.1,
        |t| p.penetration(&make(t)),
        |t| p.gouges(&make(t), tol),
    );
    (a.tilt, Some(a.gouge), a.tilt != setup.tilt)
}
