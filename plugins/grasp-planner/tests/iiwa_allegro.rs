//! A public robot the project did not design (issue 11): the KUKA iiwa with the
//! Allegro hand on its flange (`models/robots/iiwa_allegro`, composed by
//! `tsukami model compose`, grasp types from `tsukami model grasp-types`)
//! plans a can on a table with the built-in planner, and every returned grasp
//! passes the independent check (`tsukami_scenes::verify`: exact force
//! closure with the object's weight, no penetration, contacts on the hand).

#[path = "common/objects.rs"]
mod objects;

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use serde_json::json;
use tsukami_grasp_planner::planner::Planner;
use tsukami_msgs::planner::{PlanOptions, PlanReply, SetEnv, SetObject, SetRobot};
use tsukami_scenes::{verify, Tolerances, World};

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

fn robot() -> SetRobot {
    serde_json::from_value(json!({"robot": "iiwa_allegro"})).unwrap()
}

/// A 350 ml can standing on a 0.25 m table in front of the arm's base, at `xy`.
fn can_on_table(xy: [f64; 2]) -> (SetObject, SetEnv) {
    let top = 0.25;
    let pose = json!({"position": [xy[0], xy[1], top]});
    let object = json!({"name": "can", "shape": {"model": {"name": "can_350ml"}},
                        "mass": 0.15, "pose": pose});
    let env = json!({"obstacles": [{"name": "table", "shape": {"box": {"size": [0.4, 0.8, top]}},
                                    "pose": {"position": [0.7, 0.0, top / 2.0]}}],
                     "replace": true});
    (
        serde_json::from_value(object).unwrap(),
        serde_json::from_value(env).unwrap(),
    )
}

fn plan(p: &Planner, object: &SetObject, env: &SetEnv, seed: u64) -> PlanReply {
    p.set_object(object).unwrap();
    p.set_env(env).unwrap();
    let opts = PlanOptions {
        seed,
        ..PlanOptions::default()
    };
    p.plan(&opts, &AtomicBool::new(false), &mut |_| {})
        .unwrap_or_else(|e| panic!("{:?} seed {seed}: {e}", object.pose))
}

fn assert_verified(object: &SetObject, env: &SetEnv, reply: &PlanReply) {
    let world = World::from_requests(&models(), &robot(), object, env).unwrap();
    let verdict = verify(&world, reply, &Tolerances::default());
    assert!(verdict.is_ok(), "{}: {verdict}", reply.grasp_type.name);
}

#[test]
fn the_iiwa_with_the_allegro_hand_plans_verified_grasps_of_a_can() {
    let p = Planner::new(models());
    let summary = p.set_robot(&robot()).unwrap();
    assert_eq!(summary.arm_joints.len(), 7);
    assert_eq!(summary.hand_joints.len(), 16);
    // A lying can is not among them: the Allegro's fingertip postures hold
    // the object 54 mm below the palm, and on a can lying on the table the
    // fingers meet the table (docs/bring-your-own-robot.md, "Limits").
    for xy in [[0.55, 0.0], [0.5, 0.2], [0.6, -0.2]] {
        let (object, env) = can_on_table(xy);
        for seed in [0, 1] {
            let reply = plan(&p, &object, &env, seed);
            assert!(
                reply.force_closure.exact_resists_weight,
                "{xy:?} seed {seed}"
            );
            // The arm alone: the robot has no waist or whole-body joints.
            assert!(reply.joints_used.is_empty(), "{:?}", reply.joints_used);
            assert!(reply.joint_positions.contains_key("lbr_iiwa_joint_7"));
            assert_verified(&object, &env, &reply);
        }
    }
}

/// The Allegro's reference fingertip posture is narrower than a ring's tube
/// with the fingertips' thickness: at every nominal palm pose over the ring
/// a fingertip rests on it. The planner opens that finger before sampling
/// (`clearance::PRE_OPEN`) and the grasp is planned and verified; without
/// the opening, every sample collides before closing.
#[test]
fn a_finger_on_the_ring_in_the_pre_shape_is_opened_and_the_ring_is_grasped() {
    let dir = std::env::temp_dir().join(format!("tsukami-allegro-ring-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let root = std::fs::canonicalize(&dir).unwrap();
    let p = Planner::from_config(tsukami_planner_kit::PlannerConfig::with_roots([
        models(),
        root.clone(),
    ]))
    .unwrap();
    p.set_robot(&robot()).unwrap();
    // On the 0.78 m table: on the rotated counter every grasp that holds has
    // the iiwa's elbow straight, so the palm cannot back out along the
    // approach (`motion blocked`, issue #23).
    let (object, env) = objects::case_requests("torus_1", "table_0.78", &root);
    let object: SetObject = serde_json::from_value(object).unwrap();
    let env: SetEnv = serde_json::from_value(env).unwrap();
    // What this test is about is the pre-shape opening; with the standard
    // disturbance set no closed hand of the 14,000 samples holds this fat ring
    // (issue #22's figures), so the request asks for the weight test.
    p.set_object(&object).unwrap();
    p.set_env(&env).unwrap();
    let opts = PlanOptions {
        seed: 1,
        hold: tsukami_msgs::planner::HoldRequest {
            disturbances: tsukami_msgs::planner::DisturbanceSet::Gravity,
            ..Default::default()
        },
        ..PlanOptions::default()
    };
    let reply = p
        .plan(&opts, &AtomicBool::new(false), &mut |_| {})
        .unwrap_or_else(|e| panic!("the ring: {e}"));
    assert_verified(&object, &env, &reply);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(reply.force_closure.exact_resists_weight);
}
