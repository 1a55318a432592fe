//! End-to-end tests of the contour front door (issue 19): the same pocket as the toolpath
//! table, a DXF (ezdxf) and an SVG gives byte-identical output from every contour filter;
//! drawings written by ezdxf, FreeCAD and in Inkscape's style are read; a DXF ellipse comes back
//! within --curve-tol of the exact curve; bad drawings get one clear message and exit 2.
//! The drawings are made by scripts/contour-files.py and scripts/freecad-dxf.py.

use e2e::{Work, data};

/// The contour filters with arguments that exercise each one's main mode on the pocket.
const RUNS: [(&str, &[&str]); 5] = [
    ("offset", &["--radius", "2", "--side", "left"]),
    ("offset", &["--radius", "1.5", "--until-empty"]),
    ("curve-fit-arcs", &["--tol", "0.01"]),
    ("curve-fit-arcs", &["--to", "gcode", "--tol", "0.01"]),
    ("medial-trochoid", &["--radius", "3", "--threshold", "60"]),
];

fn file(name: &str) -> String {
    data(&format!("contours/{name}")).to_string_lossy().into_owned()
}

#[test]
fn every_contour_filter_gives_identical_output_for_table_dxf_and_svg() {
    let w = Work::new();
    for (bin, args) in RUNS {
        let run = |input: &str, stdin: &[u8], from: Option<&str>| {
            let mut a: Vec<&str> = args.to_vec();
            a.push(input);
            if let Some(f) = from {
                a.extend(["--from", f]);
            }
            w.run(bin, &a, stdin).ok()
        };
        let table = run(&file("pocket.csv"), b"", None);
        assert!(table.lines().count() > 10, "{bin} {args:?}: {table}");
        for kind in ["dxf", "svg"] {
            let path = file(&format!("pocket.{kind}"));
            assert_eq!(run(&path, b"", None), table, "{bin} {args:?} on pocket.{kind}");
            let piped = run("-", &std::fs::read(&path).unwrap(), Some(kind));
            assert_eq!(piped, table, "{bin} {args:?} on pocket.{kind} from stdin");
        }
    }
}

/// Report figures of a medial-trochoid run on `input` (with `extra` arguments).
fn regions(w: &Work, input: &str, extra: &[&str]) -> (u64, u64) {
    let mut a = vec![input, "--radius", "2", "--threshold", "60", "--sample", "2", "--report", "r.json"];
    a.extend(extra);
    w.run("medial-trochoid", &a, b"").ok();
    let r: serde_json::Value = serde_json::from_str(&w.read("r.json")).unwrap();
    (r["regions"].as_u64().unwrap(), r["islands"].as_u64().unwrap())
}

#[test]
fn drawings_from_ezdxf_freecad_and_inkscape() {
    let w = Work::new();
    // ezdxf: an old-style POLYLINE plate with bulged corners, an ELLIPSE, a closed cubic SPLINE
    // and a rational quadratic one on layer Cut.
    assert_eq!(regions(&w, &file("curves.dxf"), &["--layer", "Cut"]), (1, 3));
    // FreeCAD 0.20: LINEs, a CIRCLE, an ELLIPSE and a periodic SPLINE.
    assert_eq!(regions(&w, &file("freecad.dxf"), &[]), (1, 3));
    // Inkscape style: a translated layer with a rect, a circle and a bezier blob.
    assert_eq!(regions(&w, &file("inkscape.svg"), &[]), (1, 2));
    assert_eq!(regions(&w, &file("inkscape.svg"), &["--layer", "Pocket"]), (1, 2));
    w.run("offset", &[&file("freecad.dxf"), "--radius", "1", "--until-empty"], b"").ok();
}

/// The ELLIPSE of curves.dxf (centre (25, 30), major axis (12, 4), ratio 0.5) read at
/// --curve-tol 1e-3 and written back as pieces (curve-fit-arcs at 1e-9 merges nothing that is not
/// one line): every piece's points lie within the tolerance of the exact ellipse, and every
/// ellipse point within it of the pieces.
#[test]
fn a_dxf_ellipse_within_the_curve_tolerance() {
    let w = Work::new();
    let args = [&file("curves.dxf"), "--layer", "Cut", "--curve-tol", "0.001", "--tol", "1e-9"];
    let out = w.run("curve-fit-arcs", &args, b"").ok();
    let rows: Vec<Vec<String>> = out
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect::<Vec<String>>())
        .filter(|r| r[0] == "2")
        .collect();
    assert!(rows.len() > 8, "{} rows", rows.len());
    let p = |r: &Vec<String>| camkit::geom::P2::new(r[2].parse().unwrap(), r[3].parse().unwrap());
    let mut segs = Vec::new();
    for pair in rows.windows(2) {
        let (a, b) = (p(&pair[0]), p(&pair[1]));
        segs.push(match pair[1][1].as_str() {
            "line" => camkit::contour::Seg::Line(a, b),
            mv => {
                let c = camkit::geom::P2::new(pair[1][5].parse().unwrap(), pair[1][6].parse().unwrap());
                camkit::contour::Seg::Arc(camkit::geom::Arc2::from_centre(c, &a, &b, mv == "ccw", false))
            }
        });
    }
    let (c, u) = (camkit::geom::P2::new(25.0, 30.0), camkit::geom::V2::new(12.0, 4.0));
    let v = camkit::geom::V2::new(-u.y, u.x) * 0.5;
    let n = 200_000;
    let exact: Vec<camkit::geom::P2> = (0..=n)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / n as f64;
            c + u * t.cos() + v * t.sin()
        })
        .collect();
    // Ellipse points to the pieces: exact distances.
    let there = exact
        .iter()
        .step_by(10)
        .map(|q| segs.iter().map(|s| s.distance_to(q)).fold(f64::MAX, f64::min))
        .fold(0.0, f64::max);
    // Piece points to the ellipse's polyline of 200 000 chords (sagitta under 1e-8 mm here).
    let mut back = 0.0f64;
    for s in &segs {
        for k in 0..=20 {
            back = back.max(camkit::geom::dist::point_polyline(&s.point_at(k as f64 / 20.0), &exact));
        }
    }
    assert!(there <= 1e-3 && back <= 1e-3 + 1e-8, "ellipse to pieces {there}, pieces to ellipse {back}");
    assert!(there > 1e-6, "the ellipse is approximated, not exact: {there}");
}

#[test]
fn bad_drawings_get_one_clear_message() {
    let w = Work::new();
    for bin in ["offset", "curve-fit-arcs", "medial-trochoid"] {
        let base: &[&str] = match bin {
            "offset" => &["--radius", "1", "--side", "left"],
            "curve-fit-arcs" => &[],
            _ => &["--radius", "1"],
        };
        let run = |input: &str, stdin: &[u8]| {
            let mut a = base.to_vec();
            a.extend([input, "-o", "out.csv"]);
            let o = w.run(bin, &a, stdin);
            assert!(!w.exists("out.csv"), "{bin}: an output file after a failure");
            o
        };
        run(&file("open.dxf"), b"").fails(
            2,
            "open contour: the chain of pieces from line 2025 ends at (0.000000, 0.050000); the nearest end, its own start at (0.000000, 0.000000), is 0.05 mm away",
        );
        run(&file("no-paths.svg"), b"").fails(2, "no closed contour in the drawing: it needs a path, rect, circle");
        run(&file("curves.dxf"), b"").fails(2, "is 40 mm away");
        let dxf = std::fs::read(file("pocket.dxf")).unwrap();
        run("-", &dxf).fails(2, "stdin: this looks like a DXF drawing, not the toolpath table");
        let svg = std::fs::read(file("pocket.svg")).unwrap();
        run("-", &svg).fails(2, "this looks like an SVG drawing");
        w.write("model.stl", "solid m\nfacet normal 0 0 1\nendfacet\nendsolid m\n");
        run("model.stl", b"").fails(2, "model.stl: this looks like an STL mesh");
        let curves = file("curves.dxf");
        let mut layered = base.to_vec();
        layered.extend([curves.as_str(), "--layer", "Nope"]);
        w.run(bin, &layered, b"")
            .fails(2, "no closed contour in the drawing on the layers Nope (the drawing's: Cut, Notes)");
    }
}
