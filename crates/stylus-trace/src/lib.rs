//! `stylus-trace`: copy simulation (paper 000 §3.1–3.2). A virtual stylus, a sphere of radius r,
//! traces a defined model by the copying principle: L runs from the model's nearest point to the
//! stylus centre, ΔR = (r − |L|)·L/|L| (eq. 2) is corrected inside the motion plane until
//! |ΔR| ≤ the contact tolerance, and the stylus steps on. The CL data come straight from the
//! model, with no offset surface, and since the nearest point is taken over the whole model the
//! stylus never penetrates any part of it.
//!
//! Modes: scanning lines ([`scan`]), contour lines ([`contour`]) and two-surface contact
//! ([`two_surface`]); the tracer they share is in [`curve`]; [`output`] makes the toolpath table
//! and the plot; [`verify`] re-measures every CL point against the whole model, and in scan mode
//! [`coverage`] compares every line with an independent drop of the stylus ([`envelope`]).
//! [`fixed_axis`] is the other use of a scan raster: flat, ball, bull-nose and cone cutters on
//! a fixed axis dropped exactly onto the model, giving tool tips.

pub mod budget;
pub mod contour;
pub mod coverage;
pub mod curve;
pub mod envelope;
pub mod fixed_axis;
pub mod output;
pub mod scan;
pub mod two_surface;

pub use camkit::geom::Region;
use camkit::geom::{P3, V3};
use camkit::model::Model;
use camkit::model::cutter::Cutter;
use camkit::model::drop::DropCutter;
use curve::{ClPoint, Steps, Stylus};
use rayon::prelude::*;

/// The stylus could not go on: where, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    /// Stylus centre where it stopped.
    pub at: P3,
    /// What happened.
    pub what: String,
}

/// One continuous pass of CL points.
#[derive(Clone, Debug, PartialEq)]
pub struct TracedPath {
    /// The CL points in order.
    pub points: Vec<ClPoint>,
    /// Largest estimated chord deviation of its steps (mm).
    pub deviation: f64,
    /// True when the pass ended because the stylus could not follow the model any further (scan
    /// mode: neither copying nor drops go on, the envelope jumps); the next pass starts beyond.
    pub interrupted: bool,
    /// The unit of work it belongs to (scan line, contour level; 0 in two-surface mode).
    pub unit: usize,
}

/// What to trace.
#[derive(Clone, Debug, PartialEq)]
pub enum Mode {
    /// Scanning lines.
    Scan(scan::Scan),
    /// Contour lines at these heights, inside the region.
    Contour {
        /// Region in XY.
        region: Region,
        /// Heights of the stylus centre (mm), in the order traced.
        levels: Vec<f64>,
    },
    /// Two-surface contact.
    TwoSurface(two_surface::TwoSurface),
}

impl Mode {
    /// The tag written on every row.
    pub fn tag(&self) -> &'static str {
        match self {
            Mode::Scan(_) => "scan",
            Mode::Contour { .. } => "contour",
            Mode::TwoSurface(_) => "two-surface",
        }
    }

    /// Independent units of work (scan lines, levels, one line); progress counts them.
    pub fn units(&self) -> usize {
        match self {
            Mode::Scan(s) => scan::lines(s).len(),
            Mode::Contour { levels, .. } => levels.len(),
            Mode::TwoSurface(_) => 1,
        }
    }
}

/// Settings of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Stylus and contact tolerance.
    pub stylus: Stylus,
    /// Step control.
    pub steps: Steps,
    /// Mode.
    pub mode: Mode,
}

/// Traces the model. Units of work run in parallel and are gathered in order, so the result does
/// not depend on the number of threads. `tick` is called once per finished unit.
pub fn trace(model: &Model, opts: &Options, tick: &(dyn Fn() + Sync)) -> Result<Vec<TracedPath>, Failure> {
    let (stylus, steps) = (opts.stylus, &opts.steps);
    let nested: Vec<Vec<TracedPath>> = match &opts.mode {
        Mode::Scan(s) => {
            // The exact ball drop where every surface has one (starts of drops, see scan.rs).
            let exact = DropCutter::closed_forms(model, Cutter::Ball { radius: stylus.radius }, V3::z()).ok();
            scan::lines(s)
                .par_iter()
                .enumerate()
                .map(|(k, line)| {
                    let r = scan::trace_line(model, exact.as_ref(), stylus, steps, line, k);
                    tick();
                    r
                })
                .collect::<Result<_, _>>()?
        }
        Mode::Contour { region, levels } => levels
            .par_iter()
            .enumerate()
            .map(|(k, &z)| {
                let r = contour::trace_level(model, stylus, steps, region, z).map(|mut v| {
                    v.iter_mut().for_each(|p| p.unit = k);
                    v
                });
                tick();
                r
            })
            .collect::<Result<_, _>>()?,
        Mode::TwoSurface(ts) => {
            let r = two_surface::trace(model, stylus, steps, ts)?;
            tick();
            vec![r]
        }
    };
    Ok(nested.into_iter().flatten().filter(|p| p.points.len() >= 2).collect())
}

/// Figures of the independent check of every CL point against the whole model.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Verified {
    /// CL points checked.
    pub points: usize,
    /// Largest | |L| − r | over every point and contact (mm).
    pub largest_residual: f64,
    /// Smallest |L| − r over every point, measured to the whole model (mm): negative means the
    /// stylus is inside the model by that much.
    pub min_clearance: f64,
}

/// A CL point that fails the check: its 0-based row in the output and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct Rejected {
    /// Row (0-based, in output order).
    pub row: usize,
    /// What is wrong.
    pub what: String,
}

/// Re-measures every CL point: the distance to the whole model (and to both surfaces in
/// two-surface mode) must be r within the contact tolerance and every nearest-point iteration
/// must have converged. Nothing is written when a point fails.
pub fn verify(
    model: &Model,
    stylus: &Stylus,
    paths: &[TracedPath],
    two: Option<[usize; 2]>,
) -> Result<Verified, Rejected> {
    let points: Vec<&ClPoint> = paths.iter().flat_map(|p| p.points.iter()).collect();
    let r = stylus.radius;
    let per_point = |(row, p): (usize, &&ClPoint)| -> Result<(f64, f64), Rejected> {
        let n = model.nearest(&p.centre);
        let mut measured = vec![n];
        if let Some([a, b]) = two {
            measured.push(model.nearest_on(&p.centre, a));
            measured.push(model.nearest_on(&p.centre, b));
        }
        let mut residual: f64 = 0.0;
        for m in &measured {
            if !m.converged {
                return Err(Rejected {
                    row,
                    what: format!(
                        "the nearest-point iteration on surface {} did not converge at ({}, {}, {})",
                        model.surfaces[m.surface].name, p.centre.x, p.centre.y, p.centre.z
                    ),
                });
            }
            residual = residual.max((m.distance - r).abs());
        }
        if residual > stylus.contact_tol {
            return Err(Rejected {
                row,
                what: format!(
                    "|ΔR| = {residual:.3e} mm exceeds the contact tolerance {} mm at ({}, {}, {})",
                    stylus.contact_tol, p.centre.x, p.centre.y, p.centre.z
                ),
            });
        }
        Ok((residual, n.distance - r))
    };
    // Every point is measured; the first failing row (in output order) is the one reported.
    let figures: Vec<(f64, f64)> =
        points.par_iter().enumerate().map(per_point).collect::<Vec<_>>().into_iter().collect::<Result<_, _>>()?;
    Ok(Verified {
        points: figures.len(),
        largest_residual: figures.iter().map(|f| f.0).fold(0.0, f64::max),
        min_clearance: figures.iter().map(|f| f.1).fold(f64::INFINITY, f64::min),
    })
}
