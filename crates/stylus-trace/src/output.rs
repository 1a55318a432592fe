//! The traced paths as the toolpath table and as a plot.

use crate::TracedPath;
use camkit::geom::P3;
use camkit::model::Model;
use camkit::svg::Style;
use camkit::svg::figure::{Figure, Path3, views};
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

/// The 3-D views of the traced stylus centres coloured by z over `model` (the model's lines, see
/// [`camkit::svg::relief`]) and, in two-surface mode, both contact lines.
pub fn plot(paths: &[TracedPath], title: &str, model: &[(Vec<P3>, Style)]) -> Figure {
    let centres: Vec<Path3> = paths.iter().map(|p| Path3::by_z(p.points.iter().map(|q| q.centre).collect())).collect();
    let mut under = model.to_vec();
    for path in paths.iter().filter(|p| p.points.iter().any(|q| q.second.is_some())) {
        let a = path.points.iter().map(|q| q.contact).collect();
        let b = path.points.iter().filter_map(|q| q.second.map(|s| s.point)).collect();
        under.push((a, Style::stroke("#555", 0.8).dashed("4 2").named("contact on surface A")));
        under.push((b, Style::stroke("#999", 0.8).dashed("1 2").named("contact on surface B")));
    }
    views(title, &centres, "stylus centre z (mm)", &under)
}
