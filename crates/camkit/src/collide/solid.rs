//! Tool bodies and 3-D parts, and the clearance between them, for the collision check: exact
//! convex-against-triangle and convex-against-convex distances, penetration depths and swept
//! casts from `parry3d-f64` (GJK/EPA and conservative advancement on its bounding-volume tree).
//!
//! A [`Body`] is the tool (and its holder) as convex solids in tool coordinates: tip at the
//! origin, axis +Z, the spindle orientation's edge along +X. A [`Solid`] is a part: the material
//! behind each surface's outward normal, from a camkit [`Model`]: meshes as triangle meshes
//! (closed ones also answer "is this point inside"), spheres and planes as exact balls and
//! half-spaces, B-spline patches and trimmed STEP faces as triangle meshes within a stated chord error.
//! [`Solid::of_any`] also takes every other analytic surface, for clearance queries: unbounded
//! cylinders exactly (a rod as a cylinder long enough for the query, a bore in closed form: see
//! [`super::closed_form`]), flipped spheres in closed form, bounded cylinders as exact cylinders
//! (flipped ones, cones and tori as triangle meshes within the chord).

use super::closed_form::{Extreme, Hollow};
use crate::doc::tool::{Tool, ToolKind};
use crate::geom::{P3, V3};
use crate::model::analytic::Analytic;
use crate::model::face::MAX_VERTICES;
use crate::model::{Aabb, Geometry, Model};
use parry3d_f64::bounding_volume::BoundingVolume;
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

    /// The slab along the tool axis that holds the piece and the largest distance of its points
    /// from the axis: (lowest height, highest height, radius); `None` for a wedge.
    fn span(&self) -> Option<(f64, f64, f64)> {
        match self.kind {
            PieceKind::Capsule { from, to, radius } => Some((from - radius, to.max(from) + radius, radius)),
            PieceKind::Cylinder { from, to, radius, .. } => Some((from, to, radius)),
            PieceKind::Wedge => None,
        }
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
    /// gauge length; flat end mill, cone cutter and the cylindrical non-rotating tool a cylinder; bull-nose a
    /// cylinder with its rims rounded by the corner radius; the flat-type non-rotating tool the
    /// wedge of its two flanks (each `flank_length` long, the included angle between them about
    /// the axis, in the plane across the edge: tool +X); and the holder's cylinder above the gauge
    /// line when the document gives one.
    pub fn of(tool: &Tool) -> Body {
        let r = tool.radius;
        let length = default_length(tool);
        let mut pieces = vec![match tool.kind {
            ToolKind::Ball => Piece::of(PieceKind::Capsule { from: r, to: length.max(r), radius: r }),
            // A cone cutter's body is held by the cylinder of its radius (a check errs on the safe side).
            ToolKind::Flat | ToolKind::Cone | ToolKind::CylindricalNonrotating => {
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

    /// The body's extreme parts at `at`, in model coordinates (see [`super::closed_form`]): a
    /// capsule's end centres padded by its radius, a cylinder's rim circles (of a rounded one the
    /// circles its rounding's centres run on, padded by the corner radius), a wedge's corners.
    fn extremes(&self, at: &Placement) -> Vec<Extreme> {
        let (x, y, z) = at.frame();
        let world = |p: Vector| at.tip + x * p.x + y * p.y + z * p.z;
        let mut out = Vec::with_capacity(2 * self.pieces.len() + 1);
        for p in &self.pieces {
            match p.kind {
                PieceKind::Capsule { from, to, radius } => {
                    for h in [from, to.max(from)] {
                        out.push(Extreme::Point { at: at.tip + z * h, pad: radius });
                    }
                }
                PieceKind::Cylinder { from, to, radius, corner } => {
                    let mid = 0.5 * (from + to);
                    let (lo, hi) = ((from + corner).min(mid), (to - corner).max(mid));
                    for h in [lo, hi] {
                        let (centre, radius) = (at.tip + z * h, (radius - corner).max(0.0));
                        out.push(Extreme::Circle { centre, normal: z, radius, pad: corner });
                    }
                }
                PieceKind::Wedge => {
                    if let Some(t) = p.shape.as_triangle() {
                        for c in [t.a, t.b, t.c] {
                            out.push(Extreme::Point { at: world(p.pose * c), pad: 0.0 });
                        }
                    }
                }
            }
        }
        out
    }

    /// Largest distance of a point of the body from its tip (mm).
    fn extent(&self) -> f64 {
        self.pieces
            .iter()
            .map(|p| {
                let b = p.shape.compute_aabb(&p.pose);
                b.mins.abs().max(b.maxs.abs()).length()
            })
            .fold(0.0, f64::max)
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
    /// The tool's frame in model coordinates: edge (+X), +Y, axis (+Z).
    fn frame(&self) -> (V3, V3, V3) {
        let z = self.axis;
        let x = self
            .edge
            .map(|e| (e - z * e.dot(&z)).normalize())
            .unwrap_or_else(|| crate::model::analytic::any_perpendicular(&z));
        (x, z.cross(&x), z)
    }

    fn pose(&self) -> Pose {
        let (x, y, z) = self.frame();
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

/// An unbounded circular cylinder with the material inside: a rod.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Rod {
    point: P3,
    axis: V3,
    radius: f64,
}

/// A part: the material behind each surface of a model.
pub struct Solid {
    pieces: Vec<PartPiece>,
    /// Material outside a sphere or a bore ([`Solid::of_any`]).
    hollows: Vec<Hollow>,
    /// Unbounded rods ([`Solid::of_any`]).
    rods: Vec<Rod>,
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

/// A parry cylinder (standing along its Y axis) turned onto unit `axis` about `centre`.
fn along(centre: &P3, axis: &V3) -> Pose {
    Pose::from_parts(pt(centre), Quat::from_rotation_arc(Vector::Y, v(axis)))
}

/// Triangles of a parametric surface `at(u, v)` over `[u0, u1, v0, v1]`: a uniform grid refined
/// until the surface at every cell's centre and edge midpoints lies within `chord` of the cell's
/// two triangles (their planes), the triangles turned to agree with the outward normal `normal`
/// (`flip` reverses it). Returns the triangles and the largest deviation seen, the grid's
/// vertices taken from `left`; or, when a grid would need more vertices than `left` holds, that
/// number (before it is built: a finely bent patch at a tight chord makes 2 M triangles).
fn surface_triangles(
    [u0, u1, v0, v1]: [f64; 4],
    at: &dyn Fn(f64, f64) -> P3,
    normal: &dyn Fn(f64, f64) -> Option<V3>,
    flip: bool,
    chord: f64,
    left: &std::cell::Cell<usize>,
) -> Result<(Vec<[P3; 3]>, f64), usize> {
    let mut n = 8usize;
    loop {
        let need = (n + 1) * (n + 1);
        if need > left.get() {
            return Err(need);
        }
        let uv = |i: f64, j: f64| (u0 + (u1 - u0) * i / n as f64, v0 + (v1 - v0) * j / n as f64);
        let grid = |i: usize, j: usize| {
            let (u, v) = uv(i as f64, j as f64);
            at(u, v)
        };
        let mut tris = Vec::with_capacity(2 * n * n);
        let mut worst = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (grid(i, j), grid(i + 1, j), grid(i + 1, j + 1), grid(i, j + 1));
                for (t, probes) in [
                    ([a, b, c], [(0.75, 0.25), (0.5, 0.0), (1.0, 0.5)]),
                    ([a, c, d], [(0.25, 0.75), (0.5, 1.0), (0.0, 0.5)]),
                ] {
                    let nrm = (t[1] - t[0]).cross(&(t[2] - t[0]));
                    let len = nrm.norm();
                    for (du, dv) in probes {
                        let (u, v) = uv(i as f64 + du, j as f64 + dv);
                        if len > 0.0 {
                            worst = worst.max(((at(u, v) - t[0]).dot(&nrm) / len).abs());
                        }
                    }
                    let (mu, mv) = uv(i as f64 + 0.5, j as f64 + 0.5);
                    let out = normal(mu, mv).map(|m| if flip { -m } else { m });
                    let t = if out.is_some_and(|m| m.dot(&nrm) < 0.0) { [t[0], t[2], t[1]] } else { t };
                    tris.push(t);
                }
            }
        }
        if worst <= chord || n >= 1024 {
            left.set(left.get() - need);
            return Ok((tris, worst));
        }
        n *= 2;
    }
}

/// A piece of material for a mesh of triangles, and whether the mesh is closed: a closed,
/// consistently oriented one answers "inside" when `solid_inside`; any other is a sheet.
fn mesh_piece(
    name: &str,
    corners: impl Iterator<Item = [P3; 3]>,
    solid_inside: bool,
) -> Result<(PartPiece, bool), String> {
    let (vertices, indices) = welded(corners);
    let is_closed = closed(&indices);
    if solid_inside
        && is_closed
        && let Ok(shape) = SharedShape::trimesh_with_flags(vertices.clone(), indices.clone(), TriMeshFlags::ORIENTED)
    {
        return Ok((PartPiece { pose: Pose::identity(), shape, closed_mesh: true }, true));
    }
    let shape = SharedShape::trimesh(vertices, indices).map_err(|e| format!("surface {name}: {e:?}"))?;
    Ok((PartPiece { pose: Pose::identity(), shape, closed_mesh: false }, is_closed))
}

/// Signed clearance (at most `reach`) between a body piece round the tool axis (at `pos`; within
/// heights `lo..hi` of the axis from the tip of `at` and `radius` of it) and a triangle mesh: the
/// same as parry's contact of the piece with the whole mesh, but triangles that the piece's slab
/// or its cylinder round the axis separates from it by more than `reach` (exact, cheap tests) are
/// not handed to GJK/EPA — under a tool standing on a surface most of them are. Stops at the
/// first clearance below `enough`.
fn mesh_clearance(
    part: &PartPiece,
    mesh: &parry3d_f64::shape::TriMesh,
    piece: &Piece,
    pos: &Pose,
    at: &Placement,
    (lo, hi, radius): (f64, f64, f64),
    (reach, enough): (f64, f64),
) -> f64 {
    let (tip, axis) = (pt(&at.tip), v(&at.axis));
    let reach_out = reach.max(0.0);
    // Distance from the axis line of a point (the line, not the segment: a lower bound).
    let off_axis = |p: Vector| {
        let d = p - tip;
        (d - axis * d.dot(axis)).length()
    };
    let mut best = reach;
    // The piece's box in the mesh's frame, grown by the reach.
    let query = piece.shape.compute_aabb(&(part.pose.inverse() * pos)).loosened(reach_out);
    // Whole subtrees go the same way: a node's box outside the slab, or farther from the axis
    // than the radius, holds no triangle that could touch.
    let (axis_abs, local_tip, local_axis) = {
        let inv = part.pose.inverse();
        let a = inv.rotation * axis;
        (a.abs(), inv * tip, a)
    };
    let keep = |node: &parry3d_f64::partitioning::BvhNode| {
        let b = node.aabb();
        if !b.intersects(&query) {
            return false;
        }
        let (c, e) = (b.center(), b.half_extents());
        let (h, spread) = ((c - local_tip).dot(local_axis), e.dot(axis_abs));
        if h + spread < lo - reach_out || h - spread > hi + reach_out {
            return false;
        }
        let d = c - local_tip;
        (d - local_axis * d.dot(local_axis)).length() - e.length() <= radius + reach_out
    };
    for i in mesh.bvh().leaves(keep) {
        let t = mesh.triangle(i);
        let corners = [part.pose * t.a, part.pose * t.b, part.pose * t.c];
        let h = corners.map(|c| (c - tip).dot(axis));
        if h.iter().all(|&x| x < lo - reach_out) || h.iter().all(|&x| x > hi + reach_out) {
            continue;
        }
        let centre = (corners[0] + corners[1] + corners[2]) / 3.0;
        let spread = corners.iter().map(|c| (*c - centre).length()).fold(0.0, f64::max);
        if off_axis(centre) - spread > radius + reach_out {
            continue;
        }
        let tri = parry3d_f64::shape::Triangle::new(corners[0], corners[1], corners[2]);
        if let Ok(Some(c)) = query::contact(&Pose::identity(), &tri, pos, piece.shape.as_ref(), reach) {
            best = best.min(c.dist);
            if best < enough {
                return best;
            }
        }
    }
    best
}

impl Solid {
    /// The part of a model: meshes and patches as triangle meshes (patches within `chord` mm),
    /// spheres as balls and planes as half-spaces (their outward normals flipped as the model
    /// says). Other analytic surfaces (cylinders, cones, tori) and flipped spheres are refused
    /// with what they are: give such a part as an STL.
    pub fn of(model: &Model, chord: f64) -> Result<Solid, String> {
        Solid::build(model, chord, false)
    }

    /// The part of a model for [`Solid::clearance`], every surface taken: as [`Solid::of`], and
    /// also unbounded cylinders (inside: a rod, exact; flipped: a bore, in closed form), flipped
    /// spheres (a cavity, in closed form), bounded cylinders (inside: an exact cylinder with flat
    /// ends; flipped: triangles within `chord`), cones and tori (triangles within `chord`; a
    /// torus's mesh is closed and answers "inside"). [`Solid::first_within`] is not for such a
    /// solid: it counts every move as hitting at once when the solid has a rod or hollow.
    pub fn of_any(model: &Model, chord: f64) -> Result<Solid, String> {
        Solid::build(model, chord, true)
    }

    fn build(model: &Model, chord: f64, any: bool) -> Result<Solid, String> {
        // Every face's triangulation estimated before any is built (its start grid), and the
        // model refused past the bound: faces bent that finely take minutes and gigabytes.
        let least: Vec<(usize, &str)> = model
            .surfaces
            .iter()
            .filter_map(|s| match &s.geometry {
                Geometry::Face(f) => Some((f.least_vertices(chord), s.name.as_str())),
                _ => None,
            })
            .collect();
        let total: usize = least.iter().map(|l| l.0).sum();
        if total > MAX_VERTICES {
            let (n, name) = least.iter().max().copied().unwrap_or_default();
            return Err(format!(
                "within {chord} mm the faces' triangles need at least {total} vertices (the largest, surface {name}, {n}), more than the {MAX_VERTICES} a model's may have: the faces are too large or too finely bent for the check"
            ));
        }
        // The vertices left to the surfaces tessellated by their parametrisation (patches,
        // cones, tori, bounded cylinders), counted as their grids are refined.
        let left = std::cell::Cell::new(MAX_VERTICES - total);
        let mut solid =
            Solid { pieces: Vec::new(), hollows: Vec::new(), rods: Vec::new(), chord: 0.0, open: Vec::new() };
        for s in &model.surfaces {
            let place = |p: P3| s.placement.map_or(p, |iso| iso * p);
            let turn = |n: V3| s.placement.map_or(n, |iso| iso * n);
            // A surface given by its parametrisation in its own frame, as triangles placed.
            let tessellated = |at: &dyn Fn(f64, f64) -> P3,
                               normal: &dyn Fn(f64, f64) -> Option<V3>,
                               domain: [f64; 4],
                               closed: bool|
             -> Result<(PartPiece, f64), String> {
                let (tris, dev) = surface_triangles(domain, at, normal, s.flip, chord, &left).map_err(|need| {
                    format!(
                        "within {chord} mm the triangles of surface {} need {need} vertices, more than the {} left of the {MAX_VERTICES} a model's may have: the surfaces are too large or too finely bent for the check",
                        s.name,
                        left.get()
                    )
                })?;
                Ok((mesh_piece(&s.name, tris.into_iter().map(|t| t.map(place)), closed && !s.flip)?.0, dev))
            };
            let mut add = |(piece, dev): (PartPiece, f64)| {
                solid.chord = solid.chord.max(dev);
                solid.pieces.push(piece);
            };
            let tau = std::f64::consts::TAU;
            match &s.geometry {
                Geometry::Mesh(m) => {
                    let (piece, closed) = mesh_piece(&s.name, m.corners().map(|t| t.map(place)), true)?;
                    if !closed {
                        solid.open.push(s.name.clone());
                    }
                    add((piece, 0.0))
                }
                Geometry::Patch(p) => {
                    add(tessellated(&|u, v| p.eval(u, v).s, &|u, v| p.normal(u, v), p.domain(), false)?)
                }
                Geometry::Analytic(Analytic::Sphere { centre, radius }) if !s.flip => add((
                    PartPiece {
                        pose: Pose::from_translation(pt(&place(*centre))),
                        shape: SharedShape::ball(*radius),
                        closed_mesh: false,
                    },
                    0.0,
                )),
                Geometry::Analytic(Analytic::Plane { point, normal }) => {
                    let n = turn(if s.flip { -*normal } else { *normal });
                    add((
                        PartPiece {
                            pose: Pose::from_translation(pt(&place(*point))),
                            shape: SharedShape::halfspace(v(&n.normalize())),
                            closed_mesh: false,
                        },
                        0.0,
                    ));
                }
                Geometry::Analytic(Analytic::Sphere { centre, radius }) if any => {
                    solid.hollows.push(Hollow::Cavity { centre: place(*centre), radius: *radius })
                }
                Geometry::Analytic(Analytic::Cylinder { point, axis, radius, from, to }) if any => {
                    let (at, along_axis, radius) = (place(*point), turn(*axis), *radius);
                    let e = crate::model::analytic::any_perpendicular(axis);
                    let radial = |u: f64| e * u.cos() + axis.cross(&e) * u.sin();
                    match (from.is_finite() && to.is_finite(), s.flip) {
                        (false, false) => solid.rods.push(Rod { point: at, axis: along_axis, radius }),
                        (false, true) => solid.hollows.push(Hollow::Bore { point: at, axis: along_axis, radius }),
                        (true, false) => add((
                            PartPiece {
                                pose: along(&(at + along_axis * (0.5 * (from + to))), &along_axis),
                                shape: SharedShape::cylinder(0.5 * (to - from), radius),
                                closed_mesh: false,
                            },
                            0.0,
                        )),
                        (true, true) => add(tessellated(
                            &|u, h| point + axis * h + radial(u) * radius,
                            &|u, _| Some(radial(u)),
                            [0.0, tau, *from, *to],
                            false,
                        )?),
                    }
                }
                Geometry::Analytic(Analytic::Cone { apex, axis, half_angle, from, to }) if any => {
                    let e = crate::model::analytic::any_perpendicular(axis);
                    let radial = |u: f64| e * u.cos() + axis.cross(&e) * u.sin();
                    let (sn, cs, tn) = (half_angle.sin(), half_angle.cos(), half_angle.tan());
                    add(tessellated(
                        &|u, h| apex + axis * h + radial(u) * (h * tn),
                        &|u, _| Some(radial(u) * cs - axis * sn),
                        [0.0, tau, *from, *to],
                        false,
                    )?)
                }
                Geometry::Analytic(Analytic::Torus { centre, axis, major, minor }) if any => {
                    let e = crate::model::analytic::any_perpendicular(axis);
                    let radial = |u: f64| e * u.cos() + axis.cross(&e) * u.sin();
                    let tube = |u: f64, w: f64| radial(u) * w.cos() + axis * w.sin();
                    add(tessellated(
                        &|u, w| centre + radial(u) * *major + tube(u, w) * *minor,
                        &|u, w| Some(tube(u, w)),
                        [0.0, tau, 0.0, tau],
                        true,
                    )?)
                }
                Geometry::Face(f) => {
                    let (tris, dev) = f.triangles(chord).map_err(|e| format!("surface {}: {e}", s.name))?;
                    let turned = tris.into_iter().map(|t| if s.flip { [t[0], t[2], t[1]] } else { t });
                    add((mesh_piece(&s.name, turned.map(|t| t.map(place)), false)?.0, dev))
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
                        "surface {} is {what}: the collision check takes meshes, B-spline patches, STEP faces, spheres and planes; give the part as an STL",
                        s.name
                    ));
                }
            }
        }
        Ok(solid)
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
        self.clearance_below(body, at, reach, f64::NEG_INFINITY)
    }

    /// As [`Solid::clearance`], but stops at the first overlap found deeper than `enough` (a
    /// clearance below it) and returns that one: a yes/no "does the body come nearer than
    /// `enough`?" (`< enough`) at a fraction of the cost when it does.
    pub fn clearance_below(&self, body: &Body, at: &Placement, reach: f64, enough: f64) -> f64 {
        let pose = at.pose();
        let mut best = reach;
        for part in &self.pieces {
            for piece in &body.pieces {
                if best < enough {
                    return best;
                }
                let pos = pose * piece.pose;
                if let (Some(mesh), Some((lo, hi, radius))) = (part.shape.as_trimesh(), piece.span()) {
                    best = best.min(mesh_clearance(part, mesh, piece, &pos, at, (lo, hi, radius), (reach, enough)));
                    continue;
                }
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
        if !self.rods.is_empty() {
            // A finite stretch of each rod, centred level with the tip and reaching past the body
            // by more than `reach`: the same as the unbounded rod within the query's reach.
            let half = body.extent() + reach.max(0.0) + 1.0;
            for rod in &self.rods {
                let centre = rod.point + rod.axis * (at.tip - rod.point).dot(&rod.axis);
                let shape = parry3d_f64::shape::Cylinder::new(half, rod.radius);
                for piece in &body.pieces {
                    let pos = pose * piece.pose;
                    if let Ok(Some(c)) =
                        query::contact(&along(&centre, &rod.axis), &shape, &pos, piece.shape.as_ref(), reach)
                    {
                        best = best.min(c.dist);
                    }
                }
            }
        }
        if !self.hollows.is_empty() {
            let extremes = body.extremes(at);
            for h in &self.hollows {
                best = best.min(h.clearance(&extremes));
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
        if !(self.rods.is_empty() && self.hollows.is_empty()) {
            return Some(0.0);
        }
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

    /// Every analytic surface in [`Solid::of_any`]: a rod and a bore (unbounded cylinders), a
    /// cavity (a flipped sphere) and a bounded rod against closed forms; a torus's closed mesh
    /// answers "inside" and stays within its chord.
    #[test]
    fn of_any_takes_every_analytic_surface() {
        let flat = Body::of(&tool(r#"{"kind": "flat", "radius": 12.5, "length": 40}"#));
        let cyl = |point: P3, axis: V3, radius: f64, length: Option<(f64, f64)>, flip: bool| {
            let (from, to) = length.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
            Solid::of_any(&model(Geometry::Analytic(Analytic::Cylinder { point, axis, radius, from, to }), flip), 1e-3)
                .unwrap()
        };
        // A 1 mm rod along x, 0.2 mm into the side of the upright tool at heights 10 and 39.
        for z in [10.0, 39.0] {
            let rod = cyl(P3::new(0.0, 12.2, z), V3::x(), 0.5, None, false);
            let c = rod.clearance(&flat, &at(P3::new(500.0, 0.0, 0.0), V3::z()), 1.0);
            assert!((c + 0.8).abs() < 1e-6, "{c}");
        }
        // Bounded: the same rod from x = 0 to 40 misses a tool standing at x = 60.
        let rod = cyl(P3::new(0.0, 12.2, 10.0), V3::x(), 0.5, Some((0.0, 40.0)), false);
        assert!(rod.clearance(&flat, &at(P3::new(60.0, 0.0, 0.0), V3::z()), 1.0) >= 1.0);
        assert!((rod.clearance(&flat, &at(P3::new(20.0, 0.0, 0.0), V3::z()), 1.0) + 0.8).abs() < 1e-6);
        // A bore of radius 100 along y through (0, 0, 100): the rim farthest from its axis.
        let bore = cyl(P3::new(0.0, 0.0, 100.0), V3::y(), 100.0, None, true);
        for h in [0.5, 0.1, 3.0] {
            let want = 100.0 - 12.5f64.hypot(100.0 - h);
            let c = bore.clearance(&flat, &at(P3::new(0.0, 7.0, h), V3::z()), 1.0);
            assert!((c - want.min(1.0)).abs() < 1e-9, "{c} vs {want}");
        }
        // Solid::of refuses what its swept cast cannot take.
        let flipped = model(Geometry::Analytic(Analytic::Sphere { centre: P3::origin(), radius: 50.0 }), true);
        assert!(Solid::of(&flipped, 1e-3).is_err());
        // A cavity of radius 50: a ball end mill's lowest point 0.5 above its bottom.
        let cavity = Solid::of_any(
            &model(Geometry::Analytic(Analytic::Sphere { centre: P3::origin(), radius: 50.0 }), true),
            1e-3,
        )
        .unwrap();
        let ball = Body::of(&tool(r#"{"kind": "ball", "radius": 3, "length": 20}"#));
        let c = cavity.clearance(&ball, &at(P3::new(0.0, 0.0, -49.5), V3::z()), 1.0);
        assert!((c - 0.5).abs() < 1e-12, "{c}");
        // A torus: within its chord, and a tip inside its tube is found however small the tool.
        let torus = Analytic::Torus { centre: P3::origin(), axis: V3::z(), major: 20.0, minor: 5.0 };
        let solid = Solid::of_any(&model(Geometry::Analytic(torus), false), 1e-3).unwrap();
        assert!(solid.chord_error() <= 1e-3);
        let small = Body::of(&tool(r#"{"kind": "ball", "radius": 0.5, "length": 1}"#));
        assert!(solid.clearance(&small, &at(P3::new(20.0, 0.0, -1.0), V3::z()), 1.0) < -3.0);
        let c = solid.clearance(&small, &at(P3::new(0.0, 0.0, 0.0), V3::z()), 20.0);
        // The ball's centre is 0.5 up the axis: sqrt(20² + 0.5²) − 5 from the torus.
        assert!((c - (20f64.hypot(0.5) - 5.5)).abs() < 1e-3 + 1e-9, "{c}");
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
        let Geometry::Patch(p) = &m.surfaces[0].geometry else { unreachable!() };
        let left = std::cell::Cell::new(MAX_VERTICES);
        let (tris, _) =
            surface_triangles(p.domain(), &|u, v| p.eval(u, v).s, &|u, v| p.normal(u, v), false, 0.01, &left).unwrap();
        for t in tris.iter().step_by(7) {
            let centre = P3::from((t[0].coords + t[1].coords + t[2].coords) / 3.0);
            assert!(m.nearest(&centre).distance <= 0.01 + 1e-9);
            assert!(m.nearest(&t[0]).distance <= 1e-6);
        }
        // The grid's vertices are taken from those left; a grid past them is refused unbuilt.
        let n = MAX_VERTICES - left.get();
        assert!((81..=1025 * 1025).contains(&n) && (n as f64).sqrt().fract() == 0.0, "{n}");
        let few = std::cell::Cell::new(n - 1);
        let need = surface_triangles(p.domain(), &|u, v| p.eval(u, v).s, &|u, v| p.normal(u, v), false, 0.01, &few);
        assert_eq!(need.unwrap_err(), n);
        assert_eq!(few.get(), n - 1);
        // So is a model of patches that need more in all than a model may have.
        let wiggly: Vec<Vec<P3>> = (0..6)
            .map(|i| {
                (0..6)
                    .map(|j| P3::new(20.0 * i as f64, 20.0 * j as f64, if (i + j) % 2 == 0 { 20.0 } else { -20.0 }))
                    .collect()
            })
            .collect();
        let mut m = model(Geometry::Patch(crate::model::patch::BSpline::new(&wiggly, [3, 3], None, None)), false);
        let one = m.surfaces[0].clone();
        m.surfaces.push(one.clone());
        m.surfaces.push(one);
        let e = Solid::of(&m, 1e-5).err().expect("refused");
        assert!(e.contains("left of the 2000000 a model's may have"), "{e}");
    }
}
