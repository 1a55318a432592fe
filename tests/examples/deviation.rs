//! Measures how far a compressed G-code program strays from its original, with the tests'
//! independent instrument (dense sampling, exact segment distances): the same ruler for our
//! output and a peer's. Prints `moves_original moves_compressed deviation_mm`.
//!
//! `cargo run --release -p e2e --example deviation -- ORIGINAL COMPRESSED TOL`

use camkit::gcode::{Block, Motion};

/// Feed moves (G1, G2, G3) of a program; rapids are not counted (as in ArcWelder's figures).
fn feed_moves(text: &str) -> usize {
    let p = camkit::gcode::read("program", text.to_string()).expect("program parses");
    p.blocks.iter().filter(|b| matches!(b, Block::Move(m) if m.motion != Motion::Rapid)).count()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, original, compressed, tol] = args.as_slice() else {
        eprintln!("usage: deviation ORIGINAL COMPRESSED TOL");
        std::process::exit(2);
    };
    let tol: f64 = tol.parse().expect("TOL is a number");
    let a = std::fs::read_to_string(original).expect("read ORIGINAL");
    let b = std::fs::read_to_string(compressed).expect("read COMPRESSED");
    let pa = e2e::paths::program_path(original, &a, tol * 1e-3);
    let pb = e2e::paths::program_path(compressed, &b, tol * 1e-3);
    // Distances up to 4·tol are exact; beyond, the instrument says "more than 4·tol".
    let d = e2e::paths::hausdorff(&pa, &pb, tol / 20.0, 8.0 * tol);
    println!("{} {} {}", feed_moves(&a), feed_moves(&b), d);
}
