//! An independent measuring instrument for tests: programs turned into dense polylines (arcs
//! sampled as a controller would run them: centre from the start and the offsets, radius going
//! linearly from the start radius to the end radius) and a sampled two-sided Hausdorff distance
//! with a grid of buckets. It shares nothing with the filters' own deviation routines.

use camkit::gcode::{Block, Motion};
use camkit::geom::{P3, V3};
use std::collections::HashMap;

/// The path of every motion block of a G-code program, in order, arcs sampled so the polyline is
/// within `chord` (mm) of the true arc.
pub fn program_path(name: &str, text: &str, chord: f64) -> Vec<P3> {
    let program = camkit::gcode::read(name, text.to_string()).expect("program parses");
    let mut out = Vec::new();
    for b in &program.blocks {
        let Block::Move(m) = b else { continue };
        if !m.start_known {
            out.push(m.end);
            continue;
        }
        if out.is_empty() {
            out.push(m.start);
        }
        match (m.motion, m.centre) {
            (Motion::Cw | Motion::Ccw, Some(c)) => {
                let plane = m.modes.plane;
                let (s, ws) = plane.split(&m.start);
                let (e, we) = plane.split(&m.end);
                let (r0, r1) = ((s - c).norm(), (e - c).norm());
                let a0 = (s.y - c.y).atan2(s.x - c.x);
                let a1 = (e.y - c.y).atan2(e.x - c.x);
                let ccw = m.motion == Motion::Ccw;
                let mut sweep = a1 - a0;
                let tau = std::f64::consts::TAU;
                if ccw && sweep <= 0.0 {
                    sweep += tau;
                }
                if !ccw && sweep >= 0.0 {
                    sweep -= tau;
                }
                let r = r0.max(r1);
                let step = (8.0 * chord / r.max(1e-9)).sqrt().min(0.1);
                let n = ((sweep.abs() / step).ceil() as usize).max(1);
                for i in 1..=n {
                    let t = i as f64 / n as f64;
                    let a = a0 + sweep * t;
                    let rad = r0 + (r1 - r0) * t;
                    let q = camkit::geom::P2::new(c.x + rad * a.cos(), c.y + rad * a.sin());
                    out.push(plane.join(&q, ws + (we - ws) * t));
                }
            }
            _ => out.push(m.end),
        }
    }
    out
}

/// Buckets of segments for nearest-distance queries: distances up to half a cell are exact.
struct Grid<'a> {
    line: &'a [P3],
    cell: f64,
    buckets: HashMap<(i64, i64, i64), Vec<usize>>,
}

impl<'a> Grid<'a> {
    fn new(line: &'a [P3], cell: f64) -> Grid<'a> {
        let mut buckets: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
        let key = |v: f64| (v / cell).floor() as i64;
        for (i, w) in line.windows(2).enumerate() {
            // Samples a quarter cell apart; each lands its segment in its cell and the 26 around,
            // so a point within half a cell of the segment finds it in its own cell.
            let n = (((w[1] - w[0]).norm() / (0.25 * cell)).ceil() as usize).max(1);
            let mut last = None;
            for k in 0..=n {
                let p = w[0] + (w[1] - w[0]) * (k as f64 / n as f64);
                let c = (key(p.x), key(p.y), key(p.z));
                if last == Some(c) {
                    continue;
                }
                last = Some(c);
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            let list = buckets.entry((c.0 + dx, c.1 + dy, c.2 + dz)).or_default();
                            if list.last() != Some(&i) {
                                list.push(i);
                            }
                        }
                    }
                }
            }
        }
        Grid { line, cell, buckets }
    }

    /// Distance from `p` to the polyline, exact when below half a cell (infinite if nothing is near).
    fn distance(&self, p: &P3) -> f64 {
        let key = |v: f64| (v / self.cell).floor() as i64;
        self.buckets
            .get(&(key(p.x), key(p.y), key(p.z)))
            .into_iter()
            .flatten()
            .map(|&i| segment_distance(p, &self.line[i], &self.line[i + 1]))
            .fold(f64::INFINITY, f64::min)
    }
}

fn segment_distance(p: &P3, a: &P3, b: &P3) -> f64 {
    let d: V3 = b - a;
    let l2 = d.norm_squared();
    let t = if l2 > 0.0 { ((p - a).dot(&d) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + d * t)).norm()
}

/// Points along a polyline at most `step` apart (vertices included).
fn samples(line: &[P3], step: f64) -> Vec<P3> {
    let mut out = Vec::new();
    for w in line.windows(2) {
        let n = (((w[1] - w[0]).norm() / step).ceil() as usize).max(1);
        for i in 0..n {
            out.push(w[0] + (w[1] - w[0]) * (i as f64 / n as f64));
        }
    }
    out.extend(line.last());
    out
}

/// Sampled two-sided Hausdorff distance between two polylines (exact distances from samples
/// `step` apart); distances above `cell / 2` may come back as infinite.
pub fn hausdorff(a: &[P3], b: &[P3], step: f64, cell: f64) -> f64 {
    let ga = Grid::new(a, cell);
    let gb = Grid::new(b, cell);
    let ab = samples(a, step).iter().map(|p| gb.distance(p)).fold(0.0, f64::max);
    let ba = samples(b, step).iter().map(|p| ga.distance(p)).fold(0.0, f64::max);
    ab.max(ba)
}
