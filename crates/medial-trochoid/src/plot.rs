//! SVG of a plan: the contours, the medial axis, the danger stretches, the trochoids and the
//! passes coloured by engagement.

use crate::{Analysed, Plan};
use camkit::contour::Seg;
use camkit::contour::region::Region;
use camkit::geom::P2;
use camkit::svg::{Aspect, Piece, Plot, Style};

/// The moves of `a` as polylines through their samples, coloured by engagement on the colour
/// bar (degrees) from 0 to the largest engagement of cutting moves and links; entries (plunges,
/// ramps) beyond it are drawn in the top colour.
fn coloured(p: &mut Plot, a: &Analysed, width: f64) {
    let (mut pts, mut values): (Vec<P2>, Vec<f64>) = (Vec::new(), Vec::new());
    let mut last_move = usize::MAX;
    for (&(i, t), &e) in a.samples.iter().zip(&a.engagement) {
        let m = &a.program.moves[i];
        let joined = i == last_move || (last_move.checked_add(1) == Some(i) && !m.retract_before);
        if !joined {
            p.heat(&pts, &values, width);
            (pts, values) = (vec![m.seg.point_at(0.0)], vec![e]);
        }
        pts.push(m.seg.point_at(t));
        values.push(e);
        last_move = i;
    }
    p.heat(&pts, &values, width);
    p.colour_bar("path: engagement (°); entries above the top in its colour")
        .colour_range(0.0, a.max_cutting.max(a.max_link));
}

/// The contours of `regions` in black.
fn contours(p: &mut Plot, regions: &[Region]) {
    outlines(p, regions, &Style::stroke("black", 1.6).named("contour"));
}

/// The loops of `regions` drawn with `style`.
fn outlines(p: &mut Plot, regions: &[Region], style: &Style) {
    for r in regions {
        for c in r.loops() {
            if let Some(first) = c.vertices.first() {
                let pieces = c
                    .segs()
                    .map(|s| match s {
                        Seg::Line(_, b) => Piece::Line(b),
                        Seg::Arc(a) => Piece::Arc(a),
                    })
                    .collect();
                p.path(first.p, pieces, true, style.clone());
            }
        }
    }
}

/// The plot of a given (analysed) toolpath in its pocket, coloured by engagement.
pub fn given_plot(title: &str, regions: &[Region], a: &Analysed) -> Plot {
    let mut p = Plot::new(title, Aspect::Equal);
    contours(&mut p, regions);
    coloured(&mut p, a, 0.8);
    p
}

/// The plot of one program of the plan (`trochoidal` or offset-only). Where material was left
/// uncut, the input contours are drawn in black, the opened ones dashed, and the uncut stretches
/// of the input contours in magenta.
pub fn plan_plot(title: &str, plan: &Plan, trochoidal: bool) -> Plot {
    let mut p = Plot::new(title, Aspect::Equal);
    let opened = Style::stroke("#555555", 1.0).dashed("6 3");
    let uncut = Style::stroke("#e377c2", 4.0).named("left uncut (tool cannot reach it under the threshold)");
    match &plan.uncut {
        Some(u) => {
            contours(&mut p, &u.original);
            outlines(
                &mut p,
                &plan.regions,
                &opened.named(&format!("opened contour ({:.3} mm disk rolled inside)", u.rho)),
            );
            for st in &u.stretches {
                p.polyline(&st.points, uncut.clone());
            }
        }
        None => contours(&mut p, &plan.regions),
    }
    let a = if trochoidal { &plan.trochoidal } else { &plan.offset_only };
    coloured(&mut p, a, 0.8);
    for m in &plan.medial {
        for e in &m.edges {
            p.polyline(&e.points, Style::stroke("#7f7f7f", 1.0).dashed("4 2").named("medial axis"));
        }
    }
    for d in &plan.danger {
        p.polyline(d, Style::stroke("#d62728", 3.0).named("danger (engagement over threshold)"));
    }
    if trochoidal {
        for d in &plan.uncleared {
            p.polyline(d, Style::stroke("#ff7f0e", 3.0).named("danger where no trochoid fits"));
        }
        for r in &plan.rests {
            p.polygon(
                &r.outline(24),
                Style::fill("#2ca02c", 0.7).named("corner rest left to finishing (rounded wall pass)"),
            );
        }
    }
    p
}
