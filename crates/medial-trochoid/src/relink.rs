//! Links that meet uncut material: a straight step-over link into the next pass crosses the band
//! that pass is about to side-cut, and entering that band at any angle β to its edge engages
//! acos(1 − s/R) + β, over the threshold for every β > 0. So the pass (closed) is started
//! instead where a tool standing there has the least material on its circle (0 where earlier
//! loops or passes cleared it), and reached by a straight link through the pocket if that keeps
//! clear of the walls, else by a retract and a plunge there. A link still over the threshold
//! after that, or one that does not lead into a closed pass, becomes a retract; so does the link
//! after the pass if it cannot be made again from the pass's new end ([`Program::mend`]).

use crate::engagement::Cut;
use crate::program::{Move, Program, Tag, clearance};
use camkit::contour::region::Region;
use rayon::prelude::*;

/// A link replaced: where its pass now starts and the engagement of a tool standing there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Relink {
    /// The pass's new start (mm).
    pub at: camkit::geom::P2,
    /// Engagement of a tool standing there after everything cut before (degrees).
    pub standing_deg: f64,
    /// True if the pass is reached by a retract and a plunge (no feed link).
    pub retract: bool,
}

/// Index range of the pass that link `i` leads into (moves tagged contour, no retract), if it
/// is closed.
fn pass_after(p: &Program, i: usize) -> Option<(usize, usize)> {
    let j0 = i + 1;
    let mut j1 = j0;
    while j1 < p.moves.len() && p.moves[j1].tag == Tag::Contour && (j1 == j0 || !p.moves[j1].retract_before) {
        j1 += 1;
    }
    let closed = j1 > j0 && (p.moves[j0].seg.start() - p.moves[j1 - 1].seg.end()).norm() <= camkit::tol::OFFSET_TOL;
    closed.then_some((j0, j1))
}

/// The program with link `i` (whose samples go over the threshold) replaced, and what was done;
/// `None` if the link does not lead into a closed pass.
pub fn relink(
    p: &Program,
    i: usize,
    radius: f64,
    wall: f64,
    sample: f64,
    regions: &[Region],
) -> Option<(Program, Relink)> {
    let (j0, j1) = pass_after(p, i)?;
    let cut = Cut::new(radius, p.moves[..i].iter().map(|m| m.seg).collect());
    // Candidate starts: every sample along the pass (at most `sample` apart, move starts included).
    let candidates: Vec<(usize, f64)> = (j0..j1)
        .flat_map(|j| {
            let n = (p.moves[j].seg.length() / sample).ceil().max(1.0) as usize;
            (0..n).map(move |k| (j, k as f64 / n as f64))
        })
        .collect();
    let standing: Vec<f64> =
        candidates.par_iter().map(|&(j, t)| cut.engagement_at(&p.moves[j].seg.point_at(t), i)).collect();
    let best = (0..candidates.len()).fold(0, |b, k| if standing[k] < standing[b] { k } else { b });
    let (jb, tb) = candidates[best];
    let at = p.moves[jb].seg.point_at(tb);
    let from = p.moves[i].seg.start();
    let already = best == 0;
    // The rotated pass: from the best point round to it again.
    let mut pass: Vec<Move> = Vec::new();
    let piece =
        |j: usize, a: f64, b: f64| Move { seg: p.moves[j].seg.sub(a, b), tag: Tag::Contour, retract_before: false };
    if tb > 0.0 {
        pass.push(piece(jb, tb, 1.0));
    } else {
        pass.push(piece(jb, 0.0, 1.0));
    }
    pass.extend((jb + 1..j1).chain(j0..jb).map(|j| piece(j, 0.0, 1.0)));
    if tb > 0.0 {
        pass.push(piece(jb, 0.0, tb));
    }
    let link = camkit::contour::Seg::Line(from, at);
    let safe = !already
        && (at - from).norm() > camkit::tol::POINT_EPS
        && regions.iter().map(|r| clearance(&link, r)).fold(f64::INFINITY, f64::min) >= wall - camkit::tol::OFFSET_TOL;
    let mut moves: Vec<Move> = p.moves[..i].to_vec();
    if safe {
        moves.push(Move { seg: link, tag: Tag::Link, retract_before: p.moves[i].retract_before });
    } else {
        pass[0].retract_before = true;
    }
    moves.extend(pass);
    moves.extend_from_slice(&p.moves[j1..]);
    // The pass now ends where it starts, not where the link after it began: that link is made
    // again from there (or becomes a retract).
    let mut q = Program { moves };
    q.mend(regions, wall);
    Some((q, Relink { at, standing_deg: standing[best].to_degrees(), retract: !safe }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use camkit::contour::{Contour, Seg};
    use camkit::geom::P2;

    #[test]
    fn a_link_into_uncut_material_moves_the_pass_start_to_cleared_ground() {
        // A slot along y = 0 from x = 0 to 40, then a link up to a 40 × 2.34 rectangle around
        // it whose start (0, −1.17) sits on the band the rectangle is about to cut.
        let r = 5.0;
        let s = 1.17;
        let mut p = Program::default();
        p.moves.push(Move {
            seg: Seg::Line(P2::new(0.0, 0.0), P2::new(40.0, 0.0)),
            tag: Tag::Contour,
            retract_before: true,
        });
        p.moves.push(Move {
            seg: Seg::Line(P2::new(40.0, 0.0), P2::new(40.0, -s)),
            tag: Tag::Link,
            retract_before: false,
        });
        let ring = Contour::polygon(&[P2::new(40.0, -s), P2::new(40.0, s), P2::new(0.0, s), P2::new(0.0, -s)], true);
        p.push_contour(&ring, Tag::Contour, false);
        let (q, how) = relink(&p, 1, r, r, 0.5, &[]).expect("a closed pass follows");
        // The ring's corner (40, −s) is where the link came in; the best start has the least
        // material: the corner itself is not it (the slot's end disk leaves material ahead).
        assert_eq!(q.moves.len(), p.moves.len() + 1);
        let cut = Cut::new(r, vec![p.moves[0].seg]);
        assert!((cut.engagement_at(&how.at, 1).to_degrees() - how.standing_deg).abs() < 1e-12);
        let corner = cut.engagement_at(&P2::new(40.0, -s), 1).to_degrees();
        assert!(how.standing_deg <= corner, "{} vs {corner}", how.standing_deg);
        // The rotated pass is closed and as long as the ring.
        let len: f64 = q.moves.iter().filter(|m| m.tag == Tag::Contour).skip(1).map(|m| m.seg.length()).sum();
        assert!((len - ring.length()).abs() < 1e-9);
        let first = q.moves.iter().position(|m| m.tag == Tag::Contour && m.seg.start() == how.at).expect("starts at");
        assert_eq!(q.moves.last().unwrap().seg.end(), how.at);
        assert!(first >= 1);
    }
}
