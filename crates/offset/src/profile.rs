//! Profile mode (paper 004 §4, fig. 6): a profile curve in a vertical plane, cut by a tool whose
//! axis points up in that plane, moving along it. The profile is the section of a surface
//! extruded across the plane, so the tool's section is exact: a ball end mill is a circle of
//! radius R, a square end mill a flat bottom of width 2R.
//!
//! - Ball: the tool centre runs on the offset of the profile by R on the tool's side (verified
//!   like every offset), the tip R below it.
//! - Square: the flat bottom is lowered onto the profile until it touches, so the tip height at
//!   `u` is the highest profile point within R of `u`. That is the upper envelope of the profile
//!   shifted by ±R, of the profile's ends and of its local maxima held flat over 2R; it is built
//!   exactly from lines and arcs and then checked against a direct window maximum.

use camkit::contour::offset::Side;
use camkit::contour::{Contour, OffsetOptions, Seg, offset_contour};
use camkit::geom::{Arc2, P2, V2, arc::angle_of};
use std::f64::consts::FRAC_PI_2;

/// Tool shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tool {
    /// Ball end mill.
    Ball,
    /// Square (flat) end mill.
    Square,
}

/// Why a profile cannot be cut from above.
#[derive(Clone, Debug, PartialEq)]
pub enum ProfileError {
    /// The profile turns back along its horizontal axis (an undercut) at this piece.
    NotMonotone(usize),
    /// The verified offset failed.
    Offset(camkit::contour::OffsetError),
    /// The square tip path failed its check (largest difference, mm).
    Check(f64),
}

/// A tip path and its proof.
#[derive(Clone, Debug, PartialEq)]
pub struct TipPath {
    /// Pieces of the tip path, left to right.
    pub pieces: Vec<Seg>,
    /// Ball: largest deviation of the centre path from distance R; square: largest difference
    /// between the tip height and the window maximum at the checked positions (mm).
    pub deviation: f64,
    /// Positions checked (square) or pieces verified (ball).
    pub checked: usize,
}

/// Height of a u-monotone piece at `u` (clamped to the piece).
fn height(s: &Seg, u: f64) -> f64 {
    match s {
        Seg::Line(a, b) => {
            if (b.x - a.x).abs() <= 0.0 {
                return a.y.max(b.y);
            }
            let t = ((u - a.x) / (b.x - a.x)).clamp(0.0, 1.0);
            a.y + t * (b.y - a.y)
        }
        Seg::Arc(a) => {
            let mid = a.point_at_fraction(0.5);
            let du = (u - a.c.x).clamp(-a.r, a.r);
            let h = (a.r * a.r - du * du).max(0.0).sqrt();
            if mid.y >= a.c.y { a.c.y + h } else { a.c.y - h }
        }
    }
}

/// Span of a piece along u.
fn span(s: &Seg) -> (f64, f64) {
    let (a, b) = (s.start().x, s.end().x);
    (a.min(b), a.max(b))
}

/// Highest and lowest profile point over `[lo, hi]`, exactly (piece ends, clipped window ends,
/// arc tops and bottoms).
pub fn window_extremes(profile: &[Seg], lo: f64, hi: f64) -> (f64, f64) {
    let (mut top, mut bottom) = (f64::NEG_INFINITY, f64::INFINITY);
    for s in profile {
        let (a, b) = span(s);
        let (l, h) = (a.max(lo), b.min(hi));
        if l > h {
            continue;
        }
        for u in [l, h] {
            let v = height(s, u);
            top = top.max(v);
            bottom = bottom.min(v);
        }
        if let Seg::Arc(arc) = s {
            for phi in [FRAC_PI_2, -FRAC_PI_2] {
                let q = arc.point_at(phi);
                if arc.spans(phi) && q.x >= l && q.x <= h {
                    top = top.max(q.y);
                    bottom = bottom.min(q.y);
                }
            }
        }
    }
    (top, bottom)
}

/// Checks that the profile runs left to right without turning back.
pub fn check_monotone(profile: &[Seg]) -> Result<(), ProfileError> {
    for (i, s) in profile.iter().enumerate() {
        let forward = s.end().x > s.start().x;
        let turns = match s {
            Seg::Line(..) => false,
            // An arc turns back along u where its tangent is vertical: at angle 0 or π inside.
            Seg::Arc(a) => [0.0, std::f64::consts::PI]
                .iter()
                .any(|&phi| a.spans(phi) && a.progress(phi) > 1e-12 && a.progress(phi) < a.sweep.abs() - 1e-12),
        };
        if !forward || turns {
            return Err(ProfileError::NotMonotone(i));
        }
    }
    Ok(())
}

/// The ball end mill's tip path: the offset of the profile by R above it, lowered by R.
pub fn ball(profile: &Contour, r: f64, opts: &OffsetOptions) -> Result<TipPath, ProfileError> {
    let off = offset_contour(profile, r, Side::Left, opts).map_err(ProfileError::Offset)?;
    let down = V2::new(0.0, -r);
    let pieces = off
        .contours
        .iter()
        .flat_map(|c| c.segs().collect::<Vec<_>>())
        .map(|s| match s {
            Seg::Line(a, b) => Seg::Line(a + down, b + down),
            Seg::Arc(a) => Seg::Arc(Arc2 { c: a.c + down, ..a }),
        })
        .collect();
    Ok(TipPath { pieces, deviation: off.check.deviation(), checked: off.check.pieces })
}

/// A candidate of the square envelope: a function of u over a domain.
#[derive(Clone, Copy, Debug)]
enum Fun {
    /// A line through `p` with `slope`.
    Line { p: P2, slope: f64 },
    /// Upper or lower half of a circle.
    Arc { c: P2, r: f64, upper: bool },
}

impl Fun {
    fn at(&self, u: f64) -> f64 {
        match *self {
            Fun::Line { p, slope } => p.y + slope * (u - p.x),
            Fun::Arc { c, r, upper } => {
                let du = (u - c.x).clamp(-r, r);
                let h = (r * r - du * du).max(0.0).sqrt();
                if upper { c.y + h } else { c.y - h }
            }
        }
    }

    /// The piece of this function over `[a, b]`.
    fn piece(&self, a: f64, b: f64) -> Seg {
        let (pa, pb) = (P2::new(a, self.at(a)), P2::new(b, self.at(b)));
        match *self {
            Fun::Line { .. } => Seg::Line(pa, pb),
            Fun::Arc { c, r, upper } => {
                // Left to right over the upper half is clockwise.
                let mut start = angle_of(&(pa - c));
                if !upper && start >= std::f64::consts::PI {
                    start -= std::f64::consts::TAU;
                }
                let end = angle_of(&(pb - c));
                let mut sweep = end - start;
                if upper && sweep > 0.0 {
                    sweep -= std::f64::consts::TAU;
                }
                if !upper && sweep < 0.0 {
                    sweep += std::f64::consts::TAU;
                }
                Seg::Arc(Arc2 { c, r, start, sweep })
            }
        }
    }

    /// u where two candidates meet (full lines and circles, filtered by the caller).
    fn meets(&self, other: &Fun) -> Vec<f64> {
        match (*self, *other) {
            (Fun::Line { p, slope }, Fun::Line { p: q, slope: s2 }) => {
                if slope == s2 {
                    return vec![];
                }
                // p.y + slope (u - p.x) = q.y + s2 (u - q.x)
                vec![(q.y - p.y + slope * p.x - s2 * q.x) / (slope - s2)]
            }
            (Fun::Line { p, slope }, Fun::Arc { c, r, .. }) | (Fun::Arc { c, r, .. }, Fun::Line { p, slope }) => {
                // (u - cx)² + (p.y + slope (u - p.x) - cy)² = r²
                let k = p.y - slope * p.x - c.y;
                let (qa, qb, qc) = (1.0 + slope * slope, 2.0 * (slope * k - c.x), c.x * c.x + k * k - r * r);
                let disc = qb * qb - 4.0 * qa * qc;
                if disc < 0.0 {
                    return vec![];
                }
                let s = disc.sqrt();
                vec![(-qb + s) / (2.0 * qa), (-qb - s) / (2.0 * qa)]
            }
            (Fun::Arc { c: c1, r: r1, .. }, Fun::Arc { c: c2, r: r2, .. }) => {
                let d = c2 - c1;
                let dist = d.norm();
                if dist == 0.0 {
                    return vec![];
                }
                let a = (r1 * r1 - r2 * r2 + dist * dist) / (2.0 * dist);
                let h2 = r1 * r1 - a * a;
                if h2 < 0.0 {
                    return vec![];
                }
                let u = d / dist;
                let base = c1 + u * a;
                let n = V2::new(-u.y, u.x) * h2.sqrt();
                vec![(base + n).x, (base - n).x]
            }
        }
    }
}

/// The candidate function of a profile piece shifted by `du` along u.
fn shifted(s: &Seg, du: f64) -> Fun {
    match s {
        Seg::Line(a, b) => {
            let slope = if b.x != a.x { (b.y - a.y) / (b.x - a.x) } else { 0.0 };
            Fun::Line { p: P2::new(a.x + du, a.y), slope }
        }
        Seg::Arc(a) => Fun::Arc { c: P2::new(a.c.x + du, a.c.y), r: a.r, upper: a.point_at_fraction(0.5).y >= a.c.y },
    }
}

/// The square end mill's tip path: the flat bottom of half-width `r` lowered onto the profile.
pub fn square(profile: &[Seg], r: f64) -> Result<TipPath, ProfileError> {
    let (u0, u1) = (profile[0].start().x, profile[profile.len() - 1].end().x);
    let flat = |v: f64| Fun::Line { p: P2::new(0.0, v), slope: 0.0 };
    // Candidates with their domains of tip position.
    let mut cands: Vec<(Fun, f64, f64)> = Vec::new();
    for s in profile {
        let (a, b) = span(s);
        cands.push((shifted(s, -r), a - r, b - r));
        cands.push((shifted(s, r), a + r, b + r));
        if let Seg::Arc(arc) = s
            && arc.spans(FRAC_PI_2)
        {
            let top = arc.point_at(FRAC_PI_2);
            cands.push((flat(top.y), top.x - r, top.x + r));
        }
    }
    for w in profile.windows(2) {
        let (a, b) = (w[0].tangent_at(1.0), w[1].tangent_at(0.0));
        if a.y >= 0.0 && b.y <= 0.0 && (a.y > 0.0 || b.y < 0.0) {
            let v = w[0].end();
            cands.push((flat(v.y), v.x - r, v.x + r));
        }
    }
    cands.push((flat(profile[0].start().y), u0, u0 + r));
    cands.push((flat(profile[profile.len() - 1].end().y), u1 - r, u1));
    let mut cuts: Vec<f64> = vec![u0, u1];
    for &(_, a, b) in &cands {
        cuts.extend([a, b].into_iter().filter(|&x| x > u0 && x < u1));
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() <= 1e-12);
    let scale = 1e-9 * (u1 - u0).abs().max(1.0);
    let mut pieces: Vec<(usize, f64, f64)> = Vec::new();
    for w in cuts.windows(2) {
        let (s, t) = (w[0], w[1]);
        let active: Vec<usize> =
            (0..cands.len()).filter(|&k| cands[k].1 <= s + scale && cands[k].2 >= t - scale).collect();
        let mut sub = vec![s, t];
        for (i, &a) in active.iter().enumerate() {
            for &b in &active[i + 1..] {
                for u in cands[a].0.meets(&cands[b].0) {
                    if u > s + scale && u < t - scale && (cands[a].0.at(u) - cands[b].0.at(u)).abs() <= 1e-7 {
                        sub.push(u);
                    }
                }
            }
        }
        sub.sort_by(f64::total_cmp);
        sub.dedup_by(|a, b| (*a - *b).abs() <= scale);
        for q in sub.windows(2) {
            let mid = 0.5 * (q[0] + q[1]);
            let best = active.iter().copied().max_by(|&a, &b| cands[a].0.at(mid).total_cmp(&cands[b].0.at(mid)));
            let Some(best) = best else { continue };
            match pieces.last_mut() {
                Some(last) if last.0 == best && (last.2 - q[0]).abs() <= scale => last.2 = q[1],
                _ => pieces.push((best, q[0], q[1])),
            }
        }
    }
    let segs: Vec<Seg> = pieces.iter().map(|&(k, a, b)| cands[k].0.piece(a, b)).collect();
    // The check: tip height against the window maximum at every piece end, every middle and
    // every r/50 along.
    let mut us: Vec<f64> = pieces.iter().flat_map(|&(_, a, b)| [a, 0.5 * (a + b), b]).collect();
    let n = ((u1 - u0) / (r / 50.0)).ceil() as usize;
    us.extend((0..=n).map(|i| u0 + (u1 - u0) * i as f64 / n as f64));
    let mut worst: f64 = 0.0;
    for &u in &us {
        let tip = pieces
            .iter()
            .find(|&&(_, a, b)| u >= a - scale && u <= b + scale)
            .map(|&(k, _, _)| cands[k].0.at(u))
            .unwrap_or(f64::NAN);
        let (top, _) = window_extremes(profile, u - r, u + r);
        let d = (tip - top).abs();
        worst = if d.is_nan() { f64::INFINITY } else { worst.max(d) };
    }
    if worst > camkit::tol::OFFSET_TOL {
        return Err(ProfileError::Check(worst));
    }
    Ok(TipPath { pieces: segs, deviation: worst, checked: us.len() })
}

/// What the unoffset square end mill does (its tip on the profile): at each checked position
/// the depth of the bottom below the highest profile point under it (a gouge when the material
/// is below) and its height above the lowest one.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Unoffset {
    /// Tip positions u (mm).
    pub u: Vec<f64>,
    /// Depth of the bottom below the highest profile point under it (mm).
    pub gouge: Vec<f64>,
    /// Height of the bottom above the lowest profile point under it (mm).
    pub lift: Vec<f64>,
    /// Stretches of u, among the positions where the whole bottom lies over the profile, where
    /// the bottom does not cut through the profile (all of it on one side, within the
    /// threshold): (from, to).
    pub clear: Vec<(f64, f64)>,
}

/// Samples the unoffset square end mill every `step` along the profile; the bottom cuts
/// through the profile where both its depth below and its height above exceed `threshold`.
pub fn unoffset_square(profile: &[Seg], r: f64, step: f64, threshold: f64) -> Unoffset {
    let (u0, u1) = (profile[0].start().x, profile[profile.len() - 1].end().x);
    let n = ((u1 - u0) / step).ceil().max(1.0) as usize;
    let mut out = Unoffset::default();
    let mut open: Option<f64> = None;
    for i in 0..=n {
        let u = u0 + (u1 - u0) * i as f64 / n as f64;
        let f = profile_height(profile, u);
        let (top, bottom) = window_extremes(profile, u - r, u + r);
        let (g, l) = ((top - f).max(0.0), (f - bottom).max(0.0));
        out.u.push(u);
        out.gouge.push(g);
        out.lift.push(l);
        // Only where the whole bottom lies over the profile can it cut through it.
        let inside = u >= u0 + r - 1e-9 && u <= u1 - r + 1e-9;
        let through = !inside || (g > threshold && l > threshold);
        match (through, open) {
            (false, None) => open = Some(u),
            (true, Some(a)) => {
                out.clear.push((a, out.u[i - 1]));
                open = None;
            }
            _ => {}
        }
    }
    if let Some(a) = open {
        out.clear.push((a, u1));
    }
    out
}

/// Height of the profile at `u` (the piece spanning it).
pub fn profile_height(profile: &[Seg], u: f64) -> f64 {
    let s = profile.iter().find(|s| u <= s.end().x).unwrap_or(&profile[profile.len() - 1]);
    height(s, u)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sine(n: usize) -> Vec<Seg> {
        let pts: Vec<P2> = (0..=n)
            .map(|i| {
                let x = 62.8 * i as f64 / n as f64;
                P2::new(x, 10.0 * (std::f64::consts::TAU * x / 62.8).sin())
            })
            .collect();
        pts.windows(2).map(|w| Seg::Line(w[0], w[1])).collect()
    }

    #[test]
    fn square_on_a_circle_top_is_flat_then_follows_the_shifted_arc() {
        // Upper half of a circle of radius 10 about the origin, left to right.
        let arc = Seg::Arc(Arc2 {
            c: P2::origin(),
            r: 10.0,
            start: std::f64::consts::PI * 0.9,
            sweep: -0.8 * std::f64::consts::PI,
        });
        let tip = square(&[arc], 1.5).unwrap();
        // Within 1.5 of the top the tip stays at 10; beyond, it is the circle shifted by 1.5.
        let at = |u: f64| tip.pieces.iter().find(|s| u >= s.start().x && u <= s.end().x).map(|s| height(s, u)).unwrap();
        assert!((at(1.0) - 10.0).abs() < 1e-12);
        let u: f64 = 5.0;
        assert!((at(u) - (100.0 - (u - 1.5).powi(2)).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn unoffset_square_on_the_sine_is_clear_only_at_the_extremes() {
        let p = sine(628);
        let un = unoffset_square(&p, 1.5, 0.01, 0.01);
        let mids: Vec<f64> = un.clear.iter().map(|(a, b)| 0.5 * (a + b)).collect();
        assert_eq!(mids.len(), 2, "{:?}", un.clear);
        assert!((mids[0] - 15.7).abs() < 0.05 && (mids[1] - 47.1).abs() < 0.05, "{mids:?}");
        let deepest = un.gouge.iter().copied().fold(0.0, f64::max);
        assert!(deepest > 1.4, "{deepest}");
    }
}
