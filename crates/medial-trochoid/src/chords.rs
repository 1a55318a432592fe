//! Loops drawn with chords: a curve given as many short lines (a DXF polyline, a sliced mesh)
//! gives every pass a corner at each joint, all dangerous; found here so that the user can be
//! told to fit it to arcs first.

use camkit::contour::region::Region;
use camkit::contour::{Contour, Seg};
use camkit::geom::cross2;

/// A joint between two lines shorter than R that turns by less than this (degrees) is a curve
/// drawn with chords, not a corner.
pub const CHORD_TURN_DEG: f64 = 10.0;

/// The most consecutive joints of `c` (closed) that look like a curve drawn with chords: between
/// lines shorter than `r`, all turning the same way by less than [`CHORD_TURN_DEG`]. Every such
/// joint is a corner of every pass along it, and each corner is dangerous (a pass round it cuts
/// outward like the concave side cut), so the loops clear all of them; the same curve fitted to
/// arcs (curve-fit-arcs) is cut by concentric passes at the concave step instead.
pub fn chord_run(c: &Contour, r: f64) -> usize {
    let segs: Vec<Seg> = c.segs().collect();
    let n = segs.len();
    let limit = CHORD_TURN_DEG.to_radians().sin();
    // The signed turn at the joint after piece k, if it joins two short lines.
    let turn = |k: usize| match (segs[k], segs[(k + 1) % n]) {
        (Seg::Line(a, b), Seg::Line(_, d)) if (b - a).norm() < r && (d - b).norm() < r => {
            let (u, v) = ((b - a).normalize(), (d - b).normalize());
            let t = cross2(&u, &v);
            (u.dot(&v) > 0.0 && t.abs() < limit && t != 0.0).then_some(t.signum())
        }
        _ => None,
    };
    let turns: Vec<Option<f64>> = (0..n).map(turn).collect();
    let (mut best, mut run, mut sign) = (0, 0, 0.0);
    // Twice round, so that a run through the loop's start counts whole.
    for k in 0..2 * n {
        match turns[k % n] {
            Some(t) if t == sign => run += 1,
            Some(t) => (run, sign) = (1, t),
            None => (run, sign) = (0, 0.0),
        }
        best = best.max(run.min(n));
    }
    best
}

/// Runs of [`chord_run`] this long or longer make a loop a curve drawn with chords.
pub const CHORD_RUN_MIN: usize = 12;

/// The loops of `regions` drawn with chords (a [`chord_run`] of [`CHORD_RUN_MIN`] or more for a
/// tool of radius `r`): (the loop's index in the input, the run).
pub fn drawn_with_chords(regions: &[Region], r: f64) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = regions
        .iter()
        .flat_map(|g| {
            std::iter::once((&g.outer, g.outer_source)).chain(g.islands.iter().zip(g.island_sources.iter().copied()))
        })
        .map(|(c, source)| (source, chord_run(c, r)))
        .filter(|&(_, run)| run >= CHORD_RUN_MIN)
        .collect();
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use camkit::geom::P2;

    #[test]
    fn curves_drawn_with_chords_are_told_from_corners() {
        let ngon = |n: usize, radius: f64| {
            let pts: Vec<P2> = (0..n)
                .map(|k| {
                    let a = k as f64 * std::f64::consts::TAU / n as f64;
                    P2::new(radius * a.cos(), radius * a.sin())
                })
                .collect();
            Contour::polygon(&pts, true)
        };
        // A 100-gon of radius 40: sides of 2.5 mm turning 3.6° each, all the way round.
        assert_eq!(chord_run(&ngon(100, 40.0), 5.0), 100);
        assert_eq!(chord_run(&ngon(100, 40.0).reversed(), 5.0), 100);
        // Sides of 2.5 mm are not short for a tool of radius 2; a 24-gon turns 15° at each corner.
        assert_eq!(chord_run(&ngon(100, 40.0), 2.0), 0);
        assert_eq!(chord_run(&ngon(24, 5.0), 5.0), 0);
        // A square with its top drawn through nine points of a shallow bow 1 mm apart: the 8
        // joints of the short lines from the second point on (the first line, from the
        // square's corner, is long).
        let mut pts = vec![P2::new(0.0, 0.0), P2::new(10.0, 0.0)];
        pts.extend(
            (1..10).map(|k| P2::new(10.0 - f64::from(k), 10.0 + (f64::from(k) * 0.1 * std::f64::consts::PI).sin())),
        );
        pts.extend([P2::new(0.0, 10.0)]);
        assert_eq!(chord_run(&Contour::polygon(&pts, true), 5.0), 8);
    }
}
