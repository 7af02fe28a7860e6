//! The plugin adapter in-process: JSON in, JSON out, bus error codes, progress
//! events through the host handle (a recording test host; no bus).

use std::path::Path;
use std::sync::atomic::AtomicBool;

use tsukami_grasp_planner::plugin::GraspPlannerPlugin;
use tsukami_msgs::planner::PlanReply;
use tsukami_plugin_api::offline::OfflineHost;
use tsukami_plugin_api::{CallContext, Plugin};
use tsukami_scenes::{scene_requests, verify, Tolerances, World};

#[test]
fn plans_the_can_through_the_plugin_interface() {
    let offline = OfflineHost::new();
    let host = offline.host();
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let config = format!("models_dir = {:?}", models.display().to_string());
    let plugin = GraspPlannerPlugin::new(host.clone(), &config).unwrap();
    let cancel = AtomicBool::new(false);
    let ctx = CallContext::new(&cancel, &host);
    let call = |c: &str, body: &str| plugin.call(c, body.as_bytes(), &ctx);

    // Plan before anything is set: not_ready, with the planner's reason.
    let e = call("plan", "{}").unwrap_err();
    assert_eq!(e.code, "not_ready");
    assert!(e.details_json.contains("no_robot"), "{}", e.details_json);
    // A misspelt field is refused by name.
    let e = call("set_robot", r#"{"robt": "tsukami_humanoid"}"#).unwrap_err();
    assert_eq!(e.code, "invalid_request");

    let req = scene_requests(&models.join("scenes/can_breast.toml")).unwrap();
    let robot: serde_json::Value = serde_json::from_slice(
        &call("set_robot", &serde_json::to_string(&req.robot).unwrap()).unwrap(),
    )
    .unwrap();
    assert_eq!(robot["grasp_types"].as_array().unwrap().len(), 9);
    let obj: serde_json::Value = serde_json::from_slice(
        &call("set_object", &serde_json::to_string(&req.object).unwrap()).unwrap(),
    )
    .unwrap();
    assert_eq!(obj["regions"].as_array().unwrap().len(), 1);
    call("set_env", &serde_json::to_string(&req.env).unwrap()).unwrap();
    let reply: serde_json::Value =
        serde_json::from_slice(&call("plan", r#"{"seed": 3}"#).unwrap()).unwrap();
    assert_eq!(reply["grasp_type"]["style"], "fingertip4");
    assert_eq!(
        reply["palm_pose"]["quaternion"].as_array().unwrap().len(),
        4
    );
    // The independent checker recomputes the exact test (and the rest) from the reply.
    let world = World::from_requests(&models, &req.robot, &req.object, &req.env).unwrap();
    let parsed: PlanReply = serde_json::from_value(reply.clone()).unwrap();
    let verdict = verify(&world, &parsed, &Tolerances::default());
    assert!(verdict.is_ok(), "{verdict}");
    assert!(reply["timing_ms"]["total"].as_f64().unwrap() > 0.0);
    let events = offline.progress();
    assert!(!events.is_empty());
    let last: serde_json::Value = serde_json::from_slice(events.last().unwrap()).unwrap();
    assert_eq!(last["phase"], "done");

    assert_eq!(
        call("frobnicate", "{}").unwrap_err().code,
        "unknown_command"
    );
}
