//! Forward ∘ inverse = identity for every family and both branches; paper 002's eq. 3–4 in closed
//! form; the spindle orientation round trip; pose choice inside limits and near the singularity.

use super::*;
use proptest::prelude::*;

fn rotary(address: char, dir: V3, sense: f64) -> Rotary {
    Rotary { address, dir, sense, limits: None, wrap: false, home: 0.0, on_table: false }
}

/// Paper 002's A/C table machine with all four offsets non-zero (eq. 2), both table axes turning
/// the workpiece the positive way (so eq. 3–4 hold as printed).
pub(crate) fn paper_ac() -> Chain {
    let (xc, yc, za, yac) = (12.5, -7.25, 85.0, 3.125);
    Chain::new(
        vec![Link::Rotary(0), Link::Offset(V3::new(0.0, yac, 0.0)), Link::Rotary(1), Link::Linear],
        vec![rotary('C', V3::z(), -1.0), rotary('A', V3::x(), -1.0)],
    )
    .unwrap()
    .with_frame(V3::new(xc, yc, za))
}

/// One machine of every family (and a nutating head whose axes are not orthogonal).
fn machines() -> Vec<(&'static str, Chain)> {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    vec![
        ("three-axis", Chain::new(vec![Link::Linear], vec![]).unwrap().with_frame(V3::new(1.0, 2.0, 3.0))),
        (
            "four-axis A",
            Chain::new(
                vec![Link::Rotary(0), Link::Offset(V3::new(0.0, 0.0, 20.0)), Link::Linear],
                vec![rotary('A', V3::x(), 1.0)],
            )
            .unwrap(),
        ),
        ("table-table A/C (paper 002)", paper_ac()),
        (
            "table-table B/C",
            Chain::new(
                vec![Link::Rotary(0), Link::Offset(V3::new(4.0, 0.0, -30.0)), Link::Rotary(1), Link::Linear],
                vec![rotary('C', V3::z(), 1.0), rotary('B', V3::y(), 1.0)],
            )
            .unwrap()
            .with_frame(V3::new(-3.0, 8.0, 50.0)),
        ),
        (
            "head-head B/C",
            Chain::new(
                vec![
                    Link::Linear,
                    Link::Rotary(0),
                    Link::Offset(V3::new(0.5, -0.25, -40.0)),
                    Link::Rotary(1),
                    Link::Offset(V3::new(0.0, 0.0, -150.0)),
                ],
                vec![rotary('C', V3::z(), 1.0), rotary('B', V3::y(), 1.0)],
            )
            .unwrap(),
        ),
        (
            "head-head A/B",
            Chain::new(
                vec![
                    Link::Linear,
                    Link::Rotary(0),
                    Link::Offset(V3::new(0.0, 1.0, -60.0)),
                    Link::Rotary(1),
                    Link::Offset(V3::new(0.0, 0.0, -120.0)),
                ],
                vec![rotary('A', V3::x(), 1.0), rotary('B', V3::y(), -1.0)],
            )
            .unwrap(),
        ),
        (
            "head-table C/B",
            Chain::new(
                vec![
                    Link::Rotary(0),
                    Link::Offset(V3::new(2.0, 3.0, 0.0)),
                    Link::Linear,
                    Link::Rotary(1),
                    Link::Offset(V3::new(0.0, 0.0, -200.0)),
                ],
                vec![rotary('C', V3::z(), 1.0), rotary('B', V3::y(), 1.0)],
            )
            .unwrap()
            .with_frame(V3::new(5.0, 5.0, 5.0)),
        ),
        (
            "nutating head 45°",
            Chain::new(
                vec![Link::Linear, Link::Rotary(0), Link::Rotary(1), Link::Offset(V3::new(0.0, 0.0, -100.0))],
                vec![rotary('C', V3::z(), 1.0), rotary('B', V3::new(0.0, s, s), 1.0)],
            )
            .unwrap(),
        ),
    ]
}

fn angle(a: &V3, b: &V3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

fn same_angle(a: f64, b: f64, eps: f64) -> bool {
    principal_deg(a - b).abs() <= eps
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// forward ∘ inverse = identity: every solution reproduces the pose to 1e-9 mm and 1e-12 rad,
    /// and one solution is the joints we started from.
    #[test]
    fn forward_inverse_identity(
        x in -300.0f64..300.0, y in -300.0f64..300.0, z in -300.0f64..300.0,
        r0 in -179.0f64..179.0, r1 in -179.0f64..179.0,
    ) {
        for (name, chain) in machines() {
            let n = chain.rotaries().len();
            let mut rot = [0.0; 2];
            rot[..n].copy_from_slice(&[r0, r1][..n]);
            let q = Joints { xyz: V3::new(x, y, z), rot };
            let pose = chain.forward(&q);
            prop_assert!((pose.axis.norm() - 1.0).abs() < 1e-14);
            let sols = chain.inverse(&pose);
            prop_assert!(!sols.is_empty(), "{name}: no solution");
            let o = chain.orientations(&pose.axis).unwrap();
            let singular = o.off_primary < 1e-6;
            let mut found = false;
            for s in &sols {
                let back = chain.forward(s);
                prop_assert!((back.tip - pose.tip).norm() <= 1e-9, "{name}: tip {:?} vs {:?}", back.tip, pose.tip);
                prop_assert!(angle(&back.axis, &pose.axis) <= 1e-12, "{name}: axis off by {}", angle(&back.axis, &pose.axis));
                // Joints come back through atan2 of axis components and carry more round-off than
                // the pose they reproduce (seen: 1.04e-9° on A, hence 3.1e-9 mm on X at 176 mm from
                // the table centre, for a pose exact to 1e-9 mm and 1e-12 rad): the branch is found
                // when joints agree to 1e-7° and 1e-7 mm.
                if (0..n).all(|k| same_angle(s.rot[k], q.rot[k], 1e-7)) && (s.xyz - q.xyz).norm() < 1e-7 {
                    found = true;
                }
            }
            prop_assert!(found || singular, "{name}: the starting joints {q:?} are not among {sols:?}");
            if n == 2 {
                // Two different branches that give the same pose.
                prop_assert_eq!(sols.len(), 2);
            }
        }
    }

    /// Paper 002 eq. 3–4: a = atan(√(u²+v²)/w), c = atan(u/v), and the twin (−a, c + 180°).
    #[test]
    fn paper_002_equations_3_4(theta in 0.01f64..1.5, phi in -3.1f64..3.1) {
        let u = V3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
        let chain = paper_ac();
        let o = chain.orientations(&u).unwrap();
        let a = (u.x.hypot(u.y) / u.z).atan().to_degrees();
        let c = u.x.atan2(u.y).to_degrees();
        // The branch with a ≥ 0 is eq. 3–4's; the other is its twin.
        let (b0, b1) = if o.branch[0][1] >= 0.0 { (0, 1) } else { (1, 0) };
        let [c0, a0] = o.branch[b0];
        let [c1, a1] = o.branch[b1];
        prop_assert!(same_angle(a0, a, 1e-10) && same_angle(c0, c, 1e-10), "{:?} vs a {a} c {c}", o.branch);
        prop_assert!(same_angle(a1, -a, 1e-10) && same_angle(c1, c + 180.0, 1e-10), "{:?}", o.branch);
    }

    /// The spindle angle of a non-rotating tool's edge: s → machine angle → s again.
    #[test]
    fn spindle_orientation_round_trip(r0 in -179.0f64..179.0, r1 in -89.0f64..89.0, s in -179.0f64..179.0) {
        for (name, chain) in machines() {
            let rot = [r0, r1];
            let sigma = chain.spindle_angle(&rot, s);
            let back = chain.edge_orientation(&rot, sigma);
            prop_assert!(same_angle(back, s, 1e-9), "{name}: {s} → {sigma} → {back}");
        }
    }
}

#[test]
fn paper_002_eq_2_by_hand() {
    // r0 = A2(yc) A1(xc) A6(c) A2(yac) A3(za) A4(a) (x, y, z) for a point on the tool tip, with
    // the matrices of table axes turning the workpiece the positive way.
    let chain = paper_ac();
    let (xc, yc, za, yac) = (12.5, -7.25, 85.0, 3.125);
    let (a, c) = (30.0f64.to_radians(), 50.0f64.to_radians());
    let m = V3::new(10.0, -20.0, 40.0);
    let r_a = rotation(&V3::x(), -a);
    let r_c = rotation(&V3::z(), -c);
    let expected = V3::new(xc, yc, 0.0) + r_c * (V3::new(0.0, yac, za) + r_a * m);
    let pose = chain.forward(&Joints { xyz: m, rot: [50.0, 30.0] });
    assert!((pose.tip.coords - expected).norm() < 1e-12, "{:?} vs {expected:?}", pose.tip);
    assert_eq!(chain.family(), Family::TableTable);
}

#[test]
fn closed_forms_of_simple_poses() {
    let chain = paper_ac();
    // A = 90°: the tool axis lies in the workpiece's XY plane.
    let p = chain.forward(&Joints { xyz: V3::zeros(), rot: [0.0, 90.0] });
    assert!((p.axis - V3::new(0.0, 1.0, 0.0)).norm() < 1e-15, "{:?}", p.axis);
    // C = 90° then: the axis turns to +X (u = sin a sin c).
    let p = chain.forward(&Joints { xyz: V3::zeros(), rot: [90.0, 90.0] });
    assert!((p.axis - V3::new(1.0, 0.0, 0.0)).norm() < 1e-15, "{:?}", p.axis);
    // The reference of the spindle orientation is +X for a vertical tool.
    assert_eq!(spindle_reference(&V3::z()), V3::x());
    let e = edge_direction(&V3::z(), 90.0);
    assert!((e - V3::y()).norm() < 1e-15);
}

#[test]
fn bad_chains_are_refused() {
    let r = |a, d| rotary(a, d, 1.0);
    assert!(Chain::new(vec![], vec![]).unwrap_err().contains("exactly one linear"));
    let e = Chain::new(vec![Link::Linear, Link::Rotary(0)], vec![r('C', V3::z())]).unwrap_err();
    assert!(e.contains("cannot tilt"), "{e}");
    let e = Chain::new(vec![Link::Rotary(0), Link::Rotary(1), Link::Linear], vec![r('A', V3::x()), r('B', V3::x())])
        .unwrap_err();
    assert!(e.contains("parallel"), "{e}");
}

#[test]
fn choice_respects_limits_and_continuity() {
    let mut chain = paper_ac();
    chain.rotaries[1].limits = Some((-30.0, 120.0));
    chain.rotaries[0].wrap = true;
    let solver = Solver { chain: &chain, policy: Policy::Shortest, cone: 1e-3 };
    // Axis tilted 40° towards +X: a = ±40°; both are inside, the one nearer the previous pose wins.
    let t = 40.0f64.to_radians();
    let u = V3::new(t.sin(), 0.0, t.cos());
    let c = solver.choose(&u, &[0.0, 0.0]).unwrap();
    assert!(same_angle(c.rot[1].abs(), 40.0, 1e-9));
    // Coming from C = 350°, C stays near 350 + turns, not back at −10.
    let c2 = solver.choose(&u, &[c.rot[0] + 360.0, c.rot[1]]).unwrap();
    assert!((c2.rot[0] - (c.rot[0] + 360.0)).abs() < 1e-9, "{:?}", c2);
    // 60° tilt the other way: the branch with a = −60° is outside −30..120, so a = +60°.
    let t = 60.0f64.to_radians();
    let u = V3::new(-t.sin(), 0.0, t.cos());
    let c3 = solver.choose(&u, &[0.0, -20.0]).unwrap();
    assert!((c3.rot[1] - 60.0).abs() < 1e-9, "{:?}", c3);
    // Beyond 120° of tilt neither branch is inside: the message names the axis and the limits.
    let t = 130.0f64.to_radians();
    let e = solver.choose(&V3::new(t.sin(), 0.0, t.cos()), &[0.0, 0.0]).unwrap_err();
    assert!(e.0.contains("A would be") && e.0.contains("-30..120"), "{}", e.0);
    // Near the singularity C is held.
    let u = V3::new(1e-5, 0.0, 1.0).normalize();
    let h = solver.choose(&u, &[123.0, 0.0]).unwrap();
    assert!(h.singular && h.rot[0] == 123.0);
    let got = chain.orientation(&h.rot).column(2).into_owned();
    assert!(angle(&got, &u) <= 2e-5, "held pose is within the cone: {}", angle(&got, &u));
}

#[test]
fn wrap_policies() {
    let mut chain = paper_ac();
    chain.rotaries[0].wrap = true;
    for (policy, expected) in [(Policy::Shortest, 370.0), (Policy::Positive, 370.0), (Policy::Negative, 10.0)] {
        let s = Solver { chain: &chain, policy, cone: 0.0 };
        assert!((s.unwind(0, 10.0, 350.0).unwrap() - expected).abs() < 1e-9, "{policy:?}");
    }
    let s = Solver { chain: &chain, policy: Policy::Positive, cone: 0.0 };
    assert!((s.unwind(0, 340.0, 350.0).unwrap() - 700.0).abs() < 1e-9);
}

/// LinuxCNC's `xyzac-trt` kinematics (trtfuncs, its forward and inverse formulas written out from
/// the equations): the same machine as a chain `[C sense −1, offset (0, dy, dz), A sense −1,
/// offset −(rot point + (0, dy, dz)), linear]` with frame = rot point. Our forward must equal
/// theirs, and their inverse must undo our forward (a round trip, not trust).
#[test]
fn linuxcnc_xyzac_trt_cross_check() {
    let (xr, yr, zr, dy, dz) = (3.5, -2.25, 41.0, 0.75, -12.5);
    let chain = Chain::new(
        vec![
            Link::Rotary(0),
            Link::Offset(V3::new(0.0, dy, dz)),
            Link::Rotary(1),
            Link::Offset(-V3::new(xr, yr + dy, zr + dz)),
            Link::Linear,
        ],
        vec![rotary('C', V3::z(), -1.0), rotary('A', V3::x(), -1.0)],
    )
    .unwrap()
    .with_frame(V3::new(xr, yr, zr));
    let mut worst: f64 = 0.0;
    for k in 0..200 {
        let t = k as f64;
        let (jx, jy, jz) = (40.0 * (t * 0.37).sin(), 30.0 * (t * 0.71).cos(), -20.0 + 15.0 * (t * 0.13).sin());
        let (a, c) = (100.0 * (t * 0.29).sin(), 170.0 * (t * 0.53).cos());
        let (sa, ca) = a.to_radians().sin_cos();
        let (sc, cc) = c.to_radians().sin_cos();
        let (vx, vy, vz) = (jx - xr, jy - dy - yr, jz - dz - zr);
        let theirs = V3::new(
            cc * vx + sc * ca * vy + sc * sa * vz + sc * dy + xr,
            -sc * vx + cc * ca * vy + cc * sa * vz + cc * dy + yr,
            -sa * vy + ca * vz + dz + zr,
        );
        let ours = chain.forward(&Joints { xyz: V3::new(jx, jy, jz), rot: [c, a] });
        worst = worst.max((ours.tip.coords - theirs).norm());
        // Their inverse from our world position gives the joints back.
        let (x, y, z) = (ours.tip.x - xr, ours.tip.y - yr, ours.tip.z - zr);
        let back = V3::new(
            cc * x - sc * y + xr,
            sc * ca * x + cc * ca * y - sa * z - ca * dy + sa * dz + dy + yr,
            sc * sa * x + cc * sa * y + ca * z - sa * dy - ca * dz + dz + zr,
        );
        assert!((back - V3::new(jx, jy, jz)).norm() < 1e-9, "their inverse does not undo the forward: {back:?}");
        assert!((chain.linear_for(&ours.tip, &[c, a]) - V3::new(jx, jy, jz)).norm() < 1e-9);
    }
    assert!(worst < 1e-9, "our forward differs from LinuxCNC's xyzac-trt by {worst} mm");
}
