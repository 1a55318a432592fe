//! End-to-end tests of the plots (`--svg`) of every kind: each SVG is read back
//! (`camkit::svg::inspect`, which also checks that its tags balance) and its legend must list
//! exactly the drawn series, its colour bars span exactly the data written beside it (the CSV,
//! the report), and demo-sized inputs stay well under 1 MB.

use camkit::svg::inspect::{Seen, inspect};
use camkit::svg::relief;
use e2e::{Work, data};
use std::collections::BTreeSet;

/// Largest demo plot (bytes).
const MAX_SVG: usize = 1_000_000;

/// The plot `name` in `w`, read back: well formed, under [`MAX_SVG`], the legend's entries
/// exactly the drawn series.
fn plot(w: &Work, name: &str) -> Seen {
    let svg = w.read(name);
    assert!(svg.len() < MAX_SVG, "{name}: {} bytes", svg.len());
    let seen = inspect(&svg).unwrap_or_else(|e| panic!("{name}: {e}"));
    let legend: BTreeSet<String> = seen.legend.iter().cloned().collect();
    assert_eq!(legend, seen.drawn, "{name}: legend against drawn series");
    seen
}

/// The finite values of column `col` of a CSV file in `w`, and their range.
fn column_range(w: &Work, file: &str, col: &str) -> (f64, f64) {
    let text = w.read(file);
    let mut lines = text.lines();
    let at = lines.next().unwrap().split(',').position(|c| c == col).unwrap_or_else(|| panic!("{file}: no {col}"));
    lines
        .filter_map(|l| l.split(',').nth(at).and_then(|v| v.parse::<f64>().ok()))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, v| (a.0.min(v), a.1.max(v)))
}

/// Every colour bar of `seen` spans `range` to `tol`, with `label`.
fn bars_span(seen: &Seen, range: (f64, f64), tol: f64, label: &str) {
    assert!(!seen.bars.is_empty() && seen.coloured > 0, "a colour bar and coloured marks");
    for (lo, hi, l) in &seen.bars {
        assert!((lo - range.0).abs() <= tol && (hi - range.1).abs() <= tol, "bar {l}: {lo}..{hi}, data {range:?}");
        assert_eq!(l, label);
    }
}

#[test]
fn stylus_trace_draws_3d_views_coloured_by_the_written_z() {
    let w = Work::new();
    let model = data("stylus-trace/sphere-smoothing.json");
    w.run(
        "stylus-trace",
        &[
            model.to_str().unwrap(),
            "--mode",
            "scan",
            "-r",
            "12.5",
            "--pick",
            "2",
            "--region=-20,20,-20,20",
            "--svg",
            "cl.svg",
            "-o",
            "cl.csv",
        ],
        b"",
    )
    .ok();
    let seen = plot(&w, "cl.svg");
    assert_eq!(seen.bars.len(), 4, "isometric, top and two side views");
    bars_span(&seen, column_range(&w, "cl.csv", "z"), 0.0, "stylus centre z (mm)");
    assert!(seen.legend.is_empty(), "the model's grid is not in the legend: {:?}", seen.legend);
    assert_eq!(grid_lines(&w, "cl.svg"), 4 * 2 * relief::MAX_NODES, "the sphere's grid in every panel");
}

/// The model's grid lines ([`relief`]) drawn in the plot `name` of `w`.
fn grid_lines(w: &Work, name: &str) -> usize {
    w.read(name).matches(&format!("stroke=\"{}\"", relief::style().stroke)).count()
}

#[test]
fn rough_sim_maps_are_in_mm_on_a_bar_spanning_every_node() {
    let w = Work::new();
    let tool = data("rough-sim/ball-r5-z2.json");
    let base = ["patch", tool.to_str().unwrap(), "--pick", "0.5", "--feed-per-tooth", "0.5", "--step", "0.005"];
    w.run("rough-sim", &[&base[..], &["--svg", "h.svg", "-o", "h.csv"]].concat(), b"").ok();
    let seen = plot(&w, "h.svg");
    let range = column_range(&w, "h.csv", "h");
    assert!(range.1 > 0.02 && range.1 < 0.03, "the 25 µm remainder, in mm: {range:?}");
    // The CSV's heights have 7 decimals.
    bars_span(&seen, range, 5e-8, "h: height above the nominal surface (mm)");
    assert!(w.read("h.svg").contains(" µm across the feed"), "roughness in µm in the title");
    // The flat tip's map is flat: one value, no legend of swatches.
    w.run("rough-sim", &[&base[..], &["--flat-radius", "0.5", "--svg", "f.svg", "-o", "f.csv"]].concat(), b"").ok();
    let seen = plot(&w, "f.svg");
    let range = column_range(&w, "f.csv", "h");
    bars_span(&seen, range, 5e-8, "h: height above the nominal surface (mm)");
    assert_eq!(seen.bars[0].0, seen.bars[0].1);
    assert!(seen.legend.is_empty());
    // A z-map of a raster program, in absolute z.
    let mut csv = String::from("path,move,x,y,z,f\n");
    for p in 0..3 {
        let x = -0.5 + 0.5 * p as f64;
        csv.push_str(&format!("{p},line,{x},-3,2,1000\n{p},line,{x},3,2,1000\n"));
    }
    w.write("raster.csv", csv);
    let args = ["zmap", "raster.csv", "--tool", tool.to_str().unwrap(), "--spindle", "1000", "--step", "0.01"];
    w.run("rough-sim", &[&args[..], &["--area=-0.5,-0.5,0.5,0.5", "--svg", "z.svg", "-o", "z.csv"]].concat(), b"").ok();
    let seen = plot(&w, "z.svg");
    let range = column_range(&w, "z.csv", "z");
    assert!(range.0 >= 2.0 && range.1 < 2.03, "absolute z: {range:?}");
    bars_span(&seen, range, 5e-8, "z (mm)");
}

#[test]
fn medial_trochoid_colours_engagement_in_degrees_up_to_the_largest_cutting_value() {
    let w = Work::new();
    let pocket = data("medial-trochoid/box-die.csv");
    let setup = data("jobs/box-die.json");
    w.run(
        "medial-trochoid",
        &[
            pocket.to_str().unwrap(),
            "--setup",
            setup.to_str().unwrap(),
            "--threshold",
            "40",
            "--layer-depth",
            "10",
            "--trochoid-radius",
            "2.5",
            "--svg",
            "t.svg",
            "--svg-other",
            "o.svg",
            "--report",
            "r.json",
            "-o",
            "p.csv",
        ],
        b"",
    )
    .ok();
    let r: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
    let f = |k: &str| r[k].as_f64().unwrap();
    let label = "path: engagement (°); entries above the top in its colour";
    // The report measures the written program (its numbers rounded to --decimals), the plot the
    // plan: they agree to 1e-5°.
    let seen = plot(&w, "t.svg");
    bars_span(&seen, (0.0, f("largest_engagement_deg").max(f("link_engagement_deg"))), 1e-5, label);
    assert!(seen.drawn.contains("contour") && seen.drawn.contains("medial axis"));
    let seen = plot(&w, "o.svg");
    bars_span(
        &seen,
        (0.0, f("offset_only_largest_engagement_deg").max(f("offset_only_link_engagement_deg"))),
        1e-5,
        label,
    );
}

#[test]
fn post_6axis_plots_the_program_with_rapids_feeds_and_arcs() {
    let w = Work::new();
    w.write(
        "cl.csv",
        "path,move,x,y,z,xc,yc,f\n0,rapid,0,0,5,,,\n0,line,0,0,-1,,,300\n0,line,10,0,-1,,,600\n\
         0,ccw,20,0,-1,15,0,600\n0,line,20,10,-1,,,600\n1,rapid,30,10,5,,,\n1,line,30,10,-1,,,300\n1,line,40,10,-1,,,600\n",
    );
    let machine = data("post-6axis/three-axis.json");
    w.run("post-6axis", &["cl.csv", "--machine", machine.to_str().unwrap(), "--svg", "p.svg", "-o", "p.nc"], b"").ok();
    let seen = plot(&w, "p.svg");
    for s in ["rapid (G0)", "plunge or ramp", "cut"] {
        assert!(seen.drawn.contains(s), "{s} in {:?}", seen.drawn);
    }
    assert!(seen.bars.is_empty(), "nothing coloured by value: no colour bar");
    // The half circle (G17) is an SVG arc in the top view (two commands under 180° each), and
    // its sampled tip path in the side views.
    let svg = w.read("p.svg");
    let panels: Vec<&str> = svg.split("<g transform=").skip(1).collect();
    let arcs = |s: &str| s.matches('A').count();
    assert!((1..=2).contains(&arcs(panels[0])), "{}", panels[0]);
    assert_eq!(arcs(panels[1]) + arcs(panels[2]), 0);
    // --reverse plots a program it reads.
    w.run(
        "post-6axis",
        &["p.nc", "--machine", machine.to_str().unwrap(), "--reverse", "--svg", "r.svg", "-o", "r.csv"],
        b"",
    )
    .ok();
    assert_eq!(plot(&w, "r.svg").drawn, seen.drawn);
}

#[test]
fn curve_fit_arcs_draws_a_print_in_3d_with_travel_apart() {
    let w = Work::new();
    let vase = data("gcode/gcode-preview_vase_prusaslicer274.gcode");
    w.run("curve-fit-arcs", &[vase.to_str().unwrap(), "--svg", "v.svg", "-o", "v.gcode"], b"").ok();
    let seen = plot(&w, "v.svg");
    assert!(seen.drawn.contains("travel (no extrusion)"), "{:?}", seen.drawn);
    // The bar spans the heights of the print's extruding blocks (Z is modal), from the first
    // layer change on: the start code's two prime lines are single blocks, not fitted runs, and
    // are not drawn.
    let (mut z, mut lo, mut hi) = (0.0f64, f64::INFINITY, f64::NEG_INFINITY);
    let text = w.read("v.gcode");
    for line in text[text.find(";LAYER_CHANGE").unwrap()..].lines() {
        let words: Vec<&str> = line.split(';').next().unwrap().split_whitespace().collect();
        let word = |c: char| words.iter().find(|w| w.starts_with(c)).and_then(|w| w[1..].parse::<f64>().ok());
        if let Some(v) = word('Z') {
            z = v;
        }
        if matches!(words.first(), Some(&("G1" | "G2" | "G3")))
            && word('E').is_some_and(|e| e > 0.0)
            && word('X').is_some()
        {
            (lo, hi) = (lo.min(z), hi.max(z));
        }
    }
    bars_span(&seen, (lo, hi), 0.0, "extrusion: height z (mm)");
}

#[test]
fn offset_profile_plot_is_small_and_its_legend_is_what_is_drawn() {
    let w = Work::new();
    let mut csv = String::from("path,move,x,y,z\n");
    for i in 0..=628 {
        let x = i as f64 * 0.1;
        csv.push_str(&format!("0,line,{x},0,{}\n", 10.0 * (x / 10.0).sin()));
    }
    w.write("profile.csv", csv);
    w.run(
        "offset",
        &["profile.csv", "--profile", "square", "--up", "z", "--radius", "1.5", "--svg", "s.svg", "-o", "s.csv"],
        b"",
    )
    .ok();
    let seen = plot(&w, "s.svg");
    assert!(w.read("s.svg").len() < 200_000);
    assert!(seen.drawn.contains("profile") && seen.drawn.contains("tip path, offset (never cuts into the profile)"));
}

#[test]
fn tool_attitude_colours_the_tip_paths_by_the_written_axis_tilt() {
    let w = Work::new();
    let model = data("stylus-trace/sphere-smoothing.json");
    let tool = data("tool-attitude/cylinder-phi25.json");
    w.run(
        "stylus-trace",
        &[
            model.to_str().unwrap(),
            "--mode",
            "scan",
            "-r",
            "12.5",
            "--pick",
            "4",
            "--region=-20,20,-20,20",
            "-o",
            "cl.csv",
        ],
        b"",
    )
    .ok();
    w.run(
        "tool-attitude",
        &[
            "cl.csv",
            "--tool",
            tool.to_str().unwrap(),
            "--tilt",
            "-5",
            "--model",
            model.to_str().unwrap(),
            "--svg",
            "t.svg",
            "-o",
            "t.csv",
        ],
        b"",
    )
    .ok();
    let seen = plot(&w, "t.svg");
    let text = w.read("t.csv");
    let mut lines = text.lines();
    let k = lines.next().unwrap().split(',').position(|c| c == "k").unwrap();
    let tilts =
        lines.map(|l| l.split(',').nth(k).unwrap().parse::<f64>().unwrap().clamp(-1.0, 1.0).acos().to_degrees());
    let range = tilts.fold((f64::INFINITY, f64::NEG_INFINITY), |a, v| (a.0.min(v), a.1.max(v)));
    assert!(range.0 > 0.0 && range.1 > 5.0, "tilted 5° toward the feed: {range:?}");
    // The CSV's k is the shortest exact text of the same number: the same angle.
    bars_span(&seen, range, 1e-9, "tool tip: axis tilt from +z (°)");
    assert_eq!(seen.drawn.len(), 1, "the tool axis strokes: {:?}", seen.drawn);
    assert_eq!(grid_lines(&w, "t.svg"), 4 * 2 * relief::MAX_NODES, "the sphere's grid in every panel");
}
