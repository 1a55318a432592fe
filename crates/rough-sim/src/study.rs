//! One periodic cell of the paper's surface and its figures, and sweeps of them against feed
//! per tooth, tilt and spindle speed (paper 003 fig. 4b, fig. 5b, §3.2).

use crate::figures::{Figures, classic_peak, cusp_classic, cusp_exact, figures};
use crate::patch::{Conditions, Grid, HeightMap, node_source, periods, simulate, tile};

/// Heights above the classic peak by less than this (mm) are not called a remainder: the
/// solver's and grid's error stays well below it.
pub const REMAINDER_MARGIN: f64 = 1e-4;

/// The figures of one cutting condition.
#[derive(Clone, Debug, PartialEq)]
pub struct CellFigures {
    /// Classic cusp f²/8r (mm).
    pub cusp_classic: f64,
    /// Exact cusp of two spheres (mm).
    pub cusp_exact: f64,
    /// Peak of the classic surface, cusp and feed scallop added (mm).
    pub classic_peak: f64,
    /// The simulated map's figures.
    pub map: Figures,
    /// The highest point, refined around the grid's highest node by zooming (mm) and where.
    pub peak: (f64, (f64, f64)),
    /// Height of the uncut remainder: the surface's highest point if it rises above the classic
    /// peak, else 0 (mm).
    pub remainder: f64,
}

/// The grid of one periodic cell: one pick feed across the pass at x = 0, one feed per tooth
/// along it (the surface repeats with both).
pub fn cell_grid(cond: &Conditions, step: f64) -> Grid {
    Grid::covering(-cond.pick / 2.0, cond.pick / 2.0, 0.0, cond.feed_per_tooth, step)
}

/// Simulates one cell and takes its figures.
pub fn cell(cond: &Conditions, step: f64) -> (HeightMap, CellFigures) {
    let map = simulate(cond, &cell_grid(cond, step));
    let figs = cell_figures(cond, &map);
    (map, figs)
}

/// Figures of a simulated map of `cond`.
pub fn cell_figures(cond: &Conditions, map: &HeightMap) -> CellFigures {
    let r = cond.cutter.radius;
    let down_left = cond.cutter.rotation.sign() > 0.0;
    let sampling = Some((cond.pick, cond.feed_per_tooth));
    let mut f = figures(map, cond.pick, sampling, down_left);
    if let Some(period) = period_map(cond, map) {
        let p = figures(&period, cond.pick, sampling, down_left);
        (f.cross_rz, f.cross_rz_max, f.cross_rz_at, f.cross_ra) =
            (p.cross_rz, p.cross_rz_max, p.cross_rz_at, p.cross_ra);
        (f.feed_rz, f.feed_rz_max, f.feed_rz_at, f.feed_ra) = (p.feed_rz, p.feed_rz_max, p.feed_rz_at, p.feed_ra);
    }
    let classic = classic_peak(r, cond.pick, cond.feed_per_tooth);
    let peak = refine_peak(cond, f.max_height, f.max_at, map.grid.step);
    let remainder = if peak.0 > classic + REMAINDER_MARGIN { peak.0 } else { 0.0 };
    CellFigures {
        cusp_classic: cusp_classic(r, cond.pick),
        cusp_exact: cusp_exact(r, cond.pick),
        classic_peak: classic,
        map: f,
        peak,
        remainder,
    }
}

/// Most picks a cross-feed period may span for the profiles to be taken over it.
const MAX_PERIOD_PICKS: usize = 16;

/// One whole period of the surface, from `map`'s first node, when the grid fits the periods:
/// q pick feeds across (q passes shift the surface along the feed by a whole number of feeds
/// per tooth; q > 1 with a pass phase) by one feed per tooth along, end nodes included. The
/// profiles' figures are taken over it, so they do not depend on the patch's extent.
fn period_map(cond: &Conditions, map: &HeightMap) -> Option<HeightMap> {
    let (m, p, d) = periods(cond, &map.grid)?;
    if map.grid.nx < m || map.grid.ny < p {
        return None;
    }
    let q = p / gcd(d, p);
    if q > MAX_PERIOD_PICKS {
        return None;
    }
    // Start halfway between passes (x = −f/2 + k·f), as the cell does, so the sampling lengths
    // lie between the same passes whatever the patch's extent.
    let g = &map.grid;
    let i0 = ((-0.5 * cond.pick - g.x0) / g.step).round().rem_euclid(m as f64) as usize;
    let ny = p + 1;
    let wide = tile(map, (m, p, d), &Grid { nx: i0 + q * m + 1, ny, ..*g });
    Some(HeightMap { grid: Grid { x0: g.x(i0), nx: q * m + 1, ny, ..*g }, h: wide.h[i0 * ny..].to_vec() })
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// Zooms in on the neighbourhood of the grid's highest node: four rounds of 11 × 11 exact
/// evaluations, each over a span a fifth of the last, so the peak between nodes is found.
pub fn refine_peak(cond: &Conditions, h: f64, at: (f64, f64), step: f64) -> (f64, (f64, f64)) {
    let mut best = (h, at);
    let mut half = step;
    for _ in 0..4 {
        let centre = best.1;
        for i in -5..=5 {
            for j in -5..=5 {
                let (x, y) = (centre.0 + half * i as f64 / 5.0, centre.1 + half * j as f64 / 5.0);
                if let Some((v, _)) = node_source(cond, x, y) {
                    if v > best.0 {
                        best = (v, (x, y));
                    }
                }
            }
        }
        half /= 5.0;
    }
    best
}

/// The header of a figures table row.
pub const HEADER: &str = "radius,flutes,pick,feed_per_tooth,tilt_deg,pass_phase_deg,spindle_rpm,cusp_classic_um,cusp_exact_um,classic_peak_um,max_height_um,peak_um,remainder_um,cross_rz_um,cross_ra_um,feed_rz_um,feed_ra_um,down_cut_max_um,up_cut_max_um,grid_error_um";

/// One row of the figures table (µm) for `cond` (and a spindle speed if the sweep has one).
pub fn row(cond: &Conditions, spindle: Option<f64>, c: &CellFigures) -> String {
    let um = |v: f64| format!("{:.4}", v * 1e3);
    let m = &c.map;
    [
        format!("{}", cond.cutter.radius),
        format!("{}", cond.cutter.flutes),
        format!("{}", cond.pick),
        format!("{}", round(cond.feed_per_tooth)),
        format!("{}", round(cond.tilt.to_degrees())),
        format!("{}", round(cond.pass_phase.to_degrees())),
        spindle.map_or(String::new(), |n| format!("{}", round(n))),
        um(c.cusp_classic),
        um(c.cusp_exact),
        um(c.classic_peak),
        um(m.max_height),
        um(c.peak.0),
        um(c.remainder),
        um(m.cross_rz),
        um(m.cross_ra),
        um(m.feed_rz),
        um(m.feed_ra),
        um(m.down_cut_max),
        um(m.up_cut_max),
        um(m.peak_to_valley - m.peak_to_valley_half),
    ]
    .join(",")
}

/// Rounds away binary noise for printing (12 significant decimals).
fn round(v: f64) -> f64 {
    (v * 1e9).round() / 1e9
}
