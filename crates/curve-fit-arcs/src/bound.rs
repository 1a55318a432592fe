//! A certified lower bound on the moves of any segmentation of a run, to tell how far the
//! fewest-moves search can be from the optimum (and whether a target such as "20 % fewer than
//! ArcWelder" is reachable at all).
//!
//! Model: each output move replaces a contiguous stretch of the run and lies within `tol` of the
//! input points it replaces; joints may be anywhere along the input (not only on its points), and
//! arcs may have any radius and sweep. A *window* of consecutive points that no single line or
//! circle passes within `tol` of cannot be replaced by one move, so a joint lies strictly inside
//! it; windows that share at most an end point need distinct joints. The greedy choice of the
//! window that ends first gives the largest such family, and pieces ≥ windows + 1. A window's
//! points include its chords' midpoints: the piece passes within `tol` of its chords too.
//!
//! A window is declared impossible only when an exact test proves it for a subset of its points:
//! the minimum-width annulus of a few points, whose centre is a circumcentre of three of them or
//! the meeting point of the perpendicular bisectors of two disjoint pairs (Ebara et al. 1989), or
//! at infinity (the narrowest strip, whose direction is that of a pair).

use camkit::geom::{P2, P3, Plane, V2};
use camkit::tol::{ROUNDOFF_ABS, ROUNDOFF_REL};

/// Most points of a window handed to the exact test at first.
const SUBSET: usize = 9;
/// Most points the exact test may grow to before it leaves a window undecided (cost ~ k⁵).
const MAX_SUBSET: usize = 16;

/// The fewest moves any segmentation of `pts` (one run) can have under the model above.
pub fn min_pieces(pts: &[P3], tol: f64, planes: &[Plane]) -> usize {
    if pts.len() < 2 {
        return 0;
    }
    // Vertex i at 2i, the midpoint of chord (i, i+1) at 2i + 1: a piece replacing both ends of
    // a chord passes within tol of all of it.
    let projected: Vec<Vec<P2>> = planes
        .iter()
        .map(|pl| {
            let flat: Vec<P2> = pts.iter().map(|p| pl.split(p).0).collect();
            let mut dense = Vec::with_capacity(2 * flat.len());
            for w in flat.windows(2) {
                dense.extend([w[0], nalgebra::center(&w[0], &w[1])]);
            }
            dense.push(flat[flat.len() - 1]);
            dense
        })
        .collect();
    let mut joints = 0;
    let mut left = 0;
    // Any three points lie on a circle or a line: an impossible window has at least four
    // (two vertices and their chord's midpoint are three).
    let mut right = left + 2;
    while right < pts.len() {
        // A piece may lie in any allowed plane: the window is impossible only if it is in each.
        if projected.iter().all(|p| impossible(&p[2 * left..=2 * right], tol)) {
            joints += 1;
            left = right;
            right = left + 2;
        } else {
            right += 1;
        }
    }
    joints + 1
}

/// `true` when it is proved that no circle or line passes within `tol` of every point of `w`.
///
/// Constraint generation: the exact minimum-width annulus of a small subset is a lower bound on
/// the window's; if it is already too wide the window is impossible, if its centre holds the
/// whole window the window is possible, otherwise the points it leaves out join the subset.
fn impossible(w: &[P2], tol: f64) -> bool {
    let limit = 2.0 * tol;
    // A witness that one fits ends the question cheaply.
    let centre = fitted_centre(w);
    if let Some(c) = centre
        && Centre::At(c).spread(w).0 <= limit
    {
        return false;
    }
    let chord = w[w.len() - 1] - w[0];
    if chord.norm() > camkit::tol::LENGTH_EPS && Centre::Strip(chord).spread(w).0 <= limit {
        return false;
    }
    let margin = ROUNDOFF_ABS + ROUNDOFF_REL * scale(w);
    let mut subset = extremes(w, centre);
    loop {
        let points: Vec<P2> = subset.iter().map(|&i| w[i]).collect();
        let (width, best) = min_width(&points);
        if width > limit + margin {
            return true;
        }
        let (whole, inner, outer) = best.spread(w);
        if whole <= limit || subset.len() >= MAX_SUBSET {
            return false;
        }
        let before = subset.len();
        for i in [inner, outer] {
            if !subset.contains(&i) {
                subset.push(i);
            }
        }
        if subset.len() == before {
            return false;
        }
    }
}

/// Where the thinnest annulus of a point set is centred: a point, or infinity in a direction
/// (a strip along it).
#[derive(Clone, Copy, Debug)]
enum Centre {
    At(P2),
    Strip(V2),
}

impl Centre {
    /// Width of the thinnest annulus (or strip) about this centre holding `pts`, and the indices
    /// of the innermost and outermost points.
    fn spread(&self, pts: &[P2]) -> (f64, usize, usize) {
        // A strip's unit normal, once for all points.
        let normal = match self {
            Centre::Strip(d) => V2::new(-d.y, d.x).normalize(),
            Centre::At(_) => V2::zeros(),
        };
        let key = |p: &P2| match self {
            Centre::At(c) => (p - c).norm(),
            Centre::Strip(_) => normal.dot(&p.coords),
        };
        let (mut lo, mut hi) = ((f64::INFINITY, 0), (f64::NEG_INFINITY, 0));
        for (i, p) in pts.iter().enumerate() {
            let k = key(p);
            if k < lo.0 {
                lo = (k, i);
            }
            if k > hi.0 {
                hi = (k, i);
            }
        }
        (hi.0 - lo.0, lo.1, hi.1)
    }
}

/// Largest coordinate magnitude of `pts` (for round-off allowances).
fn scale(pts: &[P2]) -> f64 {
    pts.iter().fold(1.0f64, |m, p| m.max(p.x.abs()).max(p.y.abs()))
}

/// Centre of the algebraic (Kåsa) least-squares circle of `pts`, about their mean.
fn fitted_centre(pts: &[P2]) -> Option<P2> {
    let n = pts.len() as f64;
    let mean = pts.iter().fold(V2::zeros(), |s, p| s + p.coords) / n;
    let (mut suu, mut suv, mut svv, mut suuu, mut svvv, mut suvv, mut svuu) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for p in pts {
        let (u, v) = (p.x - mean.x, p.y - mean.y);
        suu += u * u;
        suv += u * v;
        svv += v * v;
        suuu += u * u * u;
        svvv += v * v * v;
        suvv += u * v * v;
        svuu += v * u * u;
    }
    let det = suu * svv - suv * suv;
    if det.abs() <= camkit::tol::LENGTH_EPS * (suu * svv).max(camkit::tol::LENGTH_EPS) {
        return None;
    }
    let (a, b) = (0.5 * (suuu + suvv), 0.5 * (svvv + svuu));
    let c = P2::new((a * svv - b * suv) / det, (b * suu - a * suv) / det);
    Some(c + mean)
}

/// Indices of the points of `w` that bound its width most: both ends, the middle, and the
/// three farthest out and in from the fitted circle (or on either side of the end-to-end chord).
fn extremes(w: &[P2], centre: Option<P2>) -> Vec<usize> {
    if w.len() <= SUBSET {
        return (0..w.len()).collect();
    }
    let chord = w[w.len() - 1] - w[0];
    let normal = V2::new(-chord.y, chord.x);
    let signed = |p: &P2| match centre {
        Some(c) => (p - c).norm(),
        None => normal.dot(&(p - w[0])),
    };
    let mut order: Vec<usize> = (1..w.len() - 1).collect();
    order.sort_by(|&a, &b| signed(&w[a]).total_cmp(&signed(&w[b])));
    let mut pick = vec![0, w.len() - 1, w.len() / 2];
    pick.extend(order.iter().take(3));
    pick.extend(order.iter().rev().take(3));
    pick.sort_unstable();
    pick.dedup();
    pick
}

/// The minimum width of an annulus (or strip) holding every point of `s`, and its centre.
/// Exact up to the round-off of the candidate centres: every circumcentre of three points, every
/// meeting point of two disjoint pairs' bisectors, and every strip along a pair.
fn min_width(s: &[P2]) -> (f64, Centre) {
    let k = s.len();
    let mut best = (f64::INFINITY, Centre::Strip(V2::x()));
    let mut consider = |c: Centre| {
        let w = c.spread(s).0;
        if w < best.0 {
            best = (w, c);
        }
    };
    for a in 0..k {
        for b in a + 1..k {
            let d = s[b] - s[a];
            if d.norm() > camkit::tol::LENGTH_EPS {
                consider(Centre::Strip(d));
            }
            for c in b + 1..k {
                if let Some(o) = camkit::geom::circle::circumcentre(&s[a], &s[b], &s[c]) {
                    consider(Centre::At(o));
                }
            }
        }
    }
    let pairs: Vec<(usize, usize)> = (0..k).flat_map(|a| (a + 1..k).map(move |b| (a, b))).collect();
    for (i, &(a, b)) in pairs.iter().enumerate() {
        for &(c, d) in &pairs[i + 1..] {
            if a == c || a == d || b == c || b == d {
                continue;
            }
            if let Some(o) = bisectors_meet(&s[a], &s[b], &s[c], &s[d]) {
                consider(Centre::At(o));
            }
        }
    }
    best
}

/// The point equidistant from `a` and `b` and from `c` and `d`, if the bisectors are not parallel.
fn bisectors_meet(a: &P2, b: &P2, c: &P2, d: &P2) -> Option<P2> {
    // |x − a|² = |x − b|²  ⇔  2 (b − a)·x = |b|² − |a|², likewise for c, d.
    let (u, v) = (b - a, d - c);
    let (r1, r2) = (
        0.5 * (b.coords.norm_squared() - a.coords.norm_squared()),
        0.5 * (d.coords.norm_squared() - c.coords.norm_squared()),
    );
    let det = u.x * v.y - u.y * v.x;
    if det.abs() <= camkit::tol::LENGTH_EPS * u.norm() * v.norm() {
        return None;
    }
    Some(P2::new((r1 * v.y - r2 * u.y) / det, (u.x * r2 - v.x * r1) / det))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Minimum annulus width of `s` by brute force: a grid search over centres refined by
    /// pattern search, plus every strip direction on a fine fan (an independent method).
    fn brute_width(s: &[P2]) -> f64 {
        let mut best = f64::INFINITY;
        for i in 0..3600 {
            let t = i as f64 * std::f64::consts::PI / 3600.0;
            best = best.min(Centre::Strip(V2::new(t.cos(), t.sin())).spread(s).0);
        }
        let lo = s.iter().fold(P2::new(f64::INFINITY, f64::INFINITY), |m, p| P2::new(m.x.min(p.x), m.y.min(p.y)));
        let hi =
            s.iter().fold(P2::new(f64::NEG_INFINITY, f64::NEG_INFINITY), |m, p| P2::new(m.x.max(p.x), m.y.max(p.y)));
        let span = (hi - lo).norm().max(1.0);
        for i in -20..=20 {
            for j in -20..=20 {
                let mut c = P2::new(lo.x + (i as f64) * span / 4.0, lo.y + (j as f64) * span / 4.0);
                let mut w = Centre::At(c).spread(s).0;
                let mut step = span / 4.0;
                while step > 1e-9 {
                    let mut moved = false;
                    for (dx, dy) in [
                        (1.0, 0.0),
                        (-1.0, 0.0),
                        (0.0, 1.0),
                        (0.0, -1.0),
                        (0.6, 0.8),
                        (-0.8, 0.6),
                        (-0.6, -0.8),
                        (0.8, -0.6),
                    ] {
                        let q = P2::new(c.x + dx * step, c.y + dy * step);
                        let wq = Centre::At(q).spread(s).0;
                        if wq < w {
                            (c, w, moved) = (q, wq, true);
                        }
                    }
                    if !moved {
                        step *= 0.5;
                    }
                }
                best = best.min(w);
            }
        }
        best
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// The candidate centres find the minimum-width annulus: never wider than what a brute
        /// search finds (which would make the bound claim too much). (Never narrower than the
        /// minimum either: each candidate is a real centre.)
        #[test]
        fn exact_width_matches_brute_force(xy in proptest::collection::vec((-5.0f64..5.0, -5.0f64..5.0), 4..7)) {
            let s: Vec<P2> = xy.iter().map(|&(x, y)| P2::new(x, y)).collect();
            let exact = min_width(&s).0;
            let brute = brute_width(&s);
            prop_assert!(exact <= brute + 1e-6, "exact {exact} brute {brute}");
        }

        /// The bound never exceeds what the fewest-moves search achieves on noisy smooth curves.
        #[test]
        fn bound_below_the_search(r in 5.0f64..50.0, sweep in 1.0f64..6.0, noise in proptest::collection::vec(-1.0f64..1.0, 200)) {
            let tol = 0.01;
            let pts: Vec<P3> = noise.iter().enumerate().map(|(i, e)| {
                let t = sweep * i as f64 / 200.0;
                let rr = r * (1.0 + 0.3 * t.sin()) + 0.9 * tol * e;
                P3::new(rr * t.cos(), rr * t.sin(), 0.0)
            }).collect();
            let opts = crate::Options { tol, ..crate::Options::default() };
            let pieces = crate::segment::segment(&pts, &opts, &crate::fit::Exact).unwrap();
            prop_assert!(min_pieces(&pts, tol, &[Plane::Xy]) <= pieces.len());
        }
    }

    /// Points on one circle and on one line: a single piece, whatever the window.
    #[test]
    fn one_circle_or_line_is_one_piece() {
        let arc: Vec<P3> = (0..500)
            .map(|i| {
                let t = i as f64 * 0.01;
                P3::new(3.0 + 20.0 * t.cos(), -1.0 + 20.0 * t.sin(), 0.0)
            })
            .collect();
        assert_eq!(min_pieces(&arc, 0.001, &[Plane::Xy]), 1);
        let line: Vec<P3> = (0..500).map(|i| P3::new(i as f64 * 0.1, 0.5 * i as f64 * 0.1, 2.0)).collect();
        assert_eq!(min_pieces(&line, 0.001, &[Plane::Xy]), 1);
    }

    /// A zigzag of n teeth, each tooth far wider than tol: every corner needs a joint, and the
    /// bound finds them all (the greedy windows share their end points at corners).
    #[test]
    fn zigzag_needs_a_piece_per_leg() {
        let teeth = 12;
        let mut pts = Vec::new();
        for k in 0..=teeth {
            // Four points per leg so each window has a corner in it.
            let y = if k % 2 == 0 { 0.0 } else { 5.0 };
            let y_next = if k % 2 == 0 { 5.0 } else { 0.0 };
            for j in 0..4 {
                let f = j as f64 / 4.0;
                pts.push(P3::new((k as f64 + f) * 5.0, y + (y_next - y) * f, 0.0));
            }
        }
        let legs = teeth + 1;
        let bound = min_pieces(&pts, 0.01, &[Plane::Xy]);
        // Windows reach from one corner to just past the next: at least one joint per two legs.
        assert!(bound >= legs / 2 && bound <= legs, "bound {bound}, legs {legs}");
    }

    /// Two arcs of different radii joined tangentially: two pieces, proved.
    #[test]
    fn two_radii_need_two_pieces() {
        let mut pts: Vec<P3> = (0..=100)
            .map(|i| {
                let t = std::f64::consts::PI * i as f64 / 100.0;
                P3::new(10.0 * t.cos(), 10.0 * t.sin(), 0.0)
            })
            .collect();
        // Continue tangentially at (−10, 0) going down, on a circle of radius 5 centred (−5, 0).
        pts.extend((1..=100).map(|i| {
            let t = std::f64::consts::PI * (1.0 + i as f64 / 100.0);
            P3::new(-5.0 + 5.0 * t.cos(), 5.0 * t.sin(), 0.0)
        }));
        assert_eq!(min_pieces(&pts, 0.01, &[Plane::Xy]), 2);
    }
}
