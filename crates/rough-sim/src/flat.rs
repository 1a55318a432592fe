//! The flat tip of paper 003 §3.3 (eq. 6–7): the radius r0 of the flat that leaves no remainder,
//! and the shortening δ it costs; plus the smallest flat the simulation itself finds.

use crate::cutter::Cutter;
use crate::patch::{Conditions, Grid, simulate};
use std::f64::consts::PI;

/// Eq. 7 evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlatTip {
    /// r_M = (Z+2)/(4Z) · F/N (mm).
    pub r_m: f64,
    /// r_N = f / (2 sin 2πN·T_N) with T_N solved with the flat's own radius r_N in the
    /// condition F·T_N + r_N cos 2πN·T_N = r_M (mm).
    pub r_n: f64,
    /// 2πN·T_N of that solution (rad).
    pub tau_n: f64,
    /// r_N when the condition is read with the tool radius r instead (mm); NaN if it has no
    /// solution in 0 ≤ T_N ≤ 1/4N.
    pub r_n_tool_radius: f64,
    /// r0 = max(r_M, r_N) (mm).
    pub r0: f64,
    /// δ = r − √(r² − r0²) (mm).
    pub delta: f64,
}

/// Bisection for a sign change of `f` on [lo, hi].
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> Option<f64> {
    let (flo, fhi) = (f(lo), f(hi));
    if !(flo.is_finite() && fhi.is_finite()) || (flo > 0.0) == (fhi > 0.0) {
        return None;
    }
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if (f(m) > 0.0) == (flo > 0.0) {
            lo = m;
        } else {
            hi = m;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Eq. 7 for a tool of `radius` with `flutes`, pick feed `pick` and feed per revolution F/N
/// (`feed_per_rev`, mm).
pub fn eq7(radius: f64, flutes: u32, pick: f64, feed_per_rev: f64) -> FlatTip {
    let z = flutes as f64;
    let r_m = (z + 2.0) / (4.0 * z) * feed_per_rev;
    // F·T = a·τ with a = F/(2πN), τ = 2πN·T ∈ (0, π/2].
    let a = feed_per_rev / (2.0 * PI);
    let eps = 1e-12;
    let tau_n = bisect(|t| a * t + 0.5 * pick / t.tan() - r_m, eps, PI / 2.0).unwrap_or(PI / 2.0);
    let r_n = pick / (2.0 * tau_n.sin());
    let r_n_tool_radius =
        bisect(|t| a * t + radius * t.cos() - r_m, 0.0, PI / 2.0).map_or(f64::NAN, |t| pick / (2.0 * t.sin()));
    let r0 = r_m.max(r_n);
    FlatTip { r_m, r_n, tau_n, r_n_tool_radius, r0, delta: radius - (radius * radius - r0 * r0).max(0.0).sqrt() }
}

/// The smallest flat radius (to `resolution` mm) for which the simulated surface of `cond`
/// (with that flat) stays within `flat_tol` mm of the flat, on a grid of `step`: the
/// simulation's own answer to eq. 7. `None` if even r0 = r/2 leaves material.
pub fn simulated_r0(cond: &Conditions, step: f64, flat_tol: f64, resolution: f64) -> Option<f64> {
    let peak = |r0: f64| {
        let c = Conditions { cutter: Cutter { flat_radius: r0, ..cond.cutter }, ..*cond };
        let grid = Grid::covering(-cond.pick / 2.0, cond.pick / 2.0, 0.0, cond.feed_per_tooth, step);
        let map = simulate(&c, &grid);
        map.h.iter().copied().filter(|v| v.is_finite()).fold(0.0, f64::max)
    };
    let (mut lo, mut hi) = (0.0, cond.cutter.radius / 2.0);
    if peak(hi) > flat_tol {
        return None;
    }
    while hi - lo > resolution {
        let m = 0.5 * (lo + hi);
        if peak(m) > flat_tol {
            lo = m;
        } else {
            hi = m;
        }
    }
    Some(hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq7_on_the_paper_conditions() {
        // Two flutes, 0.5 mm per tooth: F/N = 1 mm, r_M = 0.5 mm.
        let t = eq7(5.0, 2, 0.5, 1.0);
        assert!((t.r_m - 0.5).abs() < 1e-12);
        // r_N solves a τ + (f/2) cot τ = r_M: check the solution satisfies the condition.
        let a = 1.0 / (2.0 * PI);
        assert!((a * t.tau_n + t.r_n * t.tau_n.cos() - t.r_m).abs() < 1e-9);
        assert!((t.r_n * 2.0 * t.tau_n.sin() - 0.5).abs() < 1e-12);
        assert!(t.r_n < t.r_m && t.r0 == t.r_m);
        assert!((t.delta - (5.0 - (25.0f64 - 0.25).sqrt())).abs() < 1e-12);
    }
}
