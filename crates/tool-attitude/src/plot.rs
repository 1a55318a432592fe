//! The plot of the written poses (`--svg`): the tool tip paths in 3-D views coloured by the tool
//! axis's tilt from +z, with the axis drawn as a short stroke at evenly spaced rows.

use camkit::geom::P3;
use camkit::svg::Style;
use camkit::svg::figure::{Figure, Path3, views};
use camkit::table::Table;

/// Tool-axis strokes drawn over the whole table (about; every n-th row).
const AXIS_STROKES: usize = 150;

/// The 3-D views of `t`'s tip paths, one per pass, coloured by the axis tilt (degrees), or by
/// the tip's z when every row has the same axis (a fixed-axis tool), over `model` (the model's
/// lines, see [`camkit::svg::relief`]).
pub fn plot(t: &Table, title: &str, model: &[(Vec<P3>, Style)]) -> Figure {
    let tilt = |r: &camkit::table::Row| r.axis.z.clamp(-1.0, 1.0).acos().to_degrees();
    let fixed = t.rows.windows(2).all(|w| w[0].axis == w[1].axis);
    let paths: Vec<Path3> = t
        .passes()
        .map(|rows| {
            let pts = rows.iter().map(|r| r.pos).collect();
            if fixed { Path3::by_z(pts) } else { Path3 { pts, values: rows.iter().map(tilt).collect() } }
        })
        .collect();
    let (lo, hi) = t.rows.iter().fold(
        (
            P3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
            P3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
        ),
        |(a, b), r| (a.inf(&r.pos), b.sup(&r.pos)),
    );
    let len = if lo.x.is_finite() { 0.03 * (hi - lo).norm().max(1e-6) } else { 0.0 };
    let every = t.rows.len().div_ceil(AXIS_STROKES).max(1);
    let style = Style::stroke("#555555", 0.7).named(&format!("tool axis (every {every} rows)"));
    let mut under = model.to_vec();
    under.extend(t.rows.iter().step_by(every).map(|r| (vec![r.pos, r.pos + r.axis * len], style.clone())));
    let bar = if fixed { "tool tip z (mm), fixed axis" } else { "tool tip: axis tilt from +z (°)" };
    views(title, &paths, bar, &under)
}
