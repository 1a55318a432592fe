//! The walls of a 2.5-D part: closed loops (pocket boundaries and islands) standing vertically
//! from a floor to a top, against which a vertical tool's moves are measured exactly (distances
//! between lines and arcs in XY).

use crate::contour::region::Region;
use crate::contour::{Seg, SegSet};
use crate::geom::P2;

/// A vertical tool body for the walls: the cutter's radius from the tip up `length`, then a
/// holder of `holder_radius` up `holder_length` (none when 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Column {
    /// Radius of the cutting part (mm).
    pub radius: f64,
    /// Height of the cutting part above the tip (mm).
    pub length: f64,
    /// Radius of the holder (mm; 0 for none).
    pub holder_radius: f64,
}

/// How near a move comes to the part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearance {
    /// Signed clearance (mm): horizontal distance of the body from the walls, or height of the
    /// tip above the floor, whichever is smaller; negative inside the part.
    pub mm: f64,
    /// Where along the move (fraction).
    pub at: f64,
}

/// The walls.
pub struct Walls {
    regions: Vec<Region>,
    set: SegSet,
    floor: f64,
    top: f64,
    /// Distances beyond this are not measured (reported as this).
    reach: f64,
}

impl Walls {
    /// Walls of `regions` from `floor` to `top`; clearances are measured up to `reach` mm.
    pub fn new(regions: &[Region], floor: f64, top: f64, reach: f64) -> Walls {
        let loops: Vec<_> = regions.iter().flat_map(|r| r.loops()).collect();
        Walls { regions: regions.to_vec(), set: SegSet::new(loops), floor, top, reach }
    }

    /// Top of the walls.
    pub fn top(&self) -> f64 {
        self.top
    }

    /// Clearance of the body whose tip runs from height `z0` to `z1` (linearly) over the XY
    /// piece: the smallest of the cutting part's and the holder's horizontal distances from the
    /// walls where they are below the walls' top, and the tip's height above the floor inside the
    /// regions. A move that lies inside the part (an island, or outside every boundary) below
    /// the top has the negative of its depth into it.
    pub fn clearance(&self, body: &Column, piece: &Seg, z0: f64, z1: f64) -> Clearance {
        let mut best = Clearance { mm: self.reach, at: 0.0 };
        let mut take = |mm: f64, at: f64| {
            if mm < best.mm {
                best = Clearance { mm, at };
            }
        };
        for (radius, lift) in [(body.radius, 0.0), (body.holder_radius, body.length)] {
            if radius <= 0.0 {
                continue;
            }
            let Some((t0, t1)) = below(z0 + lift, z1 + lift, self.top) else { continue };
            let sub = piece.sub(t0, t1);
            let (d, at) = self.distance(&sub, radius);
            let inside = self.regions.iter().any(|r| r.contains(&sub.start()));
            take(if inside { d - radius } else { -(d + radius) }, t0 + (t1 - t0) * at);
        }
        let low = if z1 < z0 { (z1, 1.0) } else { (z0, 0.0) };
        if low.0 < self.top && self.regions.iter().any(|r| r.contains(&piece.point_at(low.1))) {
            take(low.0 - self.floor, low.1);
        }
        best
    }

    /// Smallest distance from the piece to the walls (up to the reach beyond `radius`), and the
    /// fraction of the piece nearest it.
    fn distance(&self, piece: &Seg, radius: f64) -> (f64, f64) {
        let (lo, hi) = piece.bounds();
        let mut best = (self.reach + radius, 0.0);
        for i in self.set.near(&lo, &hi, self.reach + radius) {
            let wall = &self.set.segs[i];
            let d = piece.min_distance(wall);
            if d < best.0 {
                best = (d, nearest_fraction_to(piece, wall));
            }
        }
        best
    }
}

/// The fractions of a move whose height (from `z0` to `z1`) is below `top`.
fn below(z0: f64, z1: f64, top: f64) -> Option<(f64, f64)> {
    match (z0 < top, z1 < top) {
        (true, true) => Some((0.0, 1.0)),
        (false, false) => None,
        (true, false) => Some((0.0, (top - z0) / (z1 - z0))),
        (false, true) => Some(((top - z0) / (z1 - z0), 1.0)),
    }
}

/// Fraction of `piece` nearest `wall` (by samples: only to say where).
fn nearest_fraction_to(piece: &Seg, wall: &Seg) -> f64 {
    (0..=32)
        .map(|k| k as f64 / 32.0)
        .map(|t| (wall.distance_to(&piece.point_at(t)), t))
        .fold((f64::INFINITY, 0.0), |a, b| if b.0 < a.0 { b } else { a })
        .1
}

/// Distance from `p` to the walls (for tests and messages).
pub fn point_distance(walls: &Walls, p: &P2) -> f64 {
    walls.distance(&Seg::Line(*p, *p), 0.0).0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::Contour;
    use crate::contour::region::regions;
    use crate::geom::Arc2;

    /// A 100 × 60 pocket with a round island R8 at (30, 30), floor −12, top 0.
    fn pocket() -> Walls {
        let outer =
            Contour::polygon(&[P2::new(0.0, 0.0), P2::new(100.0, 0.0), P2::new(100.0, 60.0), P2::new(0.0, 60.0)], true);
        let island = Contour::circle(P2::new(30.0, 30.0), 8.0, 0.0, true);
        let (r, _) = regions(&[outer, island]).unwrap();
        Walls::new(&r, -12.0, 0.0, 10.0)
    }

    const R4: Column = Column { radius: 4.0, length: 20.0, holder_radius: 0.0 };

    #[test]
    fn passes_at_r_touch_and_moves_across_an_island_go_into_it() {
        let w = pocket();
        // Along the wall at R: touching (0); 1 mm further in: 1.
        let c = w.clearance(&R4, &Seg::Line(P2::new(10.0, 4.0), P2::new(90.0, 4.0)), -6.0, -6.0);
        assert!(c.mm.abs() < 1e-12, "{c:?}");
        let c = w.clearance(&R4, &Seg::Line(P2::new(10.0, 5.0), P2::new(90.0, 5.0)), -6.0, -6.0);
        assert!((c.mm - 1.0).abs() < 1e-12, "{c:?}");
        // Round the island at 8 + 4 + 0.5 (an arc): 0.5.
        let arc = Seg::Arc(Arc2 { c: P2::new(30.0, 30.0), r: 12.5, start: 0.0, sweep: 3.0 });
        let c = w.clearance(&R4, &arc, -6.0, -6.0);
        assert!((c.mm - 0.5).abs() < 1e-12, "{c:?}");
        // Straight across the island at depth: into it by R.
        let across = Seg::Line(P2::new(10.0, 30.0), P2::new(50.0, 30.0));
        let c = w.clearance(&R4, &across, -6.0, -6.0);
        assert!((c.mm + 4.0).abs() < 1e-12, "{c:?}");
        assert!((c.at - 0.3).abs() < 0.04, "{c:?}");
        // The same above the top: clear (the reach).
        assert_eq!(w.clearance(&R4, &across, 1.0, 1.0).mm, 10.0);
        // Descending across the top: only the part below counts.
        let down = Seg::Line(P2::new(40.0, 30.0), P2::new(44.0, 30.0));
        let c = w.clearance(&R4, &down, 10.0, -10.0);
        assert!((c.mm - (4.0 - 4.0)).abs() < 1e-9, "{c:?}");
        // A plunge inside the island: deep inside.
        let c = w.clearance(&R4, &Seg::Line(P2::new(30.0, 30.0), P2::new(30.0, 30.0)), 5.0, -3.0);
        assert!((c.mm + 12.0).abs() < 1e-12, "{c:?}");
    }

    #[test]
    fn the_floor_and_the_holder() {
        let w = pocket();
        let mid = Seg::Line(P2::new(70.0, 30.0), P2::new(80.0, 30.0));
        let c = w.clearance(&R4, &mid, -11.0, -12.5);
        assert!((c.mm + 0.5).abs() < 1e-12 && c.at == 1.0, "{c:?}");
        // A holder of radius 10 from 5 mm above the tip reaches the wall top when the tip is
        // below −5: 8 mm from the wall it is 2 mm into it.
        let body = Column { radius: 4.0, length: 5.0, holder_radius: 10.0 };
        let side = Seg::Line(P2::new(60.0, 8.0), P2::new(90.0, 8.0));
        assert!((w.clearance(&body, &side, -4.0, -4.0).mm - 4.0).abs() < 1e-12);
        assert!((w.clearance(&body, &side, -6.0, -6.0).mm + 2.0).abs() < 1e-12);
        assert!((point_distance(&w, &P2::new(50.0, 30.0)) - 10.0).abs() < 1e-12);
    }
}
