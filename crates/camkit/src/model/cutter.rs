//! APT-style cutters on a fixed axis and their drop onto one triangle (the drop-cutter problem):
//! the highest tool tip at which the cutter, extended upward along its axis, touches the
//! triangle. Everything here is in the axis frame: the tool axis is +z, the tip at height `tip`.
//!
//! The cutter's lower surface is z = tip + f(ρ) for ρ ≤ R, ρ the distance from the axis, with f
//! convex and nondecreasing (flat: 0; ball, bull: a quarter circle of the corner radius beyond
//! the flat part; cone: ρ / tan α). So for a point p of the model the tip that touches it is
//! g(p) = p.z − f(ρ(p)), concave over any convex piece of the model, and the drop onto a triangle
//! is the largest g over the triangle within the cutter's shadow: at a stationary point inside
//! the facet (the facet test), else on an edge (the edge test: g concave along it, so its largest
//! value is the stationary point clamped to the edge's stretch in the shadow), or at a corner
//! (the vertex test). The edge test of the bull-nose is the one without a closed form: the
//! stationary point is found by bisection on g′, which is decreasing, until the concavity bound
//! g′(a)·(b − a) on what is left is below [`EDGE_TOL`].

use crate::geom::{P3, V3};

/// What the bisection of the bull-nose edge test leaves (mm): the proven bound on the difference
/// between the returned tip and the exact one.
pub const EDGE_TOL: f64 = 1e-10;

/// A cutter: radius R and its profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cutter {
    /// Flat (square) end mill of radius R.
    Flat {
        /// R (mm).
        radius: f64,
    },
    /// Ball end mill of radius R.
    Ball {
        /// R (mm).
        radius: f64,
    },
    /// Bull-nose end mill: flat bottom of radius R − r, corners of radius r (0 < r ≤ R).
    Bull {
        /// R (mm).
        radius: f64,
        /// r (mm).
        corner: f64,
    },
    /// Cone of radius R and half-angle α (radians, between the axis and the flank), tip at
    /// the axis, a cylinder of radius R above the cone.
    Cone {
        /// R (mm).
        radius: f64,
        /// α (radians).
        half_angle: f64,
    },
}

/// A drop onto one feature: the tip height and the contact point (axis frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Touch {
    /// Tip height.
    pub tip: f64,
    /// Contact point.
    pub contact: P3,
}

/// Which corners and edges of a triangle its drop tests (bit k: corner k, edge from corner k to
/// corner k + 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Owned {
    /// Corners tested here.
    pub corners: u8,
    /// Edges tested here.
    pub edges: u8,
    /// Edges tested here from corner k + 1 to corner k as well: another triangle runs them that
    /// way, and the two directions round differently.
    pub reversed: u8,
}

impl Owned {
    /// Every corner and edge, each one way.
    pub const ALL: Owned = Owned { corners: 0b111, edges: 0b111, reversed: 0 };
}

/// One way along an edge: its unit direction and length seen along the axis, its slope m and
/// √(1 + m²) (the same for every drop, so worked out once).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Run {
    ex: f64,
    ey: f64,
    len: f64,
    m: f64,
    root: f64,
}

impl Run {
    /// From `a` to `b`; `None` for an edge along the axis (its upper corner is the vertex test's).
    pub fn new(a: &P3, b: &P3) -> Option<Run> {
        let (ex, ey) = (b.x - a.x, b.y - a.y);
        let len = ex.hypot(ey);
        if len <= 1e-12 {
            return None;
        }
        let m = (b.z - a.z) / len;
        Some(Run { ex: ex / len, ey: ey / len, len, m, root: (1.0 + m * m).sqrt() })
    }

    /// The other way (bit for bit what [`Run::new`] gives from `b` to `a`).
    fn reversed(&self) -> Run {
        Run { ex: -self.ex, ey: -self.ey, len: self.len, m: -self.m, root: self.root }
    }
}

/// A triangle ready for drops of one cutter: corners, unit normal (n.z ≥ 0), the features it
/// tests, its edges' runs and where the cutter touches its plane (what depends on the cutter and
/// the triangle alone is worked out once).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Facet {
    /// Corners.
    pub t: [P3; 3],
    /// Unit normal with n.z ≥ 0.
    pub n: V3,
    /// The corners and edges it tests.
    pub own: Owned,
    runs: [Option<Run>; 3],
    /// Its plane, if not along the axis.
    plane: Option<Plane>,
}

impl Facet {
    /// The triangle `t` of unit normal `n` (n.z ≥ 0) for `cutter`.
    pub fn new(cutter: &Cutter, t: [P3; 3], n: V3, own: Owned) -> Facet {
        let runs = [0, 1, 2].map(|k| Run::new(&t[k], &t[(k + 1) % 3]));
        let plane = (n.z > 1e-12).then(|| Plane::new(cutter, t[0], n));
        Facet { t, n, own, runs, plane }
    }
}

/// A plane not along the axis ready for drops of one cutter: a point, the unit normal (n.z > 0)
/// and where the cutter touches it ([`Cutter::plane_contact`], and |n.x, n.y|).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    a: P3,
    n: V3,
    rho: f64,
    above: f64,
    h: f64,
}

impl Plane {
    /// The plane through `a` of unit normal `n` (n.z > 0) for `cutter`.
    pub fn new(cutter: &Cutter, a: P3, n: V3) -> Plane {
        let (rho, above) = cutter.plane_contact(&n);
        Plane { a, n, rho, above, h: n.x.hypot(n.y) }
    }
}

/// The upper boundary of the capsule of radius `r` ≥ 0 around the segment `e1`–`e2` (ρ, z) at
/// `rho`: its height, the nearest point of the segment to it, and the segment's unit normal
/// pointing up (towards that boundary point where r > 0 and it is not the normal's).
fn capsule_top(rho: f64, e1: [f64; 2], e2: [f64; 2], r: f64) -> Option<(f64, [f64; 2], [f64; 2])> {
    let (dr, dz) = (e2[0] - e1[0], e2[1] - e1[1]);
    let len = dr.hypot(dz);
    let n = if dr >= 0.0 { [-dz / len, dr / len] } else { [dz / len, -dr / len] };
    let mut best: Option<(f64, [f64; 2], [f64; 2])> = None;
    let mut take = |h: f64, foot: [f64; 2], n: [f64; 2]| {
        if best.is_none_or(|b| h > b.0) {
            best = Some((h, foot, n));
        }
    };
    // The ends' arcs.
    for e in [e1, e2] {
        let off = rho - e[0];
        if off.abs() <= r {
            let up = (r * r - off * off).sqrt();
            let dir = if r > 0.0 { [off / r, up / r] } else { n };
            take(e[1] + up, e, dir);
        }
    }
    // The side offset by r along the normal (none for a segment along the axis).
    if dr != 0.0 {
        let s = (rho - r * n[0] - e1[0]) / dr;
        if (0.0..=1.0).contains(&s) {
            let foot = [e1[0] + s * dr, e1[1] + s * dz];
            take(foot[1] + r * n[1], foot, n);
        }
    }
    best
}

/// Smallest n.z of a triangle whose plane's drop is taken as a bound of its tips.
const PLANE_BOUND: f64 = 1e-6;

/// The facet test's inside check: `c` lies in the triangle seen along z (either turn).
fn inside(t: &[P3; 3], c: &P3) -> bool {
    let side = |a: &P3, b: &P3| (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    let (s0, s1, s2) = (side(&t[0], &t[1]), side(&t[1], &t[2]), side(&t[2], &t[0]));
    (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0)
}

impl Touch {
    /// The higher of two touches (the first on a tie).
    pub fn max(a: Option<Touch>, b: Option<Touch>) -> Option<Touch> {
        match (a, b) {
            (Some(x), Some(y)) => Some(if y.tip > x.tip { y } else { x }),
            (x, None) => x,
            (None, y) => y,
        }
    }
}

impl Cutter {
    /// R.
    pub fn radius(&self) -> f64 {
        match *self {
            Cutter::Flat { radius } | Cutter::Ball { radius } | Cutter::Bull { radius, .. } => radius,
            Cutter::Cone { radius, .. } => radius,
        }
    }

    /// Flat, ball and bull as a torus: (flat radius c = R − r, corner r).
    fn torus(&self) -> Option<(f64, f64)> {
        match *self {
            Cutter::Flat { radius } => Some((radius, 0.0)),
            Cutter::Ball { radius } => Some((0.0, radius)),
            Cutter::Bull { radius, corner } => Some((radius - corner, corner)),
            Cutter::Cone { .. } => None,
        }
    }

    /// f(ρ): height of the cutter's lower surface above the tip at distance ρ ≤ R from the axis.
    pub fn height(&self, rho: f64) -> f64 {
        match *self {
            Cutter::Cone { half_angle, .. } => rho / half_angle.tan(),
            _ => {
                let (c, r) = self.torus().expect("a torus-type cutter");
                if rho <= c { 0.0 } else { r - (r * r - (rho - c) * (rho - c)).max(0.0).sqrt() }
            }
        }
    }

    /// f′(ρ) (infinite at the rim of a ball or bull-nose).
    pub(crate) fn slope(&self, rho: f64) -> f64 {
        match *self {
            Cutter::Cone { half_angle, .. } => 1.0 / half_angle.tan(),
            _ => {
                let (c, r) = self.torus().expect("a torus-type cutter");
                if rho <= c {
                    0.0
                } else {
                    let e = rho - c;
                    e / (r * r - e * e).max(0.0).sqrt()
                }
            }
        }
    }

    /// The drop onto a triangle (corners `t`, unit normal `n` with n.z ≥ 0) at `q` = (x, y);
    /// edges that cannot give a tip above `floor` are not solved (−∞: every one is).
    pub fn drop_triangle(&self, q: [f64; 2], t: &[P3; 3], n: &V3, floor: f64) -> Option<Touch> {
        self.drop_facet(q, &Facet::new(self, *t, *n, Owned::ALL), floor)
    }

    /// The drop onto a triangle testing only the corners and edges it owns (a mesh tests each
    /// shared one in one triangle); nothing when no tip of the triangle can be above `floor`.
    pub fn drop_facet(&self, q: [f64; 2], f: &Facet, floor: f64) -> Option<Touch> {
        let (t, n, own) = (&f.t, &f.n, f.own);
        let plane = f.plane.as_ref().map(|p| self.drop_on(q, p));
        // The triangle lies in its plane, so the plane's drop bounds all its tips (taken where
        // the plane is not near the axis, raised for rounding).
        if n.z > PLANE_BOUND && plane.is_some_and(|p| p.tip + super::drop::PLANE_MARGIN <= floor) {
            return None;
        }
        let mut best = None;
        for (k, p) in t.iter().enumerate() {
            if own.corners & (1 << k) != 0 {
                best = Touch::max(best, self.drop_point(q, p));
            }
        }
        best = Touch::max(best, plane.filter(|p| inside(t, &p.contact)));
        let floor = best.map_or(floor, |b| b.tip.max(floor));
        for k in 0..3 {
            let Some(run) = f.runs[k].filter(|_| own.edges & (1 << k) != 0) else { continue };
            let (a, b) = (&t[k], &t[(k + 1) % 3]);
            let e = self.drop_run(q, a, b, &run, floor);
            best = Touch::max(best, e);
            // Run the other way the rounding differs (the tip by far less than 1e-9, but at
            // the rim of a ball an end may fall inside the shadow one way only): solved again
            // unless its tip is clearly below, so the result is the larger of both as if each
            // triangle had solved it.
            if own.reversed & (1 << k) != 0 && e.is_none_or(|e| e.tip >= floor - 1e-9) {
                best = Touch::max(best, self.drop_run(q, b, a, &run.reversed(), floor));
            }
        }
        best
    }

    /// The vertex test: the tip touching point `p`, if it lies in the shadow.
    pub fn drop_point(&self, q: [f64; 2], p: &P3) -> Option<Touch> {
        let rho = (p.x - q[0]).hypot(p.y - q[1]);
        (rho <= self.radius()).then(|| Touch { tip: p.z - self.height(rho), contact: *p })
    }

    /// Where the cutter touches a plane of unit normal `n` (n.z > 0): the contact's distance
    /// from the axis (against the normal's horizontal part) and height above the tip.
    pub fn plane_contact(&self, n: &V3) -> (f64, f64) {
        let h = n.x.hypot(n.y);
        match *self {
            Cutter::Cone { radius, half_angle } => {
                // The plane's slope against the flank's: below it the tip touches, above it the rim.
                if h / n.z > 1.0 / half_angle.tan() { (radius, radius / half_angle.tan()) } else { (0.0, 0.0) }
            }
            _ => {
                let (c, r) = self.torus().expect("a torus-type cutter");
                if h <= 1e-15 { (0.0, 0.0) } else { (c + r * h, r * (1.0 - n.z)) }
            }
        }
    }

    /// The drop onto the plane through `a` with unit normal `n` (n.z > 0) at `q`: the tip and
    /// the contact point.
    pub fn drop_plane(&self, q: [f64; 2], a: &P3, n: &V3) -> Touch {
        self.drop_on(q, &Plane::new(self, *a, *n))
    }

    /// [`Cutter::drop_plane`] onto a prepared plane.
    pub fn drop_on(&self, q: [f64; 2], p: &Plane) -> Touch {
        let Plane { a, n, rho, above, h } = p;
        let (rho, above, h) = (*rho, *above, *h);
        let (cx, cy) = if rho > 0.0 { (q[0] - rho * n.x / h, q[1] - rho * n.y / h) } else { (q[0], q[1]) };
        let z = a.z - (n.x * (cx - a.x) + n.y * (cy - a.y)) / n.z;
        Touch { tip: z - above, contact: P3::new(cx, cy, z) }
    }

    /// The edge test: the largest g along the edge from `a` to `b` within the shadow, if it can
    /// be above `floor`.
    pub fn drop_edge(&self, q: [f64; 2], a: &P3, b: &P3, floor: f64) -> Option<Touch> {
        self.drop_run(q, a, b, &Run::new(a, b)?, floor)
    }

    /// [`Cutter::drop_edge`] given the edge's [`Run`].
    fn drop_run(&self, q: [f64; 2], a: &P3, b: &P3, run: &Run, floor: f64) -> Option<Touch> {
        let Run { ex, ey, len, m, root } = *run;
        // s along the edge from the foot of q, d the distance of q from the edge's line.
        let s1 = (a.x - q[0]) * ex + (a.y - q[1]) * ey;
        let d = ((a.x - q[0]) * ey - (a.y - q[1]) * ex).abs();
        let big_r = self.radius();
        // No point of the edge is nearer the axis than its line: its top less f(d) bounds its
        // tips (d taken 1e-9 nearer so rounding never lowers the bound where f is steep).
        if d > big_r || a.z.max(b.z) - self.height((d - 1e-9).max(0.0)) <= floor {
            return None;
        }
        let w = (big_r * big_r - d * d).sqrt();
        let (lo, hi) = (s1.max(-w), (s1 + len).min(w));
        if lo > hi {
            return None;
        }
        let z = |s: f64| a.z + m * (s - s1);
        let g = |s: f64| z(s) - self.height(d.hypot(s).min(big_r));
        let s = match *self {
            Cutter::Flat { .. } => {
                if m >= 0.0 {
                    hi
                } else {
                    lo
                }
            }
            Cutter::Ball { .. } => (m * w / root).clamp(lo, hi),
            Cutter::Cone { half_angle, .. } => {
                let k = m * half_angle.tan();
                if k >= 1.0 {
                    hi
                } else if k <= -1.0 {
                    lo
                } else {
                    (d * k / (1.0 - k * k).sqrt()).clamp(lo, hi)
                }
            }
            Cutter::Bull { .. } => {
                // g′(s) = m − f′(ρ)·s/ρ decreases (g is concave): bisect its sign change.
                let dg = |s: f64| {
                    let rho = d.hypot(s);
                    if rho == 0.0 { m } else { m - self.slope(rho) * s / rho }
                };
                let (mut a_s, mut b_s) = (lo, hi);
                let (mut da, mut db) = (dg(a_s), dg(b_s));
                if da <= 0.0 {
                    lo
                } else if db >= 0.0 {
                    hi
                } else {
                    // g lies under its tangents at both ends (concave): where they meet bounds
                    // it (a vertical tangent at the rim bounds nothing), 1e-9 up for rounding.
                    let (ga, gb, span) = (g(lo), g(hi), hi - lo);
                    let bound = if da.is_finite() && db.is_finite() {
                        // They meet at lo + x, x = (gb − ga − g′(b)·span) / (g′(a) − g′(b)),
                        // written so the rounding is relative to the rise above ga.
                        let meet = ga + (gb - ga - db * span) * (da / (da - db));
                        meet.min(ga + da * span).min(gb - db * span)
                    } else if da.is_finite() {
                        ga + da * span
                    } else if db.is_finite() {
                        gb - db * span
                    } else {
                        f64::INFINITY
                    };
                    if bound + 1e-9 <= floor {
                        return None;
                    }
                    // The largest g lies under the tangents at both ends: at most
                    // min(g′(a), −g′(b))·(b − a) above the better end.
                    for _ in 0..200 {
                        if da.min(-db) * (b_s - a_s) <= EDGE_TOL {
                            break;
                        }
                        let mid = 0.5 * (a_s + b_s);
                        if mid <= a_s || mid >= b_s {
                            break;
                        }
                        let dm = dg(mid);
                        if dm > 0.0 {
                            (a_s, da) = (mid, dm);
                        } else {
                            (b_s, db) = (mid, dm);
                        }
                    }
                    if g(a_s) >= g(b_s) { a_s } else { b_s }
                }
            }
        };
        let t = (s - s1) / len;
        let contact = P3::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, z(s));
        Some(Touch { tip: g(s), contact })
    }

    /// The drop onto a circle of radius `rho` in the vertical plane through the axis, its centre
    /// at distance `d` ≥ 0 from the axis and height `cz` (a sphere's or a cylinder across the
    /// axis's section): the tip and the contact as (distance from the axis towards the centre,
    /// height). Exact: the cutter's section is its profile.
    pub fn drop_circle(&self, d: f64, cz: f64, rho: f64) -> Option<(f64, f64, f64)> {
        match *self {
            Cutter::Cone { radius, half_angle } => {
                let k = 1.0 / half_angle.tan();
                let (sa, ca) = half_angle.sin_cos();
                let mut best: Option<(f64, f64, f64)> = None;
                let mut take = |c: Option<(f64, f64, f64)>| {
                    if let Some(c) = c {
                        if best.is_none_or(|b| c.0 > b.0) {
                            best = Some(c);
                        }
                    }
                };
                // The tip on the circle.
                take((d <= rho).then(|| {
                    let t = cz + (rho * rho - d * d).sqrt();
                    (t, 0.0, t)
                }));
                // The rim on the circle.
                take(((d - radius).abs() <= rho).then(|| {
                    let top = cz + (rho * rho - (d - radius) * (d - radius)).sqrt();
                    (top - k * radius, radius, top)
                }));
                // The flank tangent to the circle, where the tangent point is on the flank.
                let (cr, cz_) = (d - rho * ca, cz + rho * sa);
                take((0.0..=radius).contains(&cr).then(|| (cz + (rho - d * ca) / sa, cr, cz_)));
                best
            }
            _ => {
                let (c, r) = self.torus().expect("a torus-type cutter");
                // The cutter is the flat disc of radius c grown by r: touching means the disc is
                // r + rho from the centre.
                let m = (d - c).max(0.0);
                if m > rho + r {
                    return None;
                }
                let up = ((rho + r) * (rho + r) - m * m).sqrt();
                let s = rho / (rho + r);
                Some((cz + up - r, d - m * s, cz + up * s))
            }
        }
    }

    /// The drop onto a torus whose axis is the tool axis's direction, its centre at distance
    /// `d` ≥ 0 from the tool axis and height `cz`: the tip and the contact as (distance from the
    /// torus's axis towards the tool axis, height); `None` for a cone (not handled) or where the
    /// torus is not under the cutter. Exact: a flat, ball or bull-nose is a disc of radius c grown
    /// by r, so it touches the torus where the disc touches the torus grown by r (its tube
    /// `minor` + r), whose height at distance ρ from its axis depends on ρ alone and is highest
    /// at ρ = `major`; the disc spans ρ over [d − c, d + c] (from 0 if it holds the axis).
    pub fn drop_torus(&self, d: f64, cz: f64, major: f64, minor: f64) -> Option<(f64, f64, f64)> {
        let (c, r) = self.torus()?;
        let tube = minor + r;
        let rho = major.clamp((d - c).max(0.0), d + c);
        let off = rho - major;
        if off.abs() > tube {
            return None;
        }
        let up = (tube * tube - off * off).sqrt();
        // The contact: from the tube's centre circle towards the grown torus's point, minor away.
        let s = minor / tube;
        Some((cz + up - r, major + off * s, cz + up * s))
    }

    /// The drop onto a surface of revolution about an axis parallel to the tool axis whose
    /// section is the segment `e1`–`e2` (distance from its axis, height; a finite cone's), its
    /// axis at distance `d` ≥ 0 from the tool axis: the tip and the contact as (signed distance
    /// from the surface's axis towards the tool axis, height), and the section's unit normal
    /// there (pointing up); `None` for a cone cutter or where the surface is not under the
    /// cutter. Exact: a flat, ball or bull-nose is a disc of radius c grown by r, touching where
    /// the disc touches the surface grown by r, whose section is the segment's capsule of
    /// radius r and its mirror across the axis; the capsule's upper boundary H is concave, so its
    /// largest value over the disc's span [d − c, d + c] (from 0) is at its top clamped to it.
    pub fn drop_section(&self, d: f64, e1: [f64; 2], e2: [f64; 2]) -> Option<(f64, [f64; 2], [f64; 2])> {
        let (c, r) = self.torus()?;
        let (lo, hi) = ((d - c).max(0.0), d + c);
        let top = if e1[1] >= e2[1] { e1[0] } else { e2[0] };
        let mut best: Option<(f64, [f64; 2], [f64; 2])> = None;
        // The capsule, then its mirror: H(−ρ) over the span is H over the span mirrored.
        for (sign, (a, b)) in [(1.0, (lo, hi)), (-1.0, (-hi, -lo))] {
            let rho = top.clamp(a, b);
            if let Some((h, foot, n)) = capsule_top(rho, e1, e2, r) {
                if best.is_none_or(|x| h - r > x.0) {
                    best = Some((h - r, [sign * foot[0], foot[1]], [sign * n[0], n[1]]));
                }
            }
        }
        best
    }

    /// The model's unit normal at a contact (pointing out of the model, into the cutter) where
    /// the cutter's surface is smooth; `fallback` (the model's own normal) where the contact is
    /// on a corner of the cutter (a flat's or cone's rim, a cone's tip).
    pub fn contact_normal(&self, q: [f64; 2], tip: f64, contact: &P3, fallback: V3) -> V3 {
        const EDGE: f64 = 1e-9;
        let (dx, dy) = (contact.x - q[0], contact.y - q[1]);
        let rho = dx.hypot(dy);
        match *self {
            Cutter::Cone { radius, half_angle } => {
                if rho < EDGE || rho > radius - EDGE {
                    return fallback;
                }
                let (sa, ca) = half_angle.sin_cos();
                V3::new(-ca * dx / rho, -ca * dy / rho, sa)
            }
            _ => {
                let (c, r) = self.torus().expect("a torus-type cutter");
                if rho < c - EDGE {
                    return V3::z();
                }
                if r == 0.0 {
                    return fallback;
                }
                let (ux, uy) = if rho > 0.0 { (dx / rho, dy / rho) } else { (0.0, 0.0) };
                let ring = P3::new(q[0] + c * ux, q[1] + c * uy, tip + r);
                (ring - contact).try_normalize(1e-15).unwrap_or(fallback)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The largest g over a dense sampling of the triangle (independent of the three tests).
    fn sampled(c: &Cutter, q: [f64; 2], t: &[P3; 3], n: usize) -> f64 {
        let mut best = f64::NEG_INFINITY;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let p = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v;
                let rho = (p.x - q[0]).hypot(p.y - q[1]);
                if rho <= c.radius() {
                    best = best.max(p.z - c.height(rho));
                }
            }
        }
        best
    }

    fn cutters() -> impl Strategy<Value = Cutter> {
        prop_oneof![
            (0.5..5.0f64).prop_map(|radius| Cutter::Flat { radius }),
            (0.5..5.0f64).prop_map(|radius| Cutter::Ball { radius }),
            (0.5..5.0f64, 0.05..1.0f64).prop_map(|(radius, k)| Cutter::Bull { radius, corner: radius * k }),
            (0.5..5.0f64, 0.2..1.4f64).prop_map(|(radius, half_angle)| Cutter::Cone { radius, half_angle }),
        ]
    }

    proptest! {
        /// At the returned tip the cutter touches the triangle (the contact is on it with g = tip)
        /// and no sampled point of it is above the cutter's surface.
        #[test]
        fn touches_without_penetrating(
            c in cutters(),
            pts in prop::array::uniform9(-4.0..4.0f64),
            q in prop::array::uniform2(-3.0..3.0f64),
        ) {
            let t = [P3::new(pts[0], pts[1], pts[2]), P3::new(pts[3], pts[4], pts[5]), P3::new(pts[6], pts[7], pts[8])];
            let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
            prop_assume!(n.norm() > 1e-3);
            let n = if n.z < 0.0 { -n.normalize() } else { n.normalize() };
            let touch = c.drop_triangle(q, &t, &n, f64::NEG_INFINITY);
            let brute = sampled(&c, q, &t, 120);
            match touch {
                None => prop_assert!(brute == f64::NEG_INFINITY, "missed: sampled {brute}"),
                Some(tc) => {
                    prop_assert!(brute <= tc.tip + 1e-9, "penetrates by {}", brute - tc.tip);
                    // The contact is on the triangle (on its plane, inside) and g there is the tip.
                    let p = tc.contact;
                    prop_assert!((p - t[0]).dot(&n).abs() < 1e-9);
                    let rho = (p.x - q[0]).hypot(p.y - q[1]);
                    prop_assert!(rho <= c.radius() + 1e-9);
                    prop_assert!((p.z - c.height(rho.min(c.radius())) - tc.tip).abs() < 1e-9);
                    // Sampling comes close from below: the exact drop is not far above the samples.
                    prop_assert!(tc.tip - brute < 0.2, "sampled {brute}, exact {}", tc.tip);
                }
            }
        }
    }

    #[test]
    fn bull_on_a_tilted_plane_is_the_closed_form() {
        // Plane z = x·tanθ; the bull's disc (radius c at height tip + r) is r from it:
        // tip = (x + c)·tanθ + r·(1/cosθ − 1).
        for (radius, corner, theta) in [(5.0, 1.0, 0.3), (3.0, 3.0, 1.1), (4.0, 0.5, 0.01)] {
            let c = Cutter::Bull { radius, corner };
            let n = V3::new(-f64::sin(theta), 0.0, theta.cos());
            for x in [-2.0, 0.0, 3.5] {
                let want = (x + radius - corner) * theta.tan() + corner * (1.0 / theta.cos() - 1.0);
                let got = c.drop_plane([x, 1.0], &P3::origin(), &n).tip;
                assert!((got - want).abs() < 1e-12, "{got} vs {want}");
                // The same plane as one big triangle: the facet test agrees.
                let t = [
                    P3::new(-50.0, -50.0, -50.0 * theta.tan()),
                    P3::new(50.0, -50.0, 50.0 * theta.tan()),
                    P3::new(0.0, 50.0, 0.0),
                ];
                let tri = c.drop_triangle([x, 1.0], &t, &n, f64::NEG_INFINITY).unwrap().tip;
                assert!((tri - want).abs() < 1e-9, "{tri} vs {want}");
            }
        }
    }

    #[test]
    fn bull_edge_is_within_its_bound() {
        // A horizontal edge at height 0 along y, q at distance d across: the bull's section at d
        // reaches the edge where its profile does: tip = −f(d).
        let c = Cutter::Bull { radius: 4.0, corner: 1.5 };
        for d in [0.0, 2.0, 3.0, 3.9] {
            let t =
                c.drop_edge([-d, 0.3], &P3::new(0.0, -10.0, 0.0), &P3::new(0.0, 10.0, 0.0), f64::NEG_INFINITY).unwrap();
            assert!((t.tip + c.height(d)).abs() <= EDGE_TOL, "d {d}: {}", t.tip);
        }
        // A sloped edge: compare with a fine sampling of g along it.
        let (a, b) = (P3::new(-5.0, 1.2, -3.0), P3::new(5.0, 1.2, 4.0));
        let t = c.drop_edge([0.0, 0.0], &a, &b, f64::NEG_INFINITY).unwrap();
        let mut best = f64::NEG_INFINITY;
        for k in 0..=2_000_000 {
            let p = a + (b - a) * (k as f64 / 2e6);
            let rho = p.x.hypot(p.y);
            if rho <= 4.0 {
                best = best.max(p.z - c.height(rho));
            }
        }
        assert!(t.tip >= best - 1e-12 && t.tip - best < 1e-8, "{} vs sampled {best}", t.tip);
    }
}
