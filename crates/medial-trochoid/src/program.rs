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

/// How an entry loop takes the tool down: `drop` mm (the layer's depth; 0 when no stock top is
/// known, the loop then cut flat at the layer) at `ramp_deg` degrees along the loop, as many
/// loops as that takes, then one more loop flat at the layer so that the disk it sweeps is
/// cleared to the layer's depth everywhere (the descending loops leave a ramp on the floor,
/// which the 2D simulation counts as cleared).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    /// Depth the entry descends (mm).
    pub drop: f64,
    /// Ramp angle along the loop (degrees, over 0 and under 90).
    pub ramp_deg: f64,
}

impl Entry {
    /// No descent: one loop at the layer.
    pub const FLAT: Entry = Entry { drop: 0.0, ramp_deg: 5.0 };

    /// Loops of length `loop_mm` an entry is cut in: the descending ones and the one at depth
    /// (one loop when there is no descent).
    pub fn loops(&self, loop_mm: f64) -> usize {
        if self.drop <= 0.0 || loop_mm <= 0.0 {
            return 1;
        }
        let per_loop = loop_mm * self.ramp_deg.to_radians().tan();
        (self.drop / per_loop - 1e-9).ceil().max(1.0) as usize + 1
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

    /// Appends the entry loop `c` as [`Entry::loops`] loops tagged entry, a retract before the
    /// first.
    pub fn push_entry(&mut self, c: &Contour, entry: &Entry) {
        for k in 0..entry.loops(c.length()) {
            self.push_contour(c, Tag::Entry, k == 0);
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

    /// Makes every chain continuous: a move that does not start where the one before it ends
    /// (and starts no chain) would be joined on the machine by a straight feed move the plan
    /// never checked. A link is re-made from the end before it if that keeps `wall` mm from
    /// every loop of `regions`, else dropped and its next move starts a chain (a retract); a
    /// cutting move gets such a link, or starts a chain. Returns how many moves became retracts.
    pub fn mend(&mut self, regions: &[Region], wall: f64) -> usize {
        let clear = |s: &Seg| {
            regions.iter().map(|r| clearance(s, r)).fold(f64::INFINITY, f64::min) >= wall - camkit::tol::OFFSET_TOL
        };
        let mut out: Vec<Move> = Vec::with_capacity(self.moves.len());
        let mut retracts = 0;
        let mut pending_retract = false;
        for mut m in self.moves.drain(..) {
            m.retract_before |= pending_retract;
            pending_retract = false;
            let Some(end) = out.last().map(|p| p.seg.end()) else {
                out.push(m);
                continue;
            };
            if m.retract_before || (m.seg.start() - end).norm() <= camkit::tol::POINT_EPS {
                out.push(m);
                continue;
            }
            if m.tag == Tag::Link {
                let link = Seg::Line(end, m.seg.end());
                if link.length() > camkit::tol::POINT_EPS && clear(&link) {
                    out.push(Move { seg: link, ..m });
                } else if link.length() > camkit::tol::POINT_EPS {
                    pending_retract = true;
                    retracts += 1;
                }
                continue;
            }
            let link = Seg::Line(end, m.seg.start());
            if clear(&link) {
                out.push(Move { seg: link, tag: Tag::Link, retract_before: false });
            } else {
                m.retract_before = true;
                retracts += 1;
            }
            out.push(m);
        }
        self.moves = out;
        retracts
    }

    /// The program with the link at `i` dropped and the move after it starting a chain (a
    /// retract and a plunge instead of the feed move).
    pub fn retract_link(&mut self, i: usize) {
        debug_assert_eq!(self.moves[i].tag, Tag::Link);
        self.moves.remove(i);
        if let Some(m) = self.moves.get_mut(i) {
            m.retract_before = true;
        }
    }

    /// True if every move starts where the one before it ends or starts a chain.
    pub fn continuous(&self) -> bool {
        self.moves
            .windows(2)
            .all(|w| w[1].retract_before || (w[1].seg.start() - w[0].seg.end()).norm() <= camkit::tol::POINT_EPS)
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn an_entry_descends_no_steeper_than_its_ramp_then_loops_once_at_depth() {
        // 10 mm at 5° along a 15.708 mm loop (radius 2.5): 114.3 mm of ramp, 7.28 loops, so 8
        // descending (at 4.55°) and one at depth; none descends without a depth.
        let e = Entry { drop: 10.0, ramp_deg: 5.0 };
        let l = TAU * 2.5;
        assert_eq!(e.loops(l), 9);
        let grade = e.drop / ((e.loops(l) - 1) as f64 * l);
        assert!(grade <= 5f64.to_radians().tan() && grade > 4.5f64.to_radians().tan(), "{grade}");
        // A whole number of loops at the ramp exactly: no extra loop for the roundoff.
        let exact = Entry { drop: 3.0 * l * 5f64.to_radians().tan(), ramp_deg: 5.0 };
        assert_eq!(exact.loops(l), 4);
        assert_eq!(Entry::FLAT.loops(l), 1);
        // Each loop pushed whole, the first after a retract.
        let mut p = Program::default();
        p.push_entry(&Contour::circle(P2::new(0.0, 0.0), 2.5, 0.0, true), &e);
        assert!((p.length(Tag::Entry) - 9.0 * l).abs() < 1e-9);
        assert_eq!(p.moves.iter().filter(|m| m.retract_before).count(), 1);
        assert!(p.moves[0].retract_before);
    }

    #[test]
    fn a_link_that_no_longer_starts_where_its_pass_ends_is_made_again_or_retracted() {
        // A 40 × 20 pocket; a pass ending at (10, 10), then a link that starts at (30, 10).
        let outer =
            Contour::polygon(&[P2::new(0.0, 0.0), P2::new(40.0, 0.0), P2::new(40.0, 20.0), P2::new(0.0, 20.0)], true);
        let region = Region { outer, islands: Vec::new(), outer_source: 0, island_sources: Vec::new() };
        let mv = |a: (f64, f64), b: (f64, f64), tag: Tag| Move {
            seg: Seg::Line(P2::new(a.0, a.1), P2::new(b.0, b.1)),
            tag,
            retract_before: false,
        };
        let program = |link_to: (f64, f64)| Program {
            moves: vec![
                Move { retract_before: true, ..mv((5.0, 10.0), (10.0, 10.0), Tag::Contour) },
                mv((30.0, 10.0), link_to, Tag::Link),
                mv(link_to, (link_to.0, 15.0), Tag::Contour),
            ],
        };
        // Clear of the walls by 5: the link is made from (10, 10).
        let mut p = program((30.0, 12.0));
        assert!(!p.continuous());
        assert_eq!(p.mend(std::slice::from_ref(&region), 5.0), 0);
        assert!(p.continuous());
        assert_eq!(p.moves[1].seg, Seg::Line(P2::new(10.0, 10.0), P2::new(30.0, 12.0)));
        assert_eq!(p.moves.len(), 3);
        // A wall distance of 9.5, which the straight move from (10, 10) breaks (its end is 8
        // from the wall y = 20): dropped, the pass after it starts a chain.
        let mut p = program((30.0, 12.0));
        assert_eq!(p.mend(&[region], 9.5), 1);
        assert!(p.continuous());
        assert_eq!(p.moves.len(), 2);
        assert!(p.moves[1].retract_before && p.moves[1].tag == Tag::Contour);
    }
}
