//! Roughness figures of a height map: peak-to-valley height, profiles across and along the
//! feed with Rz and Ra (ISO 4287 style: least-squares mean line, the whole profile as one
//! sampling length, no λc filter, i.e. the primary-profile Pt and Pa), both sides of the pass
//! told apart, and the classic figures they are compared with.

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
    /// Largest peak above plus largest valley below the least-squares mean line (mm).
    pub rz: f64,
    /// Mean absolute deviation from the mean line (mm).
    pub ra: f64,
}

/// Rz and Ra of a profile; `None` with fewer than two valid points.
pub fn profile(h: &[f64]) -> Option<Profile> {
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
    /// Largest Rz of the cross-feed profiles (rows) and the y of that row (mm).
    pub cross_rz: f64,
    /// y of the cross-feed profile with the largest Rz.
    pub cross_rz_at: f64,
    /// Mean Ra of the cross-feed profiles (mm).
    pub cross_ra: f64,
    /// Largest Rz of the feed profiles (columns) and the x of that column (mm).
    pub feed_rz: f64,
    /// x of the feed profile with the largest Rz.
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

/// Figures of a map whose passes run along +y at x = k·pick; `down_cut_left` says the down-cut
/// side is the −x side of each pass (counter-clockwise rotation seen from the shank, +y feed).
pub fn figures(map: &HeightMap, pick: f64, down_cut_left: bool) -> Figures {
    let g = &map.grid;
    let mut f = Figures {
        max_height: f64::NEG_INFINITY,
        min_height: f64::INFINITY,
        down_cut_max: f64::NEG_INFINITY,
        up_cut_max: f64::NEG_INFINITY,
        ..Figures::default()
    };
    let (mut hi2, mut lo2) = (f64::NEG_INFINITY, f64::INFINITY);
    let (mut feed_ra, mut feed_n) = (0.0, 0usize);
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
        if let Some(p) = profile(col) {
            if p.rz > f.feed_rz {
                f.feed_rz = p.rz;
                f.feed_rz_at = x;
            }
            if offset.abs() > ON_PASS {
                if down {
                    f.down_cut_feed_rz = f.down_cut_feed_rz.max(p.rz);
                } else {
                    f.up_cut_feed_rz = f.up_cut_feed_rz.max(p.rz);
                }
            }
            feed_ra += p.ra;
            feed_n += 1;
        }
    }
    f.feed_ra = feed_ra / feed_n.max(1) as f64;
    let (mut cross_ra, mut cross_n) = (0.0, 0usize);
    let mut row = vec![0.0; g.nx];
    for j in 0..g.ny {
        for (i, v) in row.iter_mut().enumerate() {
            *v = map.at(i, j);
        }
        if let Some(p) = profile(&row) {
            if p.rz > f.cross_rz {
                f.cross_rz = p.rz;
                f.cross_rz_at = g.y(j);
            }
            cross_ra += p.ra;
            cross_n += 1;
        }
    }
    f.cross_ra = cross_ra / cross_n.max(1) as f64;
    f.peak_to_valley = f.max_height - f.min_height;
    f.peak_to_valley_half = hi2 - lo2;
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_of_a_sawtooth_on_a_slope() {
        // A symmetric triangle wave of height 2 on a slope: the mean line takes the slope away.
        let h: Vec<f64> = (0..=400)
            .map(|i| {
                0.01 * i as f64 + if (i / 50) % 2 == 0 { (i % 50) as f64 / 25.0 } else { 2.0 - (i % 50) as f64 / 25.0 }
            })
            .collect();
        let p = profile(&h).unwrap();
        assert!((p.rz - 2.0).abs() < 0.05, "{p:?}");
        assert!((p.ra - 0.5).abs() < 0.02, "{p:?}");
        assert!(profile(&[1.0]).is_none());
    }

    #[test]
    fn classic_figures() {
        assert!((cusp_classic(5.0, 0.5) * 1e3 - 6.25).abs() < 1e-12);
        assert!((cusp_exact(5.0, 0.5) - cusp_classic(5.0, 0.5)).abs() < 2e-5);
        assert!(classic_peak(5.0, 0.5, 0.0) == cusp_exact(5.0, 0.5));
    }
}
