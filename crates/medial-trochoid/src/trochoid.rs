//! Trochoidal loops of constant radius along a polyline (a dangerous stretch of the medial
//! axis): a helical entry circle, then one counter-clockwise (climb) circle per pitch, each
//! started on the right of travel so that the step to the next loop leaves it tangentially.

use crate::engagement::Cut;
use crate::program::{Entry, Move, Program, Tag};
use camkit::contour::{Contour, Seg};
use camkit::geom::{P2, V2};

/// Appends trochoids along `run` with loop radius `rt` and `pitch` to `prog` (the entry loop
/// flat: for the engagement of the loops).
pub fn push_trochoids(prog: &mut Program, run: &[P2], rt: f64, pitch: f64) {
    let centres: Vec<(P2, f64)> = resample(run, pitch).into_iter().map(|c| (c, rt)).collect();
    push_loops(prog, &centres, &Entry::FLAT);
}

/// Appends trochoids along `run` whose loop radius and pitch at point `i` of the run are
/// `radii[i]` and `pitches[i]`, radii not increasing along the run (a smaller loop after a
/// larger one meets no more material than the pitch allows). Each step is the pitch at the
/// far end of the step (the smaller), each loop the radius there.
pub fn push_varying(prog: &mut Program, run: &[P2], radii: &[f64], pitches: &[f64], entry: &Entry) {
    let Some(&first) = run.first() else { return };
    let mut cum = vec![0.0];
    for w in run.windows(2) {
        cum.push(cum[cum.len() - 1] + (w[1] - w[0]).norm());
    }
    let total = cum[cum.len() - 1];
    // Index of the first run point at or after arc length `s`.
    let at = |s: f64| cum.partition_point(|&c| c < s).min(run.len() - 1);
    let point = |s: f64| {
        let j = at(s).max(1);
        let (a, b) = (run[j - 1], run[j]);
        let len = cum[j] - cum[j - 1];
        if len <= 0.0 { b } else { a + (b - a) * ((s - cum[j - 1]) / len).clamp(0.0, 1.0) }
    };
    let mut centres = vec![(first, radii[0])];
    let mut s = 0.0;
    while s < total {
        let p = pitches[at(s)].min(pitches[at(s + pitches[at(s)])]);
        s = (s + p).min(total);
        centres.push((point(s), radii[at(s)]));
    }
    push_loops(prog, &centres, entry);
}

/// Appends one loop per centre (with its radius): a helical entry circle at the first, then one
/// counter-clockwise (climb) circle per centre, each started on the right of travel; the entry
/// circle cut as `entry` takes it down.
fn push_loops(prog: &mut Program, centres: &[(P2, f64)], entry: &Entry) {
    let pts: Vec<P2> = centres.iter().map(|c| c.0).collect();
    let mut previous: Option<P2> = None;
    for (k, &(c, rt)) in centres.iter().enumerate() {
        let d = direction(&pts, k);
        let right = V2::new(d.y, -d.x);
        let s = c + right * rt;
        if let Some(p) = previous {
            prog.moves.push(Move { seg: Seg::Line(p, s), tag: Tag::Trochoid, retract_before: false });
        }
        let start = (s - c).y.atan2((s - c).x);
        let circle = Contour::circle(c, rt, start, true);
        if k == 0 {
            prog.push_entry(&circle, entry);
        } else {
            prog.push_contour(&circle, Tag::Trochoid, false);
        }
        previous = Some(s);
    }
}

/// Points along `run` spaced `pitch` apart by arc length, both ends included.
fn resample(run: &[P2], pitch: f64) -> Vec<P2> {
    let Some(&first) = run.first() else { return Vec::new() };
    let mut out = vec![first];
    // Distance travelled since the last point kept.
    let mut since = 0.0;
    for w in run.windows(2) {
        let len = (w[1] - w[0]).norm();
        let mut s = pitch - since;
        while s <= len {
            out.push(w[0] + (w[1] - w[0]) * (s / len));
            s += pitch;
        }
        since = len - (s - pitch);
    }
    let last = run[run.len() - 1];
    if (last - out[out.len() - 1]).norm() > 1e-9 {
        out.push(last);
    }
    out
}

/// Unit direction of travel at centre `k`.
fn direction(c: &[P2], k: usize) -> V2 {
    let (a, b) = if c.len() < 2 {
        return V2::new(1.0, 0.0);
    } else if k + 1 < c.len() {
        (c[k], c[k + 1])
    } else {
        (c[k - 1], c[k])
    };
    (b - a).try_normalize(0.0).unwrap_or(V2::new(1.0, 0.0))
}

/// Largest engagement (degrees) of trochoids with `rt` and `pitch` along a straight line, for a
/// tool of radius `r`, entry loop excluded, sampled every `step` mm.
pub fn straight_engagement(r: f64, rt: f64, pitch: f64, step: f64) -> f64 {
    let mut prog = Program::default();
    let run: Vec<P2> = vec![P2::origin(), P2::new(8.0 * pitch, 0.0)];
    push_trochoids(&mut prog, &run, rt, pitch);
    let cut = Cut::new(r, prog.moves.iter().map(|m| m.seg).collect());
    let samples = cut.samples(step);
    let e = cut.profile(&samples);
    samples.iter().zip(e).filter(|((i, _), _)| prog.moves[*i].tag != Tag::Entry).map(|(_, e)| e).fold(0.0, f64::max)
}

/// Margin (degrees) under the threshold that the pitch search aims at: the loops of a program
/// are sampled at other places than the straight run the pitch is chosen on.
pub const PITCH_MARGIN_DEG: f64 = 0.25;

/// The largest pitch (mm) whose trochoids stay at or under `threshold` degrees less
/// [`PITCH_MARGIN_DEG`] (bisection on the simulated engagement), or `None` if even a pitch of
/// 1 % of the tool radius does not.
pub fn pitch_for(r: f64, rt: f64, threshold: f64, step: f64) -> Option<f64> {
    let threshold = threshold - PITCH_MARGIN_DEG;
    let (mut lo, mut hi) = (0.01 * r, r);
    if straight_engagement(r, rt, lo, step) > threshold {
        return None;
    }
    if straight_engagement(r, rt, hi, step) <= threshold {
        return Some(hi);
    }
    for _ in 0..12 {
        let mid = 0.5 * (lo + hi);
        if straight_engagement(r, rt, mid, step) <= threshold { lo = mid } else { hi = mid }
    }
    Some(lo)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resample_keeps_pitch_and_ends() {
        let run = vec![P2::new(0.0, 0.0), P2::new(3.0, 0.0), P2::new(3.0, 4.0)];
        let c = resample(&run, 1.0);
        assert_eq!(c.len(), 8);
        for w in c.windows(2) {
            assert!((w[1] - w[0]).norm() <= 1.0 + 1e-12);
        }
        assert_eq!(c[c.len() - 1], P2::new(3.0, 4.0));
    }

    #[test]
    fn varying_loops_shrink_along_the_run_at_their_pitch() {
        let run: Vec<P2> = (0..=20).map(|k| P2::new(f64::from(k) * 0.5, 0.0)).collect();
        let radii: Vec<f64> = (0..=20).map(|k| 2.0 - 0.05 * f64::from(k)).collect();
        let pitches: Vec<f64> = radii.iter().map(|r| 0.1 * r).collect();
        let mut prog = Program::default();
        push_varying(&mut prog, &run, &radii, &pitches, &Entry::FLAT);
        // Loop centres (arc centres), in order: steps never longer than the pitch at their far end.
        let mut centres: Vec<(P2, f64)> = Vec::new();
        for m in &prog.moves {
            if let Seg::Arc(a) = m.seg
                && centres.last().is_none_or(|c| (c.0 - a.c).norm() > 1e-12)
            {
                centres.push((a.c, a.r));
            }
        }
        assert!(centres.len() > 20);
        for w in centres.windows(2) {
            assert!(w[1].1 <= w[0].1 + 1e-12);
            assert!((w[1].0 - w[0].0).norm() <= 0.1 * w[1].1 + 0.1 * 0.05 * 0.5 + 1e-12);
        }
        assert!((centres[centres.len() - 1].0 - P2::new(10.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn chosen_pitch_holds_the_threshold() {
        let (r, rt) = (5.0, 2.0);
        let p = pitch_for(r, rt, 40.0, 0.1).expect("a pitch");
        assert!(p > 0.05 && p < r, "{p}");
        assert!(straight_engagement(r, rt, p, 0.05) <= 40.0 + 0.5);
        assert!(straight_engagement(r, rt, 2.0 * p, 0.1) > 40.0);
    }
}
