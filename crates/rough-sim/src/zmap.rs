//! Beyond the paper: the surface a ball end mill leaves when it runs any toolpath table (3- or
//! 5-axis), on a z-map, with the same exact edge kinematics as the paper's patch.
//!
//! Every feed move becomes a [`Move`]: the ball centre (tip + r·axis) goes straight from row to
//! row, the axis is the mean of the two rows' axes, the spindle turns 2πN·(length/F) over it and
//! keeps turning from move to move along a pass (each pass starts with flute 1 at angle 0).
//! Arcs are cut into chords within [`ARC_CHORD`]; rapid moves do not cut.

use crate::cutter::Cutter;
use crate::kinematics::{Frame, Move, lowest_cut};
use crate::patch::{Grid, HeightMap};
use camkit::error::{Error, Location, Result};
use camkit::geom::{P3, V3};
use camkit::table::{Move as Kind, Table};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Largest distance (mm) between an arc and the chords simulated for it.
pub const ARC_CHORD: f64 = 1e-5;
/// Nodes along one side of a tile processed together.
const TILE: usize = 32;

/// The moves of a toolpath table, with the spindle at `spindle` rpm; `feed` is used where the
/// table has no `f`. More than `max_moves` (arcs chorded) is refused as bad input.
pub fn moves(
    table: &Table,
    file: &str,
    cutter: &Cutter,
    spindle: f64,
    feed: Option<f64>,
    max_moves: usize,
) -> Result<Vec<Move>> {
    let r = cutter.radius;
    let mut out = Vec::new();
    for pass in table.passes() {
        let mut theta = 0.0;
        let mut current_feed = feed;
        for w in pass.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            if let Some(f) = b.f {
                current_feed = Some(f);
            }
            if b.mv == Kind::Rapid {
                continue;
            }
            let f = current_feed.ok_or_else(|| {
                Error::input("no feed: give an f column or --feed").at(Location::file(file).line(b.line).field("f"))
            })?;
            if !(f.is_finite() && f > 0.0) {
                return Err(Error::input(format!("feed must be positive, got {f}"))
                    .at(Location::file(file).line(b.line).field("f")));
            }
            let axis_a = unit(a.axis, file, a.line)?;
            let axis_b = unit(b.axis, file, b.line)?;
            if axis_b.z <= 0.0 {
                return Err(Error::input("the tool axis must point up (k > 0) to cut from above").at(Location::file(
                    file,
                )
                .line(b.line)
                .field("k")));
            }
            let axis = (axis_a + axis_b).normalize();
            let tips = chord_points(a.pos, b, file)?;
            if out.len() + tips.len() > max_moves {
                return Err(Error::input(format!(
                    "more than {max_moves} moves (arcs chorded within {ARC_CHORD} mm) do not fit the bound of --max-memory"
                ))
                .at(Location::file(file).line(b.line)));
            }
            let mut prev = a.pos;
            for (idx, tip) in tips.iter().enumerate() {
                let len = (tip - prev).norm();
                if len <= camkit::tol::POINT_EPS {
                    prev = *tip;
                    continue;
                }
                let span = 2.0 * PI * spindle * len / f;
                // Axis interpolated along the chords of one row.
                let t0 = idx as f64 / tips.len() as f64;
                let t1 = (idx + 1) as f64 / tips.len() as f64;
                let ax0 = (axis_a * (1.0 - t0) + axis_b * t0).normalize();
                let ax1 = (axis_a * (1.0 - t1) + axis_b * t1).normalize();
                let c0 = prev + ax0 * r;
                let c1 = tip + ax1 * r;
                let frame = Frame::about(if tips.len() == 1 { axis } else { (ax0 + ax1).normalize() });
                out.push(Move { c0, dc: (c1 - c0) / span, span, phase: theta, frame });
                theta += span;
                prev = *tip;
            }
        }
    }
    Ok(out)
}

fn unit(v: V3, file: &str, line: u64) -> Result<V3> {
    let n = v.norm();
    if !(n.is_finite() && (n - 1.0).abs() <= camkit::tol::UNIT_VECTOR_SLACK) {
        return Err(Error::input(format!("tool axis ({}, {}, {}) is not a unit vector", v.x, v.y, v.z))
            .at(Location::file(file).line(line).field("i,j,k")));
    }
    Ok(v / n)
}

/// End points of the chords of the move ending at row `b` (one point for a line); an arc in its
/// plane (xy, xz or yz: the coordinate across it linear), its radius going linearly from the
/// start's to the end's.
fn chord_points(start: P3, b: &camkit::table::Row, file: &str) -> Result<Vec<P3>> {
    if !b.mv.is_arc() {
        return Ok(vec![b.pos]);
    }
    let c = b
        .centre
        .ok_or_else(|| Error::input("arc without centre").at(Location::file(file).line(b.line).field("xc,yc")))?;
    let (s, ws) = b.plane.split(&start);
    let (e, we) = b.plane.split(&b.pos);
    let (a0, a1) = ((s.y - c.y).atan2(s.x - c.x), (e.y - c.y).atan2(e.x - c.x));
    let ccw = b.mv == Kind::Ccw;
    let mut sweep = a1 - a0;
    if ccw && sweep <= 0.0 {
        sweep += 2.0 * PI;
    }
    if !ccw && sweep >= 0.0 {
        sweep -= 2.0 * PI;
    }
    let (r0, r1) = ((s - c).norm(), (e - c).norm());
    let rad = r0.max(r1);
    let step = if rad > ARC_CHORD { 2.0 * (1.0 - ARC_CHORD / rad).acos() } else { PI };
    let n = ((sweep.abs() / step).ceil() as usize).clamp(1, 100_000);
    Ok((1..=n)
        .map(|k| {
            let t = k as f64 / n as f64;
            let ang = a0 + sweep * t;
            let rr = r0 + (r1 - r0) * t;
            let q = camkit::geom::P2::new(c.x + rr * ang.cos(), c.y + rr * ang.sin());
            b.plane.join(&q, ws + (we - ws) * t)
        })
        .collect())
}

/// The area the moves can cut: the bounding box of the ball centres, grown by r.
pub fn extent(moves: &[Move], cutter: &Cutter) -> Option<(f64, f64, f64, f64)> {
    let r = cutter.radius;
    let mut b: Option<(f64, f64, f64, f64)> = None;
    for m in moves {
        for p in [m.c0, m.centre(m.span)] {
            b = Some(match b {
                None => (p.x - r, p.y - r, p.x + r, p.y + r),
                Some(q) => (q.0.min(p.x - r), q.1.min(p.y - r), q.2.max(p.x + r), q.3.max(p.y + r)),
            });
        }
    }
    b
}

/// The z-map of the moves on `grid` (absolute heights, NaN where nothing cut). Tiles run in
/// parallel; within a tile the moves are taken nearest first and dropped once their lowest
/// possible cut is above everything already cut there, so the result is the exact lower
/// envelope whatever the thread count.
pub fn simulate(cutter: &Cutter, moves: &[Move], grid: &Grid) -> HeightMap {
    let (tx, ty) = (grid.nx.div_ceil(TILE), grid.ny.div_ceil(TILE));
    let r = cutter.radius;
    let boxes: Vec<(f64, f64, f64, f64, f64)> = moves
        .iter()
        .map(|m| {
            let (a, b) = (m.c0, m.centre(m.span));
            (a.x.min(b.x), a.y.min(b.y), a.x.max(b.x), a.y.max(b.y), a.z.min(b.z))
        })
        .collect();
    let tiles: Vec<(usize, Vec<f64>)> = (0..tx * ty)
        .into_par_iter()
        .map(|t| {
            let (ti, tj) = (t % tx, t / tx);
            let (i0, j0) = (ti * TILE, tj * TILE);
            let (i1, j1) = ((i0 + TILE).min(grid.nx), (j0 + TILE).min(grid.ny));
            let (x0, x1, y0, y1) = (grid.x(i0), grid.x(i1 - 1), grid.y(j0), grid.y(j1 - 1));
            // Candidate moves with a lower bound of their cuts over the tile.
            let mut cand: Vec<(f64, usize)> = boxes
                .iter()
                .enumerate()
                .filter_map(|(k, b)| {
                    let dx = (b.0 - x1).max(x0 - b.2).max(0.0);
                    let dy = (b.1 - y1).max(y0 - b.3).max(0.0);
                    let d2 = dx * dx + dy * dy;
                    (d2 < r * r).then(|| (b.4 - (r * r - d2).sqrt(), k))
                })
                .collect();
            cand.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let (w, h) = (i1 - i0, j1 - j0);
            let mut z = vec![f64::INFINITY; w * h];
            for (bound, k) in cand {
                let top = z.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                if bound >= top {
                    break;
                }
                let mv = &moves[k];
                for jj in 0..h {
                    for ii in 0..w {
                        let (x, y) = (grid.x(i0 + ii), grid.y(j0 + jj));
                        let slot = &mut z[jj * w + ii];
                        if mv.lower_bound(cutter, x, y).is_none_or(|lb| lb >= *slot) {
                            continue;
                        }
                        if let Some(c) = lowest_cut(cutter, mv, x, y) {
                            *slot = slot.min(c.z);
                        }
                    }
                }
            }
            (t, z)
        })
        .collect();
    let mut out = vec![f64::NAN; grid.nx * grid.ny];
    for (t, z) in tiles {
        let (ti, tj) = (t % tx, t / tx);
        let (i0, j0) = (ti * TILE, tj * TILE);
        let w = (i0 + TILE).min(grid.nx) - i0;
        for (k, v) in z.into_iter().enumerate() {
            let (ii, jj) = (k % w, k / w);
            if v.is_finite() {
                out[(i0 + ii) * grid.ny + j0 + jj] = v;
            }
        }
    }
    HeightMap { grid: *grid, h: out }
}

#[cfg(test)]
mod tests {
    use super::*;
    use camkit::geom::{P2, Plane};
    use camkit::table::Row;

    /// An arc in each plane: every chord end on its circle (radius 5 about the centre, within
    /// round-off), the coordinate across the plane linear, the end reached.
    #[test]
    fn arcs_in_every_plane_become_chords_on_their_circle() {
        for (plane, end, centre) in [
            (Plane::Xy, P3::new(0.0, 10.0, -1.0), P2::new(0.0, 5.0)),
            (Plane::Xz, P3::new(0.0, 2.0, 10.0), P2::new(5.0, 0.0)),
            (Plane::Yz, P3::new(3.0, 10.0, 0.0), P2::new(5.0, 0.0)),
        ] {
            let mut b = Row::at(0, end);
            b.mv = Kind::Cw;
            b.plane = plane;
            b.centre = Some(centre);
            let start = match plane {
                Plane::Xy => P3::new(0.0, 0.0, 1.0),
                Plane::Xz => P3::new(0.0, 2.0, 0.0),
                Plane::Yz => P3::new(3.0, 0.0, 0.0),
            };
            let pts = chord_points(start, &b, "t").unwrap();
            assert!(pts.len() > 100, "{plane:?}");
            assert!((pts.last().unwrap() - end).norm() < 1e-12, "{plane:?}");
            for (k, p) in pts.iter().enumerate() {
                let (q, w) = plane.split(p);
                assert!(((q - centre).norm() - 5.0).abs() < 1e-9, "{plane:?} {p:?}");
                let (_, w0) = plane.split(&start);
                let (_, w1) = plane.split(&end);
                let t = (k + 1) as f64 / pts.len() as f64;
                assert!((w - (w0 + (w1 - w0) * t)).abs() < 1e-12, "{plane:?}");
            }
        }
    }
}
