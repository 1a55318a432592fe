//! What a stream's `x,y,z` are: tool tips, or the centre of a stylus of some radius (the stream
//! `stylus-trace` writes with a ball stylus). Recorded in two columns on every row, so every
//! filter that passes unknown columns through keeps it: `point` (`tip` or `stylus-centre`) and
//! `stylus_radius` (mm, on stylus-centre rows). A stream without `point` is taken as tips (hand
//! made and older streams).

use super::{Field, Table};
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
    let Some(p) = table.schema.extra_index(POINT) else { return Ok(Meaning::Tip) };
    let r = table.schema.extra_index(STYLUS_RADIUS);
    let mut first: Option<Meaning> = None;
    for row in &table.rows {
        let at = |col: &str| Location::file(file).line(row.line).field(col.to_string());
        let m = match row.extra[p].as_str() {
            TIP => Meaning::Tip,
            STYLUS_CENTRE => {
                let text = r.map_or("", |i| row.extra[i].as_str());
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
        match first {
            None => first = Some(m),
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
    }
    Ok(first.unwrap_or(Meaning::Tip))
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
    if let Some(i) = table.schema.extra_index(STYLUS_RADIUS) {
        table.schema.fields.retain(|f| *f != Field::Extra(i));
        for f in &mut table.schema.fields {
            if let Field::Extra(k) = f {
                if *k > i {
                    *k -= 1;
                }
            }
        }
        table.schema.extra_names.remove(i);
        for row in &mut table.rows {
            row.extra.remove(i);
        }
    }
    let p = table.add_extra_column(POINT);
    for row in &mut table.rows {
        row.extra[p] = TIP.to_string();
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
