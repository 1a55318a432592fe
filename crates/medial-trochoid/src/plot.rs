//! SVG of a plan: the contours, the medial axis, the danger stretches, the trochoids and the
//! passes coloured by engagement.

use crate::{Analysed, Plan};
use camkit::contour::Seg;
use camkit::contour::region::Region;
use camkit::geom::P2;
use camkit::svg::{Aspect, Piece, Plot, Style, ramp};

/// Engagement colour bands (degrees per band) of the plot.
const BAND: f64 = 15.0;

fn colour(deg: f64) -> String {
    let (r, g, b) = ramp((deg / BAND).floor() * BAND / 180.0);
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// The moves of `a` as polylines through their samples, coloured by engagement band.
fn coloured(p: &mut Plot, a: &Analysed, width: f64) {
    let mut run: Vec<P2> = Vec::new();
    let mut band = f64::NAN;
    let mut last_move = usize::MAX;
    for (&(i, t), &e) in a.samples.iter().zip(&a.engagement) {
        let m = &a.program.moves[i];
        let q = m.seg.point_at(t);
        let b = (e / BAND).floor();
        let joined = i == last_move || (last_move.checked_add(1) == Some(i) && !m.retract_before);
        if !joined || b != band {
            if run.len() > 1 {
                p.polyline(&run, Style::stroke(&colour(band * BAND), width));
            }
            let from = if joined { run.last().copied() } else { None };
            run = vec![from.unwrap_or_else(|| m.seg.point_at(0.0))];
            band = b;
        }
        run.push(q);
        last_move = i;
    }
    if run.len() > 1 {
        p.polyline(&run, Style::stroke(&colour(band * BAND), width));
    }
}

/// The contours of `regions` in black.
fn contours(p: &mut Plot, regions: &[Region]) {
    outlines(p, regions, &Style::stroke("black", 1.6));
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
    p.legend("contour", Style::stroke("black", 1.6))
        .legend("path: engagement 0° (dark) to 180° (yellow), 15° bands", Style::stroke(&colour(90.0), 0.8));
    p
}

/// The plot of one program of the plan (`trochoidal` or offset-only). Where material was left
/// uncut, the input contours are drawn in black, the opened ones dashed, and the uncut stretches
/// of the input contours in magenta.
pub fn plan_plot(title: &str, plan: &Plan, trochoidal: bool) -> Plot {
    let mut p = Plot::new(title, Aspect::Equal);
    let opened = Style::stroke("#555555", 1.0).dashed("6 3");
    let uncut = Style::stroke("#e377c2", 4.0);
    match &plan.uncut {
        Some(u) => {
            contours(&mut p, &u.original);
            outlines(&mut p, &plan.regions, &opened);
            for st in &u.stretches {
                p.polyline(&st.points, uncut.clone());
            }
            p.legend(&format!("opened contour ({:.3} mm disk rolled inside)", u.rho), opened)
                .legend("left uncut (tool cannot reach it under the threshold)", uncut);
        }
        None => contours(&mut p, &plan.regions),
    }
    let a = if trochoidal { &plan.trochoidal } else { &plan.offset_only };
    coloured(&mut p, a, 0.8);
    for m in &plan.medial {
        for e in &m.edges {
            p.polyline(&e.points, Style::stroke("#7f7f7f", 1.0).dashed("4 2"));
        }
    }
    for d in &plan.danger {
        p.polyline(d, Style::stroke("#d62728", 3.0));
    }
    if trochoidal {
        for d in &plan.uncleared {
            p.polyline(d, Style::stroke("#ff7f0e", 3.0));
        }
        for r in &plan.rests {
            p.polygon(&r.outline(24), Style::fill("#2ca02c", 0.7));
        }
        p.legend("corner rest left to finishing (rounded wall pass)", Style::fill("#2ca02c", 0.7));
    }
    p.legend("contour", Style::stroke("black", 1.6))
        .legend("medial axis", Style::stroke("#7f7f7f", 1.0).dashed("4 2"))
        .legend("danger (engagement over threshold)", Style::stroke("#d62728", 3.0))
        .legend("passes: engagement 0° (dark) to 180° (yellow), 15° bands", Style::stroke(&colour(90.0), 0.8));
    p
}
