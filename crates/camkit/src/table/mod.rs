//! The toolpath table every filter reads and writes (see `docs/formats.md`): typed rows, a
//! schema that remembers which columns were present and in what order, and unknown columns
//! carried through unchanged.

pub mod columns;
pub mod meaning;
mod read;
mod write;

pub use columns::{COLUMNS, Col, ColumnSpec};
pub use read::{read, read_each, read_each_source};
pub use write::{RowWriter, WriteOptions, write};

use crate::geom::{P2, P3, Plane, V3};

/// The kind of move a row ends.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Move {
    /// G0.
    Rapid,
    /// G1.
    #[default]
    Line,
    /// G2: clockwise arc in its plane.
    Cw,
    /// G3: counter-clockwise arc in its plane.
    Ccw,
}

impl Move {
    /// Name in the table.
    pub fn name(self) -> &'static str {
        match self {
            Move::Rapid => "rapid",
            Move::Line => "line",
            Move::Cw => "cw",
            Move::Ccw => "ccw",
        }
    }

    /// Parses a `move` field (also `g0`..`g3`).
    pub fn parse(text: &str) -> Option<Move> {
        match text.trim().to_ascii_lowercase().as_str() {
            "rapid" | "g0" | "g00" => Some(Move::Rapid),
            "line" | "g1" | "g01" | "" => Some(Move::Line),
            "cw" | "g2" | "g02" => Some(Move::Cw),
            "ccw" | "g3" | "g03" => Some(Move::Ccw),
            _ => None,
        }
    }

    /// True for `cw` and `ccw`.
    pub fn is_arc(self) -> bool {
        matches!(self, Move::Cw | Move::Ccw)
    }
}

/// One row of the toolpath table.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Pass id.
    pub path: i64,
    /// Kind of move ending at this row.
    pub mv: Move,
    /// Position `x, y, z` (mm).
    pub pos: P3,
    /// Arc centre in the arc's plane coordinates (see [`Plane`]), for `cw`/`ccw`.
    pub centre: Option<P2>,
    /// Plane of an arc.
    pub plane: Plane,
    /// Tool axis `i, j, k`.
    pub axis: V3,
    /// Spindle orientation (degrees).
    pub s: Option<f64>,
    /// Feed (mm/min).
    pub f: Option<f64>,
    /// Contact point `px, py, pz`.
    pub contact: Option<P3>,
    /// Unit surface normal `nx, ny, nz`.
    pub normal: Option<V3>,
    /// Free label.
    pub tag: String,
    /// Values of the unknown columns, in the schema's extra order.
    pub extra: Vec<String>,
    /// Source line (1-based), 0 for rows made by a filter.
    pub line: u64,
}

impl Row {
    /// A `line` row at `pos` on pass `path` with every optional field at its default.
    pub fn at(path: i64, pos: P3) -> Row {
        Row {
            path,
            mv: Move::Line,
            pos,
            centre: None,
            plane: Plane::Xy,
            axis: V3::z(),
            s: None,
            f: None,
            contact: None,
            normal: None,
            tag: String::new(),
            extra: Vec::new(),
            line: 0,
        }
    }
}

/// One column position in a table's header.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Field {
    /// A typed column.
    Known(Col),
    /// An unknown column: index into [`Schema::extra_names`].
    Extra(usize),
}

/// Which columns a table has, in header order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Schema {
    /// Header order.
    pub fields: Vec<Field>,
    /// Names of the unknown columns, in the order they appear.
    pub extra_names: Vec<String>,
}

impl Schema {
    /// A schema of typed columns in the given order.
    pub fn of(cols: &[Col]) -> Schema {
        Schema { fields: cols.iter().map(|&c| Field::Known(c)).collect(), extra_names: Vec::new() }
    }

    /// True if the typed column is present.
    pub fn has(&self, col: Col) -> bool {
        self.fields.contains(&Field::Known(col))
    }

    /// Adds typed columns that are not present yet; each goes after the last present column
    /// that precedes it in the canonical order (or first), so tables stay readable.
    pub fn add(&mut self, cols: &[Col]) {
        for &col in cols {
            if self.has(col) {
                continue;
            }
            let at = self.fields.iter().rposition(|f| matches!(f, Field::Known(k) if *k < col)).map_or(0, |i| i + 1);
            self.fields.insert(at, Field::Known(col));
        }
    }

    /// Removes typed columns (a filter that consumed them).
    pub fn remove(&mut self, cols: &[Col]) {
        self.fields.retain(|f| !matches!(f, Field::Known(c) if cols.contains(c)));
    }

    /// Appends an unknown (filter-named) column at the end (an existing one of that name is
    /// reused); returns its index into [`Row::extra`].
    pub fn add_extra(&mut self, name: &str) -> usize {
        if let Some(i) = self.extra_index(name) {
            return i;
        }
        self.extra_names.push(name.to_string());
        self.fields.push(Field::Extra(self.extra_names.len() - 1));
        self.extra_names.len() - 1
    }

    /// Index into [`Row::extra`] of the unknown column `name`.
    pub fn extra_index(&self, name: &str) -> Option<usize> {
        self.extra_names.iter().position(|n| n == name)
    }
}

/// A whole toolpath table.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    /// Columns.
    pub schema: Schema,
    /// Rows in order.
    pub rows: Vec<Row>,
}

impl Table {
    /// Appends an unknown (filter-named) column at the end, empty in every row; returns its
    /// index into [`Row::extra`]. An existing column of that name is reused.
    pub fn add_extra_column(&mut self, name: &str) -> usize {
        let i = self.schema.add_extra(name);
        let n = self.schema.extra_names.len();
        for row in &mut self.rows {
            row.extra.resize(n, String::new());
        }
        i
    }

    /// The rows grouped into passes: maximal runs of consecutive rows with the same `path`.
    pub fn passes(&self) -> impl Iterator<Item = &[Row]> {
        self.rows.chunk_by(|a, b| a.path == b.path)
    }
}
