use rough_sim::cutter::Cutter;
use rough_sim::patch::{Conditions, Grid, simulate};
fn main() {
    let args: Vec<f64> = std::env::args().skip(1).map(|a| a.parse().unwrap()).collect();
    let (fz, z, tilt, lean, step, ph) =
        (args[0], args[1] as u32, args[2], args[3], args[4], args.get(5).copied().unwrap_or(0.0));
    let cond = Conditions {
        cutter: Cutter::ball(5.0, z),
        pick: 0.5,
        feed_per_tooth: fz,
        tilt: tilt.to_radians(),
        lean,
        pass_phase: ph.to_radians(),
    };
    let grid = Grid::covering(-0.25, 0.25, 0.0, fz, step);
    let t = std::time::Instant::now();
    let map = simulate(&cond, &grid);
    let max = map.h.iter().cloned().fold(f64::MIN, f64::max);
    let min = map.h.iter().cloned().fold(f64::MAX, f64::min);
    // argmax
    let k = map.h.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).unwrap().0;
    let (i, j) = (k / grid.ny, k % grid.ny);
    println!(
        "fz {fz} Z {z} tilt {tilt} lean {lean}: max {:.3} um at x {:.4} y {:.4}, min {:.3} um, {} nodes, {:?}",
        max * 1e3,
        grid.x(i),
        grid.y(j),
        min * 1e3,
        map.h.len(),
        t.elapsed()
    );
    // column max profile
    let mut s = String::new();
    for i in (0..grid.nx).step_by((grid.nx / 25).max(1)) {
        let c = map.column(i).iter().cloned().fold(f64::MIN, f64::max);
        s += &format!("{:.3}:{:.1} ", grid.x(i), c * 1e3);
    }
    println!("{s}");
}
