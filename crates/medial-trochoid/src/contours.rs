//! The toolpath table as closed contours: each pass (`path`) is a chain of lines and arcs in the
//! XY plane at one z, closed when it ends where it starts.

use camkit::contour::{Contour, Vertex};
use camkit::error::{Error, Location, Result};
use camkit::geom::{Arc2, P2, Plane};
use camkit::table::{Move, Row, Table};
use camkit::tol;

/// A contour read from the table with where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// The contour in XY.
    pub contour: Contour,
    /// Its `path` id.
    pub path: i64,
    /// Its height (mm).
    pub z: f64,
    /// Source line of its first row.
    pub line: u64,
    /// Source line of its last row.
    pub last_line: u64,
}

/// Reads every pass of `table` as a closed contour; a `rapid` row inside a pass starts a new one.
pub fn read(table: &Table, name: &str) -> Result<Vec<Source>> {
    let mut out = Vec::new();
    let mut start = 0;
    while start < table.rows.len() {
        let path = table.rows[start].path;
        let mut end = start + 1;
        while end < table.rows.len() && table.rows[end].path == path && table.rows[end].mv != Move::Rapid {
            end += 1;
        }
        if let Some(s) = one(&table.rows[start..end], name)? {
            out.push(s);
        }
        start = end;
    }
    Ok(out)
}

fn one(rows: &[Row], name: &str) -> Result<Option<Source>> {
    let at = |r: &Row| Location::file(name).line(r.line);
    let z = rows[0].pos.z;
    let mut pts: Vec<Vertex> = vec![Vertex { p: P2::new(rows[0].pos.x, rows[0].pos.y), bulge: 0.0 }];
    for r in &rows[1..] {
        if (r.pos.z - z).abs() > tol::POINT_EPS {
            return Err(Error::input(format!(
                "a contour lies at one z: this path starts at z = {z} and reaches z = {}",
                r.pos.z
            ))
            .at(at(r).field("z")));
        }
        if r.mv.is_arc() && r.plane != Plane::Xy {
            return Err(Error::input(format!("arcs of a contour lie in the xy plane, this one in {}", r.plane.name()))
                .at(at(r).field("plane")));
        }
        let p = P2::new(r.pos.x, r.pos.y);
        let from = pts.last().expect("a first vertex").p;
        if (p - from).norm() <= tol::POINT_EPS {
            continue;
        }
        let bulge = match (r.mv, r.centre) {
            (Move::Cw | Move::Ccw, Some(c)) => {
                let (r0, r1) = ((from - c).norm(), (p - c).norm());
                if (r0 - r1).abs() > tol::ARC_END_MISMATCH {
                    return Err(Error::input(format!(
                        "the arc's ends are not on one circle about its centre: radii {r0:.6} and {r1:.6} mm"
                    ))
                    .at(at(r).field("xc")));
                }
                (Arc2::from_centre(c, &from, &p, r.mv == Move::Ccw, false).sweep / 4.0).tan()
            }
            _ => 0.0,
        };
        pts.last_mut().expect("a first vertex").bulge = bulge;
        pts.push(Vertex { p, bulge: 0.0 });
    }
    let last = rows[rows.len() - 1].line;
    if pts.len() < 2 {
        return Ok(None);
    }
    let closed = (pts[0].p - pts[pts.len() - 1].p).norm() <= tol::POINT_EPS;
    if !closed {
        let e = pts[pts.len() - 1].p;
        return Err(Error::input(format!(
            "a pocket needs closed contours: path {} ends at ({:.6}, {:.6}), not where it starts (line {})",
            rows[0].path, e.x, e.y, rows[0].line
        ))
        .at(Location::file(name).line(last)));
    }
    pts.pop();
    if pts.len() == 1 {
        // A full circle written as one arc: two halves.
        let (p, b) = (pts[0].p, pts[0].bulge);
        let Some(c) = rows[1..].iter().find_map(|r| r.centre) else { return Ok(None) };
        let half = if b >= 0.0 { 1.0 } else { -1.0 };
        pts = vec![Vertex { p, bulge: half }, Vertex { p: c + (c - p), bulge: half }];
    }
    Ok(Some(Source {
        contour: Contour { vertices: pts, closed: true },
        path: rows[0].path,
        z,
        line: rows[0].line,
        last_line: last,
    }))
}
