//! SVG of a fit: the input points and the fitted pieces, lines and arcs in their own colours.

use crate::FittedRun;
use crate::fit::Shape;
use camkit::geom::{Arc2, Plane};
use camkit::svg::{Aspect, Piece, Plot, Style};

/// Colour of line pieces.
const LINE: &str = "#1f77b4";
/// Colour of arc pieces.
const ARC: &str = "#d62728";
/// Input points are drawn as dots only up to this many (beyond, the picture is ink).
const MAX_DOTS: usize = 20_000;

/// The plot of `runs` projected on `plane`.
pub fn plot(runs: &[FittedRun], plane: Plane, title: &str) -> Plot {
    let mut p = Plot::new(title, Aspect::Equal);
    let [u, v, _] = plane.axes();
    let names = ["x", "y", "z"];
    p.labels(&format!("{} (mm)", names[u]), &format!("{} (mm)", names[v]));
    let total: usize = runs.iter().map(|r| r.pts.len()).sum();
    if total <= MAX_DOTS {
        for run in runs {
            let flat: Vec<_> = run.pts.iter().map(|q| plane.split(q).0).collect();
            p.dots(&flat, 1.0, Style::fill("#999", 0.7).named("input points"));
        }
    }
    let mut joints = Vec::new();
    for run in runs {
        for piece in &run.pieces {
            joints.push(plane.split(&piece.start).0);
            let a = plane.split(&piece.start).0;
            let b = plane.split(&piece.end).0;
            match piece.shape {
                Shape::Line => {
                    p.polyline(&[a, b], Style::stroke(LINE, 2.2).named("line"));
                }
                Shape::Arc { centre, plane: arc_plane, ccw } => {
                    // Arcs in another plane are drawn by their end points only.
                    if arc_plane == plane {
                        let arc = Arc2::from_centre(centre, &a, &b, ccw, false);
                        p.path(a, vec![Piece::Arc(arc)], false, Style::stroke(ARC, 2.2).named("arc"));
                    } else {
                        p.polyline(&[a, b], Style::stroke(ARC, 2.2).dashed("3 2").named("arc in another plane (chord)"));
                    }
                }
            }
            joints.push(b);
        }
    }
    p.dots(&joints, 2.2, Style::fill("black", 1.0).named("piece ends"));
    p
}
