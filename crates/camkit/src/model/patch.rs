//! B-spline (Bézier, NURBS) surfaces: evaluation with derivatives and the nearest point, found by a
//! safeguarded Newton iteration on the foot-point condition started in every knot span that can
//! hold a nearer point than the best so far (the spans' control-point hulls bound them).

use super::analytic::Foot;
use super::bvh::{Aabb, Bvh};
use super::sheet::{Bezier, Map};
use crate::doc::model::MAX_DEGREE;
use crate::geom::{P3, V3};

/// Largest tangential residual (mm) of a converged foot point: |(S − q)·Su|/|Su| and the same
/// for v (the foot-point condition), except along a parameter held at the span's edge.
pub const FOOT_TOL: f64 = 1e-9;

/// Length (mm) below which a Newton step on the surface is taken without a line search.
const NEWTON_TRUST: f64 = 1e-4;

/// Newton iterations per start before a start is declared not converged.
const MAX_ITER: usize = 60;

/// A B-spline surface with its span index.
#[derive(Clone, Debug)]
pub struct BSpline {
    degree: [usize; 2],
    /// Net size (nu, nv).
    size: [usize; 2],
    /// Control points, `i * nv + j`.
    ctrl: Vec<P3>,
    /// Weights of a NURBS surface, `i * nv + j` (None: polynomial).
    weights: Option<Vec<f64>>,
    knots: [Vec<f64>; 2],
    /// Parameter rectangles of the spans, in the index's order: (u0, u1, v0, v1, span_u, span_v).
    spans: Vec<([f64; 4], [usize; 2])>,
    index: Bvh,
    /// Whether the surface closes on itself in u and in v (a tube's seam).
    closed: [bool; 2],
}

/// Point and derivatives up to second order at (u, v).
#[derive(Clone, Copy, Debug)]
pub struct Derivs {
    /// S.
    pub s: P3,
    /// ∂S/∂u.
    pub su: V3,
    /// ∂S/∂v.
    pub sv: V3,
    /// ∂²S/∂u².
    pub suu: V3,
    /// ∂²S/∂u∂v.
    pub suv: V3,
    /// ∂²S/∂v².
    pub svv: V3,
}

#[cfg(test)]
impl Derivs {
    /// Checks the derivatives of `eval` at (u, v) against central differences of its lower orders.
    pub(crate) fn assert_match_differences(eval: impl Fn(f64, f64) -> Derivs, u: f64, v: f64) {
        let h = 1e-6;
        let d = eval(u, v);
        let du = (eval(u + h, v).s - eval(u - h, v).s) / (2.0 * h);
        let dv = (eval(u, v + h).s - eval(u, v - h).s) / (2.0 * h);
        let duu = (eval(u + h, v).su - eval(u - h, v).su) / (2.0 * h);
        let duv = (eval(u, v + h).su - eval(u, v - h).su) / (2.0 * h);
        let dvv = (eval(u, v + h).sv - eval(u, v - h).sv) / (2.0 * h);
        for (a, b) in [(d.su, du), (d.sv, dv), (d.suu, duu), (d.suv, duv), (d.svv, dvv)] {
            assert!((a - b).norm() < 1e-5 * (1.0 + a.norm()), "{a} vs {b}");
        }
    }
}

/// Clamped uniform knots for `n` points of degree `p` on [0, 1].
pub fn clamped_uniform(n: usize, p: usize) -> Vec<f64> {
    let inner = n - p;
    (0..n + p + 1)
        .map(|i| {
            if i <= p {
                0.0
            } else if i >= n {
                1.0
            } else {
                (i - p) as f64 / inner as f64
            }
        })
        .collect()
}

/// Index of the knot span holding `t` (the last non-empty one at the domain's end).
pub(super) fn find_span(knots: &[f64], n: usize, p: usize, t: f64) -> usize {
    if t >= knots[n] {
        let mut s = n - 1;
        while knots[s] >= knots[s + 1] {
            s -= 1;
        }
        return s;
    }
    if t <= knots[p] {
        let mut s = p;
        while knots[s] >= knots[s + 1] {
            s += 1;
        }
        return s;
    }
    // Largest s in [p, n−1] with knots[s] ≤ t.
    let (mut lo, mut hi) = (p, n);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if knots[mid] <= t { lo = mid } else { hi = mid }
    }
    lo
}

/// The triangle of basis functions of degree 0..=`p` at `t` in span `s` and the knot differences
/// (The NURBS Book, A2.2/A2.3's `ndu`): `ndu[j][p]` is N_{s−p+j}.
fn basis_table(knots: &[f64], s: usize, p: usize, t: f64) -> [[f64; MAX_DEGREE + 1]; MAX_DEGREE + 1] {
    const M: usize = MAX_DEGREE + 1;
    let mut ndu = [[0.0f64; M]; M];
    let mut left = [0.0f64; M];
    let mut right = [0.0f64; M];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[s + 1 - j];
        right[j] = knots[s + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    ndu
}

/// Basis functions of degree `p` at `t` in span `s` without derivatives: `out[j]` is
/// N_{s−p+j}, bit for bit the first row of [`basis_derivs`].
pub(super) fn basis(knots: &[f64], s: usize, p: usize, t: f64) -> [f64; MAX_DEGREE + 1] {
    let ndu = basis_table(knots, s, p, t);
    std::array::from_fn(|j| if j <= p { ndu[j][p] } else { 0.0 })
}

/// Basis functions of degree `p` at `t` in span `s` and their first two derivatives (The NURBS
/// Book, A2.3): `out[k][j]` is the k-th derivative of N_{s−p+j}.
pub(super) fn basis_derivs(knots: &[f64], s: usize, p: usize, t: f64) -> [[f64; MAX_DEGREE + 1]; 3] {
    const M: usize = MAX_DEGREE + 1;
    let ndu = basis_table(knots, s, p, t);
    let mut ders = [[0.0f64; M]; 3];
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let nd = 2.min(p);
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, 1usize);
        let mut a = [[0.0f64; M]; 2];
        a[0][0] = 1.0;
        for k in 1..=nd {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk as usize];
                d = a[s2][0] * ndu[rk as usize][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if r as isize - 1 <= pk as isize { k - 1 } else { p - r };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = p as f64;
    for row in ders.iter_mut().take(nd + 1).skip(1) {
        for v in row.iter_mut().take(p + 1) {
            *v *= factor;
        }
        factor *= (p - 1) as f64;
    }
    ders
}

/// Knots and control points (rows of any width, combined linearly) of the same spline with every
/// knot of the domain inserted until it is at least `p`-fold.
pub(super) fn bezier_knots(knots: &[f64], mut pts: Vec<Vec<f64>>, p: usize) -> (Vec<f64>, Vec<Vec<f64>>) {
    let mut knots = knots.to_vec();
    let (start, end) = (knots[p], knots[pts.len()]);
    let mut values: Vec<f64> = knots.iter().copied().filter(|&t| t >= start && t <= end).collect();
    values.dedup();
    for t in values {
        while knots.iter().filter(|&&k| k == t).count() < p {
            // t in [U[k], U[k + 1]) (at the domain's end, in (U[k], U[k + 1]]).
            let k = if t == end { knots.iter().rposition(|&x| x < t) } else { knots.iter().rposition(|&x| x <= t) }
                .expect("a knot at or below one of the domain");
            let mut next = Vec::with_capacity(pts.len() + 1);
            next.extend(pts[..=k - p].iter().cloned());
            for i in k + 1 - p..=k {
                let a = (t - knots[i]) / (knots[i + p] - knots[i]);
                next.push(pts[i].iter().zip(&pts[i - 1]).map(|(x, y)| a * x + (1.0 - a) * y).collect());
            }
            next.extend(pts[k..].iter().cloned());
            knots.insert(k + 1, t);
            pts = next;
        }
    }
    (knots, pts)
}

/// The non-empty spans of a Bézier-form knot vector: the index of each one's last point and its
/// ends.
pub(super) fn bezier_spans(knots: &[f64], p: usize) -> Vec<(usize, f64, f64)> {
    let n = knots.len() - p - 1;
    (p..n).filter(|&k| knots[k] < knots[k + 1]).map(|k| (k, knots[k], knots[k + 1])).collect()
}

impl BSpline {
    /// A surface from a rectangular net (`net[i][j]`, i along u), degrees and knots (clamped
    /// uniform when `None`). The caller has validated sizes and knots.
    pub fn new(net: &[Vec<P3>], degree: [usize; 2], knots_u: Option<Vec<f64>>, knots_v: Option<Vec<f64>>) -> BSpline {
        BSpline::with_weights(net, None, degree, knots_u, knots_v)
    }

    /// A NURBS surface when `weights` (the net's shape, all positive) are given, else as
    /// [`BSpline::new`]. Positive weights keep each span inside its control points' hull, which
    /// the span index relies on.
    pub fn with_weights(
        net: &[Vec<P3>],
        weights: Option<&[Vec<f64>]>,
        degree: [usize; 2],
        knots_u: Option<Vec<f64>>,
        knots_v: Option<Vec<f64>>,
    ) -> BSpline {
        let size = [net.len(), net[0].len()];
        let weights = weights.map(|w| w.iter().flatten().copied().collect());
        let ctrl: Vec<P3> = net.iter().flatten().copied().collect();
        let knots = [
            knots_u.unwrap_or_else(|| clamped_uniform(size[0], degree[0])),
            knots_v.unwrap_or_else(|| clamped_uniform(size[1], degree[1])),
        ];
        let mut spans = Vec::new();
        let mut boxes = Vec::new();
        for su in degree[0]..size[0] {
            if knots[0][su] >= knots[0][su + 1] {
                continue;
            }
            for sv in degree[1]..size[1] {
                if knots[1][sv] >= knots[1][sv + 1] {
                    continue;
                }
                // The span lies in the convex hull of the (p+1)(q+1) points acting on it.
                let mut b = Aabb::empty();
                for i in su - degree[0]..=su {
                    for j in sv - degree[1]..=sv {
                        b = b.with(&ctrl[i * size[1] + j]);
                    }
                }
                boxes.push(b);
                spans.push(([knots[0][su], knots[0][su + 1], knots[1][sv], knots[1][sv + 1]], [su, sv]));
            }
        }
        let index = Bvh::build(&boxes);
        let spans = index.order.iter().map(|&i| spans[i as usize]).collect();
        let mut s = BSpline { degree, size, ctrl, weights, knots, spans, index, closed: [false; 2] };
        s.closed = [0, 1].map(|c| s.closes(c));
        s
    }

    /// True when the boundary curves at both ends of parameter `c` coincide (checked at four
    /// points per control point of the other direction, to 1e-9 of the surface's size).
    fn closes(&self, c: usize) -> bool {
        let d = self.domain();
        let b = self.bounds();
        let tol = 1e-9 * (1.0 + (b.max - b.min).norm().min(1e12) + b.max.coords.norm().min(1e12));
        let n = 4 * self.size[1 - c];
        (0..=n).all(|k| {
            let t = d[2 - 2 * c] + (d[3 - 2 * c] - d[2 - 2 * c]) * k as f64 / n as f64;
            let (a, e) = if c == 0 {
                (self.eval(d[0], t), self.eval(d[1], t))
            } else {
                (self.eval(t, d[2]), self.eval(t, d[3]))
            };
            (a.s - e.s).norm() <= tol
        })
    }

    /// Whether the surface closes on itself in u and in v: the parameter is then periodic in the
    /// face reader's inside test.
    pub fn closed(&self) -> [bool; 2] {
        self.closed
    }

    /// Parameter domain [u0, u1, v0, v1].
    pub fn domain(&self) -> [f64; 4] {
        let [p, q] = self.degree;
        let [nu, nv] = self.size;
        [self.knots[0][p], self.knots[0][nu], self.knots[1][q], self.knots[1][nv]]
    }

    /// A box holding the surface.
    pub fn bounds(&self) -> Aabb {
        self.index.bounds()
    }

    /// Point and derivatives at (u, v).
    pub fn eval(&self, u: f64, v: f64) -> Derivs {
        let [p, q] = self.degree;
        let [nu, nv] = self.size;
        let su = find_span(&self.knots[0], nu, p, u);
        let sv = find_span(&self.knots[1], nv, q, v);
        self.eval_in(u, v, [su, sv])
    }

    /// Point at (u, v): bit for bit `eval(u, v).s`, without the derivatives (a tessellation's
    /// probes need none).
    pub fn point(&self, u: f64, v: f64) -> P3 {
        let [p, q] = self.degree;
        let [nu, nv] = self.size;
        let su = find_span(&self.knots[0], nu, p, u);
        let sv = find_span(&self.knots[1], nv, q, v);
        let bu = basis(&self.knots[0], su, p, u);
        let bv = basis(&self.knots[1], sv, q, v);
        let (mut a, mut wa) = (V3::zeros(), 0.0f64);
        for (i, b0) in bu.iter().take(p + 1).enumerate() {
            for (j, c0) in bv.iter().take(q + 1).enumerate() {
                let k = (su - p + i) * self.size[1] + (sv - q + j);
                let w = self.weights.as_ref().map_or(1.0, |ws| ws[k]);
                let b = b0 * c0;
                a += self.ctrl[k].coords * w * b;
                wa += w * b;
            }
        }
        if self.weights.is_none() { P3::from(a) } else { P3::from(a / wa) }
    }

    fn eval_in(&self, u: f64, v: f64, [su, sv]: [usize; 2]) -> Derivs {
        let [p, q] = self.degree;
        let bu = basis_derivs(&self.knots[0], su, p, u);
        let bv = basis_derivs(&self.knots[1], sv, q, v);
        // Homogeneous sums: A = Σ w·P·N and its derivatives, W = Σ w·N (w = 1 unless NURBS).
        let mut acc = [V3::zeros(); 6];
        let mut wacc = [0.0f64; 6];
        for (i, ((b0, b1), b2)) in bu[0].iter().zip(&bu[1]).zip(&bu[2]).take(p + 1).enumerate() {
            for (j, ((c0, c1), c2)) in bv[0].iter().zip(&bv[1]).zip(&bv[2]).take(q + 1).enumerate() {
                let k = (su - p + i) * self.size[1] + (sv - q + j);
                let w = self.weights.as_ref().map_or(1.0, |ws| ws[k]);
                let c = self.ctrl[k].coords * w;
                let basis = [b0 * c0, b1 * c0, b0 * c1, b2 * c0, b1 * c1, b0 * c2];
                for ((a, wa), b) in acc.iter_mut().zip(wacc.iter_mut()).zip(basis) {
                    *a += c * b;
                    *wa += w * b;
                }
            }
        }
        if self.weights.is_none() {
            return Derivs { s: P3::from(acc[0]), su: acc[1], sv: acc[2], suu: acc[3], suv: acc[4], svv: acc[5] };
        }
        // S = A/W and the quotient rule (The NURBS Book, eq. 4.20) up to second order.
        let [w, wu, wv, wuu, wuv, wvv] = wacc;
        let s = acc[0] / w;
        let su = (acc[1] - s * wu) / w;
        let sv = (acc[2] - s * wv) / w;
        let suu = (acc[3] - su * (2.0 * wu) - s * wuu) / w;
        let suv = (acc[4] - su * wv - sv * wu - s * wuv) / w;
        let svv = (acc[5] - sv * (2.0 * wv) - s * wvv) / w;
        Derivs { s: P3::from(s), su, sv, suu, suv, svv }
    }

    /// The surface as rational Bézier patches, one per knot span, each mapping [0, 1]² onto its
    /// span (knots inserted until every one in the domain is p- or q-fold: the NURBS Book, A5.1).
    pub fn bezier_pieces(&self) -> Vec<Bezier> {
        let [p, q] = self.degree;
        let [nu, nv] = self.size;
        let w = |k: usize| self.weights.as_ref().map_or(1.0, |ws| ws[k]);
        let h = |k: usize| {
            let c = self.ctrl[k] * w(k);
            [c.x, c.y, c.z, w(k)]
        };
        // Along u: row i holds the homogeneous points of column i (4 nv numbers).
        let rows: Vec<Vec<f64>> = (0..nu).map(|i| (0..nv).flat_map(|j| h(i * nv + j)).collect()).collect();
        let (ku, rows) = bezier_knots(&self.knots[0], rows, p);
        let nu = rows.len();
        // Along v: row j holds the points of row j over every i.
        let cols: Vec<Vec<f64>> =
            (0..nv).map(|j| (0..nu).flat_map(|i| rows[i][4 * j..4 * j + 4].to_vec()).collect()).collect();
        let (kv, cols) = bezier_knots(&self.knots[1], cols, q);
        let mut out = Vec::new();
        for (a, ua, ub) in bezier_spans(&ku, p) {
            for (b, va, vb) in bezier_spans(&kv, q) {
                let mut pts = Vec::with_capacity((p + 1) * (q + 1));
                for i in a - p..=a {
                    for col in &cols[b - q..=b] {
                        let c = &col[4 * i..4 * i + 4];
                        pts.push([c[0], c[1], c[2], c[3]]);
                    }
                }
                out.push(Bezier::new([p, q], pts, [Map::Linear(ua, ub), Map::Linear(va, vb)]));
            }
        }
        out
    }

    /// Unit normal Su × Sv at (u, v), if the surface is regular there.
    pub fn normal(&self, u: f64, v: f64) -> Option<V3> {
        let d = self.eval(u, v);
        d.su.cross(&d.sv).try_normalize(crate::tol::LENGTH_EPS)
    }

    /// The nearest point to `q` no farther than `bound` (mm): foot, parameters and whether
    /// Newton converged there; `None` when the whole surface is farther than `bound`.
    pub fn nearest(&self, q: &P3, bound: f64) -> Option<(Foot, [f64; 2], bool)> {
        self.nearest_where(q, bound, |_| true)
    }

    /// As [`BSpline::nearest`] over the spans' nearest points whose (u, v) `accept` takes: a
    /// trimmed face's nearest interior point when the surface's own lies outside the face (a
    /// span's nearest point, where it is accepted, is a point of the face no farther than any
    /// other of that span's local minima that Newton reaches from the span's best sample).
    pub fn nearest_where(
        &self,
        q: &P3,
        bound: f64,
        accept: impl Fn([f64; 2]) -> bool,
    ) -> Option<(Foot, [f64; 2], bool)> {
        let mut best: Option<(f64, [f64; 2], Derivs, bool)> = None;
        let bound2 = if bound.is_finite() { bound * bound } else { f64::INFINITY };
        self.index.nearest(q, bound2, |k, best2| {
            let (rect, span) = self.spans[k];
            let (uv, d, converged) = self.span_min(q, rect, span);
            if !accept(uv) {
                return f64::INFINITY;
            }
            let e = (d.s - q).norm_squared();
            if e <= best2 && best.as_ref().is_none_or(|b| e < b.0) {
                best = Some((e, uv, d, converged));
            }
            e
        });
        let (_, uv, d, converged) = best?;
        let normal = d.su.cross(&d.sv).try_normalize(crate::tol::LENGTH_EPS).unwrap_or_else(|| {
            // A degenerate point (a collapsed edge): the direction to q is the best normal there.
            (q - d.s).try_normalize(crate::tol::LENGTH_EPS).unwrap_or(V3::z())
        });
        Some((Foot { point: d.s, normal }, uv, converged))
    }

    /// The nearest point of one span: projected Newton on f = |S − q|²/2 in the span's
    /// rectangle from the best of nine samples, with backtracking; Gauss–Newton where the
    /// Hessian is not positive definite.
    fn span_min(&self, q: &P3, [u0, u1, v0, v1]: [f64; 4], span: [usize; 2]) -> ([f64; 2], Derivs, bool) {
        let f = |u: f64, v: f64| -> (f64, Derivs) {
            let d = self.eval_in(u, v, span);
            ((d.s - q).norm_squared(), d)
        };
        let mut start = ([u0, v0], f64::INFINITY);
        for a in [0.0, 0.5, 1.0] {
            for b in [0.0, 0.5, 1.0] {
                let (u, v) = (u0 + a * (u1 - u0), v0 + b * (v1 - v0));
                let (e, _) = f(u, v);
                if e < start.1 {
                    start = ([u, v], e);
                }
            }
        }
        let [mut u, mut v] = start.0;
        let (mut fe, mut d) = f(u, v);
        for _ in 0..MAX_ITER {
            let r = d.s - q;
            let (gu, gv) = (r.dot(&d.su), r.dot(&d.sv));
            // Variables held at a bound the gradient pushes against.
            let fix_u = (u <= u0 && gu > 0.0) || (u >= u1 && gu < 0.0);
            let fix_v = (v <= v0 && gv > 0.0) || (v >= v1 && gv < 0.0);
            let (nu2, nv2) = (d.su.norm_squared(), d.sv.norm_squared());
            let res_u = if fix_u || nu2 == 0.0 { 0.0 } else { gu.abs() / nu2.sqrt() };
            let res_v = if fix_v || nv2 == 0.0 { 0.0 } else { gv.abs() / nv2.sqrt() };
            if res_u <= FOOT_TOL && res_v <= FOOT_TOL {
                return ([u, v], d, true);
            }
            let (mut huu, mut huv, mut hvv) =
                (nu2 + r.dot(&d.suu), d.su.dot(&d.sv) + r.dot(&d.suv), nv2 + r.dot(&d.svv));
            let det = huu * hvv - huv * huv;
            if !(huu > 0.0 && hvv > 0.0 && det > 0.0) {
                (huu, huv, hvv) = (nu2, d.su.dot(&d.sv), nv2);
            }
            let (du, dv) = match (fix_u, fix_v) {
                (true, true) => return ([u, v], d, true),
                (true, false) => (0.0, -gv / hvv),
                (false, true) => (-gu / huu, 0.0),
                (false, false) => {
                    let det = huu * hvv - huv * huv;
                    if det.abs() <= f64::MIN_POSITIVE {
                        (-gu / huu.max(f64::MIN_POSITIVE), -gv / hvv.max(f64::MIN_POSITIVE))
                    } else {
                        ((-gu * hvv + gv * huv) / det, (-gv * huu + gu * huv) / det)
                    }
                }
            };
            if !(du.is_finite() && dv.is_finite()) {
                return ([u, v], d, false);
            }
            // Near the foot Newton is in its quadratic region and the change of f is below its
            // rounding: take the step. Farther out, backtrack on the projected step.
            let (nu, nv) = ((u + du).clamp(u0, u1), (v + dv).clamp(v0, v1));
            if (d.su * (nu - u) + d.sv * (nv - v)).norm() <= NEWTON_TRUST {
                (u, v) = (nu, nv);
                (fe, d) = f(u, v);
                continue;
            }
            let mut t = 1.0;
            let mut moved = false;
            for _ in 0..30 {
                let (nu, nv) = ((u + t * du).clamp(u0, u1), (v + t * dv).clamp(v0, v1));
                let (fe2, d2) = f(nu, nv);
                if fe2 <= fe {
                    (u, v, fe, d) = (nu, nv, fe2, d2);
                    moved = true;
                    break;
                }
                t *= 0.5;
            }
            if !moved {
                // No descent along a descent direction: f is flat to rounding here.
                return ([u, v], d, res_u.max(res_v) <= FOOT_TOL * 1e3);
            }
        }
        ([u, v], d, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bicubic net for z = x² / 20 + sin(y / 10): curved both ways.
    fn net(n: usize) -> Vec<Vec<P3>> {
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let (x, y) = (i as f64 * 10.0, j as f64 * 10.0);
                        P3::new(x, y, x * x / 200.0 + (y / 15.0).sin() * 4.0)
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn derivatives_match_differences() {
        let s = BSpline::new(&net(7), [3, 3], None, None);
        Derivs::assert_match_differences(|u, v| s.eval(u, v), 0.37, 0.61);
        // A clamped B-spline interpolates its corner points.
        assert!((s.eval(0.0, 0.0).s - P3::new(0.0, 0.0, 0.0)).norm() < 1e-12);
        assert!((s.eval(1.0, 1.0).s - net(7)[6][6]).norm() < 1e-12);
    }

    /// Half a cylinder of radius `r` about the y axis (x ≥ 0 side up to −x), 0 ≤ y ≤ 40, as an
    /// exact NURBS: u along y (degree 1), v round the circle (two rational quadratic quarters).
    fn half_cylinder(r: f64) -> BSpline {
        let circle = [[r, 0.0], [r, r], [0.0, r], [-r, r], [-r, 0.0]];
        let net: Vec<Vec<P3>> =
            [0.0, 40.0].iter().map(|&y| circle.iter().map(|c| P3::new(c[0], y, c[1])).collect()).collect();
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let w = vec![vec![1.0, h, 1.0, h, 1.0]; 2];
        BSpline::with_weights(&net, Some(&w), [1, 2], None, Some(vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0]))
    }

    #[test]
    fn point_is_the_evaluations_point_to_the_bit() {
        let plain = BSpline::new(&net(7), [3, 3], None, None);
        let rational = half_cylinder(20.0);
        for k in 0..=400 {
            let (u, v) = ((k as f64 * 0.618).fract(), k as f64 / 400.0);
            for s in [&plain, &rational] {
                assert_eq!(s.point(u, v), s.eval(u, v).s, "({u}, {v})");
            }
        }
    }

    #[test]
    fn nurbs_cylinder_is_exact() {
        let s = half_cylinder(20.0);
        // Every point of the surface is on the circle, and the derivatives are the quotient's
        // (checked inside the spans, where they are smooth).
        for k in 0..=50 {
            let (u, v) = (k as f64 / 50.0, 0.05 + 0.4 * (k as f64 * 0.37).fract() + 0.5 * (k % 2) as f64);
            let d = s.eval(u, v);
            assert!((d.s.x.hypot(d.s.z) - 20.0).abs() < 1e-12, "{}", d.s);
            let h = 1e-6;
            let dv = (s.eval(u, v + h).s - s.eval(u, v - h).s) / (2.0 * h);
            let dvv = (s.eval(u, v + h).sv - s.eval(u, v - h).sv) / (2.0 * h);
            let duv = (s.eval(u, v + h).su - s.eval(u, v - h).su) / (2.0 * h);
            for (a, b) in [(d.sv, dv), (d.svv, dvv), (d.suv, duv)] {
                assert!((a - b).norm() < 1e-5 * (1.0 + b.norm()), "{a} vs {b}");
            }
        }
        // Nearest points: radial, at | ρ − R | (closed form), with the outward normal.
        for (x, y, z) in [(30.0, 5.0, 2.0), (-3.0, 20.0, 7.0), (10.0, 39.0, 30.0), (-25.0, 1.0, 0.5), (1.0, 12.0, 2.0)]
        {
            let q = P3::new(x, y, z);
            let (foot, _, converged) = s.nearest(&q, f64::INFINITY).unwrap();
            assert!(converged);
            let rho = x.hypot(z);
            assert!(((foot.point - q).norm() - (rho - 20.0).abs()).abs() < 1e-9, "{q}: {}", foot.point);
            assert!((foot.normal - V3::new(x / rho, 0.0, z / rho)).norm() < 1e-9, "{q}: {}", foot.normal);
        }
    }

    #[test]
    fn nearest_point_beats_a_dense_search() {
        let s = BSpline::new(&net(7), [3, 3], None, None);
        for q in
            [P3::new(20.0, 30.0, 15.0), P3::new(-5.0, 25.0, 2.0), P3::new(33.0, 71.0, -8.0), P3::new(55.0, 5.0, 40.0)]
        {
            let (foot, _, converged) = s.nearest(&q, f64::INFINITY).unwrap();
            assert!(converged);
            let found = (foot.point - q).norm();
            let mut brute = f64::INFINITY;
            for i in 0..=400 {
                for j in 0..=400 {
                    brute = brute.min((s.eval(i as f64 / 400.0, j as f64 / 400.0).s - q).norm());
                }
            }
            assert!(found <= brute + 1e-12, "{q}: {found} > dense {brute}");
            assert!(brute - found < 1e-3, "{q}: dense {brute} ≫ {found}");
        }
    }
}
