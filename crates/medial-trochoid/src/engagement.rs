//! Exact 2D engagement: the arc of the tool circle that lies in material left by everything cut
//! before. The material removed by a disk of radius R swept along a piece is exactly the set of
//! points closer than R to the piece, so the removed arc of the circle at `p` is a union of
//! closed-form angle sets, one per earlier piece (disks at its ends, the band along a line, the
//! annular sector along an arc). No polygon approximation: the angle is exact to round-off.

use crate::angles::{AngleSet, merge};
use camkit::contour::Seg;
use camkit::geom::{P2, V2, arc::angle_of, cross2};
use rayon::prelude::*;
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Distances below this (mm) count as the same point: a disk centred on the tool's own
/// position removes nothing from its circle.
const SAME_POINT: f64 = 1e-9;

/// Angles of the circle (centre `p`, radius `r`) closer than `r` to the disk-swept piece `s`.
pub fn removed_by(p: &P2, r: f64, s: &Seg) -> AngleSet {
    let (a, b) = (s.start(), s.end());
    let mut out = disk(p, r, &a).union(&disk(p, r, &b));
    let body = match s {
        Seg::Line(..) => {
            let d = b - a;
            let len = d.norm();
            if len <= SAME_POINT {
                return out;
            }
            let t = d / len;
            let n = V2::new(-t.y, t.x);
            let (at, an) = (angle_of(&t), angle_of(&n));
            let along = AngleSet::band((p - a).dot(&t), r, at, 0.0, len);
            along.intersect(&AngleSet::band((p - a).dot(&n), r, an, -r, r))
        }
        Seg::Arc(q) => {
            let v = p - q.c;
            let dist = v.norm();
            let (lo, hi) = ((q.r - r).max(0.0), q.r + r);
            let ring = if dist <= SAME_POINT {
                if r > lo && r < hi { AngleSet::full() } else { AngleSet::default() }
            } else {
                // |q − c|² = D² + R² + 2RD cos(θ − α).
                AngleSet::band(dist * dist + r * r, 2.0 * r * dist, angle_of(&v), lo * lo, hi * hi)
            };
            ring.intersect(&wedge(p, r, q.c, q.start.min(q.start + q.sweep), q.sweep.abs()))
        }
    };
    out = out.union(&body);
    out
}

/// Angles whose circle point is closer than `r` to `c` (open disk of radius `r`).
fn disk(p: &P2, r: f64, c: &P2) -> AngleSet {
    let d = (c - p).norm();
    if d <= SAME_POINT || d >= 2.0 * r {
        return AngleSet::default();
    }
    AngleSet::around(angle_of(&(c - p)), (d / (2.0 * r)).acos())
}

/// Angles whose circle point, seen from `c`, lies at an angle in `[a0, a0 + w]`.
fn wedge(p: &P2, r: f64, c: P2, a0: f64, w: f64) -> AngleSet {
    let v = p - c;
    let d0 = V2::new(a0.cos(), a0.sin());
    let d1 = V2::new((a0 + w).cos(), (a0 + w).sin());
    // Left of the first ray: cross(d0, v + R u) ≥ 0, i.e. cross(d0, v) + R cos(θ − a0 − π/2) ≥ 0.
    let h1 = AngleSet::band(cross2(&d0, &v), r, a0 + FRAC_PI_2, 0.0, f64::INFINITY);
    // Right of the second ray: cross(v + R u, d1) ≥ 0, i.e. cross(v, d1) + R cos(θ − a1 + π/2) ≥ 0.
    let h2 = AngleSet::band(cross2(&v, &d1), r, a0 + w - FRAC_PI_2, 0.0, f64::INFINITY);
    if w <= PI { h1.intersect(&h2) } else { h1.union(&h2) }
}

/// The cutting moves of one layer in machining order, with a grid to find the pieces near a
/// point.
pub struct Cut {
    /// Tool radius (mm).
    pub radius: f64,
    /// Swept pieces of the tool centre in order.
    pub pieces: Vec<Seg>,
    /// Bounding box of each piece.
    boxes: Vec<(P2, P2)>,
    cell: f64,
    grid: HashMap<(i64, i64), Vec<usize>>,
}

impl Cut {
    /// The cut made by sweeping a tool of `radius` along `pieces` in order.
    pub fn new(radius: f64, pieces: Vec<Seg>) -> Cut {
        let cell = 2.0 * radius;
        let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
        for (i, s) in pieces.iter().enumerate() {
            let (lo, hi) = s.bounds();
            let (x0, y0) = key(cell, &P2::new(lo.x - radius, lo.y - radius));
            let (x1, y1) = key(cell, &P2::new(hi.x + radius, hi.y + radius));
            for x in x0..=x1 {
                for y in y0..=y1 {
                    grid.entry((x, y)).or_default().push(i);
                }
            }
        }
        let boxes = pieces.iter().map(Seg::bounds).collect();
        Cut { radius, pieces, boxes, cell, grid }
    }

    /// The arcs of the tool circle at `p` removed by pieces `0..before` whose grid cells lie
    /// within the tool's reach (each piece once, in index order).
    fn removed_near(&self, p: &P2, before: usize) -> Vec<(f64, f64)> {
        let r = self.radius;
        let (x0, y0) = key(self.cell, &P2::new(p.x - r, p.y - r));
        let (x1, y1) = key(self.cell, &P2::new(p.x + r, p.y + r));
        let mut near: Vec<usize> = Vec::new();
        for x in x0..=x1 {
            for y in y0..=y1 {
                if let Some(v) = self.grid.get(&(x, y)) {
                    near.extend(v.iter().copied().filter(|&j| j < before));
                }
            }
        }
        near.sort_unstable();
        near.dedup();
        // A piece whose box is 2R or more from `p` leaves the circle alone: skip it before the
        // trigonometry (the grid's cells are 2R wide, so most of the pieces found are so).
        near.iter()
            .filter(|&&j| within_reach(&self.boxes[j], p, 2.0 * r))
            .flat_map(|&j| removed_by(p, r, &self.pieces[j]).0)
            .collect()
    }

    /// Engagement (radians) at fraction `t` of piece `i`: the part of the tool circle not
    /// removed by pieces `0..i` and by piece `i` up to `t`.
    pub fn engagement(&self, i: usize, t: f64) -> f64 {
        let r = self.radius;
        let p = self.pieces[i].point_at(t);
        let mut all = self.removed_near(&p, i);
        if t > 0.0 {
            all.extend(removed_by(&p, r, &self.pieces[i].sub(0.0, t)).0);
        }
        merge(&mut all);
        (TAU - all.iter().map(|(a, b)| b - a).sum::<f64>()).max(0.0)
    }

    /// Engagement (radians) of a tool standing at `p` after pieces `0..before`: the part of its
    /// circle in material they left.
    pub fn engagement_at(&self, p: &P2, before: usize) -> f64 {
        let mut all = self.removed_near(p, before);
        merge(&mut all);
        (TAU - all.iter().map(|(a, b)| b - a).sum::<f64>()).max(0.0)
    }

    /// Engagement (radians) at fraction `t` of `extra[k]`, pieces cut after all of `self`:
    /// the part of the tool circle not removed by `self`, `extra[..k]` and `extra[k]` up to `t`.
    pub fn engagement_after(&self, extra: &[Seg], k: usize, t: f64) -> f64 {
        let r = self.radius;
        let p = extra[k].point_at(t);
        let mut all = self.removed_near(&p, self.pieces.len());
        for e in extra[..k].iter().filter(|e| within_reach(&e.bounds(), &p, 2.0 * r)) {
            all.extend(removed_by(&p, r, e).0);
        }
        if t > 0.0 {
            all.extend(removed_by(&p, r, &extra[k].sub(0.0, t)).0);
        }
        merge(&mut all);
        (TAU - all.iter().map(|(a, b)| b - a).sum::<f64>()).max(0.0)
    }

    /// Sample positions along every piece: fractions at most `step` mm apart, the piece's end
    /// always included (corners are where engagement peaks). Returns (piece, fraction) pairs.
    pub fn samples(&self, step: f64) -> Vec<(usize, f64)> {
        let mut out = Vec::new();
        for (i, s) in self.pieces.iter().enumerate() {
            let n = (s.length() / step).ceil().max(1.0) as usize;
            out.extend((1..=n).map(|k| (i, k as f64 / n as f64)));
        }
        out
    }

    /// Engagement (degrees) at each sample, computed in parallel (the result does not depend on
    /// the thread count: each sample is independent).
    pub fn profile(&self, samples: &[(usize, f64)]) -> Vec<f64> {
        samples.par_iter().map(|&(i, t)| self.engagement(i, t).to_degrees()).collect()
    }
}

/// True if the box `(lo, hi)` comes nearer than `reach` to `p`.
fn within_reach((lo, hi): &(P2, P2), p: &P2, reach: f64) -> bool {
    let dx = (lo.x - p.x).max(p.x - hi.x).max(0.0);
    let dy = (lo.y - p.y).max(p.y - hi.y).max(0.0);
    dx * dx + dy * dy < reach * reach
}

fn key(cell: f64, p: &P2) -> (i64, i64) {
    ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(a: (f64, f64), b: (f64, f64)) -> Seg {
        Seg::Line(P2::new(a.0, a.1), P2::new(b.0, b.1))
    }

    #[test]
    fn straight_slot_is_half_the_circle() {
        let cut = Cut::new(5.0, vec![line((0.0, 0.0), (50.0, 0.0))]);
        for t in [0.2, 0.5, 1.0] {
            assert!((cut.engagement(0, t).to_degrees() - 180.0).abs() < 1e-9);
        }
    }

    #[test]
    fn side_cut_matches_arccos() {
        let r = 5.0;
        for ae in [0.5, 1.0, 2.5, 4.0, 7.5] {
            let cut = Cut::new(r, vec![line((0.0, 0.0), (60.0, 0.0)), line((0.0, ae), (60.0, ae))]);
            let e = cut.engagement(1, 0.5);
            let exact = (1.0 - ae / r).acos();
            assert!((e - exact).abs() < 1e-9, "ae {ae}: {} vs {}", e.to_degrees(), exact.to_degrees());
        }
    }

    #[test]
    fn slot_turning_a_corner() {
        // A slot along +x turning to +y: at s along the new leg, 90° + acos(1 − s/R).
        let r = 5.0;
        let cut = Cut::new(r, vec![line((-30.0, 0.0), (0.0, 0.0)), line((0.0, 0.0), (0.0, 30.0))]);
        for s in [0.5, 2.5, 4.0] {
            let e = cut.engagement(1, s / 30.0).to_degrees();
            let exact = 90.0 + (1.0 - s / r).acos().to_degrees();
            assert!((e - exact).abs() < 1e-9, "s {s}: {e} vs {exact}");
        }
    }

    #[test]
    fn arcs_remove_their_annular_sector() {
        // A slot along a half circle of radius 20 then a concentric pass 2 mm outside it.
        let r = 5.0;
        let c = P2::new(0.0, 0.0);
        let inner = Seg::from_bulge(P2::new(20.0, 0.0), P2::new(-20.0, 0.0), 1.0);
        let outer = Seg::from_bulge(P2::new(22.0, 0.0), P2::new(-22.0, 0.0), 1.0);
        let cut = Cut::new(r, vec![inner, outer]);
        let e = cut.engagement(1, 0.5);
        // Material beyond radius 25 from c, on the circle of radius 5 about (0, 22), ahead of it.
        let p = P2::new(0.0, 22.0) - c;
        let lim = 25.0_f64;
        // |p + 5u|² > 25² ⇔ 22² + 25 + 220 cos(θ − 90°) > 625
        let cosv = (lim * lim - p.norm_squared() - r * r) / (2.0 * r * p.norm());
        let half = cosv.acos();
        // The part of that arc ahead of the tool (travel is −x at the top of the circle): the
        // swept body of the current pass removes the half behind, which here is the +x half.
        let exact = half;
        assert!((e - exact).abs() < 1e-6, "{} vs {}", e.to_degrees(), exact.to_degrees());
    }
}
