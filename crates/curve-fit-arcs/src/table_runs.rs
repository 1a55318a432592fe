//! Fitting a toolpath table: runs are consecutive `line` rows of one path with the same feed,
//! tool axis, spindle orientation and tag; every other row passes through unchanged.

use crate::fit::{Exact, Rounding, Shape};
use crate::segment::{self, Unfittable};
use crate::{FittedRun, Options, Stats, push_distinct};
use camkit::geom::{P2, P3};
use camkit::num::round_to;
use camkit::table::{Col, Move, Row, Table};

/// Rounding of positions and centres to fixed decimals, as the table writer does.
pub struct Decimals(pub u32);

impl Rounding for Decimals {
    fn point(&self, p: &P3) -> P3 {
        p.map(|v| round_to(v, self.0))
    }
    fn centre(&self, c: &P2, _start: &P2) -> P2 {
        c.map(|v| round_to(v, self.0))
    }
}

/// A run that could not be fitted: the row where it failed.
#[derive(Clone, Debug, PartialEq)]
pub struct TableError {
    /// Source line of the offending row.
    pub line: u64,
    /// What failed.
    pub cause: Unfittable,
}

/// True if `row` continues a run whose first merged row is `head` and whose start row is `start`
/// (tool axes within `axis_tol` radians of the head's).
fn continues(start: &Row, head: &Row, row: &Row, axis_tol: f64) -> bool {
    let apart = row.axis.cross(&head.axis).norm().atan2(row.axis.dot(&head.axis));
    row.path == start.path
        && row.mv == Move::Line
        && row.f == head.f
        && apart <= axis_tol
        && row.s == head.s
        && row.tag == head.tag
}

/// Fits every run of `table`; `decimals` is the output's rounding (`None`: exact).
pub fn fit_table(
    table: &Table,
    opts: &Options,
    decimals: Option<u32>,
) -> Result<(Table, Stats, Vec<FittedRun>), TableError> {
    let rounding: Box<dyn Rounding> = match decimals {
        Some(d) => Box::new(Decimals(d)),
        None => Box::new(Exact),
    };
    let rows = &table.rows;
    let mut out = Vec::with_capacity(rows.len());
    let mut stats = Stats { input_moves: rows.len(), ..Stats::default() };
    let mut runs = Vec::new();
    // Row k is where the next run would start; it has been written.
    if let Some(first) = rows.first() {
        out.push(first.clone());
    }
    let mut k = 0;
    while k + 1 < rows.len() {
        // Rows k+1..=end continue a run starting at row k.
        let mut end = k;
        while end + 1 < rows.len() && continues(&rows[k], &rows[k + 1], &rows[end + 1], opts.axis_tol) {
            end += 1;
        }
        if end == k {
            out.push(rows[k + 1].clone());
            k += 1;
            continue;
        }
        // Points of the run and, for each, the row it came from.
        let mut pts = vec![rows[k].pos];
        let mut from = vec![k];
        for (i, row) in rows.iter().enumerate().take(end + 1).skip(k + 1) {
            if push_distinct(&mut pts, row.pos) {
                from.push(i);
            } else {
                stats.dropped_repeats += 1;
            }
        }
        let pieces = segment::segment(&pts, opts, rounding.as_ref())
            .map_err(|cause| TableError { line: rows[from[cause.at + 1]].line, cause })?;
        for p in &pieces {
            let mut row = rows[from[p.last]].clone();
            row.pos = p.end;
            match p.shape {
                Shape::Line => {
                    row.mv = Move::Line;
                    row.centre = None;
                }
                Shape::Arc { centre, plane, ccw } => {
                    row.mv = if ccw { Move::Ccw } else { Move::Cw };
                    row.centre = Some(centre);
                    row.plane = plane;
                }
            }
            out.push(row);
        }
        stats.points += pts.len();
        stats.add_pieces(&pieces);
        runs.push(FittedRun { pts, pieces, extrusion: None });
        // The run's last row starts the next one.
        k = end;
    }
    stats.output_moves = out.len();
    let mut schema = table.schema.clone();
    schema.add(&[Col::Move]);
    if out.iter().any(|r| r.mv.is_arc()) {
        schema.add(&[Col::Xc, Col::Yc]);
        if out.iter().any(|r| r.mv.is_arc() && r.plane != camkit::geom::Plane::Xy) {
            schema.add(&[Col::Zc, Col::Plane]);
        }
    }
    Ok((Table { schema, rows: out }, stats, runs))
}
