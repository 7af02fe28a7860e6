//! Inverse kinematics on the humanoid: success rate on reachable targets,
//! limits, determinism, and whole-body joint lists.

mod common;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use tsukami_body::ik::{IkOptions, IkSolver};
use tsukami_body::kinematics::{FkState, JointSelection};

fn arm_solver<'m>(m: &'m tsukami_body::RobotModel, extra: &[&str]) -> IkSolver<'m> {
    let mut names: Vec<&str> = extra.to_vec();
    names.extend(common::humanoid_groups().arm);
    let sel = JointSelection::from_names(m, &names).unwrap();
    IkSolver::new(m, m.link_id("r_palm").unwrap(), sel, IkOptions::default()).unwrap()
}

#[test]
fn arm_reaches_random_reachable_targets() {
    let m = common::humanoid();
    let palm = m.link_id("r_palm").unwrap();
    let mut solver = arm_solver(&m, &[]);
    let mut rng = common::rng(7);
    let mut fk = FkState::new(&m);
    let rest = m.rest_positions();
    let arm: Vec<usize> = common::humanoid_groups()
        .arm
        .iter()
        .map(|n| m.joint_id(n).unwrap())
        .collect();
    let (mut ok, n) = (0, 1000);
    let mut iterations = 0;
    for _ in 0..n {
        // A target made from a random in-limit arm configuration.
        let mut q = rest.clone();
        let r = common::random_q(&m, &mut rng);
        for &j in &arm {
            q[j] = r[j];
        }
        m.forward_kinematics(&q, &mut fk);
        let target = *fk.pose(palm);
        let sol = solver.solve(&target, true, &rest, None);
        iterations += sol.iterations;
        if sol.ok {
            ok += 1;
            // Within limits, and the reported error is the real one.
            for &j in &arm {
                let lim = m.joints[j].limits;
                assert!(sol.q[j] >= lim.lower && sol.q[j] <= lim.upper);
            }
            m.forward_kinematics(&sol.q, &mut fk);
            let p = fk.pose(palm);
            assert!((p.translation.vector - target.translation.vector).norm() <= 1e-5);
            assert!(p.rotation.angle_to(&target.rotation) <= 1e-4);
            // Joints outside the list did not move.
            for (j, (a, b)) in sol.q.iter().zip(&rest).enumerate() {
                if !arm.contains(&j) && m.joints[j].mimic.is_none() {
                    assert_eq!(a, b, "{}", m.joints[j].name);
                }
            }
        }
    }
    eprintln!(
        "arm IK: {ok}/{n} solved, mean {} iterations",
        iterations / n
    );
    assert!(ok as f64 >= 0.99 * n as f64, "only {ok}/{n} solved");
}

#[test]
fn deterministic_for_a_seed() {
    let m = common::humanoid();
    let mut solver = arm_solver(&m, &common::humanoid_groups().waist);
    let target = Isometry3::from_parts(
        Translation3::new(0.45, -0.35, 0.95),
        UnitQuaternion::from_euler_angles(0.3, 1.2, -0.4),
    );
    let rest = m.rest_positions();
    let a = solver.solve(&target, true, &rest, None);
    let b = solver.solve(&target, true, &rest, None);
    assert_eq!(a.q, b.q);
    assert_eq!(a.iterations, b.iterations);
}

#[test]
fn position_only_target() {
    let m = common::humanoid();
    let mut solver = arm_solver(&m, &[]);
    let target = Isometry3::translation(0.35, -0.3, 1.05);
    let sol = solver.solve(&target, false, &m.rest_positions(), None);
    assert!(sol.ok, "{sol:?}");
    assert_eq!(sol.orientation_error, 0.0);
}

#[test]
fn squat_reaches_what_the_arm_cannot() {
    let m = common::humanoid();
    // A palm 0.30 m above the floor in front of the robot, palm facing
    // sideways (+y): far below what the standing arm can reach.
    let rot = UnitQuaternion::from_basis_unchecked(&[
        Vector3::x(),  // fingers forward
        -Vector3::z(), // y = z × x
        Vector3::y(),  // palm normal to the left
    ]);
    let target = Isometry3::from_parts(Translation3::new(0.40, -0.25, 0.40), rot);
    let rest = m.rest_positions();
    let arm = arm_solver(&m, &[]).solve(&target, true, &rest, None);
    assert!(!arm.ok, "arm alone should fail: {arm:?}");
    let groups = common::humanoid_groups();
    let mut whole = vec![groups.squat];
    whole.extend(groups.waist);
    let body = arm_solver(&m, &whole).solve(&target, true, &rest, None);
    assert!(body.ok, "{body:?}");
    assert!(body.q[m.joint_id(groups.squat).unwrap()] < -0.05);
}

#[test]
fn bad_selections_are_errors() {
    let m = common::humanoid();
    assert!(JointSelection::from_names(&m, &["r_index_j4"]).is_err()); // mimic
    assert!(JointSelection::from_names(&m, &["camera_joint"]).is_err()); // fixed
    assert!(JointSelection::from_names(&m, &["no_such_joint"]).is_err());
    let head = JointSelection::from_names(&m, &["head_yaw"]).unwrap();
    assert!(IkSolver::new(&m, m.link_id("r_palm").unwrap(), head, IkOptions::default()).is_err());
}

/// Random configurations of the selected joints (uniform in their limits, a
/// quarter of them pushed to a limit, where the reach bound's arcs end) from
/// a random start of the others: the solver's reach bound never puts the
/// link's own position beyond reach, and it does refuse targets 0.3 m past
/// the farthest of them without an attempt.
fn reach_bound_holds(m: &tsukami_body::RobotModel, link: &str, joints: &[&str], seed: u64) {
    let link = m.link_id(link).unwrap();
    let sel = JointSelection::from_names(m, joints).unwrap();
    let ids = sel.joints.clone();
    let mut solver = IkSolver::new(m, link, sel, IkOptions::default()).unwrap();
    let mut rng = common::rng(seed);
    let mut fk = FkState::new(m);
    let (mut widest, mut refused) = (f64::NEG_INFINITY, 0);
    let tries = 2000;
    for k in 0..tries {
        let start = common::random_q(m, &mut rng);
        let mut q = start.clone();
        let r = common::random_q(m, &mut rng);
        for (c, &j) in ids.iter().enumerate() {
            let l = m.joints[j].limits;
            q[j] = match (k % 4 == 0, (k / 4 + c) % 2 == 0) {
                (true, true) => l.lower,
                (true, false) => l.upper,
                _ => r[j],
            };
        }
        m.apply_mimics(&mut q);
        m.forward_kinematics(&q, &mut fk);
        let target = *fk.pose(link);
        solver.options_mut().max_attempts = 1;
        solver.options_mut().max_iterations = 1;
        let sol = solver.solve(&target, false, &start, None);
        assert!(
            sol.beyond_reach <= 1e-9,
            "{joints:?}: a reached position is {} m beyond reach",
            sol.beyond_reach
        );
        widest = widest.max(sol.beyond_reach);
        // Straight out from the chain's base, well past anything reached.
        let base = fk.pose(m.joints[ids[0]].parent).translation.vector;
        let out = target.translation.vector - base;
        let far = Isometry3::from_parts(
            Translation3::from(base + out.normalize() * (out.norm() + 2.0)),
            UnitQuaternion::identity(),
        );
        let sol = solver.solve(&far, false, &start, None);
        if !sol.ok && sol.attempts == 0 && sol.beyond_reach > 0.0 {
            refused += 1;
        }
    }
    eprintln!("{joints:?}: closest to the bound {widest:.3} m; {refused}/{tries} far targets refused at once");
    assert_eq!(
        refused, tries,
        "{joints:?}: far targets went to the iterations"
    );
}

#[test]
fn the_reach_bound_never_refuses_a_reachable_target() {
    let m = common::humanoid();
    let g = common::humanoid_groups();
    let arm = g.arm.clone();
    let waist: Vec<&str> = g.waist.iter().chain(&arm).copied().collect();
    let mut whole = vec![g.squat];
    whole.extend(&waist);
    for (seed, joints) in [(1, &arm), (2, &waist), (3, &whole)] {
        reach_bound_holds(&m, "r_palm", joints, seed);
    }
    // A public arm with another hand (different axes, offsets and limits).
    let iiwa = tsukami_body::urdf::load_urdf(
        &common::models_dir().join("robots/iiwa_allegro/iiwa_allegro.urdf"),
    )
    .unwrap();
    let joints: Vec<&str> = (1..=7)
        .map(|i| &*format!("lbr_iiwa_joint_{i}").leak())
        .collect();
    reach_bound_holds(&iiwa, "palm", &joints, 4);
}

#[test]
fn a_low_target_is_refused_at_once_by_the_arm_and_waist() {
    // The paper's whole-body fallback: a palm 0.30 m above the floor is out of
    // the standing arm's and the bending waist's reach (its pitch limit), so
    // those stages cost no iterations before the squat stage solves it.
    let m = common::humanoid();
    let g = common::humanoid_groups();
    let target = Isometry3::translation(0.40, -0.25, 0.30);
    let rest = m.rest_positions();
    let arm = arm_solver(&m, &[]).solve(&target, false, &rest, None);
    let waist = arm_solver(&m, &g.waist).solve(&target, false, &rest, None);
    for s in [&arm, &waist] {
        assert!(!s.ok && s.attempts == 0 && s.beyond_reach > 0.0, "{s:?}");
    }
    assert!(waist.beyond_reach < arm.beyond_reach);
    let mut whole = vec![g.squat];
    whole.extend(&g.waist);
    let body = arm_solver(&m, &whole).solve(&target, false, &rest, None);
    assert!(body.ok && body.beyond_reach <= 0.0, "{body:?}");
}
