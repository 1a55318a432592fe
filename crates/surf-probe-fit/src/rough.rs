//! The rough shape of paper 002 §3: the 3-axis raster as a Delaunay triangulation of the scanned
//! points over XY (spade), with a normal per facet and an area-weighted normal per point, before
//! any element is assumed; and the 5-axis measuring plan — sensor poses with the beam along the
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
    /// Area-weighted unit normal at each input point (`None` for points in no facet: repeats of
    /// an XY position).
    pub normals: Vec<Option<V3>>,
}

/// Triangulates `points` over XY and computes facet and point normals (area-weighted means). Facets steeper than
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
    let normals = sums.iter().map(|s| (s.norm() > 0.0).then(|| s.normalize())).collect();
    Ok(RoughSurface { facets, facet_normals, normals })
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
