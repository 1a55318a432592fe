//! Tool bodies and 3-D parts, and the clearance between them, for the collision check: exact
//! convex-against-triangle and convex-against-convex distances, penetration depths and swept
//! casts from `parry3d-f64` (GJK/EPA and conservative advancement on its bounding-volume tree).
//!
//! A [`Body`] is the tool (and its holder) as convex solids in tool coordinates: tip at the
//! origin, axis +Z, the spindle orientation's edge along +X. A [`Solid`] is a part: the material
//! behind each surface's outward normal, from a camkit [`Model`]: meshes as triangle meshes
//! (closed ones also answer "is this point inside"), spheres and planes as exact balls and
//! half-spaces, B-spline patches as triangle meshes within a stated chord error.

use crate::doc::tool::{Tool, ToolKind};
use crate::geom::{P3, V3};
use crate::model::analytic::Analytic;
use crate::model::{Aabb, Geometry, Model};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::{self, ShapeCastOptions};
use parry3d_f64::shape::{SharedShape, TriMeshFlags};

type Quat = parry3d_f64::glamx::DQuat;

fn v(p: &V3) -> Vector {
    Vector::new(p.x, p.y, p.z)
}

fn pt(p: &P3) -> Vector {
    Vector::new(p.x, p.y, p.z)
}

/// One convex piece of a body: its pose in tool coordinates, its shape, and how to shrink it.
#[derive(Clone)]
struct Piece {
    pose: Pose,
    shape: SharedShape,
    kind: PieceKind,
    /// The holder: it may never touch the part.
    holder: bool,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum PieceKind {
    /// A capsule along +Z from `from` to `to` (heights) of `radius`.
    Capsule { from: f64, to: f64, radius: f64 },
    /// A cylinder along +Z from `from` to `to` of `radius`, rims rounded by `corner`.
    Cylinder { from: f64, to: f64, radius: f64, corner: f64 },
    /// A thin wedge (no volume: not shrunk).
    Wedge,
}

impl Piece {
    fn of(kind: PieceKind) -> Piece {
        // parry's cylinders stand along their Y axis: turned onto Z.
        let upright = Quat::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let (pose, shape) = match kind {
            PieceKind::Capsule { from, to, radius } => (
                Pose::identity(),
                SharedShape::capsule(Vector::new(0.0, 0.0, from), Vector::new(0.0, 0.0, to.max(from)), radius),
            ),
            PieceKind::Cylinder { from, to, radius, corner } => {
                let half = 0.5 * (to - from);
                let pose = Pose::from_parts(Vector::new(0.0, 0.0, 0.5 * (from + to)), upright);
                let shape = if corner > 0.0 {
                    SharedShape::round_cylinder((half - corner).max(0.0), (radius - corner).max(0.0), corner)
                } else {
                    SharedShape::cylinder(half, radius)
                };
                (pose, shape)
            }
            PieceKind::Wedge => unreachable!("wedges are built with their corners"),
        };
        Piece { pose, shape, kind, holder: false }
    }

    /// The piece shrunk by `e` (every surface moved `e` inwards); `None` if nothing is left.
    fn eroded(&self, e: f64) -> Option<Piece> {
        match self.kind {
            PieceKind::Capsule { from, to, radius } => {
                (radius > e).then(|| Piece::of(PieceKind::Capsule { from, to, radius: radius - e }))
            }
            PieceKind::Cylinder { from, to, radius, corner } => (radius > e && to - from > 2.0 * e).then(|| {
                Piece::of(PieceKind::Cylinder {
                    from: from + e,
                    to: to - e,
                    radius: radius - e,
                    corner: (corner - e).max(0.0),
                })
            }),
            PieceKind::Wedge => Some(self.clone()),
        }
    }
}

/// A tool body: its convex pieces in tool coordinates.
#[derive(Clone)]
pub struct Body {
    pieces: Vec<Piece>,
    /// Radius of the cutting part (mm).
    pub radius: f64,
    /// Gauge length: the cutting part's height above the tip (mm).
    pub length: f64,
}

/// Gauge length of a tool whose document gives none: three diameters.
pub fn default_length(tool: &Tool) -> f64 {
    tool.length.unwrap_or(6.0 * tool.radius)
}

impl Body {
    /// The body of a tool document: ball end mill a capsule (ball centre R above the tip) up the
    /// gauge length; flat end mill and the cylindrical non-rotating tool a cylinder; bull-nose a
    /// cylinder with its rims rounded by the corner radius; the flat-type non-rotating tool the
    /// wedge of its two flanks (each `flank_length` long, the included angle between them about
    /// the axis, in the plane across the edge: tool +X); and the holder's cylinder above the gauge
    /// line when the document gives one.
    pub fn of(tool: &Tool) -> Body {
        let r = tool.radius;
        let length = default_length(tool);
        let mut pieces = vec![match tool.kind {
            ToolKind::Ball => Piece::of(PieceKind::Capsule { from: r, to: length.max(r), radius: r }),
            ToolKind::Flat | ToolKind::CylindricalNonrotating => {
                Piece::of(PieceKind::Cylinder { from: 0.0, to: length, radius: r, corner: 0.0 })
            }
            ToolKind::Bull => {
                Piece::of(PieceKind::Cylinder { from: 0.0, to: length, radius: r, corner: tool.corner_radius })
            }
            ToolKind::FlatNonrotating => {
                let half = 0.5 * tool.included_angle.unwrap_or(60.0).to_radians();
                let len = tool.flank_length.unwrap_or(r);
                let (s, c) = half.sin_cos();
                Piece {
                    pose: Pose::identity(),
                    shape: SharedShape::triangle(
                        Vector::ZERO,
                        Vector::new(0.0, s * len, c * len),
                        Vector::new(0.0, -s * len, c * len),
                    ),
                    kind: PieceKind::Wedge,
                    holder: false,
                }
            }
        }];
        if let (Some(d), Some(h)) = (tool.holder_diameter, tool.holder_length) {
            let holder = Piece::of(PieceKind::Cylinder { from: length, to: length + h, radius: 0.5 * d, corner: 0.0 });
            pieces.push(Piece { holder: true, ..holder });
        }
        Body { pieces, radius: r, length }
    }

    /// True if [`Solid::first_within`] decides the whole body exactly: its cutting part is a
    /// capsule (a ball end mill). Shrinking a capsule by e is exactly "a point deeper than e
    /// inside it"; at a flat or bull-nose rim it is not, so such bodies are sampled instead.
    pub fn sweeps_exactly(&self) -> bool {
        self.pieces.iter().all(|p| p.holder || matches!(p.kind, PieceKind::Capsule { .. }))
    }
}

/// Where a body is: tip, unit axis, and the edge direction for a tool whose orientation about its
/// axis matters (the spindle orientation's edge; any perpendicular otherwise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Tool tip (mm).
    pub tip: P3,
    /// Unit tool axis.
    pub axis: V3,
    /// Unit edge direction, perpendicular to the axis.
    pub edge: Option<V3>,
}

impl Placement {
    fn pose(&self) -> Pose {
        let z = self.axis;
        let x = self
            .edge
            .map(|e| (e - z * e.dot(&z)).normalize())
            .unwrap_or_else(|| crate::model::analytic::any_perpendicular(&z));
        let y = z.cross(&x);
        let m = parry3d_f64::glamx::DMat3::from_cols(v(&x), v(&y), v(&z));
        Pose::from_parts(pt(&self.tip), Quat::from_mat3(&m).normalize())
    }
}

/// One piece of a part: its pose, shape, and whether it is a closed mesh (which also says
/// whether a point is inside it).
struct PartPiece {
    pose: Pose,
    shape: SharedShape,
    closed_mesh: bool,
}

/// A part: the material behind each surface of a model.
pub struct Solid {
    pieces: Vec<PartPiece>,
    chord: f64,
    /// Names of the mesh surfaces that are not closed and consistently oriented.
    open: Vec<String>,
}

/// Grid (mm) vertices are welded on: corners given back as `a + (b − a)` differ from `b` by
/// round-off only.
const WELD: f64 = 1e-8;

/// Vertices welded (positions on the same [`WELD`] grid point) and triangles as indices, for a
/// mesh with a topology; triangles that collapse are dropped.
fn welded(corners: impl Iterator<Item = [P3; 3]>) -> (Vec<Vector>, Vec<[u32; 3]>) {
    let mut at = std::collections::HashMap::new();
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    for tri in corners {
        let mut idx = [0u32; 3];
        for (k, p) in tri.iter().enumerate() {
            let key = ((p.x / WELD).round() as i64, (p.y / WELD).round() as i64, (p.z / WELD).round() as i64);
            idx[k] = *at.entry(key).or_insert_with(|| {
                vertices.push(pt(p));
                (vertices.len() - 1) as u32
            });
        }
        if idx[0] != idx[1] && idx[1] != idx[2] && idx[0] != idx[2] {
            indices.push(idx);
        }
    }
    (vertices, indices)
}

/// True when the welded triangles close a surface: every edge is met once in each direction by
/// two triangles (no hole, no edge shared by three, orientations agreeing). parry's `ORIENTED`
/// flag alone accepts an open mesh, whose "inside" is then wrong near the hole.
fn closed(indices: &[[u32; 3]]) -> bool {
    let mut edges = std::collections::HashMap::with_capacity(3 * indices.len());
    for t in indices {
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0u32) += 1;
        }
    }
    edges.iter().all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1))
}

/// Triangles of a B-spline patch over its domain: a uniform grid refined until the patch at every
/// cell's centre and edge midpoints lies within `chord` of the cell's two triangles (their
/// planes), normals agreeing with the patch's outward normal (`flip` reverses it). Returns the
/// triangles and the largest deviation seen.
fn patch_triangles(p: &crate::model::patch::BSpline, flip: bool, chord: f64) -> (Vec<[P3; 3]>, f64) {
    let [u0, u1, v0, v1] = p.domain();
    let mut n = 8usize;
    loop {
        let at =
            |i: usize, j: usize| p.eval(u0 + (u1 - u0) * i as f64 / n as f64, v0 + (v1 - v0) * j as f64 / n as f64).s;
        let mut tris = Vec::with_capacity(2 * n * n);
        let mut worst = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                for (t, probes) in [
                    ([a, b, c], [(0.75, 0.25), (0.5, 0.0), (1.0, 0.5)]),
                    ([a, c, d], [(0.25, 0.75), (0.5, 1.0), (0.0, 0.5)]),
                ] {
                    let nrm = (t[1] - t[0]).cross(&(t[2] - t[0]));
                    let len = nrm.norm();
                    for (du, dv) in probes {
                        let q = p
                            .eval(
                                u0 + (u1 - u0) * (i as f64 + du) / n as f64,
                                v0 + (v1 - v0) * (j as f64 + dv) / n as f64,
                            )
                            .s;
                        if len > 0.0 {
                            worst = worst.max(((q - t[0]).dot(&nrm) / len).abs());
                        }
                    }
                    let mid =
                        (u0 + (u1 - u0) * (i as f64 + 0.5) / n as f64, v0 + (v1 - v0) * (j as f64 + 0.5) / n as f64);
                    let out = p.normal(mid.0, mid.1).map(|m| if flip { -m } else { m });
                    let t = if out.is_some_and(|m| m.dot(&nrm) < 0.0) { [t[0], t[2], t[1]] } else { t };
                    tris.push(t);
                }
            }
        }
        if worst <= chord || n >= 1024 {
            return (tris, worst);
        }
        n *= 2;
    }
}

impl Solid {
    /// The part of a model: meshes and patches as triangle meshes (patches within `chord` mm),
    /// spheres as balls and planes as half-spaces (their outward normals flipped as the model
    /// says). Other analytic surfaces (cylinders, cones, tori) and flipped spheres are refused
    /// with what they are: give such a part as an STL.
    pub fn of(model: &Model, chord: f64) -> Result<Solid, String> {
        let mut pieces = Vec::new();
        let mut open = Vec::new();
        let mut worst = 0.0f64;
        for s in &model.surfaces {
            let place = |p: P3| s.placement.map_or(p, |iso| iso * p);
            let turn = |n: V3| s.placement.map_or(n, |iso| iso * n);
            match &s.geometry {
                Geometry::Mesh(m) => {
                    let (vertices, indices) = welded(m.corners().map(|t| t.map(place)));
                    let is_closed = closed(&indices);
                    let (shape, closed) = match SharedShape::trimesh_with_flags(
                        vertices.clone(),
                        indices.clone(),
                        TriMeshFlags::ORIENTED,
                    ) {
                        Ok(shape) => (shape, is_closed),
                        Err(_) => (
                            SharedShape::trimesh(vertices, indices)
                                .map_err(|e| format!("surface {}: {e:?}", s.name))?,
                            false,
                        ),
                    };
                    if !closed {
                        open.push(s.name.clone());
                    }
                    pieces.push(PartPiece { pose: Pose::identity(), shape, closed_mesh: closed });
                }
                Geometry::Patch(p) => {
                    let (tris, dev) = patch_triangles(p, s.flip, chord);
                    worst = worst.max(dev);
                    let (vertices, indices) = welded(tris.into_iter().map(|t| t.map(place)));
                    let shape =
                        SharedShape::trimesh(vertices, indices).map_err(|e| format!("surface {}: {e:?}", s.name))?;
                    pieces.push(PartPiece { pose: Pose::identity(), shape, closed_mesh: false });
                }
                Geometry::Analytic(Analytic::Sphere { centre, radius }) if !s.flip => pieces.push(PartPiece {
                    pose: Pose::from_translation(pt(&place(*centre))),
                    shape: SharedShape::ball(*radius),
                    closed_mesh: false,
                }),
                Geometry::Analytic(Analytic::Plane { point, normal }) => {
                    let n = turn(if s.flip { -*normal } else { *normal });
                    pieces.push(PartPiece {
                        pose: Pose::from_translation(pt(&place(*point))),
                        shape: SharedShape::halfspace(v(&n.normalize())),
                        closed_mesh: false,
                    });
                }
                Geometry::Analytic(a) => {
                    let what = match a {
                        Analytic::Sphere { .. } => "a sphere with its normal flipped (material outside it)",
                        Analytic::Cylinder { .. } => "a cylinder",
                        Analytic::Cone { .. } => "a cone",
                        Analytic::Torus { .. } => "a torus",
                        Analytic::Plane { .. } => unreachable!("planes are half-spaces"),
                    };
                    return Err(format!(
                        "surface {} is {what}: the collision check takes meshes, B-spline patches, spheres and planes; give the part as an STL",
                        s.name
                    ));
                }
            }
        }
        Ok(Solid { pieces, chord: worst, open })
    }

    /// Mesh surfaces that are open or not consistently oriented (a hole, a non-manifold edge):
    /// clearances to their triangles are measured as for any mesh, but whether a point lies
    /// inside needs a closed mesh, so a tool wholly inside such a part is not seen. Filters say
    /// so rather than leave it silent.
    pub fn open_meshes(&self) -> &[String] {
        &self.open
    }

    /// Largest distance between a tessellated patch and its triangles (mm; 0 without patches).
    pub fn chord_error(&self) -> f64 {
        self.chord
    }

    /// Signed clearance (mm) between the body at `at` and the part: the distance when apart (at
    /// most `reach`), minus the penetration depth when they overlap — also where the body's tip
    /// lies wholly inside a closed mesh.
    pub fn clearance(&self, body: &Body, at: &Placement, reach: f64) -> f64 {
        let pose = at.pose();
        let mut best = reach;
        for part in &self.pieces {
            for piece in &body.pieces {
                let pos = pose * piece.pose;
                // The part first: parry 0.31 gives a wrong sign for a shape against a half-space
                // given second (right with it first).
                if let Ok(Some(c)) = query::contact(&part.pose, part.shape.as_ref(), &pos, piece.shape.as_ref(), reach)
                {
                    best = best.min(c.dist);
                }
            }
            if part.closed_mesh {
                let p = part.shape.project_point(&part.pose, pt(&at.tip), true);
                if p.is_inside {
                    best = best.min(-(p.point - pt(&at.tip)).length());
                }
            }
        }
        best
    }

    /// The body moved straight (orientation held) from `at` to `to_tip`: the first fraction of the
    /// move at which a capsule of its cutting part comes nearer the part than `limit` mm (negative:
    /// that much penetration allowed; the capsule shrunk by it and cast), or its holder touches it
    /// (cast as it is) — exactly; `None` if that never happens. Other cutting pieces (flat,
    /// bull-nose, wedge) are not cast: see [`Body::sweeps_exactly`]. A capsule thinner than the
    /// allowed penetration counts as hitting at once.
    pub fn first_within(&self, body: &Body, at: &Placement, to_tip: &P3, limit: f64) -> Option<f64> {
        let mut cast: Vec<(Piece, f64)> = Vec::new();
        for p in &body.pieces {
            match (p.holder, p.kind) {
                (true, _) => cast.push((p.clone(), limit.max(0.0))),
                (false, PieceKind::Capsule { .. }) if limit < 0.0 => match p.eroded(-limit) {
                    Some(e) => cast.push((e, 0.0)),
                    None => return Some(0.0),
                },
                (false, PieceKind::Capsule { .. }) => cast.push((p.clone(), limit)),
                _ => {}
            }
        }
        let pose = at.pose();
        let vel = v(&(to_tip - at.tip));
        let mut first: Option<f64> = None;
        for part in &self.pieces {
            for (piece, target) in &cast {
                let opts = ShapeCastOptions {
                    max_time_of_impact: 1.0,
                    target_distance: *target,
                    stop_at_penetration: true,
                    compute_impact_geometry_on_penetration: false,
                };
                let pos = pose * piece.pose;
                if let Ok(Some(hit)) = query::cast_shapes(
                    &part.pose,
                    Vector::ZERO,
                    part.shape.as_ref(),
                    &pos,
                    vel,
                    piece.shape.as_ref(),
                    opts,
                ) && first.is_none_or(|f| hit.time_of_impact < f)
                {
                    first = Some(hit.time_of_impact);
                }
            }
        }
        first
    }

    /// A box holding the part's finite pieces.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::empty();
        for p in &self.pieces {
            let a = p.shape.compute_aabb(&p.pose);
            b = b.with(&P3::new(a.mins.x, a.mins.y, a.mins.z)).with(&P3::new(a.maxs.x, a.maxs.y, a.maxs.z));
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Surface;
    use crate::model::mesh::Mesh;
    use proptest::prelude::*;

    fn tool(text: &str) -> Tool {
        crate::json::from_input(&crate::io::Input { name: "t.json".into(), data: text.as_bytes().to_vec() }).unwrap()
    }

    fn model(geometry: Geometry, flip: bool) -> Model {
        Model { surfaces: vec![Surface::new("s".into(), geometry, None, flip)] }
    }

    fn floor() -> Solid {
        Solid::of(&model(Geometry::Analytic(Analytic::Plane { point: P3::origin(), normal: V3::z() }), false), 1e-3)
            .unwrap()
    }

    fn tilted(deg: f64) -> V3 {
        V3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos())
    }

    fn at(tip: P3, axis: V3) -> Placement {
        Placement { tip, axis, edge: None }
    }

    /// A closed sphere of triangles (latitude-longitude, outward), radius `r` about `c`.
    fn mesh_sphere(c: P3, r: f64, n: usize) -> Vec<[P3; 3]> {
        let p = |i: usize, j: usize| {
            let j = j % (2 * n);
            if i == 0 || i == n {
                return c + V3::z() * if i == 0 { r } else { -r };
            }
            let (th, ph) =
                (std::f64::consts::PI * i as f64 / n as f64, std::f64::consts::TAU * j as f64 / (2 * n) as f64);
            c + V3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * r
        };
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..2 * n {
                let (a, b, cc, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
                if i > 0 {
                    t.push([a, b, d]);
                }
                if i + 1 < n {
                    t.push([b, cc, d]);
                }
            }
        }
        t
    }

    #[test]
    fn closed_forms_over_a_plane_and_a_sphere() {
        let plane = floor();
        let ball = Body::of(&tool(r#"{"kind": "ball", "radius": 3}"#));
        assert!((plane.clearance(&ball, &at(P3::new(1.0, 2.0, 0.7), V3::z()), 10.0) - 0.7).abs() < 1e-9);
        assert!((plane.clearance(&ball, &at(P3::new(1.0, 2.0, -0.5), V3::z()), 10.0) + 0.5).abs() < 1e-9);
        // Tilted 30°, the ball still touches at its own bottom: the centre is 3 up the axis.
        let c = plane.clearance(&ball, &at(P3::new(0.0, 0.0, 0.2), tilted(30.0)), 10.0);
        assert!((c - (0.2 + 3.0 * 30f64.to_radians().cos() - 3.0)).abs() < 1e-9, "{c}");
        let flat = Body::of(&tool(r#"{"kind": "flat", "radius": 4}"#));
        let c = plane.clearance(&flat, &at(P3::new(0.0, 0.0, 3.0), tilted(20.0)), 10.0);
        assert!((c - (3.0 - 4.0 * 20f64.to_radians().sin())).abs() < 1e-9, "{c}");
        let bull = Body::of(&tool(r#"{"kind": "bull", "radius": 4, "corner_radius": 1}"#));
        let th = 20f64.to_radians();
        let c = plane.clearance(&bull, &at(P3::new(0.0, 0.0, 3.0), tilted(20.0)), 10.0);
        assert!((c - (3.0 - 3.0 * th.sin() - (1.0 - th.cos()))).abs() < 1e-9, "{c}");
        let sphere = Solid::of(
            &model(Geometry::Analytic(Analytic::Sphere { centre: P3::new(0.0, 0.0, -50.0), radius: 50.0 }), false),
            1e-3,
        )
        .unwrap();
        assert!((sphere.clearance(&ball, &at(P3::new(0.0, 0.0, 0.25), V3::z()), 10.0) - 0.25).abs() < 1e-9);
        let n = V3::new(0.6, 0.0, 0.8);
        let tip = P3::new(0.0, 0.0, -50.0) + n * 50.0 - V3::z() * 0.0;
        let c = sphere.clearance(&ball, &at(tip + n * 3.1 - V3::z() * 3.0, V3::z()), 10.0);
        assert!((c - 0.1).abs() < 1e-9, "ball centre 53.1 from the sphere's centre: {c}");
    }

    /// A closed sphere mesh answers "inside"; with a facet taken out (a hole) it is named open.
    #[test]
    fn a_mesh_with_a_hole_is_named_open() {
        let tris = mesh_sphere(P3::origin(), 20.0, 24);
        let closed = Solid::of(&model(Geometry::Mesh(Mesh::new(&tris).unwrap()), false), 0.002).unwrap();
        assert!(closed.open_meshes().is_empty());
        let holed = Solid::of(&model(Geometry::Mesh(Mesh::new(&tris[1..]).unwrap()), false), 0.002).unwrap();
        assert_eq!(holed.open_meshes(), ["s"]);
    }

    #[test]
    fn holders_and_deep_penetration_in_a_closed_mesh() {
        let plane = floor();
        let held = Body::of(&tool(
            r#"{"kind": "flat", "radius": 2, "length": 10, "holder_diameter": 30, "holder_length": 20}"#,
        ));
        // Tilted 45°, 5 mm up: the holder's rim (15 from the axis at 10 along it) is lowest.
        let (s, c) = (45f64.to_radians().sin(), 45f64.to_radians().cos());
        let want = (5.0 + 10.0 * c - 15.0 * s).min(5.0 - 2.0 * s);
        let got = plane.clearance(&held, &at(P3::new(0.0, 0.0, 5.0), tilted(45.0)), 20.0);
        assert!((got - want).abs() < 1e-9, "{got} vs {want}");
        let mesh = Mesh::new(&mesh_sphere(P3::origin(), 20.0, 24)).unwrap();
        let solid = Solid::of(&model(Geometry::Mesh(mesh), false), 1e-3).unwrap();
        let ball = Body::of(&tool(r#"{"kind": "ball", "radius": 1, "length": 3}"#));
        // Deep inside, no triangle near: negative by at least the tip's depth.
        let c = solid.clearance(&ball, &at(P3::origin(), V3::z()), 5.0);
        assert!(c < -15.0, "{c}");
        // Just outside the top vertex (the mesh's pole is exactly at 20): clear by 0.5.
        let c = solid.clearance(&ball, &at(P3::new(0.0, 0.0, 20.5), V3::z()), 5.0);
        assert!((c - 0.5).abs() < 1e-9, "{c}");
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

        /// The swept cast agrees with bisection on the sampled clearance: a ball end mill (with
        /// and without a holder, which may not touch at all) moving straight over a plane and a
        /// ball, its first fraction within `limit` found by both to 1e-4 (or neither finds one).
        #[test]
        fn first_within_agrees_with_sampled_clearance(
            x0 in -20.0f64..20.0, x1 in -20.0f64..20.0, z0 in -1.0f64..6.0, z1 in -1.0f64..6.0,
            tilt in 0.0f64..40.0, kind in 0usize..2, limit in -0.2f64..1.0,
        ) {
            let t = [r#"{"kind": "ball", "radius": 3}"#, r#"{"kind": "ball", "radius": 2, "length": 8, "holder_diameter": 20, "holder_length": 10}"#][kind];
            let body = Body::of(&tool(t));
            let solid = Solid::of(&Model { surfaces: vec![
                Surface::new("p".into(), Geometry::Analytic(Analytic::Plane { point: P3::new(0.0, 0.0, -2.0), normal: V3::z() }), None, false),
                Surface::new("b".into(), Geometry::Analytic(Analytic::Sphere { centre: P3::new(3.0, 1.0, -8.0), radius: 8.5 }), None, false),
            ] }, 1e-3).unwrap();
            // With a holder (which may not touch at all) the limit is a clearance, not a penetration.
            let limit = if kind == 1 { limit.abs() } else { limit };
            let axis = tilted(tilt);
            let (a, b) = (P3::new(x0, 0.5, z0), P3::new(x1, 0.5, z1));
            let c = |t: f64| solid.clearance(&body, &at(a + (b - a) * t, axis), 20.0);
            let cast = solid.first_within(&body, &at(a, axis), &b, limit);
            // Bisection from the first sample below the limit.
            let n = 4000;
            let first = (0..=n).map(|k| k as f64 / n as f64).find(|&t| c(t) < limit);
            match (cast, first) {
                (None, None) => {}
                (Some(tc), Some(ts)) => {
                    let (mut lo, mut hi) = ((ts - 1.0 / n as f64).max(0.0), ts);
                    if c(lo) < limit { lo = 0.0; hi = lo; }
                    for _ in 0..60 {
                        let m = 0.5 * (lo + hi);
                        if c(m) < limit { hi = m } else { lo = m }
                    }
                    prop_assert!((tc - hi).abs() < 1e-4 || (hi == 0.0 && tc < 1e-6), "cast {tc} vs bisection {hi}");
                }
                (Some(tc), None) => {
                    // A graze between samples: the clearance at the cast's fraction is at the limit.
                    prop_assert!(c(tc) < limit + 1e-6, "cast {tc} with clearance {} above {limit}", c(tc));
                }
                (None, Some(ts)) => prop_assert!(false, "missed: clearance {} at {ts}", c(ts)),
            }
        }
    }

    /// A bicubic patch tessellated within its stated chord error: the exact nearest-point query
    /// finds every triangle vertex on the patch and every triangle centre within the error.
    #[test]
    fn patches_are_tessellated_within_their_chord() {
        let net: Vec<Vec<P3>> = (0..4)
            .map(|i| {
                (0..4).map(|j| P3::new(10.0 * i as f64, 10.0 * j as f64, ((i * j) as f64 * 1.3).sin() * 3.0)).collect()
            })
            .collect();
        let patch = crate::model::patch::BSpline::new(&net, [3, 3], None, None);
        let m = model(Geometry::Patch(patch), false);
        let solid = Solid::of(&m, 0.01).unwrap();
        assert!(solid.chord_error() <= 0.01 && solid.chord_error() > 0.0, "{}", solid.chord_error());
        let (tris, _) = patch_triangles(
            match &m.surfaces[0].geometry {
                Geometry::Patch(p) => p,
                _ => unreachable!(),
            },
            false,
            0.01,
        );
        for t in tris.iter().step_by(7) {
            let centre = P3::from((t[0].coords + t[1].coords + t[2].coords) / 3.0);
            assert!(m.nearest(&centre).distance <= 0.01 + 1e-9);
            assert!(m.nearest(&t[0]).distance <= 1e-6);
        }
    }
}
