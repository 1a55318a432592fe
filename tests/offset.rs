//! End-to-end tests of `offset`: every mode on the built binary against exact answers (circles,
//! rectangles, removed loops, pockets with islands, the paper's sine for square and ball end
//! mills through `curve-fit-arcs`, a square on a tilted plane), and bad input refused with one
//! clear line and no output file.

use camkit::geom::P2;
use camkit::geom::dist::point_segment;
use e2e::Work;
use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

const BIN: &str = "offset";
/// The promise: every output point within this of distance R (mm).
const TOL: f64 = 1e-6;

/// Rows of a CSV table as maps from column name to text.
fn table(text: &str) -> Vec<HashMap<String, String>> {
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<String> = lines.next().expect("header").split(',').map(str::to_string).collect();
    lines.map(|l| header.iter().cloned().zip(l.split(',').map(str::to_string)).collect::<HashMap<_, _>>()).collect()
}

fn num(row: &HashMap<String, String>, col: &str) -> f64 {
    row[col].parse().unwrap_or_else(|_| panic!("{col} = {:?}", row[col]))
}

/// One piece of a written path.
#[derive(Clone, Copy, Debug)]
enum Piece {
    Line(P2, P2),
    /// Centre, radius, start angle, signed sweep.
    Arc(P2, f64, f64, f64),
}

impl Piece {
    fn at(&self, t: f64) -> P2 {
        match *self {
            Piece::Line(a, b) => a + (b - a) * t,
            Piece::Arc(c, r, a0, sw) => c + r * camkit::geom::V2::new((a0 + t * sw).cos(), (a0 + t * sw).sin()),
        }
    }

    fn distance(&self, p: &P2) -> f64 {
        match *self {
            Piece::Line(a, b) => point_segment(p, &a, &b),
            Piece::Arc(c, r, a0, sw) => {
                let phi = (p.y - c.y).atan2(p.x - c.x);
                let k = ((phi - a0) * sw.signum()).rem_euclid(TAU);
                if k <= sw.abs() {
                    ((p - c).norm() - r).abs()
                } else {
                    (p - self.at(0.0)).norm().min((p - self.at(1.0)).norm())
                }
            }
        }
    }
}

/// Pieces of each path of a table (columns `u`, `v` as the plane's axes).
fn paths_in(text: &str, u: &str, v: &str) -> Vec<Vec<Piece>> {
    let rows = table(text);
    let mut out: Vec<Vec<Piece>> = Vec::new();
    let mut last: Option<(String, P2)> = None;
    for r in &rows {
        let p = P2::new(num(r, u), num(r, v));
        let id = r.get("path").cloned().unwrap_or_default();
        match &last {
            Some((pid, from)) if *pid == id && r["move"] != "rapid" => {
                let piece = match r["move"].as_str() {
                    "line" => Piece::Line(*from, p),
                    m => {
                        let c = P2::new(num(r, &format!("{u}c")), num(r, &format!("{v}c")));
                        let a0 = (from.y - c.y).atan2(from.x - c.x);
                        let a1 = (p.y - c.y).atan2(p.x - c.x);
                        let mut sw = (a1 - a0).rem_euclid(TAU);
                        if sw < 1e-12 {
                            sw = TAU;
                        }
                        if m == "cw" {
                            sw -= TAU;
                        }
                        // Written centres are rounded: the arc is the one through both ends
                        // with this sweep (as the filters read it).
                        assert!(((p - c).norm() - (*from - c).norm()).abs() < 1e-5, "arc ends at its radius");
                        let chord = p - *from;
                        let b = (sw / 4.0).tan();
                        let left = camkit::geom::V2::new(-chord.y, chord.x);
                        let c = *from + chord * 0.5 + left * ((1.0 - b * b) / (4.0 * b));
                        let a0 = (from.y - c.y).atan2(from.x - c.x);
                        Piece::Arc(c, (*from - c).norm(), a0, sw)
                    }
                };
                out.last_mut().expect("a path").push(piece);
            }
            _ => out.push(Vec::new()),
        }
        last = Some((id, p));
    }
    out
}

fn paths(text: &str) -> Vec<Vec<Piece>> {
    paths_in(text, "x", "y")
}

/// Sample points of every piece (ends and 15 interior points).
fn samples(path: &[Piece]) -> Vec<P2> {
    path.iter().flat_map(|s| (0..=16).map(move |k| s.at(k as f64 / 16.0))).collect()
}

/// Distance from `p` to a closed polygon.
fn polygon_distance(p: &P2, poly: &[P2]) -> f64 {
    (0..poly.len()).map(|i| point_segment(p, &poly[i], &poly[(i + 1) % poly.len()])).fold(f64::INFINITY, f64::min)
}

/// A closed polygon as a table (one path).
fn polygon_csv(path: i64, poly: &[P2]) -> String {
    let mut s = String::new();
    for (k, p) in poly.iter().chain(std::iter::once(&poly[0])).enumerate() {
        s.push_str(&format!("{path},{},{},{},,\n", if k == 0 { "rapid" } else { "line" }, p.x, p.y));
    }
    s
}

const HEAD: &str = "path,move,x,y,xc,yc\n";

fn report(w: &Work, name: &str) -> serde_json::Value {
    serde_json::from_str(&w.read(name)).expect("report is JSON")
}

fn pts(v: &[(f64, f64)]) -> Vec<P2> {
    v.iter().map(|&(x, y)| P2::new(x, y)).collect()
}

#[test]
fn circle_offsets_are_arcs_of_radius_r0_plus_or_minus_r() {
    let w = Work::new();
    // A counter-clockwise circle of radius 10 about (3, -1), as G-code too.
    let csv = format!("{HEAD}0,rapid,13,-1,,\n0,ccw,-7,-1,3,-1\n0,ccw,13,-1,3,-1\n");
    w.write("circle.csv", &csv);
    w.write("circle.nc", "G21 G90\nG0 X13 Y-1 Z0\nG3 X-7 Y-1 I-10 J0 F500\nG3 X13 Y-1 I10 J0\nM2\n");
    for (input, side, r, expect) in [
        ("circle.csv", "left", 2.5, 7.5),
        ("circle.csv", "right", 2.5, 12.5),
        ("circle.nc", "G41", 4.0, 6.0),
        ("circle.csv", "+1", 0.5, 10.5),
    ] {
        let out = w.run(BIN, &[input, "--radius", &r.to_string(), "--side", side], b"").ok();
        let ps = paths(&out);
        assert_eq!(ps.len(), 1, "{side}: {out}");
        for piece in &ps[0] {
            let Piece::Arc(c, rad, _, sw) = *piece else { panic!("an arc's offset is an arc: {piece:?}") };
            assert!((c - P2::new(3.0, -1.0)).norm() < TOL && (rad - expect).abs() < TOL, "{c} {rad}");
            assert!(sw > 0.0, "still counter-clockwise");
        }
        let swept: f64 = ps[0].iter().map(|p| if let Piece::Arc(_, _, _, s) = p { *s } else { 0.0 }).sum();
        assert!((swept - TAU).abs() < 1e-9, "one full turn: {swept}");
    }
    // Larger than the circle: nothing to cut, a warning, exit status 0.
    let out = w.run(BIN, &["circle.csv", "--radius", "10.5", "--side", "left", "-o", "gone.csv"], b"");
    out.ok();
    assert!(out.stderr.contains("leaves nothing"), "{}", out.stderr);
    assert!(paths(&w.read("gone.csv")).is_empty());
}

#[test]
fn rectangle_outside_gets_corner_arcs_of_radius_r_inside_stays_sharp() {
    let w = Work::new();
    let rect = pts(&[(0.0, 0.0), (40.0, 0.0), (40.0, 20.0), (0.0, 20.0)]);
    w.write("rect.csv", format!("{HEAD}{}", polygon_csv(7, &rect)));
    let out = w.run(BIN, &["rect.csv", "--radius", "3", "--side", "right", "--report", "r.json"], b"").ok();
    let ps = paths(&out);
    assert_eq!(ps.len(), 1);
    let arcs: Vec<(P2, f64, f64)> =
        ps[0].iter().filter_map(|p| if let Piece::Arc(c, r, _, s) = p { Some((*c, *r, *s)) } else { None }).collect();
    assert_eq!(arcs.len(), 4, "one arc per convex corner");
    for (c, r, s) in arcs {
        assert!(rect.iter().any(|q| (q - c).norm() < TOL), "arc centred on a corner: {c}");
        assert!((r - 3.0).abs() < TOL && (s - PI / 2.0).abs() < 1e-9);
    }
    for p in samples(&ps[0]) {
        assert!((polygon_distance(&p, &rect) - 3.0).abs() <= TOL, "{p}");
    }
    let rep = report(&w, "r.json");
    assert!(rep["largest_deviation_mm"].as_f64().unwrap() <= TOL);
    assert!(out.lines().skip(1).all(|l| l.starts_with("0,")), "paths renumbered from 0");
    // Inside: the 34 × 14 rectangle, corners trimmed sharp.
    let out = w.run(BIN, &["rect.csv", "--radius", "3", "--side", "left"], b"").ok();
    let ps = paths(&out);
    assert!(ps[0].iter().all(|p| matches!(p, Piece::Line(..))));
    for p in samples(&ps[0]) {
        assert!((polygon_distance(&p, &rect) - 3.0).abs() <= TOL);
        assert!(p.x >= 3.0 - TOL && p.x <= 37.0 + TOL && p.y >= 3.0 - TOL && p.y <= 17.0 + TOL);
    }
}

#[test]
fn invalid_loops_are_removed_necks_split_and_narrow_slots_stay_uncut() {
    let w = Work::new();
    // Two 20 × 20 rooms joined by a neck 2 mm wide, and a slot 2 mm wide into the right room.
    let shape = pts(&[
        (0.0, 0.0),
        (20.0, 0.0),
        (20.0, 9.0),
        (30.0, 9.0),
        (30.0, 0.0),
        (50.0, 0.0),
        (50.0, 20.0),
        (41.0, 20.0),
        (41.0, 8.0),
        (39.0, 8.0),
        (39.0, 20.0),
        (30.0, 20.0),
        (30.0, 11.0),
        (20.0, 11.0),
        (20.0, 20.0),
        (0.0, 20.0),
    ]);
    w.write("rooms.csv", format!("{HEAD}{}", polygon_csv(0, &shape)));
    let out = w.run(BIN, &["rooms.csv", "--radius", "1.5", "--side", "left", "--svg", "rooms.svg"], b"").ok();
    let ps = paths(&out);
    assert_eq!(ps.len(), 2, "the neck splits the offset into two loops");
    for path in &ps {
        for p in samples(path) {
            let d = polygon_distance(&p, &shape);
            assert!((d - 1.5).abs() <= TOL, "{p} at {d}");
            assert!(!(p.x > 20.0 && p.x < 30.0), "nothing in the neck: {p}");
            assert!(!(p.x > 39.0 && p.x < 41.0 && p.y > 8.0), "nothing in the slot: {p}");
        }
    }
    assert!(w.read("rooms.svg").starts_with("<svg") || w.read("rooms.svg").contains("<svg"));
    // A wider tool at 1 mm fits the neck: one loop through it.
    let out = w.run(BIN, &["rooms.csv", "--radius", "0.9", "--side", "left"], b"").ok();
    assert_eq!(paths(&out).len(), 1);
}

#[test]
fn pocket_with_an_island_passes_at_every_step_in_machining_order() {
    let w = Work::new();
    let square = pts(&[(0.0, 0.0), (60.0, 0.0), (60.0, 60.0), (0.0, 60.0)]);
    // The island given counter-clockwise: it is turned around (with a warning).
    let csv = format!("{HEAD}{}1,rapid,35,30,,\n1,ccw,25,30,30,30\n1,ccw,35,30,30,30\n", polygon_csv(0, &square));
    w.write("pocket.csv", &csv);
    let out = w.run(
        BIN,
        &["pocket.csv", "--radius", "1.5", "--repeat", "3", "--step", "2", "--report", "p.json", "-o", "p.csv"],
        b"",
    );
    out.ok();
    assert!(out.stderr.contains("turned around"), "{}", out.stderr);
    let text = w.read("p.csv");
    let rows = table(&text);
    let ps = paths(&text);
    assert_eq!(ps.len(), 6, "3 levels around the boundary and 3 around the island");
    let mut seen = Vec::new();
    for (k, path) in ps.iter().enumerate() {
        let d: f64 = num(rows.iter().find(|r| r["path"] == k.to_string()).unwrap(), "offset");
        let island = samples(path).iter().all(|p| (p - P2::new(30.0, 30.0)).norm() < 20.0);
        for p in samples(path) {
            let to_boundary = polygon_distance(&p, &square);
            let to_island = ((p - P2::new(30.0, 30.0)).norm() - 5.0).abs();
            assert!((to_boundary.min(to_island) - d).abs() <= TOL, "path {k} at {p}: {to_boundary} {to_island} vs {d}");
            assert!(to_boundary >= d - TOL && to_island >= d - TOL, "no gouge");
        }
        if island {
            assert!(path.iter().all(|p| matches!(p, Piece::Arc(_, r, _, _) if (r - 5.0 - d).abs() < TOL)));
        }
        seen.push((island, d));
    }
    // Machining order: from the centre out, the wall passes last.
    assert!(seen.windows(2).all(|w| w[0].1 >= w[1].1), "deepest first: {seen:?}");
    let mut ds: Vec<f64> = seen.iter().map(|s| s.1).collect();
    ds.sort_by(f64::total_cmp);
    ds.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    assert_eq!(ds, vec![1.5, 3.5, 5.5]);
    let rep = report(&w, "p.json");
    assert_eq!(rep["islands"], 1);
    assert_eq!(rep["passes"], 6);
    // Until empty: a 20 × 20 square with R 1.5, step 2 has levels 1.5 .. 9.5 (inscribed radius 10).
    let small = pts(&[(0.0, 0.0), (20.0, 0.0), (20.0, 20.0), (0.0, 20.0)]);
    w.write("small.csv", format!("{HEAD}{}", polygon_csv(0, &small)));
    let out =
        w.run(BIN, &["small.csv", "--radius", "1.5", "--until-empty", "--step", "2", "--report", "u.json"], b"").ok();
    let offsets: Vec<f64> = table(&out).iter().map(|r| num(r, "offset")).collect();
    let deepest = offsets.iter().copied().fold(0.0, f64::max);
    assert!((9.5 - TOL..10.0).contains(&deepest), "{deepest}");
    for (k, path) in paths(&out).iter().enumerate() {
        let d = num(table(&out).iter().find(|r| r["path"] == k.to_string()).unwrap(), "offset");
        for p in samples(path) {
            assert!((polygon_distance(&p, &small) - d).abs() <= TOL);
        }
    }
    // A tool wider than the pocket: nothing to cut, a warning, status 0.
    let out = w.run(BIN, &["small.csv", "--radius", "11", "--repeat", "1"], b"");
    out.ok();
    assert!(out.stderr.contains("does not fit"), "{}", out.stderr);
}

/// The paper's sine: y = 10 sin(2π x / 62.8).
fn sine(x: f64) -> f64 {
    10.0 * (TAU * x / 62.8).sin()
}

/// Highest point of the sine over [a, b] ∩ [0, 62.8], in closed form.
fn sine_window_max(a: f64, b: f64) -> f64 {
    let (a, b) = (a.max(0.0), b.min(62.8));
    let crest = 62.8 / 4.0;
    if a <= crest && crest <= b { 10.0 } else { sine(a).max(sine(b)) }
}

/// Height of a u-monotone tip path at `u`.
fn height_at(path: &[Piece], u: f64) -> f64 {
    for p in path {
        let (a, b) = (p.at(0.0), p.at(1.0));
        if u < a.x.min(b.x) - 1e-12 || u > a.x.max(b.x) + 1e-12 {
            continue;
        }
        return match *p {
            Piece::Line(a, b) if (b.x - a.x).abs() < 1e-12 => a.y.max(b.y),
            Piece::Line(a, b) => a.y + (u - a.x) / (b.x - a.x) * (b.y - a.y),
            Piece::Arc(c, r, _, _) => {
                // The branch of the circle the piece lies on: its middle decides.
                let m = p.at(0.5);
                let h = (r * r - (u - c.x).powi(2)).max(0.0).sqrt();
                if m.y >= c.y { c.y + h } else { c.y - h }
            }
        };
    }
    panic!("u = {u} outside the tip path");
}

#[test]
fn sine_profile_for_ball_and_square_end_mills_through_curve_fit_arcs() {
    let w = Work::new();
    let mut points = String::from("x,y\n");
    for i in 0..=628 {
        let x = i as f64 * 0.1;
        points.push_str(&format!("{x:.4},{:.9}\n", sine(x)));
    }
    w.write("points.csv", points);
    w.run("curve-fit-arcs", &["points.csv", "--tol", "0.01", "-o", "fitted.csv"], b"").ok();
    let fitted = w.read("fitted.csv");
    let profile = paths(&fitted).concat();
    assert!(profile.iter().any(|p| matches!(p, Piece::Arc(..))), "the fit has arcs");
    let r = 1.5;
    // Ball: the centre (tip + R up) is at distance R from the fitted profile, within 1e-6 mm.
    let ball = w
        .run(BIN, &["fitted.csv", "--radius", "1.5", "--profile", "ball", "--up", "y", "--report", "b.json"], b"")
        .ok();
    let tip = paths(&ball).concat();
    assert!(tip.iter().any(|p| matches!(p, Piece::Arc(..))), "arcs stay arcs");
    for q in samples(&tip) {
        let c = q + camkit::geom::V2::new(0.0, r);
        let d = profile.iter().map(|p| p.distance(&c)).fold(f64::INFINITY, f64::min);
        assert!((d - r).abs() <= TOL, "ball centre {c} at {d} from the profile");
    }
    // Square: the tip height at u is the sine's highest point within R of u (closed form),
    // within the fit's tolerance.
    let square = w
        .run(
            BIN,
            &[
                "fitted.csv",
                "--radius",
                "1.5",
                "--profile",
                "square",
                "--up",
                "y",
                "--report",
                "s.json",
                "--svg",
                "s.svg",
            ],
            b"",
        )
        .ok();
    let tip = paths(&square).concat();
    let mut worst = 0.0f64;
    for i in 0..=6280 {
        let u = i as f64 * 0.01;
        worst = worst.max((height_at(&tip, u) - sine_window_max(u - r, u + r)).abs());
    }
    // The fit holds 0.01 mm normal to the sine (+1.3e-4 between samples); vertically that is
    // up to √(1 + slope²) = √2 times more where the sine is steepest.
    assert!(worst <= 0.0102 * 2f64.sqrt(), "square tip path off the closed form by {worst} mm");
    let own = report(&w, "s.json")["largest_deviation_mm"].as_f64().unwrap();
    assert!(own <= TOL, "the filter's own check of the tip path against the fitted profile: {own}");
    // The paper's observation: the unoffset square end mill cuts through the sine everywhere but
    // near x = 15.7 and 47.1 mm, checked against the closed-form sine.
    let rep = report(&w, "s.json");
    let centres: Vec<f64> =
        rep["unoffset_square_clear_centres_mm"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert_eq!(centres.len(), 2, "{centres:?}");
    assert!((centres[0] - 15.7).abs() < 0.1 && (centres[1] - 47.1).abs() < 0.1, "{centres:?}");
    // Clear (the bottom on one side of the sine) only where 10 (1 − cos(2π δ / 62.8)) ≤ 0.01 mm,
    // δ ≤ 0.45 mm from a crest or trough; cutting through everywhere else.
    for i in 0..=628 {
        let u = i as f64 * 0.1;
        let inside = u >= r && u <= 62.8 - r;
        let f = sine(u);
        let (above, below) = (0..=300)
            .map(|k| sine(u - r + k as f64 * 0.01) - f)
            .fold((0.0f64, 0.0f64), |(a, b), d| (a.max(d), b.max(-d)));
        let through = above > 0.01 && below > 0.01;
        let delta = (u - 15.7).abs().min((u - 47.1).abs());
        if inside && delta < 0.4 {
            assert!(!through, "u = {u}");
        } else if inside && delta > 0.5 {
            assert!(through, "u = {u}");
        }
        let reported_clear = rep["unoffset_square_clear_mm"]
            .as_array()
            .unwrap()
            .iter()
            .any(|s| s[0].as_f64().unwrap() <= u && u <= s[1].as_f64().unwrap());
        if inside && !(0.4..=0.5).contains(&delta) {
            assert_eq!(reported_clear, !through, "the report at u = {u}");
        }
    }
    assert!(rep["unoffset_square_deepest_gouge_mm"].as_f64().unwrap() > 1.0);
    let svg = w.read("s.svg");
    assert!(svg.contains("gouge of the unoffset path"), "the plot shows the gouge regions");
}

#[test]
fn three_d_square_on_a_tilted_plane_is_offset_in_that_plane() {
    let w = Work::new();
    let t = 30f64.to_radians();
    let n = (0.0, -t.sin(), t.cos());
    let corners = [(0.0, 0.0), (20.0, 0.0), (20.0, 10.0), (0.0, 10.0), (0.0, 0.0)];
    let mut csv = String::from("path,move,x,y,z,i,j,k\n");
    for (k, (u, v)) in corners.iter().enumerate() {
        let mv = if k == 0 { "rapid" } else { "line" };
        csv.push_str(&format!("0,{mv},{u},{},{},{},{},{}\n", v * t.cos(), v * t.sin(), n.0, n.1, n.2));
    }
    w.write("tilt.csv", csv);
    let out = w.run(BIN, &["tilt.csv", "--3d", "--radius", "2", "--side", "right", "--report", "t.json"], b"").ok();
    let rows = table(&out);
    assert!(rows.len() > 8, "corners rounded by several points");
    let rect = pts(&corners[..4]);
    for r in &rows {
        let (x, y, z) = (num(r, "x"), num(r, "y"), num(r, "z"));
        // In the plane, and at distance R (up to the chord tolerance at corners) from the square.
        assert!((x * n.0 + y * n.1 + z * n.2).abs() < 1e-9, "off the plane: {x} {y} {z}");
        let (u, v) = (x, y * t.cos() + z * t.sin());
        let d = polygon_distance(&P2::new(u, v), &rect);
        assert!((2.0 - TOL..=2.0 + 0.001 + TOL).contains(&d), "({u}, {v}) at {d}");
        assert!(!(0.0..=20.0).contains(&u) || !(0.0..=10.0).contains(&v), "outside, on the right of travel");
    }
    let rep = report(&w, "t.json");
    assert!(rep["largest_excess_mm"].as_f64().unwrap() <= 0.001 + TOL);
    assert_eq!(rep["rounded_corners"], 4);
}

/// A flat star whose spikes are narrower than 2R beside reflex corners (found by fuzzing the 3D
/// mode): with the default look-ahead (4R each side) a trimmed row's point came nearer than R to
/// a part of the contour beyond the window; the window now doubles until the check passes. The
/// result follows the contour at R (every written point within [R, R + chord tolerance]) on the
/// inside. A window the user gives is kept, and the check refuses it (exit 1).
#[test]
fn three_d_window_grows_until_the_contour_is_cleared() {
    let w = Work::new();
    let star = [
        (23.607, 0.0),
        (15.83, 3.484),
        (23.99, 11.099),
        (12.381, 9.412),
        (11.124, 13.097),
        (11.147, 21.025),
        (7.887, 28.408),
        (1.409, 25.984),
        (-3.202, 19.53),
        (-5.674, 14.24),
        (-12.533, 18.484),
        (-13.047, 12.359),
        (-24.067, 14.481),
        (-27.158, 9.151),
        (-22.953, 2.496),
        (-16.317, -1.775),
        (-22.224, -7.488),
        (-21.844, -13.143),
        (-18.827, -17.834),
        (-13.998, -20.645),
        (-8.939, -22.435),
        (-2.641, -16.107),
        (1.157, -21.339),
        (7.987, -28.765),
        (9.571, -18.052),
        (13.692, -16.119),
        (14.933, -11.351),
        (23.138, -10.705),
        (25.718, -5.661),
    ];
    let mut csv = String::from("path,move,x,y,z,i,j,k\n");
    for (k, (x, y)) in star.iter().chain(&star[..1]).enumerate() {
        csv.push_str(&format!("0,{},{x},{y},0,0,0,1\n", if k == 0 { "rapid" } else { "line" }));
    }
    w.write("star.csv", csv);
    let out = w.run(BIN, &["star.csv", "--3d", "--radius", "5", "--side", "left", "--report", "s.json"], b"").ok();
    let rep = report(&w, "s.json");
    assert_eq!(rep["window_doublings"], 1, "{rep}");
    assert!(rep["largest_gouge_mm"].as_f64().unwrap() <= 1e-9);
    let poly = pts(&star);
    let inside = camkit::contour::Contour::polygon(&poly, true);
    let rows = table(&out);
    assert!(rows.len() > star.len());
    for r in &rows {
        let p = P2::new(num(r, "x"), num(r, "y"));
        let d = polygon_distance(&p, &poly);
        assert!((5.0 - TOL..=5.0 + 0.001 + TOL).contains(&d), "{p} at {d}");
        assert_ne!(inside.winding_number(&p), 0, "{p} inside the star");
    }
    w.run(BIN, &["star.csv", "--3d", "--radius", "5", "--side", "left", "--window", "20"], b"").fails(1, "comes 0.09");
}

#[test]
fn zero_length_moves_are_dropped_and_counted() {
    let w = Work::new();
    let csv =
        format!("{HEAD}0,rapid,0,0,,\n0,line,10,0,,\n0,line,10,0,,\n0,line,10,10,,\n0,line,0,10,,\n0,line,0,0,,\n");
    w.write("dup.csv", csv);
    w.run(BIN, &["dup.csv", "--radius", "1", "--side", "left", "--report", "d.json"], b"").ok();
    assert_eq!(report(&w, "d.json")["dropped_zero_length_moves"], 1);
}

#[test]
fn bad_input_is_refused_with_one_line_and_no_output_file() {
    let w = Work::new();
    let bow = format!("{HEAD}0,rapid,0,0,,\n0,line,20,10,,\n0,line,20,0,,\n0,line,0,10,,\n0,line,0,0,,\n");
    w.write("bow.csv", &bow);
    w.write("open.csv", format!("{HEAD}0,rapid,0,0,,\n0,line,10,0,,\n0,line,10,10,,\n"));
    w.write("nan.csv", format!("{HEAD}0,rapid,0,0,,\n0,line,NaN,0,,\n0,line,10,10,,\n"));
    w.write("text.csv", format!("{HEAD}0,rapid,0,0,,\n0,line,1O,0,,\n"));
    w.write("nox.csv", "path,move,y\n0,line,1\n");
    w.write("empty.csv", "");
    // An island (path 7) touching the outer loop at a vertex: named by its path id.
    let touching = format!(
        "{HEAD}0,rapid,0,0,,\n0,line,10,0,,\n0,line,10,10,,\n0,line,0,10,,\n0,line,0,0,,\n\
         7,rapid,10,5,,\n7,line,5,3,,\n7,line,5,7,,\n7,line,10,5,,\n"
    );
    w.write("touching.csv", &touching);
    // Profiles that turn back (an undercut), named at the row of the piece: a line going back,
    // and an arc whose ends run forward but whose middle passes a vertical tangent.
    w.write("back.csv", format!("{HEAD}0,rapid,0,0,,\n0,line,10,0,,\n0,line,5,5,,\n0,line,20,5,,\n"));
    w.write(
        "bulge.csv",
        format!("{HEAD}0,rapid,0,0,,\n0,line,10,0,,\n0,line,20,0,,\n0,ccw,22,8,21,4\n0,line,30,8,,\n"),
    );
    let cases: &[(&[&str], &str)] = &[
        (&["back.csv", "--radius", "1", "--profile", "ball", "--up", "y"], "back.csv:4: the profile turns back"),
        (&["bulge.csv", "--radius", "1", "--profile", "square", "--up", "y"], "bulge.csv:5: the profile turns back"),
        (&["touching.csv", "--radius", "1", "--repeat", "1"], "crosses or touches path 7 at (10.000000, 5.000000)"),
        (&["bow.csv", "--radius", "1", "--side", "left"], "bow.csv:2"),
        (&["bow.csv", "--radius", "1", "--side", "left"], "crosses itself at (10.000000, 5.000000)"),
        (&["open.csv", "--radius", "1", "--repeat", "2"], "open.csv:4"),
        (&["nan.csv", "--radius", "1", "--side", "left"], "nan.csv:3"),
        (&["text.csv", "--radius", "1", "--side", "left"], "text.csv:3"),
        (&["nox.csv", "--radius", "1", "--side", "left"], "x"),
        (&["empty.csv", "--radius", "1", "--side", "left"], "empty.csv"),
        (&["open.csv", "--radius", "0", "--side", "left"], "--radius"),
        (&["open.csv", "--radius", "-2", "--side", "left"], "--radius"),
        (&["open.csv", "--radius", "NaN", "--side", "left"], "--radius"),
        (&["open.csv", "--radius", "1"], "--side"),
        (&["open.csv", "--radius", "1", "--side", "up"], "--side"),
    ];
    for (args, needle) in cases {
        let mut a: Vec<&str> = args.to_vec();
        a.extend(["-o", "out.csv", "--report", "out.json", "--svg", "out.svg"]);
        w.run(BIN, &a, b"").fails(2, needle);
        assert!(!w.exists("out.csv") && !w.exists("out.json") && !w.exists("out.svg"), "{args:?}: {:?}", w.files());
    }
    // A column name is named with the position.
    let out = w.run(BIN, &["text.csv", "--radius", "1", "--side", "left"], b"");
    assert!(out.stderr.contains('x'), "{}", out.stderr);
    // A crossing may be accepted on request: an open path looping over itself.
    w.write(
        "loop.csv",
        format!("{HEAD}0,rapid,0,0,,\n0,line,20,0,,\n0,line,20,10,,\n0,line,10,10,,\n0,line,10,-10,,\n"),
    );
    w.run(BIN, &["loop.csv", "--radius", "1", "--side", "left"], b"")
        .fails(2, "crosses itself at (10.000000, 0.000000)");
    let out = w.run(BIN, &["loop.csv", "--radius", "1", "--side", "left", "--allow-self-crossing"], b"").ok();
    let shape = [P2::new(0.0, 0.0), P2::new(20.0, 0.0), P2::new(20.0, 10.0), P2::new(10.0, 10.0), P2::new(10.0, -10.0)];
    for p in paths(&out).iter().flat_map(|p| samples(p)) {
        let d = (0..4).map(|i| point_segment(&p, &shape[i], &shape[i + 1])).fold(f64::INFINITY, f64::min);
        assert!((d - 1.0).abs() <= TOL, "{p} at {d}");
    }
}

#[test]
fn loops_touching_at_exactly_2r_are_cut_as_two_loops_meeting_at_the_point() {
    let w = Work::new();
    // Two rooms joined by a passage whose walls bulge in as half circles of radius 4 about
    // (25, 5) and (25, 15): exactly 2 mm wide at (25, 10), so at R = 1 the loops touch there.
    let rows = [
        "0,rapid,0,0,,",
        "0,line,20,0,,",
        "0,line,20,5,,",
        "0,line,21,5,,",
        "0,cw,29,5,25,5",
        "0,line,30,5,,",
        "0,line,30,0,,",
        "0,line,50,0,,",
        "0,line,50,20,,",
        "0,line,30,20,,",
        "0,line,30,15,,",
        "0,line,29,15,,",
        "0,cw,21,15,25,15",
        "0,line,20,15,,",
        "0,line,20,20,,",
        "0,line,0,20,,",
        "0,line,0,0,,",
    ];
    w.write("bumps.csv", format!("{HEAD}{}\n", rows.join("\n")));
    let shape = paths(&w.read("bumps.csv")).remove(0);
    let out = w.run(BIN, &["bumps.csv", "--radius", "1", "--side", "left", "--report", "r.json"], b"").ok();
    let ps = paths(&out);
    assert_eq!(ps.len(), 2, "one loop per room, split where they touch");
    let touch = P2::new(25.0, 10.0);
    for path in &ps {
        let pts = samples(path);
        assert!(pts.iter().any(|p| (p - touch).norm() <= TOL), "each loop reaches the touching point");
        for p in pts {
            let d = shape.iter().map(|s| s.distance(&p)).fold(f64::INFINITY, f64::min);
            assert!((d - 1.0).abs() <= TOL, "{p} at {d}");
        }
    }
    assert!(report(&w, "r.json")["largest_deviation_mm"].as_f64().unwrap() <= TOL);
}

#[test]
fn a_closed_self_crossing_contour_is_offset_on_request_to_what_can_be_cut() {
    let w = Work::new();
    // A bow tie crossing itself at (10, 5): refused by default, offset on request into the left
    // lobe's triangle shrunk by 1 mm and an open stretch around the right lobe.
    let bow = pts(&[(0.0, 0.0), (20.0, 10.0), (20.0, 0.0), (0.0, 10.0)]);
    w.write("bow.csv", format!("{HEAD}{}", polygon_csv(0, &bow)));
    w.run(BIN, &["bow.csv", "--radius", "1", "--side", "left"], b"")
        .fails(2, "crosses itself at (10.000000, 5.000000)");
    let out = w.run(BIN, &["bow.csv", "--radius", "1", "--side", "left", "--allow-self-crossing"], b"").ok();
    let ps = paths(&out);
    assert_eq!(ps.len(), 2, "{out}");
    let r5 = 5f64.sqrt();
    let corners = [P2::new(10.0 - r5, 5.0), P2::new(1.0, 0.5 + 0.5 * r5), P2::new(1.0, 9.5 - 0.5 * r5)];
    let ends = |p: &[Piece]| (p[0].at(0.0), p[p.len() - 1].at(1.0));
    let (tri, open): (Vec<&Vec<Piece>>, Vec<&Vec<Piece>>) = ps.iter().partition(|p| {
        let (a, b) = ends(p);
        (a - b).norm() < TOL
    });
    assert_eq!((tri.len(), open.len()), (1, 1));
    for q in corners {
        assert!(tri[0].iter().any(|s| (s.at(0.0) - q).norm() < 1e-6), "corner {q}");
    }
    let (a, b) = ends(open[0]);
    for q in [P2::new(10.0, 5.0 + 0.5 * r5), P2::new(10.0, 5.0 - 0.5 * r5)] {
        assert!((a - q).norm() < 1e-6 || (b - q).norm() < 1e-6, "open end {q}");
    }
    for p in ps.iter().flat_map(|p| samples(p)) {
        assert!((polygon_distance(&p, &bow) - 1.0).abs() <= TOL, "{p}");
    }
}

#[test]
fn a_kernel_debug_assertion_never_reaches_the_user() {
    // A regular 63-gon of radius 1 offset inward by 0.9 trips cavalier_contours' debug assertion
    // (pline_view.rs:353) in debug builds, as these tests run: the offset is retried, verified,
    // and nothing but the result is written (no panic message on stderr).
    let w = Work::new();
    let gon: Vec<P2> = (0..63).map(|k| TAU * k as f64 / 63.0).map(|a| P2::new(a.cos(), a.sin())).collect();
    w.write("gon.csv", format!("{HEAD}{}", polygon_csv(0, &gon)));
    for args in
        [&["gon.csv", "--radius", "0.9", "--side", "left"][..], &["gon.csv", "--radius", "0.9", "--repeat", "1"]]
    {
        let out = w.run(BIN, args, b"");
        assert!(!out.stderr.contains("panick") && !out.stderr.contains("internal error"), "{}", out.stderr);
        let ps = paths(&out.ok());
        assert_eq!(ps.len(), 1);
        // The same polygon, apothem cos(π/63) − 0.9: its points within its circumradius.
        let inner = ((PI / 63.0).cos() - 0.9) / (PI / 63.0).cos();
        for p in samples(&ps[0]) {
            assert!((polygon_distance(&p, &gon) - 0.9).abs() <= TOL, "{p}");
            assert!(p.coords.norm() <= inner + TOL, "{p}");
        }
    }
}

/// A square 20 km from the origin (once a panic in the epsilon ladder: round-off there is above
/// the ladder's cap) is offset like the same square at the origin, moved; so are its pocket and
/// medial-trochoid's plan of it.
#[test]
fn far_from_the_origin_the_offset_is_the_same_moved() {
    let w = Work::new();
    let square = |x0: f64| {
        let mut s = String::from("path,move,x,y\n");
        for (x, y) in [(0.0, 0.0), (60.0, 0.0), (60.0, 40.0), (0.0, 40.0), (0.0, 0.0)] {
            s.push_str(&format!("1,line,{},{y}\n", x0 + x));
        }
        s
    };
    w.write("near.csv", square(0.0));
    w.write("far.csv", square(2e7));
    for args in [&["--radius", "1", "--side", "left"][..], &["--radius", "3", "--until-empty"][..]] {
        let near = table(&w.run(BIN, &[&["near.csv"], args].concat(), b"").ok());
        let far = table(&w.run(BIN, &[&["far.csv"], args].concat(), b"").ok());
        assert_eq!(near.len(), far.len(), "{args:?}");
        for (a, b) in near.iter().zip(&far) {
            assert!((num(b, "x") - 2e7 - num(a, "x")).abs() < 1e-6 && (num(b, "y") - num(a, "y")).abs() < 1e-6);
        }
    }
    w.run("medial-trochoid", &["far.csv", "--radius", "5"], b"").ok();
}

/// A DXF drawing (an LWPOLYLINE with a bulge and a CIRCLE island) is offset and pocketed exactly
/// as the same contours written as the table are (the output byte for byte); its other entities
/// are named in one warning.
#[test]
fn a_dxf_drawing_offsets_like_its_table() {
    let w = Work::new();
    let dxf = "0\nSECTION\n2\nENTITIES\n\
               0\nLWPOLYLINE\n8\n0\n90\n4\n70\n1\n10\n0\n20\n0\n10\n40\n20\n0\n42\n1\n10\n40\n20\n30\n10\n0\n20\n30\n\
               0\nCIRCLE\n8\n0\n10\n15\n20\n15\n30\n0\n40\n5\n\
               0\nTEXT\n8\n0\n10\n0\n20\n0\n1\nnote\n\
               0\nENDSEC\n0\nEOF\n";
    w.write("pocket.dxf", dxf);
    w.write(
        "pocket.csv",
        "path,move,x,y,z,xc,yc\n1,line,0,0,0,,\n1,line,40,0,0,,\n1,ccw,40,30,0,40,15\n1,line,0,30,0,,\n1,line,0,0,0,,\n\
         2,line,20,15,0,,\n2,ccw,10,15,0,15,15\n2,ccw,20,15,0,15,15\n",
    );
    for args in [&["--radius", "2", "--side", "left"][..], &["--radius", "2", "--until-empty"][..]] {
        let table = w.run(BIN, &[&["pocket.csv"], args].concat(), b"").ok();
        let drawing = w.run(BIN, &[&["pocket.dxf"], args].concat(), b"");
        assert_eq!(drawing.ok(), table, "{args:?}");
        assert!(
            drawing.stderr.contains("1 entities that are not contours skipped (the first: TEXT"),
            "{}",
            drawing.stderr
        );
    }
}

#[test]
fn a_pocket_exactly_2r_wide_is_cut_along_its_centre_line() {
    // A 50 × 5 slot: at R = 2.5 (and a hair under) the region offset is a loop of zero width,
    // which pocket mode used to drop ("does not fit") while contour mode cut the centre line.
    let w = Work::new();
    let slot = pts(&[(0.0, 0.0), (50.0, 0.0), (50.0, 5.0), (0.0, 5.0)]);
    w.write("slot.csv", format!("{HEAD}{}", polygon_csv(0, &slot)));
    for r in ["2.5", "2.4999999"] {
        let run = w.run(BIN, &["slot.csv", "--radius", r, "--until-empty", "--report", "r.json", "-o", "p.csv"], b"");
        run.ok();
        assert!(!run.stderr.contains("does not fit"), "{}", run.stderr);
        let rep = report(&w, "r.json");
        assert_eq!(rep["passes"], 1, "{rep}");
        assert_eq!(rep["centre_line_passes"], 1, "{rep}");
        let ps = paths(&w.read("p.csv"));
        assert_eq!(ps.len(), 1);
        let radius: f64 = r.parse().unwrap();
        let pts = samples(&ps[0]);
        // Along the centre line from end to end, every point R or more from the walls.
        let xs = pts.iter().map(|p| p.x).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
        assert!((xs.0 - radius).abs() <= TOL && (xs.1 - (50.0 - radius)).abs() <= TOL, "{xs:?}");
        for p in pts {
            assert!((p.y - radius).abs() <= TOL, "{p}");
            assert!(polygon_distance(&p, &slot) >= radius - TOL, "{p}");
        }
    }
    // Wider than the slot: still nothing to cut.
    let run = w.run(BIN, &["slot.csv", "--radius", "2.6", "--until-empty", "-o", "n.csv"], b"");
    run.ok();
    assert!(run.stderr.contains("does not fit"), "{}", run.stderr);
}

/// Issue 20: a run whose memory follows from its options (passes at the step over, points of a
/// corner polygon) is estimated before it starts and refused past `--max-memory`, at once,
/// naming the option and the estimate: a step of 1e-6 mm ran for hours, a `--chord-tol` of
/// 1e-300 aborted on a 4 GiB allocation.
#[test]
fn runs_past_the_memory_bound_are_refused_up_front() {
    let w = Work::new();
    w.write(
        "island.csv",
        "path,move,x,y,z\n1,rapid,0,0,0\n1,line,60,0,0\n1,line,60,40,0\n1,line,0,40,0\n1,line,0,0,0\n\
         2,rapid,24,16,0\n2,line,24,24,0\n2,line,36,24,0\n2,line,36,16,0\n2,line,24,16,0\n",
    );
    let mut csv = String::from("path,move,x,y,z,i,j,k\n");
    for k in 0..=40 {
        let t = TAU * (k % 40) as f64 / 40.0;
        let mv = if k == 0 { "rapid" } else { "line" };
        csv.push_str(&format!("0,{mv},{},{},0,0,0,1\n", 20.0 * t.cos(), 20.0 * t.sin()));
    }
    w.write("ring.csv", csv);
    let started = std::time::Instant::now();
    let cases: [(&[&str], &str); 4] = [
        (&["island.csv", "--radius", "2", "--until-empty", "--step", "1e-6"], "--step 0.000001 mm needs an estimated"),
        (&["island.csv", "--radius", "2", "--repeat", "1000000000", "--step", "1e-6"], "--max-memory"),
        (&["ring.csv", "--3d", "--radius", "0.1", "--side", "right", "--chord-tol", "1e-300"], "--chord-tol 1e-300 mm"),
        (&["island.csv", "--radius", "2", "--until-empty", "--max-memory", "0"], "more than the bound of 0 MB"),
    ];
    for (args, needle) in cases {
        let mut a = args.to_vec();
        a.extend(["-o", "out.csv"]);
        w.run(BIN, &a, b"").fails(2, needle);
        assert!(!w.exists("out.csv"));
    }
    assert!(started.elapsed().as_secs_f64() < 10.0, "refused at once: {:?}", started.elapsed());
    // Within the bound the same runs go ahead.
    w.run(BIN, &["island.csv", "--radius", "2", "--until-empty", "--step", "1"], b"").ok();
    w.run(BIN, &["ring.csv", "--3d", "--radius", "0.1", "--side", "right", "--chord-tol", "1e-9"], b"").ok();
}

/// Issue 20: every numeric option at extreme values, seeded (scripts/fuzz-options.py runs them
/// all): no panic, exit 0/1/2, one error line, under 20 s and 4 GiB.
#[test]
fn extreme_option_values_end_in_time_with_one_line() {
    let w = Work::new();
    w.write(
        "island.csv",
        "path,move,x,y,z\n1,rapid,0,0,0\n1,line,60,0,0\n1,line,60,40,0\n1,line,0,40,0\n1,line,0,0,0\n\
         2,rapid,24,16,0\n2,line,24,24,0\n2,line,36,24,0\n2,line,36,16,0\n2,line,24,16,0\n",
    );
    let mut ring = String::from("path,move,x,y,z,i,j,k\n");
    for k in 0..=40 {
        let t = TAU * (k % 40) as f64 / 40.0;
        ring.push_str(&format!(
            "0,{},{},{},0,0,0,1\n",
            if k == 0 { "rapid" } else { "line" },
            20.0 * t.cos(),
            20.0 * t.sin()
        ));
    }
    w.write("ring.csv", ring);
    let contour = ["--radius", "2", "--side", "left"];
    w.fuzz_options(BIN, "island.csv", &contour, &["--radius", "--feed", "--decimals", "--max-memory"], 20, 6);
    let pocket = ["--radius", "2", "--until-empty"];
    w.fuzz_options(BIN, "island.csv", &pocket, &["--radius", "--step", "--repeat"], 21, 6);
    let space = ["--3d", "--radius", "1", "--side", "left"];
    w.fuzz_options(BIN, "ring.csv", &space, &["--radius", "--window", "--chord-tol"], 22, 6);
}

/// The closed curve r = 50 + 5 sin 7t + 0.5 sin 97t as `n` lines, counter-clockwise (its
/// tightest convex bend has radius 0.46 mm).
fn wiggle(n: usize) -> String {
    let mut csv = String::from("path,move,x,y,z\n");
    for i in 0..=n {
        let t = TAU * (i % n) as f64 / n as f64;
        let r = 50.0 + 5.0 * (7.0 * t).sin() + 0.5 * (97.0 * t).sin();
        csv.push_str(&format!("0,{},{:.9},{:.9},0\n", if i == 0 { "rapid" } else { "line" }, r * t.cos(), r * t.sin()));
    }
    csv
}

/// Issue 20 (D13): the 100 000-line wiggle offset inward by R 0.5 verifies as one loop, as at
/// 10 000 lines (it failed with exit 1 from 50 000 lines on: the kernel took its lines of a few
/// µm as collinear where they turn by milliradians; see camkit::contour::offset).
#[test]
fn a_dense_chorded_curve_offsets_verified_at_every_density() {
    let w = Work::new();
    for n in [10_000, 100_000] {
        w.write("w.csv", wiggle(n));
        let out = w.run(BIN, &["w.csv", "--radius", "0.5", "--side", "left", "--report", "r.json"], b"").ok();
        let rep: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
        assert!(rep["largest_deviation_mm"].as_f64().unwrap() <= TOL, "{n}: {rep}");
        assert_eq!(rep["output_paths"], 1, "{n}: {rep}");
        assert!(out.lines().count() > n, "{n}: the loop follows every line");
    }
}
