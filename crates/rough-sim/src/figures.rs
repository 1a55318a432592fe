//! Roughness figures of a height map: peak-to-valley height, profiles across and along the
//! feed with Rz and Ra (ISO 4287 / ISO 21920-2 definitions on the unfiltered profile: for the
//! paper's periodic surface the sampling length is one period and the mean line the profile's
//! mean; for a z-map of any toolpath the primary profile's least-squares line), both sides of
//! the pass told apart, and the classic figures they are compared with.

use crate::patch::HeightMap;

/// Nodes closer than this (mm) to a pass's centre line belong to neither side of it.
const ON_PASS: f64 = 1e-12;

/// The classic cusp height between passes, f²/8r (mm).
pub fn cusp_classic(radius: f64, pick: f64) -> f64 {
    pick * pick / (8.0 * radius)
}

/// The exact cusp of two spheres f apart, r − √(r² − f²/4) (mm).
pub fn cusp_exact(radius: f64, pick: f64) -> f64 {
    radius - (radius * radius - pick * pick / 4.0).sqrt()
}

/// The classic surface of the ball stamped once per tooth: cusp and feed scallop added, the
/// peak of four spheres on an f × fz lattice, r − √(r² − f²/4 − fz²/4) (mm).
pub fn classic_peak(radius: f64, pick: f64, feed_per_tooth: f64) -> f64 {
    radius - (radius * radius - pick * pick / 4.0 - feed_per_tooth * feed_per_tooth / 4.0).sqrt()
}

/// Rz and Ra of one profile of equally spaced heights (NaN entries skipped).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Profile {
    /// Rz (mm): the mean over the sampling lengths of the peak-to-valley height within each.
    pub rz: f64,
    /// Ra (mm): the mean absolute deviation from the mean line over the evaluation length.
    pub ra: f64,
}

/// Nodes within this fraction of a step of a sampling length's end belong to it.
const END_SLACK: f64 = 1e-6;

/// Rz and Ra of a periodic profile (ISO 4287 / ISO 21920-2 definitions, no λc filter): heights
/// `h` every `step` mm, the sampling length `period` mm: the profile's period (the feed per
/// tooth along a pass; across the passes the pick feed, the spacing of the cusps, which is the
/// whole period unless a pass phase shifts neighbouring passes along the feed). The evaluation
/// length is the whole sampling lengths the profile holds; the mean line is the profile's mean
/// over them (the integral by the trapezoidal rule), not a line fitted through them, so a
/// periodic profile starting anywhere in its period gives the same figures. A profile shorter
/// than one sampling length (or `period` not finite) is one sampling length of its own length.
/// `None` with fewer than two valid points.
pub fn profile(h: &[f64], step: f64, period: f64) -> Option<Profile> {
    if h.iter().filter(|v| v.is_finite()).count() < 2 {
        return None;
    }
    let span = (h.len() - 1) as f64 * step;
    let per = period / step;
    let whole = if period.is_finite() && period > 0.0 { (span / period + END_SLACK).floor() } else { 0.0 };
    // Sampling lengths as inclusive node ranges.
    let ranges: Vec<(usize, usize)> = if whole >= 1.0 {
        (0..whole as usize)
            .map(|i| {
                let lo = ((i as f64 * per - END_SLACK).ceil().max(0.0)) as usize;
                let hi = (((i + 1) as f64 * per + END_SLACK).floor() as usize).min(h.len() - 1);
                (lo, hi)
            })
            .collect()
    } else {
        vec![(0, h.len() - 1)]
    };
    let last = ranges.last().map_or(0, |r| r.1);
    let eval = &h[..=last];
    let mean = trapezoid(eval, |v| v)?;
    let ra = trapezoid(eval, |v| (v - mean).abs())?;
    let heights: Vec<f64> = ranges
        .iter()
        .filter_map(|&(lo, hi)| {
            let (top, bottom) = h[lo..=hi]
                .iter()
                .filter(|v| v.is_finite())
                .fold((f64::NEG_INFINITY, f64::INFINITY), |a, &v| (a.0.max(v), a.1.min(v)));
            (top >= bottom).then_some(top - bottom)
        })
        .collect();
    let rz = heights.iter().sum::<f64>() / heights.len().max(1) as f64;
    Some(Profile { rz, ra })
}

/// The mean of `f(h)` over a profile by the trapezoidal rule on the intervals whose two ends
/// are valid; `None` if there is none.
fn trapezoid(h: &[f64], f: impl Fn(f64) -> f64) -> Option<f64> {
    let (mut sum, mut n) = (0.0, 0usize);
    for w in h.windows(2) {
        if w[0].is_finite() && w[1].is_finite() {
            sum += 0.5 * (f(w[0]) + f(w[1]));
            n += 1;
        }
    }
    (n > 0).then(|| sum / n as f64)
}

/// Rz and Ra of a profile with no known period: the primary profile's Pt and Pa about its
/// least-squares line, the whole profile one sampling length (the z-map of any toolpath);
/// `None` with fewer than two valid points.
pub fn primary_profile(h: &[f64]) -> Option<Profile> {
    let pts: Vec<(f64, f64)> =
        h.iter().enumerate().filter(|(_, v)| v.is_finite()).map(|(i, v)| (i as f64, *v)).collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mt, mh) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let stt: f64 = pts.iter().map(|p| (p.0 - mt).powi(2)).sum();
    let sth: f64 = pts.iter().map(|p| (p.0 - mt) * (p.1 - mh)).sum();
    let slope = if stt > 0.0 { sth / stt } else { 0.0 };
    let dev = |p: &(f64, f64)| p.1 - mh - slope * (p.0 - mt);
    let (mut hi, mut lo, mut sum) = (f64::NEG_INFINITY, f64::INFINITY, 0.0);
    for p in &pts {
        let e = dev(p);
        hi = hi.max(e);
        lo = lo.min(e);
        sum += e.abs();
    }
    Some(Profile { rz: hi - lo, ra: sum / n })
}

/// Figures of a patch's height map.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Figures {
    /// Highest point above the nominal surface (mm).
    pub max_height: f64,
    /// Where it is (x, y).
    pub max_at: (f64, f64),
    /// Lowest point (mm).
    pub min_height: f64,
    /// Peak to valley over the map (mm).
    pub peak_to_valley: f64,
    /// The same on the grid of every other node: the difference estimates the grid error (mm).
    pub peak_to_valley_half: f64,
    /// Rz of the cross-feed profiles (rows, mm): the mean over every sampling length of every
    /// row (the rows weighted by the trapezoidal rule over a periodic map, else alike).
    pub cross_rz: f64,
    /// The largest Rz of one row (mm).
    pub cross_rz_max: f64,
    /// y of that row (mm).
    pub cross_rz_at: f64,
    /// Mean Ra of the cross-feed profiles, weighted as Rz (mm).
    pub cross_ra: f64,
    /// Rz of the feed profiles (columns), as the cross-feed one (mm).
    pub feed_rz: f64,
    /// The largest Rz of one column (mm).
    pub feed_rz_max: f64,
    /// x of that column (mm).
    pub feed_rz_at: f64,
    /// Mean Ra of the feed profiles (mm).
    pub feed_ra: f64,
    /// Highest point on the down-cut side of the passes (mm).
    pub down_cut_max: f64,
    /// Highest point on the up-cut side (mm).
    pub up_cut_max: f64,
    /// Largest feed-profile Rz on the down-cut side (mm).
    pub down_cut_feed_rz: f64,
    /// Largest feed-profile Rz on the up-cut side (mm).
    pub up_cut_feed_rz: f64,
}

/// Weighted means of profiles' Rz and Ra.
#[derive(Default)]
struct Mean {
    rz: f64,
    ra: f64,
    weight: f64,
}

impl Mean {
    fn add(&mut self, p: Profile, w: f64) {
        self.rz += w * p.rz;
        self.ra += w * p.ra;
        self.weight += w;
    }

    /// (Rz, Ra), 0 without profiles.
    fn get(&self) -> (f64, f64) {
        let w = self.weight.max(f64::MIN_POSITIVE);
        (self.rz / w, self.ra / w)
    }
}

/// Figures of a map whose passes run along +y at x = k·pick; `down_cut_left` says the down-cut
/// side is the −x side of each pass (counter-clockwise rotation seen from the shank, +y feed).
/// `periods` (across, along: the pick feed and the feed per tooth) makes the profiles periodic
/// ([`profile`]); without them each profile is a primary profile ([`primary_profile`]).
pub fn figures(map: &HeightMap, pick: f64, periods: Option<(f64, f64)>, down_cut_left: bool) -> Figures {
    let g = &map.grid;
    let mut f = Figures {
        max_height: f64::NEG_INFINITY,
        min_height: f64::INFINITY,
        down_cut_max: f64::NEG_INFINITY,
        up_cut_max: f64::NEG_INFINITY,
        ..Figures::default()
    };
    let (mut hi2, mut lo2) = (f64::NEG_INFINITY, f64::INFINITY);
    let of = |h: &[f64], period: Option<f64>| match period {
        Some(p) => profile(h, g.step, p),
        None => primary_profile(h),
    };
    // Profiles of a periodic map are weighted by the trapezoidal rule across them (its first
    // and last rows or columns are one period apart, the same profile).
    let weight = |k: usize, n: usize| if periods.is_some() && (k == 0 || k + 1 == n) && n > 1 { 0.5 } else { 1.0 };
    let mut feed = Mean::default();
    for i in 0..g.nx {
        let x = g.x(i);
        let offset = x - (x / pick).round() * pick;
        let left = offset < 0.0;
        let down = if down_cut_left { left } else { !left };
        let col = map.column(i);
        for (j, &h) in col.iter().enumerate() {
            if !h.is_finite() {
                continue;
            }
            if h > f.max_height {
                f.max_height = h;
                f.max_at = (x, g.y(j));
            }
            f.min_height = f.min_height.min(h);
            if i % 2 == 0 && j % 2 == 0 {
                hi2 = hi2.max(h);
                lo2 = lo2.min(h);
            }
            if offset.abs() > ON_PASS {
                if down {
                    f.down_cut_max = f.down_cut_max.max(h);
                } else {
                    f.up_cut_max = f.up_cut_max.max(h);
                }
            }
        }
        if let Some(p) = of(col, periods.map(|p| p.1)) {
            if p.rz > f.feed_rz_max {
                f.feed_rz_max = p.rz;
                f.feed_rz_at = x;
            }
            if offset.abs() > ON_PASS {
                if down {
                    f.down_cut_feed_rz = f.down_cut_feed_rz.max(p.rz);
                } else {
                    f.up_cut_feed_rz = f.up_cut_feed_rz.max(p.rz);
                }
            }
            feed.add(p, weight(i, g.nx));
        }
    }
    (f.feed_rz, f.feed_ra) = feed.get();
    let mut cross = Mean::default();
    let mut row = vec![0.0; g.nx];
    for j in 0..g.ny {
        for (i, v) in row.iter_mut().enumerate() {
            *v = map.at(i, j);
        }
        if let Some(p) = of(&row, periods.map(|p| p.0)) {
            if p.rz > f.cross_rz_max {
                f.cross_rz_max = p.rz;
                f.cross_rz_at = g.y(j);
            }
            cross.add(p, weight(j, g.ny));
        }
    }
    (f.cross_rz, f.cross_ra) = cross.get();
    f.peak_to_valley = f.max_height - f.min_height;
    f.peak_to_valley_half = hi2 - lo2;
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primary_profile_of_a_sawtooth_on_a_slope() {
        // A symmetric triangle wave of height 2 on a slope: the least-squares line takes the
        // slope away.
        let h: Vec<f64> = (0..=400)
            .map(|i| {
                0.01 * i as f64 + if (i / 50) % 2 == 0 { (i % 50) as f64 / 25.0 } else { 2.0 - (i % 50) as f64 / 25.0 }
            })
            .collect();
        let p = primary_profile(&h).unwrap();
        assert!((p.rz - 2.0).abs() < 0.05, "{p:?}");
        assert!((p.ra - 0.5).abs() < 0.02, "{p:?}");
        assert!(primary_profile(&[1.0]).is_none());
        assert!(profile(&[1.0, f64::NAN], 0.1, 1.0).is_none());
    }

    /// The cusp profile of a ball of radius r picked by p: circular arcs h = r − √(r² − u²),
    /// u the distance from the nearest pass, periodic in p. Closed forms: Rz = r − √(r² − p²/4);
    /// mean m = r − (a√(r² − a²) + r² asin(a/r))/(2a) with a = p/2; Ra from the primitive
    /// H(u) = r u − (u√(r² − u²) + r² asin(u/r))/2 of h: Ra = (2/p)(2 m u0 − 2 H(u0) + H(a) − m a),
    /// u0 = √(r² − (r − m)²) where h crosses the mean.
    fn arc_figures(r: f64, p: f64) -> (f64, f64, f64) {
        let a = p / 2.0;
        let big_h = |u: f64| r * u - (u * (r * r - u * u).sqrt() + r * r * (u / r).asin()) / 2.0;
        let m = r - (a * (r * r - a * a).sqrt() + r * r * (a / r).asin()) / (2.0 * a);
        let u0 = (r * r - (r - m) * (r - m)).sqrt();
        let ra = (2.0 / p) * (2.0 * m * u0 - 2.0 * big_h(u0) + big_h(a) - m * a);
        (r - (r * r - a * a).sqrt(), m, ra)
    }

    fn arc_profile(r: f64, p: f64, start: f64, periods: f64, step: f64) -> Vec<f64> {
        let n = (periods * p / step).round() as usize;
        (0..=n)
            .map(|i| {
                let x = start + i as f64 * step;
                let u = x - (x / p).round() * p;
                r - (r * r - u * u).sqrt()
            })
            .collect()
    }

    /// Against the closed forms, wherever the profile starts in its period and however many
    /// periods it holds (a least-squares line through a period starting off a pass tilts: Rz
    /// and Ra came out wrong by tens of per cent).
    #[test]
    fn cusp_profile_figures_match_the_closed_form() {
        for (r, p) in [(5.0, 0.5), (5.0, 2.0), (1.0, 1.5)] {
            let (rz, _, ra) = arc_figures(r, p);
            let step = p / 500.0;
            for start in [-p / 2.0, -p / 4.0, 0.1 * p, 0.0] {
                for periods in [1.0, 2.0, 3.0] {
                    let h = arc_profile(r, p, start, periods, step);
                    let f = profile(&h, step, p).unwrap();
                    assert!((f.rz - rz).abs() < 1e-3 * rz, "r {r} p {p} start {start} ×{periods}: Rz {} vs {rz}", f.rz);
                    assert!((f.ra - ra).abs() < 1e-3 * ra, "r {r} p {p} start {start} ×{periods}: Ra {} vs {ra}", f.ra);
                }
            }
        }
        // Ra of the parabola f²/8r: 4/(9√3) of its height.
        let (rz, _, ra) = arc_figures(1000.0, 0.5);
        assert!((ra / rz - 4.0 / (9.0 * 3f64.sqrt())).abs() < 1e-4, "{}", ra / rz);
    }

    #[test]
    fn classic_figures() {
        assert!((cusp_classic(5.0, 0.5) * 1e3 - 6.25).abs() < 1e-12);
        assert!((cusp_exact(5.0, 0.5) - cusp_classic(5.0, 0.5)).abs() < 2e-5);
        assert!(classic_peak(5.0, 0.5, 0.0) == cusp_exact(5.0, 0.5));
    }
}
