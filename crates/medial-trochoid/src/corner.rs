//! Rounded inside corners of the semi-roughing passes. A tool that reaches a sharp inside corner
//! of a pass touches both walls there and has at least the corner's whole quadrant in material
//! (≥ 90° for a 90° corner), however small the step: a round tool cannot rough a sharp inside
//! corner under a 40° threshold. So every sharp left turn between two lines of a pass (climb:
//! material on the right, so a left turn is an inside corner) is replaced by a tangent arc of
//! radius ρ, and the corner's rest material is left to finishing and named ([`Rest`]).

use crate::engagement::Cut;
use camkit::contour::{Contour, Seg, Vertex};
use camkit::geom::{P2, V2, cross2};

/// Turning angles below this (radians) are not corners (collinear pieces).
const MIN_TURN: f64 = 1e-6;

/// The rest material a rounded corner of the wall pass leaves beyond the wall (or the wall
/// plus the allowance): the part of the corner between the two walls outside the swept disk
/// of radius r = R + ρ tangent to both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rest {
    /// The corner of the walls the tool is offset from (mm).
    pub corner: P2,
    /// Unit direction from the corner into the pocket (the bisector).
    pub inward: V2,
    /// Fillet radius of the pass there (mm).
    pub rho: f64,
    /// Turning angle of the pass at the corner (radians; π minus the corner's inside angle).
    pub turn: f64,
    /// Tool radius R (mm).
    pub tool: f64,
    /// Largest engagement near the corner in the fitting simulation (degrees; `None` when the
    /// radius was given).
    pub fitted_deg: Option<f64>,
}

impl Rest {
    /// Radius of the swept disk that bounds the rest (mm).
    pub fn swept(&self) -> f64 {
        self.tool + self.rho
    }

    /// Largest thickness of the rest, along the bisector (mm): r (1/cos(τ/2) − 1).
    pub fn thickness(&self) -> f64 {
        self.swept() * (1.0 / (0.5 * self.turn).cos() - 1.0)
    }

    /// Area of the rest (mm²): r² (tan(τ/2) − τ/2).
    pub fn area(&self) -> f64 {
        let r = self.swept();
        r * r * ((0.5 * self.turn).tan() - 0.5 * self.turn)
    }

    /// The rest's outline: the two wall stretches and the swept arc, as a polygon with the arc
    /// flattened to `n` chords.
    pub fn outline(&self, n: usize) -> Vec<P2> {
        let r = self.swept();
        let h = 0.5 * self.turn;
        // Centre of the swept disk on the bisector; tangent points at ±(π/2 − h) from −inward.
        let c = self.corner + self.inward * (r / h.cos());
        let back = -self.inward;
        let a0 = back.y.atan2(back.x);
        let half = std::f64::consts::FRAC_PI_2 - h;
        let mut pts = vec![self.corner];
        pts.extend((0..=n).map(|k| {
            let a = a0 - half + 2.0 * half * k as f64 / n as f64;
            c + V2::new(a.cos(), a.sin()) * r
        }));
        pts
    }
}

/// A rounded corner of a pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rounded {
    /// The sharp corner it replaces (mm).
    pub at: P2,
    /// Unit bisector pointing into the turn (towards the arc's centre).
    pub inward: V2,
    /// Turning angle (radians).
    pub turn: f64,
    /// Radius used (mm).
    pub rho: f64,
    /// Index of the arc's first vertex in the rounded contour.
    pub arc: usize,
}

/// Indices of the vertices of `c` where it turns left between two lines (inside corners).
pub fn inside_corners(c: &Contour) -> Vec<usize> {
    let n = c.vertices.len();
    if !c.closed || n < 3 {
        return Vec::new();
    }
    (0..n).filter(|&i| turn_at(c, i).is_some()).collect()
}

/// Turning angle and unit directions in and out at vertex `i` if it is a left turn between
/// two lines.
fn turn_at(c: &Contour, i: usize) -> Option<(f64, V2, V2, f64, f64)> {
    let n = c.vertices.len();
    let prev = c.vertices[(i + n - 1) % n];
    let v = c.vertices[i];
    let next = c.vertices[(i + 1) % n];
    let (din, dout) = (v.p - prev.p, next.p - v.p);
    let (lin, lout) = (din.norm(), dout.norm());
    if prev.bulge != 0.0 || v.bulge != 0.0 || lin <= 0.0 || lout <= 0.0 {
        return None;
    }
    let (tin, tout) = (din / lin, dout / lout);
    let turn = cross2(&tin, &tout).atan2(tin.dot(&tout));
    (turn > MIN_TURN).then_some((turn, tin, tout, lin, lout))
}

/// `c` with every sharp left turn between two lines replaced by a tangent arc of radius `rho`
/// (smaller where the lines are short: each line gives at most half its length to a corner).
/// Returns the contour and its rounded corners.
pub fn round_inside_corners(c: &Contour, rho: f64) -> (Contour, Vec<Rounded>) {
    round_with(c, |_| rho)
}

/// [`round_inside_corners`] with a radius per vertex (0 or less keeps the corner sharp).
pub fn round_with(c: &Contour, rho: impl Fn(usize) -> f64) -> (Contour, Vec<Rounded>) {
    let n = c.vertices.len();
    if !c.closed || n < 3 {
        return (c.clone(), Vec::new());
    }
    let mut out = Vec::with_capacity(n + 8);
    let mut corners = Vec::new();
    for i in 0..n {
        let v = c.vertices[i];
        let want = rho(i);
        let Some((turn, tin, tout, lin, lout)) = turn_at(c, i).filter(|_| want > 0.0) else {
            out.push(v);
            continue;
        };
        let tan_h = (0.5 * turn).tan();
        let t = (want * tan_h).min(0.5 * lin).min(0.5 * lout);
        let r = t / tan_h;
        let arc = out.len();
        out.push(Vertex { p: v.p - tin * t, bulge: (0.25 * turn).tan() });
        out.push(Vertex { p: v.p + tout * t, bulge: v.bulge });
        // Bisector of the corner, pointing into the turn (towards the arc's centre).
        let inward = (tout - tin).try_normalize(0.0).unwrap_or(V2::new(-tin.y, tin.x));
        corners.push(Rounded { at: v.p, inward, turn, rho: r, arc });
    }
    (Contour { vertices: out, closed: true }, corners)
}

/// `c` started at the middle of its first piece when that piece is a line leaving an inside
/// corner, so that no loop starts (with uncut material behind it) on a rounded corner.
pub fn start_mid_line(c: &Contour) -> Contour {
    let n = c.vertices.len();
    if !c.closed || n < 3 || c.vertices[0].bulge != 0.0 || turn_at(c, 0).is_none() {
        return c.clone();
    }
    let m = P2::from((c.vertices[0].p.coords + c.vertices[1].p.coords) * 0.5);
    let mut vertices = vec![Vertex { p: m, bulge: 0.0 }];
    vertices.extend_from_slice(&c.vertices[1..]);
    vertices.push(c.vertices[0]);
    Contour { vertices, closed: true }
}

/// Radii for the inside corners of the pass `c` (as [`inside_corners`] lists them), corner by
/// corner in cutting order: for each, the smallest of `candidates` (ascending, mm) whose
/// rounding keeps the simulated engagement near the corner at or under `limit_deg` (on the arc
/// `arc_margin_deg` under it: the program samples the arc at other places), the pass
/// being cut (from its start, with the corners before already rounded) after everything in
/// `before`. Each entry is the radius and the largest engagement near the corner (degrees),
/// `Err` when no candidate holds the limit (then the candidate with the lowest engagement);
/// radius 0 (the corner kept sharp) when the sharp corner already holds the limit.
/// Samples every `step` mm along the last tool radius of the incoming line and the first two
/// tool radii of the outgoing line, and every `step / 2.5` mm along the arc.
pub fn fit_corners(
    before: &Cut,
    c: &Contour,
    candidates: &[f64],
    limit_deg: f64,
    arc_margin_deg: f64,
    step: f64,
) -> Vec<Result<(f64, f64), (f64, f64)>> {
    let corners = inside_corners(c);
    let mut out: Vec<Result<(f64, f64), (f64, f64)>> = Vec::with_capacity(corners.len());
    // Corner index of each vertex (one lookup per vertex, not a search per vertex per trial).
    let mut slot = vec![None; c.vertices.len()];
    for (q, &v) in corners.iter().enumerate() {
        slot[v] = Some(q);
    }
    let fitted = |o: &Result<(f64, f64), (f64, f64)>| o.map_or_else(|e| e.0, |o| o.0);
    for (j, &vertex) in corners.iter().enumerate() {
        let mut best = (0.0, f64::INFINITY);
        let mut found = None;
        // Corners before this one kept sharp make no arc: this one's arc is the next made.
        let arcs_before = out.iter().filter(|o| fitted(o) > 0.0).count();
        // A shallow turn may hold the limit sharp: the sharp corner is simulated first (the same
        // samples: the last tool radius in, the first two out), and kept if it holds.
        let sharp = |v: usize| match slot[v] {
            Some(q) if q < j => fitted(&out[q]),
            _ => 0.0,
        };
        let (plain, _) = round_with(c, sharp);
        let at = vertex + arcs_before;
        if at >= 1 && at + 1 < plain.vertices.len() {
            let pieces: Vec<Seg> = (0..=at).map(|q| plain.seg(q)).collect();
            let (max, _) = near_corner(before, &pieces, at - 1, step);
            if max <= limit_deg {
                out.push(Ok((0.0, max)));
                continue;
            }
        }
        for &rho in candidates {
            let radius = |v: usize| match slot[v] {
                Some(q) if q < j => fitted(&out[q]),
                Some(q) if q == j => rho,
                _ => 0.0,
            };
            let (rounded, made) = round_with(c, radius);
            let Some(&Rounded { rho: used, arc: k, .. }) = made.get(arcs_before) else { break };
            let m = rounded.vertices.len();
            if k == 0 || k + 1 >= m {
                break;
            }
            let pieces: Vec<Seg> = (0..=k + 1).map(|q| rounded.seg(q)).collect();
            // Lines at the limit, the arc (sampled elsewhere by the program) at a margin under it.
            let (max, arc_max) = near_corner(before, &pieces, k - 1, step);
            if max <= limit_deg && arc_max <= limit_deg - arc_margin_deg {
                found = Some((used, max));
                break;
            }
            if max < best.1 {
                best = (used, max);
            }
        }
        out.push(found.ok_or(best));
    }
    out
}

/// Largest engagement (degrees) near a corner of the pass `pieces` (from its start to the piece
/// after the corner), and the largest on the pieces between `pieces[first]` and the last (the
/// corner's arc, if any). Samples every `step` mm along the last tool radius of `pieces[first]`
/// and the first two tool radii of the last piece, and every `step / 2.5` mm between.
fn near_corner(before: &Cut, pieces: &[Seg], first: usize, step: f64) -> (f64, f64) {
    let r = before.radius;
    let last = pieces.len() - 1;
    let (mut max, mut arc_max) = (0.0f64, 0.0f64);
    for (pk, piece) in pieces.iter().enumerate().skip(first) {
        let len = piece.length();
        let (lo, hi, h) = if pk == first {
            (((len - r) / len).max(0.0), 1.0, step)
        } else if pk == last {
            (0.0, (2.0 * r / len).min(1.0), step)
        } else {
            (0.0, 1.0, step / 2.5)
        };
        let n = ((hi - lo) * len / h).ceil().max(1.0) as usize;
        for q in 1..=n {
            let t = lo + (hi - lo) * q as f64 / n as f64;
            let e = before.engagement_after(pieces, pk, t).to_degrees();
            max = max.max(e);
            if pk != first && pk != last {
                arc_max = arc_max.max(e);
            }
        }
    }
    (max, arc_max)
}

/// Engagement (radians) of a tool of radius `r` on a circular path of radius `rho` that cuts
/// outward from a concentric cleared disk of radius `rho − s + r` (the previous pass at step
/// `s` rounded concentrically): cos φ = 1 − s/R − s/ρ + s²/(2ρR). The straight side cut is the
/// limit ρ → ∞.
pub fn concave_engagement(r: f64, rho: f64, s: f64) -> f64 {
    (1.0 - s / r - s / rho + s * s / (2.0 * rho * r)).clamp(-1.0, 1.0).acos()
}

/// The largest step `s` at which [`concave_engagement`] stays at most `phi` (radians): the smaller
/// root of s²/(2ρR) − s(1/R + 1/ρ) + 1 − cos φ = 0 (always real), in the form without
/// cancellation: the straight side cut's R(1 − cos φ) as ρ → ∞, falling to 0 with ρ.
pub fn concave_step(r: f64, rho: f64, phi: f64) -> f64 {
    let (a, b, c) = (0.5 / (rho * r), 1.0 / r + 1.0 / rho, 1.0 - phi.cos());
    2.0 * c / (b + (b * b - 4.0 * a * c).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(h: f64) -> Contour {
        Contour::polygon(
            &[P2::new(h, h), P2::new(100.0 - h, h), P2::new(100.0 - h, 100.0 - h), P2::new(h, 100.0 - h)],
            true,
        )
    }

    #[test]
    fn fillets_are_tangent_and_rest_matches_the_closed_form() {
        let (c, corners) = round_inside_corners(&square(5.0), 3.0);
        assert_eq!(c.vertices.len(), 8);
        assert_eq!(corners.len(), 4);
        for s in c.segs() {
            if let Seg::Arc(a) = s {
                assert!((a.r - 3.0).abs() < 1e-12);
                assert!((a.sweep - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
                // Centre at 5 + 3 from both walls of its corner.
                let d = a.c.x.min(100.0 - a.c.x);
                assert!((d - 8.0).abs() < 1e-12, "{:?}", a.c);
            }
        }
        // 90° corner, r = 8: thickness 8(√2 − 1), area 64(1 − π/4).
        let Rounded { at: p, inward, turn, rho, .. } = corners[0];
        let rest = Rest {
            corner: p - inward * (5.0 * std::f64::consts::SQRT_2),
            inward,
            rho,
            turn,
            tool: 5.0,
            fitted_deg: None,
        };
        assert!(rest.corner.x.abs() < 1e-12 && (rest.corner.y.abs() < 1e-12 || (rest.corner.y - 100.0).abs() < 1e-12));
        assert!((rest.thickness() - 8.0 * (2f64.sqrt() - 1.0)).abs() < 1e-12);
        assert!((rest.area() - 64.0 * (1.0 - std::f64::consts::FRAC_PI_4)).abs() < 1e-12);
        // The outline's shoelace area converges to the closed form.
        let o = rest.outline(2000);
        let shoelace: f64 = (0..o.len()).map(|k| cross2(&o[k].coords, &o[(k + 1) % o.len()].coords)).sum::<f64>() / 2.0;
        assert!((shoelace.abs() - rest.area()).abs() < 1e-4, "{shoelace} vs {}", rest.area());
    }

    #[test]
    fn short_lines_give_half_their_length() {
        let c = Contour::polygon(&[P2::new(0.0, 0.0), P2::new(2.0, 0.0), P2::new(2.0, 50.0), P2::new(0.0, 50.0)], true);
        let (_, corners) = round_inside_corners(&c, 5.0);
        for c in corners {
            assert!(c.rho <= 1.0 + 1e-12);
        }
    }

    #[test]
    fn rounded_corner_engagement_matches_the_closed_form() {
        // Two passes of a square pocket at step s, both rounded concentrically (ρ − s, then ρ):
        // on the arc of the second pass the engagement is the concave closed form.
        let (r, s) = (5.0, 1.0);
        for rho in [2.0, 4.0, 8.0] {
            let (inner, _) = round_inside_corners(&square(r + s), rho - s);
            let (outer, _) = round_inside_corners(&square(r), rho);
            let mut pieces: Vec<Seg> = inner.segs().collect();
            let first = pieces.len();
            pieces.extend(outer.segs());
            let cut = Cut::new(r, pieces.clone());
            // The second corner of the outer pass: its incoming leg is already cut.
            let arc = (first..pieces.len()).filter(|&i| matches!(pieces[i], Seg::Arc(_))).nth(1).expect("an arc");
            let exact = concave_engagement(r, rho, s);
            // Exact while the tool's forward material stays within the arc's angle (beyond
            // it the previous pass's straight leg cleared more): an upper bound after that.
            let Seg::Arc(a) = pieces[arc] else { unreachable!() };
            let lead = (r * exact.sin()).atan2(rho + r * exact.cos());
            let mut exact_seen = 0;
            for k in 1..20 {
                let t = f64::from(k) / 20.0;
                let e = cut.engagement(arc, t);
                if a.sweep * t + lead < a.sweep - 1e-9 {
                    assert!((e - exact).abs() < 1e-7, "ρ {rho} t {t}: {} vs {}", e.to_degrees(), exact.to_degrees());
                    exact_seen += 1;
                } else {
                    assert!(e <= exact + 1e-7, "ρ {rho} t {t}: {} over {}", e.to_degrees(), exact.to_degrees());
                }
            }
            assert!(exact_seen >= 3);
        }
        // The straight side cut is the limit.
        assert!((concave_engagement(5.0, 1e12, 1.0) - 0.8f64.acos()).abs() < 1e-9);
        // The step is its inverse, the side cut's step in the limit, smaller the tighter the arc.
        for rho in [0.1, 1.0, 2.5, 5.0, 20.0, 1e3] {
            for deg in [10.0f64, 40.0, 60.0] {
                let s = concave_step(5.0, rho, deg.to_radians());
                assert!((concave_engagement(5.0, rho, s) - deg.to_radians()).abs() < 1e-9, "ρ {rho} {deg}°");
                assert!(s < 5.0 * (1.0 - deg.to_radians().cos()));
            }
        }
        assert!((concave_step(5.0, 1e12, 40f64.to_radians()) - 5.0 * (1.0 - 40f64.to_radians().cos())).abs() < 1e-9);
    }
}
