//! The independent check: edge points sampled densely by the forward kinematics (eq. 5), with
//! no root finding. No sampled point may lie below the computed surface at its own (x, y); and
//! as the angle and edge steps shrink, the samples come ever closer to the computed surface in
//! every cell of a grid ([`envelope_gaps`]): the computed surface is their lower envelope.

use crate::patch::{Conditions, Grid, HeightMap, node_cut};
use camkit::geom::P3;
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

/// A spindle-angle step (rad) that moves the farthest sampled point by about `spacing` mm.
pub fn angle_step(max_radial: f64, feed_per_radian: f64, spacing: f64) -> f64 {
    (spacing / (max_radial + feed_per_radian)).min(PI / 8.0)
}

/// A second, independent envelope: each flute's swept surface meshed in (spindle angle, radial
/// distance) with steps `dtheta` and `dradial` up to `max_radial`, every triangle's lower
/// surface rasterised onto the nodes of `grid` by linear interpolation, the lowest kept (NaN
/// where no triangle covers a node). Its error shrinks with the square of the steps, so it
/// shows the exact surface's convergence in angle step.
pub fn mesh_envelope(cond: &Conditions, grid: &Grid, dtheta: f64, dradial: f64, max_radial: f64) -> HeightMap {
    let mut h = vec![f64::INFINITY; grid.nx * grid.ny];
    let (x0, x1, y0, y1) = (grid.x0, grid.x(grid.nx - 1), grid.y0, grid.y(grid.ny - 1));
    let a = cond.feed_per_radian();
    let k0 = ((x0 - max_radial) / cond.pick).floor() as i64;
    let k1 = ((x1 + max_radial) / cond.pick).ceil() as i64;
    let nr = (max_radial / dradial).ceil() as usize;
    for k in k0..=k1 {
        let mv = cond.pass(k, y0, y1);
        let t0 = ((y0 - max_radial - mv.c0.y) / a - 2.0 * dtheta).max(0.0);
        let t1 = ((y1 + max_radial - mv.c0.y) / a + 2.0 * dtheta).min(mv.span);
        let nt = ((t1 - t0) / dtheta).ceil() as usize;
        for n in 0..cond.cutter.flutes {
            let row = |it: usize| -> Vec<P3> {
                let theta = t0 + (t1 - t0) * it as f64 / nt.max(1) as f64;
                (0..=nr).map(|ir| mv.edge_point(&cond.cutter, n, theta, max_radial * ir as f64 / nr as f64)).collect()
            };
            let mut prev = row(0);
            for it in 1..=nt {
                let cur = row(it);
                for ir in 0..nr {
                    raster(grid, &mut h, [prev[ir], prev[ir + 1], cur[ir + 1]]);
                    raster(grid, &mut h, [prev[ir], cur[ir + 1], cur[ir]]);
                }
                prev = cur;
            }
        }
    }
    let reference = cond.reference();
    let h = h.into_iter().map(|v| if v.is_finite() { v - reference } else { f64::NAN }).collect();
    HeightMap { grid: *grid, h }
}

/// Triangles whose plan area (twice, mm²) is below this are edge-on and skipped: their
/// neighbours cover the same nodes.
const DEGENERATE_AREA: f64 = 1e-18;
/// Barycentric slack so nodes on a shared triangle edge are covered by both.
const INSIDE_SLACK: f64 = 1e-12;

/// Lowers the nodes under triangle `t` to its linearly interpolated height.
fn raster(grid: &Grid, h: &mut [f64], t: [P3; 3]) {
    let [p, q, r] = t;
    let det = (q.x - p.x) * (r.y - p.y) - (r.x - p.x) * (q.y - p.y);
    if det.abs() < DEGENERATE_AREA {
        return;
    }
    let lo = |v: f64, o: f64| ((v - o) / grid.step).ceil().max(0.0) as usize;
    let hi = |v: f64, o: f64, n: usize| (((v - o) / grid.step).floor() + 1.0).clamp(0.0, n as f64) as usize;
    let (i0, i1) = (lo(p.x.min(q.x).min(r.x), grid.x0), hi(p.x.max(q.x).max(r.x), grid.x0, grid.nx));
    let (j0, j1) = (lo(p.y.min(q.y).min(r.y), grid.y0), hi(p.y.max(q.y).max(r.y), grid.y0, grid.ny));
    for i in i0..i1 {
        for j in j0..j1 {
            let (x, y) = (grid.x(i) - p.x, grid.y(j) - p.y);
            let b = (x * (r.y - p.y) - (r.x - p.x) * y) / det;
            let c = ((q.x - p.x) * y - x * (q.y - p.y)) / det;
            if b >= -INSIDE_SLACK && c >= -INSIDE_SLACK && b + c <= 1.0 + INSIDE_SLACK {
                let z = p.z + b * (q.z - p.z) + c * (r.z - p.z);
                let slot = &mut h[i * grid.ny + j];
                *slot = slot.min(z);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cutter::Cutter;
    use crate::patch::simulate;

    /// The convergence in angle step: halving the spindle-angle and edge steps of the meshed
    /// envelope brings it onto the exact surface at every node (second order), to well below
    /// the stated 0.1 µm.
    #[test]
    fn meshed_envelope_converges_onto_the_exact_surface() {
        let cond = Conditions {
            cutter: Cutter::ball(5.0, 2),
            pick: 0.5,
            feed_per_tooth: 0.5,
            tilt: 3f64.to_radians(),
            lean: -1.0,
            pass_phase: PI / 2.0,
        };
        let grid = Grid::covering(-0.25, 0.25, 0.0, 0.5, 0.025);
        let exact = simulate(&cond, &grid);
        let mut errors = Vec::new();
        for spacing in [0.02, 0.01, 0.005] {
            let dtheta = angle_step(0.8, cond.feed_per_radian(), spacing);
            let mesh = mesh_envelope(&cond, &grid, dtheta, spacing, 0.8);
            let worst = exact.h.iter().zip(&mesh.h).map(|(e, m)| (e - m).abs()).fold(0.0, f64::max);
            assert!(mesh.h.iter().all(|v| v.is_finite()), "every node covered at spacing {spacing}");
            errors.push(worst);
        }
        eprintln!("meshed envelope, largest error per spacing (mm): {errors:?}");
        assert!(errors[1] < errors[0] && errors[2] < errors[1], "{errors:?}");
        assert!(errors[2] < 1e-4, "finest error {} µm ({errors:?})", errors[2] * 1e3);
    }
}
