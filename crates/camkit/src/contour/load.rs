//! Closed contours from a file, whatever a user brings: a DXF drawing (by extension) or the
//! toolpath table; and the pocket regions (boundaries with islands) they make.

use super::region::Region;
use super::table::{self as contour_table, Source};
use crate::error::{Error, Location, Result};
use crate::io::Input;
use crate::table::{self, Col};

/// Contours read from one input, with what was skipped.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Loaded {
    /// The contours in input order.
    pub sources: Vec<Source>,
    /// DXF entities that are not contours: their kind and line.
    pub skipped: Vec<(String, u64)>,
}

/// Reads the contours of `input`: DXF when its name ends in `.dxf`, the toolpath table otherwise.
pub fn contours(input: &Input) -> Result<Loaded> {
    let name = input.name.clone();
    if input.extension() == "dxf" {
        let read = crate::dxf::read(&name, &String::from_utf8_lossy(&input.data))?;
        return Ok(Loaded { sources: read.sources, skipped: read.skipped });
    }
    let t = table::read(input, &[Col::X, Col::Y])?;
    if t.rows.is_empty() {
        return Err(Error::input("no rows: no contour").at(Location::file(&name)));
    }
    Ok(Loaded { sources: contour_table::read(&t, &name)?.sources, skipped: Vec::new() })
}

/// The pocket regions of the closed contours in the file `path` (DXF or table): outer boundaries
/// counter-clockwise with their islands clockwise.
pub fn regions(path: &str) -> Result<Vec<Region>> {
    let input = Input::open(path)?;
    let loaded = contours(&input)?;
    if loaded.sources.is_empty() {
        return Err(Error::input("no closed contour in the input").at(Location::file(&input.name)));
    }
    Ok(contour_table::pocket_regions(&loaded.sources, &input.name)?.0)
}
