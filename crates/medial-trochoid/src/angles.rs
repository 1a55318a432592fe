//! Sets of angles on the tool circle as sorted, disjoint open intervals of [0, 2π): the
//! arithmetic of the exact engagement angle.

use smallvec::{SmallVec, smallvec};
use std::f64::consts::TAU;

/// Intervals of an [`AngleSet`]: up to four inline (a disk's set has at most two, a band's
/// three), so that the millions of sets the engagement builds allocate nothing.
pub type Intervals = SmallVec<[(f64, f64); 4]>;

/// A set of angles (radians): sorted, disjoint intervals inside [0, 2π).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AngleSet(pub Intervals);

impl AngleSet {
    /// The whole circle.
    pub fn full() -> AngleSet {
        AngleSet(smallvec![(0.0, TAU)])
    }

    /// Angles within `half` of `centre` (the whole circle when `half ≥ π`).
    pub fn around(centre: f64, half: f64) -> AngleSet {
        if half <= 0.0 {
            return AngleSet::default();
        }
        if half >= std::f64::consts::PI {
            return AngleSet::full();
        }
        let a = (centre - half).rem_euclid(TAU);
        let b = a + 2.0 * half;
        if b <= TAU { AngleSet(smallvec![(a, b)]) } else { AngleSet(smallvec![(0.0, b - TAU), (a, TAU)]) }
    }

    /// Angles θ with `lo < c + r·cos(θ − phi) < hi`: the circle of radius `r` met with a band
    /// between two parallel lines (or two circles' radial bounds), in closed form.
    pub fn band(c: f64, r: f64, phi: f64, lo: f64, hi: f64) -> AngleSet {
        let (ulo, uhi) = ((lo - c) / r, (hi - c) / r);
        if ulo >= 1.0 || uhi <= -1.0 || ulo >= uhi {
            return AngleSet::default();
        }
        let above = if ulo < -1.0 { AngleSet::full() } else { AngleSet::around(phi, ulo.acos()) };
        if uhi > 1.0 {
            return above;
        }
        let below = AngleSet::around(phi + std::f64::consts::PI, std::f64::consts::PI - uhi.acos());
        above.intersect(&below)
    }

    /// Common angles of two sets.
    pub fn intersect(&self, other: &AngleSet) -> AngleSet {
        let mut out = Intervals::new();
        let (mut i, mut j) = (0, 0);
        while i < self.0.len() && j < other.0.len() {
            let (a0, a1) = self.0[i];
            let (b0, b1) = other.0[j];
            let (lo, hi) = (a0.max(b0), a1.min(b1));
            if lo < hi {
                out.push((lo, hi));
            }
            if a1 < b1 { i += 1 } else { j += 1 }
        }
        AngleSet(out)
    }

    /// Angles in either set.
    pub fn union(&self, other: &AngleSet) -> AngleSet {
        let mut all: Vec<(f64, f64)> = self.0.iter().chain(&other.0).copied().collect();
        merge(&mut all);
        AngleSet(Intervals::from_vec(all))
    }

    /// Total measure (radians).
    pub fn measure(&self) -> f64 {
        self.0.iter().map(|(a, b)| b - a).sum()
    }
}

/// Sorts and merges intervals in place.
pub fn merge(all: &mut Vec<(f64, f64)>) {
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(all.len());
    for &(a, b) in all.iter() {
        match out.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => out.push((a, b)),
        }
    }
    *all = out;
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn wrap_band_and_union() {
        let s = AngleSet::around(0.0, 0.5);
        assert_eq!(s.0.len(), 2);
        assert!((s.measure() - 1.0).abs() < 1e-15);
        // cos θ > 0: the right half.
        let b = AngleSet::band(0.0, 1.0, 0.0, 0.0, 2.0);
        assert!((b.measure() - PI).abs() < 1e-12, "{b:?}");
        // 0 < cos θ < 0.5: two arcs of 30° each.
        let b = AngleSet::band(0.0, 1.0, 0.0, 0.0, 0.5);
        assert!((b.measure() - PI / 3.0).abs() < 1e-12, "{b:?}");
        let u = s.union(&AngleSet::around(PI, 0.5));
        assert!((u.measure() - 2.0).abs() < 1e-12);
        assert!((s.intersect(&AngleSet::around(0.25, 0.5)).measure() - 0.75).abs() < 1e-12);
    }
}
