//! The dense test star shared by the offset examples: r = 50 + 15 cos 8θ with `n` vertices, lines
//! or arcs of alternating bulge ±0.05.

use camkit::contour::{Contour, Vertex};
use camkit::geom::P2;

/// A star of `n` vertices; arcs of alternating bulge ±0.05 if `arcs`.
pub fn star(n: usize, arcs: bool) -> Contour {
    let vertices = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let r = 50.0 + 15.0 * (8.0 * a).cos();
            let bulge = if arcs { if i % 2 == 0 { 0.05 } else { -0.05 } } else { 0.0 };
            Vertex { p: P2::new(r * a.cos(), r * a.sin()), bulge }
        })
        .collect();
    Contour { vertices, closed: true }
}
