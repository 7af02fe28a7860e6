//! A fixed subset of the object benchmark (issue #10) over the bus: the host
//! loads the real grasp-planner `.so`, each object goes to it as a binary STL
//! file under a model root, each placement's supports as obstacles, and every
//! case must plan (seed 1, default options) and pass the independent check of
//! `tsukami_scenes::verify` (exact force closure with the weight recomputed
//! from the reply's contacts, contacts on the surface, no link more than 1 mm
//! inside the object or an obstacle, joint limits). The objects and placements
//! are the benchmark's own (`plugins/grasp-planner/tests/common/objects.rs`);
//! the whole benchmark is `cargo run --release -p tsukami-grasp-planner
//! --example object_bench` (figures in `docs/benchmarks.md`).

#[path = "../../plugins/grasp-planner/tests/common/objects.rs"]
mod objects;

use std::path::PathBuf;
use std::time::Duration;

use objects::{objects, placements, set_env, set_object};
use serde_json::{json, Value};
use tsukami::client::BusClient;
use tsukami_e2e::{models_dir, planner_entry, test_config, TestBus};
use tsukami_msgs::keys::{planner, ROLE_GRASP_PLANNER};
use tsukami_msgs::planner::{PlanReply, SetEnv, SetObject, SetRobot};
use tsukami_scenes::{verify, Tolerances, World};

const T: Duration = Duration::from_secs(120);

/// (object, placement): one of each family, on every placement, upright and
/// lying, chosen among the cases the benchmark plans; the last two plan only
/// with an approach at an angle (`tilt` in the reply; [`TILTED`] lists the
/// cases whose reply is tilted).
const SUBSET: [(&str, &str); 14] = [
    ("can_2", "table_0.78"),
    ("can_2", "table_0.72_lying"),
    ("bottle_0", "counter_1.00_rotated"),
    ("box_0", "table_0.72_lying"),
    ("fruit_4", "table_0.72_lying"),
    ("spray_3", "table_0.72_lying"),
    ("vase_2", "shelf_0.60"),
    ("scan_1", "stool_0.45"),
    ("mug_1", "counter_1.00_rotated"),
    ("low_0", "table_0.78"),
    ("cone_1", "shelf_0.60"),
    ("torus_1", "table_0.78"),
    ("low_0", "counter_1.00_rotated"),
    ("low_3", "shelf_0.60"),
];

/// The cases of [`SUBSET`] no approach along the object box's axes holds —
/// or, for the cone under the shelf's board, none whose approach, closing and
/// lift are free (the grasp planner checks them, issue #23); the can lying on
/// the table, where the axis-aligned grasps hold under 5 of the 8 sampled pose
/// errors at best and a tilted one under all (a weak fingertip grasp looks
/// further, docs/force-closure.md, "Holding").
const TILTED: [(&str, &str); 4] = [
    ("can_2", "table_0.72_lying"),
    ("low_0", "counter_1.00_rotated"),
    ("low_3", "shelf_0.60"),
    ("cone_1", "shelf_0.60"),
];

/// A temporary model root, removed on drop.
struct TempRoot(PathBuf);

impl Drop for TempRoot {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn send(c: &BusClient, command: &str, payload: &Value) -> Value {
    let bytes = c
        .command(
            ROLE_GRASP_PLANNER,
            command,
            payload.to_string().as_bytes(),
            T,
        )
        .unwrap_or_else(|e| panic!("{command} {payload}: {e:?}"));
    serde_json::from_slice(&bytes).expect("reply is JSON")
}

#[test]
fn a_fixed_subset_of_the_object_benchmark_plans_and_verifies_over_the_bus() {
    let dir = std::env::temp_dir().join(format!("tsukami-object-subset-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let root = TempRoot(std::fs::canonicalize(&dir).unwrap());
    let mut config = test_config(vec![planner_entry()]);
    config.models.roots = vec![models_dir(), root.0.clone()];
    let bus = TestBus::start(config);
    let c = &bus.client;
    let robot = json!({"robot": "tsukami_humanoid"});
    send(c, planner::SET_ROBOT, &robot);
    let (objs, places) = (objects(), placements());
    let mut failures = Vec::new();
    for (o_name, p_name) in SUBSET {
        let o = objs.iter().find(|o| o.name == o_name).expect(o_name);
        let p = places.iter().find(|p| p.name == p_name).expect(p_name);
        let path = root.0.join(format!("{o_name}.stl"));
        o.mesh.write_stl(&path).unwrap();
        let object = set_object(o, p, &path.display().to_string());
        let env = set_env(p);
        send(c, planner::SET_OBJECT, &object);
        send(c, planner::SET_ENV, &env);
        let reply = c.command(ROLE_GRASP_PLANNER, planner::PLAN, br#"{"seed": 1}"#, T);
        let Ok(bytes) = reply else {
            failures.push(format!("{o_name} on {p_name}: {reply:?}"));
            continue;
        };
        let reply: PlanReply = serde_json::from_slice(&bytes).expect("a plan reply");
        if TILTED.contains(&(o_name, p_name)) != reply.tilt.is_some() {
            failures.push(format!("{o_name} on {p_name}: tilt {:?}", reply.tilt));
        }
        let world = World::from_requests(
            &models_dir(),
            &serde_json::from_value::<SetRobot>(robot.clone()).unwrap(),
            &serde_json::from_value::<SetObject>(object.clone()).unwrap(),
            &serde_json::from_value::<SetEnv>(env.clone()).unwrap(),
        )
        .expect("the checker loads what the planner loaded");
        let verdict = verify(&world, &reply, &Tolerances::default());
        if !verdict.is_ok() {
            failures.push(format!(
                "{o_name} on {p_name}: returned a grasp that fails the check: {verdict}"
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
