//! Fitting a toolpath table: runs are consecutive `line` rows of one path with the same feed,
//! tool axis, spindle orientation and tag; every other row passes through unchanged.

use crate::fit::{Exact, Rounding, Shape};
use crate::segment::{self, Unfittable};
use crate::{FittedRun, Options, Stats, push_distinct};
use camkit::geom::{P2, P3};
use camkit::num::round_to;
use camkit::table::{Col, Move, Row, Schema, Table};

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
    let mut fitter = Fitter::new(opts, decimals, true);
    let mut out = Vec::with_capacity(table.rows.len());
    for row in &table.rows {
        fitter.push(row.clone())?;
        out.append(&mut fitter.ready);
    }
    fitter.flush()?;
    out.append(&mut fitter.ready);
    let (stats, runs, written) = fitter.into_results();
    let schema = written.schema(&table.schema);
    Ok((Table { schema, rows: out }, stats, runs))
}

/// What the fitted rows hold, for the output's header: any arc, any arc outside the XY plane.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Written {
    /// Some row is an arc (the header needs `xc,yc`).
    pub arcs: bool,
    /// Some arc lies in another plane than XY (the header needs `zc,plane`).
    pub other_planes: bool,
}

impl Written {
    /// The output's columns: the input's, `move`, and the centre columns the arcs need.
    pub fn schema(&self, input: &Schema) -> Schema {
        let mut schema = input.clone();
        schema.add(&[Col::Move]);
        if self.arcs {
            schema.add(&[Col::Xc, Col::Yc]);
            if self.other_planes {
                schema.add(&[Col::Zc, Col::Plane]);
            }
        }
        schema
    }

    fn note(&mut self, row: &Row) {
        if row.mv.is_arc() {
            self.arcs = true;
            self.other_planes |= row.plane != camkit::geom::Plane::Xy;
        }
    }
}

/// Fits runs of rows as they come, so that a table is fitted run by run and never held whole:
/// [`Fitter::push`] each row in order and take the rows ready for output from `ready`; a run is
/// fitted when the first row that does not continue it arrives, or at [`Fitter::flush`].
pub struct Fitter<'o> {
    opts: &'o Options,
    rounding: Box<dyn Rounding>,
    /// The run at hand: its start row (already written) and the rows continuing it.
    run: Vec<Row>,
    stats: Stats,
    /// The fitted runs, kept for a plot or the lower bound (`None`: not kept).
    runs: Option<Vec<FittedRun>>,
    written: Written,
    /// Rows ready for output, in order.
    pub ready: Vec<Row>,
}

impl<'o> Fitter<'o> {
    /// A fitter writing positions rounded to `decimals` (`None`: exact); `keep_runs` keeps every
    /// fitted run for [`Fitter::into_results`].
    pub fn new(opts: &'o Options, decimals: Option<u32>, keep_runs: bool) -> Fitter<'o> {
        let rounding: Box<dyn Rounding> = match decimals {
            Some(d) => Box::new(Decimals(d)),
            None => Box::new(Exact),
        };
        Fitter {
            opts,
            rounding,
            run: Vec::new(),
            stats: Stats::default(),
            runs: keep_runs.then(Vec::new),
            written: Written::default(),
            ready: Vec::new(),
        }
    }

    /// Takes the next row of the table.
    pub fn push(&mut self, row: Row) -> Result<(), TableError> {
        self.stats.input_moves += 1;
        match self.run.len() {
            0 => {
                self.emit(row.clone());
                self.run.push(row);
            }
            1 => self.after_start(row),
            _ if continues(&self.run[0], &self.run[1], &row, self.opts.axis_tol) => self.run.push(row),
            _ => {
                self.fit_run()?;
                self.after_start(row);
            }
        }
        Ok(())
    }

    /// Fits the run still held (after the last row), its rows to `ready`.
    pub fn flush(&mut self) -> Result<(), TableError> {
        if self.run.len() > 1 {
            self.fit_run()?;
        }
        Ok(())
    }

    /// The statistics, the runs kept and what was written.
    pub fn into_results(self) -> (Stats, Vec<FittedRun>, Written) {
        (self.stats, self.runs.unwrap_or_default(), self.written)
    }

    /// `row` after a run's start row alone: it continues the run, or is written and starts the
    /// next one.
    fn after_start(&mut self, row: Row) {
        if continues(&self.run[0], &row, &row, self.opts.axis_tol) {
            self.run.push(row);
        } else {
            self.emit(row.clone());
            self.run = vec![row];
        }
    }

    fn emit(&mut self, row: Row) {
        self.written.note(&row);
        self.stats.output_moves += 1;
        self.ready.push(row);
    }

    /// Fits the run at hand (its start row written), writes its pieces and keeps its last row as
    /// the next run's start.
    fn fit_run(&mut self) -> Result<(), TableError> {
        let rows = std::mem::take(&mut self.run);
        // Points of the run and, for each, the row it came from.
        let mut pts = vec![rows[0].pos];
        let mut from = vec![0];
        for (i, row) in rows.iter().enumerate().skip(1) {
            if push_distinct(&mut pts, row.pos) {
                from.push(i);
            } else {
                self.stats.dropped_repeats += 1;
            }
        }
        let pieces = segment::segment(&pts, self.opts, self.rounding.as_ref())
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
            self.emit(row);
        }
        self.stats.points += pts.len();
        self.stats.add_pieces(&pieces);
        if let Some(runs) = &mut self.runs {
            runs.push(FittedRun { pts, pieces, extrusion: None });
        }
        // The run's last row starts the next one.
        self.run = vec![rows.into_iter().last().expect("a run has rows")];
        Ok(())
    }
}
