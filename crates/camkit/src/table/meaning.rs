//! What a stream's `x,y,z` are: tool tips, or the centre of a stylus of some radius (the stream
//! `stylus-trace` writes with a ball stylus). Recorded in two columns on every row, so every
//! filter that passes unknown columns through keeps it: `point` (`tip` or `stylus-centre`) and
//! `stylus_radius` (mm, on stylus-centre rows). A stream without `point` is taken as tips (hand
//! made and older streams).

use super::{Field, Row, Schema, Table};
use crate::error::{Error, Location, Result};

/// Column naming what `x,y,z` is.
pub const POINT: &str = "point";
/// Column of the stylus radius of a stylus-centre stream.
pub const STYLUS_RADIUS: &str = "stylus_radius";
/// `point` of a tool-tip row.
pub const TIP: &str = "tip";
/// `point` of a stylus-centre row.
pub const STYLUS_CENTRE: &str = "stylus-centre";

/// What a stream's positions are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Meaning {
    /// Tool tips (also a stream that does not say).
    Tip,
    /// Centres of a stylus of this radius (mm).
    StylusCentre(f64),
}

/// What `table` (read from `file`) records: every row must say the same; a stylus-centre row
/// must give its positive radius. Errors name the line and column.
pub fn of(table: &Table, file: &str) -> Result<Meaning> {
    let mut check = Check::new(&table.schema);
    for row in &table.rows {
        check.row(row, file)?;
    }
    Ok(check.meaning())
}

/// [`of`] row by row, for a stream read as it comes: [`Check::row`] each row, then
/// [`Check::meaning`].
#[derive(Clone, Debug)]
pub struct Check {
    point: Option<usize>,
    radius: Option<usize>,
    first: Option<Meaning>,
}

impl Check {
    /// A check of rows of `schema`.
    pub fn new(schema: &Schema) -> Check {
        Check { point: schema.extra_index(POINT), radius: schema.extra_index(STYLUS_RADIUS), first: None }
    }

    /// True when the stream has a `point` column (says what it holds).
    pub fn says(&self) -> bool {
        self.point.is_some()
    }

    /// Checks one row (read from `file`) against the rows before it.
    pub fn row(&mut self, row: &Row, file: &str) -> Result<()> {
        let Some(p) = self.point else { return Ok(()) };
        let at = |col: &str| Location::file(file).line(row.line).field(col.to_string());
        let m = match row.extra[p].as_str() {
            TIP => Meaning::Tip,
            STYLUS_CENTRE => {
                let text = self.radius.map_or("", |i| row.extra[i].as_str());
                let radius = text.parse::<f64>().ok().filter(|v| v.is_finite() && *v > 0.0).ok_or_else(|| {
                    Error::input(format!("a stylus-centre row needs its stylus radius (mm), got {text:?}"))
                        .at(at(STYLUS_RADIUS))
                })?;
                Meaning::StylusCentre(radius)
            }
            other => {
                return Err(
                    Error::input(format!("`point` must be `{TIP}` or `{STYLUS_CENTRE}`, got {other:?}")).at(at(POINT))
                );
            }
        };
        match self.first {
            None => self.first = Some(m),
            Some(f) if f != m => {
                return Err(Error::input(format!(
                    "the stream mixes {} rows with {}: one stream, one meaning",
                    describe(&f),
                    describe(&m)
                ))
                .at(at(POINT)));
            }
            _ => {}
        }
        Ok(())
    }

    /// What the rows checked so far record (tips when none says).
    pub fn meaning(&self) -> Meaning {
        self.first.unwrap_or(Meaning::Tip)
    }
}

/// The meaning in words, for messages.
pub fn describe(m: &Meaning) -> String {
    match m {
        Meaning::Tip => "tool-tip".to_string(),
        Meaning::StylusCentre(r) => format!("stylus-centre (stylus radius {r} mm)"),
    }
}

/// Marks every row a tool tip: `point` = `tip` (the column added if missing) and `stylus_radius`
/// dropped.
pub fn mark_tip(table: &mut Table) {
    let marker = TipMarker::new(&table.schema);
    for row in &mut table.rows {
        marker.row(row);
    }
    table.schema = marker.schema;
}

/// [`mark_tip`] row by row: the output's schema, and each row made to say `tip`.
#[derive(Clone, Debug)]
pub struct TipMarker {
    /// The schema of the marked rows.
    pub schema: Schema,
    /// Index of `stylus_radius` in the input rows' extra values, removed.
    radius: Option<usize>,
    /// Index of `point` in the marked rows' extra values.
    point: usize,
}

impl TipMarker {
    /// The marker of rows of `schema`.
    pub fn new(schema: &Schema) -> TipMarker {
        let mut out = schema.clone();
        let radius = out.extra_index(STYLUS_RADIUS);
        if let Some(i) = radius {
            out.fields.retain(|f| *f != Field::Extra(i));
            for f in &mut out.fields {
                if let Field::Extra(k) = f
                    && *k > i
                {
                    *k -= 1;
                }
            }
            out.extra_names.remove(i);
        }
        let point = out.add_extra(POINT);
        TipMarker { schema: out, radius, point }
    }

    /// Marks one row of the input schema as a tip row of [`TipMarker::schema`].
    pub fn row(&self, row: &mut Row) {
        if let Some(i) = self.radius {
            row.extra.remove(i);
        }
        row.extra.resize(self.schema.extra_names.len(), String::new());
        row.extra[self.point] = TIP.to_string();
    }
}

/// Marks every row the centre of a stylus of `radius`.
pub fn mark_stylus_centre(table: &mut Table, radius: f64) {
    let p = table.add_extra_column(POINT);
    let r = table.add_extra_column(STYLUS_RADIUS);
    for row in &mut table.rows {
        row.extra[p] = STYLUS_CENTRE.to_string();
        row.extra[r] = format!("{radius}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::Input;

    fn table(text: &str) -> Result<Table> {
        super::super::read(&Input { name: "s.csv".into(), data: text.as_bytes().to_vec() }, &[])
    }

    #[test]
    fn reads_marks_and_refuses() {
        let t = table("x,y,z\n1,2,3\n").unwrap();
        assert_eq!(of(&t, "s.csv").unwrap(), Meaning::Tip);
        let mut t = table("x,y,z,point,stylus_radius,tag\n1,2,3,stylus-centre,3,a\n4,5,6,stylus-centre,3,b\n").unwrap();
        assert_eq!(of(&t, "s.csv").unwrap(), Meaning::StylusCentre(3.0));
        mark_tip(&mut t);
        assert_eq!(of(&t, "s.csv").unwrap(), Meaning::Tip);
        assert_eq!(t.schema.extra_names, vec!["point"]);
        assert_eq!(t.rows[1].extra, vec!["tip"]);
        mark_stylus_centre(&mut t, 2.5);
        assert_eq!(of(&t, "s.csv").unwrap(), Meaning::StylusCentre(2.5));
        let e = of(&table("x,y,point\n1,2,tip\n1,2,stylus-centre\n").unwrap(), "s.csv").unwrap_err();
        assert!(e.to_string().starts_with("s.csv:3 (stylus_radius)"), "{e}");
        let e = of(&table("x,y,point\n1,2,tip\n1,2,centre\n").unwrap(), "s.csv").unwrap_err();
        assert!(e.to_string().starts_with("s.csv:3 (point)"), "{e}");
        let e = of(&table("x,y,point,stylus_radius\n1,2,tip,\n1,2,stylus-centre,1\n").unwrap(), "s.csv").unwrap_err();
        assert!(e.to_string().contains("mixes"), "{e}");
    }
}
