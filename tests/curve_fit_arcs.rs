//! End-to-end tests of `curve-fit-arcs`: real G-code and tables in, outputs measured by the
//! independent instrument in `paths`, bad input refused with one clear line.

use camkit::geom::P3;
use e2e::paths::{hausdorff, program_path};
use e2e::{Work, data};

const BIN: &str = "curve-fit-arcs";

fn report(w: &Work, name: &str) -> serde_json::Value {
    serde_json::from_str(&w.read(name)).expect("report is JSON")
}

/// Deviation of a written program from its source, by the independent instrument.
fn measured(input: &str, output: &str, tol: f64) -> f64 {
    let a = program_path("in", input, tol * 1e-3);
    let b = program_path("out", output, tol * 1e-3);
    hausdorff(&a, &b, tol / 10.0, 4.0 * tol)
}

#[test]
fn engraving_is_compressed_within_tolerance_both_ways() {
    let w = Work::new();
    let src = std::fs::read_to_string(data("gcode/cncjs_jsdc-engrave.gcode")).unwrap();
    for tol in [0.025, 0.005] {
        let out = w.run(
            BIN,
            &[
                data("gcode/cncjs_jsdc-engrave.gcode").to_str().unwrap(),
                "--tol",
                &tol.to_string(),
                "--report",
                "r.json",
                "--lower-bound",
                "-o",
                "out.nc",
            ],
            b"",
        );
        out.ok();
        let text = w.read("out.nc");
        let r = report(&w, "r.json");
        // The proved floor of any segmentation lies below what the search wrote, not far below.
        let floor = r["moves_lower_bound"].as_u64().unwrap();
        let written = r["output_moves"].as_u64().unwrap();
        assert!(floor <= written && 2 * floor >= written, "bound {floor}, written {written}");
        let reported = r["largest_deviation_mm"].as_f64().unwrap();
        assert!(reported <= tol, "reported {reported} > {tol}");
        let independent = measured(&src, &text, tol);
        assert!(independent <= tol * (1.0 + 1e-9), "measured {independent} > tol {tol}");
        assert!(
            independent <= reported + tol / 50.0,
            "the filter's figure {reported} is below what it wrote ({independent})"
        );
        let (input_moves, output_moves) = (r["input_moves"].as_u64().unwrap(), r["output_moves"].as_u64().unwrap());
        assert_eq!(input_moves, 2382);
        // ArcWelder: 103 moves at ±0.025 and 160 at ±0.005 on this file (../shared/data).
        assert!(output_moves < if tol > 0.01 { 103 } else { 160 }, "{output_moves} moves at tol {tol}");
        // Comments and non-motion blocks are kept, in order.
        let remarks = |t: &str| {
            t.lines()
                .filter(|l| l.starts_with(';') || l.starts_with("G2") && l.contains("Set units"))
                .map(str::to_string)
                .collect::<Vec<_>>()
        };
        assert_eq!(remarks(&text), remarks(&src));
    }
}

#[test]
fn printer_extrusion_is_carried_over_merged_moves() {
    let w = Work::new();
    let path = data("gcode/gcode-preview_vase_prusaslicer274.gcode");
    let src = std::fs::read_to_string(&path).unwrap();
    w.run(BIN, &[path.to_str().unwrap(), "--tol", "0.025", "-o", "out.gcode"], b"").ok();
    let text = w.read("out.gcode");
    let total_e = |t: &str| -> f64 {
        let p = camkit::gcode::read("x", t.to_string()).unwrap();
        p.blocks.iter().filter_map(|b| if let camkit::gcode::Block::Move(m) = b { m.e_delta } else { None }).sum()
    };
    let (a, b) = (total_e(&src), total_e(&text));
    assert!((a - b).abs() < 1e-6, "extrusion {a} became {b}");
    assert!(measured(&src, &text, 0.025) <= 0.025 * (1.0 + 1e-9));
    // Every M, temperature and fan command is still there, in order.
    let commands = |t: &str| t.lines().filter(|l| l.starts_with('M')).map(str::to_string).collect::<Vec<_>>();
    assert_eq!(commands(&text), commands(&src));
}

#[test]
fn inch_circle_of_ten_thousand_segments_becomes_a_few_arcs() {
    // As LinuxCNC's circle_small_segments test: a 1-inch circle as 10 000 G01 of 0.0006 in.
    let mut src = String::from("G20 G90\nG0 X0 Y0 Z0\nF9999\n");
    for i in 0..=10_000 {
        let a = std::f64::consts::TAU * i as f64 / 10_000.0;
        src.push_str(&format!("G01 X{:.4} Y{:.4}\n", a.sin(), a.cos()));
    }
    let w = Work::new();
    w.write("circle.ngc", &src);
    w.run(BIN, &["circle.ngc", "--tol", "0.005", "-o", "out.ngc", "--report", "r.json"], b"").ok();
    let out = w.read("out.ngc");
    let arcs = out.lines().filter(|l| l.starts_with("G2") || l.starts_with("G3")).count();
    assert!((2..=4).contains(&arcs), "{arcs} arcs:\n{out}");
    assert!(out.starts_with("G20 G90"), "stays in inches");
    assert!(measured(&src, &out, 0.005) <= 0.005 * (1.0 + 1e-9));
}

#[test]
fn modal_moves_and_line_numbers_are_read_and_kept_valid() {
    // Modal moves (no G word) after an arc must get their G1 back; N numbers stay in order.
    let mut src = String::from("G21 G90 G17\nG0 X0 Y0 Z1\nG1 Z-1 F300\n");
    let mut n = 10;
    for i in 1..=200 {
        let a = std::f64::consts::PI * i as f64 / 200.0;
        src.push_str(&format!("N{n} X{:.5} Y{:.5}\n", 20.0 - 20.0 * a.cos(), 20.0 * a.sin()));
        n += 10;
    }
    // A modal block the filter cannot merge (it carries S): copied verbatim, it needs its G1 back.
    src.push_str("N3000 X50 Y0 S900\nN3010 X60 Y0\nN3020 X70 Y0\nN3030 M5\n");
    let w = Work::new();
    w.write("modal.ngc", &src);
    let out = w.run(BIN, &["modal.ngc", "--tol", "0.01"], b"").ok();
    assert!(out.lines().count() < 20, "{out}");
    assert!(out.contains("\nN3000 G1 X50 Y0 S900\n"), "modal line after an arc gets G1:\n{out}");
    assert!(out.contains("\nN3020 G1 X70\n"), "collinear moves merge:\n{out}");
    let numbers: Vec<u64> = out
        .lines()
        .filter_map(|l| l.strip_prefix('N'))
        .map(|l| l.split(|c: char| !c.is_ascii_digit()).next().unwrap().parse().unwrap())
        .collect();
    assert!(numbers.windows(2).all(|w| w[0] < w[1]), "N numbers in order: {numbers:?}");
    assert!(measured(&src, &out, 0.01) <= 0.01 * (1.0 + 1e-9));
}

#[test]
fn table_of_points_on_an_arc_gives_one_arc_and_passes_columns_through() {
    let mut csv = String::from("# an exact quarter circle\ny,x,label\n");
    for i in 0..=90 {
        let a = (i as f64).to_radians();
        csv.push_str(&format!("{},{},p{i}\n", 5.0 + 12.5 * a.sin(), -3.0 + 12.5 * a.cos()));
    }
    let w = Work::new();
    let out = w.run(BIN, &["-", "--tol", "0.001"], csv.as_bytes()).ok();
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "move,y,x,xc,yc,label", "{out}");
    assert_eq!(lines.len(), 3, "{out}");
    assert!(lines[1].starts_with("line,") && lines[1].ends_with(",,,p0"), "{}", lines[1]);
    let f: Vec<&str> = lines[2].split(',').collect();
    assert_eq!((f[0], f[5]), ("ccw", "p90"));
    let (xc, yc): (f64, f64) = (f[3].parse().unwrap(), f[4].parse().unwrap());
    assert!((xc + 3.0).abs() < 1e-9 * 12.5 && (yc - 5.0).abs() < 1e-9 * 12.5, "centre {xc},{yc}");
}

#[test]
fn gcode_to_table_and_back_keeps_every_position() {
    let w = Work::new();
    let src = std::fs::read_to_string(data("gcode/cncjs_jsdc-engrave.gcode")).unwrap();
    // Without fitting (a tolerance below the file's resolution keeps every move) and with it.
    w.run(
        BIN,
        &[data("gcode/cncjs_jsdc-engrave.gcode").to_str().unwrap(), "--to", "table", "-o", "t.csv", "--tol", "1e-9"],
        b"",
    )
    .ok();
    let back = w.run(BIN, &["t.csv", "--to", "gcode", "--tol", "1e-9"], b"").ok();
    let ends = |t: &str| -> Vec<P3> {
        let p = camkit::gcode::read("x", t.to_string()).unwrap();
        p.blocks.iter().filter_map(|b| if let camkit::gcode::Block::Move(m) = b { Some(m.end) } else { None }).collect()
    };
    let (a, b) = (ends(&src), ends(&back));
    // Only exactly collinear moves merge at this tolerance: the written ends are source ends, in
    // order, and the paths coincide.
    let mut k = 0;
    for q in &b {
        while k < a.len() && (a[k] - q).norm() > 1e-12 {
            k += 1;
        }
        assert!(k < a.len(), "{q:?} is not a source position in order");
    }
    assert!(a.len() - b.len() < 10, "{} of {} moves merged", a.len() - b.len(), a.len());
    assert!(measured(&src, &back, 0.01) <= 1e-9);
    w.run(
        BIN,
        &[data("gcode/cncjs_jsdc-engrave.gcode").to_str().unwrap(), "--to", "table", "-o", "f.csv", "--tol", "0.01"],
        b"",
    )
    .ok();
    let fitted = w.run(BIN, &["f.csv", "--to", "gcode", "--decimals", "6", "--tol", "0.01"], b"").ok();
    assert!(measured(&src, &fitted, 0.01) <= 0.01 * (1.0 + 1e-9));
}

#[test]
fn bad_input_is_refused_with_file_line_and_column() {
    let w = Work::new();
    w.write("bad.csv", "x,y,z\n1,2,3\n1,2,1,2x\n");
    w.run(BIN, &["bad.csv"], b"").fails(2, "bad.csv:3:");
    w.write("text.csv", "x,y,z\n1,2,3\n1,2,\"1,2x\"\n");
    w.run(BIN, &["text.csv", "-o", "out.csv"], b"")
        .fails(2, "curve-fit-arcs: text.csv:3:3 (z): expected a number, found \"1,2x\"");
    assert!(!w.exists("out.csv"), "no partial output");
    w.write("noy.csv", "x,z\n1,2\n3,4\n");
    w.run(BIN, &["noy.csv"], b"").fails(2, "noy.csv:1: missing column `y`");
    w.write("nan.csv", "x,y\n1,2\n3,NaN\n");
    w.run(BIN, &["nan.csv"], b"").fails(2, "nan.csv:3:2 (y): expected a finite number, found \"NaN\"");
    w.write("inf.csv", "x,y\n1,2\ninf,3\n");
    w.run(BIN, &["inf.csv"], b"").fails(2, "inf.csv:3:1 (x)");
    w.write("empty.csv", "");
    w.run(BIN, &["empty.csv"], b"").fails(2, "empty.csv: empty input");
    w.write("one.csv", "x,y\n1,2\n");
    w.run(BIN, &["one.csv"], b"").fails(2, "one.csv: a single point");
    w.write("same.csv", "x,y\n1,2\n1,2\n1,2\n");
    w.run(BIN, &["same.csv"], b"").fails(2, "a single point");
    w.write("bad.nc", "G21\nG1 X1 Y1\nG1 X2 Q@ Y2\n");
    w.run(BIN, &["bad.nc", "-o", "out.nc"], b"").fails(2, "bad.nc:3:");
    assert!(!w.exists("out.nc"));
    w.write("word.nc", "G1 X1.2.3 Y2\n");
    w.run(BIN, &["word.nc"], b"").fails(2, "word.nc:1:4 (X1.2.3): malformed word");
    w.run(BIN, &["missing.csv"], b"").fails(2, "cannot read missing.csv");
    w.run(BIN, &["--tol", "-1"], b"x,y\n0,0\n1,1\n").fails(2, "--tol must be a positive number");
    w.run(BIN, &["--plane", "uv"], b"x,y\n0,0\n1,1\n").fails(2, "--plane must be xy, xz, yz or auto");
    assert_eq!(w.files().iter().filter(|f| f.starts_with(".camkit")).count(), 0, "no temporary files left");
}

#[test]
fn repeated_points_are_dropped_and_counted() {
    let w = Work::new();
    let out = w.run(BIN, &["-", "--report", "r.json"], b"x,y\n0,0\n1,0\n1,0\n2,0\n2,0\n2,0\n3,0\n").ok();
    assert_eq!(out, "move,x,y\nline,0.0,0.0\nline,3.0,0.0\n");
    assert_eq!(report(&w, "r.json")["dropped_repeats"], 3);
}

#[test]
fn never_merges_across_path_feed_axis_or_rapid() {
    let csv = "path,move,x,y,f,i,j,k\n\
        0,rapid,0,0,,0,0,1\n0,line,1,0,100,0,0,1\n0,line,2,0,100,0,0,1\n0,line,3,0,200,0,0,1\n0,line,4,0,200,0,0,1\n\
        0,line,5,0,200,0,0.6,0.8\n0,line,6,0,200,0,0.6,0.8\n1,line,7,0,200,0,0.6,0.8\n1,line,8,0,200,0,0.6,0.8\n0,rapid,9,0,,0,0,1\n0,line,10,0,200,0,0,1\n";
    let w = Work::new();
    let out = w.run(BIN, &["-"], csv.as_bytes()).ok();
    let xs: Vec<&str> = out.lines().skip(1).map(|l| l.split(',').nth(2).unwrap()).collect();
    // 0 → 2 at feed 100, 2 → 4 at 200, 4 → 6 with a tilted axis, a new path 7 → 8, a rapid to 9.
    assert_eq!(xs, ["0.0", "2.0", "4.0", "6.0", "7.0", "8.0", "9.0", "10.0"], "{out}");
}

#[test]
fn svg_plot_shows_points_lines_and_arcs() {
    let w = Work::new();
    let mut csv = String::from("x,y\n");
    for i in 0..=300 {
        let x = i as f64 * 0.1;
        csv.push_str(&format!("{x},{}\n", if x < 10.0 { 0.0 } else { 5.0 * ((x - 10.0) / 5.0).sin() }));
    }
    w.run(BIN, &["-", "--svg", "plot.svg", "-o", "out.csv"], csv.as_bytes()).ok();
    let svg = w.read("plot.svg");
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("#1f77b4") && svg.contains("#d62728") && svg.contains("<circle"), "lines, arcs, points");
}

#[test]
fn closed_output_pipe_is_not_an_error() {
    use std::process::{Command, Stdio};
    let mut csv = String::from("x,y\n");
    for i in 0..200_000 {
        csv.push_str(&format!("{i},{}\n", i % 7));
    }
    let w = Work::new();
    w.write("big.csv", &csv);
    let mut child = Command::new(e2e::bin(BIN))
        .arg(w.path("big.csv"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.stderr.is_empty(), "{}", String::from_utf8_lossy(&out.stderr));
}

/// Tool axes that differ only by round-off from an earlier stage (1e-16 in `i`) do not split a
/// run: a quarter circle of 200 points becomes one arc; axes 0.01° apart are kept apart.
#[test]
fn axes_equal_to_round_off_merge() {
    let w = Work::new();
    let table = |wobble: f64| {
        let mut s = String::from("path,x,y,z,i,j,k\n");
        for n in 0..=200 {
            let a = std::f64::consts::FRAC_PI_2 * n as f64 / 200.0;
            let i = if n % 2 == 0 { 0.0 } else { wobble };
            s.push_str(&format!("0,{},{},0,{i:e},0,{}\n", 20.0 * a.cos(), 20.0 * a.sin(), (1.0 - i * i).sqrt()));
        }
        s
    };
    w.write("roundoff.csv", table(1e-16));
    w.write("tilted.csv", table(0.01f64.to_radians().sin()));
    let rows = |name: &str| w.run(BIN, &[name, "--tol", "0.001"], b"").ok().lines().count() - 1;
    assert_eq!(rows("roundoff.csv"), 2, "a start row and one arc");
    assert_eq!(rows("tilted.csv"), 201, "every row its own axis");
}

/// Issue 20: every numeric option at extreme values, seeded (scripts/fuzz-options.py runs them
/// all): no panic, exit 0/1/2, one error line, under 20 s and 4 GiB.
#[test]
fn extreme_option_values_end_in_time_with_one_line() {
    let w = Work::new();
    let points: String =
        (0..200).map(|k| format!("{},{:.6}\n", k as f64 * 0.5, (k as f64 * 0.05).sin() * 10.0)).collect();
    w.write("points.csv", format!("x,y\n{points}"));
    let options = [
        "--tol",
        "--min-radius",
        "--max-radius",
        "--max-sweep",
        "--tangent",
        "--corner",
        "--curvature-threshold",
        "--e-rate-tol",
        "--axis-tol",
        "--decimals",
    ];
    w.fuzz_options(BIN, "points.csv", &[], &options, 20, 12);
}

/// G-code is streamed run by run (issue 20): a program whose precision shows only past the lines
/// the first guess reads is written again with it, the same from a file, from standard input
/// (copied to a temporary file to be read twice) and to a file, leaving no temporary behind; a
/// run that cannot be fitted leaves no output file.
#[test]
fn streamed_program_is_the_same_from_file_stdin_and_to_a_file() {
    let w = Work::new();
    let mut text = String::from("G21 G90\nG0 X0 Y0 Z0\nG1 F600\n");
    for k in 1..=3000 {
        let t = k as f64 * 0.01;
        text += &format!("G1 X{:.3} Y{:.3}\n", 20.0 * t.cos(), 20.0 * t.sin());
    }
    text += "G1 X9000.12345 Y1\nG1 X9001.5 Y2\n";
    let path = w.write("p.nc", &text);
    let from_file = w.run(BIN, &[path.to_str().unwrap()], b"").ok();
    assert!(from_file.contains("X9000.12345"), "the whole program's 5 decimals");
    assert!(from_file.lines().count() < 100, "the arc is fitted: {} lines", from_file.lines().count());
    let from_stdin = w.run(BIN, &["-", "--from", "gcode"], text.as_bytes()).ok();
    assert_eq!(from_stdin, from_file);
    w.run(BIN, &[path.to_str().unwrap(), "-o", "out.nc"], b"").ok();
    assert_eq!(w.read("out.nc"), from_file);
    assert!(!w.files().iter().any(|f| f.contains(".camkit-")), "{:?}", w.files());
    w.run(BIN, &[path.to_str().unwrap(), "--decimals", "0", "--tol", "0.001", "-o", "bad.nc"], b"")
        .fails(2, "write more --decimals");
    assert!(!w.exists("bad.nc"));
    assert!(!w.files().iter().any(|f| f.contains(".camkit-")), "{:?}", w.files());
}

/// A table is fitted run by run as it is read; the header is known only after the fit (centre
/// columns, plane columns for arcs off XY), so the streamed writer rewrites it when its guess
/// was wrong: a half circle in XZ after a straight run comes out with `zc,plane`, centred.
#[test]
fn streamed_table_header_follows_the_arcs_written() {
    let mut input = String::from("path,x,y,z\n");
    for i in 0..=10 {
        input.push_str(&format!("0,{},0,0\n", -20.0 + i as f64));
    }
    for i in 0..=60 {
        let t = std::f64::consts::PI * i as f64 / 60.0;
        input.push_str(&format!("1,{:.9},0,{:.9}\n", 10.0 * t.cos(), 10.0 * t.sin()));
    }
    let w = Work::new();
    let out = w.run(BIN, &["-", "--plane", "auto", "--tol", "0.01"], input.as_bytes()).ok();
    let mut lines = out.lines();
    assert_eq!(lines.next(), Some("path,move,x,y,z,xc,yc,zc,plane"));
    let arcs: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect::<Vec<_>>()).filter(|f| f[1] != "line").collect();
    assert!(!arcs.is_empty());
    for f in &arcs {
        assert_eq!(f[8], "xz", "{f:?}");
        let (xc, zc): (f64, f64) = (f[5].parse().unwrap(), f[7].parse().unwrap());
        assert!(xc.abs() < 1e-6 && zc.abs() < 1e-6, "centre ({xc}, {zc})");
    }
}
