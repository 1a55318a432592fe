//! Zeros of small trigonometric polynomials in one angle γ: closed form for degree 1, certified
//! isolation (no zero missed, none invented) for degree ≤ 3. The edge-trajectory solver splits
//! its parameter range at these zeros so that every piece is monotone.

use std::f64::consts::PI;

/// Width (radians) below which an interval is not split further when isolating zeros.
const ISOLATE_WIDTH: f64 = 1e-13;

/// Zeros of `e0 + e1 sin γ + e2 cos γ` strictly inside `(lo, hi)`, ascending.
pub fn trig1_zeros(e0: f64, e1: f64, e2: f64, lo: f64, hi: f64) -> Vec<f64> {
    let r = e1.hypot(e2);
    if r <= f64::MIN_POSITIVE || e0.abs() > r {
        return Vec::new();
    }
    // e1 sin γ + e2 cos γ = r sin(γ + β), cos β = e1/r, sin β = e2/r.
    let beta = e2.atan2(e1);
    let base = (-e0 / r).clamp(-1.0, 1.0).asin();
    let mut out = Vec::new();
    for g in [base - beta, PI - base - beta] {
        // Every representative of g modulo 2π inside the range.
        let mut k = ((lo - g) / (2.0 * PI)).ceil();
        loop {
            let v = g + k * 2.0 * PI;
            if v >= hi {
                break;
            }
            if v > lo && !out.iter().any(|&w: &f64| (w - v).abs() < ISOLATE_WIDTH) {
                out.push(v);
            }
            k += 1.0;
        }
    }
    out.sort_by(f64::total_cmp);
    out
}

/// Sub-intervals of `[lo, hi]` where `e0 + e1 sin γ + e2 cos γ ≤ 0`.
pub fn trig1_nonpositive(e0: f64, e1: f64, e2: f64, lo: f64, hi: f64) -> Vec<(f64, f64)> {
    let f = |g: f64| e0 + e1 * g.sin() + e2 * g.cos();
    let mut cuts = vec![lo];
    cuts.extend(trig1_zeros(e0, e1, e2, lo, hi));
    cuts.push(hi);
    let mut out: Vec<(f64, f64)> = Vec::new();
    for w in cuts.windows(2) {
        if w[1] <= w[0] || f(0.5 * (w[0] + w[1])) > 0.0 {
            continue;
        }
        match out.last_mut() {
            Some(last) if last.1 == w[0] => last.1 = w[1],
            _ => out.push((w[0], w[1])),
        }
    }
    out
}

/// Intersection of two sorted lists of disjoint intervals.
pub fn intersect(a: &[(f64, f64)], b: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for &(a0, a1) in a {
        for &(b0, b1) in b {
            let (lo, hi) = (a0.max(b0), a1.min(b1));
            if hi > lo {
                out.push((lo, hi));
            }
        }
    }
    out.sort_by(|x, y| x.0.total_cmp(&y.0));
    out
}

/// A trigonometric polynomial of degree ≤ 3 known through a function that evaluates it exactly
/// (up to round-off): its Fourier coefficients bound its derivatives, which certifies zeros.
pub struct Trig3<F: Fn(f64) -> f64> {
    f: F,
    /// Bound of |f'| over all γ.
    d1: f64,
    /// Bound of |f''| over all γ.
    d2: f64,
    /// Coefficients (a_k, b_k), k = 1..3, for f'.
    coef: [(f64, f64); 3],
    /// Slack for round-off in evaluations of f.
    slack: f64,
}

impl<F: Fn(f64) -> f64> Trig3<F> {
    /// Samples `f` at 8 angles and takes its coefficients (exact for degree ≤ 3).
    pub fn new(f: F) -> Self {
        const N: usize = 8;
        let samples: Vec<f64> = (0..N).map(|j| f(2.0 * PI * j as f64 / N as f64)).collect();
        let mut coef = [(0.0, 0.0); 3];
        let mut size = samples.iter().map(|v| v.abs()).fold(0.0, f64::max);
        for (k, c) in coef.iter_mut().enumerate() {
            let k1 = (k + 1) as f64;
            let (mut a, mut b) = (0.0, 0.0);
            for (j, v) in samples.iter().enumerate() {
                let g = 2.0 * PI * j as f64 / N as f64;
                a += v * (k1 * g).cos();
                b += v * (k1 * g).sin();
            }
            *c = (a * 2.0 / N as f64, b * 2.0 / N as f64);
            size = size.max(c.0.abs() + c.1.abs());
        }
        let d1 = coef.iter().enumerate().map(|(k, c)| (k + 1) as f64 * (c.0.abs() + c.1.abs())).sum::<f64>();
        let d2 = coef.iter().enumerate().map(|(k, c)| ((k + 1) as f64).powi(2) * (c.0.abs() + c.1.abs())).sum::<f64>();
        // Round-off of the samples and coefficients: a generous multiple of ε times the size.
        let slack = 1e-12 * size;
        Trig3 { f, d1: d1 * (1.0 + 1e-9) + slack, d2: d2 * (1.0 + 1e-9) + slack, coef, slack }
    }

    fn derivative(&self, g: f64) -> f64 {
        self.coef
            .iter()
            .enumerate()
            .map(|(k, c)| (k + 1) as f64 * (c.1 * ((k + 1) as f64 * g).cos() - c.0 * ((k + 1) as f64 * g).sin()))
            .sum()
    }

    /// Every point in `(lo, hi)` where f changes sign, ascending. Zeros where f only touches 0
    /// (even multiplicity) are not sign changes and are not reported.
    pub fn sign_changes(&self, lo: f64, hi: f64) -> Vec<f64> {
        let mut out = Vec::new();
        let mut stack = vec![(lo, hi, (self.f)(lo), (self.f)(hi))];
        while let Some((a, b, fa, fb)) = stack.pop() {
            let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
            let fm = (self.f)(m);
            if fm.abs() > self.d1 * h + self.slack {
                continue; // no zero in [a, b]
            }
            let opposite = (fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0);
            if self.derivative(m).abs() > self.d2 * h + self.slack {
                // f monotone on [a, b]: one zero if the ends differ in sign, else none.
                if opposite {
                    out.push(self.bisect(a, b, fa));
                }
                continue;
            }
            if h < ISOLATE_WIDTH {
                if opposite {
                    out.push(m);
                }
                continue;
            }
            // Right half first so the left half is popped first: output ascending.
            stack.push((m, b, fm, fb));
            stack.push((a, m, fa, fm));
        }
        out.retain(|&g| g > lo && g < hi);
        out
    }

    fn bisect(&self, mut a: f64, mut b: f64, fa: f64) -> f64 {
        while b - a > ISOLATE_WIDTH {
            let m = 0.5 * (a + b);
            if m <= a || m >= b {
                break;
            }
            let fm = (self.f)(m);
            if (fm < 0.0) == (fa < 0.0) && fm != 0.0 {
                a = m;
            } else {
                b = m;
            }
        }
        0.5 * (a + b)
    }
}

/// `x` reduced to (−π, π].
pub fn wrap_pi(x: f64) -> f64 {
    let y = x.rem_euclid(2.0 * PI);
    if y > PI { y - 2.0 * PI } else { y }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degree_one_zeros_and_signs() {
        // sin γ − 0.5 on (−π/2, π/2): zero at π/6.
        let z = trig1_zeros(-0.5, 1.0, 0.0, -PI / 2.0, PI / 2.0);
        assert_eq!(z.len(), 1);
        assert!((z[0] - PI / 6.0).abs() < 1e-15);
        let neg = trig1_nonpositive(-0.5, 1.0, 0.0, -PI / 2.0, PI / 2.0);
        assert_eq!(neg.len(), 1);
        assert!((neg[0].1 - PI / 6.0).abs() < 1e-15 && neg[0].0 == -PI / 2.0);
        assert!(trig1_zeros(2.0, 1.0, 0.0, -PI, PI).is_empty());
        assert_eq!(trig1_nonpositive(2.0, 1.0, 1.0, -1.0, 1.0), vec![]);
        assert_eq!(trig1_nonpositive(-2.0, 1.0, 1.0, -1.0, 1.0), vec![(-1.0, 1.0)]);
    }

    #[test]
    fn certified_isolation_finds_close_zeros() {
        // (cos γ − cos 0.3)(sin γ − 0.001): zeros at ±0.3 and at asin(0.001), π − asin(0.001).
        let f = |g: f64| (g.cos() - 0.3f64.cos()) * (g.sin() - 0.001);
        let t = Trig3::new(f);
        let z = t.sign_changes(-PI / 2.0, PI / 2.0);
        assert_eq!(z.len(), 3, "{z:?}");
        assert!((z[0] + 0.3).abs() < 1e-12 && (z[1] - 0.001f64.asin()).abs() < 1e-12 && (z[2] - 0.3).abs() < 1e-12);
        // Two zeros 2e-6 apart are both found.
        let g = |x: f64| (x.sin() - 1e-6) * (x.sin() + 1e-6) * x.cos();
        assert_eq!(Trig3::new(g).sign_changes(-1.0, 1.0).len(), 2);
        // A touching zero is not a sign change.
        let h = |x: f64| x.sin().powi(2) + 0.0 * x;
        assert!(Trig3::new(h).sign_changes(-1.0, 1.0).is_empty());
    }
}
