//! Exact 2D engagement: the arc of the tool circle that lies in material left by everything cut
//! before. The material removed by a disk of radius R swept along a piece is exactly the set of
//! points closer than R to the piece, so the removed arc of the circle at `p` is a union of
//! closed-form angle sets, one per earlier piece (disks at its ends, the band along a line, the
//! annular sector along an arc). No polygon approximation: the angle is exact to round-off.

use crate::angles::{AngleSet, merge};
use crate::feed::Load;
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
    removed_shaped(p, r, s, &Shape::of(s))
}

/// The constants of a piece that [`removed_by`] needs at every sample: a line's direction and
/// normal with their angles, an arc's wedge rays (computed once per piece, the same values).
#[derive(Clone, Copy, Debug)]
enum Shape {
    /// A line of length `len` (over [`SAME_POINT`]) along `t`, normal `n`, at angles `at`, `an`.
    Line { len: f64, t: V2, n: V2, at: f64, an: f64 },
    /// A line no longer than [`SAME_POINT`]: its end disks only.
    Point,
    /// An arc's wedge from angle `a0` over `w`, its rays `d0`, `d1`.
    Arc { a0: f64, w: f64, d0: V2, d1: V2 },
}

impl Shape {
    fn of(s: &Seg) -> Shape {
        match s {
            Seg::Line(a, b) => {
                let d = b - a;
                let len = d.norm();
                if len <= SAME_POINT {
                    return Shape::Point;
                }
                let t = d / len;
                let n = V2::new(-t.y, t.x);
                Shape::Line { len, t, n, at: angle_of(&t), an: angle_of(&n) }
            }
            Seg::Arc(q) => {
                let (a0, w) = (q.start.min(q.start + q.sweep), q.sweep.abs());
                Shape::Arc { a0, w, d0: V2::new(a0.cos(), a0.sin()), d1: V2::new((a0 + w).cos(), (a0 + w).sin()) }
            }
        }
    }
}

/// [`removed_by`] with the piece's [`Shape`] given.
fn removed_shaped(p: &P2, r: f64, s: &Seg, shape: &Shape) -> AngleSet {
    let mut out = Vec::new();
    removed_into(p, r, s, shape, false, &mut out);
    merge(&mut out);
    AngleSet(crate::angles::Intervals::from_vec(out))
}

/// The intervals of [`removed_shaped`] appended to `out` unmerged (their merged union is the
/// same set, to the bit: merging only compares and picks ends), saving a sort and two vectors
/// per piece in [`Cut::removed`], which merges all pieces' intervals at once; `end_known`: the
/// disk at the piece's end is already in `out` (the next piece starts there), so it is left out.
fn removed_into(p: &P2, r: f64, s: &Seg, shape: &Shape, end_known: bool, out: &mut Vec<(f64, f64)>) {
    let (a, b) = (s.start(), s.end());
    out.extend(disk(p, r, &a).0);
    if !end_known {
        out.extend(disk(p, r, &b).0);
    }
    let body = match (s, shape) {
        (_, Shape::Point) => return,
        (Seg::Line(..), &Shape::Line { len, t, n, at, an }) => {
            let along = AngleSet::band((p - a).dot(&t), r, at, 0.0, len);
            along.intersect(&AngleSet::band((p - a).dot(&n), r, an, -r, r))
        }
        (Seg::Arc(q), &Shape::Arc { a0, w, d0, d1 }) => {
            let v = p - q.c;
            let dist = v.norm();
            let (lo, hi) = ((q.r - r).max(0.0), q.r + r);
            let ring = if dist <= SAME_POINT {
                if r > lo && r < hi { AngleSet::full() } else { AngleSet::default() }
            } else {
                // |q − c|² = D² + R² + 2RD cos(θ − α).
                AngleSet::band(dist * dist + r * r, 2.0 * r * dist, angle_of(&v), lo * lo, hi * hi)
            };
            ring.intersect(&wedge(p, r, q.c, a0, w, d0, d1))
        }
        _ => unreachable!("a shape is made from its own piece"),
    };
    out.extend(body.0);
}

/// Angles whose circle point is closer than `r` to `c` (open disk of radius `r`).
fn disk(p: &P2, r: f64, c: &P2) -> AngleSet {
    let d = (c - p).norm();
    if d <= SAME_POINT || d >= 2.0 * r {
        return AngleSet::default();
    }
    AngleSet::around(angle_of(&(c - p)), (d / (2.0 * r)).acos())
}

/// Angles whose circle point, seen from `c`, lies at an angle in `[a0, a0 + w]` (rays `d0`
/// and `d1` at the two ends).
fn wedge(p: &P2, r: f64, c: P2, a0: f64, w: f64, d0: V2, d1: V2) -> AngleSet {
    let v = p - c;
    // Left of the first ray: cross(d0, v + R u) ≥ 0, i.e. cross(d0, v) + R cos(θ − a0 − π/2) ≥ 0.
    let h1 = AngleSet::band(cross2(&d0, &v), r, a0 + FRAC_PI_2, 0.0, f64::INFINITY);
    // Right of the second ray: cross(v + R u, d1) ≥ 0, i.e. cross(v, d1) + R cos(θ − a1 + π/2) ≥ 0.
    let h2 = AngleSet::band(cross2(&v, &d1), r, a0 + w - FRAC_PI_2, 0.0, f64::INFINITY);
    if w <= PI { h1.intersect(&h2) } else { h1.union(&h2) }
}

/// The cutting moves of one layer in machining order, with a grid to find the pieces near a
/// point (each piece listed in the cells it runs through, not all those of its box: a wide
/// arc's box covers the pocket).
pub struct Cut {
    /// Tool radius (mm).
    pub radius: f64,
    /// Swept pieces of the tool centre in order.
    pub pieces: Vec<Seg>,
    /// Bounding box of each piece.
    boxes: Vec<(P2, P2)>,
    /// How each piece is listed in the grid.
    listed: Vec<Listed>,
    /// Constants of each piece for its angle sets.
    shapes: Vec<Shape>,
    cell: f64,
    /// Pieces (ascending) by the grid cells their boxes meet.
    grid: HashMap<(i64, i64), Vec<usize>>,
}

impl Cut {
    /// The cut made by sweeping a tool of `radius` along `pieces` in order.
    pub fn new(radius: f64, pieces: Vec<Seg>) -> Cut {
        let cell = radius;
        let boxes: Vec<(P2, P2)> = pieces.iter().map(Seg::bounds).collect();
        let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
        let mut listed = Vec::with_capacity(pieces.len());
        for (i, seg) in pieces.iter().enumerate() {
            let (cells, how) = cells_of(cell, seg);
            for c in cells {
                grid.entry(c).or_default().push(i);
            }
            listed.push(how);
        }
        let shapes = pieces.iter().map(Shape::of).collect();
        Cut { radius, pieces, boxes, listed, shapes, cell, grid }
    }

    /// Appends `seg`, cut after every piece so far (indexed at once).
    pub fn push(&mut self, seg: Seg) {
        let i = self.pieces.len();
        let (cells, how) = cells_of(self.cell, &seg);
        for c in cells {
            self.grid.entry(c).or_default().push(i);
        }
        self.listed.push(how);
        self.boxes.push(seg.bounds());
        self.shapes.push(Shape::of(&seg));
        self.pieces.push(seg);
    }

    /// Removes the last piece (the reverse of [`Cut::push`]).
    pub fn pop(&mut self) -> Option<Seg> {
        let seg = self.pieces.pop()?;
        let i = self.pieces.len();
        self.boxes.pop();
        self.shapes.pop();
        self.listed.pop();
        for c in cells_of(self.cell, &seg).0 {
            if let Some(list) = self.grid.get_mut(&c)
                && list.last() == Some(&i)
            {
                list.pop();
            }
        }
        Some(seg)
    }

    /// The part of the circle at `p` (radians) not removed by pieces `0..before` of `self`
    /// followed by `recent` (cut after them, in order).
    ///
    /// Only pieces whose box is nearer than 2R to `p` can touch the circle. They are taken in
    /// two stages, latest first: `recent` and the [`RECENT`] pieces before `before`, by index
    /// (the latest cuts, which clear most of the circle); then, from the grid, the older pieces
    /// near the arcs still in material. In both, a piece whose box is R + [`SCREEN_MARGIN`] or
    /// more from the boxes of those arcs (renewed every [`SCREEN_EVERY`] pieces taken) is skipped: it removes
    /// nothing from them, so every arc it would remove lies inside the union already taken and
    /// the merged union, hence the angle, is the same to the bit as with every piece taken.
    fn free(&self, p: &P2, before: usize, recent: &[Seg]) -> f64 {
        let all = self.removed(p, before, recent);
        (TAU - all.iter().map(|(a, b)| b - a).sum::<f64>()).max(0.0)
    }

    /// The merged angle set (radians) of the circle at `p` removed by pieces `0..before` and
    /// `recent`: the union [`Cut::free`] measures, taken as described there.
    fn removed(&self, p: &P2, before: usize, recent: &[Seg]) -> Vec<(f64, f64)> {
        let r = self.radius;
        let touches = |b: &(P2, P2)| boxes_within(b, &(*p, *p), 2.0 * r);
        let reach = r + SCREEN_MARGIN;
        let mut all: Vec<(f64, f64)> = Vec::with_capacity(32);
        let mut screen: Option<Vec<(P2, P2)>> = None;
        let mut taken = 0;
        let old = before.saturating_sub(RECENT);
        let latest = recent
            .iter()
            .rev()
            .map(|s| (s, s.bounds(), None))
            .chain((old..before).rev().map(|j| (&self.pieces[j], self.boxes[j], Some(&self.shapes[j]))));
        // Start of the piece taken last (the next in cutting order): the disk there is taken.
        let mut next_start: Option<P2> = None;
        for (s, b, shape) in latest {
            if !touches(&b) || screen.as_ref().is_some_and(|q| !q.iter().any(|q| boxes_within(&b, q, reach))) {
                next_start = None;
                continue;
            }
            let end_known = next_start == Some(s.end());
            match shape {
                Some(k) => removed_into(p, r, s, k, end_known, &mut all),
                None => removed_into(p, r, s, &Shape::of(s), end_known, &mut all),
            }
            next_start = Some(s.start());
            taken += 1;
            if taken % SCREEN_EVERY == 0 {
                merge(&mut all);
                screen = Some(material_boxes(p, r, &all));
            }
        }
        merge(&mut all);
        let mut screen = material_boxes(p, r, &all);
        if let Some((lo, hi)) = hull(&screen) {
            let (qx0, qy0) = key(self.cell, &P2::new(lo.x - reach, lo.y - reach));
            let (qx1, qy1) = key(self.cell, &P2::new(hi.x + reach, hi.y + reach));
            // Pieces listed in parts met already (each piece is taken once).
            let mut seen: Vec<usize> = Vec::new();
            'cells: for x in qx0..=qx1 {
                for y in qy0..=qy1 {
                    let Some(list) = self.grid.get(&(x, y)) else { continue };
                    for &j in list.iter().take_while(|&&j| j < old) {
                        // Each piece once: one listed by its box in the first of its cells
                        // inside the range, one listed in parts where it is met first.
                        let first = match self.listed[j] {
                            Listed::Box((fx, fy)) => (fx.max(qx0), fy.max(qy0)) == (x, y),
                            Listed::Parts => {
                                !seen.contains(&j) && {
                                    seen.push(j);
                                    true
                                }
                            }
                        };
                        let b = &self.boxes[j];
                        if !first || !touches(b) || !screen.iter().any(|q| boxes_within(b, q, reach)) {
                            continue;
                        }
                        removed_into(p, r, &self.pieces[j], &self.shapes[j], false, &mut all);
                        taken += 1;
                        if taken % SCREEN_EVERY == 0 {
                            merge(&mut all);
                            screen = material_boxes(p, r, &all);
                            if screen.is_empty() {
                                break 'cells;
                            }
                        }
                    }
                }
            }
        }
        merge(&mut all);
        all
    }

    /// Engagement (radians) at fraction `t` of piece `i`: the part of the tool circle not
    /// removed by pieces `0..i` and by piece `i` up to `t`.
    pub fn engagement(&self, i: usize, t: f64) -> f64 {
        self.on_piece(i, t, |p, own| self.free(p, i, own))
    }

    /// The arcs of the tool circle in material at fraction `t` of piece `i` (what
    /// [`Cut::engagement`] measures), as angle intervals (radians, within [0, 2π)).
    pub fn material(&self, i: usize, t: f64) -> Vec<(f64, f64)> {
        self.on_piece(i, t, |p, own| gaps(&self.removed(p, i, own)))
    }

    /// Engagement (degrees) at fraction `t` of piece `i` and the [`Load`] of its material arcs
    /// for travel along the piece there (none on a piece too short to have a direction).
    pub fn contact(&self, i: usize, t: f64) -> (f64, Load) {
        self.on_piece(i, t, |p, own| {
            let removed = self.removed(p, i, own);
            let deg = (TAU - removed.iter().map(|(a, b)| b - a).sum::<f64>()).max(0.0).to_degrees();
            let travel = self.pieces[i].tangent_at(t);
            let load =
                if travel.norm() > 0.5 { Load::of_arcs(&gaps(&removed), angle_of(&travel)) } else { Load::default() };
            (deg, load)
        })
    }

    /// `f` of the tool centre at fraction `t` of piece `i` and what that piece has cut so far.
    fn on_piece<R>(&self, i: usize, t: f64, f: impl FnOnce(&P2, &[Seg]) -> R) -> R {
        let p = self.pieces[i].point_at(t);
        let own: Vec<Seg> = if t > 0.0 { vec![self.pieces[i].sub(0.0, t)] } else { Vec::new() };
        f(&p, &own)
    }

    /// Engagement (radians) of a tool standing at `p` after pieces `0..before`: the part of its
    /// circle in material they left.
    pub fn engagement_at(&self, p: &P2, before: usize) -> f64 {
        self.free(p, before, &[])
    }

    /// Engagement (radians) at fraction `t` of `extra[k]`, pieces cut after all of `self`:
    /// the part of the tool circle not removed by `self`, `extra[..k]` and `extra[k]` up to `t`.
    pub fn engagement_after(&self, extra: &[Seg], k: usize, t: f64) -> f64 {
        let p = extra[k].point_at(t);
        let mut recent: Vec<Seg> = extra[..k].to_vec();
        if t > 0.0 {
            recent.push(extra[k].sub(0.0, t));
        }
        self.free(&p, self.pieces.len(), &recent)
    }

    /// True if the point `q` is removed: closer than R to one of the pieces (the swept disk
    /// removes exactly those points).
    pub fn removes(&self, q: &P2) -> bool {
        let (kx, ky) = key(self.cell, q);
        let r = self.radius;
        (kx - 1..=kx + 1).any(|x| {
            (ky - 1..=ky + 1).any(|y| {
                self.grid.get(&(x, y)).is_some_and(|list| {
                    list.iter()
                        .any(|&j| boxes_within(&self.boxes[j], &(*q, *q), r) && self.pieces[j].distance_to(q) < r)
                })
            })
        })
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

    /// [`Cut::contact`] at each sample, in parallel, with the first `known.len()` given (those
    /// of samples whose pieces and every piece before are the same as when they were computed:
    /// what the tool meets at a sample depends on nothing cut after it).
    pub fn contacts_from(&self, samples: &[(usize, f64)], known: &[(f64, Load)]) -> Vec<(f64, Load)> {
        let mut out = known.to_vec();
        out.par_extend(samples[known.len()..].par_iter().map(|&(i, t)| self.contact(i, t)));
        out
    }
}

/// Pieces taken by index (the latest before the sample) before the older ones are screened.
const RECENT: usize = 32;

/// Pieces taken between two screenings of the rest against the arcs still in material.
const SCREEN_EVERY: usize = 8;

/// Margin (mm) of the screen beyond the tool radius: far more than the round-off of a box, and
/// keeps a skipped piece's arcs (whose ends carry the round-off of an acos near ±1, up to about
/// 1e-8 rad) at least about √(2·margin/R) ≈ 6e-4 rad clear of the arcs in material.
const SCREEN_MARGIN: f64 = 1e-6;

/// Boxes of the arcs of the circle (centre `p`, radius `r`) outside the merged angle set
/// `removed`, each arc cut into parts of at most π/8 so that the boxes stay tight.
fn material_boxes(p: &P2, r: f64, removed: &[(f64, f64)]) -> Vec<(P2, P2)> {
    let at = |a: f64| P2::new(p.x + r * a.cos(), p.y + r * a.sin());
    let mut out = Vec::new();
    for (a, b) in gaps(removed) {
        let n = ((b - a) / (PI / 8.0)).ceil().max(1.0) as usize;
        for k in 0..n {
            let (a0, a1) = (a + (b - a) * k as f64 / n as f64, a + (b - a) * (k + 1) as f64 / n as f64);
            let (q0, q1) = (at(a0), at(a1));
            let (mut lo, mut hi) = (P2::new(q0.x.min(q1.x), q0.y.min(q1.y)), P2::new(q0.x.max(q1.x), q0.y.max(q1.y)));
            // The circle's extreme points in x and y inside the part.
            for q in 0..=4 {
                let e = f64::from(q) * FRAC_PI_2;
                if e > a0 && e < a1 {
                    let x = at(e);
                    lo = P2::new(lo.x.min(x.x), lo.y.min(x.y));
                    hi = P2::new(hi.x.max(x.x), hi.y.max(x.y));
                }
            }
            out.push((lo, hi));
        }
    }
    out
}

/// The complement in [0, 2π) of the merged angle set `removed`: the arcs still in material.
fn gaps(removed: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut from = 0.0;
    for &(a, b) in removed {
        if a > from {
            out.push((from, a));
        }
        from = from.max(b);
    }
    if from < TAU {
        out.push((from, TAU));
    }
    out
}

/// The box around all of `boxes` (`None` if there are none).
fn hull(boxes: &[(P2, P2)]) -> Option<(P2, P2)> {
    boxes
        .iter()
        .copied()
        .reduce(|a, b| (P2::new(a.0.x.min(b.0.x), a.0.y.min(b.0.y)), P2::new(a.1.x.max(b.1.x), a.1.y.max(b.1.y))))
}

/// True if the boxes `a` and `b` come nearer than `reach` to each other (a point is the box
/// `(p, p)`).
fn boxes_within(a: &(P2, P2), b: &(P2, P2), reach: f64) -> bool {
    let dx = (a.0.x - b.1.x).max(b.0.x - a.1.x).max(0.0);
    let dy = (a.0.y - b.1.y).max(b.0.y - a.1.y).max(0.0);
    dx * dx + dy * dy < reach * reach
}

/// Most parts a piece is cut into for the grid (its parts are longer than a cell past this).
const MAX_PARTS: f64 = 1e6;

/// How a piece is listed in the grid: over the cells of its box, whose low corner is the
/// cell, or (a long line across cells, a wide arc) over the cells its parts' boxes meet.
#[derive(Clone, Copy, PartialEq)]
enum Listed {
    Box((i64, i64)),
    Parts,
}

/// The grid cells (each once) where `seg` is listed, and how: those of its box, unless the
/// box holds many more cells than the piece runs through; then those of the boxes of its
/// parts, each at most `cell` long (a wide arc's box covers the pocket).
fn cells_of(cell: f64, seg: &Seg) -> (Vec<(i64, i64)>, Listed) {
    let rect = |(lo, hi): (P2, P2)| {
        let ((x0, y0), (x1, y1)) = (key(cell, &lo), key(cell, &hi));
        (x0..=x1).flat_map(move |x| (y0..=y1).map(move |y| (x, y)))
    };
    let b = seg.bounds();
    let n = (seg.length() / cell).ceil().clamp(1.0, MAX_PARTS);
    let in_box = ((b.1.x - b.0.x) / cell + 2.0) * ((b.1.y - b.0.y) / cell + 2.0);
    if in_box <= 4.0 * n + 16.0 {
        return (rect(b).collect(), Listed::Box(key(cell, &b.0)));
    }
    let n = n as usize;
    let mut out: Vec<(i64, i64)> =
        (0..n).flat_map(|k| rect(seg.sub(k as f64 / n as f64, (k + 1) as f64 / n as f64).bounds())).collect();
    out.sort_unstable();
    out.dedup();
    (out, Listed::Parts)
}

fn key(cell: f64, p: &P2) -> (i64, i64) {
    ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::Program;
    use proptest::prelude::*;

    /// The oracle: the free part of the circle at `p` after every piece of `pieces`, all taken.
    fn brute(r: f64, p: &P2, pieces: &[Seg]) -> f64 {
        let mut all: Vec<(f64, f64)> = pieces.iter().flat_map(|s| removed_by(p, r, s).0).collect();
        merge(&mut all);
        (TAU - all.iter().map(|(a, b)| b - a).sum::<f64>()).max(0.0)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

        /// The grid, the latest pieces first and the screen against the arcs still in material
        /// give the engagement of every piece taken, on random programs of lines and arcs
        /// followed by a trochoid run (dense loops: most older pieces are screened out).
        #[test]
        fn indexed_engagement_equals_every_piece_taken(
            r in 2.0f64..6.0,
            walk in proptest::collection::vec((-8.0f64..8.0, -8.0f64..8.0, -1.5f64..1.5), 4..30),
            rt in 0.5f64..3.0,
            pitch in 0.05f64..1.0,
            run in (-10.0f64..10.0, -10.0f64..10.0),
        ) {
            let mut prog = Program::default();
            let mut at = P2::new(0.0, 0.0);
            for (dx, dy, bulge) in walk {
                let to = P2::new((at.x + dx).clamp(-15.0, 15.0), (at.y + dy).clamp(-15.0, 15.0));
                if (to - at).norm() > 1e-3 {
                    let seg = if bulge.abs() < 0.3 { Seg::Line(at, to) } else { Seg::from_bulge(at, to, bulge) };
                    prog.moves.push(crate::program::Move { seg, tag: crate::program::Tag::Contour, retract_before: false });
                    at = to;
                }
            }
            crate::trochoid::push_trochoids(&mut prog, &[at, P2::new(run.0, run.1)], rt, pitch);
            let pieces: Vec<Seg> = prog.moves.iter().map(|m| m.seg).collect();
            let cut = Cut::new(r, pieces.clone());
            let samples = cut.samples(0.7);
            let fast = cut.profile(&samples);
            for (&(i, t), e) in samples.iter().zip(&fast) {
                let p = pieces[i].point_at(t);
                let mut before = pieces[..i].to_vec();
                if t > 0.0 {
                    before.push(pieces[i].sub(0.0, t));
                }
                let exact = brute(r, &p, &before).to_degrees();
                prop_assert!((e - exact).abs() <= 1e-9, "piece {i} t {t}: {e} vs {exact}");
                // The material arcs are what the engagement measures.
                let arcs: f64 = cut.material(i, t).iter().map(|(a, b)| b - a).sum();
                prop_assert!((arcs.to_degrees() - e).abs() <= 1e-9, "piece {i} t {t}: arcs {arcs} vs {e}");
                // Standing and after-the-cut forms too.
                let standing = cut.engagement_at(&p, i).to_degrees();
                prop_assert!((standing - brute(r, &p, &pieces[..i]).to_degrees()).abs() <= 1e-9);
                // The contact is the same engagement with the load of those arcs.
                let (deg, load) = cut.contact(i, t);
                prop_assert!((deg - e).abs() <= 1e-12);
                let travel = pieces[i].tangent_at(t);
                if travel.norm() > 0.5 {
                    prop_assert_eq!(load, Load::of_arcs(&cut.material(i, t), angle_of(&travel)));
                }
            }
            let extra = &pieces[pieces.len() / 2..];
            let head = Cut::new(r, pieces[..pieces.len() / 2].to_vec());
            for k in (0..extra.len()).step_by(3) {
                let p = extra[k].point_at(0.5);
                let mut before = pieces[..pieces.len() / 2 + k].to_vec();
                before.push(extra[k].sub(0.0, 0.5));
                let e = head.engagement_after(extra, k, 0.5);
                prop_assert!((e - brute(r, &p, &before)).abs() <= 1e-12, "extra {k}");
            }
        }
    }

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
            if ae < r {
                // In material: from where the first pass's band ends (sin θ = 1 − ae/R) to the
                // normal ahead of the second (θ = 90°; behind it the pass itself cut).
                let arcs = cut.material(1, 0.5);
                assert_eq!(arcs.len(), 1, "ae {ae}: {arcs:?}");
                assert!((arcs[0].0 - (1.0 - ae / r).asin()).abs() < 1e-9, "ae {ae}: {arcs:?}");
                assert!((arcs[0].1 - FRAC_PI_2).abs() < 1e-9, "ae {ae}: {arcs:?}");
                // Its load is the closed form's side cut of that angle.
                let (_, load) = cut.contact(1, 0.5);
                let side = Load::side_cut(exact.to_degrees());
                assert!((load.force - side.force).abs() < 1e-9 && (load.chip - side.chip).abs() < 1e-9, "ae {ae}");
            }
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
