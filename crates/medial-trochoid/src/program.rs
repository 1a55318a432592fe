//! A layer's program as moves of the tool centre in machining order, each tagged with what it
//! does; chains of feed moves are separated by retracts (a rapid before the move).

use camkit::contour::pocket::Pass;
use camkit::contour::region::Region;
use camkit::contour::{Contour, Seg};
use camkit::geom::P2;

/// What a move does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Tag {
    /// A helical entry loop (ramping down; its 2D engagement is not a full-depth load).
    Entry,
    /// A trochoidal loop or the step between loops.
    Trochoid,
    /// A contour-parallel pass.
    Contour,
    /// A feed move between passes that stays clear of the walls.
    Link,
}

impl Tag {
    /// The `tag` column's text.
    pub fn name(self) -> &'static str {
        match self {
            Tag::Entry => "entry",
            Tag::Trochoid => "trochoid",
            Tag::Contour => "contour",
            Tag::Link => "link",
        }
    }
}

/// One move of the tool centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Move {
    /// The piece (mm).
    pub seg: Seg,
    /// What it does.
    pub tag: Tag,
    /// True if the tool retracts and comes down at the move's start (a new chain).
    pub retract_before: bool,
}

/// The moves of one layer.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Program {
    /// Moves in order.
    pub moves: Vec<Move>,
}

impl Program {
    /// Appends a closed or open contour's pieces; the first piece starts a chain if `retract`.
    pub fn push_contour(&mut self, c: &Contour, tag: Tag, retract: bool) {
        for (k, seg) in c.segs().enumerate() {
            self.moves.push(Move { seg, tag, retract_before: retract && k == 0 });
        }
    }

    /// Appends `passes` linked by straight feed moves where a link keeps `wall` mm from every
    /// loop of `region` (a retract otherwise).
    pub fn push_passes(&mut self, passes: &[Pass], region: &Region, wall: f64) {
        for p in passes {
            let start = p.contour.vertices.first().map(|v| v.p);
            let linked = match (self.end(), start) {
                (Some(a), Some(b)) if (b - a).norm() > 0.0 => {
                    let link = Seg::Line(a, b);
                    let safe = clearance(&link, region) >= wall - camkit::tol::OFFSET_TOL;
                    if safe {
                        self.moves.push(Move { seg: link, tag: Tag::Link, retract_before: false });
                    }
                    safe
                }
                (Some(_), Some(_)) => true,
                _ => false,
            };
            self.push_contour(&p.contour, Tag::Contour, !linked);
        }
    }

    /// Where the last move ends.
    pub fn end(&self) -> Option<P2> {
        self.moves.last().map(|m| m.seg.end())
    }

    /// Total length of moves with `tag` (mm).
    pub fn length(&self, tag: Tag) -> f64 {
        self.moves.iter().filter(|m| m.tag == tag).map(|m| m.seg.length()).sum()
    }
}

/// Smallest distance from `s` to the boundary of `region` (mm), exactly.
pub fn clearance(s: &Seg, region: &Region) -> f64 {
    region.loops().iter().flat_map(|c| c.segs()).map(|b| b.min_distance(s)).fold(f64::INFINITY, f64::min)
}

/// Distance from `p` to the boundary of `region` (mm), exactly.
pub fn point_clearance(p: &P2, region: &Region) -> f64 {
    region.loops().iter().flat_map(|c| c.segs()).map(|b| b.distance_to(p)).fold(f64::INFINITY, f64::min)
}
