//! Jobs end to end: a toolpath, a setup and a machine make a program with safe links, checked
//! here independently of the post's own check (the NC text parsed here, the rapids measured
//! against the stock top, the walls and the islands with exact distances, the material under a
//! descent from the feed moves before it).

use e2e::{Work, data};

const BIN: &str = "post-6axis";

/// A 100 × 60 pocket (stock top 0) with a round island R8 at (50, 30).
const POCKET: &str = "path,move,x,y,z,xc,yc\n\
0,line,0,0,0,,\n0,line,100,0,0,,\n0,line,100,60,0,,\n0,line,0,60,0,,\n0,line,0,0,0,,\n\
1,line,58,30,0,,\n1,ccw,42,30,0,50,30\n1,ccw,58,30,0,50,30\n";

const R: f64 = 4.0;
const ISLAND: (f64, f64, f64) = (50.0, 30.0, 8.0);
const APPROACH: f64 = 1.0;

const TOOL: &str = r#"{"kind": "flat", "radius": 4, "flutes": 3, "length": 25, "number": 7, "spindle_speed": 9000, "feed": 800, "plunge_feed": 150}"#;

const SETUP: &str = r#"{"tool": "tool.json", "stock": {"min": [0, 0, -20], "max": [100, 60, 0]},
  "part": {"contours": "pocket.csv", "floor": -12}, "clearance_height": 25, "safe_height": 5, "approach": 1}"#;

/// Passes of a φ8 flat end mill at two depths: round the walls at R, round the island on an
/// octagon clear of it, and two slots either side of it on y = 30, so that a straight G0 from
/// one slot to the next crosses the island.
fn passes() -> String {
    let mut s = String::from("path,move,x,y,z\n");
    let mut path = 0;
    for z in [-6.0, -12.0] {
        let mut pass = |pts: &[(f64, f64)]| {
            for (k, (x, y)) in pts.iter().enumerate() {
                s.push_str(&format!("{path},{},{x},{y},{z}\n", if k == 0 { "rapid" } else { "line" }));
            }
            path += 1;
        };
        pass(&[(4.0, 4.0), (96.0, 4.0), (96.0, 56.0), (4.0, 56.0), (4.0, 4.0)]);
        let oct: Vec<(f64, f64)> = (0..=8)
            .map(|k| {
                let a = std::f64::consts::FRAC_PI_4 * k as f64;
                (50.0 + 14.5 * a.cos(), 30.0 + 14.5 * a.sin())
            })
            .collect();
        pass(&oct);
        pass(&[(10.0, 30.0), (30.0, 30.0)]);
        pass(&[(70.0, 30.0), (90.0, 30.0)]);
    }
    s
}

fn job() -> Work {
    let w = Work::new();
    w.write("pocket.csv", POCKET);
    w.write("tool.json", TOOL);
    w.write("setup.json", SETUP);
    w.write("passes.csv", passes());
    w
}

fn machine() -> String {
    data("post-6axis/three-axis.json").to_string_lossy().into_owned()
}

/// One motion block read from the program text: G0 or not, where it starts and ends, its line.
#[derive(Clone, Copy, Debug)]
struct Block {
    rapid: bool,
    from: [f64; 3],
    to: [f64; 3],
    line: usize,
}

/// The motion blocks of a 3-axis program of G0/G1 blocks (modal words carried), after the first
/// position is known in every axis.
fn blocks(nc: &str) -> Vec<Block> {
    let (mut pos, mut known, mut rapid) = ([0.0f64; 3], [false; 3], true);
    let mut out = Vec::new();
    for (i, line) in nc.lines().enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        if words.contains(&"G53") {
            known = [false; 3];
            continue;
        }
        for w in &words {
            match *w {
                "G0" => rapid = true,
                "G1" => rapid = false,
                _ => {}
            }
        }
        let mut to = pos;
        let mut moved = false;
        for w in &words {
            let k = match w.as_bytes()[0] {
                b'X' => 0,
                b'Y' => 1,
                b'Z' => 2,
                _ => continue,
            };
            to[k] = w[1..].parse().expect("a number");
            moved = true;
        }
        if !moved {
            continue;
        }
        if known.iter().all(|k| *k) {
            out.push(Block { rapid, from: pos, to, line: i + 1 });
        }
        for (k, w) in ["X", "Y", "Z"].iter().enumerate() {
            known[k] |= words.iter().any(|x| x.starts_with(w));
        }
        pos = to;
    }
    out
}

/// Distance from (x, y) to the segment a–b in XY.
fn seg_dist(x: f64, y: f64, a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 { (((x - a[0]) * dx + (y - a[1]) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
    ((x - a[0] - t * dx).powi(2) + (y - a[1] - t * dy).powi(2)).sqrt()
}

/// Every G0 of the program that is unsafe, with why: a rapid that moves sideways below the stock
/// top plus the approach; a rapid below the top within R of the walls or the island (or inside
/// it); a descent that ends less than the approach above the material under the tool (the stock
/// less the feed moves before it, over a polar grid of the footprint).
fn unsafe_rapids(nc: &str) -> Vec<(usize, String)> {
    let bs = blocks(nc);
    let mut bad = Vec::new();
    for (i, b) in bs.iter().enumerate().filter(|(_, b)| b.rapid) {
        let sideways = (b.to[0] - b.from[0]).hypot(b.to[1] - b.from[1]) > 1e-9;
        let low = b.from[2].min(b.to[2]);
        let mut why = Vec::new();
        if sideways && low < APPROACH - 1e-9 {
            why.push(format!("sideways at z {low}"));
        }
        if low < 0.0 {
            // The rectangle's walls are convex: the nearest point of a segment is an end.
            let walls = [b.from, b.to]
                .iter()
                .map(|p| p[0].min(100.0 - p[0]).min(p[1]).min(60.0 - p[1]))
                .fold(f64::INFINITY, f64::min)
                - R;
            let island = seg_dist(ISLAND.0, ISLAND.1, &b.from, &b.to) - ISLAND.2 - R;
            if island.min(walls) < -1e-6 {
                why.push(format!("{:.4} mm into the walls or the island", -island.min(walls)));
            }
        }
        if !why.is_empty() {
            bad.push((b.line, why.join(", ")));
            continue;
        }
        if b.to[2] < b.from[2] {
            let top = |x: f64, y: f64| {
                bs[..i]
                    .iter()
                    .filter(|f| !f.rapid && seg_dist(x, y, &f.from, &f.to) <= R)
                    .map(|f| f.from[2].min(f.to[2]))
                    .fold(0.0f64, f64::min)
            };
            let mut highest = f64::NEG_INFINITY;
            for ring in 0..=16 {
                let rho = (R - 0.011) * ring as f64 / 16.0;
                for k in 0..64 {
                    let a = std::f64::consts::TAU * k as f64 / 64.0;
                    highest = highest.max(top(b.to[0] + rho * a.cos(), b.to[1] + rho * a.sin()));
                }
            }
            if b.to[2] < highest + APPROACH - 0.01 - 1e-9 {
                bad.push((b.line, format!("descends to {} over material at {highest}", b.to[2])));
            }
        }
    }
    bad
}

fn report(w: &Work, name: &str) -> serde_json::Value {
    serde_json::from_str(&w.read(name)).expect("report JSON")
}

/// The island pocket posted with its setup: every G0 safe by the independent check; the same
/// passes posted as given (no setup) fail it, so the check can fail.
#[test]
fn an_island_pocket_posted_with_a_setup_has_no_unsafe_rapid() {
    let w = job();
    let m = machine();
    w.run(BIN, &["passes.csv", "--machine", &m, "--setup", "setup.json", "--report", "r.json", "-o", "p.ngc"], b"")
        .ok();
    let nc = w.read("p.ngc");
    assert_eq!(unsafe_rapids(&nc), vec![], "{nc}");
    let r = report(&w, "r.json");
    assert_eq!(r["rapids_into_material"], 0);
    assert_eq!(r["part_collisions"], 0);
    assert_eq!(r["links"], 8);
    // Every pass but the first starts in or beside cut material: the slots' second layer over
    // their first's floor (1 mm above −6), the rest from 1 mm above the stock.
    assert!(nc.contains("T7 M6") && nc.contains("G43 H7") && nc.contains("S9000 M3"), "{nc}");
    assert!(r["smallest_feed_clearance_mm"].as_f64().unwrap().abs() < 1e-9, "{r}");
    let naive = w.run(BIN, &["passes.csv", "--machine", &m, "--feed", "800"], b"");
    let naive = naive.ok();
    let found = unsafe_rapids(&naive);
    assert!(found.len() >= 7, "{found:?}");
    assert!(found.iter().any(|(_, why)| why.contains("into the walls or the island")), "{found:?}");
}

/// The post's own check names the first unsafe G0 of a program by its NC line, and writes its
/// report; the linked program passes it.
#[test]
fn a_rapid_into_an_island_is_caught_and_named_by_block() {
    let w = job();
    let m = machine();
    let naive = w.run(BIN, &["passes.csv", "--machine", &m, "--feed", "800"], b"").ok();
    w.write("naive.ngc", &naive);
    let o = w.run(BIN, &["--machine", &m, "--setup", "setup.json", "--check", "naive.ngc"], b"");
    o.fails(1, "collision check: NC line ");
    let line: usize = o.stderr.split("NC line ").nth(1).unwrap().split(':').next().unwrap().parse().unwrap();
    assert!(naive.lines().nth(line - 1).unwrap().starts_with("G0"), "line {line}: {}", o.stderr);
    assert!(unsafe_rapids(&naive).iter().any(|(l, _)| *l == line), "{line}");
    let r: serde_json::Value = serde_json::from_str(&o.out()).unwrap();
    assert!(r["rapids_into_material"].as_u64().unwrap() >= 7, "{r}");
    assert!(r["part_collisions"].as_u64().unwrap() >= 1, "{r}");
    // The island crossing: the G0 from the end of the left slot to the right one.
    let crossing = naive.lines().position(|l| l == "G0 X70").map(|i| i + 1).unwrap();
    assert!(unsafe_rapids(&naive).iter().any(|(l, why)| *l == crossing && why.contains("sideways")));
    w.run(BIN, &["passes.csv", "--machine", &m, "--setup", "setup.json", "-o", "p.ngc"], b"").ok();
    let o = w.run(BIN, &["--machine", &m, "--setup", "setup.json", "--check", "p.ngc"], b"");
    assert_eq!(o.status, 0, "{}", o.stderr);
}

/// A holder that reaches the wall top is a collision: no program, exit 1, unless
/// --allow-collision (written, a warning).
#[test]
fn a_collision_withholds_the_program_unless_allowed() {
    let w = job();
    w.write("tool.json", TOOL.replace(r#""length": 25"#, r#""length": 3, "holder_diameter": 30, "holder_length": 40"#));
    let m = machine();
    let o = w.run(BIN, &["passes.csv", "--machine", &m, "--setup", "setup.json", "-o", "p.ngc"], b"");
    o.fails(1, "a feed move comes");
    assert!(!w.exists("p.ngc"));
    let o =
        w.run(BIN, &["passes.csv", "--machine", &m, "--setup", "setup.json", "--allow-collision", "-o", "p.ngc"], b"");
    assert_eq!(o.status, 0, "{}", o.stderr);
    assert!(o.stderr.contains("written anyway"), "{}", o.stderr);
    assert!(w.exists("p.ngc"));
}

/// Bad setups and jobs: one line naming the file and the JSON path, exit 2, no program.
#[test]
fn bad_jobs_are_refused_naming_the_field() {
    let m = machine();
    let cases: [(&str, String, &str); 4] = [
        (
            "setup.json",
            SETUP.replace(r#""max": [100, 60, 0]"#, r#""max": [50, 60, 0]"#),
            "setup.json (stock): the stock does not contain the toolpath: passes.csv:",
        ),
        (
            "setup.json",
            SETUP.replace(r#""clearance_height": 25"#, r#""clearance_height": -2"#),
            "setup.json (clearance_height): clearance_height -2 is below the stock top 0",
        ),
        ("tool.json", TOOL.replace(r#", "number": 7"#, ""), "tool.json (number): the tool has no `number`"),
        (
            "passes.csv",
            passes().replacen("0,rapid,4,4,-6", "0,rapid,48,30,-6", 1),
            "setup.json (part): the pass starting at passes.csv:2",
        ),
    ];
    for (file, text, needle) in cases {
        let w = job();
        w.write(file, text);
        let o = w.run(BIN, &["passes.csv", "--machine", &m, "--setup", "setup.json", "-o", "p.ngc"], b"");
        o.fails(2, needle);
        assert!(!w.exists("p.ngc"), "{needle}");
    }
}

/// medial-trochoid's layers from a setup: the stock top down to the part's floor in equal steps of
/// at most --layer-depth; box-die's from the setup are the demo's (4 of 10 mm from z 50), a
/// 12 mm limit gives the same 4 layers, and 9 mm gives 5 of 8 mm.
#[test]
fn medial_trochoid_takes_its_layers_from_the_setup() {
    let w = Work::new();
    w.write("tool.json", r#"{"kind": "flat", "radius": 5, "number": 1, "plunge_feed": 200}"#);
    let contour = data("medial-trochoid/box-die.csv");
    let contour = contour.to_string_lossy();
    w.write(
        "setup.json",
        format!(
            r#"{{"tool": "tool.json", "stock": {{"min": [0, 0, 0], "max": [100, 100, 60]}},
              "part": {{"contours": "{contour}", "floor": 20}}, "clearance_height": 80, "safe_height": 65}}"#
        ),
    );
    let common = ["--threshold", "40", "--sample", "2", "--program", "offset"];
    let given = {
        let mut a = vec![contour.as_ref(), "--radius", "5", "--layers", "4", "--layer-depth", "10"];
        a.extend(common);
        w.run("medial-trochoid", &a, b"").ok()
    };
    let from_setup = |depth: &str, report: &str| {
        let mut a = vec![contour.as_ref(), "--setup", "setup.json", "--layer-depth", depth, "--report", report];
        a.extend(common);
        w.run("medial-trochoid", &a, b"").ok()
    };
    assert_eq!(from_setup("10", "a.json"), given);
    assert_eq!(from_setup("12", "b.json"), given);
    from_setup("9", "c.json");
    let r: serde_json::Value = serde_json::from_str(&w.read("c.json")).unwrap();
    assert_eq!(
        (r["layers"].as_u64(), r["layer_depth_mm"].as_f64(), r["first_layer_z"].as_f64()),
        (Some(5), Some(8.0), Some(52.0))
    );
    let mut a = vec![contour.as_ref(), "--setup", "setup.json", "--radius", "4"];
    a.extend(common);
    w.run("medial-trochoid", &a, b"").fails(2, "--radius 4 disagrees with the radius 5");
}

/// Random passes (polylines at random depths, clear of the walls and the island) in the island
/// pocket, posted with the setup: every program passes the independent rapid check and the
/// post's own collision check, with and without ramps. 40 seeded cases.
#[test]
fn random_pocket_jobs_link_safely() {
    let m = machine();
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rand = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let clear = |a: (f64, f64), b: (f64, f64)| {
        let from = [a.0, a.1, 0.0];
        let to = [b.0, b.1, 0.0];
        seg_dist(ISLAND.0, ISLAND.1, &from, &to) >= ISLAND.2 + R + 0.2
    };
    for case in 0..40 {
        let w = job();
        if case % 2 == 1 {
            w.write("setup.json", SETUP.replace(r#""approach": 1"#, r#""approach": 1, "plunge": {"ramp_angle": 5}"#));
        }
        let mut s = String::from("path,move,x,y,z\n");
        let passes = 2 + (rand() * 5.0) as usize;
        for path in 0..passes {
            let z = -2.0 * (1.0 + (rand() * 6.0).floor());
            let mut pts: Vec<(f64, f64)> = Vec::new();
            while pts.len() < 2 + (rand() * 4.0) as usize {
                let p = (R + 0.5 + rand() * (100.0 - 2.0 * R - 1.0), R + 0.5 + rand() * (60.0 - 2.0 * R - 1.0));
                if pts.last().is_none_or(|q| clear(*q, p)) && clear(p, p) {
                    pts.push(p);
                }
            }
            for (k, (x, y)) in pts.iter().enumerate() {
                s.push_str(&format!("{path},{},{x:.4},{y:.4},{z}\n", if k == 0 { "rapid" } else { "line" }));
            }
        }
        w.write("passes.csv", &s);
        let o = w.run(
            BIN,
            &["passes.csv", "--machine", &m, "--setup", "setup.json", "--report", "r.json", "-o", "p.ngc"],
            b"",
        );
        assert_eq!(o.status, 0, "case {case}: {}\n{s}", o.stderr);
        let nc = w.read("p.ngc");
        assert_eq!(unsafe_rapids(&nc), vec![], "case {case}:\n{s}");
        let r = report(&w, "r.json");
        assert_eq!(
            (r["rapids_into_material"].as_u64(), r["part_collisions"].as_u64()),
            (Some(0), Some(0)),
            "case {case}"
        );
    }
}
