//! The plugin adapter in-process through the `Plugin` trait: JSON in, JSON
//! out, bus error codes, state kept on bad input, progress through a
//! recording test host, cancellation through the call's flag.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use tsukami_antipodal_planner::AntipodalPlugin;
use tsukami_msgs::planner::PlanReply;
use tsukami_plugin_api::offline::OfflineHost;
use tsukami_plugin_api::{CallContext, CallError, Host, Plugin};
use tsukami_scenes::{scene_requests, verify, SceneRequests, Tolerances, World};

fn models() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../models")
}

fn setup() -> (OfflineHost, Host, AntipodalPlugin) {
    let rec = OfflineHost::new();
    let host = rec.host();
    let config = format!("models_dir = {:?}", models().display().to_string());
    let plugin = AntipodalPlugin::new(host.clone(), &config).unwrap();
    (rec, host, plugin)
}

fn json<T: serde::Serialize>(v: &T) -> Vec<u8> {
    serde_json::to_vec(v).unwrap()
}

fn details(e: &CallError) -> serde_json::Value {
    serde_json::from_str(&e.details_json).unwrap()
}

/// The reply's grasp holds in the world `req` describes, by the independent
/// checker (exact test recomputed, contacts on the can, no link sunk in).
fn assert_holds(req: &SceneRequests, reply: &PlanReply) {
    let world = World::from_requests(&models(), &req.robot, &req.object, &req.env).unwrap();
    let verdict = verify(&world, reply, &Tolerances::default());
    assert!(verdict.is_ok(), "{verdict}");
}

#[test]
fn plans_can_breast_through_the_plugin_interface() {
    let (rec, host, plugin) = setup();
    let cancel = AtomicBool::new(false);
    let ctx = CallContext::new(&cancel, &host);
    let e = plugin.call("plan", b"{}", &ctx).unwrap_err();
    assert_eq!(e.code, "not_ready", "{e}");
    assert_eq!(details(&e)["missing"], "set_robot");

    let req = scene_requests(&models().join("scenes/can_breast.toml")).unwrap();
    let robot: serde_json::Value =
        serde_json::from_slice(&plugin.call("set_robot", &json(&req.robot), &ctx).unwrap())
            .unwrap();
    assert_eq!(robot["arm_joints"].as_array().unwrap().len(), 7);
    let e = plugin.call("plan", b"", &ctx).unwrap_err();
    assert_eq!(e.code, "not_ready");
    assert_eq!(details(&e)["missing"], "set_object");
    let object: serde_json::Value =
        serde_json::from_slice(&plugin.call("set_object", &json(&req.object), &ctx).unwrap())
            .unwrap();
    assert_eq!(object["regions"].as_array().unwrap().len(), 1);
    plugin.call("set_env", &json(&req.env), &ctx).unwrap();

    let reply: PlanReply =
        serde_json::from_slice(&plugin.call("plan", br#"{"seed": 3}"#, &ctx).unwrap()).unwrap();
    assert_holds(&req, &reply);
    assert_eq!(reply.contacts.len(), 3);
    let events = rec.progress();
    assert!(!events.is_empty());
    let last: serde_json::Value = serde_json::from_slice(events.last().unwrap()).unwrap();
    assert_eq!(last["phase"], "done");
}

#[test]
fn bad_input_names_the_field_and_keeps_state() {
    let (_rec, host, plugin) = setup();
    let cancel = AtomicBool::new(false);
    let ctx = CallContext::new(&cancel, &host);
    let req = scene_requests(&models().join("scenes/can_waist.toml")).unwrap();
    plugin.call("set_robot", &json(&req.robot), &ctx).unwrap();
    plugin.call("set_object", &json(&req.object), &ctx).unwrap();

    let mut bad = req.object.clone();
    bad.mass = -1.0;
    let e = plugin.call("set_object", &json(&bad), &ctx).unwrap_err();
    assert_eq!(e.code, "invalid_value");
    assert_eq!(details(&e)["field"], "mass");
    assert!(e.message.contains("mass"), "{e}");
    let e = plugin.call("set_object", br#"{"shape": {"model": {"name": "can_350ml"}}, "mass": 0.1, "pose": {"position": [0, 0, 0], "quaternion": [0, 0, 0, 0]}}"#, &ctx).unwrap_err();
    assert_eq!(e.code, "invalid_value");
    assert_eq!(details(&e)["field"], "pose.quaternion");
    let e = plugin.call("set_object", br#"{"shape": {"model": {"name": "teapot"}}, "mass": 0.1, "pose": {"position": [0, 0, 0]}}"#, &ctx).unwrap_err();
    assert_eq!(e.code, "model_error");
    assert_eq!(details(&e)["field"], "shape.model.name");
    assert!(e.message.contains("teapot"), "{e}");
    let e = plugin
        .call(
            "set_object",
            br#"{"shape": {"model": {"name": "can_350ml"}}, "mas": 0.1}"#,
            &ctx,
        )
        .unwrap_err();
    assert_eq!(e.code, "invalid_request");
    let e = plugin
        .call("set_robot", br#"{"robot": "no_such_robot"}"#, &ctx)
        .unwrap_err();
    assert_eq!(e.code, "model_error");
    let e = plugin
        .call("set_env", br#"{"obstacles": [{"name": "ok", "shape": {"sphere": {"radius": 0.1}}, "pose": {"position": [2, 0, 0]}}, {"name": "flat", "shape": {"box": {"size": [1, 0, 1]}}, "pose": {"position": [0, 0, 0]}}]}"#, &ctx)
        .unwrap_err();
    assert_eq!(e.code, "invalid_value");
    assert_eq!(details(&e)["field"], "obstacles[1].shape");
    let e = plugin
        .call("remove_env", br#"{"names": ["ghost"]}"#, &ctx)
        .unwrap_err();
    assert_eq!(e.code, "invalid_value");
    assert_eq!(details(&e)["field"], "names[0]");
    let e = plugin
        .call("plan", br#"{"max_samples": 0}"#, &ctx)
        .unwrap_err();
    assert_eq!(e.code, "invalid_value");
    assert_eq!(details(&e)["field"], "max_samples");
    let e = plugin
        .call("plan", br#"{"grasp_types": ["envelope4_large"]}"#, &ctx)
        .unwrap_err();
    assert_eq!(e.code, "infeasible");
    let e = plugin.call("fly", b"{}", &ctx).unwrap_err();
    assert_eq!(e.code, "unknown_command");

    // None of the bad requests changed the state: no obstacle was added
    // (the half-valid set_env added nothing) and the can still plans.
    let env: serde_json::Value = serde_json::from_slice(
        &plugin
            .call("remove_env", br#"{"all": true}"#, &ctx)
            .unwrap(),
    )
    .unwrap();
    assert_eq!(env["obstacles"].as_array().unwrap().len(), 0);
    plugin.call("set_env", &json(&req.env), &ctx).unwrap();
    let reply: PlanReply =
        serde_json::from_slice(&plugin.call("plan", b"{}", &ctx).unwrap()).unwrap();
    assert!(
        (reply.object.mass - 0.15).abs() < 1e-12,
        "object was replaced by a bad request"
    );
    assert_holds(&req, &reply);
}

#[test]
fn a_cancel_raised_mid_plan_stops_it() {
    let (rec, host, plugin) = setup();
    let cancel = AtomicBool::new(false);
    let ctx = CallContext::new(&cancel, &host);
    let req = scene_requests(&models().join("scenes/can_breast.toml")).unwrap();
    plugin.call("set_robot", &json(&req.robot), &ctx).unwrap();
    // A nearly frictionless can: no sample can hold it, so only the cancel flag
    // (raised once the plan has reported progress) ends the search early.
    let mut slippery = req.object.clone();
    slippery.friction = Some(0.01);
    plugin.call("set_object", &json(&slippery), &ctx).unwrap();
    let max_samples = 200_000;
    let options = format!(r#"{{"max_samples": {max_samples}}}"#);
    let e = std::thread::scope(|s| {
        s.spawn(|| {
            // Wait for the plan's first progress event, then raise the flag.
            while rec.progress().is_empty() {
                std::thread::yield_now();
            }
            cancel.store(true, std::sync::atomic::Ordering::Relaxed);
        });
        plugin.call("plan", options.as_bytes(), &ctx).unwrap_err()
    });
    assert_eq!(e.code, "cancelled", "{e}");
    // It stopped in the middle: after some progress, well before its budget.
    let events = rec.progress();
    assert!(!events.is_empty());
    let last: serde_json::Value = serde_json::from_slice(events.last().unwrap()).unwrap();
    assert!(
        last["samples"].as_u64().unwrap() < max_samples,
        "last progress {last}"
    );
}

#[test]
fn an_unreachable_object_is_infeasible() {
    let (_rec, host, plugin) = setup();
    let cancel = AtomicBool::new(false);
    let ctx = CallContext::new(&cancel, &host);
    let req = scene_requests(&models().join("scenes/can_breast.toml")).unwrap();
    plugin.call("set_robot", &json(&req.robot), &ctx).unwrap();
    let mut far = req.object.clone();
    far.pose.position = [3.0, -0.25, 1.1];
    plugin.call("set_object", &json(&far), &ctx).unwrap();
    let e = plugin
        .call(
            "plan",
            br#"{"max_samples": 20, "whole_body": "arm_only"}"#,
            &ctx,
        )
        .unwrap_err();
    assert_eq!(e.code, "infeasible", "{e}");
    assert_eq!(details(&e)["samples"], 20);
    assert!(e.message.contains("out of reach"), "{e}");
}
