//! The edge-trajectory model of paper 003 (eq. 1–5), generalised to any straight move with a
//! fixed tool axis, and the exact lowest cut of the flutes over one vertical line.
//!
//! A point of flute n at angle ξ from the axis sits at `C(θ) + r sin ξ (cos φ û + sin φ v̂)
//! − r cos ξ ŵ`, with the ball centre `C(θ) = C0 + θ·D` moving linearly with the spindle angle θ
//! and the flute angle `φ = φ0 + (n−1)·2π/Z + σθ` (σ = ±1, the sense of rotation). For the
//! paper's case (feed F along y, tilt ζ about y) `D = (0, F/2πN, 0)`, `ŵ = (sin ζ, 0, cos ζ)`,
//! `û = (cos ζ, 0, −sin ζ)`, `v̂ = ŷ`, which is eq. 5 with the ball centre as reference.
//!
//! The machined surface over a point (x, y) is the lowest edge point that ever passes over it.
//! Seen from the moving (not turning) tool, the vertical line through (x, y) slides across the
//! ball and meets its lower half on a circle arc, parametrised by γ: along-track offset
//! `s = ρ sin γ`, depth `ρ cos γ`, `ρ = √(r² − d²)` with d the cross-track offset. A flute passes
//! through the line's point γ exactly when `G(γ) = α(γ) + σ s/a` (α the point's angle about the
//! axis, a the feed per radian) equals the flute's angle reference modulo 2π/Z. G's derivative
//! has the sign of a trigonometric polynomial of degree 3 and α's of one of degree 1, so their
//! zeros (found with certified isolation) cut the arc into pieces on which both are monotone:
//! on each piece the level crossings are counted exactly and solved by safeguarded Newton. The
//! cut height is unimodal in γ, so searching outward from its minimum, the first crossing on
//! each side is the lowest. The result is the exact envelope to round-off (≈1e-12 mm), not a
//! sampled one.

use crate::cutter::Cutter;
use crate::trig::{Trig3, intersect, trig1_nonpositive, trig1_zeros, wrap_pi};
use camkit::geom::{P3, V3};
use std::f64::consts::FRAC_PI_2;

/// Below this feed per radian (mm/rad) a move is a plunge: the tool does not travel sideways.
pub const PLUNGE_FEED: f64 = 1e-12;
/// A line passing closer than this (mm) to the tip (or to the flat's centre) is cut by it.
pub const TIP_EPS: f64 = 1e-10;
/// Newton and bisection stop when the parameter moves less than this (rad).
const SOLVE_TOL: f64 = 1e-14;
/// Newton stops after a step shorter than this (rad): the error left is of its square's order.
const NEWTON_STOP: f64 = 1e-7;
/// Relative slack (of the angles' magnitude) within which a flute passing a piece's start is
/// taken as passing it: a few ulps of G.
const LEVEL_SLACK: f64 = 1e-12;
/// Pieces are split until α changes by less than this along each (rad, below π).
const PIECE_TURN: f64 = 3.0;

/// Tool axis frame: ŵ along the axis toward the shank, û the direction of flute angle 0,
/// v̂ = ŵ × û.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Direction of flute angle 0.
    pub u: V3,
    /// ŵ × û.
    pub v: V3,
    /// Axis, tip to shank.
    pub w: V3,
}

impl Frame {
    /// The paper's frame for a tilt ζ (rad) of the axis toward +x about the y axis (eq. 3).
    pub fn tilted(zeta: f64) -> Frame {
        Frame {
            u: V3::new(zeta.cos(), 0.0, -zeta.sin()),
            v: V3::new(0.0, 1.0, 0.0),
            w: V3::new(zeta.sin(), 0.0, zeta.cos()),
        }
    }

    /// A frame about any unit axis: û is the world x axis (or y, for an axis near x) made
    /// perpendicular to it.
    pub fn about(axis: V3) -> Frame {
        let w = axis.normalize();
        let refd = if w.x.abs() < 0.9 { V3::x() } else { V3::y() };
        let u = (refd - w * refd.dot(&w)).normalize();
        Frame { u, v: w.cross(&u), w }
    }
}

/// One straight move of the tool with a fixed axis and a turning spindle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Move {
    /// Ball centre at the start (mm).
    pub c0: P3,
    /// Displacement of the ball centre per radian of spindle rotation (mm/rad): F/(2πN) along
    /// the feed direction.
    pub dc: V3,
    /// Spindle rotation over the move (rad).
    pub span: f64,
    /// Angle of flute 1 at the start (rad), measured from û about ŵ.
    pub phase: f64,
    /// Tool axis frame.
    pub frame: Frame,
}

/// Which part of the flute made a cut.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Zone {
    /// The ball part of a flute (ξ from ξ0 to 90°).
    Ball,
    /// The tip point ξ = 0, shared by every flute.
    Tip,
    /// The flat ground at the tip (paper eq. 6–7).
    Flat,
}

/// The lowest cut over one vertical line by one move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cut {
    /// Height of the cut (mm).
    pub z: f64,
    /// Spindle angle since the move's start when the cut happens (rad).
    pub theta: f64,
    /// Flute index 0..Z (0 also for the tip, which every flute shares).
    pub flute: u32,
    /// Distance of the cutting point from the tool axis (mm): r sin ξ on the ball.
    pub radial: f64,
    /// The part of the flute that cut.
    pub zone: Zone,
}

impl Move {
    /// Ball centre at spindle angle θ.
    pub fn centre(&self, theta: f64) -> P3 {
        self.c0 + self.dc * theta
    }

    /// Angle of flute `n` (0-based) at spindle angle θ (rad).
    pub fn flute_angle(&self, cutter: &Cutter, n: u32, theta: f64) -> f64 {
        self.phase + n as f64 * cutter.pitch() + cutter.rotation.sign() * theta
    }

    /// Forward kinematics (eq. 5): the point at `radial` distance from the axis on flute `n`
    /// at spindle angle θ, on the ball (radial ≥ r0) or on the flat (radial ≤ r0).
    pub fn edge_point(&self, cutter: &Cutter, n: u32, theta: f64, radial: f64) -> P3 {
        let phi = self.flute_angle(cutter, n, theta);
        let r = cutter.radius;
        let axial =
            if radial >= cutter.flat_radius { (r * r - radial * radial).max(0.0).sqrt() } else { cutter.flat_depth() };
        let f = &self.frame;
        self.centre(theta) + (f.u * phi.cos() + f.v * phi.sin()) * radial - f.w * axial
    }

    /// Feed per radian of spindle rotation in the horizontal plane (mm/rad).
    pub fn feed_per_radian(&self) -> f64 {
        self.dc.x.hypot(self.dc.y)
    }

    /// A lower bound of any cut of this move over (x, y): the ball's lower surface at its
    /// closest approach; `None` if the ball never reaches over the point.
    pub fn lower_bound(&self, cutter: &Cutter, x: f64, y: f64) -> Option<f64> {
        let r = cutter.radius;
        let (rx, ry) = (x - self.c0.x, y - self.c0.y);
        let a = self.feed_per_radian();
        if a < PLUNGE_FEED {
            let rho2 = r * r - rx * rx - ry * ry;
            return (rho2 >= 0.0).then(|| self.c0.z.min(self.centre(self.span).z) - rho2.sqrt());
        }
        let (hx, hy) = (self.dc.x / a, self.dc.y / a);
        let d = -hy * rx + hx * ry;
        let s_node = hx * rx + hy * ry;
        let rho2 = r * r - d * d;
        if rho2 < 0.0 {
            return None;
        }
        let rho = rho2.sqrt();
        let k = self.dc.z / a;
        let (lo, hi) = (((s_node - a * self.span) / rho).max(-1.0), (s_node / rho).min(1.0));
        if lo > hi {
            return None;
        }
        let gm = k.atan().clamp(lo.asin(), hi.asin());
        Some(self.c0.z + k * s_node - k * rho * gm.sin() - rho * gm.cos())
    }
}

/// The lowest cut of `mv` over (x, y), by every flute zone; `None` if no edge passes over it.
pub fn lowest_cut(cutter: &Cutter, mv: &Move, x: f64, y: f64) -> Option<Cut> {
    let ball = if mv.feed_per_radian() < PLUNGE_FEED {
        plunge_ball(cutter, mv, x, y)
    } else {
        Track::new(cutter, mv, x, y).lowest(x, y)
    };
    let flat = if cutter.flat_radius > 0.0 { lowest_flat(cutter, mv, x, y) } else { None };
    lower(ball, flat)
}

/// The lower of two optional cuts.
pub fn lower(a: Option<Cut>, b: Option<Cut>) -> Option<Cut> {
    match (a, b) {
        (Some(p), Some(q)) => Some(if q.z < p.z { q } else { p }),
        (p, None) => p,
        (None, q) => q,
    }
}

/// One monotone piece of the arc.
#[derive(Clone, Copy, Debug)]
struct Piece {
    g0: f64,
    g1: f64,
    /// α at g0 (limit from the right), unwrapped.
    a0: f64,
    /// G at the ends.
    big0: f64,
    big1: f64,
    /// G at TABLE + 1 evenly spaced γ from g0 to g1, in `Track::table` from this index.
    table: usize,
}

/// Samples of G kept per piece for the Newton start.
const TABLE: usize = 64;

/// A bracketed crossing: G − level changes sign between lo and hi on one piece.
#[derive(Clone, Copy, Debug)]
struct Bracket {
    piece: usize,
    lo: f64,
    flo: f64,
    hi: f64,
    fhi: f64,
    level: f64,
}

/// The ball-zone geometry of one move seen from every vertical line at one cross-track offset:
/// everything that does not depend on the along-track position, so a column of a height map
/// parallel to the move shares one track.
#[derive(Clone, Debug)]
pub struct Track {
    cutter: Cutter,
    mv: Move,
    /// Horizontal feed direction and its left normal.
    hx: f64,
    hy: f64,
    /// Feed per radian.
    a: f64,
    /// Cross-track offset d and arc radius ρ.
    d: f64,
    rho: f64,
    /// Vertical slope of the move per horizontal mm.
    k: f64,
    /// γ of the lowest point of the arc.
    gm: f64,
    /// Projections on the tool's radial plane: P(γ) = A + ρ sin γ B + ρ cos γ C.
    pa: (f64, f64),
    pb: (f64, f64),
    pc: (f64, f64),
    pieces: Vec<Piece>,
    /// Samples of G on the pieces.
    table: Vec<f64>,
    /// γ where the line passes through the tip (every flute cuts there).
    tips: Vec<f64>,
}

fn cross(p: (f64, f64), q: (f64, f64)) -> f64 {
    p.0 * q.1 - p.1 * q.0
}

impl Track {
    /// The track of the line through (x, y); valid for every point at the same cross-track
    /// offset. The move must not be a plunge.
    pub fn new(cutter: &Cutter, mv: &Move, x: f64, y: f64) -> Track {
        let a = mv.feed_per_radian();
        let (hx, hy) = (mv.dc.x / a, mv.dc.y / a);
        let (rx, ry) = (x - mv.c0.x, y - mv.c0.y);
        let d = -hy * rx + hx * ry;
        let r = cutter.radius;
        let rho = (r * r - d * d).max(0.0).sqrt();
        let k = mv.dc.z / a;
        let f = &mv.frame;
        let n3 = V3::new(-hy, hx, 0.0);
        let h3 = V3::new(hx, hy, 0.0);
        let pa = (d * n3.dot(&f.u), d * n3.dot(&f.v));
        let pb = (h3.dot(&f.u), h3.dot(&f.v));
        let pc = (-f.u.z, -f.v.z);
        let mut t = Track {
            cutter: *cutter,
            mv: *mv,
            hx,
            hy,
            a,
            d,
            rho,
            k,
            gm: k.atan(),
            pa,
            pb,
            pc,
            pieces: Vec::new(),
            table: Vec::new(),
            tips: Vec::new(),
        };
        if d.abs() < r {
            t.build(n3.dot(&f.w) * d, h3.dot(&f.w), f.w.z);
        }
        t
    }

    /// P(γ): the line's point on the ball, projected on the tool's radial plane.
    fn p(&self, g: f64) -> (f64, f64) {
        let (s, c) = (self.rho * g.sin(), self.rho * g.cos());
        (self.pa.0 + s * self.pb.0 + c * self.pc.0, self.pa.1 + s * self.pb.1 + c * self.pc.1)
    }

    /// dP/dγ.
    fn dp(&self, g: f64) -> (f64, f64) {
        let (s, c) = (self.rho * g.sin(), self.rho * g.cos());
        (c * self.pb.0 - s * self.pc.0, c * self.pb.1 - s * self.pc.1)
    }

    fn sigma(&self) -> f64 {
        self.cutter.rotation.sign()
    }

    /// J(γ) = P × dP/dγ: the sign of dα/dγ.
    fn j(&self, g: f64) -> f64 {
        cross(self.p(g), self.dp(g))
    }

    /// Q(γ) = J + σ ρ cos γ |P|²/a: the sign of dG/dγ.
    fn q(&self, g: f64) -> f64 {
        let p = self.p(g);
        self.j(g) + self.sigma() * self.rho * g.cos() * (p.0 * p.0 + p.1 * p.1) / self.a
    }

    fn linear(&self, g: f64) -> f64 {
        self.sigma() * self.rho * g.sin() / self.a
    }

    /// Cut height at γ for a point at along-track offset `s_node`.
    fn z_at(&self, s_node: f64, g: f64) -> f64 {
        self.mv.c0.z + self.k * s_node - self.k * self.rho * g.sin() - self.rho * g.cos()
    }

    /// Angle of P at a piece end: atan2, or the direction of approach if P vanishes there.
    fn angle_at(&self, g: f64, from_right: bool) -> f64 {
        let p = self.p(g);
        if p.0.hypot(p.1) > TIP_EPS {
            return p.1.atan2(p.0);
        }
        let t = self.dp(g);
        if from_right { t.1.atan2(t.0) } else { (-t.1).atan2(-t.0) }
    }

    fn build(&mut self, w0: f64, wh: f64, wz: f64) {
        let rho = self.rho;
        let mut domain = vec![(-FRAC_PI_2, FRAC_PI_2)];
        // Lower hemisphere of the tool: axial coordinate W(γ) = w0 + ρ wh sin γ − ρ wz cos γ ≤ 0.
        domain = intersect(&domain, &trig1_nonpositive(w0, rho * wh, -rho * wz, -FRAC_PI_2, FRAC_PI_2));
        if self.cutter.flat_radius > 0.0 {
            // Above the flat: W ≥ −h0.
            let h0 = self.cutter.flat_depth();
            domain = intersect(&domain, &trig1_nonpositive(-w0 - h0, -rho * wh, rho * wz, -FRAC_PI_2, FRAC_PI_2));
        }
        let (k1, k2, k3) = (cross(self.pa, self.pb), cross(self.pa, self.pc), cross(self.pb, self.pc));
        let qpoly = Trig3::new(|g| self.q(g));
        let mut pieces = Vec::new();
        let mut tips = Vec::new();
        for &(lo, hi) in &domain {
            let mut cuts = vec![lo];
            // J = ρ cos γ k1 − ρ sin γ k2 − ρ² k3.
            cuts.extend(trig1_zeros(-rho * rho * k3, -rho * k2, rho * k1, lo, hi));
            cuts.extend(qpoly.sign_changes(lo, hi));
            if self.gm > lo && self.gm < hi {
                cuts.push(self.gm);
            }
            cuts.push(hi);
            cuts.sort_by(f64::total_cmp);
            cuts.dedup_by(|b, a| (*b - *a).abs() < 1e-15);
            for &g in &cuts {
                let p = self.p(g);
                if self.cutter.flat_radius == 0.0 && p.0.hypot(p.1) <= TIP_EPS {
                    tips.push(g);
                }
            }
            let mut a0 = self.angle_at(lo, true);
            for w in cuts.windows(2) {
                a0 = self.push_pieces(&mut pieces, w[0], w[1], a0, 0);
                a0 += wrap_pi(self.angle_at(w[1], true) - self.angle_at(w[1], false));
            }
        }
        let mut table = Vec::with_capacity(pieces.len() * (TABLE + 1));
        for p in &mut pieces {
            p.table = table.len();
            for i in 0..=TABLE {
                let g = p.g0 + (p.g1 - p.g0) * i as f64 / TABLE as f64;
                table.push(if i == 0 {
                    p.big0
                } else if i == TABLE {
                    p.big1
                } else {
                    self.big_in(p, g)
                });
            }
        }
        self.pieces = pieces;
        self.table = table;
        self.tips = tips;
    }

    /// Appends the piece [g0, g1] (α monotone on it) starting at unwrapped angle `a0`, split
    /// until α turns less than [`PIECE_TURN`] on each; returns α at g1 (from the left).
    fn push_pieces(&self, out: &mut Vec<Piece>, g0: f64, g1: f64, a0: f64, depth: u32) -> f64 {
        if g1 <= g0 {
            return a0;
        }
        let dir = self.j(0.5 * (g0 + g1));
        let raw = self.angle_at(g1, false);
        let delta = wrap_pi(raw - a0);
        let wrong_way = (dir > 0.0 && delta < -1e-9) || (dir < 0.0 && delta > 1e-9);
        if (wrong_way || delta.abs() >= PIECE_TURN) && depth < 40 {
            let m = 0.5 * (g0 + g1);
            let amid = self.push_pieces(out, g0, m, a0, depth + 1);
            return self.push_pieces(out, m, g1, amid, depth + 1);
        }
        let a1 = a0 + delta;
        out.push(Piece { g0, g1, a0, big0: a0 + self.linear(g0), big1: a1 + self.linear(g1), table: 0 });
        a1
    }

    /// G inside a piece.
    fn big_in(&self, piece: &Piece, g: f64) -> f64 {
        let p = self.p(g);
        piece.a0 + wrap_pi(p.1.atan2(p.0) - piece.a0) + self.linear(g)
    }

    /// The lowest cut over (x, y), a point at this track's cross-track offset.
    pub fn lowest(&self, x: f64, y: f64) -> Option<Cut> {
        if self.pieces.is_empty() && self.tips.is_empty() {
            return None;
        }
        let (rx, ry) = (x - self.mv.c0.x, y - self.mv.c0.y);
        let s_node = self.hx * rx + self.hy * ry;
        // The move's time window in γ.
        let lo_s = (s_node - self.a * self.mv.span) / self.rho;
        let hi_s = s_node / self.rho;
        if lo_s > 1.0 || hi_s < -1.0 {
            return None;
        }
        let (wlo, whi) = (lo_s.max(-1.0).asin(), hi_s.min(1.0).asin());
        let sigma = self.sigma();
        // Flute 1's angle reference: the cut condition is G(γ) ≡ c (mod 2π/Z).
        let c = self.mv.phase + sigma * s_node / self.a;
        let pitch = self.cutter.pitch();
        let mut best: Option<(f64, f64)> = None; // (z, γ)
        let start = self.gm.clamp(wlo, whi);
        // The first crossing on each side, bracketed by the tables; the one whose bracket
        // starts lower is solved first, the other only if it can still be lower.
        let right = self.locate(start, whi, c, pitch, true);
        let left = self.locate(wlo, start, c, pitch, false);
        let near = |b: &Bracket| if b.lo >= start { b.lo } else { b.hi };
        let mut sides: Vec<Bracket> = [right, left].into_iter().flatten().collect();
        sides.sort_by(|p, q| self.z_at(s_node, near(p)).total_cmp(&self.z_at(s_node, near(q))));
        for b in &sides {
            if best.is_some_and(|(bz, _)| self.z_at(s_node, near(b)) >= bz) {
                break;
            }
            let g = self.solve(b);
            let z = self.z_at(s_node, g);
            if best.is_none_or(|(bz, _)| z < bz) {
                best = Some((z, g));
            }
        }
        let mut tip = None;

        for &g in &self.tips {
            if g >= wlo && g <= whi {
                let z = self.z_at(s_node, g);
                if best.is_none_or(|b| z < b.0) {
                    best = Some((z, g));
                    tip = Some(g);
                }
            }
        }
        let (z, g) = best?;
        let theta = (s_node - self.rho * g.sin()) / self.a;
        let p = self.p(g);
        let radial = p.0.hypot(p.1);
        let (zone, flute) = if tip == Some(g) {
            (Zone::Tip, 0)
        } else {
            (Zone::Ball, flute_at(&self.cutter, &self.mv, p.1.atan2(p.0), theta))
        };
        Some(Cut { z, theta, flute, radial, zone })
    }

    /// The first crossing of G with a level c + m·pitch travelling away from the lowest point
    /// within [wlo, whi] (rightward: from wlo up; leftward: from whi down), bracketed.
    fn locate(&self, wlo: f64, whi: f64, c: f64, pitch: f64, rightward: bool) -> Option<Bracket> {
        if whi < wlo {
            return None;
        }
        let n = self.pieces.len();
        for idx in 0..n {
            let pi = if rightward { idx } else { n - 1 - idx };
            let p = &self.pieces[pi];
            if p.g1 < wlo || p.g0 > whi {
                continue;
            }
            let (g0, g1) = (p.g0.max(wlo), p.g1.min(whi));
            if g1 <= g0 {
                continue;
            }
            let b0 = if g0 == p.g0 { p.big0 } else { self.big_in(p, g0) };
            let b1 = if g1 == p.g1 { p.big1 } else { self.big_in(p, g1) };
            let (bs, be) = if rightward { (b0, b1) } else { (b1, b0) };
            // A flute passing at the start itself must not be lost to round-off in G: the
            // first level is taken with a slack of a few ulps, and when it is the start's own
            // value the crossing is there. (Without the slack, a node where the flute passes
            // the lowest point of the arc exactly, e.g. a whole number of turns since the
            // move's start, was cut by the next flute instead: up to 12.8 µm too high.)
            let slack = LEVEL_SLACK * (c.abs() + bs.abs() + pitch);
            let level = if be >= bs {
                let l = c + pitch * ((bs - c - slack) / pitch).ceil();
                if l > be {
                    continue;
                }
                l
            } else {
                let l = c + pitch * ((bs - c + slack) / pitch).floor();
                if l < be {
                    continue;
                }
                l
            };
            if (bs - level).abs() <= slack {
                let g = if rightward { g0 } else { g1 };
                return Some(Bracket { piece: pi, lo: g, flo: 0.0, hi: g, fhi: 0.0, level });
            }
            let (mut lo, mut flo, mut hi, mut fhi) = (g0, b0 - level, g1, b1 - level);
            // Narrow with the table (G is monotone on the piece).
            let tab = &self.table[p.table..=p.table + TABLE];
            let step = (p.g1 - p.g0) / TABLE as f64;
            let increasing = tab[TABLE] >= tab[0];
            let i = tab.partition_point(|&v| if increasing { v < level } else { v > level }).clamp(1, TABLE);
            for (t, v) in [(p.g0 + step * (i - 1) as f64, tab[i - 1] - level), (p.g0 + step * i as f64, tab[i] - level)]
            {
                if t > lo && t < hi {
                    if (v < 0.0) == (flo < 0.0) && v != 0.0 {
                        (lo, flo) = (t, v);
                    } else {
                        (hi, fhi) = (t, v);
                    }
                }
            }
            return Some(Bracket { piece: pi, lo, flo, hi, fhi, level });
        }
        None
    }

    /// G and dG/dγ inside a piece, sharing one sine and cosine.
    fn big_and_slope(&self, piece: &Piece, g: f64) -> (f64, f64) {
        let (sn, cs) = g.sin_cos();
        let (s, c) = (self.rho * sn, self.rho * cs);
        let p = (self.pa.0 + s * self.pb.0 + c * self.pc.0, self.pa.1 + s * self.pb.1 + c * self.pc.1);
        let dp = (c * self.pb.0 - s * self.pc.0, c * self.pb.1 - s * self.pc.1);
        let sig = self.sigma();
        let big = piece.a0 + wrap_pi(p.1.atan2(p.0) - piece.a0) + sig * s / self.a;
        let slope = cross(p, dp) / (p.0 * p.0 + p.1 * p.1) + sig * c / self.a;
        (big, slope)
    }

    /// Safeguarded Newton for G(γ) = level inside a bracket.
    fn solve(&self, b: &Bracket) -> f64 {
        if b.flo == 0.0 {
            return b.lo;
        }
        if b.fhi == 0.0 {
            return b.hi;
        }
        let p = &self.pieces[b.piece];
        if b.flo == b.fhi || b.hi <= b.lo {
            return b.lo;
        }
        let (mut lo, mut flo, mut hi) = (b.lo, b.flo, b.hi);
        let mut g = lo + (hi - lo) * flo / (flo - b.fhi);
        for _ in 0..100 {
            let (big, dg) = self.big_and_slope(p, g);
            let f = big - b.level;
            if f == 0.0 {
                return g;
            }
            if (f < 0.0) == (flo < 0.0) {
                lo = g;
                flo = f;
            } else {
                hi = g;
            }
            let mut next = g - f / dg;
            if !(next > lo && next < hi && next.is_finite()) {
                next = 0.5 * (lo + hi);
            }
            if (next - g).abs() < NEWTON_STOP || hi - lo < SOLVE_TOL {
                return next;
            }
            g = next;
        }
        g
    }

    /// The cross-track offset of this track (mm).
    pub fn offset(&self) -> f64 {
        self.d
    }
}

/// Lowest ball-zone cut of a plunge (no sideways travel): the line's point on the ball is fixed
/// in the tool and every flute passes it once a turn.
fn plunge_ball(cutter: &Cutter, mv: &Move, x: f64, y: f64) -> Option<Cut> {
    let r = cutter.radius;
    let (rx, ry) = (x - mv.c0.x, y - mv.c0.y);
    let rho2 = r * r - rx * rx - ry * ry;
    if rho2 < 0.0 {
        return None;
    }
    let rel = V3::new(rx, ry, -rho2.sqrt());
    let f = &mv.frame;
    let (pu, pv, pw) = (rel.dot(&f.u), rel.dot(&f.v), rel.dot(&f.w));
    let radial = pu.hypot(pv);
    if pw > 0.0 || radial < cutter.flat_radius {
        return None;
    }
    let theta = first_pass(cutter, mv, pv.atan2(pu), radial)?;
    let z = mv.centre(theta).z + rel.z;
    let zone = if radial <= TIP_EPS { Zone::Tip } else { Zone::Ball };
    Some(Cut { z, theta, flute: flute_at(cutter, mv, pv.atan2(pu), theta), radial, zone })
}

/// The spindle angle in [0, span] nearest the move's lower end at which a flute passes the
/// angle `alpha` (any angle for a point on the axis).
fn first_pass(cutter: &Cutter, mv: &Move, alpha: f64, radial: f64) -> Option<f64> {
    let pitch = cutter.pitch();
    let descending = mv.dc.z < 0.0;
    if radial <= TIP_EPS {
        return Some(if descending { mv.span } else { 0.0 });
    }
    let sigma = cutter.rotation.sign();
    // σθ ≡ α − φ0 (mod pitch).
    let base = (sigma * (alpha - mv.phase)).rem_euclid(pitch);
    let theta = if descending { base + pitch * ((mv.span - base) / pitch).floor() } else { base };
    (theta >= 0.0 && theta <= mv.span).then_some(theta)
}

fn flute_at(cutter: &Cutter, mv: &Move, alpha: f64, theta: f64) -> u32 {
    let sigma = cutter.rotation.sign();
    let rel = alpha - mv.phase - sigma * theta;
    ((sigma * rel / cutter.pitch()).round().rem_euclid(cutter.flutes as f64)) as u32
}

/// Lowest cut of the flat tip (a disk of radius r0 at depth h0 on the axis, swept by the flutes'
/// straight parts): the line meets the disk's plane at a point moving linearly in the tool, so
/// dα/dθ has a constant numerator and G(θ) = α − σθ has at most two turning points.
pub fn lowest_flat(cutter: &Cutter, mv: &Move, x: f64, y: f64) -> Option<Cut> {
    let f = &mv.frame;
    if f.w.z <= 0.0 {
        return None;
    }
    let h0 = cutter.flat_depth();
    let r0 = cutter.flat_radius;
    // Point of the line on the flat's plane at θ, relative to the ball centre.
    let rel = |theta: f64| {
        let c = mv.centre(theta);
        let (qx, qy) = (x - c.x, y - c.y);
        let qz = (-h0 - f.w.x * qx - f.w.y * qy) / f.w.z;
        V3::new(qx, qy, qz)
    };
    let proj = |v: V3| (v.dot(&f.u), v.dot(&f.v));
    let (r0v, r1v) = (rel(0.0), rel(1.0));
    let f0 = proj(r0v);
    let f1 = {
        let p1 = proj(r1v);
        (p1.0 - f0.0, p1.1 - f0.1)
    };
    let zslope = mv.dc.z + (r1v.z - r0v.z);
    let z_of = |theta: f64| mv.c0.z + r0v.z + zslope * theta;
    let pt = |theta: f64| (f0.0 + f1.0 * theta, f0.1 + f1.1 * theta);
    let aa = f1.0 * f1.0 + f1.1 * f1.1;
    let bb = f0.0 * f1.0 + f0.1 * f1.1;
    let cc = f0.0 * f0.0 + f0.1 * f0.1;
    if aa < PLUNGE_FEED * PLUNGE_FEED {
        let radial = cc.sqrt();
        if radial > r0 {
            return None;
        }
        let theta = first_pass(cutter, mv, f0.1.atan2(f0.0), radial)?;
        let zone_flute = flute_at(cutter, mv, f0.1.atan2(f0.0), theta);
        return Some(Cut { z: z_of(theta), theta, flute: zone_flute, radial, zone: Zone::Flat });
    }
    // |P(θ)|² = aa θ² + 2 bb θ + cc ≤ r0².
    let disc = bb * bb - aa * (cc - r0 * r0);
    if disc < 0.0 {
        return None;
    }
    let (t_in, t_out) = ((-bb - disc.sqrt()) / aa, (-bb + disc.sqrt()) / aa);
    let (lo, hi) = (t_in.max(0.0), t_out.min(mv.span));
    if hi < lo {
        return None;
    }
    let sigma = cutter.rotation.sign();
    let jf = cross(f0, f1);
    let mut cuts = vec![lo, hi];
    // Turning points of G: |P|² = σ J.
    let disc2 = bb * bb - aa * (cc - sigma * jf);
    if sigma * jf > 0.0 && disc2 > 0.0 {
        cuts.push((-bb - disc2.sqrt()) / aa);
        cuts.push((-bb + disc2.sqrt()) / aa);
    }
    // Closest approach to the disk's centre (a pass through it is cut by every flute).
    let tc = -bb / aa;
    cuts.push(tc);
    cuts.retain(|t| *t >= lo && *t <= hi);
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let p_c = pt(tc);
    if tc >= lo && tc <= hi && p_c.0.hypot(p_c.1) <= TIP_EPS {
        // Through the centre: cut there, and nothing on this move is lower unless the flat is
        // tilted, where the ends of the chord may be lower: handled by the search below.
        let centre = Cut { z: z_of(tc), theta: tc, flute: 0, radial: 0.0, zone: Zone::Flat };
        let other = flat_search(cutter, mv, &cuts, &pt, &z_of, zslope, sigma, tc);
        return lower(Some(centre), other);
    }
    flat_search(cutter, mv, &cuts, &pt, &z_of, zslope, sigma, f64::NAN)
}

/// Searches the flat's chord pieces from the low end for the first flute passage.
#[allow(clippy::too_many_arguments)]
fn flat_search(
    cutter: &Cutter,
    mv: &Move,
    cuts: &[f64],
    pt: &dyn Fn(f64) -> (f64, f64),
    z_of: &dyn Fn(f64) -> f64,
    zslope: f64,
    sigma: f64,
    skip: f64,
) -> Option<Cut> {
    let pitch = cutter.pitch();
    let big = |theta: f64, near: f64| {
        let p = pt(theta);
        near + wrap_pi(p.1.atan2(p.0) - near) - sigma * theta
    };
    let order: Vec<(f64, f64)> = if zslope < 0.0 {
        cuts.windows(2).rev().map(|w| (w[1], w[0])).collect()
    } else {
        cuts.windows(2).map(|w| (w[0], w[1])).collect()
    };
    for (ts, te) in order {
        // Angles at the ends approached from inside the piece (the centre passage is excluded).
        let inside = |t: f64, toward: f64| if t == skip { t + (toward - t) * 1e-9 } else { t };
        let (ts_i, te_i) = (inside(ts, te), inside(te, ts));
        let ps = pt(ts_i);
        let a_s = ps.1.atan2(ps.0);
        let bs = a_s - sigma * ts_i;
        let be = big(te_i, a_s);
        let c = mv.phase;
        let level = if be >= bs {
            let l = c + pitch * ((bs - c) / pitch).ceil();
            if l > be {
                continue;
            }
            l
        } else {
            let l = c + pitch * ((bs - c) / pitch).floor();
            if l < be {
                continue;
            }
            l
        };
        // Bisection with Newton on θ.
        let (mut lo, mut hi) = if ts_i < te_i { (ts_i, te_i) } else { (te_i, ts_i) };
        let flo0 = big(lo, a_s) - level;
        let mut flo = flo0;
        let mut t = 0.5 * (lo + hi);
        for _ in 0..200 {
            let fv = big(t, a_s) - level;
            if fv == 0.0 {
                break;
            }
            if (fv < 0.0) == (flo < 0.0) {
                lo = t;
                flo = fv;
            } else {
                hi = t;
            }
            let p = pt(t);
            let n2 = p.0 * p.0 + p.1 * p.1;
            let dp = (pt(t + 1.0).0 - p.0, pt(t + 1.0).1 - p.1);
            let deriv = cross(p, dp) / n2 - sigma;
            let mut next = t - fv / deriv;
            if !(next > lo && next < hi && next.is_finite()) {
                next = 0.5 * (lo + hi);
            }
            if (next - t).abs() < SOLVE_TOL || hi - lo < SOLVE_TOL {
                t = next;
                break;
            }
            t = next;
        }
        let p = pt(t);
        let radial = p.0.hypot(p.1);
        return Some(Cut {
            z: z_of(t),
            theta: t,
            flute: flute_at(cutter, mv, p.1.atan2(p.0), t),
            radial,
            zone: Zone::Flat,
        });
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn paper_move(zeta: f64, fz: f64, flutes: u32, x_pass: f64) -> (Cutter, Move) {
        let cutter = Cutter::ball(5.0, flutes);
        let a = fz * flutes as f64 / (2.0 * PI);
        let y0 = -20.0;
        let mv = Move {
            c0: P3::new(x_pass, y0, 5.0),
            dc: V3::new(0.0, a, 0.0),
            span: 40.0 / a,
            phase: -y0 / a,
            frame: Frame::tilted(zeta),
        };
        (cutter, mv)
    }

    #[test]
    fn the_cut_is_an_edge_point_over_the_line() {
        for &(zeta, fz, z) in &[(0.0, 0.5, 2), (3f64.to_radians(), 0.4, 2), (10f64.to_radians(), 0.3, 4)] {
            let (cutter, mv) = paper_move(zeta, fz, z, 0.0);
            for i in 0..40 {
                let (x, y) = (-0.3 + 0.6 * i as f64 / 39.0, 0.013 * i as f64);
                let cut = lowest_cut(&cutter, &mv, x, y).expect("cut");
                let p = mv.edge_point(&cutter, cut.flute, cut.theta, cut.radial);
                assert!(
                    (p.x - x).abs() < 1e-9 && (p.y - y).abs() < 1e-9 && (p.z - cut.z).abs() < 1e-9,
                    "{p:?} {x} {y} {cut:?}"
                );
            }
        }
    }

    /// A 12 mm move at 1 mm per turn, two flutes: the cut repeats every 0.5 mm along it. At
    /// y = 0 the spindle has turned exactly six times and flute 1 passes the arc's lowest point
    /// over nodes beside the pass; that crossing was lost to round-off and the next flute's
    /// taken, up to 12.8 µm too high (`rough-sim zmap`, the demo raster's y = 0 row).
    #[test]
    fn a_flute_at_the_lowest_point_of_the_arc_is_not_lost() {
        let cutter = Cutter::ball(5.0, 2);
        let span = 24.0 * PI;
        let mv = Move {
            c0: P3::new(0.0, -6.0, 5.0),
            dc: V3::new(0.0, 12.0 / span, 0.0),
            span,
            phase: 0.0,
            frame: Frame::about(V3::z()),
        };
        let mut worst: f64 = 0.0;
        for i in 0..=300 {
            let x = -0.75 + 0.005 * i as f64;
            for y in [0.0, -1.5, 2.0] {
                let a = lowest_cut(&cutter, &mv, x, y).expect("cut").z;
                let b = lowest_cut(&cutter, &mv, x, y + 0.5).expect("cut").z;
                worst = worst.max((a - b).abs());
            }
        }
        assert!(worst < 1e-8, "cuts one feed per tooth apart differ by {} µm", worst * 1e3);
    }

    #[test]
    fn dense_edge_points_never_pass_below() {
        let (cutter, mv) = paper_move(0.0, 0.5, 2, 0.0);
        let a = mv.feed_per_radian();
        let theta_mid = 20.0 / a;
        let mut worst: f64 = f64::NEG_INFINITY;
        for it in 0..800 {
            let theta = theta_mid + (it as f64 / 800.0 - 0.5) * 4.0 * PI;
            for n in 0..2 {
                for ix in 0..30 {
                    let radial = 0.6 * ix as f64 / 29.0;
                    let p = mv.edge_point(&cutter, n, theta, radial);
                    let cut = lowest_cut(&cutter, &mv, p.x, p.y).expect("cut");
                    worst = worst.max(cut.z - p.z);
                }
            }
        }
        assert!(worst < 1e-9, "an edge point passes {worst} mm below the computed surface");
    }
}
