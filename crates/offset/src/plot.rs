//! SVGs of offsets: the input contours and the offset passes; for profiles, the paper's fig. 6
//! with the gouge of the unoffset tool.

use crate::profile::{Tool, Unoffset, profile_height};
use camkit::contour::{Contour, Seg};
use camkit::geom::P2;
use camkit::svg::{Aspect, Piece, Plot, Style};

/// Colour of input contours.
const INPUT: &str = "black";
/// Colour of offset passes.
const PASS: &str = "#1f77b4";
/// Colour of gouge regions.
const GOUGE: &str = "#d62728";
/// Most gouge slices drawn (more shade the same region and only add bytes).
const GOUGE_SLICES: usize = 300;

/// The pieces of a contour for the plot.
fn pieces(segs: impl Iterator<Item = Seg>) -> Vec<Piece> {
    segs.map(|s| match s {
        Seg::Line(_, b) => Piece::Line(b),
        Seg::Arc(a) => Piece::Arc(a),
    })
    .collect()
}

/// Draws a contour.
pub fn contour(plot: &mut Plot, c: &Contour, style: Style) {
    if let Some(first) = c.vertices.first() {
        plot.path(first.p, pieces(c.segs()), c.closed, style);
    }
}

/// Input contours and offset passes, pass starts as dots.
pub fn passes(title: &str, input: &[Contour], output: &[Contour]) -> Plot {
    let mut p = Plot::new(title, Aspect::Equal);
    for c in input {
        contour(&mut p, c, Style::stroke(INPUT, 1.6).named("input contour"));
    }
    for c in output {
        contour(&mut p, c, Style::stroke(PASS, 1.2).named("offset (tool centre)"));
    }
    let starts: Vec<P2> = output.iter().filter_map(|c| c.vertices.first().map(|v| v.p)).collect();
    p.dots(&starts, 2.5, Style::fill(PASS, 1.0).named("pass start"));
    p
}

/// Fig. 6 of paper 004 for one tool: the profile, the tool along the unoffset path (square: its
/// bottom every 1 mm; ball: its circle every 0.5 mm), the gouge regions where the unoffset square
/// bottom lies below the profile, and the verified tip path.
pub fn profile(title: &str, profile: &[Seg], tool: Tool, r: f64, tip: &[Seg], unoffset: &Unoffset) -> Plot {
    let mut p = Plot::new(title, Aspect::Equal);
    let (u0, u1) = (profile[0].start().x, profile[profile.len() - 1].end().x);
    if tool == Tool::Square {
        // Gouge: the region between the bottom and the profile above it, as thin slices.
        // At most GOUGE_SLICES slices, evenly spaced.
        let every = unoffset.u.len().div_ceil(GOUGE_SLICES).max(1);
        for (i, &u) in unoffset.u.iter().enumerate() {
            if unoffset.gouge[i] <= 0.0 || i % every != 0 {
                continue;
            }
            let f = profile_height(profile, u);
            let (a, b) = ((u - r).max(u0), (u + r).min(u1));
            let n = 12;
            let mut poly: Vec<P2> = (0..=n)
                .map(|k| {
                    let x = a + (b - a) * k as f64 / n as f64;
                    P2::new(x, profile_height(profile, x).max(f))
                })
                .collect();
            poly.push(P2::new(b, f));
            poly.push(P2::new(a, f));
            p.polygon(&poly, Style::fill(GOUGE, 0.15).named("gouge of the unoffset path (bottom below the profile)"));
        }
        let mut u = u0;
        while u <= u1 + 1e-9 {
            let f = profile_height(profile, u);
            p.polyline(
                &[P2::new(u - r, f), P2::new(u + r, f)],
                Style::stroke("#777", 1.0).named("square end mill bottom on the unoffset path, every 1 mm"),
            );
            u += 1.0;
        }
        for (a, b) in &unoffset.clear {
            let m = 0.5 * (a + b);
            p.label(P2::new(m - 1.5, profile_height(profile, m) + 2.5), &format!("x = {m:.1}"), 12.0, "green");
        }
    } else {
        let mut u = u0;
        while u <= u1 + 1e-9 {
            p.circle(
                P2::new(u, profile_height(profile, u)),
                r,
                Style::stroke("#999", 0.6).named("ball on the unoffset path, every 0.5 mm"),
            );
            u += 0.5;
        }
    }
    let first = profile[0].start();
    p.path(first, pieces(profile.iter().copied()), false, Style::stroke(INPUT, 1.8).named("profile"));
    if let Some(s) = tip.first() {
        p.path(
            s.start(),
            pieces(tip.iter().copied()),
            false,
            Style::stroke(PASS, 1.8).named("tip path, offset (never cuts into the profile)"),
        );
    }
    p
}

/// A view from above of a 3D contour and its offset.
pub fn space(title: &str, input: &[Vec<P2>], output: &[Vec<P2>]) -> Plot {
    let mut p = Plot::new(title, Aspect::Equal);
    for c in input {
        p.polyline(c, Style::stroke(INPUT, 1.4).named("contour (seen from +z)"));
    }
    for c in output {
        p.polyline(c, Style::stroke(PASS, 1.2).named("tool tip"));
    }
    p
}
