//! The memory a run will hold, estimated from the input and the options before offsetting
//! (see [`camkit::budget`]): a pocket's passes, a 3D contour's corner polygons. A step over of
//! 1e-6 mm (2·10⁷ passes of a 60 × 40 pocket) or a `--chord-tol` of 1e-300 (a corner of
//! unbounded points) is refused up front instead of running for hours or aborting on an
//! allocation.

use crate::space;
use camkit::budget::ROW_BYTES;
use camkit::contour::pocket::{Passes, PocketOptions};
use camkit::table::Table;

/// Copies of a pass held at once: the kernel's result, the verified contours, the rows.
const COPIES: f64 = 3.0;

/// Bytes a pocket of `table` under `opts` is estimated to hold: a pass per step over until the
/// widest possible region (half the rows' box across, its narrower side) is used up, or the
/// count asked if fewer; each pass as many pieces as the input has rows, twice (an arc at every
/// corner), and a few more per contour.
pub fn pocket(table: &Table, opts: &PocketOptions) -> f64 {
    let (mut x, mut y) = ((f64::INFINITY, f64::NEG_INFINITY), (f64::INFINITY, f64::NEG_INFINITY));
    for r in &table.rows {
        x = (x.0.min(r.pos.x), x.1.max(r.pos.x));
        y = (y.0.min(r.pos.y), y.1.max(r.pos.y));
    }
    let across = if table.rows.is_empty() { 0.0 } else { (x.1 - x.0).min(y.1 - y.0) };
    let deep = (0.5 * across - opts.radius).max(0.0) / opts.step + 2.0;
    let passes = match opts.passes {
        Passes::Count(n) => deep.min(n as f64),
        Passes::UntilEmpty => deep,
    };
    let paths = table.rows.iter().filter(|r| r.mv == camkit::table::Move::Rapid).count().max(1) as f64;
    passes * (2.0 * table.rows.len() as f64 + 8.0 * paths) * ROW_BYTES * COPIES
}

/// Bytes a 3D offset of `rows` rows under `opts` is estimated to hold: at every row, a corner
/// polygon of up to π / (2·acos(R / (R + chord_tol))) points (a turn of π at most), a row each.
pub fn space(rows: usize, opts: &space::Options) -> f64 {
    let step = 2.0 * (opts.radius / (opts.radius + opts.chord_tol)).acos();
    rows as f64 * ((std::f64::consts::PI / step).ceil() + 1.0) * ROW_BYTES * COPIES
}
