//! Regions to machine: closed contours nested into outer boundaries with islands.
//!
//! A loop inside an even number of other loops is an outer boundary; inside an odd number, an
//! island of the innermost boundary around it. Orientation follows the role (boundaries
//! counter-clockwise, islands clockwise), so "left of travel" is always the material to remove
//! and a climb-milling pass (spindle clockwise) runs in the loop's own direction.

use super::Contour;
use crate::geom::P2;
use std::fmt;

/// An outer boundary and the islands inside it.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// The boundary, counter-clockwise.
    pub outer: Contour,
    /// Islands, clockwise.
    pub islands: Vec<Contour>,
    /// Index of the outer loop in the input list.
    pub outer_source: usize,
    /// Indices of the islands in the input list.
    pub island_sources: Vec<usize>,
}

impl Region {
    /// Boundary then islands.
    pub fn loops(&self) -> Vec<&Contour> {
        std::iter::once(&self.outer).chain(&self.islands).collect()
    }

    /// True if `p` lies in the material to remove (inside the boundary, outside every island).
    pub fn contains(&self, p: &P2) -> bool {
        self.outer.winding_number(p) != 0 && self.islands.iter().all(|i| i.winding_number(p) == 0)
    }
}

/// Why loops do not make regions.
#[derive(Clone, Debug, PartialEq)]
pub enum RegionError {
    /// Loop `index` is open.
    Open(usize),
    /// Loop `index` has no area.
    Degenerate(usize),
    /// Loop `index` crosses itself at a point.
    SelfCrossing(usize, P2),
    /// Loops `a` and `b` cross or touch at a point.
    Crossing(usize, usize, P2),
}

impl fmt::Display for RegionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RegionError::Open(_) => write!(f, "a region needs closed contours: this one is open"),
            RegionError::Degenerate(_) => write!(f, "the contour encloses no area"),
            RegionError::SelfCrossing(_, p) => write!(f, "the contour crosses itself at ({:.6}, {:.6})", p.x, p.y),
            RegionError::Crossing(_, b, p) => {
                write!(f, "the contour crosses contour #{} at ({:.6}, {:.6})", b + 1, p.x, p.y)
            }
        }
    }
}

/// Nests closed, non-crossing loops into regions. Returns the regions and how many loops were
/// turned around to match their role.
pub fn regions(loops: &[Contour]) -> Result<(Vec<Region>, usize), RegionError> {
    for (i, c) in loops.iter().enumerate() {
        if !c.closed {
            return Err(RegionError::Open(i));
        }
        if c.seg_count() < 1 || c.area().abs() <= crate::tol::LENGTH_EPS {
            return Err(RegionError::Degenerate(i));
        }
        if let Some(p) = c.self_crossing() {
            return Err(RegionError::SelfCrossing(i, p));
        }
    }
    let bounds: Vec<(P2, P2)> = loops.iter().map(|c| c.bounds().expect("closed loops have pieces")).collect();
    for i in 0..loops.len() {
        for j in i + 1..loops.len() {
            let ((alo, ahi), (blo, bhi)) = (bounds[i], bounds[j]);
            if alo.x <= bhi.x && blo.x <= ahi.x && alo.y <= bhi.y && blo.y <= ahi.y {
                if let Some(p) = loops[i].crossing_with(&loops[j]) {
                    return Err(RegionError::Crossing(i, j, p));
                }
            }
        }
    }
    // Parent: the smallest loop containing this one; depth: how many contain it.
    let probes: Vec<P2> = loops.iter().map(|c| c.probe_point().expect("loops have pieces")).collect();
    let areas: Vec<f64> = loops.iter().map(|c| c.area().abs()).collect();
    let mut parent = vec![None; loops.len()];
    let mut depth = vec![0usize; loops.len()];
    for i in 0..loops.len() {
        for j in 0..loops.len() {
            if i != j && areas[j] > areas[i] && loops[j].winding_number(&probes[i]) != 0 {
                depth[i] += 1;
                if parent[i].is_none_or(|p: usize| areas[j] < areas[p]) {
                    parent[i] = Some(j);
                }
            }
        }
    }
    let mut turned = 0;
    let mut oriented = |c: &Contour, ccw: bool| {
        if c.is_ccw() == ccw {
            c.clone()
        } else {
            turned += 1;
            c.reversed()
        }
    };
    let mut out: Vec<Region> = Vec::new();
    let mut slot = vec![usize::MAX; loops.len()];
    for i in (0..loops.len()).filter(|&i| depth[i] % 2 == 0) {
        slot[i] = out.len();
        out.push(Region {
            outer: oriented(&loops[i], true),
            islands: Vec::new(),
            outer_source: i,
            island_sources: Vec::new(),
        });
    }
    for i in (0..loops.len()).filter(|&i| depth[i] % 2 == 1) {
        let p = parent[i].expect("an island has a boundary around it");
        let r = &mut out[slot[p]];
        r.islands.push(oriented(&loops[i], false));
        r.island_sources.push(i);
    }
    Ok((out, turned))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x: f64, y: f64, s: f64, ccw: bool) -> Contour {
        let c = Contour::polygon(&[P2::new(x, y), P2::new(x + s, y), P2::new(x + s, y + s), P2::new(x, y + s)], true);
        if ccw { c } else { c.reversed() }
    }

    #[test]
    fn nesting_decides_roles_and_orientation() {
        let loops = vec![square(2.0, 2.0, 2.0, true), square(0.0, 0.0, 10.0, false), square(2.5, 2.5, 1.0, true)];
        let (rs, turned) = regions(&loops).unwrap();
        assert_eq!(rs.len(), 2);
        assert_eq!(turned, 1 + 1);
        assert_eq!(rs[0].outer_source, 1);
        assert_eq!(rs[0].island_sources, vec![0]);
        assert!(rs[0].outer.is_ccw() && !rs[0].islands[0].is_ccw());
        assert_eq!(rs[1].outer_source, 2);
        assert!(rs[0].contains(&P2::new(1.0, 1.0)) && !rs[0].contains(&P2::new(3.0, 3.0)));
    }

    #[test]
    fn crossing_loops_are_refused() {
        let e = regions(&[square(0.0, 0.0, 10.0, true), square(5.0, 5.0, 10.0, true)]).unwrap_err();
        assert!(matches!(e, RegionError::Crossing(0, 1, _)), "{e:?}");
    }
}
