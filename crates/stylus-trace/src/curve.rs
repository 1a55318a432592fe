//! The copying loop of paper 000 §3.1 as a predictor–corrector tracer: the stylus steps along the
//! tangent of its CL curve, the difference vector ΔR = (r − |L|)·L/|L| (eq. 2) is corrected away
//! by Newton moves across the step (inside the motion plane, or in the XY–Z plane of two-surface
//! contact), and the step length adapts so the chord between CL points stays within the chord
//! tolerance of the true CL curve.

use camkit::geom::{P3, V3};
use camkit::model::{Model, Nearest};

/// One CL point: the stylus centre where it touches the model, and what it touches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClPoint {
    /// Stylus centre.
    pub centre: P3,
    /// Contact point on the model (nearest point of the whole model; of surface A in
    /// two-surface mode).
    pub contact: P3,
    /// Unit normal at the contact, from the contact towards the centre (L/|L|).
    pub normal: V3,
    /// Surface touched.
    pub surface: usize,
    /// The second contact in two-surface mode.
    pub second: Option<Contact>,
    /// Newton corrections this point took.
    pub iterations: u32,
    /// |ΔR| left: | |L| − r | (largest of both contacts in two-surface mode).
    pub residual: f64,
    /// True when the centre is on the outward side of the surface touched (L · n > 0).
    pub front: bool,
}

/// A contact with a second surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Contact point.
    pub point: P3,
    /// Unit normal from the contact towards the centre.
    pub normal: V3,
    /// Surface touched.
    pub surface: usize,
}

impl ClPoint {
    /// The unit bisector of both contact normals (two-surface mode), else the normal.
    pub fn bisector(&self) -> V3 {
        match &self.second {
            Some(s) => (self.normal + s.normal).try_normalize(camkit::tol::LENGTH_EPS).unwrap_or(self.normal),
            None => self.normal,
        }
    }
}

/// A point of the curve with its unit tangent, oriented by the curve's own rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvePoint {
    /// The CL point.
    pub cl: ClPoint,
    /// Unit tangent of the CL curve there.
    pub tangent: V3,
}

/// A CL curve defined by contact conditions.
pub trait Curve: Sync {
    /// Newton-corrects `guess` onto the curve, moving only across the direction `across` (the
    /// step's direction); `None` when it does not converge.
    fn correct(&self, guess: &P3, across: &V3) -> Option<CurvePoint>;

    /// How far `at` is from the curve along the correction across `across` (mm); `None` when
    /// no correction converges. By default the full correction's length.
    fn offset(&self, at: &P3, across: &V3) -> Option<f64> {
        self.correct(at, across).map(|p| (p.cl.centre - at).norm())
    }
}

/// Newton iterations one correction may take.
pub const MAX_NEWTON: u32 = 40;

/// Smallest |∂|L|/∂λ| a correction accepts: below it the move direction is nearly tangent to the
/// offset surface and one Newton step could jump more than 1/this times |ΔR|.
const MIN_SLOPE: f64 = 0.2;

/// The stylus and the accuracy it keeps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stylus {
    /// Stylus radius r (mm).
    pub radius: f64,
    /// Largest |ΔR| (mm) of a CL point.
    pub contact_tol: f64,
}

impl Stylus {
    /// |ΔR| the corrections aim for: well inside the tolerance, since Newton converges fast.
    pub fn target(&self) -> f64 {
        (self.contact_tol * 1e-3).max(1e-12 * self.radius)
    }
}

/// The CL curve of a stylus in a motion plane (scanning-line and contour-line modes).
pub struct PlaneCurve<'a> {
    /// The model.
    pub model: &'a Model,
    /// The stylus.
    pub stylus: Stylus,
    /// Unit normal of the motion plane; the tangent is `plane_normal × g`, g the in-plane part
    /// of L, so the material stays on one side.
    pub plane_normal: V3,
    /// Where the offset surface is nearly parallel to the motion plane (|g| below [`MIN_SLOPE`]),
    /// correct anyway along g, each move at most this long (mm), instead of giving up. Contour
    /// levels near a flat spot need it; scan lines give up there (the motion plane is nearly
    /// tangent to the offset surface: they go on by drops) and use `None`. The chord check of
    /// every step catches a move that lands on another branch of the curve.
    pub flat_moves: Option<f64>,
}

impl PlaneCurve<'_> {
    /// The curve point at a converged centre. Where L stands square to the motion plane (a
    /// scan line right over a contact on a wall parallel to it) the curve runs level: the tangent
    /// is the plane's horizontal direction then.
    pub fn finish(&self, c: P3, n: &Nearest, iterations: u32) -> Option<CurvePoint> {
        let u = n.direction(&c);
        let g = u - self.plane_normal * u.dot(&self.plane_normal);
        let tangent = self
            .plane_normal
            .cross(&g)
            .try_normalize(1e-9)
            .or_else(|| self.plane_normal.cross(&V3::z()).try_normalize(1e-9))?;
        let cl = ClPoint {
            centre: c,
            contact: n.point,
            normal: u,
            surface: n.surface,
            second: None,
            iterations,
            residual: (n.distance - self.stylus.radius).abs(),
            front: u.dot(&n.normal) > 0.0,
        };
        Some(CurvePoint { cl, tangent })
    }
}

impl Curve for PlaneCurve<'_> {
    fn correct(&self, guess: &P3, across: &V3) -> Option<CurvePoint> {
        let r = self.stylus.radius;
        let mut w = self.plane_normal.cross(across).try_normalize(1e-12)?;
        let mut c = *guess;
        // |L| is 1-Lipschitz: after a move of m, the nearest point is at most |L| + m away, a
        // bound that lets the model's index prune from the start.
        let mut bound = f64::INFINITY;
        for it in 1..=MAX_NEWTON {
            let n = self.model.nearest_within(&c, bound)?;
            if !n.converged {
                return None;
            }
            let delta = r - n.distance;
            if delta.abs() <= self.stylus.target() {
                return self.finish(c, &n, it);
            }
            let u = n.direction(&c);
            let mut slope = u.dot(&w);
            if slope.abs() < MIN_SLOPE {
                // Across the step the offset surface is nearly parallel (a concave corner turning
                // by more than ~80°): correct along ΔR's own projection on the plane instead,
                // the copying machine's two-dimensional correction.
                let g = u - self.plane_normal * u.dot(&self.plane_normal);
                let least = if self.flat_moves.is_some() { camkit::tol::LENGTH_EPS.sqrt() } else { MIN_SLOPE };
                if g.norm() < least {
                    return None;
                }
                w = g.normalize();
                slope = u.dot(&w);
            }
            let mut moved = delta / slope;
            if let Some(cap) = self.flat_moves {
                moved = moved.clamp(-cap, cap);
            }
            c += w * moved;
            bound = n.distance + moved.abs() * (1.0 + 1e-9) + 1e-9;
        }
        let n = self.model.nearest(&c);
        if n.converged && (n.distance - r).abs() <= self.stylus.contact_tol {
            self.finish(c, &n, MAX_NEWTON)
        } else {
            None
        }
    }

    /// One nearest-point query: the first Newton move |ΔR|/(L̂·w) across the step, which is the
    /// distance along w to the curve up to a term of order |ΔR|²·curvature (below 1e-9 mm at
    /// chord-tolerance distances). Falls back to the full correction where the slope is small.
    fn offset(&self, at: &P3, across: &V3) -> Option<f64> {
        let w = self.plane_normal.cross(across).try_normalize(1e-12)?;
        let n = self.model.nearest(at);
        if !n.converged {
            return None;
        }
        let slope = n.direction(at).dot(&w);
        if slope.abs() < MIN_SLOPE {
            return self.correct(at, across).map(|p| (p.cl.centre - at).norm());
        }
        Some(((self.stylus.radius - n.distance) / slope).abs())
    }
}

/// The CL curve of a stylus touching two surfaces at once (paper 000 fig. 8–10): corrections
/// move in XY across the step and in Z, the tangent is L_A × L_B.
pub struct TwoSurfaceCurve<'a> {
    /// The model.
    pub model: &'a Model,
    /// The stylus.
    pub stylus: Stylus,
    /// The two surfaces.
    pub surfaces: [usize; 2],
    /// Trace the other way round.
    pub reverse: bool,
}

impl Curve for TwoSurfaceCurve<'_> {
    fn correct(&self, guess: &P3, across: &V3) -> Option<CurvePoint> {
        let r = self.stylus.radius;
        // XY correction direction: horizontal, perpendicular to the step's XY part.
        let e1 = V3::z().cross(across).try_normalize(1e-9)?;
        let e2 = V3::z();
        let mut c = *guess;
        for it in 1..=MAX_NEWTON {
            let a = self.model.nearest_on(&c, self.surfaces[0]);
            let b = self.model.nearest_on(&c, self.surfaces[1]);
            if !(a.converged && b.converged) {
                return None;
            }
            let (ua, ub) = (a.direction(&c), b.direction(&c));
            let (da, db) = (r - a.distance, r - b.distance);
            if da.abs().max(db.abs()) <= self.stylus.target() {
                return self.finish(c, &a, &b, it);
            }
            // Solve [ua·e1 ua·e2; ub·e1 ub·e2] [x; z] = [da; db].
            let (m11, m12, m21, m22) = (ua.dot(&e1), ua.dot(&e2), ub.dot(&e1), ub.dot(&e2));
            let det = m11 * m22 - m12 * m21;
            if det.abs() < MIN_SLOPE * MIN_SLOPE {
                return None;
            }
            let x = (da * m22 - m12 * db) / det;
            let z = (m11 * db - m21 * da) / det;
            c += e1 * x + e2 * z;
        }
        None
    }
}

impl TwoSurfaceCurve<'_> {
    fn finish(&self, c: P3, a: &Nearest, b: &Nearest, iterations: u32) -> Option<CurvePoint> {
        let (ua, ub) = (a.direction(&c), b.direction(&c));
        // The stylus must be outside both surfaces and no other part of the model nearer.
        if ua.dot(&a.normal) <= 0.0 || ub.dot(&b.normal) <= 0.0 {
            return None;
        }
        let whole = self.model.nearest_within(&c, self.stylus.radius - self.stylus.contact_tol);
        if whole.is_some() {
            return None;
        }
        let mut tangent = ua.cross(&ub).try_normalize(1e-9)?;
        if self.reverse {
            tangent = -tangent;
        }
        let r = self.stylus.radius;
        let cl = ClPoint {
            centre: c,
            contact: a.point,
            normal: ua,
            surface: a.surface,
            second: Some(Contact { point: b.point, normal: ub, surface: b.surface }),
            iterations,
            residual: (a.distance - r).abs().max((b.distance - r).abs()),
            front: true,
        };
        Some(CurvePoint { cl, tangent })
    }
}

/// How steps are sized.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Steps {
    /// Largest distance (mm) between the chord of two consecutive CL points and the CL curve.
    pub chord_tol: f64,
    /// Longest step (mm).
    pub max_step: f64,
    /// Shortest step (mm): a curve that cannot be followed with it ends there.
    pub min_step: f64,
}

/// Fraction of the chord tolerance a step aims for (the estimate below can miss a corner's
/// deviation by up to a quarter).
pub const AIM: f64 = 0.7;

/// An accepted step.
#[derive(Clone, Copy, Debug)]
pub struct Step {
    /// The new point.
    pub to: CurvePoint,
    /// Its estimated chord deviation (mm).
    pub deviation: f64,
    /// Suggested length of the next step.
    pub next: f64,
}

/// Estimated largest distance between the chord `a → b` and the curve: the chord's points at
/// 1/4, 1/2, 3/4 corrected onto the curve across the chord, and the arc estimate h·Δθ/8 from the
/// tangents (which bounds a corner anywhere along the chord to within a quarter).
pub fn chord_deviation(curve: &dyn Curve, a: &CurvePoint, b: &CurvePoint, limit: f64) -> f64 {
    let d = b.cl.centre - a.cl.centre;
    let h = d.norm();
    if h == 0.0 {
        return 0.0;
    }
    let dir = d / h;
    let turn = a.tangent.dot(&b.tangent).clamp(-1.0, 1.0).acos();
    let mut dev = h * turn / 8.0;
    if dev > limit {
        return dev;
    }
    for f in [0.5, 0.25, 0.75] {
        let m = a.cl.centre + d * f;
        match curve.offset(&m, &dir) {
            Some(off) => dev = dev.max(off),
            None => return f64::INFINITY,
        }
        if dev > limit {
            break;
        }
    }
    dev
}

/// One step from `a` of about `h` mm: predict along the tangent, correct, and shorten until the
/// chord is within tolerance. `None` when even the shortest step fails.
pub fn step(curve: &dyn Curve, a: &CurvePoint, h: f64, steps: &Steps) -> Option<Step> {
    let mut h = h.clamp(steps.min_step, steps.max_step);
    loop {
        let guess = a.cl.centre + a.tangent * h;
        let reduce = match curve.correct(&guess, &a.tangent) {
            Some(b) if (b.cl.centre - a.cl.centre).dot(&a.tangent) > 0.0 => {
                let dev = chord_deviation(curve, a, &b, steps.chord_tol * AIM);
                if dev <= steps.chord_tol * AIM {
                    let grow = if dev > 0.0 { (steps.chord_tol * AIM * 0.8 / dev).sqrt().min(2.0) } else { 2.0 };
                    return Some(Step {
                        to: b,
                        deviation: dev,
                        next: (h * grow).clamp(steps.min_step, steps.max_step),
                    });
                }
                if dev.is_finite() { (0.8 * (steps.chord_tol * AIM / dev).sqrt()).clamp(0.1, 0.5) } else { 0.5 }
            }
            _ => 0.5,
        };
        if h <= steps.min_step {
            return None;
        }
        h = (h * reduce).max(steps.min_step);
    }
}
