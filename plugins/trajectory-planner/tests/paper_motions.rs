//! In-process: each paper scene's grasp (the paper's planner, seed 0) is reached
//! from rest, phases in order, ending at the grasp; the same seed gives the same
//! trajectory. The full independent re-check runs over the bus in
//! `tests/tests/motion.rs`.

mod common;

use tsukami_msgs::motion::{JointTrajectory, MotionGrasp};
use tsukami_planner_kit::validate::Limits;
use tsukami_trajectory_planner::motion::{plan_motion, Motion, MotionConfig, MotionQuery, Variant};

fn motion(scene: &str, seed: u64) -> (Motion, MotionGrasp) {
    let (world, grasp) = common::grasps::scene(scene, 0);
    let snapshot = world.snapshot();
    let w = snapshot.world().unwrap();
    let query = MotionQuery {
        grasp: &grasp,
        start: w.robot.model.rest_positions(),
        lift_height: 0.05,
        pregrasp_distance: 0.05,
        seed,
        max_samples: 5000,
        recheck: false,
        clearance: tsukami_trajectory_planner::motion::Clearance::default(),
        acceleration: 2.0,
    };
    let cfg = MotionConfig::default();
    let m = plan_motion(
        &w,
        &query,
        &cfg,
        &Limits::default(),
        Variant::default(),
        &|| false,
        &mut |_, _| {},
    )
    .unwrap_or_else(|e| panic!("{scene}: {e}"));
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
    eprintln!(
        "{scene}: {} points, {:.2} s, {} samples, {} checks",
        t.points.len(),
        t.points.last().unwrap().time,
        m.samples,
        m.checks
    );
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
    let query = MotionQuery {
        grasp: &grasp,
        start: w.robot.model.rest_positions(),
        lift_height: 0.05,
        pregrasp_distance: 0.05,
        seed: 1,
        max_samples: 5000,
        recheck: false,
        clearance: tsukami_trajectory_planner::motion::Clearance::default(),
        acceleration: 2.0,
    };
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
            grasp: &grasp,
            start: w.robot.model.rest_positions(),
            lift_height: 0.05,
            pregrasp_distance: 0.05,
            seed: 1,
            max_samples: 5000,
            recheck: true,
            clearance: tsukami_trajectory_planner::motion::Clearance::default(),
            acceleration: 2.0,
        };
        let version = w.version;
        let out = plan_motion(
            &w,
            &query,
            &MotionConfig::default(),
            &Limits::default(),
            Variant::default(),
            &|| false,
            &mut |_, _| {},
        );
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
