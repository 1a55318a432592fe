//! The one list of toolpath-table columns: names, units, defaults and meanings. Both every
//! filter's `--help` and `docs/formats.md` are made from it, so they cannot drift apart.

/// A column the table reader understands and stores in typed fields of a [`super::Row`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[allow(missing_docs)] // each variant is documented by its entry in COLUMNS
pub enum Col {
    Path,
    Move,
    X,
    Y,
    Z,
    Xc,
    Yc,
    Zc,
    Plane,
    I,
    J,
    K,
    S,
    F,
    Px,
    Py,
    Pz,
    Nx,
    Ny,
    Nz,
    Tag,
}

/// Documentation of one column.
#[derive(Clone, Copy, Debug)]
pub struct ColumnSpec {
    /// The column, if the reader stores it in a typed field; `None` for documented columns that
    /// filters read or write by name (they travel in [`super::Row::extra`]).
    pub col: Option<Col>,
    /// Header name.
    pub name: &'static str,
    /// Unit, or the kind of value.
    pub unit: &'static str,
    /// Value when the column is absent or the field empty; `required` when it has none.
    pub default: &'static str,
    /// What the value means.
    pub meaning: &'static str,
}

macro_rules! typed {
    ($col:ident, $name:literal, $unit:literal, $default:literal, $meaning:literal) => {
        ColumnSpec { col: Some(Col::$col), name: $name, unit: $unit, default: $default, meaning: $meaning }
    };
}

/// A column that travels in [`super::Row::extra`]: named here so it is documented once.
#[allow(unused_macros)] // used as filters name their own columns
macro_rules! named {
    ($name:literal, $unit:literal, $default:literal, $meaning:literal) => {
        ColumnSpec { col: None, name: $name, unit: $unit, default: $default, meaning: $meaning }
    };
}

/// Every column of the toolpath table: the shared vocabulary (typed) in the canonical output
/// order, then the columns particular filters read or write by name.
pub const COLUMNS: &[ColumnSpec] = &[
    typed!(Path, "path", "integer", "0", "id of one continuous pass; a new id starts a new pass"),
    typed!(
        Move,
        "move",
        "rapid|line|cw|ccw",
        "line",
        "G0/G1/G2/G3: the row is the end of a move from the previous row of its path"
    ),
    typed!(X, "x", "mm", "required", "position: tool tip for cutter streams, stylus centre in stylus-trace's stream"),
    typed!(Y, "y", "mm", "required", "position"),
    typed!(Z, "z", "mm", "0", "position"),
    typed!(Xc, "xc", "mm", "required for cw/ccw", "arc centre, x"),
    typed!(Yc, "yc", "mm", "required for cw/ccw", "arc centre, y"),
    typed!(Zc, "zc", "mm", "required for cw/ccw in planes xz, yz", "arc centre, z (arcs in the xz or yz plane)"),
    typed!(
        Plane,
        "plane",
        "xy|xz|yz",
        "xy",
        "plane of a cw/ccw arc (G17/G18/G19); the coordinate normal to it varies linearly (helix)"
    ),
    typed!(I, "i", "unit vector", "0", "tool axis, x component"),
    typed!(J, "j", "unit vector", "0", "tool axis, y component"),
    typed!(K, "k", "unit vector", "1", "tool axis, z component"),
    typed!(S, "s", "deg", "empty", "spindle orientation of a non-rotating tool"),
    typed!(F, "f", "mm/min", "empty", "feed"),
    typed!(Px, "px", "mm", "empty", "contact point, x"),
    typed!(Py, "py", "mm", "empty", "contact point, y"),
    typed!(Pz, "pz", "mm", "empty", "contact point, z"),
    typed!(Nx, "nx", "unit vector", "empty", "unit surface normal at the contact point, x"),
    typed!(Ny, "ny", "unit vector", "empty", "unit surface normal, y"),
    typed!(Nz, "nz", "unit vector", "empty", "unit surface normal, z"),
    typed!(Tag, "tag", "text", "empty", "free label (trochoid, contour, probe, ...)"),
    named!(
        "point",
        "tip|stylus-centre",
        "tip",
        "what x,y,z is: a tool tip, or the centre of a stylus (stylus-trace's ball stream; tool-attitude turns it into tips, post-6axis refuses it)"
    ),
    named!("stylus_radius", "mm", "empty", "radius of the stylus whose centre x,y,z is (stylus-centre rows)"),
    named!("surface", "text", "empty", "stylus-trace: name of the model surface the contact point lies on"),
    named!("p2x", "mm", "empty", "stylus-trace two-surface mode: contact point on the second surface, x"),
    named!("p2y", "mm", "empty", "second contact point, y"),
    named!("p2z", "mm", "empty", "second contact point, z"),
    named!("n2x", "unit vector", "empty", "unit normal at the second contact (towards the stylus centre), x"),
    named!("n2y", "unit vector", "empty", "second contact normal, y"),
    named!("n2z", "unit vector", "empty", "second contact normal, z"),
    named!("surface2", "text", "empty", "name of the model surface of the second contact"),
    named!("bx", "unit vector", "empty", "bisector of both contact normals (basic tool axis, paper 000 fig. 10), x"),
    named!("by", "unit vector", "empty", "bisector, y"),
    named!("bz", "unit vector", "empty", "bisector, z"),
    named!(
        "a",
        "degrees",
        "0",
        "surf-probe-fit raw sensor records: A axis position (each rotary axis of the machine by its letter)"
    ),
    named!("b", "degrees", "0", "surf-probe-fit raw sensor records: B axis position"),
    named!("c", "degrees", "0", "surf-probe-fit raw sensor records: C axis position"),
    named!(
        "reading",
        "mm",
        "required in records",
        "surf-probe-fit: laser sensor reading, distance along the beam (−tool axis)"
    ),
    named!("incidence", "degrees", "empty", "surf-probe-fit simulate: angle between the beam and the surface normal"),
    named!("residual", "mm", "empty", "surf-probe-fit fit --residuals: signed distance from the fitted element"),
    named!("outlier", "0/1", "empty", "surf-probe-fit fit --residuals, RANSAC: 1 for a point left out of the fit"),
    named!("tilt", "deg", "empty", "tool-attitude: tilt used (θ cylinder, ζ ball, flat-type axis correction)"),
    named!("r_edge", "mm", "empty", "tool-attitude: R' of paper 000 eq. 1 (cylindrical tool; empty: infinite)"),
    named!("flank_gap", "deg", "empty", "tool-attitude: stand-off of the flat-type tool's second flank"),
    named!("gouge", "mm", "empty", "tool-attitude --model: deepest penetration of the tool body into the model"),
    named!("ac_a", "deg", "empty", "tool-attitude: A angle of paper 002 eq. 3 (A/C table machine)"),
    named!("ac_c", "deg", "empty", "tool-attitude: C angle of paper 002 eq. 4"),
    named!(
        "engagement",
        "deg",
        "empty",
        "medial-trochoid: engagement angle of the tool at the row's end, from the material-removal simulation"
    ),
];

/// The spec of a typed column.
pub fn spec(col: Col) -> &'static ColumnSpec {
    COLUMNS.iter().find(|s| s.col == Some(col)).expect("every Col has a spec")
}

/// The typed column with header `name`.
pub fn by_name(name: &str) -> Option<Col> {
    COLUMNS.iter().find(|s| s.name == name).and_then(|s| s.col)
}

/// Plain-text list of columns for a filter's `--help`: what it reads and what it writes.
pub fn help_text(reads: &[Col], writes: &[Col]) -> String {
    let mut out = String::from(
        "Toolpath table columns (CSV, header row required, any order, `#` lines are comments;\nunknown columns pass through unchanged):\n",
    );
    let section = |out: &mut String, title: &str, cols: &[Col]| {
        out.push_str(title);
        out.push('\n');
        for &c in cols {
            let s = spec(c);
            out.push_str(&format!("  {:<6} {:<18} {}", s.name, s.unit, s.meaning));
            if s.default != "empty" {
                out.push_str(&format!(" [{}]", s.default));
            }
            out.push('\n');
        }
    };
    section(&mut out, "reads:", reads);
    section(&mut out, "writes:", writes);
    out
}

/// Markdown table of every column, for `docs/formats.md`.
pub fn markdown_table() -> String {
    let mut out = String::from("| column | unit | default | meaning |\n|---|---|---|---|\n");
    for s in COLUMNS {
        let cell = |t: &str| t.replace('|', "\\|");
        out.push_str(&format!("| `{}` | {} | {} | {} |\n", s.name, cell(s.unit), cell(s.default), cell(s.meaning)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `docs/formats.md` holds the generated table between its markers; `make docs` rewrites it.
    #[test]
    fn docs_in_sync() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/formats.md");
        let text = std::fs::read_to_string(&path).expect("docs/formats.md");
        let (begin, end) = ("<!-- columns:begin -->\n", "<!-- columns:end -->");
        let a = text.find(begin).expect("begin marker") + begin.len();
        let b = text.find(end).expect("end marker");
        let table = markdown_table();
        if std::env::var_os("UPDATE_DOCS").is_some() {
            std::fs::write(&path, format!("{}{}{}", &text[..a], table, &text[b..])).expect("write docs");
        } else {
            assert_eq!(&text[a..b], table, "docs/formats.md is out of date: run `make docs`");
        }
    }

    #[test]
    fn names_are_unique_and_resolvable() {
        for (i, s) in COLUMNS.iter().enumerate() {
            assert!(COLUMNS[i + 1..].iter().all(|t| t.name != s.name), "duplicate {}", s.name);
            if let Some(c) = s.col {
                assert_eq!(by_name(s.name), Some(c));
                assert_eq!(spec(c).name, s.name);
            }
        }
    }
}
