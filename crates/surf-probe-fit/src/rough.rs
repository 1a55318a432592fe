//! The rough shape of paper 002 §3: the 3-axis raster as a Delaunay triangulation of the scanned
//! points over XY (spade), with a normal per facet and a normal per point (a quadric fitted to its
//! two-ring of neighbours), before any element is assumed; and the 5-axis measuring plan — sensor poses with the beam along the
//! normal at the sensor's stand-off — from that surface or from a fitted sphere.

use camkit::geom::{P3, V3};
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

/// A scanned point as a triangulation vertex (its index in the input kept).
#[derive(Clone, Copy, Debug)]
struct Vertex {
    p: P3,
    index: usize,
}

impl HasPosition for Vertex {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        Point2::new(self.p.x, self.p.y)
    }
}

/// The triangulated rough surface.
#[derive(Clone, Debug)]
pub struct RoughSurface {
    /// Facets as indices into the input points (counter-clockwise seen from +Z).
    pub facets: Vec<[usize; 3]>,
    /// Unit normal of each facet (pointing up, +Z side).
    pub facet_normals: Vec<V3>,
    /// Unit normal at each input point: the normal of a quadric fitted to its two-ring, or the
    /// area-weighted mean of its facets' normals where that fit is not determined (`None` for
    /// points in no facet: repeats of an XY position).
    pub normals: Vec<Option<V3>>,
}

/// Triangulates `points` over XY and computes facet and point normals. Facets steeper than
/// `max_slope_deg` (the long slivers along the convex hull of a scanned dome) are dropped.
pub fn triangulate(points: &[P3], max_slope_deg: f64) -> Result<RoughSurface, String> {
    let mut t: DelaunayTriangulation<Vertex> = DelaunayTriangulation::new();
    for (index, p) in points.iter().enumerate() {
        t.insert(Vertex { p: *p, index }).map_err(|e| format!("point {index} cannot be triangulated: {e:?}"))?;
    }
    let cos_max = max_slope_deg.to_radians().cos();
    let mut facets = Vec::new();
    let mut facet_normals = Vec::new();
    let mut sums = vec![V3::zeros(); points.len()];
    for face in t.inner_faces() {
        let [a, b, c] = face.vertices().map(|v| *v.data());
        let cross = (b.p - a.p).cross(&(c.p - a.p));
        let len = cross.norm();
        if len == 0.0 {
            continue;
        }
        let n = if cross.z < 0.0 { -cross / len } else { cross / len };
        if n.z < cos_max {
            continue;
        }
        for v in [a, b, c] {
            sums[v.index] += n * len;
        }
        facets.push([a.index, b.index, c.index]);
        facet_normals.push(n);
    }
    if facets.is_empty() {
        return Err("the points form no triangle (all on one line, or every facet steeper than the limit)".into());
    }
    let area: Vec<Option<V3>> = sums.iter().map(|s| (s.norm() > 0.0).then(|| s.normalize())).collect();
    let mut ring: Vec<Vec<usize>> = vec![Vec::new(); points.len()];
    for f in &facets {
        for (a, b) in [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])] {
            ring[a].push(b);
            ring[b].push(a);
        }
    }
    let normals = (0..points.len())
        .map(|i| {
            let n0 = area[i]?;
            let mut near: Vec<usize> = ring[i].iter().flat_map(|&j| ring[j].iter().copied().chain([j])).collect();
            near.sort_unstable();
            near.dedup();
            near.retain(|&j| j != i);
            Some(quadric_normal(points, i, &near, n0).unwrap_or(n0))
        })
        .collect();
    Ok(RoughSurface { facets, facet_normals, normals })
}

/// The normal at point `i` of the quadric `h = a s + b t + c s² + d s t + e t² + f` fitted by least
/// squares to its neighbours `near` (the two-ring of the triangulation) in the frame of the facet
/// normal `n0`: exact for a locally quadratic surface, so it does not lean with an asymmetric fan
/// of facets as facet averages do. `None` with fewer than 6 neighbours or a singular fit.
fn quadric_normal(points: &[P3], i: usize, near: &[usize], n0: V3) -> Option<V3> {
    if near.len() < 6 {
        return None;
    }
    let (u, v) = crate::shapes::basis(&n0);
    let mut ata = nalgebra::SMatrix::<f64, 6, 6>::zeros();
    let mut atb = nalgebra::SVector::<f64, 6>::zeros();
    let mut scale: f64 = 0.0;
    for &j in near {
        let d = points[j] - points[i];
        scale = scale.max(d.norm());
    }
    for &j in near.iter().chain([&i]) {
        let d = (points[j] - points[i]) / scale;
        let (s, t, h) = (u.dot(&d), v.dot(&d), n0.dot(&d));
        let row = nalgebra::SVector::<f64, 6>::from([s, t, s * s, s * t, t * t, 1.0]);
        ata.syger(1.0, &row, &row, 1.0);
        atb += row * h;
    }
    ata.fill_upper_triangle_with_lower_triangle();
    let x = ata.cholesky()?.solve(&atb);
    let n = (n0 - u * x[0] - v * x[1]).normalize();
    n.iter().all(|c| c.is_finite()).then_some(n)
}

/// One planned sensor pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// Pass id.
    pub path: i64,
    /// The expected surface point.
    pub point: P3,
    /// The unit outward normal there (the tool axis; the beam runs against it).
    pub normal: V3,
}

impl Probe {
    /// The sensor's reference point at stand-off `s`.
    pub fn tip(&self, standoff: f64) -> P3 {
        self.point + self.normal * standoff
    }
}

/// Probes at the points of the rough surface that carry a normal, every `every`-th one, in input
/// order, keeping each point's pass.
pub fn plan_from_surface(points: &[P3], paths: &[i64], surface: &RoughSurface, every: usize) -> Vec<Probe> {
    let every = every.max(1);
    points
        .iter()
        .zip(paths)
        .zip(&surface.normals)
        .enumerate()
        .filter(|(i, _)| i % every == 0)
        .filter_map(|(_, ((p, path), n))| n.map(|n| Probe { path: *path, point: *p, normal: n }))
        .collect()
}

/// Probes on a sphere (centre, radius): rings of constant angle from the top (+Z), from the top
/// to `max_polar_deg`, `ring_step_deg` apart, points about `ring_step_deg` apart along each ring.
/// One pass per ring.
pub fn plan_on_sphere(centre: &P3, radius: f64, max_polar_deg: f64, ring_step_deg: f64) -> Vec<Probe> {
    let mut out = vec![Probe { path: 0, point: centre + V3::z() * radius, normal: V3::z() }];
    let rings = (max_polar_deg / ring_step_deg).floor() as usize;
    for k in 1..=rings {
        let theta = (k as f64 * ring_step_deg).to_radians();
        let count = ((360.0 * theta.sin() / ring_step_deg).round() as usize).max(3);
        for j in 0..count {
            let phi = std::f64::consts::TAU * j as f64 / count as f64;
            let n = V3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
            out.push(Probe { path: k as i64, point: centre + n * radius, normal: n });
        }
    }
    out
}
