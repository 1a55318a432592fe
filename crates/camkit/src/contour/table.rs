//! The toolpath table as contours: each pass (`path`) is a chain of lines and arcs in the XY
//! plane at one z, closed when it ends where it starts; and closed contours as pocket regions,
//! with errors that name the row they come from. Shared by every filter that reads contours.

use super::region::{self, Region, RegionError};
use super::{Contour, Vertex};
use crate::error::{Error, Location, Result};
use crate::geom::{Arc2, P2, P3, Plane};
use crate::table::{Move, Row, Table};
use crate::tol;

/// A contour read from the table, with where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// The contour in XY.
    pub contour: Contour,
    /// Its `path` id.
    pub path: i64,
    /// Its height.
    pub z: f64,
    /// Index of its first row in the table (its pass-through values).
    pub row: usize,
    /// Source line of its first row.
    pub line: u64,
    /// Source line of its last row.
    pub last_line: u64,
}

/// Contours of a table and what reading them found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Read {
    /// The contours in input order.
    pub sources: Vec<Source>,
    /// Zero-length moves dropped.
    pub dropped: usize,
    /// Largest difference between an arc's start and end radius about its centre (mm).
    pub arc_mismatch: f64,
}

/// Reads every pass of `table` as a contour. A `rapid` row inside a pass starts a new contour.
pub fn read(table: &Table, name: &str) -> Result<Read> {
    let mut out = Read::default();
    let mut start = 0;
    while start < table.rows.len() {
        let path = table.rows[start].path;
        let mut end = start + 1;
        while end < table.rows.len() && table.rows[end].path == path && table.rows[end].mv != Move::Rapid {
            end += 1;
        }
        let src = one(&table.rows, start, end, name, &mut out)?;
        out.sources.extend(src);
        start = end;
    }
    Ok(out)
}

fn one(rows: &[Row], start: usize, end: usize, name: &str, out: &mut Read) -> Result<Option<Source>> {
    let at = |r: &Row| Location::file(name).line(r.line);
    let z = rows[start].pos.z;
    let mut pts: Vec<Vertex> = vec![Vertex { p: flat(&rows[start].pos), bulge: 0.0 }];
    for r in &rows[start + 1..end] {
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
        let p = flat(&r.pos);
        let from = pts.last().expect("a first vertex").p;
        if (p - from).norm() <= tol::POINT_EPS {
            out.dropped += 1;
            continue;
        }
        let bulge = match (r.mv, r.centre) {
            (Move::Cw | Move::Ccw, Some(c)) => {
                let (r0, r1) = ((from - c).norm(), (p - c).norm());
                let mismatch = (r0 - r1).abs();
                if mismatch > tol::ARC_END_MISMATCH {
                    return Err(Error::input(format!(
                        "the arc's ends are not on one circle about its centre: radii {r0:.6} and {r1:.6} mm"
                    ))
                    .at(at(r).field("xc")));
                }
                out.arc_mismatch = out.arc_mismatch.max(mismatch);
                let arc = Arc2::from_centre(c, &from, &p, r.mv == Move::Ccw, false);
                (arc.sweep / 4.0).tan()
            }
            _ => 0.0,
        };
        pts.last_mut().expect("a first vertex").bulge = bulge;
        pts.push(Vertex { p, bulge: 0.0 });
    }
    if pts.len() < 2 {
        out.dropped += usize::from(end - start > 1);
        return Ok(None);
    }
    let closed = (pts[0].p - pts[pts.len() - 1].p).norm() <= tol::POINT_EPS;
    if closed {
        pts.pop();
    }
    // A full circle written as one arc: split it into two halves.
    if closed && pts.len() == 1 {
        let (p, b) = (pts[0].p, pts[0].bulge);
        let Some(Row { centre: Some(c), .. }) = rows[start + 1..end].iter().find(|r| r.mv.is_arc()) else {
            return Ok(None);
        };
        let half = if b >= 0.0 { 1.0 } else { -1.0 };
        pts = vec![Vertex { p, bulge: half }, Vertex { p: c + (c - p), bulge: half }];
    }
    Ok(Some(Source {
        contour: Contour { vertices: pts, closed },
        path: rows[start].path,
        z,
        row: start,
        line: rows[start].line,
        last_line: rows[end - 1].line,
    }))
}

fn flat(p: &P3) -> P2 {
    P2::new(p.x, p.y)
}

/// Closed contours at one z nested into regions with islands (`region::regions`), and how many
/// loops were turned to the right orientation; an open contour, another z or a bad loop is an
/// error naming the path and its line.
pub fn pocket_regions(sources: &[Source], name: &str) -> Result<(Vec<Region>, usize)> {
    for s in sources {
        if !s.contour.closed {
            let end = s.contour.vertices.last().map_or(P2::origin(), |v| v.p);
            return Err(Error::input(format!(
                "a pocket needs closed contours: path {} ends at ({:.6}, {:.6}), not where it starts (line {})",
                s.path, end.x, end.y, s.line
            ))
            .at(Location::file(name).line(s.last_line)));
        }
    }
    if let Some(s) = sources.iter().find(|s| (s.z - sources[0].z).abs() > tol::POINT_EPS) {
        return Err(
            Error::input("the contours of a pocket lie at one z").at(Location::file(name).line(s.line).field("z"))
        );
    }
    let loops: Vec<Contour> = sources.iter().map(|s| s.contour.clone()).collect();
    region::regions(&loops).map_err(|e| {
        let (i, message) = match e {
            RegionError::Open(i) | RegionError::Degenerate(i) | RegionError::SelfCrossing(i, _) => (i, e.to_string()),
            // Name the other contour by its path id, as the user wrote it, not by its index.
            RegionError::Crossing(i, j, p) => {
                (i, format!("the contour crosses or touches path {} at ({:.6}, {:.6})", sources[j].path, p.x, p.y))
            }
        };
        Error::input(format!("path {}: {message}", sources[i].path)).at(Location::file(name).line(sources[i].line))
    })
}
