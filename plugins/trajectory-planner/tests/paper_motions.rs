//! In-process: each paper scene's grasp (the paper's planner, seed 0) is reached
//! from rest, phases in order, ending at the grasp; the same seed gives the same
//! trajectory. The full independent re-check runs over the bus in
//! `tests/tests/motion.rs`.

mod common;

use tsukami_msgs::motion::{JointTrajectory, MotionGrasp};
use tsukami_planner_kit::validate::Limits;
use tsukami_trajectory_planner::motion::{
    plan_default, plan_motion, Motion, MotionConfig, MotionQuery, Variant,
};

fn motion(scene: &str, seed: u64) -> (Motion, MotionGrasp) {
    let (world, grasp) = common::grasps::scene(scene, 0);
    let snapshot = world.snapshot();
    let w = snapshot.world().unwrap();
    let query = MotionQuery::new(&grasp, w.robot.model.rest_positions(), seed);
    let m = plan_default(&w, &query).unwrap_or_else(|e| panic!("{scene}: {e}"));
    (m, grasp)
}

fn check(scene: &str) {
    let (m, grasp) = motion(scene, 1);
    let t = &m.trajectory;
    let mut phases: Vec<&str> = t.points.iter().map(|p| p.phase.as_str()).collect();
    phases.dedup();
    assert_eq!(phases, ["reach", "approach", "close", "lift"], "{scene}");
    let k = t.points.iter().rposition(|p| p.phase == "close").unwrap();
    for (n, q) in t.joint_names.iter().zip(&t.points[k].positions) {
        if let Some(g) = grasp.joint_positions.get(n) {
            assert!((q - g).abs() < 1e-9, "{scene}: {n}");
        }
    }
    squeezed(scene, t, &grasp);
    assert_eq!(motion(scene, 1).0, m, "{scene}: deterministic");
    let mut spans = Vec::new();
    for name in ["reach", "approach", "close", "lift"] {
        let i = t.points.iter().position(|p| p.phase == name).unwrap();
        let k = t.points.iter().rposition(|p| p.phase == name).unwrap();
        let start = if i > 0 { t.points[i - 1].time } else { 0.0 };
        spans.push(format!("{name} {:.2} s", t.points[k].time - start));
    }
    eprintln!(
        "{scene}: {} points, {:.2} s ({}), {} samples, {} checks",
        t.points.len(),
        t.points.last().unwrap().time,
        spans.join(", "),
        m.samples,
        m.checks
    );
    no_stop_inside_a_phase(scene, t);
    // A person takes about 2 s; issue #23 asks for under 4 s at the robot's limits.
    if scene == "can_breast" {
        let total = t.points.last().unwrap().time;
        assert!(total < 4.0, "{scene}: {total:.2} s from rest to lifted");
    }
}

/// The velocity is zero only where a phase begins or ends.
fn no_stop_inside_a_phase(scene: &str, t: &JointTrajectory) {
    let n = t.points.len();
    for k in 1..n - 1 {
        let p = &t.points[k];
        let ends = t.points[k - 1].phase != p.phase || t.points[k + 1].phase != p.phase;
        let still = p.velocities.iter().all(|v| v.abs() < 1e-9);
        assert!(
            ends || !still,
            "{scene}: point {k} ({}, t = {:.3} s) is a stop",
            p.phase,
            p.time
        );
    }
}

/// The grasp's squeeze is the command of the last `close` point and of every
/// `lift` point: the squeezed joints at their targets, the others at the
/// point's positions; no other point has a command.
fn squeezed(scene: &str, t: &JointTrajectory, grasp: &MotionGrasp) {
    assert!(
        !grasp.squeeze.is_empty(),
        "{scene}: the Plan reply squeezes"
    );
    for s in &grasp.squeeze {
        assert!(t.joint_names.contains(&s.joint), "{scene}: {}", s.joint);
    }
    let last_close = t.points.iter().rposition(|p| p.phase == "close").unwrap();
    for (k, p) in t.points.iter().enumerate() {
        if k != last_close && p.phase != "lift" {
            assert!(p.command.is_empty(), "{scene}: point {k} ({})", p.phase);
            continue;
        }
        assert_eq!(p.command.len(), p.positions.len(), "{scene}: point {k}");
        for (i, name) in t.joint_names.iter().enumerate() {
            let want = grasp
                .squeeze
                .iter()
                .find(|s| &s.joint == name)
                .map_or(p.positions[i], |s| s.target);
            assert_eq!(p.command[i], want, "{scene}: point {k}, {name}");
        }
    }
    let moved = grasp
        .squeeze
        .iter()
        .any(|s| (s.target - s.position).abs() > 1e-6);
    assert!(moved, "{scene}: some target lies beyond contact");
}

#[test]
fn can_breast() {
    check("can_breast");
}

#[test]
fn can_waist() {
    check("can_waist");
}

#[test]
fn heavy_low() {
    check("heavy_low");
}

#[test]
fn fridge_pet() {
    check("fridge_pet");
}

#[test]
fn vase_table() {
    check("vase_table");
}

/// Progress names the phases in order; a raised cancel flag stops the reach
/// planner with `Cancelled` (what the host's `stop` does to a running call).
#[test]
fn progress_in_phase_order_and_stop_cancels() {
    let (world, grasp) = common::grasps::scene("can_breast", 0);
    let snapshot = world.snapshot();
    let w = snapshot.world().unwrap();
    let query = MotionQuery::new(&grasp, w.robot.model.rest_positions(), 1);
    let cfg = MotionConfig::default();
    let mut phases = Vec::new();
    let run = |cancel: bool, phases: &mut Vec<String>| {
        plan_motion(
            &w,
            &query,
            &cfg,
            &Limits::default(),
            Variant::default(),
            &|| cancel,
            &mut |p, _| phases.push(p.to_owned()),
        )
    };
    run(false, &mut phases).unwrap();
    assert_eq!(
        phases,
        ["approach", "reach", "close", "lift", "timing", "done"]
    );
    let cancelled = run(true, &mut Vec::new());
    assert_eq!(
        cancelled,
        Err(tsukami_trajectory_planner::error::MotionError::Cancelled)
    );
}

/// A grasp re-validated on the world it was planned on passes; once the object
/// has moved 3 cm, the same grasp fails the re-check (`grasp_invalid`, naming
/// both versions and what fails) instead of closing the hand on air.
#[test]
fn a_revalidated_grasp_holds_on_its_world_and_fails_once_the_object_moved() {
    use tsukami_trajectory_planner::error::MotionError;
    let (world, grasp) = common::grasps::scene("can_breast", 0);
    let plan = |world: &tsukami_planner_kit::Session<_>| {
        let snapshot = world.snapshot();
        let w = snapshot.world().unwrap();
        let query = MotionQuery {
            recheck: true,
            ..MotionQuery::new(&grasp, w.robot.model.rest_positions(), 1)
        };
        let version = w.version;
        let out = plan_default(&w, &query);
        (out, version)
    };
    let (same, _) = plan(&world);
    same.expect("the grasp holds on the world it was planned on");
    let scene = common::grasps::models().join("scenes/can_breast.toml");
    let mut object = tsukami_scenes::scene_requests(&scene).unwrap().object;
    object.pose.position[1] += 0.03;
    world.set_object(&object).unwrap();
    let (moved, version) = plan(&world);
    match moved {
        Err(MotionError::Infeasible {
            reason, message, ..
        }) => {
            assert_eq!(reason, "grasp_invalid");
            let versions = format!(
                "planned on world version {} does not hold on version {version}",
                grasp.world_version
            );
            assert!(message.contains(&versions), "{message}");
        }
        other => panic!("a moved object must fail the re-check: {other:?}"),
    }
}

/// Asked for a retreat, the motion ends with it: the palm goes straight back
/// against the approach, by the distance asked, from where the lift left it,
/// the object carried; the retreat does not stop on the way.
#[test]
fn the_retreat_backs_the_palm_out_against_the_approach() {
    let (world, grasp) = common::grasps::scene("can_breast", 0);
    let snapshot = world.snapshot();
    let w = snapshot.world().unwrap();
    let query = MotionQuery {
        retreat_distance: 0.08,
        ..MotionQuery::new(&grasp, w.robot.model.rest_positions(), 1)
    };
    let m = plan_default(&w, &query).expect("a motion with a retreat");
    let t = &m.trajectory;
    let mut phases: Vec<&str> = t.points.iter().map(|p| p.phase.as_str()).collect();
    phases.dedup();
    assert_eq!(phases, ["reach", "approach", "close", "lift", "retreat"]);
    no_stop_inside_a_phase("can_breast", t);
    let model = &w.robot.model;
    let palm_at = |k: usize| {
        let mut q = query.start.clone();
        for (n, v) in t.joint_names.iter().zip(&t.points[k].positions) {
            q[model.joint_id(n).unwrap()] = *v;
        }
        model.apply_mimics(&mut q);
        let mut fk = tsukami_body::kinematics::FkState::new(model);
        model.forward_kinematics(&q, &mut fk);
        *fk.pose(w.robot.hand().palm)
    };
    let lifted = t.points.iter().rposition(|p| p.phase == "lift").unwrap();
    let (a, b) = (palm_at(lifted), palm_at(t.points.len() - 1));
    let moved = b.translation.vector - a.translation.vector;
    let types = &w.robot.hand().grasp_types.grasp_types;
    let g = types
        .iter()
        .find(|g| g.name == grasp.grasp_type.name)
        .unwrap();
    let approach = a.rotation * g.approach();
    assert!((moved.norm() - 0.08).abs() < 1e-3, "{moved:?}");
    assert!(
        moved.normalize().dot(&-approach) > 0.999,
        "{moved:?} vs {approach:?}"
    );
    assert!(a.rotation.angle_to(&b.rotation) < 1e-3);
    // The squeeze is held through the retreat.
    assert!(t.points[lifted + 1..].iter().all(|p| !p.command.is_empty()));
}
