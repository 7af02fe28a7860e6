//! Does every grasp the paper's planner returns on the object benchmark have a
//! motion? Each case of the object benchmark (`plugins/grasp-planner/tests/
//! common/objects.rs`, 275 cases) is planned with seed 1 by the grasp planner,
//! loaded from its plugin file, and every returned grasp is handed to this
//! planner's `plan_motion` from the rest posture with the request defaults
//! (5 cm pre-grasp, 5 cm lift, 10 mm / 3 mm clearance). Prints how many motions
//! were found, and per failure reason how many were not: `approach_blocked`,
//! `close_blocked` or `lift_blocked` on a returned grasp is what issue #23 says
//! must not happen (the grasp planner checks those phases before it returns a
//! grasp); `no_path` (the reach within the sample budget) is the reach
//! planner's own limit.
//!
//! Run in release: `cargo run --release -p tsukami-trajectory-planner --example
//! object_motions [-- --only TEXT]` (`cargo benchmarks --only object_motions`).

#[allow(dead_code)]
#[path = "../tests/common/grasps.rs"]
mod grasps;
#[path = "../../grasp-planner/tests/common/objects.rs"]
mod objects;

use std::collections::BTreeMap;
use std::sync::atomic::AtomicBool;

use abi_stable::sabi_trait::TD_Opaque;
use abi_stable::std_types::RArc;
use objects::{objects, placements, set_env, set_object};
use serde_json::{json, Value};
use tsukami_msgs::motion::MotionGrasp;
use tsukami_msgs::planner::{SetEnv, SetObject, SetRobot};
use tsukami_planner_kit::{PlannerConfig, Session};
use tsukami_plugin_api::ffi::FfiHost_TO;
use tsukami_plugin_api::loader::LoadedLibrary;
use tsukami_plugin_api::offline::OfflineHost;
use tsukami_trajectory_planner::error::MotionError;
use tsukami_trajectory_planner::motion::{plan_default, MotionQuery};
use tsukami_trajectory_planner::world::SharedWorld;

const VALID: &str = "the benchmark's own requests are valid";

/// The motion of `grasp` from rest: `Ok` or the failure's reason.
fn motion(world: &Session<SharedWorld>, grasp: &MotionGrasp) -> Result<(), String> {
    let snapshot = world.snapshot();
    let w = snapshot.world().map_err(|e| e.to_string())?;
    let query = MotionQuery::new(grasp, w.robot.model.rest_positions(), 0);
    let out = plan_default(&w, &query);
    match out {
        Ok(_) => Ok(()),
        Err(MotionError::Infeasible {
            reason, message, ..
        }) => Err(format!("{reason}: {message}")),
        Err(e) => Err(format!("error: {e}")),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let only = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1))
        .cloned()
        .unwrap_or_default();
    let tmp = std::env::temp_dir().join(format!("tsukami-object-motions-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let root = std::fs::canonicalize(&tmp).unwrap();
    let roots = [grasps::models(), root.clone()];
    let world = Session::<SharedWorld>::from_config(PlannerConfig::with_roots(roots.clone()))
        .expect("the world starts");
    let library =
        LoadedLibrary::load(&grasps::grasp_planner_file()).expect("the grasp planner loads");
    let host = FfiHost_TO::from_ptr(RArc::new(OfflineHost::new()), TD_Opaque);
    let config = format!(
        "model_roots = [{:?}, {:?}]",
        roots[0].display().to_string(),
        roots[1].display().to_string()
    );
    let planner = library
        .create(host, &config)
        .expect("the grasp planner starts");
    let cancel = AtomicBool::new(false);
    let call = |command: &str, v: &Value| {
        planner
            .call(command, &serde_json::to_vec(v).unwrap(), &cancel)
            .map_err(|e| format!("{} {}", e.code, e.message))
    };
    let robot = json!({ "robot": "tsukami_humanoid" });
    call("set_robot", &robot).unwrap();
    world
        .set_robot(&serde_json::from_value::<SetRobot>(robot).expect(VALID))
        .unwrap();
    let (mut cases, mut grasps_returned, mut moved) = (0, 0, 0);
    let mut failures: BTreeMap<String, u32> = BTreeMap::new();
    for o in objects() {
        let path = root.join(format!("{}.stl", o.name));
        o.mesh.write_stl(&path).unwrap();
        let path = path.display().to_string();
        for p in placements() {
            if !(o.name.contains(&only) || p.name.contains(&only)) {
                continue;
            }
            cases += 1;
            let (obj, env) = (set_object(&o, &p, &path), set_env(&p));
            call("set_object", &obj).unwrap();
            call("set_env", &env).unwrap();
            world
                .set_object(&serde_json::from_value::<SetObject>(obj).expect(VALID))
                .unwrap();
            world
                .set_env(&serde_json::from_value::<SetEnv>(env).expect(VALID))
                .unwrap();
            let Ok(reply) = call("plan", &json!({"seed": 1})) else {
                continue;
            };
            grasps_returned += 1;
            let grasp: MotionGrasp = serde_json::from_slice(&reply).expect("a Plan reply");
            match motion(&world, &grasp) {
                Ok(()) => moved += 1,
                Err(why) => {
                    println!("  {:<10} {:<22} {why}", o.name, p.name);
                    let reason = why.split(':').next().unwrap_or("").to_owned();
                    *failures.entry(reason).or_default() += 1;
                }
            }
        }
    }
    let _ = std::fs::remove_dir_all(&tmp);
    let blocked: u32 = ["approach_blocked", "close_blocked", "lift_blocked"]
        .iter()
        .filter_map(|r| failures.get(*r))
        .sum();
    println!(
        "object benchmark, seed 1: {cases} cases, {grasps_returned} grasps returned, {moved} with a motion from rest"
    );
    println!(
        "returned grasps whose approach, closing or lift is blocked: {blocked} of {grasps_returned}"
    );
    for (reason, n) in &failures {
        println!("  {reason}: {n}");
    }
}
