//! Jobs end to end: a toolpath, a setup and a machine make a program with safe links, checked
//! here independently of the post's own check (the NC text parsed here, the rapids measured
//! against the stock top, the walls and the islands with exact distances, the material under a
//! descent from the feed moves before it).

use e2e::{Work, data};
use std::process::Command;

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

/// One motion block read from the program text: G0 or not, where it starts and ends, the centre
/// and direction of an XY arc (G17 G2/G3 with I J), its line.
#[derive(Clone, Copy, Debug)]
struct Block {
    rapid: bool,
    from: [f64; 3],
    to: [f64; 3],
    arc: Option<([f64; 2], bool)>,
    line: usize,
}

/// The motion blocks of a 3-axis program of G0/G1/G2/G3 blocks in G17 (modal words carried),
/// after the first position is known in every axis.
fn blocks(nc: &str) -> Vec<Block> {
    let (mut pos, mut known, mut motion) = ([0.0f64; 3], [false; 3], 0);
    let mut out = Vec::new();
    for (i, line) in nc.lines().enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        if words.contains(&"G53") {
            known = [false; 3];
            continue;
        }
        assert!(!words.contains(&"G18") && !words.contains(&"G19"), "XY arcs only here");
        for w in &words {
            match *w {
                "G0" => motion = 0,
                "G1" => motion = 1,
                "G2" => motion = 2,
                "G3" => motion = 3,
                _ => {}
            }
        }
        let word =
            |l: u8| words.iter().find(|w| w.as_bytes()[0] == l).map(|w| w[1..].parse::<f64>().expect("a number"));
        let mut to = pos;
        for (k, l) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
            if let Some(v) = word(l) {
                to[k] = v;
            }
        }
        let (ci, cj) = (word(b'I'), word(b'J'));
        let moved = to != pos || ci.is_some() || cj.is_some();
        if !moved || words.iter().any(|w| w.starts_with('M') || w.starts_with('T')) {
            continue;
        }
        let arc = (motion >= 2).then(|| ([pos[0] + ci.unwrap_or(0.0), pos[1] + cj.unwrap_or(0.0)], motion == 3));
        if known.iter().all(|k| *k) {
            out.push(Block { rapid: motion == 0, from: pos, to, arc, line: i + 1 });
        }
        for (k, l) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
            known[k] |= word(l).is_some();
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

/// Distance from (x, y) to the XY path of a block: its segment, or its arc (the ends if the
/// point's direction from the centre is outside the sweep).
fn block_dist(x: f64, y: f64, b: &Block) -> f64 {
    let Some((c, ccw)) = b.arc else { return seg_dist(x, y, &b.from, &b.to) };
    let ang = |p: [f64; 2]| (p[1] - c[1]).atan2(p[0] - c[0]);
    let (a0, a1, ap) = (ang([b.from[0], b.from[1]]), ang([b.to[0], b.to[1]]), ang([x, y]));
    let tau = std::f64::consts::TAU;
    let (sweep, along) = if ccw {
        ((a1 - a0).rem_euclid(tau), (ap - a0).rem_euclid(tau))
    } else {
        ((a0 - a1).rem_euclid(tau), (a0 - ap).rem_euclid(tau))
    };
    let sweep = if sweep == 0.0 { tau } else { sweep };
    let r = (b.from[0] - c[0]).hypot(b.from[1] - c[1]);
    if along <= sweep {
        ((x - c[0]).hypot(y - c[1]) - r).abs()
    } else {
        (x - b.from[0]).hypot(y - b.from[1]).min((x - b.to[0]).hypot(y - b.to[1]))
    }
}

/// Every G0 of the program that is unsafe, with why: a rapid that moves sideways below the stock
/// top plus the approach; a rapid below the top whose end comes nearer than R to the part
/// (`part`: the signed distance from (x, y) to the part's walls and islands, positive where the
/// tool may be); a descent that ends less than the approach above the material under the tool
/// (the stock less the feed moves before it, over a polar grid of the footprint).
fn unsafe_rapids_in(nc: &str, part: &dyn Fn(f64, f64) -> f64) -> Vec<(usize, String)> {
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
            // Along the rapid every 0.01 mm (a vertical one is a point).
            let n = ((b.to[0] - b.from[0]).hypot(b.to[1] - b.from[1]) / 0.01).ceil().max(1.0) as usize;
            let d = (0..=n)
                .map(|k| {
                    let t = k as f64 / n as f64;
                    part(b.from[0] + (b.to[0] - b.from[0]) * t, b.from[1] + (b.to[1] - b.from[1]) * t)
                })
                .fold(f64::INFINITY, f64::min)
                - R;
            if d < -1e-4 {
                why.push(format!("{:.4} mm into the walls or an island", -d));
            }
        }
        if !why.is_empty() {
            bad.push((b.line, why.join(", ")));
            continue;
        }
        if b.to[2] < b.from[2] {
            let (x0, y0) = (b.to[0], b.to[1]);
            let near: Vec<&Block> = bs[..i].iter().filter(|f| !f.rapid && block_dist(x0, y0, f) <= 2.0 * R).collect();
            let top = |x: f64, y: f64| {
                near.iter().filter(|f| block_dist(x, y, f) <= R).map(|f| f.from[2].min(f.to[2])).fold(0.0f64, f64::min)
            };
            let mut highest = f64::NEG_INFINITY;
            for ring in 0..=8 {
                let rho = (R - 0.011) * ring as f64 / 8.0;
                for k in 0..48 {
                    let a = std::f64::consts::TAU * k as f64 / 48.0;
                    highest = highest.max(top(x0 + rho * a.cos(), y0 + rho * a.sin()));
                }
            }
            if b.to[2] < highest + APPROACH - 0.01 - 1e-9 {
                bad.push((b.line, format!("descends to {} over material at {highest}", b.to[2])));
            }
        }
    }
    bad
}

/// [`unsafe_rapids_in`] for the 100 × 60 pocket with its round island.
fn unsafe_rapids(nc: &str) -> Vec<(usize, String)> {
    unsafe_rapids_in(nc, &|x, y| {
        let island = (x - ISLAND.0).hypot(y - ISLAND.1) - ISLAND.2;
        let walls = x.min(100.0 - x).min(y).min(60.0 - y);
        island.min(walls)
    })
}

/// Signed distance from (x, y) to a rectangle centred at (cx, cy), half sides (hx, hy), corners
/// rounded by r: positive outside.
fn rounded_box(x: f64, y: f64, (cx, cy): (f64, f64), (hx, hy): (f64, f64), r: f64) -> f64 {
    let (qx, qy) = ((x - cx).abs() - (hx - r), (y - cy).abs() - (hy - r));
    qx.max(0.0).hypot(qy.max(0.0)) + qx.max(qy).min(0.0) - r
}

/// The XY point at fraction `t` of a block (along its arc for G2/G3, the short way from its
/// start's angle in its direction).
fn block_point(b: &Block, t: f64) -> (f64, f64) {
    let Some((c, ccw)) = b.arc else {
        return (b.from[0] + (b.to[0] - b.from[0]) * t, b.from[1] + (b.to[1] - b.from[1]) * t);
    };
    let ang = |p: &[f64; 3]| (p[1] - c[1]).atan2(p[0] - c[0]);
    let tau = std::f64::consts::TAU;
    let sweep =
        if ccw { (ang(&b.to) - ang(&b.from)).rem_euclid(tau) } else { -(ang(&b.from) - ang(&b.to)).rem_euclid(tau) };
    let r = (b.from[0] - c[0]).hypot(b.from[1] - c[1]);
    let a = ang(&b.from) + sweep * t;
    (c[0] + r * a.cos(), c[1] + r * a.sin())
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
    assert!(found.iter().any(|(_, why)| why.contains("into the walls or an island")), "{found:?}");
}

/// The island pocket with lead arcs (R3) and 3° ramps: the slots and the octagon entered and left
/// along tangent arcs on the side away from the part (the octagon round the island leads
/// outwards: inwards would come 0.12 mm into it); the wall passes, which start and end in a
/// corner touching two walls, have room for neither (counted, not cut); every feed move, arcs
/// sampled, keeps R from the walls and the island, and every G0 stays safe.
#[test]
fn lead_arcs_keep_clear_of_the_part() {
    let w = job();
    let m = machine();
    w.write(
        "lead.json",
        SETUP.replace(
            r#""approach": 1"#,
            r#""approach": 1, "lead": {"radius": 3}, "plunge": {"feed": 150, "ramp_angle": 3}"#,
        ),
    );
    w.run(BIN, &["passes.csv", "--machine", &m, "--setup", "lead.json", "--report", "r.json", "-o", "p.ngc"], b"").ok();
    let nc = w.read("p.ngc");
    let r = report(&w, "r.json");
    assert_eq!(
        (r["lead_ins"].as_u64(), r["lead_outs"].as_u64(), r["leads_not_clear"].as_u64()),
        (Some(6), Some(6), Some(4)),
        "{r}"
    );
    assert_eq!((r["rapids_into_material"].as_u64(), r["part_collisions"].as_u64()), (Some(0), Some(0)), "{r}");
    assert_eq!(unsafe_rapids(&nc), vec![], "{nc}");
    let part =
        |x: f64, y: f64| ((x - ISLAND.0).hypot(y - ISLAND.1) - ISLAND.2).min(x.min(100.0 - x).min(y).min(60.0 - y));
    let bs = blocks(&nc);
    assert!(bs.iter().filter(|b| b.arc.is_some()).count() >= 16, "{nc}");
    for b in bs.iter().filter(|b| !b.rapid && b.to[2] < 0.0) {
        for k in 0..=32 {
            let (x, y) = block_point(b, k as f64 / 32.0);
            assert!(part(x, y) >= R - 1e-3, "line {}: ({x}, {y}) is {} from the part", b.line, part(x, y));
        }
    }
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
            "setup.json:1:32 (stock): the stock does not contain the toolpath: passes.csv:",
        ),
        (
            "setup.json",
            SETUP.replace(r#""clearance_height": 25"#, r#""clearance_height": -2"#),
            "setup.json:2:73 (clearance_height): clearance_height -2 is below the stock top 0",
        ),
        ("tool.json", TOOL.replace(r#", "number": 7"#, ""), "tool.json:1:1 (number): the tool has no `number`"),
        (
            "passes.csv",
            passes().replacen("0,rapid,4,4,-6", "0,rapid,48,30,-6", 1),
            "setup.json:2:11 (part): the pass starting at passes.csv:2",
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

/// medial-trochoid's engagement model is a flat end mill's (a disc of the tool's radius cutting
/// each layer to its floor): a setup whose tool is a cone is refused naming the tool (exit 2),
/// nothing written.
#[test]
fn medial_trochoid_refuses_a_cone_cutter() {
    let w = Work::new();
    w.write("tool.json", r#"{"kind": "cone", "radius": 5, "half_angle": 45, "number": 1, "plunge_feed": 200}"#);
    let contour = data("medial-trochoid/box-die.csv");
    let contour = contour.to_string_lossy();
    w.write(
        "setup.json",
        format!(
            r#"{{"tool": "tool.json", "stock": {{"min": [0, 0, 0], "max": [100, 100, 60]}},
              "part": {{"contours": "{contour}", "floor": 20}}, "clearance_height": 80, "safe_height": 65}}"#
        ),
    );
    w.run("medial-trochoid", &[contour.as_ref(), "--setup", "setup.json", "-o", "out.csv"], b"")
        .fails(2, "setup.json:1:10 (tool): ./tool.json is a cone cutter: the engagement model is a flat end mill's");
    assert!(!w.exists("out.csv"));
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

/// The DXF pocket with two islands (data/post-6axis/pocket-islands.dxf) roughed by medial-trochoid
/// for a φ8 flat end mill in 3 layers (the layers from the setup), posted with the setup: every
/// G0 safe by the independent check against the islands' and the walls' exact shapes, the stock
/// top and the material the earlier cuts left; the post's check agrees.
#[test]
fn the_dxf_pocket_with_two_islands_posts_with_safe_rapids() {
    let w = Work::new();
    let setup = data("jobs/pocket-islands.json");
    let setup = setup.to_string_lossy();
    let dxf = data("post-6axis/pocket-islands.dxf");
    let args = [dxf.to_str().unwrap(), "--setup", &setup, "--layer-depth", "4", "--sample", "2", "--decimals", "4"];
    w.run("medial-trochoid", &[&args[..], &["--report", "mt.json", "-o", "rough.csv"]].concat(), b"").ok();
    let mt: serde_json::Value = serde_json::from_str(&w.read("mt.json")).unwrap();
    assert_eq!((mt["layers"].as_u64(), mt["islands"].as_u64()), (Some(3), Some(2)), "{mt}");
    w.run(
        BIN,
        &["rough.csv", "--machine", &machine(), "--setup", &setup, "--report", "r.json", "-o", "rough.ngc"],
        b"",
    )
    .ok();
    let nc = w.read("rough.ngc");
    let part = |x: f64, y: f64| {
        let walls = -rounded_box(x, y, (60.0, 40.0), (60.0, 40.0), 10.0);
        let round = (x - 35.0).hypot(y - 40.0) - 8.0;
        let square = rounded_box(x, y, (85.0, 40.0), (10.0, 8.0), 3.0);
        walls.min(round).min(square)
    };
    let bad = unsafe_rapids_in(&nc, &part);
    assert_eq!(bad, vec![], "unsafe rapids");
    let rapids = blocks(&nc).iter().filter(|b| b.rapid && b.from[2].min(b.to[2]) < 0.0).count();
    assert!(rapids > 50, "{rapids} rapids below the stock top checked");
    let r = report(&w, "r.json");
    assert_eq!((r["rapids_into_material"].as_u64(), r["part_collisions"].as_u64()), (Some(0), Some(0)), "{r}");
    // Every feed move keeps R from the islands and the walls (to the rounding of 4 decimals).
    for b in blocks(&nc).iter().filter(|b| !b.rapid && b.to[2] < 0.0) {
        for t in 0..=4 {
            let t = t as f64 / 4.0;
            let (x, y) = match b.arc {
                None => (b.from[0] + (b.to[0] - b.from[0]) * t, b.from[1] + (b.to[1] - b.from[1]) * t),
                Some(_) => (b.to[0], b.to[1]),
            };
            assert!(part(x, y) >= R - 1e-3, "line {}: ({x}, {y}) is {} from the part", b.line, part(x, y));
        }
    }
}

/// The check against a 3-D part shows a progress bar on a terminal (run under `script`, which
/// gives the program one) and nothing in a pipe.
#[test]
fn the_part_check_shows_progress_on_a_terminal_only() {
    use camkit::geom::P3;
    let w = job();
    let floor = [
        [P3::new(-10.0, -10.0, -13.0), P3::new(110.0, -10.0, -13.0), P3::new(110.0, 70.0, -13.0)],
        [P3::new(-10.0, -10.0, -13.0), P3::new(110.0, 70.0, -13.0), P3::new(-10.0, 70.0, -13.0)],
    ];
    w.write("floor.stl", camkit::model::mesh::binary_stl(&floor));
    w.write("solid.json", SETUP.replace(r#""contours": "pocket.csv", "floor": -12"#, r#""model": "floor.stl""#));
    let m = machine();
    let args = ["passes.csv", "--machine", &m, "--setup", "solid.json", "-o", "p.ngc"];
    let piped = w.run(BIN, &args, b"");
    piped.ok();
    assert!(!piped.stderr.contains("checking against the part"), "{}", piped.stderr);
    if Command::new("script").arg("--version").output().is_err() {
        return;
    }
    let line = std::iter::once(e2e::bin(BIN).display().to_string())
        .chain(args.iter().map(|a| a.to_string()))
        .collect::<Vec<_>>()
        .join(" ");
    let tty = Command::new("script").args(["-qec", &line, "/dev/null"]).current_dir(w.path("")).output().unwrap();
    assert!(tty.status.success(), "{tty:?}");
    assert!(String::from_utf8_lossy(&tty.stdout).contains("checking against the part"), "{tty:?}");
}

/// A cone cutter is not linked or checked with a setup: the stock model would take its V groove
/// for a flat end mill's full-width slot and let rapids pass through stock still standing. Refused
/// naming the setup's tool (exit 2), no program written.
#[test]
fn a_cone_cutter_is_refused_with_a_setup() {
    let w = job();
    w.write("tool.json", r#"{"kind": "cone", "radius": 4, "half_angle": 45, "number": 7, "plunge_feed": 200}"#);
    let m = machine();
    w.run(BIN, &["passes.csv", "--machine", &m, "--setup", "setup.json", "-o", "p.ngc"], b"")
        .fails(2, "setup.json:1:10 (tool): ./tool.json is a cone cutter");
    assert!(!w.exists("p.ngc"));
}
