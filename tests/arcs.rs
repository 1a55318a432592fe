//! Arcs through the post and back: rows with arcs in every plane posted as G2/G3 where the
//! controller moves on a true circle (3-axis, a vertical axis on a table machine), linearised
//! against the true arc where it cannot (a tilted, locked axis), read back by `--reverse` and
//! `--verify`, by LinuxCNC's interpreter where it is installed; and the post's NC compressed by
//! curve-fit-arcs and verified again.

use camkit::geom::{P2, P3, Plane};
use camkit::io::Input;
use camkit::table::{self, Col, Move, Table};
use e2e::{Work, data};

const BIN: &str = "post-6axis";

fn machine(name: &str) -> String {
    data(&format!("post-6axis/{name}")).to_string_lossy().into_owned()
}

fn parse(name: &str, text: &str) -> Table {
    table::read(&Input { name: name.into(), data: text.as_bytes().to_vec() }, &[Col::X]).expect("a table")
}

/// A pass of lines and arcs: a quarter in XY, a full circle, a helical turn, a half circle in XZ
/// and one in YZ, a three-quarter arc the long way round.
const ROWS: &str = "path,move,x,y,z,xc,yc,zc,plane,i,j,k\n\
0,rapid,0,0,-1,,,,,0,0,1\n\
0,line,10,0,-1,,,,,0,0,1\n\
0,ccw,0,10,-1,0,0,,xy,0,0,1\n\
0,cw,0,10,-1,0,5,,xy,0,0,1\n\
0,ccw,0,10,-4,0,5,,xy,0,0,1\n\
0,cw,10,10,-4,5,,-4,xz,0,0,1\n\
0,ccw,10,20,-4,,15,-4,yz,0,0,1\n\
0,cw,20,30,-4,20,20,,xy,0,0,1\n";

/// The feed rows of a table as (move, position, centre, plane).
fn feeds(t: &Table) -> Vec<(Move, P3, Option<P2>, Plane)> {
    t.rows.iter().filter(|r| r.mv != Move::Rapid).map(|r| (r.mv, r.pos, r.centre, r.plane)).collect()
}

/// Posted on the 3-axis machine every arc is one G2/G3 block, in its plane; `--reverse` gives the
/// same moves back (positions and centres to the rounding of 4 decimals) and LinuxCNC agrees.
#[test]
fn arcs_round_trip_through_the_post() {
    let w = Work::new();
    w.write("arcs.csv", ROWS);
    let m = machine("three-axis.json");
    w.run(BIN, &["arcs.csv", "--machine", &m, "--feed", "500", "--report", "r.json", "-o", "arcs.ngc"], b"").ok();
    let nc = w.read("arcs.ngc");
    let r: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
    assert!(r["largest_tip_deviation_mm"].as_f64().unwrap() < 1e-4, "{r}");
    assert!(r["largest_row_distance_mm"].as_f64().unwrap() < 1e-4, "{r}");
    let arcs = nc.lines().filter(|l| l.starts_with("G2 ") || l.starts_with("G3 ")).count();
    assert_eq!(arcs, 6, "{nc}");
    assert!(nc.contains("G18\n") && nc.contains("G19\n") && nc.contains("G17\n"), "{nc}");
    let back = parse("back.csv", &w.run(BIN, &["arcs.ngc", "--machine", &m, "--reverse"], b"").ok());
    let want = feeds(&parse("arcs.csv", ROWS));
    let got = feeds(&back);
    assert_eq!(got.len(), want.len(), "{back:?}");
    for ((mg, pg, cg, lg), (mw, pw, cw, lw)) in got.iter().zip(&want) {
        assert_eq!((mg, lg), (mw, lw));
        assert!((pg - pw).norm() < 1e-9, "{pg:?} vs {pw:?}");
        match (cg, cw) {
            (Some(a), Some(b)) => assert!((a - b).norm() < 1e-9, "{a:?} vs {b:?}"),
            (None, None) => {}
            _ => panic!("centre lost: {cg:?} {cw:?}"),
        }
    }
    // --verify with the rows: within the tolerance, 16 samples on the full circles at least.
    let v: serde_json::Value = serde_json::from_str(
        &w.run(BIN, &["arcs.csv", "--machine", &m, "--feed", "500", "--verify", "arcs.ngc"], b"").ok(),
    )
    .unwrap();
    assert!(v["largest_tip_deviation_mm"].as_f64().unwrap() < 1e-4, "{v}");
    if std::path::Path::new("/usr/bin/rs274").exists() {
        let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/linuxcnc-check.sh");
        let o = std::process::Command::new("bash").arg(script).arg(w.path("arcs.ngc")).output().unwrap();
        let said = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success() && said.contains("(6 arcs)"), "{said}");
    }
}

/// On a table machine a vertical tool keeps the rotaries still: XY arcs stay G2/G3. Tilted 30°
/// about X (A locked) the XY plane is no plane of the controller's: the arcs are linearised, and
/// read back within the tolerance of the true arcs.
#[test]
fn arcs_on_a_table_machine_are_kept_or_linearised() {
    let w = Work::new();
    let m = machine("paper002-ac.json");
    let xy_rows = |i: f64, j: f64, k: f64| {
        format!(
            "path,move,x,y,z,xc,yc,i,j,k\n0,rapid,10,0,5,,,{i},{j},{k}\n0,ccw,0,10,5,0,0,{i},{j},{k}\n0,ccw,-10,0,5,0,0,{i},{j},{k}\n0,cw,10,0,5,0,0,{i},{j},{k}\n"
        )
    };
    w.write("up.csv", xy_rows(0.0, 0.0, 1.0));
    w.run(BIN, &["up.csv", "--machine", &m, "--feed", "500", "--report", "up.json", "-o", "up.ngc"], b"").ok();
    let r: serde_json::Value = serde_json::from_str(&w.read("up.json")).unwrap();
    let nc = w.read("up.ngc");
    assert_eq!(nc.lines().filter(|l| l.starts_with("G2 ") || l.starts_with("G3 ")).count(), 2, "{nc}");
    assert!(r["largest_tip_deviation_mm"].as_f64().unwrap() <= 0.005, "{r}");
    let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    w.write("tilted.csv", xy_rows(0.0, -s, c));
    w.run(
        BIN,
        &["tilted.csv", "--machine", &m, "--feed", "500", "--tol", "0.002", "--report", "t.json", "-o", "t.ngc"],
        b"",
    )
    .ok();
    let r: serde_json::Value = serde_json::from_str(&w.read("t.json")).unwrap();
    let nc = w.read("t.ngc");
    assert!(!nc.lines().any(|l| l.starts_with("G2 ") || l.starts_with("G3 ")), "{nc}");
    assert!(r["blocks"].as_u64().unwrap() > 50, "{r}");
    assert!(r["largest_tip_deviation_mm"].as_f64().unwrap() <= 0.002, "{r}");
    // An independent check of the linearisation: every block end lies on the circle of radius 10
    // (the reverse's tip positions), and so does every chord's middle within the tolerance.
    let back = parse("b.csv", &w.run(BIN, &["t.ngc", "--machine", &m, "--reverse"], b"").ok());
    let pts: Vec<P3> = back.rows.iter().filter(|r| r.mv != Move::Rapid).map(|r| r.pos).collect();
    for p in &pts {
        assert!(((p.x * p.x + p.y * p.y).sqrt() - 10.0).abs() < 1e-3 && (p.z - 5.0).abs() < 1e-3, "{p:?}");
    }
    for q in pts.windows(2) {
        let mid = (q[0].coords + q[1].coords) * 0.5;
        assert!(10.0 - (mid.x * mid.x + mid.y * mid.y).sqrt() <= 0.002 + 1e-3, "{mid:?}");
    }
}

/// The post's own 3-axis program, its G1 runs fitted to arcs by curve-fit-arcs, still does what
/// the rows ask (the post's --verify reads the arcs), with far fewer blocks.
#[test]
fn the_post_reads_its_program_after_curve_fit_arcs() {
    let w = Work::new();
    let mut rows = String::from("path,move,x,y,z\n0,rapid,20,0,-2\n");
    for k in 1..=720 {
        let a = (k as f64 * 0.5).to_radians();
        rows.push_str(&format!("0,line,{},{},-2\n", 20.0 * a.cos(), 20.0 * a.sin()));
    }
    w.write("circle.csv", &rows);
    let m = machine("three-axis.json");
    w.run(BIN, &["circle.csv", "--machine", &m, "--feed", "500", "-o", "c.ngc"], b"").ok();
    w.run("curve-fit-arcs", &["c.ngc", "--tol", "0.002", "-o", "fit.ngc"], b"").ok();
    let fit = w.read("fit.ngc");
    let arcs = fit.lines().filter(|l| l.starts_with("G2 ") || l.starts_with("G3 ")).count();
    assert!(arcs >= 1 && fit.lines().count() < 40, "{fit}");
    let v = w.run(BIN, &["circle.csv", "--machine", &m, "--feed", "500", "--verify", "fit.ngc", "--tol", "0.005"], b"");
    let v: serde_json::Value = serde_json::from_str(&v.ok()).unwrap();
    assert!(v["largest_tip_deviation_mm"].as_f64().unwrap() <= 0.005, "{v}");
    assert!(v["largest_row_distance_mm"].as_f64().unwrap() <= 0.005, "{v}");
    let back = parse("b.csv", &w.run(BIN, &["fit.ngc", "--machine", &m, "--reverse"], b"").ok());
    assert!(back.rows.iter().any(|r| r.mv.is_arc()));
}
