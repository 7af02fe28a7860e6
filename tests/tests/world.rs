//! One world for every plugin, over a real bus: two planners loaded under two
//! roles see one `set_object` at one version; a refused change reaches none;
//! `<ns>/planner/set_*` is the same world; a change arriving mid-plan does not
//! touch the plan under way; a second robot, added as data only, plans.

use std::time::Duration;

use serde_json::{json, Value};
use tsukami::client::BusClient;
use tsukami_e2e::{grasp_planner_entry, models_dir, plugin_entry, test_config, TestBus};
use tsukami_msgs::keys::ROLE_GRASP_PLANNER;
use zenoh::Wait;

const T: Duration = Duration::from_secs(60);
const ANTIPODAL: &str = "tsukami-antipodal-planner";
const CAN: &str = r#"{"shape": {"model": {"name": "can_350ml"}}, "mass": 0.15, "pose": {"position": [0.45, -0.25, 1.05]}}"#;

fn two_planners() -> TestBus {
    let mut second = plugin_entry(ANTIPODAL, "tsukami_antipodal_planner");
    second.config = grasp_planner_entry("tsukami_antipodal_planner").config;
    TestBus::start(test_config(vec![
        grasp_planner_entry("tsukami_grasp_planner"),
        second,
    ]))
}

fn world(
    c: &BusClient,
    command: &str,
    payload: &str,
) -> Result<Value, tsukami::client::RequestError> {
    let bytes = c.request_key(&c.keys().world(command), payload.as_bytes(), T)?;
    Ok(serde_json::from_slice(&bytes).unwrap())
}

fn plan(c: &BusClient, role: &str, payload: &str) -> Result<Value, tsukami::client::RequestError> {
    let bytes = c.command(role, "plan", payload.as_bytes(), T)?;
    Ok(serde_json::from_slice(&bytes).unwrap())
}

#[test]
fn one_set_object_is_seen_by_both_planners() {
    let bus = two_planners();
    let c = &bus.client;
    world(c, "set_robot", r#"{"robot": "tsukami_humanoid"}"#).unwrap();
    let object = world(c, "set_object", CAN).unwrap();
    let v = object["world_version"].as_u64().unwrap();
    assert_eq!(v, 2);
    for role in [ROLE_GRASP_PLANNER, ANTIPODAL] {
        let r = plan(c, role, r#"{"seed": 1}"#).unwrap_or_else(|e| panic!("{role}: {e}"));
        assert_eq!(r["world_version"], v, "{role}");
        assert_eq!(
            r["object"]["center_of_mass"], object["center_of_mass"],
            "{role}"
        );
        assert_eq!(r["force_closure"]["exact_resists_weight"], true, "{role}");
    }
    // A change one planner refuses reaches none, and the version stays.
    let bad = CAN.replace("0.15", "-1");
    let e = world(c, "set_object", &bad).unwrap_err();
    assert_eq!(e.code(), Some(tsukami_msgs::ErrorCode::InvalidValue), "{e}");
    let state = world(c, "get", "{}").unwrap();
    assert_eq!(state["version"], v);
    assert_eq!(state["object"]["mass"], 0.15);
    assert_eq!(state["plugins"], json!([ROLE_GRASP_PLANNER, ANTIPODAL]));
    // The old key is the same world: both planners see the moved can.
    let moved = CAN.replace("0.45", "0.5");
    let r = c
        .command(ROLE_GRASP_PLANNER, "set_object", moved.as_bytes(), T)
        .unwrap();
    let r: Value = serde_json::from_slice(&r).unwrap();
    assert_eq!(r["world_version"], v + 1);
    let p = plan(c, ANTIPODAL, r#"{"seed": 1}"#).unwrap();
    assert_eq!(p["world_version"], v + 1);
    assert_eq!(p["object"]["center_of_mass"], r["center_of_mass"]);
}

#[test]
fn a_set_object_mid_plan_leaves_the_plan_on_its_world() {
    let bus = two_planners();
    let c = &bus.client;
    world(c, "set_robot", r#"{"robot": "tsukami_humanoid"}"#).unwrap();
    let v = world(c, "set_object", CAN).unwrap()["world_version"]
        .as_u64()
        .unwrap();
    let progress = c
        .session()
        .declare_subscriber(c.keys().progress(ROLE_GRASP_PLANNER))
        .wait()
        .unwrap();
    // A plan that cannot succeed (δf out of reach) runs until stopped.
    let hopeless = r#"{"delta_f": 1000.0, "max_samples": 10000, "max_candidates": 1000}"#;
    std::thread::scope(|s| {
        let running = s.spawn(|| plan(c, ROLE_GRASP_PLANNER, hopeless));
        progress
            .recv_timeout(T)
            .unwrap()
            .expect("the plan reports progress");
        let moved = world(c, "set_object", &CAN.replace("0.45", "0.5")).unwrap();
        assert_eq!(moved["world_version"], v + 1);
        let stop = c.command(ROLE_GRASP_PLANNER, "stop", b"{}", T).unwrap();
        assert_eq!(
            serde_json::from_slice::<Value>(&stop).unwrap()["stopped"],
            true
        );
        let e = running.join().unwrap().unwrap_err();
        assert_eq!(e.code(), Some(tsukami_msgs::ErrorCode::Cancelled), "{e}");
        let tsukami::client::RequestError::Reply(r) = e else {
            unreachable!()
        };
        assert_eq!(
            r.error.details.unwrap()["world_version"],
            v,
            "the plan under way saw the change"
        );
    });
    let p = plan(c, ROLE_GRASP_PLANNER, r#"{"seed": 1}"#).unwrap();
    assert_eq!(p["world_version"], v + 1);
}

#[test]
fn a_second_robot_plans_from_its_description_alone() {
    assert!(models_dir()
        .join("robots/tsukami_arm7/description.toml")
        .is_file());
    let bus = TestBus::start(test_config(vec![grasp_planner_entry(
        "tsukami_grasp_planner",
    )]));
    let c = &bus.client;
    let robot = world(c, "set_robot", r#"{"robot": "tsukami_arm7"}"#).unwrap();
    assert_eq!(robot["name"], "tsukami_arm7");
    assert_eq!(robot["body_joints"], json!([]));
    world(c, "set_object", CAN).unwrap();
    let p = plan(c, ROLE_GRASP_PLANNER, r#"{"seed": 1}"#).unwrap();
    assert_eq!(p["force_closure"]["exact_resists_weight"], true);
    assert_eq!(p["joints_used"], json!([]));
    assert!(p["joint_positions"].get("waist_yaw").is_none());
}

/// `world_prepare`, `world_commit` and `world_abort` are the host's own
/// commands to its plugins: a client sending them on any role's keys, with a
/// made-up version and a moved object, is refused, and nothing changes —
/// `world/get`, a grasp plan and a motion plan all stay on the world the host
/// holds.
#[test]
fn host_to_plugin_world_commands_are_not_bus_commands() {
    use tsukami_e2e::{motion_entry, planner_entry, viewer_entry};
    use tsukami_msgs::host::{WorldChange, WorldPrepare, WorldVersion};
    use tsukami_msgs::keys::{world as wk, ROLE_RESULT_VIEWER, ROLE_TRAJECTORY_PLANNER};
    let bus = TestBus::start(test_config(vec![
        planner_entry(),
        motion_entry(),
        viewer_entry(),
    ]));
    let c = &bus.client;
    world(c, "set_robot", r#"{"robot": "tsukami_humanoid"}"#).unwrap();
    let object = world(c, "set_object", CAN).unwrap();
    let v = object["world_version"].as_u64().unwrap();
    let moved = serde_json::from_str(&CAN.replace("0.45", "0.60")).unwrap();
    let forged = WorldPrepare {
        version: v + 40,
        change: WorldChange::SetObject(moved),
    };
    let prepare = serde_json::to_vec(&forged).unwrap();
    let commit = serde_json::to_vec(&WorldVersion { version: v + 40 }).unwrap();
    for role in [
        ROLE_GRASP_PLANNER,
        ROLE_TRAJECTORY_PLANNER,
        ROLE_RESULT_VIEWER,
    ] {
        for (command, payload) in [
            (wk::PREPARE, &prepare),
            (wk::COMMIT, &commit),
            (wk::ABORT, &commit),
        ] {
            let e = c.command(role, command, payload, T).unwrap_err();
            assert_eq!(
                e.code(),
                Some(tsukami_msgs::ErrorCode::UnknownCommand),
                "{role}/{command}: {e}"
            );
            assert!(e.to_string().contains(command), "{role}/{command}: {e}");
        }
    }
    let state = world(c, "get", "{}").unwrap();
    assert_eq!(state["version"], v);
    assert_eq!(
        state["object"]["pose"]["position"],
        json!([0.45, -0.25, 1.05])
    );
    let grasp = plan(c, ROLE_GRASP_PLANNER, r#"{"seed": 1}"#).unwrap();
    assert_eq!(grasp["world_version"], v);
    assert_eq!(grasp["object"]["center_of_mass"], object["center_of_mass"]);
    // The trajectory planner still holds version v: it takes the grasp of v.
    let request = serde_json::to_vec(&json!({ "grasp": grasp, "seed": 1 })).unwrap();
    let motion = c
        .command(ROLE_TRAJECTORY_PLANNER, "plan", &request, T)
        .unwrap_or_else(|e| panic!("the motion of the grasp of version {v}: {e}"));
    let motion: Value = serde_json::from_slice(&motion).unwrap();
    assert_eq!(motion["world_version"], v);
}
