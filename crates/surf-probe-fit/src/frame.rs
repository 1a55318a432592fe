//! The fit as the workpiece frame document `post-6axis` reads (`camkit::doc::Frame`): the
//! translation `(xc, yc, za)` of paper 002 eq. 2 that puts the workpiece origin at the fitted
//! element's centre (a sphere's centre, a circle's centre, the axis point of a cylinder, the
//! centroid of a plane), with the whole fit carried in `fit`.

use crate::shapes::{Fit, Shape};
use camkit::doc::Frame;
use camkit::geom::V3;

/// The element's origin in table coordinates.
pub fn origin(shape: &Shape) -> V3 {
    match shape {
        Shape::Sphere { centre, .. } | Shape::Circle { centre, .. } => V3::from(*centre),
        Shape::Plane { point, .. } | Shape::Cylinder { point, .. } => V3::from(*point),
    }
}

/// The frame document of a fit, with `source` describing where it came from.
pub fn frame_of(fit: &Fit, source: String) -> Frame {
    let mut frame = Frame::with_origin_at(origin(&fit.shape));
    frame.source = Some(source);
    frame.fit = serde_json::to_value(fit).ok();
    frame
}
