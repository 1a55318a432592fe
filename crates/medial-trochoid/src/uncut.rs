//! What the tool leaves uncut when no program reaches it under the threshold: the opening of a
//! region by a radius ρ (a disk of radius ρ rolled inside it) and the stretches of the region's
//! loops that the opening does not reach.
//!
//! The opening shrinks the region by ρ (`camkit::contour::offset_region`, verified) and grows
//! what is left by ρ again (`camkit::contour::offset::grow_region`: all the shrunk loops together,
//! so that two pieces whose disks overlap, at a neck just under 2ρ wide, come out merged as one
//! loop, the boundary of their union; verified: each output piece at ρ within `OFFSET_TOL` from
//! the shrunk loops, none missing), nested again into regions.

use camkit::contour::offset::{OffsetOptions, grow_region, offset_region};
use camkit::contour::region::{Region, regions as nest};
use camkit::contour::{Contour, Seg};
use camkit::geom::P2;
use std::fmt;

/// Boundary points farther than this (mm) from the opened region are uncut: a micron, well
/// above the two verified offsets' deviation (2 × `OFFSET_TOL`), well below any rest worth naming.
pub const UNCUT_TOL: f64 = 1e-3;

/// A region opened by ρ: the pieces of one input region that a disk of radius ρ reaches.
#[derive(Clone, Debug, PartialEq)]
pub struct Opening {
    /// The opening radius (mm).
    pub rho: f64,
    /// The opened regions (each with the `outer_source` of the input region it lies in; its
    /// islands' sources are that region's outer source too: an opened island need not match an
    /// input one).
    pub regions: Vec<Region>,
}

/// Why an opening could not be made.
#[derive(Clone, Debug, PartialEq)]
pub struct OpenError(pub String);

impl fmt::Display for OpenError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "opening: {}", self.0)
    }
}

/// The opening of `regions` by `rho` (mm, > 0): each region shrunk by `rho`, the rest grown by
/// `rho` (merged where grown pieces overlap), nested into regions. A region narrower than 2ρ
/// everywhere has no opened piece.
pub fn open(regions: &[Region], rho: f64) -> Result<Opening, OpenError> {
    let opts = OffsetOptions::default();
    let mut out = Opening { rho, regions: Vec::new() };
    for region in regions {
        let shrunk = offset_region(region, rho, &opts).map_err(|e| OpenError(format!("shrinking by {rho} mm: {e}")))?;
        if shrunk.contours.is_empty() {
            continue;
        }
        let grown = grow(&shrunk.contours, rho)?;
        let (pieces, _) = nest(&grown).map_err(|e| OpenError(format!("the grown loops do not nest: {e}")))?;
        for mut piece in pieces {
            piece.outer_source = region.outer_source;
            piece.island_sources = vec![region.outer_source; piece.islands.len()];
            out.regions.push(piece);
        }
    }
    Ok(out)
}

/// The loops `shrunk` (oriented as a region: boundaries counter-clockwise, islands clockwise)
/// grown outward by `rho` together, verified.
fn grow(shrunk: &[Contour], rho: f64) -> Result<Vec<Contour>, OpenError> {
    let input: Vec<&Contour> = shrunk.iter().collect();
    let grown = grow_region(&input, rho, &OffsetOptions::default())
        .map_err(|e| OpenError(format!("growing by {rho} mm: {e}")))?;
    if grown.contours.is_empty() {
        return Err(OpenError(format!("growing by {rho} mm: no loop")));
    }
    Ok(grown.contours)
}

/// Area (mm²) of `regions` that no tool of radius `wall` reaches at all: the regions less their
/// opening by `wall` (the fillets of inside corners, acute tips, gaps narrower than 2·`wall`).
/// `None` if the opening cannot be made.
pub fn unreachable_area(regions: &[Region], wall: f64) -> Option<f64> {
    let opened = open(regions, wall).ok()?;
    let total: f64 = regions.iter().map(area).sum();
    Some((total - opened.regions.iter().map(area).sum::<f64>()).max(0.0))
}

/// Area of a region (mm²): the boundary's less the islands'.
pub fn area(r: &Region) -> f64 {
    r.outer.area().abs() - r.islands.iter().map(|i| i.area().abs()).sum::<f64>()
}

/// A stretch of an input loop left uncut: consecutive boundary samples farther than
/// [`UNCUT_TOL`] from the opened region.
#[derive(Clone, Debug, PartialEq)]
pub struct Stretch {
    /// Index of the loop in the input list (a region's `outer_source` or island source).
    pub source: usize,
    /// The uncut samples along the loop, in its direction (the first is `from`, the last `to`).
    pub points: Vec<P2>,
    /// Length along the loop from the first uncut sample to the last (mm).
    pub length: f64,
    /// Largest distance of a sample to the opened region's boundary (mm).
    pub thickness: f64,
    /// Where that sample is.
    pub thickest_at: P2,
}

/// Points of `c` at most `h` apart along it, every vertex included, each with its distance
/// along the loop from the first vertex; the first point is not repeated at the end.
pub fn samples(c: &Contour, h: f64) -> Vec<(P2, f64)> {
    let mut out = Vec::new();
    let mut along = 0.0;
    for s in c.segs() {
        let len = s.length();
        let n = (len / h).ceil().max(1.0) as usize;
        out.extend((0..n).map(|k| {
            let t = k as f64 / n as f64;
            (s.point_at(t), along + t * len)
        }));
        along += len;
    }
    out
}

/// Distance (mm) from `p` to the nearest piece of `segs` (infinite if none).
pub fn distance(p: &P2, segs: &[Seg]) -> f64 {
    segs.iter().map(|s| s.distance_to(p)).fold(f64::INFINITY, f64::min)
}

/// The stretches of the loops of `original` that `opened` leaves uncut, sampled every `h` mm
/// (vertices included): per loop, the maximal runs (around the loop's start too) of samples
/// farther than [`UNCUT_TOL`] from the opened boundary. The opened region lies inside the
/// original, so a boundary point's distance to it is its distance to the opened boundary.
pub fn stretches(original: &[Region], opened: &[Region], h: f64) -> Vec<Stretch> {
    let segs: Vec<Seg> = opened.iter().flat_map(|r| r.loops().into_iter().flat_map(|c| c.segs())).collect();
    let mut out = Vec::new();
    for r in original {
        let sources = std::iter::once(r.outer_source).chain(r.island_sources.iter().copied());
        for (c, source) in r.loops().into_iter().zip(sources) {
            let pts = samples(c, h);
            let d: Vec<f64> = pts.iter().map(|(p, _)| distance(p, &segs)).collect();
            let total = c.length();
            let n = pts.len();
            let uncut = |k: usize| d[k % n] > UNCUT_TOL;
            // Start after a sample that is reached, so that no stretch is split at the loop's start.
            let Some(first_cut) = (0..n).find(|&k| !uncut(k)) else {
                if n > 0 {
                    let k = (0..n).max_by(|&a, &b| d[a].total_cmp(&d[b])).expect("samples");
                    out.push(Stretch {
                        source,
                        points: pts.iter().map(|p| p.0).chain([pts[0].0]).collect(),
                        length: total,
                        thickness: d[k],
                        thickest_at: pts[k].0,
                    });
                }
                continue;
            };
            let mut k = first_cut + 1;
            while k < first_cut + n {
                if !uncut(k) {
                    k += 1;
                    continue;
                }
                let start = k;
                while k < first_cut + n && uncut(k) {
                    k += 1;
                }
                let idx: Vec<usize> = (start..k).map(|j| j % n).collect();
                let along = |j: usize| pts[j % n].1 + if j >= n { total } else { 0.0 };
                let thick = idx.iter().copied().max_by(|&a, &b| d[a].total_cmp(&d[b])).expect("a stretch");
                out.push(Stretch {
                    source,
                    points: idx.iter().map(|&j| pts[j].0).collect(),
                    length: along(k - 1) - along(start),
                    thickness: d[thick],
                    thickest_at: pts[thick].0,
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    fn region(loops: &[Contour]) -> Region {
        nest(loops).expect("valid loops").0.remove(0)
    }

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Contour {
        Contour::polygon(&[P2::new(x0, y0), P2::new(x1, y0), P2::new(x1, y1), P2::new(x0, y1)], true)
    }

    #[test]
    fn a_square_loses_its_corners_to_the_closed_form() {
        let (a, rho) = (20.0, 3.0);
        let sq = region(&[rect(0.0, 0.0, a, a)]);
        let o = open(std::slice::from_ref(&sq), rho).unwrap();
        assert_eq!(o.regions.len(), 1);
        let lost = area(&sq) - area(&o.regions[0]);
        assert!((lost - (4.0 - PI) * rho * rho).abs() < 1e-6, "{lost}");
        let st = stretches(std::slice::from_ref(&sq), &o.regions, 0.05);
        assert_eq!(st.len(), 4, "{st:?}");
        let corner = (2f64.sqrt() - 1.0) * rho;
        for s in &st {
            assert!((s.thickness - corner).abs() < 1e-6, "{s:?}");
            let c = s.thickest_at;
            assert!((c.x == 0.0 || c.x == a) && (c.y == 0.0 || c.y == a), "thickest at the corner: {c}");
            // Each stretch runs from the corner's tangent points (ρ along each side), less the
            // tolerance's sliver where the arc leaves the side (sqrt(2 ρ tol)).
            let reach = rho - (2.0 * rho * UNCUT_TOL).sqrt();
            assert!(s.length <= 2.0 * rho && s.length >= 2.0 * reach - 2.0 * 0.05, "{s:?}");
            assert_eq!(s.source, 0);
        }
    }

    #[test]
    fn a_circle_wider_than_the_opening_is_unchanged() {
        let disk = region(&[Contour::circle(P2::new(3.0, -2.0), 10.0, 0.4, true)]);
        let o = open(std::slice::from_ref(&disk), 4.0).unwrap();
        assert_eq!(o.regions.len(), 1);
        assert!((area(&o.regions[0]) - PI * 100.0).abs() < 1e-6);
        assert!(stretches(std::slice::from_ref(&disk), &o.regions, 0.1).is_empty());
        // Narrower than 2ρ everywhere: nothing is reached, the whole loop is one stretch.
        let o = open(std::slice::from_ref(&disk), 10.5).unwrap();
        assert!(o.regions.is_empty());
        let st = stretches(std::slice::from_ref(&disk), &o.regions, 0.1);
        assert_eq!(st.len(), 1);
        assert!((st[0].length - 20.0 * PI).abs() < 1e-9);
    }

    /// Two 20 × 20 rooms joined by a neck 6 long and `w` wide.
    fn rooms(w: f64) -> Region {
        let (lo, hi) = (10.0 - 0.5 * w, 10.0 + 0.5 * w);
        let pts = [
            (0.0, 0.0),
            (20.0, 0.0),
            (20.0, lo),
            (26.0, lo),
            (26.0, 0.0),
            (46.0, 0.0),
            (46.0, 20.0),
            (26.0, 20.0),
            (26.0, hi),
            (20.0, hi),
            (20.0, 20.0),
            (0.0, 20.0),
        ];
        region(&[Contour::polygon(&pts.map(|(x, y)| P2::new(x, y)), true)])
    }

    #[test]
    fn a_neck_narrower_than_the_opening_splits_the_rooms() {
        let rho = 2.0;
        let narrow = rooms(3.5);
        let o = open(std::slice::from_ref(&narrow), rho).unwrap();
        assert_eq!(o.regions.len(), 2, "{:?}", o.regions);
        // The whole neck is uncut: its walls on both sides, and the rooms' inside corners.
        let st = stretches(std::slice::from_ref(&narrow), &o.regions, 0.1);
        let near_neck = |p: &P2| p.x > 20.0 + 1e-9 && p.x < 26.0 - 1e-9;
        assert!(st.iter().filter(|s| s.points.iter().any(near_neck)).count() == 2, "{st:?}");
        let wide = rooms(4.5);
        let o = open(std::slice::from_ref(&wide), rho).unwrap();
        assert_eq!(o.regions.len(), 1);
        assert!(o.regions[0].islands.is_empty());
    }

    #[test]
    fn a_neck_just_under_the_opening_gives_overlapping_pieces_merged() {
        // Neck 3.9 wide and 1 long at ρ 2: the shrunk rooms bulge into the neck's mouths to
        // 1.9 mm apart (2 − sqrt(4 − 1.95²) past each room's wall), so their grown disks overlap
        // across the neck: one merged loop, not two crossing ones.
        let (lo, hi) = (10.0 - 1.95, 10.0 + 1.95);
        let pts = [
            (0.0, 0.0),
            (20.0, 0.0),
            (20.0, lo),
            (21.0, lo),
            (21.0, 0.0),
            (41.0, 0.0),
            (41.0, 20.0),
            (21.0, 20.0),
            (21.0, hi),
            (20.0, hi),
            (20.0, 20.0),
            (0.0, 20.0),
        ];
        let r = region(&[Contour::polygon(&pts.map(|(x, y)| P2::new(x, y)), true)]);
        let shrunk = offset_region(&r, 2.0, &OffsetOptions::default()).unwrap();
        assert_eq!(shrunk.contours.len(), 2, "the neck splits the shrunk rooms");
        let o = open(std::slice::from_ref(&r), 2.0).unwrap();
        assert_eq!(o.regions.len(), 1, "{:?}", o.regions);
        // It loses the 8 convex corners' fillets and at most the neck.
        let (lost, corners) = (area(&r) - area(&o.regions[0]), 8.0 * (1.0 - 0.25 * PI) * 4.0);
        assert!(lost >= corners - 1e-6 && lost < corners + 3.9, "{lost}");
    }

    /// A star-shaped loop about (0, 0): radii at equal angles.
    fn star(radii: &[f64]) -> Region {
        let n = radii.len() as f64;
        let pts: Vec<P2> = radii
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let a = k as f64 * 2.0 * PI / n;
                P2::new(r * a.cos(), r * a.sin())
            })
            .collect();
        region(&[Contour::polygon(&pts, true)])
    }

    /// A rectilinear staircase loop: columns of width 4 with the given heights.
    fn steps(heights: &[f64]) -> Region {
        let mut pts = vec![P2::new(0.0, 0.0)];
        let w = 4.0 * heights.len() as f64;
        pts.push(P2::new(w, 0.0));
        for (k, h) in heights.iter().enumerate().rev() {
            pts.push(P2::new(4.0 * (k + 1) as f64, *h));
            pts.push(P2::new(4.0 * k as f64, *h));
        }
        pts.dedup();
        region(&[Contour::polygon(&pts, true)])
    }

    fn check(r: &Region, rho: f64) {
        let o = open(std::slice::from_ref(r), rho).unwrap();
        let orig: Vec<Seg> = r.loops().into_iter().flat_map(|c| c.segs()).collect();
        let opened: Vec<Seg> = o.regions.iter().flat_map(|q| q.loops().into_iter().flat_map(|c| c.segs())).collect();
        // The opened region lies inside the original.
        for q in &o.regions {
            for c in q.loops() {
                for (p, _) in samples(c, 0.2) {
                    assert!(r.contains(&p) || distance(&p, &orig) <= UNCUT_TOL, "{p} outside");
                }
            }
        }
        assert!(o.regions.iter().map(area).sum::<f64>() <= area(r) + 1e-9);
        // Uncut samples are farther than the tolerance from it, the others within it.
        let h = 0.25;
        let st = stretches(std::slice::from_ref(r), &o.regions, h);
        let mut uncut = 0;
        for s in &st {
            for p in &s.points {
                assert!(distance(p, &opened) > UNCUT_TOL);
            }
            uncut += s.points.len();
        }
        let all: Vec<(P2, f64)> = r.loops().into_iter().flat_map(|c| samples(c, h)).collect();
        let reached = all.iter().filter(|(p, _)| distance(p, &opened) <= UNCUT_TOL).count();
        // A loop left whole repeats its first point to close the stretch.
        let whole = st.iter().filter(|s| s.points.first() == s.points.last() && s.points.len() > 1).count();
        assert_eq!(reached + uncut - whole, all.len());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(16))]

        #[test]
        fn opened_stars_lie_inside_and_name_what_they_leave(
            radii in proptest::collection::vec(6.0f64..14.0, 5..12),
            rho in 0.5f64..3.0,
        ) {
            check(&star(&radii), rho);
        }

        #[test]
        fn opened_staircases_lie_inside_and_name_what_they_leave(
            heights in proptest::collection::vec(2.0f64..16.0, 2..6),
            rho in 0.5f64..3.0,
        ) {
            check(&steps(&heights), rho);
        }
    }
}
