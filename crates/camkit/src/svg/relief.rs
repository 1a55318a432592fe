//! The model under a 3-D plot: its top surface as a coarse grid of light grey lines along x and
//! y, each node the model's highest point on the vertical through it (a drop of a ball of
//! [`PROBE`] radius along +z), for [`super::figure::views`]'s underlay.

use super::Style;
use crate::geom::{P3, V3};
use crate::model::Model;
use crate::model::cutter::Cutter;
use crate::model::drop::{DropCutter, Unsupported};

/// Radius (mm) of the ball dropped at each node: the drawn point is within it of the node's x, y.
pub const PROBE: f64 = 1e-6;

/// Most grid nodes along each side.
pub const MAX_NODES: usize = 60;

/// The style of the grid lines (not in the legend).
pub fn style() -> Style {
    Style::stroke("#c8c8c8", 0.5)
}

/// The top of `model` over the box `lo`–`hi` (x, y) as grid lines along x and y through
/// `nodes` × `nodes` nodes (2 to [`MAX_NODES`]), broken where nothing of the model is under a
/// node; an error for surfaces the drop-cutter does not take (cones, tori, patches).
pub fn height_grid(
    model: &Model,
    lo: [f64; 2],
    hi: [f64; 2],
    nodes: usize,
) -> Result<Vec<(Vec<P3>, Style)>, Unsupported> {
    let dc = DropCutter::new(model, Cutter::Ball { radius: PROBE }, V3::z())?;
    let n = nodes.clamp(2, MAX_NODES);
    let at = |k: usize, a: f64, b: f64| a + (b - a) * k as f64 / (n - 1) as f64;
    let grid: Vec<Vec<Option<P3>>> = (0..n)
        .map(|j| {
            let y = at(j, lo[1], hi[1]);
            (0..n).map(|i| dc.drop(at(i, lo[0], hi[0]), y).map(|d| d.contact)).collect()
        })
        .collect();
    let rows = grid.iter().cloned();
    let cols = (0..n).map(|i| grid.iter().map(|row| row[i]).collect::<Vec<_>>());
    let mut lines = Vec::new();
    for line in rows.chain(cols) {
        for run in line.split(|p| p.is_none()).filter(|r| r.len() > 1) {
            lines.push((run.iter().flatten().copied().collect(), style()));
        }
    }
    Ok(lines)
}

/// [`height_grid`] of [`MAX_NODES`] over the x, y box of the finite points `over` (none without
/// any).
pub fn grid_under<'a>(
    model: &Model,
    over: impl IntoIterator<Item = &'a P3>,
) -> Result<Vec<(Vec<P3>, Style)>, Unsupported> {
    let (lo, hi) = over
        .into_iter()
        .filter(|p| p.coords.iter().all(|v| v.is_finite()))
        .fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), p| {
            ([lo[0].min(p.x), lo[1].min(p.y)], [hi[0].max(p.x), hi[1].max(p.y)])
        });
    if lo[0] > hi[0] {
        return Ok(Vec::new());
    }
    height_grid(model, lo, hi, MAX_NODES)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::analytic::Analytic;
    use crate::model::{Geometry, Surface};

    /// An R500 sphere under a 100 mm square: 60 rows and 60 columns of 60 points, every one on
    /// the sphere's top within 1e-6 mm and within the probe of its node.
    #[test]
    fn a_sphere_grid_lies_on_the_sphere() {
        let (c, r) = (P3::new(0.0, 0.0, -500.0), 500.0);
        let geometry = Geometry::Analytic(Analytic::Sphere { centre: c, radius: r });
        let model = Model { surfaces: vec![Surface::new("s".into(), geometry, None, false)] };
        let lines = height_grid(&model, [-50.0, -50.0], [50.0, 50.0], 100).unwrap();
        assert_eq!(lines.len(), 2 * MAX_NODES);
        for (pts, style) in &lines {
            assert_eq!(pts.len(), MAX_NODES);
            assert!(style.name.is_empty());
            for p in pts {
                assert!(((p - c).norm() - r).abs() < 1e-6, "{p}");
                assert!(p.z > c.z);
                let off = |v: f64| (v / (100.0 / 59.0)).round() * (100.0 / 59.0) - v;
                assert!(off(p.x + 50.0).abs() <= PROBE && off(p.y + 50.0).abs() <= PROBE, "{p}");
            }
        }
    }

    /// Lines break where the model is not under the grid: an R10.5 ball in a 100 mm square of
    /// 10 mm cells is under three nodes of the middle row and column only.
    #[test]
    fn lines_break_off_the_model() {
        let geometry = Geometry::Analytic(Analytic::Sphere { centre: P3::origin(), radius: 10.5 });
        let model = Model { surfaces: vec![Surface::new("s".into(), geometry, None, false)] };
        let lines = height_grid(&model, [-50.0, -50.0], [50.0, 50.0], 11).unwrap();
        assert_eq!(lines.len(), 2);
        for (pts, _) in &lines {
            assert_eq!(pts.len(), 3);
            assert!(pts.iter().all(|p| (p.coords.norm() - 10.5).abs() < 1e-6 && p.z > 0.0));
        }
    }
}
