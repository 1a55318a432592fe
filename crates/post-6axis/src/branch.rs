//! Choosing one inverse-kinematics solution per CL row over the whole program: dynamic programming
//! over the branches (and, where a pass starts, the turns of limited axes), so that a pass is
//! refused only when no continuous sequence of solutions within the axis limits exists.

use crate::plan::{Cl, Machine, Options, PlanError, angle_between};
use camkit::geom::V3;
use camkit::io::spool::{Put, Take};
use camkit::io::{Get, Record, RecordSpool};
use camkit::kinematics::{Choice, Orientations, principal_deg};

/// Largest axis error of a pose whose primary angle is held inside the singular cone, as a share
/// of the planning angle tolerance: beyond it the exact solutions are taken instead, so that the
/// blocks between poses keep the rest of the tolerance.
pub const HOLD_SHARE: f64 = 0.5;

/// Largest distance (degrees) at which two poses count as one state of the search.
const SAME_POSE_DEG: f64 = 1e-9;

/// Cost added to a pose whose secondary angle is negative: ties go to paper 002 eq. 3's branch.
const TIE_BREAK: f64 = 1e-9;

/// A pose reachable at a row from the previous pose, and what getting there costs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Next {
    /// The pose.
    pub choice: Choice,
    /// Total rotary move (degrees) from the previous pose.
    pub cost: f64,
    /// Wrapping axes unwound at this row.
    pub unwinds: usize,
}

/// The poses chosen for every row.
#[derive(Debug)]
pub struct Chosen {
    /// One pose per row.
    pub choices: Choices,
    /// Total rotary move (degrees, with tie-breaks) of the sequence.
    pub cost: f64,
    /// Wrapping axes unwound at pass starts.
    pub unwinds: usize,
}

/// The rotary angles a program starts from: every axis at its home.
pub fn home(m: &Machine) -> [f64; 2] {
    let mut h = [0.0; 2];
    for (k, r) in m.solver.chain.rotaries().iter().enumerate() {
        h[k] = r.home;
    }
    h
}

/// The inverse solutions for a row's axis, or why there are none.
pub fn orientations(m: &Machine, row: &Cl, i: usize) -> Result<Orientations, PlanError> {
    let unreachable = |message| PlanError { row: i, message, unreachable: true };
    match m.solver.chain.orientations(&row.axis) {
        Some(o) => Ok(o),
        None => Err(unreachable(match m.solver.choose(&row.axis, &home(m)) {
            Err(e) => e.0,
            Ok(_) => "no rotary angles of this machine turn the tool onto this axis".into(),
        })),
    }
}

/// The tool axis at rotary angles `rot`.
fn axis_at(m: &Machine, rot: &[f64; 2]) -> V3 {
    m.solver.chain.orientation(rot).column(2).into_owned()
}

/// Angle (radians) between the tool axis at `c` and `axis`.
fn pose_error(m: &Machine, c: &Choice, axis: &V3) -> f64 {
    angle_between(&axis_at(m, &c.rot), axis)
}

/// The move of each axis from `a` to `b`: wrapping axes the shorter way.
fn rotary_move(m: &Machine, a: &[f64; 2], b: &[f64; 2]) -> [f64; 2] {
    let mut d = [0.0; 2];
    for (k, r) in m.solver.chain.rotaries().iter().enumerate() {
        d[k] = if r.wrap { principal_deg(b[k] - a[k]) } else { b[k] - a[k] };
    }
    d
}

/// The pose with the primary angle held at `primary` inside the singular cone, if its axis error
/// is within [`HOLD_SHARE`] of the angle tolerance; otherwise why not.
pub fn held(m: &Machine, opts: &Options, axis: &V3, primary: f64, prev: &[f64; 2]) -> Result<Choice, String> {
    let c = m.solver.hold(axis, primary, prev).map_err(|e| e.0)?;
    let e = pose_error(m, &c, axis);
    if e > HOLD_SHARE * opts.angle_tol {
        let r = &m.solver.chain.rotaries()[0];
        return Err(format!(
            "{} held at {primary:.4}° leaves the tool {:.4}° off its axis (more than {:.4}°)",
            r.address,
            e.to_degrees(),
            (HOLD_SHARE * opts.angle_tol).to_degrees()
        ));
    }
    Ok(c)
}

/// Every value of rotary `k` equivalent to `angle` (modulo 360°) inside its limits, nearest to
/// `prev` first; a wrapping axis has the one its policy turns to.
fn equivalents(m: &Machine, k: usize, angle: f64, prev: f64) -> Vec<f64> {
    let r = &m.solver.chain.rotaries()[k];
    if r.wrap {
        return m.solver.unwind(k, angle, prev).into_iter().collect();
    }
    let near = prev + principal_deg(angle - prev);
    let mut out: Vec<f64> = (-2..=2).map(|t| near + 360.0 * t as f64).filter(|a| r.admits(*a)).collect();
    out.sort_by(|a, b| (a - prev).abs().total_cmp(&(b - prev).abs()));
    out
}

/// Why rotary `k` cannot take `angle`.
fn beyond(m: &Machine, k: usize, angle: f64) -> String {
    let r = &m.solver.chain.rotaries()[k];
    let (lo, hi) = r.limits.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
    format!("{} would be {angle:.4}° (limits {lo}..{hi})", r.address)
}

/// Every pose of row `row` (inverse solutions `o`) reachable from the pose `prev`, and the
/// reasons the others are not. Inside the singular cone: the primary angle held, if that keeps
/// the axis within tolerance. Where a pass starts: each branch at every turn of the limited axes
/// inside their limits. Within a pass: the branch nearest `prev`, each axis turned the shorter way
/// (wrapping axes by the policy), as the controller's interpolation continues it; the other branch
/// would swing the axes in mid-cut. Wrapping axes are unwound where the row allows re-orientation.
/// The reasons are written only if `explain` (they would cost a message per row).
pub fn successors(
    m: &Machine,
    opts: &Options,
    row: &Cl,
    o: &Orientations,
    prev: &[f64; 2],
    explain: bool,
) -> (Vec<Next>, Vec<String>) {
    let chain = m.solver.chain;
    let n = chain.rotaries().len();
    let mut out = Vec::new();
    let mut why = Vec::new();
    let cost = |rot: &[f64; 2]| {
        (0..n).map(|k| (rot[k] - prev[k]).abs()).sum::<f64>() + if n == 2 && rot[1] < 0.0 { TIE_BREAK } else { 0.0 }
    };
    if n == 2 && o.count == 2 && o.off_primary < m.solver.cone {
        match held(m, opts, &row.axis, prev[0], prev) {
            Ok(choice) => out.push(Next { choice, cost: cost(&choice.rot), unwinds: 0 }),
            Err(e) => why.push(e),
        }
    }
    let branches = &o.branch[..o.count];
    let mut values: Vec<(usize, [f64; 2])> = Vec::new();
    if row.rapid {
        for (b, rot) in branches.iter().enumerate() {
            let mut combos: Vec<[f64; 2]> = vec![[0.0; 2]];
            for k in 0..n {
                let eq = equivalents(m, k, rot[k], prev[k]);
                if eq.is_empty() && explain {
                    why.push(beyond(m, k, rot[k]));
                }
                combos = combos
                    .iter()
                    .flat_map(|v| {
                        eq.iter().map(move |&a| {
                            let mut w = *v;
                            w[k] = a;
                            w
                        })
                    })
                    .collect();
            }
            values.extend(combos.into_iter().map(|v| (b, v)));
        }
    } else {
        // The continuation: each branch turned the shorter way, the cheaper one taken.
        let turned: Vec<[f64; 2]> = branches
            .iter()
            .map(|rot| {
                let mut v = [0.0; 2];
                for k in 0..n {
                    v[k] = if chain.rotaries()[k].wrap {
                        m.solver.unwind(k, rot[k], prev[k]).unwrap_or(rot[k])
                    } else {
                        prev[k] + principal_deg(rot[k] - prev[k])
                    };
                }
                v
            })
            .collect();
        let best = (0..turned.len()).min_by(|&a, &b| cost(&turned[a]).total_cmp(&cost(&turned[b]))).unwrap_or(0);
        let v = turned[best];
        match (0..n).find(|&k| !chain.rotaries()[k].admits(v[k])) {
            Some(k) if explain => why.push(beyond(m, k, v[k])),
            Some(_) => {}
            None => values.push((best, v)),
        }
        for w in turned.iter().enumerate().filter(|&(b, _)| explain && b != best).map(|(_, w)| w) {
            let names: Vec<String> =
                chain.rotaries().iter().enumerate().map(|(k, r)| format!("{} {:.4}°", r.address, w[k])).collect();
            why.push(format!(
                "the other branch ({}) would swing the rotary axes {:.1}° in mid-pass",
                names.join(", "),
                cost(w)
            ));
        }
    }
    for (b, mut v) in values {
        let mut unwinds = 0;
        if row.reorient {
            for (k, r) in chain.rotaries().iter().enumerate() {
                if r.wrap && v[k].abs() >= 360.0 {
                    v[k] = principal_deg(v[k]);
                    unwinds += 1;
                }
            }
        }
        out.push(Next { choice: Choice { rot: v, branch: b, singular: false }, cost: cost(&v), unwinds });
    }
    (out, why)
}

/// True if two poses are one state: every future pose and cost from them is the same (wrapping
/// axes compared modulo 360°).
fn same_state(m: &Machine, a: &[f64; 2], b: &[f64; 2]) -> bool {
    rotary_move(m, a, b).iter().all(|d| d.abs() <= SAME_POSE_DEG)
}

/// One state of the search at a row.
#[derive(Clone, Copy, Debug)]
struct Node {
    choice: Choice,
    cost: f64,
    parent: usize,
    unwinds: usize,
}

fn put_choice(c: &Choice, out: &mut Put) {
    out.f64(c.rot[0]).f64(c.rot[1]).u8(c.branch as u8).u8(u8::from(c.singular));
}

fn take_choice(bytes: &mut Take) -> Choice {
    Choice { rot: [bytes.f64(), bytes.f64()], branch: usize::from(bytes.u8()), singular: bytes.u8() != 0 }
}

impl Record for Node {
    const SIZE: usize = 18 + 24;
    fn put(&self, out: &mut Put) {
        put_choice(&self.choice, out);
        out.f64(self.cost).u64(self.parent as u64).u64(self.unwinds as u64);
    }
    fn take(bytes: &mut Take) -> Self {
        let choice = take_choice(bytes);
        let (cost, parent, unwinds) = (bytes.f64(), bytes.u64(), bytes.u64());
        Node { choice, cost, parent: usize::try_from(parent).unwrap_or(usize::MAX), unwinds: unwinds as usize }
    }
}

/// A chosen pose as a record.
#[derive(Clone, Copy, Debug)]
struct Picked(Choice);

impl Record for Picked {
    const SIZE: usize = 18;
    fn put(&self, out: &mut Put) {
        put_choice(&self.0, out);
    }
    fn take(bytes: &mut Take) -> Self {
        Picked(take_choice(bytes))
    }
}

/// One pose per row, by row index, kept on disk beyond a page (the search finds them from the
/// last row back, and keeps them in that order).
#[derive(Debug, Default)]
pub struct Choices {
    back: RecordSpool<Picked>,
}

impl Choices {
    /// Rows.
    pub fn len(&self) -> usize {
        self.back.len()
    }

    /// True if there are none.
    pub fn is_empty(&self) -> bool {
        self.back.is_empty()
    }

    /// The pose of row `i`.
    pub fn get(&mut self, i: usize) -> Choice {
        let n = self.back.len();
        self.back.get(n - 1 - i).0
    }

    /// Replaces the pose of row `i`.
    pub fn set(&mut self, i: usize, c: &Choice) {
        let n = self.back.len();
        self.back.set(n - 1 - i, &Picked(*c));
    }
}

/// The sequence of poses, one per row, with the least total rotary move among those that stay
/// within the limits, move continuously within each pass and hold the axis within tolerance in
/// the singular cone. Refused (the first row no sequence reaches, and why) only when none exists.
pub fn choose<R: Get<Cl> + ?Sized>(rows: &R, m: &Machine, opts: &Options) -> Result<Chosen, PlanError> {
    let start = Choice { rot: home(m), branch: 0, singular: false };
    // Every state of every row, on disk beyond a page; the states of the row at hand in memory.
    let mut nodes: RecordSpool<Node> = RecordSpool::new();
    let mut layer: Vec<(usize, Node)> = Vec::new();
    for i in 0..rows.len() {
        let row = rows.get(i);
        let o = orientations(m, &row, i)?;
        let mut next: Vec<Node> = Vec::new();
        let prevs: Vec<(usize, Choice, f64)> = if i == 0 {
            vec![(usize::MAX, start, 0.0)]
        } else {
            layer.iter().map(|(p, n)| (*p, n.choice, n.cost)).collect()
        };
        for &(parent, pc, pcost) in &prevs {
            for s in successors(m, opts, &row, &o, &pc.rot, false).0 {
                let cost = pcost + s.cost;
                let node = Node { choice: s.choice, cost, parent, unwinds: s.unwinds };
                match next.iter_mut().find(|n| same_state(m, &n.choice.rot, &s.choice.rot)) {
                    Some(n) if cost < n.cost => *n = node,
                    Some(_) => {}
                    None => next.push(node),
                }
            }
        }
        if next.is_empty() {
            let mut why: Vec<String> =
                prevs.iter().flat_map(|(_, pc, _)| successors(m, opts, &row, &o, &pc.rot, true).1).collect();
            why.sort();
            why.dedup();
            return Err(PlanError {
                row: i,
                message: format!(
                    "no solution within the axis limits that the pass reaches continuously: {}",
                    why.join(" or ")
                ),
                unreachable: true,
            });
        }
        let base = nodes.len();
        layer = next.iter().enumerate().map(|(k, n)| (base + k, *n)).collect();
        for n in &next {
            nodes.push(n);
        }
    }
    let Some(&(best, Node { cost, .. })) = layer.iter().min_by(|a, b| a.1.cost.total_cmp(&b.1.cost)) else {
        return Ok(Chosen { choices: Choices::default(), cost: 0.0, unwinds: 0 });
    };
    let mut back = RecordSpool::new();
    let mut unwinds = 0;
    let mut at = best;
    while at != usize::MAX {
        let node = nodes.get(at);
        back.push(&Picked(node.choice));
        unwinds += node.unwinds;
        at = node.parent;
    }
    Ok(Chosen { choices: Choices { back }, cost, unwinds })
}

#[cfg(test)]
mod tests {
    use super::*;
    use camkit::doc::machine::Machine as MachineDoc;
    use camkit::geom::P3;
    use camkit::kinematics::Chain;
    use proptest::prelude::*;

    fn machine(name: &str) -> (MachineDoc, Chain) {
        let path = format!("{}/../../data/post-6axis/{name}", env!("CARGO_MANIFEST_DIR"));
        MachineDoc::read(&path).expect("machine document")
    }

    /// The least total cost over every sequence of successors, by exhaustive search.
    fn brute_force(rows: &[Cl], m: &Machine, opts: &Options, i: usize, prev: &[f64; 2]) -> Option<f64> {
        if i == rows.len() {
            return Some(0.0);
        }
        let o = orientations(m, &rows[i], i).ok()?;
        let (succ, _) = successors(m, opts, &rows[i], &o, prev, false);
        succ.iter()
            .filter_map(|s| brute_force(rows, m, opts, i + 1, &s.choice.rot).map(|c| c + s.cost))
            .min_by(f64::total_cmp)
    }

    fn row(tilt: f64, azimuth: f64, k: usize, rapid: bool) -> Cl {
        let (t, a) = (tilt.to_radians(), azimuth.to_radians());
        Cl {
            tip: P3::new(k as f64, 0.0, 5.0),
            axis: V3::new(t.sin() * a.cos(), t.sin() * a.sin(), t.cos()),
            s: None,
            feed: Some(500.0),
            rapid,
            reorient: rapid,
            line: k as u64 + 2,
            arc: None,
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

        /// On short random passes (axes anywhere on the upper hemisphere and past it, near the
        /// primary axis too), the search finds a sequence exactly when one exists, and the least
        /// costly one, as enumerating every sequence of branches finds.
        #[test]
        fn search_agrees_with_enumerating_every_branch_sequence(
            which in 0usize..3,
            steps in proptest::collection::vec((-130.0f64..130.0, -40.0f64..40.0, 0u8..8), 2..7),
            start in (-130.0f64..130.0, -180.0f64..180.0),
        ) {
            let names = ["paper002-ac.json", "head-bc.json", "head-table-cb.json"];
            let (doc, chain) = machine(names[which]);
            let m = crate::planning(&doc, &chain);
            let opts = Options::default();
            let (mut tilt, mut az) = start;
            let mut rows = vec![row(tilt, az, 0, true)];
            for (k, (dt, da, kind)) in steps.iter().enumerate() {
                // Mostly small steps; now and then a step onto the primary axis or a new pass.
                tilt = if *kind == 0 { 0.2 } else { (tilt + dt * 0.25).clamp(-130.0, 130.0) };
                az += da;
                rows.push(row(tilt, az, k + 1, *kind == 7));
            }
            let exhaustive = brute_force(&rows, &m, &opts, 0, &home(&m));
            match (choose(&rows, &m, &opts), exhaustive) {
                (Ok(mut c), Some(best)) => {
                    let choices: Vec<Choice> = (0..c.choices.len()).map(|i| c.choices.get(i)).collect();
                    prop_assert!((c.cost - best).abs() <= 1e-6 * (1.0 + best), "search {} exhaustive {best}", c.cost);
                    // The sequence is one the rules allow, and costs what the search says.
                    let mut prev = home(&m);
                    let mut total = 0.0;
                    for (i, (r, choice)) in rows.iter().zip(&choices).enumerate() {
                        let o = orientations(&m, r, i).unwrap();
                        let (succ, _) = successors(&m, &opts, r, &o, &prev, false);
                        let s = succ.iter().find(|s| same_state(&m, &s.choice.rot, &choice.rot));
                        prop_assert!(s.is_some(), "row {i}: {choice:?} is not a successor of {prev:?}");
                        total += s.unwrap().cost;
                        prev = choice.rot;
                    }
                    prop_assert!((total - c.cost).abs() <= 1e-6 * (1.0 + total));
                }
                (Err(_), None) => {}
                (got, want) => prop_assert!(false, "search {got:?}, exhaustive {want:?}"),
            }
        }
    }

    /// Over passes of thousands of rows (the search's states and the poses on disk, many pages
    /// of them), every pose chosen is a successor of the one before and the costs add up to the
    /// search's total.
    #[test]
    fn long_programs_choose_a_sequence_of_successors() {
        let (doc, chain) = machine("paper002-ac.json");
        let m = crate::planning(&doc, &chain);
        let opts = Options::default();
        let rows: Vec<Cl> =
            (0..6000).map(|k| row(25.0 + 15.0 * (k as f64 * 0.003).sin(), 0.05 * k as f64, k, k % 1500 == 0)).collect();
        let mut c = choose(&rows, &m, &opts).expect("reachable");
        assert_eq!(c.choices.len(), rows.len());
        let mut prev = home(&m);
        let mut total = 0.0;
        for (i, r) in rows.iter().enumerate() {
            let choice = c.choices.get(i);
            let o = orientations(&m, r, i).unwrap();
            let (succ, _) = successors(&m, &opts, r, &o, &prev, false);
            let s = succ.iter().find(|s| same_state(&m, &s.choice.rot, &choice.rot));
            assert!(s.is_some(), "row {i}: {choice:?} is not a successor of {prev:?}");
            total += s.unwrap().cost;
            prev = choice.rot;
        }
        assert!((total - c.cost).abs() <= 1e-6 * (1.0 + total), "{total} {}", c.cost);
    }

    /// The sweep of paper 002's A/C machine from 25° one way to 110° the other in the XZ plane: the
    /// greedy choice from home (C −90°) runs A into its −30° limit; the search takes C 90° for the
    /// whole pass.
    #[test]
    fn sweep_through_the_primary_axis_keeps_one_branch() {
        let (doc, chain) = machine("paper002-ac.json");
        let m = crate::planning(&doc, &chain);
        let rows: Vec<Cl> = (0..28).map(|k| row(-25.0 + 5.0 * k as f64, 0.0, k, k == 0)).collect();
        let mut c = choose(&rows, &m, &Options::default()).expect("one branch covers the pass");
        let choices: Vec<Choice> = (0..c.choices.len()).map(|i| c.choices.get(i)).collect();
        assert!(choices.iter().all(|c| c.singular || (c.rot[0] - 90.0).abs() < 1e-9), "{choices:?}");
        let a: Vec<f64> = choices.iter().map(|c| c.rot[1]).collect();
        assert!((a[0] + 25.0).abs() < 1e-9 && (a[27] - 110.0).abs() < 1e-9, "{a:?}");
        // Past A's 120° limit on both branches: refused at that row, naming the limit.
        let mut far = rows.clone();
        far.push(row(125.0, 0.0, 28, false));
        let e = choose(&far, &m, &Options::default()).unwrap_err();
        assert_eq!(e.row, 28);
        assert!(e.message.contains("A would be") && e.message.contains("limits -30..120"), "{}", e.message);
    }
}
