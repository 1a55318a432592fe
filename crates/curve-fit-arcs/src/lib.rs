//! `curve-fit-arcs`: compresses point sequences (toolpath tables, G-code) into lines and arcs
//! whose distance from the input, measured after rounding to the output's decimals, never
//! exceeds the tolerance (paper 004 §2).
//!
//! A *run* is a stretch of input that may be merged: consecutive feed moves of one pass with the
//! same feed, tool axis and extrusion rate. Each run is cut into pieces ([`segment`]), each piece
//! fitted as a line or an arc through its end points ([`fit`]) and measured ([`deviation`]).

pub mod bound;
pub mod deviation;
pub mod fit;
pub mod gcode_runs;
pub mod plot;
pub mod segment;
pub mod table_runs;

use camkit::geom::{P3, Plane};
use rayon::prelude::*;

/// How runs are cut into pieces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Method {
    /// The longest piece that fits from each start (fewest moves).
    #[default]
    Fewest,
    /// Paper 004's grouping by curvature threshold, split where a point strays beyond tolerance.
    Paper,
}

/// A largest sweep of an arc, kept with its direction (cos, sin): every arc tried is compared
/// with it, and the comparison needs no trigonometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    /// The angle's unit direction relative to +x, counter-clockwise.
    pub dir: camkit::geom::V2,
}

impl Sweep {
    /// The sweep of `deg` degrees.
    pub fn degrees(deg: f64) -> Sweep {
        let angle = deg.to_radians();
        Sweep { dir: camkit::geom::V2::new(angle.cos(), angle.sin()) }
    }
}

/// Settings of a fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Largest Hausdorff distance between output and input (mm).
    pub tol: f64,
    /// Segmentation method.
    pub method: Method,
    /// Planes arcs may lie in, tried in order.
    pub planes: Vec<Plane>,
    /// Smallest arc radius written (mm).
    pub min_radius: f64,
    /// Largest arc radius written (mm); flatter runs become lines.
    pub max_radius: f64,
    /// Largest angle one arc may sweep.
    pub max_sweep: Sweep,
    /// Tangent continuity between pieces: largest change of direction at a joint (radians).
    pub tangent: Option<f64>,
    /// Turning angle (radians) above which a point is a corner no piece spans.
    pub corner: f64,
    /// Curvature (1/mm) at or above which the paper method groups points into arcs.
    pub curvature_threshold: f64,
    /// Largest relative difference of extrusion per mm between moves merged into one.
    pub e_rate_tol: f64,
    /// Largest angle (radians) between tool axes of table rows merged into one run.
    pub axis_tol: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            tol: 0.01,
            method: Method::Fewest,
            planes: vec![Plane::Xy],
            min_radius: 0.0,
            max_radius: 10_000.0,
            max_sweep: Sweep::degrees(350.0),
            tangent: None,
            corner: 60f64.to_radians(),
            curvature_threshold: 1e-3,
            e_rate_tol: 0.05,
            axis_tol: 1e-7f64.to_radians(),
        }
    }
}

/// Figures of a fit, summed over runs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Motion moves in the input (G0..G3 blocks or table rows).
    pub input_moves: usize,
    /// Motion moves in the output.
    pub output_moves: usize,
    /// Line pieces written for merged runs.
    pub lines: usize,
    /// Arc pieces written.
    pub arcs: usize,
    /// Points fitted (in runs).
    pub points: usize,
    /// Repeated identical points dropped.
    pub dropped_repeats: usize,
    /// Largest verified deviation of any piece (mm).
    pub largest_deviation: f64,
}

impl Stats {
    /// Input moves per output move.
    pub fn ratio(&self) -> f64 {
        if self.output_moves == 0 { 1.0 } else { self.input_moves as f64 / self.output_moves as f64 }
    }

    fn add_pieces(&mut self, pieces: &[fit::Piece]) {
        for p in pieces {
            match p.shape {
                fit::Shape::Line => self.lines += 1,
                fit::Shape::Arc { .. } => self.arcs += 1,
            }
            self.largest_deviation = self.largest_deviation.max(p.deviation);
        }
    }
}

/// One fitted run kept for plotting: its points and pieces.
#[derive(Clone, Debug, PartialEq)]
pub struct FittedRun {
    /// The run's points.
    pub pts: Vec<P3>,
    /// Its pieces.
    pub pieces: Vec<fit::Piece>,
    /// Extrusion (E) per mm of its blocks, for G-code that carries E words; `None` for toolpath
    /// rows and blocks without E (a printer's travel).
    pub extrusion: Option<f64>,
}

/// Appends `p` to `pts` unless it repeats the last point; returns false if it was dropped.
fn push_distinct(pts: &mut Vec<P3>, p: P3) -> bool {
    if pts.last().is_some_and(|q| (q - p).norm() <= camkit::tol::POINT_EPS) {
        return false;
    }
    pts.push(p);
    true
}

/// A certified lower bound on the output moves of any segmentation of the same runs, joints
/// anywhere ([`bound`]): the moves written outside runs plus each run's bound. Runs are bounded
/// in parallel; the sum is the same for any thread count.
pub fn moves_lower_bound(stats: &Stats, runs: &[FittedRun], opts: &Options) -> usize {
    let fitted: usize = runs.iter().map(|r| r.pieces.len()).sum();
    let bound: usize = runs.par_iter().map(|r| bound::min_pieces(&r.pts, opts.tol, &opts.planes)).sum();
    stats.output_moves - fitted + bound
}
