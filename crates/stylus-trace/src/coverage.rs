//! The coverage check of scan mode: every scan line's written CL points against an independent
//! drop of the stylus ([`crate::envelope`]) at the line's sample positions. A line is covered when
//! no stretch longer than the gap tolerance, with the model under it (a stylus smaller by the
//! envelope tolerance lands there), lies outside every pass,
//! and no CL point lies below the upper envelope by more than the envelope tolerance, measured
//! across the envelope (the vertical depth times the z of the envelope's normal there), and with
//! the envelope taken as its lowest within that tolerance horizontally, so a pass climbing a
//! vertical wall at a step of the envelope, or a point off a steep face of it within the contact
//! tolerance, is not counted. The chords between written points are checked the same way at the
//! sample positions, against the chord tolerance. Depths reported are vertical.

use crate::TracedPath;
use crate::envelope::Dropper;
use crate::scan::{self, Line, Scan};
use camkit::geom::P3;
use camkit::model::Model;
use rayon::prelude::*;

/// Points around a CL point, on a circle of the envelope tolerance, where the envelope is also
/// dropped: a point is below the envelope only if it is below all of them.
const NEIGHBOURS: usize = 8;

/// What the check asks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Longest stretch of a line, with the model under it, that no pass may cover (mm).
    pub gap: f64,
    /// Deepest a written point may lie below the envelope (mm).
    pub below: f64,
    /// Deepest a chord between written points may run below the envelope (mm).
    pub chord: f64,
    /// Spacing of the sample positions along a line (mm).
    pub spacing: f64,
}

/// A line that fails the check: where, and how.
#[derive(Clone, Debug, PartialEq)]
pub struct Defect {
    /// Line number (0-based, in output order).
    pub line: usize,
    /// Start of the stretch (stylus centre XY, z 0).
    pub from: P3,
    /// End of the stretch.
    pub to: P3,
    /// What is wrong.
    pub what: String,
}

/// Figures of the check over all lines.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Coverage {
    /// Scan lines checked.
    pub lines: usize,
    /// Drops made.
    pub drops: usize,
    /// Longest stretch with the model under it that no pass covers (mm).
    pub largest_gap: f64,
    /// Written points below the envelope by more than the tolerance.
    pub points_below: usize,
    /// Largest depth of a written point below the envelope (mm; 0 when none is below).
    pub largest_below: f64,
    /// Positions inside chords checked.
    pub chord_samples: usize,
    /// Of them, those where the chord runs below the envelope by more than the chord tolerance.
    pub chords_below: usize,
    /// Largest depth of a chord below the envelope among them (mm; 0 when none is).
    pub largest_chord_below: f64,
    /// The failing stretches, in line order.
    pub defects: Vec<Defect>,
}

/// Checks the written scan: `paths` carry their line number in `unit`, `round` maps a
/// coordinate to what is written.
pub fn check(
    model: &Model,
    radius: f64,
    scan: &Scan,
    paths: &[TracedPath],
    tol: &Tolerances,
    round: &(dyn Fn(f64) -> f64 + Sync),
) -> Coverage {
    let dropper = Dropper::new(model, radius, (tol.below * 0.1).max(1e-9));
    // The model is under a stretch no pass covers where a stylus smaller by the envelope's
    // tolerance still lands: the tracer may pass a contact by that depth, and a line grazing a
    // face's side (faces.step's roof at y = ±13, touched at its equator at exactly r) is no gap.
    let under = (radius - tol.below).max(0.5 * radius);
    let lines = scan::lines(scan);
    let per_line: Vec<LineFigures> = lines
        .par_iter()
        .enumerate()
        .map(|(k, line)| {
            let written: Vec<Vec<P3>> = paths
                .iter()
                .filter(|p| p.unit == k)
                .map(|p| p.points.iter().map(|q| q.centre.map(round)).collect())
                .collect();
            check_line(model, (&dropper, under), k, line, &written, tol)
        })
        .collect();
    let mut out = Coverage { lines: lines.len(), ..Coverage::default() };
    for f in per_line {
        out.drops += f.drops;
        out.largest_gap = out.largest_gap.max(f.largest_gap);
        out.points_below += f.below;
        out.largest_below = out.largest_below.max(f.largest_below);
        out.chord_samples += f.chord_samples;
        out.chords_below += f.chords_below;
        out.largest_chord_below = out.largest_chord_below.max(f.largest_chord_below);
        out.defects.extend(f.defects);
    }
    out
}

/// The z of the unit normal of the envelope at a stylus centre on it: from the model's nearest
/// point (the tolerance's scale only; the envelope itself comes from the drop).
fn slope(model: &Model, x: f64, y: f64, z: f64) -> f64 {
    let c = P3::new(x, y, z);
    model.nearest(&c).direction(&c).z.abs()
}

/// One line's figures.
#[derive(Default)]
struct LineFigures {
    drops: usize,
    largest_gap: f64,
    below: usize,
    largest_below: f64,
    chord_samples: usize,
    chords_below: usize,
    largest_chord_below: f64,
    defects: Vec<Defect>,
}

fn check_line(
    model: &Model,
    (d, under): (&Dropper, f64),
    k: usize,
    line: &Line,
    passes: &[Vec<P3>],
    tol: &Tolerances,
) -> LineFigures {
    let mut f = LineFigures::default();
    let at = |s: f64| line.at(s, 0.0);
    let drop = |s: f64, f: &mut LineFigures| {
        f.drops += 1;
        let p = at(s);
        d.drop_of(p.x, p.y, under)
    };
    // Covered stretches of the line parameter, merged.
    let mut covered: Vec<(f64, f64)> = passes
        .iter()
        .filter(|p| !p.is_empty())
        .map(|p| p.iter().map(|q| line.s_of(q)).fold((f64::INFINITY, -f64::INFINITY), |(a, b), s| (a.min(s), b.max(s))))
        .collect();
    covered.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut holes = Vec::new();
    let mut reach = line.s0;
    for (a, b) in covered {
        if a > reach {
            holes.push((reach, a.min(line.s1)));
        }
        reach = reach.max(b);
    }
    if reach < line.s1 {
        holes.push((reach, line.s1));
    }
    let delta = tol.gap * 0.25;
    for (a, b) in holes.into_iter().filter(|(a, b)| b > a) {
        let mut samples = if b - a <= 2.0 * delta {
            vec![0.5 * (a + b)]
        } else {
            let mut v = vec![a + delta];
            let first = ((a - line.s0) / tol.spacing).floor() as i64 + 1;
            let mut j = first;
            while line.s0 + j as f64 * tol.spacing < b - delta {
                let s = line.s0 + j as f64 * tol.spacing;
                if s > a + delta {
                    v.push(s);
                }
                j += 1;
            }
            v.push(b - delta);
            v
        };
        samples.dedup();
        let hits: Vec<bool> = samples.iter().map(|&s| drop(s, &mut f).is_some()).collect();
        let (Some(i0), Some(i1)) = (hits.iter().position(|&h| h), hits.iter().rposition(|&h| h)) else {
            continue;
        };
        // The model's stretch within the hole: to the hole's end where the end sample hits, else
        // bisected against the neighbouring miss.
        let edge = |hit: f64, miss: f64, f: &mut LineFigures| {
            let (mut h, mut m) = (hit, miss);
            while (h - m).abs() > delta {
                let mid = 0.5 * (h + m);
                if drop(mid, f).is_some() {
                    h = mid;
                } else {
                    m = mid;
                }
            }
            h
        };
        let lo = if i0 == 0 { a } else { edge(samples[i0], samples[i0 - 1], &mut f) };
        let hi = if i1 == samples.len() - 1 { b } else { edge(samples[i1], samples[i1 + 1], &mut f) };
        let gap = (hi - lo).max(0.0);
        f.largest_gap = f.largest_gap.max(gap);
        if gap > tol.gap {
            f.defects.push(Defect {
                line: k,
                from: at(lo),
                to: at(hi),
                what: format!("the model is under it but no pass covers {gap:.4} mm"),
            });
        }
    }
    // Written points against the envelope, its lowest within the tolerance around them.
    let mut below: Option<(P3, P3, f64, usize)> = None;
    for p in passes.iter().flatten() {
        if let Some(depth) = depth_below(model, d, p, tol.below, &mut f.drops) {
            f.below += 1;
            f.largest_below = f.largest_below.max(depth);
            let here = at(line.s_of(p));
            below = Some(match below {
                None => (here, here, depth, 1),
                Some((a, _, m, n)) => (a, here, m.max(depth), n + 1),
            });
        }
    }
    if let Some((from, to, depth, n)) = below {
        f.defects.push(Defect {
            line: k,
            from,
            to,
            what: format!("{n} CL points lie below the stylus's upper envelope, by up to {depth:.4} mm"),
        });
    }
    // The chords between them at the sample positions, against the chord tolerance.
    let mut under: Option<(P3, P3, f64)> = None;
    for pass in passes {
        for w in pass.windows(2) {
            let (sa, sb) = (line.s_of(&w[0]), line.s_of(&w[1]));
            if sb - sa <= 0.0 {
                continue;
            }
            let mut j = ((sa - line.s0) / tol.spacing).floor() as i64 + 1;
            while line.s0 + j as f64 * tol.spacing < sb {
                let s = line.s0 + j as f64 * tol.spacing;
                j += 1;
                if s <= sa {
                    continue;
                }
                let q = w[0] + (w[1] - w[0]) * ((s - sa) / (sb - sa));
                f.chord_samples += 1;
                if let Some(depth) = depth_below(model, d, &q, tol.chord, &mut f.drops) {
                    f.chords_below += 1;
                    f.largest_chord_below = f.largest_chord_below.max(depth);
                    under = Some(match under {
                        None => (at(s), at(s), depth),
                        Some((a, _, m)) => (a, at(s), m.max(depth)),
                    });
                }
            }
        }
    }
    if let Some((from, to, depth)) = under {
        f.defects.push(Defect {
            line: k,
            from,
            to,
            what: format!("between CL points the path runs below the stylus's upper envelope, by up to {depth:.4} mm"),
        });
    }
    f
}

/// How far `p` lies below the envelope (vertically) when it does by more than `tol`, measured
/// across the envelope (the depth times the z of its normal there, so a point within `tol` of a
/// steep face of it is not below), with the envelope taken as its lowest over `p`'s column and a
/// circle of radius `tol` round it (a pass climbing a vertical wall, a step of the envelope, is
/// not below). `drops` counts the drops made.
fn depth_below(model: &Model, d: &Dropper, p: &P3, tol: f64, drops: &mut usize) -> Option<f64> {
    let mut env = f64::INFINITY;
    // The neighbours only matter when the point is below the envelope right over it.
    for k in 0..=NEIGHBOURS {
        if env - p.z <= tol {
            return None;
        }
        let (dy, dx) = (k as f64 / NEIGHBOURS as f64 * std::f64::consts::TAU).sin_cos();
        let e = if k == 0 { 0.0 } else { tol };
        *drops += 1;
        env = env.min(d.drop(p.x + dx * e, p.y + dy * e).unwrap_or(-f64::INFINITY));
    }
    let depth = env - p.z;
    (depth > tol && depth * slope(model, p.x, p.y, env) > tol).then_some(depth)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Region;
    use crate::curve::ClPoint;
    use camkit::geom::V3;
    use camkit::io::Input;

    fn point(x: f64, y: f64, z: f64) -> ClPoint {
        let c = P3::new(x, y, z);
        ClPoint {
            centre: c,
            contact: c,
            normal: V3::z(),
            surface: 0,
            second: None,
            iterations: 1,
            residual: 0.0,
            front: true,
        }
    }

    /// A floor and a floating ball, r = 5: lines that run along the floor under the ball, one of
    /// them left half-traced, are named with their stretches.
    #[test]
    fn finds_gaps_and_points_under_the_envelope() {
        let m = Model::load(&Input {
            name: "m.json".into(),
            data: br#"{"surfaces": [{"type": "plane", "point": [0,0,0], "normal": [0,0,1]},
                                    {"type": "sphere", "centre": [50,0,30], "radius": 10}]}"#
                .to_vec(),
        })
        .unwrap();
        let scan =
            Scan { region: Region { x0: 20.0, x1: 80.0, y0: 0.0, y1: 4.0 }, angle: 0.0, pick: 4.0, zigzag: false };
        let pass = |y: f64, x0: f64, x1: f64, unit: usize| TracedPath {
            points: (0..=60).map(|k| point(x0 + (x1 - x0) * k as f64 / 60.0, y, 5.0)).collect(),
            deviation: 0.0,
            interrupted: false,
            unit,
        };
        // Line 0 (y = 0) along the floor right through under the ball; line 1 (y = 4) only to 50.
        let paths = [pass(0.0, 20.0, 80.0, 0), pass(4.0, 20.0, 50.0, 1)];
        let tol = Tolerances { gap: 1e-3, below: 1e-4, chord: 1.1e-3, spacing: 0.3 };
        let c = check(&m, 5.0, &scan, &paths, &tol, &|v| v);
        assert_eq!(c.lines, 2);
        assert!((c.largest_gap - 30.0).abs() < 1e-9, "{c:?}");
        // Under the ball (within 15 of its axis, the top 15 above its centre): 29 points of each
        // line, x 36..64 on y = 0 and 36..50 on y = 4.
        assert_eq!(c.points_below, 58, "{c:?}");
        assert!((c.largest_below - 40.0).abs() < 1e-9, "{c:?}");
        // The chords under the ball too, sampled every 0.3 mm.
        assert!(c.chord_samples > 250 && c.chords_below > 100, "{c:?}");
        assert!(c.largest_chord_below > 39.9, "{c:?}");
        assert_eq!(c.defects.len(), 5, "{:?}", c.defects);
        let gap = c.defects.iter().find(|d| d.line == 1 && d.what.contains("no pass")).unwrap();
        assert_eq!((gap.from.x, gap.to.x), (50.0, 80.0));
        let under = c.defects.iter().find(|d| d.line == 0).unwrap();
        assert_eq!((under.from.x, under.to.x), (36.0, 64.0));
    }
}
