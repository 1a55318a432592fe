//! The bench input: paper 000's smoothing of an R500 sphere (tool tilted −5° towards the feed,
//! spindle orientation along the feed), 0.2 mm between rows, so no block needs inserting.

use camkit::geom::{P3, V3};
use camkit::kinematics::edge_angle;
use post_6axis::plan::Cl;

/// Scan lines over the top of an R500 sphere, `n` rows.
pub fn rows(n: usize) -> Vec<Cl> {
    let (r, c) = (500.0, P3::new(0.0, 0.0, -500.0));
    let per_line = 1000;
    (0..n)
        .map(|i| {
            let (line, k) = (i / per_line, i % per_line);
            let y = -20.0 + line as f64;
            let x = -100.0 + k as f64 * 0.2;
            let p = P3::new(x, y, c.z + (r * r - x * x - y * y).sqrt());
            let normal = (p - c) / r;
            let feed = V3::x();
            let feed = (feed - normal * normal.dot(&feed)).normalize();
            let t = (-5.0f64).to_radians();
            let axis = (normal * t.cos() + feed * t.sin()).normalize();
            let s = edge_angle(&axis, &(feed - axis * axis.dot(&feed)).normalize());
            Cl {
                tip: p,
                axis,
                s: Some(s),
                feed: Some(1000.0),
                rapid: k == 0,
                reorient: k == 0,
                line: i as u64 + 2,
                arc: None,
            }
        })
        .collect()
}
