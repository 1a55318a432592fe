//! A given toolpath (another program's, or our own written one) read back as one layer's
//! [`Program`], so that [`crate::analyse`] re-simulates it with the same exact engagement, feed
//! model and gouge check as our own programs: the peer comparison.
//!
//! The layer is the table's lowest z: feed moves there cut; feed moves going down that reach it
//! (before the next air move) are entries (ramps or helices, their 2D engagement not a
//! full-depth load, as our own entries); other moves above it (level, going up, or going down to
//! a higher layer) and rapids are air and break the chain (a retract).

use crate::program::{Move, Program, Tag};
use camkit::contour::Seg;
use camkit::error::{Error, Location, Result};
use camkit::geom::{Arc2, P2, Plane};
use camkit::table::{Move as Mv, Table};
use camkit::tol;

/// A given toolpath as one layer's moves, and what reading it dropped.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Given {
    /// The moves at (or coming down to) the layer's depth, in order.
    pub program: Program,
    /// The layer's depth: the lowest z of the table (mm).
    pub depth: f64,
    /// Length of the feed moves above the layer, not simulated (mm).
    pub air_length: f64,
    /// Number of chains (each starts after a rapid or an air move).
    pub chains: usize,
}

/// The table's rows as moves of one layer. The first row of the table only places the tool.
/// Rows whose `tag` is one of ours (entry, trochoid, contour, link) keep it; other cutting
/// rows are `contour` and rows coming down to the layer are `entry`.
pub fn read(table: &Table, name: &str) -> Result<Given> {
    let Some(first) = table.rows.first() else {
        return Err(Error::input("no rows: no toolpath to analyse").at(Location::file(name)));
    };
    let depth = table.rows.iter().map(|r| r.pos.z).fold(f64::INFINITY, f64::min);
    let at_depth = |z: f64| z <= depth + tol::POINT_EPS;
    let mut out = Given { depth, ..Given::default() };
    let mut from = first.pos;
    let mut retract = true;
    // Moves going down since the last air move: entries if the chain reaches the layer.
    let mut descent: Vec<Seg> = Vec::new();
    for r in &table.rows[1..] {
        let to = r.pos;
        let (a, b) = (P2::new(from.x, from.y), P2::new(to.x, to.y));
        let going_down = to.z < from.z - tol::POINT_EPS;
        let level = at_depth(from.z) && at_depth(to.z);
        from = to;
        if r.mv == Mv::Rapid {
            out.air_length += descent.drain(..).map(|s| s.length()).sum::<f64>();
            retract = true;
            continue;
        }
        if r.mv.is_arc() && r.plane != Plane::Xy {
            return Err(Error::input(format!(
                "arcs of an analysed toolpath lie in the xy plane, this one in {}",
                r.plane.name()
            ))
            .at(Location::file(name).line(r.line).field("plane")));
        }
        let seg = match (r.mv, r.centre) {
            (Mv::Cw | Mv::Ccw, Some(c)) => {
                let mismatch = ((a - c).norm() - (b - c).norm()).abs();
                if mismatch > tol::ARC_END_MISMATCH {
                    return Err(Error::input(format!(
                        "the arc's ends are not on one circle about its centre: radii differ by {mismatch:.6} mm"
                    ))
                    .at(Location::file(name).line(r.line).field("xc")));
                }
                Seg::Arc(Arc2::from_centre(c, &a, &b, r.mv == Mv::Ccw, true))
            }
            (Mv::Cw | Mv::Ccw, None) => {
                return Err(Error::input("an arc row needs its centre (xc, yc)")
                    .at(Location::file(name).line(r.line).field("xc")));
            }
            _ => Seg::Line(a, b),
        };
        if !going_down && !level {
            // Level above the layer, or going up: air.
            out.air_length += seg.length() + descent.drain(..).map(|s| s.length()).sum::<f64>();
            retract = true;
            continue;
        }
        if going_down {
            if seg.length() > tol::POINT_EPS {
                descent.push(seg);
            }
            if at_depth(to.z) {
                push(&mut out, descent.drain(..), Tag::Entry, &mut retract);
            }
            continue;
        }
        // Level at the layer: the descent (if any, e.g. ended by a straight plunge) reached it.
        push(&mut out, descent.drain(..), Tag::Entry, &mut retract);
        let tag = match r.tag.as_str() {
            "entry" => Tag::Entry,
            "trochoid" => Tag::Trochoid,
            "link" => Tag::Link,
            _ => Tag::Contour,
        };
        if seg.length() > tol::POINT_EPS {
            push(&mut out, std::iter::once(seg), tag, &mut retract);
        }
    }
    out.air_length += descent.iter().map(|s| s.length()).sum::<f64>();
    Ok(out)
}

/// Appends `segs` as moves with `tag`, the first starting a chain if `retract` (then cleared).
fn push(out: &mut Given, segs: impl Iterator<Item = Seg>, tag: Tag, retract: &mut bool) {
    for seg in segs {
        out.chains += usize::from(*retract);
        out.program.moves.push(Move { seg, tag, retract_before: *retract });
        *retract = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use camkit::io::Input;
    use camkit::table::{self, Col};

    fn given(text: &str) -> Given {
        let input = Input { name: "t.csv".into(), data: text.as_bytes().to_vec() };
        read(&table::read(&input, &[Col::X, Col::Y, Col::Z]).unwrap(), "t.csv").unwrap()
    }

    #[test]
    fn the_lowest_layer_is_kept_with_its_entries() {
        // Two layers: the upper one's ramp and pass are air, the lower one's ramp an entry.
        let g = given(
            "path,move,x,y,z,tag\n1,rapid,0,0,20,\n1,line,10,0,10,\n1,line,30,0,10,\n1,rapid,30,0,20,\n\
             2,rapid,0,5,10,\n2,line,10,5,5,\n2,line,20,5,0,\n2,line,40,5,0,link\n2,line,40,15,0,\n",
        );
        assert_eq!(g.depth, 0.0);
        assert!((g.air_length - (10.0 + 20.0)).abs() < 1e-12, "{}", g.air_length);
        let tags: Vec<Tag> = g.program.moves.iter().map(|m| m.tag).collect();
        assert_eq!(tags, vec![Tag::Entry, Tag::Entry, Tag::Link, Tag::Contour]);
        assert_eq!(g.chains, 1);
        assert!(g.program.moves[0].retract_before && !g.program.moves[1].retract_before);
        // An arc row without a centre is refused.
        let input =
            Input { name: "t.csv".into(), data: b"path,move,x,y,z,xc,yc\n1,rapid,0,0,0,,\n1,cw,1,1,0,,\n".to_vec() };
        let e = table::read(&input, &[Col::X, Col::Y]).and_then(|t| read(&t, "t.csv")).unwrap_err();
        assert!(e.to_string().contains("t.csv:3"), "{e}");
    }
}
