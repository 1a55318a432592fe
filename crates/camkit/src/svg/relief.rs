//! The model under a 3-D plot: its top surface as a coarse grid of light grey lines along x and
//! y, each node the model's highest point on the vertical through it (a drop of a ball of
//! [`PROBE`] radius along +z; for surfaces the drop-cutter does not take, the point of the
//! surface on the vertical that nearest-point queries from above settle on), for
//! [`super::figure::views`]'s underlay.

use super::Style;
use crate::geom::{P3, V3};
use crate::model::Model;
use crate::model::cutter::Cutter;
use crate::model::drop::DropCutter;

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
/// node or its top is above `ceiling`.
pub fn height_grid(model: &Model, lo: [f64; 2], hi: [f64; 2], nodes: usize, ceiling: f64) -> Vec<(Vec<P3>, Style)> {
    let dc = DropCutter::closed_forms(model, Cutter::Ball { radius: PROBE }, V3::z()).ok();
    let top = model.bounds().max.z;
    let top = if top.is_finite() { top } else { 0.0 };
    let n = nodes.clamp(2, MAX_NODES);
    let at = |k: usize, a: f64, b: f64| a + (b - a) * k as f64 / (n - 1) as f64;
    let grid: Vec<Vec<Option<P3>>> = (0..n)
        .map(|j| {
            let y = at(j, lo[1], hi[1]);
            (0..n)
                .map(|i| {
                    let x = at(i, lo[0], hi[0]);
                    let p = dc.as_ref().map_or_else(|| settle(model, x, y, top), |dc| dc.drop(x, y).map(|d| d.contact));
                    p.filter(|p| p.z <= ceiling)
                })
                .collect()
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
    lines
}

/// The point of `model` on the vertical through (`x`, `y`) that nearest-point queries settle on
/// from height `top` (each moving the query to the foot's tangent plane), or `None` where they
/// do not (off the model, or a wall).
fn settle(model: &Model, x: f64, y: f64, top: f64) -> Option<P3> {
    let mut z = top;
    for _ in 0..30 {
        let f = model.nearest(&P3::new(x, y, z));
        let (dx, dy) = (x - f.point.x, y - f.point.y);
        if dx.hypot(dy) <= PROBE {
            return f.converged.then_some(f.point);
        }
        if f.normal.z.abs() < 0.05 {
            return None;
        }
        z = f.point.z - (f.normal.x * dx + f.normal.y * dy) / f.normal.z;
    }
    None
}

/// [`height_grid`] of [`MAX_NODES`] over the x, y box of the finite points `over` (none without
/// any), up to a tenth of the box's width above their highest: the model under the paths, not
/// the tops of whole surfaces of which the paths follow a concave piece.
pub fn grid_under<'a>(model: &Model, over: impl IntoIterator<Item = &'a P3>) -> Vec<(Vec<P3>, Style)> {
    let (lo, hi) = over.into_iter().filter(|p| p.coords.iter().all(|v| v.is_finite())).fold(
        (
            P3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
            P3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    if lo.x > hi.x {
        return Vec::new();
    }
    let ceiling = hi.z + 0.1 * (hi.x - lo.x).max(hi.y - lo.y);
    height_grid(model, [lo.x, lo.y], [hi.x, hi.y], MAX_NODES, ceiling)
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
        let lines = height_grid(&model, [-50.0, -50.0], [50.0, 50.0], 100, f64::INFINITY);
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
        let low = height_grid(&model, [-50.0, -50.0], [50.0, 50.0], 100, -1.0);
        assert!(!low.is_empty() && low.iter().flat_map(|l| l.0.iter()).all(|p| p.z <= -1.0));
    }

    /// Lines break where the model is not under the grid: an R10.5 ball in a 100 mm square of
    /// 10 mm cells is under three nodes of the middle row and column only.
    #[test]
    fn lines_break_off_the_model() {
        let geometry = Geometry::Analytic(Analytic::Sphere { centre: P3::origin(), radius: 10.5 });
        let model = Model { surfaces: vec![Surface::new("s".into(), geometry, None, false)] };
        let lines = height_grid(&model, [-50.0, -50.0], [50.0, 50.0], 11, f64::INFINITY);
        assert_eq!(lines.len(), 2);
        for (pts, _) in &lines {
            assert_eq!(pts.len(), 3);
            assert!(pts.iter().all(|p| (p.coords.norm() - 10.5).abs() < 1e-6 && p.z > 0.0));
        }
    }

    /// A torus (which the drop-cutter does not take) of tube 2 around a circle of radius 10:
    /// the nodes over the tube settle on its top within 1e-6 mm, the hole and the outside are
    /// left out.
    #[test]
    fn a_torus_grid_settles_on_its_top() {
        let geometry =
            Geometry::Analytic(Analytic::Torus { centre: P3::origin(), axis: V3::z(), major: 10.0, minor: 2.0 });
        let model = Model { surfaces: vec![Surface::new("t".into(), geometry, None, false)] };
        let lines = height_grid(&model, [-15.0, -15.0], [15.0, 15.0], 31, f64::INFINITY);
        let pts: Vec<&P3> = lines.iter().flat_map(|l| l.0.iter()).collect();
        assert!(pts.len() > 100, "{} points", pts.len());
        for p in pts {
            let rho = p.x.hypot(p.y);
            assert!((8.0..=12.0).contains(&rho), "{p}");
            assert!((p.z - (4.0 - (rho - 10.0).powi(2)).sqrt()).abs() < 1e-6, "{p}");
        }
    }
}
