//! Height maps and figures written out: CSV (x, y, height), an SVG colour map, and profile and
//! sweep plots.

use crate::figures::Figures;
use crate::patch::HeightMap;
use camkit::geom::P2;
use camkit::svg::{Aspect, Plot, Raster, Style};
use std::fmt::Write;

/// Cells along the longer side of a colour map; larger maps are sampled down to this.
const MAP_CELLS: usize = 300;

/// The map as CSV: `x,y,<name>` in mm, one node per row, rows of constant y in order; NaN nodes
/// (never cut) are written with an empty height.
pub fn csv(map: &HeightMap, name: &str) -> Vec<u8> {
    let g = &map.grid;
    let mut out = String::with_capacity(g.nx * g.ny * 28 + 16);
    let _ = writeln!(out, "x,y,{name}");
    for j in 0..g.ny {
        for i in 0..g.nx {
            let v = map.at(i, j);
            if v.is_finite() {
                let _ = writeln!(out, "{:.6},{:.6},{:.7}", g.x(i), g.y(j), v);
            } else {
                let _ = writeln!(out, "{:.6},{:.6},", g.x(i), g.y(j));
            }
        }
    }
    out.into_bytes()
}

/// An SVG colour map of the heights in mm (absolute, as in the CSV), sampled down to at most
/// [`MAP_CELLS`] a side by taking each cell's highest node (peaks stay visible), on a colour bar
/// labelled `bar` (with its unit); the roughness figures, if given, in µm in the title.
pub fn colour_map(map: &HeightMap, title: &str, bar: &str, figures: Option<&Figures>) -> String {
    let g = &map.grid;
    let k = g.nx.max(g.ny).div_ceil(MAP_CELLS).max(1);
    let (nx, ny) = (g.nx.div_ceil(k), g.ny.div_ceil(k));
    let mut values = vec![f64::NAN; nx * ny];
    for i in 0..g.nx {
        for j in 0..g.ny {
            let v = map.at(i, j);
            let cell = &mut values[(j / k) * nx + i / k];
            if v.is_finite() && !(cell.is_finite() && *cell >= v) {
                *cell = v;
            }
        }
    }
    // The colour bar spans every node, not only the cells' highest ones.
    let (lo, hi) = map
        .h
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, &v| (a.0.min(v), a.1.max(v)));
    let cell = (g.step * k as f64, g.step * k as f64);
    let title = match figures {
        Some(f) => format!(
            "{title}: highest point {:.2} µm, Rz {:.2} µm across the feed, {:.2} µm along it",
            f.max_height * 1e3,
            f.cross_rz * 1e3,
            f.feed_rz * 1e3
        ),
        None => title.to_string(),
    };
    let mut p = Plot::new(&title, Aspect::Equal);
    p.labels("x (mm)", "y (mm)").colour_bar(bar);
    let origin = P2::new(g.x0 - cell.0 / 2.0, g.y0 - cell.1 / 2.0);
    p.raster(Raster { origin, cell, nx, ny, values });
    if lo.is_finite() {
        p.colour_range(lo, hi);
    }
    p.to_svg(900.0)
}

/// One line of a chart: its legend, points, colour slot and whether it is dashed.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Points (x, y); non-finite y are left out.
    pub pts: Vec<(f64, f64)>,
    /// Colour slot: series of one radius share it.
    pub colour: usize,
    /// Dashed (the classic figures) or solid (the simulation).
    pub dashed: bool,
}

/// A chart of series of (x, y) points with a legend.
pub fn chart(title: &str, x_label: &str, y_label: &str, series: &[Series]) -> String {
    const COLOURS: [&str; 6] = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"];
    let mut p = Plot::new(title, Aspect::Free);
    p.labels(x_label, y_label);
    p.include(P2::new(series.iter().flat_map(|s| s.pts.iter().map(|q| q.0)).fold(f64::INFINITY, f64::min), 0.0));
    for s in series {
        let pts: Vec<P2> = s.pts.iter().filter(|q| q.1.is_finite()).map(|q| P2::new(q.0, q.1)).collect();
        let colour = COLOURS[s.colour % COLOURS.len()];
        let mut style = Style::stroke(colour, if s.dashed { 1.2 } else { 1.8 }).named(&s.name);
        if s.dashed {
            style = style.dashed("6 4");
        } else {
            p.dots(&pts, 2.5, Style::fill(colour, 1.0));
        }
        p.polyline(&pts, style);
    }
    p.to_svg(800.0)
}
