//! Paper 000 eq. (1): the radius R' that the cylindrical non-rotating tool's edge, tilted by θ,
//! transfers to the surface across the feed, and its inverse (the tilt that gives a wanted R').
//!
//! Reading of eq. (1): tilting the axis by |θ| turns the rim of radius R into an ellipse in the
//! section across the feed, with semi-axes R and R·sin|θ|. Eq. (1) is the circle through the
//! rim's lowest point and the two rim points at depth T above it (sagitta T, half-chord
//! √(R² − (T/sin|θ| − R)²)); T → 0 gives the ellipse's vertex radius R/sin|θ|, which is the
//! paper's figure: φ25 over θ ∈ [−20°, 0°) gives R' from 36.5 mm to infinity.

/// R' of eq. (1) for tool radius `r`, depth `t` (mm, 0 for the limit T → 0) and tilt `theta`
/// (radians, either sign); `None` where it is undefined: θ = 0 (a straight section, R' = ∞) or a
/// depth the tilted rim does not reach (T ≥ 2R·sin|θ|).
pub fn edge_radius(r: f64, t: f64, theta: f64) -> Option<f64> {
    let s = theta.abs().sin();
    if s <= camkit::tol::ANGLE_EPS || t >= 2.0 * r * s {
        return None;
    }
    if t == 0.0 {
        return Some(r / s);
    }
    let q = (t - r * s) / s;
    Some((t * t + r * r - q * q) / (2.0 * t))
}

/// The largest R' eq. (1) gives for depth `t` > 0 (at sin|θ| = T/R): R²/(2T) + T/2.
pub fn largest_edge_radius(r: f64, t: f64) -> f64 {
    if t == 0.0 { f64::INFINITY } else { r * r / (2.0 * t) + t / 2.0 }
}

/// The tilt θ ≤ 0 (radians) at which eq. (1) gives `r_edge`, on the branch that reaches the
/// paper's range (sin|θ| ≥ T/R); `None` if no tilt up to 90° gives it.
pub fn tilt_for_edge_radius(r: f64, t: f64, r_edge: f64) -> Option<f64> {
    if !(r_edge.is_finite() && r_edge >= r) {
        return None;
    }
    // Eq. (1) as (R' − T/2)·s² − R·s + T/2 = 0 in s = sin|θ|; the larger root tends to R/R'.
    let a = r_edge - t / 2.0;
    let disc = r * r - 2.0 * t * a;
    if disc < 0.0 {
        return None;
    }
    let s = (r + disc.sqrt()) / (2.0 * a);
    (s <= 1.0).then(|| -s.asin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_figure_phi25() {
        // φ25 tool, θ ∈ [−20°, 0°): R' from 36 mm to infinity (paper 000 §2.2).
        let r = 12.5;
        let at20 = edge_radius(r, 0.0, (-20f64).to_radians()).unwrap();
        assert!((36.0..37.0).contains(&at20), "{at20}");
        assert!((at20 - 12.5 / 20f64.to_radians().sin()).abs() < 1e-12);
        let mut last = at20;
        for k in 1..2000 {
            let theta = (-20.0 + k as f64 * 0.01f64).to_radians();
            let v = edge_radius(r, 0.0, theta).unwrap();
            assert!(v > last, "R' grows as θ → 0");
            last = v;
        }
        assert!(last > 10_000.0);
        assert_eq!(edge_radius(r, 0.0, 0.0), None);
        // With a depth of cut in the paper's 5–20 µm the figure stands (36.47 mm at 20 µm).
        let deep = edge_radius(r, 0.02, (-20f64).to_radians()).unwrap();
        assert!((36.0..at20).contains(&deep), "{deep}");
    }

    #[test]
    fn inverse_round_trips() {
        for &t in &[0.0, 0.005, 0.02] {
            for deg in [-20.0, -10.0, -5.0, -1.0, -0.5] {
                let theta = f64::to_radians(deg);
                let re = edge_radius(12.5, t, theta).unwrap();
                let back = tilt_for_edge_radius(12.5, t, re).unwrap();
                assert!((back - theta).abs() < 1e-9, "t {t} θ {deg}: {back}");
            }
        }
        assert_eq!(tilt_for_edge_radius(12.5, 0.0, 10.0), None);
        assert_eq!(tilt_for_edge_radius(12.5, 0.02, largest_edge_radius(12.5, 0.02) * 1.01), None);
    }
}
