//! A weak fingertip grasp set aside is not the end of the search (issue #22):
//! when a stage's candidates give only a fingertip grasp that holds under
//! fewer than `WEAK_SHARE` of the sampled object pose errors, the planner goes
//! on to the later tiers (the types that fit in size only, the tilts) on the
//! same whole-body stage and returns the better grasp it finds there.
//!
//! The case: the object benchmark's `box_4` (a 9 × 6 × 12 cm box of 0.2 kg)
//! standing on the 0.78 m table, seed 1, reached with the arm and the waist.
//! The mass range's types give at best a three-fingertip grasp that holds
//! under 5 of the 8 pose errors (the reply before the rule); the tilted
//! approaches give a four-fingertip grasp that holds under all of them.

#[path = "common/objects.rs"]
mod objects;

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use serde_json::json;
use tsukami_grasp_planner::planner::{Planner, WEAK_SHARE};
use tsukami_msgs::planner::{PlanOptions, PlanReply, SetEnv, SetObject, SetRobot};
use tsukami_scenes::{verify, Tolerances, World};

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

struct Case {
    /// The folder of the mesh file (removed at the end).
    dir: PathBuf,
    planner: Planner,
    robot: SetRobot,
    object: SetObject,
    env: SetEnv,
}

fn box_on_table() -> Case {
    let dir = std::env::temp_dir().join(format!("tsukami-set-aside-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let root = std::fs::canonicalize(&dir).unwrap();
    let planner = Planner::from_config(tsukami_planner_kit::PlannerConfig::with_roots([
        models(),
        root.clone(),
    ]))
    .unwrap();
    let robot: SetRobot = serde_json::from_value(json!({"robot": "tsukami_humanoid"})).unwrap();
    planner.set_robot(&robot).unwrap();
    let (object, env) = objects::case_requests("box_4", "table_0.78", &root);
    let object: SetObject = serde_json::from_value(object).unwrap();
    let env: SetEnv = serde_json::from_value(env).unwrap();
    planner.set_object(&object).unwrap();
    planner.set_env(&env).unwrap();
    Case {
        dir: root,
        planner,
        robot,
        object,
        env,
    }
}

fn plan(c: &Case, opts: &PlanOptions) -> PlanReply {
    c.planner
        .plan(opts, &AtomicBool::new(false), &mut |_| {})
        .unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_weak_fingertip_grasp_is_traded_for_a_better_one_of_a_later_tier() {
    let c = box_on_table();
    let opts = PlanOptions {
        seed: 1,
        ..PlanOptions::default()
    };
    let r = plan(&c, &opts);
    // The stage's first tier (the mass range's types) gives at best a grasp
    // that holds under 5 of the 8 errors (a three-fingertip grasp, returned
    // before the rule); the later tiers were searched and gave a better one.
    let tried = &r.candidates_tried;
    assert!(tried.len() > opts.max_candidates as usize, "{tried:?}");
    let rb = r.force_closure.robustness;
    assert!(
        rb.share() >= WEAK_SHARE,
        "{}: held under {rb:?}",
        r.grasp_type.name
    );
    // Not traded for more of the body than the weak grasp needed.
    assert!(
        !r.joints_used.iter().any(|j| j == "squat_z"),
        "{:?}",
        r.joints_used
    );
    let world = World::from_requests(&models(), &c.robot, &c.object, &c.env).unwrap();
    let verdict = verify(&world, &r, &Tolerances::default());
    assert!(verdict.is_ok(), "{verdict}");
    // The same seed, the same reply.
    let again = plan(&c, &opts);
    assert_eq!(again.joint_positions, r.joint_positions);
    let _ = std::fs::remove_dir_all(&c.dir);
}

/// An envelope set aside is returned when its stage is spent, weak or not:
/// its type is the one the selection chose for the weight (the PET bottle in
/// the fridge, seed 1: an envelope that holds under 2 of the 8 errors, which
/// MuJoCo holds under every pull and with the pose noise).
#[test]
fn a_weak_envelope_is_returned_at_the_end_of_its_stage() {
    let models = models();
    let req = tsukami_scenes::scene_requests(&models.join("scenes/fridge_pet.toml")).unwrap();
    let p = Planner::new(&models);
    p.set_robot(&req.robot).unwrap();
    p.set_object(&req.object).unwrap();
    p.set_env(&req.env).unwrap();
    let opts = PlanOptions {
        seed: 1,
        ..PlanOptions::default()
    };
    let r = p.plan(&opts, &AtomicBool::new(false), &mut |_| {}).unwrap();
    assert!(
        r.grasp_type.name.starts_with("envelope"),
        "{}",
        r.grasp_type.name
    );
    let share = r.force_closure.robustness.share();
    assert!(share < WEAK_SHARE, "{share}: no longer a weak envelope");
    // Only the stage's first tier was searched.
    assert!(
        r.candidates_tried.len() <= opts.max_candidates as usize,
        "{:?}",
        r.candidates_tried
    );
}
