//! Outlines given by longitude and latitude mapped onto a fitted sphere (the globe of paper 002
//! fig. 1): points on the sphere in workpiece coordinates (origin at the centre, north pole +Z)
//! with the tool axis along the outward normal, each edge followed along its great circle.

use camkit::geom::{P3, V3};

/// Unit vector of longitude `lon` and latitude `lat` (degrees), with longitude `lon0` facing +X.
pub fn direction(lon: f64, lat: f64, lon0: f64) -> V3 {
    let (lo, la) = ((lon - lon0).to_radians(), lat.to_radians());
    V3::new(la.cos() * lo.cos(), la.cos() * lo.sin(), la.sin())
}

/// The number of points [`map_outline`] gives (in floating point, so a tiny step gives a huge
/// number, not an overflow): the work and memory of a map, known before it is made.
pub fn outline_points(lonlat: &[[f64; 2]], lon0: f64, step_deg: f64) -> f64 {
    let dirs: Vec<V3> = lonlat.iter().map(|p| direction(p[0], p[1], lon0)).collect();
    let edges: f64 = dirs.windows(2).map(|w| (w[0].angle(&w[1]).to_degrees() / step_deg).ceil().max(1.0)).sum();
    edges + if dirs.is_empty() { 0.0 } else { 1.0 }
}

/// One outline on the sphere: points `radius · n` and normals `n`, edges split along their great
/// circle so no step is longer than `step_deg` degrees of arc; a closed outline repeats its first
/// point at the end.
pub fn map_outline(lonlat: &[[f64; 2]], radius: f64, lon0: f64, step_deg: f64) -> Vec<(P3, V3)> {
    let dirs: Vec<V3> = lonlat.iter().map(|p| direction(p[0], p[1], lon0)).collect();
    let mut out = Vec::new();
    for w in dirs.windows(2) {
        let (a, b) = (w[0], w[1]);
        let angle = a.angle(&b);
        let n = ((angle.to_degrees() / step_deg).ceil() as usize).max(1);
        for k in 0..n {
            let t = k as f64 / n as f64;
            // Spherical interpolation between a and b.
            let d = if angle > 0.0 { (a * ((1.0 - t) * angle).sin() + b * (t * angle).sin()) / angle.sin() } else { a };
            out.push((P3::from(d * radius), d));
        }
    }
    if let Some(last) = dirs.last() {
        out.push((P3::from(last * radius), *last));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_estimate_is_the_count() {
        let outline = [[130.0, 33.0], [135.5, 34.2], [141.9, 40.1], [130.0, 33.0]];
        for step in [0.5, 1.0, 7.0, 90.0] {
            assert_eq!(outline_points(&outline, 138.0, step), map_outline(&outline, 25.0, 138.0, step).len() as f64);
        }
        assert!(outline_points(&outline, 138.0, 1e-9) > 1e10);
    }

    #[test]
    fn points_lie_on_the_sphere_along_great_circles() {
        let pts = map_outline(&[[130.0, 30.0], [145.0, 45.0], [140.0, 35.0], [130.0, 30.0]], 25.0, 138.0, 1.0);
        let n0 = direction(130.0, 30.0, 138.0);
        let n1 = direction(145.0, 45.0, 138.0);
        let plane = n0.cross(&n1).normalize();
        for (p, n) in &pts {
            assert!((p.coords.norm() - 25.0).abs() < 1e-12 && (p.coords / 25.0 - n).norm() < 1e-12);
        }
        // The first edge stays on its great circle, in steps of at most 1°.
        let first: Vec<_> = pts.iter().take_while(|(_, n)| n.dot(&plane).abs() < 1e-12).collect();
        assert!(first.len() > 10);
        for w in pts.windows(2) {
            assert!(w[0].1.angle(&w[1].1).to_degrees() <= 1.0 + 1e-9);
        }
        assert!((pts.first().unwrap().0 - pts.last().unwrap().0).norm() < 1e-12, "closed");
        assert!((direction(138.0, 0.0, 138.0) - V3::x()).norm() < 1e-15);
    }
}
