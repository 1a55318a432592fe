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
    for run in runs {
        let flat: Vec<_> = run.pts.iter().map(|q| plane.split(q).0).collect();
        for piece in &run.pieces {
            let a = plane.split(&piece.start).0;
            let b = plane.split(&piece.end).0;
            match piece.shape {
                Shape::Line => {
                    p.polyline(&[a, b], Style::stroke(LINE, 1.6));
                }
                Shape::Arc { centre, plane: arc_plane, ccw } => {
                    // Arcs in another plane are drawn by their end points only.
                    if arc_plane == plane {
                        let arc = Arc2::from_centre(centre, &a, &b, ccw, false);
                        p.path(a, vec![Piece::Arc(arc)], false, Style::stroke(ARC, 1.6));
                    } else {
                        p.polyline(&[a, b], Style::stroke(ARC, 1.6).dashed("3 2"));
                    }
                }
            }
        }
        if total <= MAX_DOTS {
            p.dots(&flat, 1.3, Style::fill("#444", 0.8));
        }
    }
    p.legend("line", Style::stroke(LINE, 1.6)).legend("arc", Style::stroke(ARC, 1.6));
    if total <= MAX_DOTS {
        p.legend("input points", Style::fill("#444", 0.8));
    }
    p
}
