//! Issue 21's progress promise: each filter's long stages show a bar (or a spinner) on a
//! terminal, nothing in a pipe, and nothing with `--quiet`. Runs under util-linux `script`, which
//! gives the filter a terminal; skipped where `script` is absent.

use e2e::{Work, data};

/// Runs `bin` with `args` in a pipe, on a terminal, and on a terminal with `--quiet`; the
/// terminal run alone shows `stage`, and all three succeed.
fn shows_progress_on_a_terminal_only(w: &Work, bin: &str, args: &[&str], stage: &str) {
    let piped = w.run(bin, args, b"");
    piped.ok();
    assert!(!piped.stderr.contains(stage), "{bin} in a pipe: {}", piped.stderr);
    let Some(tty) = w.run_on_terminal(bin, args) else { return };
    assert_eq!(tty.status, 0, "{bin} on a terminal: {}", tty.out());
    assert!(tty.out().contains(stage), "{bin} on a terminal shows no {stage:?}: {}", tty.out());
    let quiet: Vec<&str> = args.iter().copied().chain(["--quiet"]).collect();
    let hushed = w.run_on_terminal(bin, &quiet).expect("script ran once");
    assert_eq!(hushed.status, 0, "{bin} --quiet: {}", hushed.out());
    assert!(!hushed.out().contains(stage), "{bin} --quiet on a terminal: {}", hushed.out());
}

const SQUARE: &str = "path,move,x,y,z\n1,rapid,0,0,0\n1,line,60,0,0\n1,line,60,40,0\n1,line,0,40,0\n1,line,0,0,0\n";

#[test]
fn tool_attitude_shows_its_rows() {
    let w = Work::new();
    let mut cl = String::from("x,y,z\n");
    for k in 0..2000 {
        cl.push_str(&format!("{},{},5\n", k as f64 * 0.01, (k % 7) as f64));
    }
    w.write("cl.csv", cl);
    let tool = data("tool-attitude/ball-r5.json");
    let args = ["cl.csv", "--tool", tool.to_str().unwrap(), "--axis", "0,0,1", "-o", "tip.csv"];
    shows_progress_on_a_terminal_only(&w, "tool-attitude", &args, "placing tips");
}

#[test]
fn offset_shows_its_stage() {
    let w = Work::new();
    w.write("square.csv", SQUARE);
    let args = ["square.csv", "--radius", "2", "--side", "left", "-o", "o.csv"];
    shows_progress_on_a_terminal_only(&w, "offset", &args, "offsetting and verifying");
}

#[test]
fn medial_trochoid_shows_planning_and_the_check() {
    let w = Work::new();
    w.write("square.csv", SQUARE);
    let args = ["square.csv", "--radius", "3", "-o", "m.csv"];
    shows_progress_on_a_terminal_only(&w, "medial-trochoid", &args, "planning the passes");
}

#[test]
fn curve_fit_arcs_shows_its_fit() {
    let w = Work::new();
    let g = data("gcode/cncjs_jsdc-engrave.gcode");
    let args = [g.to_str().unwrap(), "--tol", "0.025", "-o", "fit.ngc"];
    shows_progress_on_a_terminal_only(&w, "curve-fit-arcs", &args, "fitting arcs");
}

#[test]
fn rough_sim_shows_its_simulation() {
    let w = Work::new();
    let tool = data("rough-sim/ball-r5-z2.json");
    let args = ["patch", tool.to_str().unwrap(), "--pick", "0.5", "--feed-per-tooth", "0.5", "-o", "h.csv"];
    shows_progress_on_a_terminal_only(&w, "rough-sim", &args, "simulating the patch");
}
