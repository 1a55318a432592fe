//! SVG of a fit: the input points and the fitted pieces, lines and arcs in their own colours; a
//! layered program (a print: many heights) as 3-D views coloured by height, extrusion apart
//! from travel.

use crate::FittedRun;
use crate::fit::{Piece as FitPiece, Shape};
use camkit::geom::{Arc2, P3, Plane};
use camkit::svg::figure::{Path3, views};
use camkit::svg::{Aspect, Piece, Plot, Style};

/// Colour of line pieces.
const LINE: &str = "#1f77b4";
/// Colour of arc pieces.
const ARC: &str = "#d62728";
/// Input points are drawn as dots only up to this many (beyond, the picture is ink).
const MAX_DOTS: usize = 20_000;
/// Distinct heights (to 1 µm) from which a program counts as layered and is drawn in 3-D.
const LAYERED: usize = 3;

/// The SVG of `runs`, `width` pixels wide: in 3-D views if they lie at [`LAYERED`] heights or
/// more, else projected on `plane`.
pub fn svg(runs: &[FittedRun], plane: Plane, title: &str, width: f64) -> String {
    if plane == Plane::Xy && layered(runs) {
        layers(runs, title).to_svg(width)
    } else {
        plot(runs, plane, title).to_svg(width)
    }
}

/// True if the runs' points lie at [`LAYERED`] distinct heights or more (to 1 µm).
fn layered(runs: &[FittedRun]) -> bool {
    let mut seen = std::collections::HashSet::new();
    runs.iter().flat_map(|r| r.pts.iter()).any(|p| {
        seen.insert((p.z * 1e3).round() as i64);
        seen.len() >= LAYERED
    })
}

/// Points along a piece: its ends, and an arc every 5°.
fn trace(piece: &FitPiece, out: &mut Vec<P3>) {
    match piece.helix() {
        Some(h) => {
            let (arc, wa, wb) = h.arc();
            let n = ((arc.sweep.abs() / 5f64.to_radians()).ceil() as usize).max(1);
            for i in 1..=n {
                let t = i as f64 / n as f64;
                out.push(h.plane.join(&arc.point_at_fraction(t), wa + (wb - wa) * t));
            }
        }
        None => out.push(piece.end),
    }
}

/// A layered program in 3-D: the extruding runs coloured by height, travel (runs without
/// extrusion, in a program that extrudes) dashed grey under them.
pub fn layers(runs: &[FittedRun], title: &str) -> camkit::svg::figure::Figure {
    let prints = runs.iter().any(|r| r.extrusion.is_some_and(|e| e > 0.0));
    let mut paths = Vec::new();
    let mut travel = Vec::new();
    for run in runs {
        let Some(first) = run.pieces.first() else { continue };
        let mut pts = vec![first.start];
        for piece in &run.pieces {
            trace(piece, &mut pts);
        }
        if prints && !run.extrusion.is_some_and(|e| e > 0.0) {
            travel.push((pts, Style::stroke("#999999", 0.6).dashed("3 3").named("travel (no extrusion)")));
        } else {
            paths.push(Path3::by_z(pts));
        }
    }
    let what = if prints { "extrusion: height z (mm)" } else { "height z (mm)" };
    views(title, &paths, what, &travel)
}

/// The plot of `runs` projected on `plane`: consecutive pieces of one shape as one path.
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
    let line = Style::stroke(LINE, 2.2).named("line");
    let arc_style = Style::stroke(ARC, 2.2).named("arc");
    let chord = Style::stroke(ARC, 2.2).dashed("3 2").named("arc in another plane (chord)");
    let mut joints = Vec::new();
    for run in runs {
        // The open path: its style and pieces from its start.
        let mut open: Option<(Style, camkit::geom::P2, Vec<Piece>)> = None;
        for piece in &run.pieces {
            let a = plane.split(&piece.start).0;
            let b = plane.split(&piece.end).0;
            joints.push(a);
            let (style, drawn) = match piece.shape {
                Shape::Line => (&line, Piece::Line(b)),
                // Arcs in another plane are drawn by their chords.
                Shape::Arc { centre, plane: arc_plane, ccw } if arc_plane == plane => {
                    (&arc_style, Piece::Arc(Arc2::from_centre(centre, &a, &b, ccw, false)))
                }
                Shape::Arc { .. } => (&chord, Piece::Line(b)),
            };
            if open.as_ref().is_some_and(|o| o.0 != *style) {
                let (s, start, pieces) = open.take().expect("checked");
                p.path(start, pieces, false, s);
            }
            open.get_or_insert_with(|| (style.clone(), a, Vec::new())).2.push(drawn);
            joints.push(b);
        }
        if let Some((s, start, pieces)) = open {
            p.path(start, pieces, false, s);
        }
    }
    p.dots(&joints, 2.2, Style::fill("black", 1.0).named("piece ends"));
    p
}
