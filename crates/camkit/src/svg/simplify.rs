//! Thinning of polylines to the plot's resolution: points that lie within a fraction of a pixel
//! of the simplified line are dropped (Douglas–Peucker in screen space), so a plot's size grows
//! with what can be seen, not with the number of input points.

/// The points of `pts` (screen pixels) kept so that no dropped point lies farther than `eps`
/// pixels from the kept polyline; the first and last points are always kept.
pub fn simplify(pts: &[(f64, f64)], eps: f64) -> Vec<(f64, f64)> {
    if pts.len() < 3 {
        return pts.to_vec();
    }
    let mut keep = vec![false; pts.len()];
    keep[0] = true;
    keep[pts.len() - 1] = true;
    let mut stack = vec![(0, pts.len() - 1)];
    while let Some((a, b)) = stack.pop() {
        let (mut far, mut at) = (0.0, 0);
        for (k, p) in pts.iter().enumerate().take(b).skip(a + 1) {
            let d = distance(*p, pts[a], pts[b]);
            if d > far {
                (far, at) = (d, k);
            }
        }
        if far > eps {
            keep[at] = true;
            stack.push((a, at));
            stack.push((at, b));
        }
    }
    pts.iter().zip(keep).filter_map(|(p, k)| k.then_some(*p)).collect()
}

/// Distance of `p` from the segment `a`–`b`.
fn distance(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 { (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0) } else { 0.0 };
    ((p.0 - a.0 - t * dx).powi(2) + (p.1 - a.1 - t * dy).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_straight_line_keeps_its_ends() {
        let pts: Vec<_> = (0..100).map(|i| (i as f64, 2.0 * i as f64)).collect();
        assert_eq!(simplify(&pts, 0.25), vec![(0.0, 0.0), (99.0, 198.0)]);
    }

    proptest! {
        /// Every dropped point lies within `eps` of the kept polyline (checked against every
        /// kept segment, not the one the algorithm chose).
        #[test]
        fn dropped_points_stay_within_eps(ys in proptest::collection::vec(-50.0f64..50.0, 2..200)) {
            let pts: Vec<_> = ys.iter().enumerate().map(|(i, &y)| (i as f64 * 0.3, y * 0.05)).collect();
            let kept = simplify(&pts, 0.25);
            prop_assert_eq!(kept.first(), pts.first());
            prop_assert_eq!(kept.last(), pts.last());
            for p in &pts {
                let d = kept.windows(2).map(|w| distance(*p, w[0], w[1])).fold(f64::INFINITY, f64::min);
                prop_assert!(d <= 0.25 + 1e-12, "{p:?} is {d} px off");
            }
        }
    }
}
