//! An independent drop of the stylus: the highest centre z at which a sphere of radius r, lowered
//! along the vertical through (x, y), touches the model. This is the upper envelope a scan line
//! must follow, computed by a different method from the tracer (which copies the model by
//! nearest-point corrections): triangles are met exactly (the classic drop-cutter's facet, edge
//! and vertex tests, through an XY grid), planes, spheres and unbounded cylinders in closed form,
//! and the other surfaces (finite cylinders, cones, tori, free-form patches) by a certified
//! search on their exact distance: |L| − r is 1-Lipschitz along the vertical, so an interval
//! whose middle is farther than half its length cannot hold a contact and is skipped.

use camkit::geom::{P3, V3};
use camkit::model::analytic::Analytic;
use camkit::model::face::{Carrier, Curve, Face};
use camkit::model::{Geometry, Model, Surface};

/// A triangle in the model's frame with its unit normal.
#[derive(Clone, Copy, Debug)]
struct Tri {
    p: [P3; 3],
    n: V3,
}

/// Triangles binned on a uniform XY grid by their boxes grown by r.
#[derive(Clone, Debug)]
struct Grid {
    tris: Vec<Tri>,
    x0: f64,
    y0: f64,
    cell: f64,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
}

/// One surface as the drop sees it.
#[derive(Clone, Debug)]
enum Part<'a> {
    Mesh(Grid),
    Plane {
        point: P3,
        normal: V3,
    },
    Sphere {
        centre: P3,
        radius: f64,
    },
    /// An unbounded cylinder (lateral surface): a point of its axis, the unit axis, its radius.
    Cylinder {
        point: P3,
        axis: V3,
        radius: f64,
    },
    /// A trimmed face on a plane or a sphere, or round a vertical axis: the stylus rests on its
    /// inside where its carrier's contact (closed form; none on a vertical wall, where an inner
    /// contact raised stays a contact) lies in the face, else on its boundary edges (segments and
    /// horizontal arcs exactly, other curves by the search). Never a search on the face itself,
    /// whose distance is flat along a wall.
    Face {
        surface: &'a Surface,
        face: &'a Face,
    },
    /// Anything else: searched on its own exact distance between these heights of the centre.
    Search {
        surface: &'a Surface,
        z0: f64,
        z1: f64,
    },
}

/// The drop-cutter for one model and stylus radius.
#[derive(Clone, Debug)]
pub struct Dropper<'a> {
    parts: Vec<Part<'a>>,
    radius: f64,
    /// Resolution of the certified search (mm).
    tol: f64,
}

impl<'a> Dropper<'a> {
    /// Prepares `model` for drops of a stylus of radius `r`; `tol` is the resolution of the
    /// certified search on surfaces without a closed form.
    pub fn new(model: &'a Model, r: f64, tol: f64) -> Dropper<'a> {
        let parts = model.surfaces.iter().map(|s| part(s, r)).collect();
        Dropper { parts, radius: r, tol }
    }

    /// The highest stylus centre z over (x, y) touching the model, or `None` when the stylus
    /// can pass the whole model by. Surfaces the vertical touches at every height (a vertical
    /// unbounded plane or cylinder) are left out.
    pub fn drop(&self, x: f64, y: f64) -> Option<f64> {
        self.drop_of(x, y, self.radius)
    }

    /// [`Dropper::drop`] for a stylus of radius `r`, no larger than the one prepared for (the
    /// surfaces' search ranges and the meshes' grids reach that far).
    pub fn drop_of(&self, x: f64, y: f64, r: f64) -> Option<f64> {
        let r = r.min(self.radius);
        let mut best: Option<f64> = None;
        for part in &self.parts {
            let take = raise;
            match part {
                Part::Mesh(g) => {
                    if let Some(z) = g.drop(x, y, r) {
                        take(&mut best, z);
                    }
                }
                Part::Plane { point, normal } => {
                    if normal.z.abs() > 1e-12 {
                        let base = (x - point.x) * normal.x + (y - point.y) * normal.y;
                        take(&mut best, point.z + (r * normal.z.signum() - base) / normal.z);
                    }
                }
                Part::Sphere { centre, radius } => {
                    let rho2 = (x - centre.x).powi(2) + (y - centre.y).powi(2);
                    let big = (radius + r).powi(2);
                    if rho2 <= big {
                        take(&mut best, centre.z + (big - rho2).sqrt());
                    }
                }
                Part::Cylinder { point, axis, radius } => {
                    for rr in [radius + r, radius - r].into_iter().filter(|rr| *rr >= 0.0) {
                        if let Some(t) = line_tube(&P3::new(x, y, point.z), point, axis, rr) {
                            take(&mut best, point.z + t);
                        }
                    }
                }
                Part::Face { surface, face } => {
                    for z in face_contacts(surface, face, x, y, r) {
                        take(&mut best, z);
                    }
                    let place = |p: P3| surface.placement.map_or(p, |iso| iso * p);
                    for curve in face.edges() {
                        if let Some(z) = self.drop_on_curve(surface, curve, &place, [x, y, r], best) {
                            take(&mut best, z);
                        }
                    }
                }
                Part::Search { surface, z0, z1 } => {
                    let lo = best.map_or(*z0, |b| b.max(*z0));
                    let f = |z: f64| {
                        surface
                            .nearest(&P3::new(x, y, z), f64::INFINITY)
                            .map(|(foot, _)| (foot.point - P3::new(x, y, z)).norm() - r)
                    };
                    if let Some(z) = highest_root(&f, lo, *z1, self.tol) {
                        take(&mut best, z);
                    }
                }
            }
        }
        best
    }
}

/// Keeps the larger height.
fn raise(best: &mut Option<f64>, z: f64) {
    if z.is_finite() && best.is_none_or(|b| z > b) {
        *best = Some(z);
    }
}

/// Largest t with a point `q + t·ẑ` at distance `rr` from the axis through `point` along unit
/// `axis`: the upper crossing of the vertical with a tube (None if it misses or runs along it).
fn line_tube(q: &P3, point: &P3, axis: &V3, rr: f64) -> Option<f64> {
    let v0 = q - point;
    let (a_z, v_a) = (axis.z, v0.dot(axis));
    // |v0 + t ẑ|² − ((v0 + t ẑ)·a)² = rr²
    let qa = 1.0 - a_z * a_z;
    let qb = 2.0 * (v0.z - v_a * a_z);
    let qc = v0.norm_squared() - v_a * v_a - rr * rr;
    if qa < 1e-12 {
        return None;
    }
    let disc = qb * qb - 4.0 * qa * qc;
    (disc >= 0.0).then(|| (-qb + disc.sqrt()) / (2.0 * qa))
}

/// How a surface is dropped onto.
fn part(s: &Surface, r: f64) -> Part<'_> {
    let to_model = |p: P3| s.placement.map_or(p, |iso| iso * p);
    let dir = |v: V3| s.placement.map_or(v, |iso| iso * v);
    let search = || {
        let b = s.bounds();
        Part::Search { surface: s, z0: b.min.z - r, z1: b.max.z + r }
    };
    match &s.geometry {
        Geometry::Mesh(m) => {
            let tris: Vec<Tri> = m
                .corners()
                .map(|c| {
                    let p = c.map(to_model);
                    let n = (p[1] - p[0]).cross(&(p[2] - p[0])).normalize();
                    Tri { p, n }
                })
                .collect();
            Part::Mesh(Grid::new(tris, r))
        }
        Geometry::Analytic(Analytic::Plane { point, normal }) => {
            Part::Plane { point: to_model(*point), normal: dir(*normal) }
        }
        Geometry::Analytic(Analytic::Sphere { centre, radius }) => {
            Part::Sphere { centre: to_model(*centre), radius: *radius }
        }
        Geometry::Analytic(Analytic::Cylinder { point, axis, radius, from, to })
            if !from.is_finite() && !to.is_finite() =>
        {
            Part::Cylinder { point: to_model(*point), axis: dir(*axis), radius: *radius }
        }
        Geometry::Face(face) => match face.carrier() {
            Carrier::Analytic(Analytic::Plane { .. } | Analytic::Sphere { .. }) => Part::Face { surface: s, face },
            Carrier::Analytic(Analytic::Cylinder { axis, .. }) if dir(*axis).z.abs() >= 1.0 - 1e-12 => {
                Part::Face { surface: s, face }
            }
            _ => search(),
        },
        _ => search(),
    }
}

/// The highest z in [z0, z1] where the 1-Lipschitz `f` may vanish, to within `tol`: intervals are
/// split top half first and skipped where |f(middle)| exceeds half their length.
fn highest_root(f: &dyn Fn(f64) -> Option<f64>, z0: f64, z1: f64, tol: f64) -> Option<f64> {
    if !(z0.is_finite() && z1.is_finite()) || z1 < z0 {
        return None;
    }
    let mut stack = vec![(z0, z1)];
    while let Some((a, b)) = stack.pop() {
        let (m, w) = (0.5 * (a + b), 0.5 * (b - a));
        let Some(v) = f(m) else { continue };
        if v > w {
            continue;
        }
        if w <= 0.5 * tol {
            return Some(m);
        }
        // Lower half first onto the stack so the upper half is searched first.
        stack.push((a, m));
        stack.push((m, b));
    }
    None
}

/// Most cells of a mesh's grid per triangle.
const CELLS_PER_TRIANGLE: usize = 4;

impl Grid {
    fn new(tris: Vec<Tri>, r: f64) -> Grid {
        let (mut x0, mut y0, mut x1, mut y1) = (f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY);
        for t in &tris {
            for p in &t.p {
                (x0, y0, x1, y1) = (x0.min(p.x), y0.min(p.y), x1.max(p.x), y1.max(p.y));
            }
        }
        let (x0, y0, x1, y1) = (x0 - r, y0 - r, x1 + r, y1 + r);
        let area = (x1 - x0) * (y1 - y0);
        let cells_wanted = (tris.len() * CELLS_PER_TRIANGLE).max(1) as f64;
        let cell = (area / cells_wanted).sqrt().max(r * 0.25).max(1e-9);
        let nx = (((x1 - x0) / cell).ceil() as usize).max(1);
        let ny = (((y1 - y0) / cell).ceil() as usize).max(1);
        let mut cells = vec![Vec::new(); nx * ny];
        for (k, t) in tris.iter().enumerate() {
            let (mut a, mut b, mut c, mut d) = (f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY);
            for p in &t.p {
                (a, b, c, d) = (a.min(p.x), b.min(p.y), c.max(p.x), d.max(p.y));
            }
            let ix = |x: f64| (((x - x0) / cell).floor().max(0.0) as usize).min(nx - 1);
            let iy = |y: f64| (((y - y0) / cell).floor().max(0.0) as usize).min(ny - 1);
            for j in iy(b - r)..=iy(d + r) {
                for i in ix(a - r)..=ix(c + r) {
                    cells[j * nx + i].push(k as u32);
                }
            }
        }
        Grid { tris, x0, y0, cell, nx, ny, cells }
    }

    fn drop(&self, x: f64, y: f64, r: f64) -> Option<f64> {
        let (fx, fy) = ((x - self.x0) / self.cell, (y - self.y0) / self.cell);
        if !(fx >= 0.0 && fy >= 0.0 && fx < self.nx as f64 && fy < self.ny as f64) {
            return None;
        }
        let cell = &self.cells[fy as usize * self.nx + fx as usize];
        let mut best: Option<f64> = None;
        for &k in cell {
            if let Some(z) = drop_on_triangle(&self.tris[k as usize], x, y, r) {
                if best.is_none_or(|b| z > b) {
                    best = Some(z);
                }
            }
        }
        best
    }
}

/// The highest centre z over (x, y) at which a sphere of radius r touches the triangle: the
/// facet (contact inside it), its edges (contact inside them) and its corners.
fn drop_on_triangle(t: &Tri, x: f64, y: f64, r: f64) -> Option<f64> {
    let mut best: Option<f64> = None;
    let mut take = |z: f64| raise(&mut best, z);
    // Facet: the centre r above the plane along the upward normal, its foot inside.
    let n = if t.n.z < 0.0 { -t.n } else { t.n };
    if n.z > 1e-12 {
        let a = t.p[0];
        let zc = a.z + (r - (x - a.x) * n.x - (y - a.y) * n.y) / n.z;
        let foot = P3::new(x, y, zc) - n * r;
        if inside(t, &foot) {
            take(zc);
        }
    }
    for i in 0..3 {
        let (a, b) = (t.p[i], t.p[(i + 1) % 3]);
        // Corner.
        let rho2 = (x - a.x).powi(2) + (y - a.y).powi(2);
        if rho2 <= r * r {
            take(a.z + (r * r - rho2).sqrt());
        }
        // Edge: the vertical's upper crossing with the tube of radius r around it, foot inside.
        let len = (b - a).norm();
        let d = (b - a) / len;
        if let Some(tz) = line_tube(&P3::new(x, y, a.z), &a, &d, r) {
            let c = P3::new(x, y, a.z + tz);
            let along = (c - a).dot(&d);
            if (0.0..=len).contains(&along) {
                take(c.z);
            }
        }
    }
    best
}

/// Heights over (x, y) at which a stylus of radius r touches the inside of a plane or sphere face
/// (every tangency with the carrier whose contact lies in the face; none for a vertical wall).
fn face_contacts(s: &Surface, face: &Face, x: f64, y: f64, r: f64) -> Vec<f64> {
    let to_local = |p: P3| s.placement.map_or(p, |iso| iso.inverse_transform_point(&p));
    let to_model = |p: P3| s.placement.map_or(p, |iso| iso * p);
    let up = s.placement.map_or(V3::z(), |iso| iso.inverse_transform_vector(&V3::z()));
    let base = to_local(P3::new(x, y, 0.0));
    // Centre heights t (model z) with the contact point (face frame) of each tangency.
    let mut found = Vec::new();
    match face.carrier() {
        Carrier::Analytic(Analytic::Plane { .. }) if up.z.abs() > 1e-12 => {
            // Local plane z = 0: the centre at local z = ±r.
            for side in [r, -r] {
                let t = (side - base.z) / up.z;
                let c = base + up * t;
                found.push((t, P3::new(c.x, c.y, 0.0)));
            }
        }
        Carrier::Analytic(Analytic::Sphere { radius, .. }) => {
            // Local centre at the origin: |base + t·up| = R ± r.
            let (b, c0) = (base.coords.dot(&up), base.coords.norm_squared());
            for rr in [radius + r, (radius - r).abs()] {
                let disc = b * b - (c0 - rr * rr);
                if disc >= 0.0 {
                    for t in [-b + disc.sqrt(), -b - disc.sqrt()] {
                        let c = base + up * t;
                        if let Some(u) = c.coords.try_normalize(1e-300) {
                            found.push((t, P3::from(u * *radius)));
                        }
                    }
                }
            }
        }
        _ => {}
    }
    found.into_iter().filter(|(_, p)| face.contains(p)).map(|(t, _)| to_model(base + up * t).z).collect()
}

impl Dropper<'_> {
    /// The highest centre z over (x, y) of a stylus of radius r touching a boundary curve of a
    /// face, above `best`: segments and horizontal arcs in closed form, other curves by the
    /// certified search.
    fn drop_on_curve(
        &self,
        s: &Surface,
        curve: &Curve,
        place: &dyn Fn(P3) -> P3,
        [x, y, r]: [f64; 3],
        best: Option<f64>,
    ) -> Option<f64> {
        let local = |q: P3| s.placement.map_or(q, |iso| iso.inverse_transform_point(&q));
        match curve {
            Curve::Line { a, b } => drop_on_segment(&place(*a), &place(*b), x, y, r),
            Curve::Arc { centre, x: ax, y: ay, .. }
                if (place(centre + ax).z - place(*centre).z).abs() <= 1e-12
                    && (place(centre + ay).z - place(*centre).z).abs() <= 1e-12 =>
            {
                // A horizontal arc: its nearest point to the vertical is the same at every height.
                let zc = place(*centre).z;
                let q = P3::new(x, y, zc);
                let h = (place(curve.nearest(&local(q)).0) - q).norm();
                (h <= r).then(|| zc + (r * r - h * h).sqrt())
            }
            _ => {
                let b = curve.bounds();
                let (z0, z1) = (0..8)
                    .map(|k| {
                        place(P3::new(
                            if k & 1 == 0 { b.min.x } else { b.max.x },
                            if k & 2 == 0 { b.min.y } else { b.max.y },
                            if k & 4 == 0 { b.min.z } else { b.max.z },
                        ))
                        .z
                    })
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| (lo.min(z), hi.max(z)));
                let lo = best.map_or(z0 - r, |bz| bz.max(z0 - r));
                let f = |z: f64| {
                    let q = local(P3::new(x, y, z));
                    Some((curve.nearest(&q).0 - q).norm() - r)
                };
                highest_root(&f, lo, z1 + r, self.tol)
            }
        }
    }
}

/// The highest centre z over (x, y) at which a sphere of radius r touches the segment a–b: its
/// ends, or its inside (the vertical's upper crossing with the tube round it).
fn drop_on_segment(a: &P3, b: &P3, x: f64, y: f64, r: f64) -> Option<f64> {
    let mut best: Option<f64> = None;
    for c in [a, b] {
        let rho2 = (x - c.x).powi(2) + (y - c.y).powi(2);
        if rho2 <= r * r {
            raise(&mut best, c.z + (r * r - rho2).sqrt());
        }
    }
    let len = (b - a).norm();
    let d = (b - a) / len;
    if let Some(tz) = line_tube(&P3::new(x, y, a.z), a, &d, r) {
        let c = P3::new(x, y, a.z + tz);
        if (0.0..=len).contains(&(c - a).dot(&d)) {
            raise(&mut best, c.z);
        }
    }
    best
}

/// True when `p`, in the triangle's plane, lies inside it (edges included, to rounding).
fn inside(t: &Tri, p: &P3) -> bool {
    let eps = -1e-12;
    (0..3).all(|i| {
        let (a, b) = (t.p[i], t.p[(i + 1) % 3]);
        (b - a).cross(&(p - a)).dot(&t.n) >= eps * (b - a).norm_squared()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use camkit::io::Input;

    fn model(text: &str) -> Model {
        Model::load(&Input { name: "m.json".into(), data: text.as_bytes().to_vec() }).unwrap()
    }

    #[test]
    fn closed_forms() {
        let m = model(
            r#"{"surfaces": [{"type": "plane", "point": [0,0,0], "normal": [0,0,1]},
                             {"type": "sphere", "centre": [50,0,30], "radius": 10}]}"#,
        );
        let d = Dropper::new(&m, 5.0, 1e-6);
        assert_eq!(d.drop(0.0, 0.0), Some(5.0));
        assert!((d.drop(50.0, 12.0).unwrap() - (30.0 + 81f64.sqrt())).abs() < 1e-12);
        // A finite cylinder (searched) against its closed form over its middle.
        let m = model(
            r#"{"surfaces": [{"type": "cylinder", "point": [0,0,0], "axis": [1,0,0], "radius": 2, "length": [-10, 10]}]}"#,
        );
        let d = Dropper::new(&m, 1.0, 1e-7);
        assert!((d.drop(3.0, 1.0).unwrap() - 8f64.sqrt()).abs() < 1e-6);
        // Past its end by 0.5: the rim circle.
        assert!((d.drop(10.5, 0.0).unwrap() - (2.0 + 0.75f64.sqrt())).abs() < 1e-6);
        assert_eq!(d.drop(11.5, 0.0), None);
    }

    #[test]
    fn mesh_grid_agrees_with_every_triangle() {
        // A wavy height field with a tilted, placed copy: the grid's candidates hold every
        // triangle that matters, and the placement is applied.
        let f = |i: usize, j: usize| {
            let (x, y) = (i as f64 * 2.0, j as f64 * 2.0);
            P3::new(x, y, (x * 0.4).sin() * 3.0 + (y * 0.3).cos() * 2.0)
        };
        let mut tris = Vec::new();
        for i in 0..15 {
            for j in 0..15 {
                tris.push([f(i, j), f(i + 1, j), f(i + 1, j + 1)]);
                tris.push([f(i, j), f(i + 1, j + 1), f(i, j + 1)]);
            }
        }
        let stl = camkit::model::mesh::binary_stl(&tris);
        let m = Model::load(&Input { name: "w.stl".into(), data: stl }).unwrap();
        let stored: Vec<Tri> = match &m.surfaces[0].geometry {
            Geometry::Mesh(mesh) => {
                mesh.corners().map(|p| Tri { p, n: (p[1] - p[0]).cross(&(p[2] - p[0])).normalize() }).collect()
            }
            _ => unreachable!("a mesh"),
        };
        let d = Dropper::new(&m, 1.7, 1e-7);
        for k in 0..400 {
            let (x, y) = ((k as f64 * 0.618).fract() * 34.0 - 2.0, (k as f64 * 0.377).fract() * 34.0 - 2.0);
            let brute = stored
                .iter()
                .filter_map(|t| drop_on_triangle(t, x, y, 1.7))
                .fold(None, |b: Option<f64>, z| Some(b.map_or(z, |b| b.max(z))));
            assert_eq!(d.drop(x, y), brute, "at ({x}, {y})");
        }
    }

    #[test]
    fn triangle_facet_edge_corner() {
        let t = Tri { p: [P3::origin(), P3::new(10.0, 0.0, 0.0), P3::new(0.0, 10.0, 0.0)], n: V3::z() };
        assert_eq!(drop_on_triangle(&t, 2.0, 2.0, 1.0), Some(1.0));
        // Beyond the hypotenuse by 0.5/√2·√2: the edge.
        let z = drop_on_triangle(&t, 5.5, 5.5, 1.0).unwrap();
        assert!((z - (1.0 - 0.5f64.powi(2) * 2.0).sqrt()).abs() < 1e-12, "{z}");
        let z = drop_on_triangle(&t, -0.6, -0.8, 1.0).unwrap();
        assert!(z.abs() < 1e-12);
        assert_eq!(drop_on_triangle(&t, -1.0, -1.0, 1.0), None);
    }
}
