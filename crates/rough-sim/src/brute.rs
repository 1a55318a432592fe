//! The independent check: edge points sampled densely by the forward kinematics (eq. 5), with
//! no root finding. No sampled point may lie below the computed surface at its own (x, y); and
//! deposited on a grid, the samples' lower envelope approaches the computed one as the angle
//! step shrinks.

use crate::patch::{Conditions, Grid, HeightMap, node_cut};
use std::f64::consts::PI;

/// Edge points of the patch's passes over [x0, x1] × [y0, y1], every `dtheta` of spindle angle
/// and every `dradial` mm from the axis up to `max_radial`; calls `visit(x, y, z)` for each.
pub fn sample(
    cond: &Conditions,
    area: (f64, f64, f64, f64),
    dtheta: f64,
    dradial: f64,
    max_radial: f64,
    mut visit: impl FnMut(f64, f64, f64),
) {
    let (x0, x1, y0, y1) = area;
    let r = cond.cutter.radius;
    let a = cond.feed_per_radian();
    let k0 = ((x0 - max_radial) / cond.pick).floor() as i64;
    let k1 = ((x1 + max_radial) / cond.pick).ceil() as i64;
    let nr = (max_radial / dradial).ceil() as usize;
    for k in k0..=k1 {
        let mv = cond.pass(k, y0, y1);
        // Spindle angles where the centre is within reach of the area.
        let t0 = ((y0 - max_radial - r * 0.0 - mv.c0.y) / a).max(0.0);
        let t1 = ((y1 + max_radial - mv.c0.y) / a).min(mv.span);
        let nt = ((t1 - t0) / dtheta).ceil() as usize;
        for it in 0..=nt {
            let theta = t0 + (t1 - t0) * it as f64 / nt.max(1) as f64;
            for n in 0..cond.cutter.flutes {
                for ir in 0..=nr {
                    let radial = max_radial * ir as f64 / nr.max(1) as f64;
                    let p = mv.edge_point(&cond.cutter, n, theta, radial);
                    if p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1 {
                        visit(p.x, p.y, p.z - cond.reference());
                    }
                }
            }
        }
    }
}

/// The most any sampled edge point lies below the computed surface at its (x, y) (mm; ≤ 0 when
/// none does), and the number of samples checked.
pub fn worst_below(
    cond: &Conditions,
    area: (f64, f64, f64, f64),
    dtheta: f64,
    dradial: f64,
    max_radial: f64,
) -> (f64, usize) {
    let mut worst = f64::NEG_INFINITY;
    let mut count = 0;
    sample(cond, area, dtheta, dradial, max_radial, |x, y, z| {
        if let Some((_, cut)) = node_cut(cond, x, y) {
            worst = worst.max(cut.z - cond.reference() - z);
            count += 1;
        }
    });
    (worst, count)
}

/// The samples deposited on `grid`: each node keeps the lowest sample within half a step of it
/// (NaN where none fell).
pub fn deposit(cond: &Conditions, grid: &Grid, dtheta: f64, dradial: f64, max_radial: f64) -> HeightMap {
    let mut h = vec![f64::NAN; grid.nx * grid.ny];
    let area = (
        grid.x0 - grid.step / 2.0,
        grid.x(grid.nx - 1) + grid.step / 2.0,
        grid.y0 - grid.step / 2.0,
        grid.y(grid.ny - 1) + grid.step / 2.0,
    );
    sample(cond, area, dtheta, dradial, max_radial, |x, y, z| {
        let i = ((x - grid.x0) / grid.step).round();
        let j = ((y - grid.y0) / grid.step).round();
        if i >= 0.0 && j >= 0.0 && (i as usize) < grid.nx && (j as usize) < grid.ny {
            let slot = &mut h[i as usize * grid.ny + j as usize];
            if !(slot.is_finite() && *slot <= z) {
                *slot = z;
            }
        }
    });
    HeightMap { grid: *grid, h }
}

/// A spindle-angle step (rad) that moves the farthest sampled point by about `spacing` mm.
pub fn angle_step(max_radial: f64, feed_per_radian: f64, spacing: f64) -> f64 {
    (spacing / (max_radial + feed_per_radian)).min(PI / 8.0)
}
