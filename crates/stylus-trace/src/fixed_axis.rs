//! Fixed-axis cutter mode: a flat, ball, bull-nose or cone cutter held along one axis is dropped
//! onto the model (camkit's exact drop-cutter) at points `step` apart along the scan lines, which
//! lie in the plane across the axis (the axis frame of [`camkit::model::drop::AxisFrame`]). Each
//! run of points where the cutter finds the model under it is one pass of tool tips.

use crate::scan::{self, Scan};
use camkit::geom::P3;
use camkit::model::Model;
use camkit::model::drop::{Drop, DropCutter};
use camkit::table::{Col, Row, Schema, Table};
use rayon::prelude::*;

/// The positions along a line from `s0` to `s1`: both ends and evenly between, at most `step`
/// apart.
pub fn stations(s0: f64, s1: f64, step: f64) -> Vec<f64> {
    let n = ((s1 - s0) / step).ceil().max(1.0) as usize;
    (0..=n).map(|k| if k == n { s1 } else { s0 + (s1 - s0) * k as f64 / n as f64 }).collect()
}

/// The passes of tips of every scan line, line by line in order (lines run in parallel; the
/// result does not depend on the number of threads). `tick` is called once per line.
pub fn drop_lines(dc: &DropCutter, scan: &Scan, step: f64, tick: &(dyn Fn() + Sync)) -> Vec<Vec<Drop>> {
    let nested: Vec<Vec<Vec<Drop>>> = scan::lines(scan)
        .par_iter()
        .map(|line| {
            let mut passes: Vec<Vec<Drop>> = Vec::new();
            let mut open = false;
            // The contact before, a point of the model: its tip prunes the next drop.
            let mut near = None;
            for s in stations(line.s0, line.s1, step) {
                let p = line.at(s, 0.0);
                let found = dc.drop_near(p.x, p.y, near);
                near = found.map(|d| (d.contact, d.surface));
                match found {
                    Some(d) => {
                        if !open {
                            passes.push(Vec::new());
                            open = true;
                        }
                        passes.last_mut().expect("a pass is open").push(d);
                    }
                    None => open = false,
                }
            }
            tick();
            passes
        })
        .collect();
    nested.into_iter().flatten().collect()
}

/// The tip table: `path` per pass, `x,y,z` the tip, `i,j,k` the axis, the contact and the
/// model's normal there, `tag` `drop`, then `surface` and `point` (`tip`).
pub fn table(model: &Model, dc: &DropCutter, passes: &[Vec<Drop>]) -> Table {
    let mut t = Table {
        schema: Schema::of(&[
            Col::Path,
            Col::X,
            Col::Y,
            Col::Z,
            Col::I,
            Col::J,
            Col::K,
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
    t.add_extra_column(crate::output::SURFACE);
    t.add_extra_column(camkit::table::meaning::POINT);
    for (id, pass) in passes.iter().enumerate() {
        for d in pass {
            let mut row = Row::at(id as i64, d.tip);
            row.axis = dc.frame.axis;
            row.contact = Some(d.contact);
            row.normal = Some(d.normal);
            row.tag = "drop".to_string();
            row.extra.push(model.surfaces[d.surface].name.clone());
            row.extra.push(camkit::table::meaning::TIP.to_string());
            t.rows.push(row);
        }
    }
    t
}

/// The tips of the passes, for the plot.
pub fn tips(passes: &[Vec<Drop>]) -> Vec<Vec<P3>> {
    passes.iter().map(|p| p.iter().map(|d| d.tip).collect()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Region;
    use camkit::geom::V3;
    use camkit::io::Input;
    use camkit::model::cutter::Cutter;

    #[test]
    fn stations_cover_the_line_evenly() {
        assert_eq!(stations(0.0, 1.0, 0.5), vec![0.0, 0.5, 1.0]);
        let s = stations(-1.0, 2.0, 0.7);
        assert_eq!((s.len(), s[0], *s.last().unwrap()), (6, -1.0, 2.0));
        assert!(s.windows(2).all(|w| w[1] - w[0] <= 0.7));
    }

    #[test]
    fn passes_break_where_the_model_is_not_under_the_cutter_and_threads_do_not_matter() {
        // Two spheres 20 apart along x: each scan line through both has two passes.
        let m = Model::load(&Input {
            name: "m.json".into(),
            data: br#"{"surfaces": [{"type": "sphere", "centre": [0,0,0], "radius": 3},
                                   {"type": "sphere", "centre": [20,0,0], "radius": 3}]}"#
                .to_vec(),
        })
        .unwrap();
        let dc = DropCutter::new(&m, Cutter::Bull { radius: 2.0, corner: 0.5 }, V3::z()).unwrap();
        let scan =
            Scan { region: Region { x0: -10.0, x1: 30.0, y0: -1.0, y1: 1.0 }, angle: 0.0, pick: 1.0, zigzag: false };
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let passes = one.install(|| drop_lines(&dc, &scan, 0.25, &|| {}));
        assert_eq!(passes.len(), 6);
        for p in &passes {
            // The cutter's shadow reaches 2 beyond the sphere's 3.
            let (a, b) = (p[0].tip.x, p.last().unwrap().tip.x);
            assert!(b - a <= 10.0 + 1e-9 && b - a > 9.0, "{a}..{b}");
        }
        assert_eq!(drop_lines(&dc, &scan, 0.25, &|| {}), passes);
        let t = table(&m, &dc, &passes);
        assert_eq!(t.schema.extra_names, vec!["surface", "point"]);
        assert!(t.rows.iter().all(|r| r.extra[1] == "tip" && r.axis == V3::z()));
    }
}
