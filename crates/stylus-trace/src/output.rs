//! The traced paths as the toolpath table and as a plot.

use crate::TracedPath;
use camkit::geom::P2;
use camkit::model::Model;
use camkit::svg::{Aspect, Plot, Style};
use camkit::table::{Col, Row, Schema, Table};

/// The columns written besides the shared ones: the surface touched, and in two-surface mode
/// the second contact, its normal, its surface and the bisector of both normals.
pub const SURFACE: &str = "surface";
/// Columns of the second contact (two-surface mode), in order.
pub const SECOND: [&str; 10] = ["p2x", "p2y", "p2z", "n2x", "n2y", "n2z", "surface2", "bx", "by", "bz"];

/// The toolpath table: `path` per pass, `x,y,z` the stylus centre, `px,py,pz` the contact,
/// `nx,ny,nz` the unit normal L/|L|, `tag` the mode, then `surface` (and the second contact),
/// `point` (`stylus-centre`) and `stylus_radius`: what x,y,z is, for the filters downstream.
pub fn table(model: &Model, paths: &[TracedPath], tag: &str, two: bool, radius: f64) -> Table {
    let mut t = Table {
        schema: Schema::of(&[
            Col::Path,
            Col::X,
            Col::Y,
            Col::Z,
            Col::Px,
            Col::Py,
            Col::Pz,
            Col::Nx,
            Col::Ny,
            Col::Nz,
            Col::Tag,
        ]),
        rows: Vec::new(),
    };
    t.add_extra_column(SURFACE);
    if two {
        for name in SECOND {
            t.add_extra_column(name);
        }
    }
    let name = |i: usize| model.surfaces[i].name.clone();
    for (id, path) in paths.iter().enumerate() {
        for p in &path.points {
            let mut row = Row::at(id as i64, p.centre);
            row.contact = Some(p.contact);
            row.normal = Some(p.normal);
            row.tag = tag.to_string();
            row.extra.push(name(p.surface));
            if let Some(s) = &p.second {
                let b = p.bisector();
                let num = |v: f64| format!("{v}");
                row.extra.extend([
                    num(s.point.x),
                    num(s.point.y),
                    num(s.point.z),
                    num(s.normal.x),
                    num(s.normal.y),
                    num(s.normal.z),
                    name(s.surface),
                    num(b.x),
                    num(b.y),
                    num(b.z),
                ]);
            } else if two {
                row.extra.extend(std::iter::repeat_n(String::new(), SECOND.len()));
            }
            t.rows.push(row);
        }
    }
    camkit::table::meaning::mark_stylus_centre(&mut t, radius);
    t
}

/// Colours of successive passes.
const COLOURS: [&str; 6] = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf"];

/// Most points drawn per pass (longer passes are thinned evenly for the picture only).
const MAX_DRAWN: usize = 4000;

/// Top view of the traced stylus centres (and, in two-surface mode, both contact lines).
pub fn plot(paths: &[TracedPath], title: &str) -> Plot {
    let mut p = Plot::new(title, Aspect::Equal);
    p.labels("x (mm)", "y (mm)");
    let thin = |n: usize| n.div_ceil(MAX_DRAWN).max(1);
    for (k, path) in paths.iter().enumerate() {
        let every = thin(path.points.len());
        let mut centres: Vec<P2> = path.points.iter().step_by(every).map(|q| P2::new(q.centre.x, q.centre.y)).collect();
        if let Some(last) = path.points.last() {
            centres.push(P2::new(last.centre.x, last.centre.y));
        }
        p.polyline(&centres, Style::stroke(COLOURS[k % COLOURS.len()], 1.2));
        if path.points.iter().any(|q| q.second.is_some()) {
            let a: Vec<P2> = path.points.iter().step_by(every).map(|q| P2::new(q.contact.x, q.contact.y)).collect();
            let b: Vec<P2> = path
                .points
                .iter()
                .step_by(every)
                .filter_map(|q| q.second.map(|s| P2::new(s.point.x, s.point.y)))
                .collect();
            p.polyline(&a, Style::stroke("#555", 0.8).dashed("4 2"));
            p.polyline(&b, Style::stroke("#999", 0.8).dashed("1 2"));
        }
    }
    if let Some(first) = paths.first().and_then(|p| p.points.first()) {
        p.dots(&[P2::new(first.centre.x, first.centre.y)], 3.0, Style::fill("black", 1.0));
        p.legend("start", Style::fill("black", 1.0));
    }
    p.legend("stylus centre (one colour per pass)", Style::stroke(COLOURS[0], 1.2));
    if paths.iter().any(|q| q.points.iter().any(|c| c.second.is_some())) {
        p.legend("contact on surface A", Style::stroke("#555", 0.8).dashed("4 2"));
        p.legend("contact on surface B", Style::stroke("#999", 0.8).dashed("1 2"));
    }
    p
}
