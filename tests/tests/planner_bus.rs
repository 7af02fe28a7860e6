//! The grasp-planner plugin over the bus: bad input gets clear errors and keeps the
//! state; Stop interrupts a Plan; progress is published; the default config finds
//! the plugin beside the executable.

use std::time::{Duration, Instant};
use tsukami::client::{BusClient, RequestError};
use tsukami_e2e::{
    cli_plugins_listing, models_dir, planner_entry, spawn_tsukami, test_config, TestBus,
};
use tsukami_msgs::keys::{planner, ROLE_GRASP_PLANNER};
use tsukami_msgs::ErrorCode;
use tsukami_scenes::scene_requests;
use zenoh::Wait;

const T: Duration = Duration::from_secs(60);

fn send(c: &BusClient, command: &str, payload: &str) -> Result<serde_json::Value, RequestError> {
    c.command(ROLE_GRASP_PLANNER, command, payload.as_bytes(), T)
        .map(|bytes| serde_json::from_slice(&bytes).expect("reply is JSON"))
}

fn error(result: Result<serde_json::Value, RequestError>) -> tsukami_msgs::error::ErrorBody {
    match result {
        Err(RequestError::Reply(reply)) => reply.error,
        other => panic!("expected an error reply, got {other:?}"),
    }
}

fn set_up_can(c: &BusClient) -> serde_json::Value {
    let req = scene_requests(&models_dir().join("scenes/can_breast.toml")).unwrap();
    send(
        c,
        planner::SET_ROBOT,
        &serde_json::to_string(&req.robot).unwrap(),
    )
    .unwrap();
    let object = send(
        c,
        planner::SET_OBJECT,
        &serde_json::to_string(&req.object).unwrap(),
    )
    .unwrap();
    send(
        c,
        planner::SET_ENV,
        &serde_json::to_string(&req.env).unwrap(),
    )
    .unwrap();
    object
}

#[test]
fn plan_before_set_up_says_what_is_missing() {
    let bus = TestBus::start(test_config(vec![planner_entry()]));
    let e = error(send(&bus.client, planner::PLAN, "{}"));
    assert_eq!(e.code, ErrorCode::NotReady);
    assert!(e.message.contains("set_robot"), "{}", e.message);
}

#[test]
fn bad_objects_get_clear_errors_and_the_planner_keeps_its_state() {
    let bus = TestBus::start(test_config(vec![planner_entry()]));
    let c = &bus.client;
    let object = set_up_can(c);
    let can = r#"{"shape": {"model": {"name": "can_350ml"}}, "mass": 0.15, "pose": {"position": [0.4, -0.2, 1.1]}}"#;
    let cases = [
        (can.replace("0.15", "-1.0"), ErrorCode::InvalidValue, "mass"),
        (can.replace("0.15", "0.0"), ErrorCode::InvalidValue, "mass"),
        (can.replace("[0.4, -0.2, 1.1]", "[0.4, \"x\", 1.1]"), ErrorCode::InvalidRequest, "pose"),
        (can.replace("can_350ml", "no_such_can"), ErrorCode::ModelError, "no_such_can"),
        (can.replace("\"mass\"", "\"weight\""), ErrorCode::InvalidRequest, "weight"),
        (r#"{"shape": {"mesh": {"path": "/nonexistent/x.stl"}}, "mass": 0.1, "pose": {"position": [0.4, -0.2, 1.1]}}"#.to_owned(), ErrorCode::ModelError, "/nonexistent/x.stl"),
    ];
    for (payload, code, needle) in &cases {
        let e = error(send(c, planner::SET_OBJECT, payload));
        assert_eq!(e.code, *code, "{payload}: {}", e.message);
        assert!(
            e.message.contains(needle),
            "`{needle}` missing from: {}",
            e.message
        );
    }
    // NaN cannot be written in JSON; a non-unit zero quaternion is the closest bad pose.
    let e = error(send(
        c,
        planner::SET_OBJECT,
        &can.replace(
            "\"pose\": {\"position\": [0.4, -0.2, 1.1]}",
            "\"pose\": {\"position\": [0.4, -0.2, 1.1], \"quaternion\": [0, 0, 0, 0]}",
        ),
    ));
    assert_eq!(e.code, ErrorCode::InvalidValue, "{}", e.message);

    // The can set before is still the object: planning still finds its grasp.
    let plan = send(c, planner::PLAN, r#"{"seed": 3}"#).unwrap();
    assert_eq!(plan["grasp_type"]["style"], "fingertip4");
    assert_eq!(plan["object"]["mass"], object["mass"]);
}

#[test]
fn stop_interrupts_a_plan_and_progress_is_published() {
    // This host allows a huge sample budget (the default cap would refuse it), so
    // only Stop can end the plan below.
    let mut config = test_config(vec![planner_entry()]);
    config.limits.max_samples = 100_000_000;
    let bus = TestBus::start(config);
    let c = &bus.client;
    set_up_can(c);
    let progress = c
        .session()
        .declare_subscriber(c.keys().progress(ROLE_GRASP_PLANNER))
        .wait()
        .unwrap();
    // A plan that cannot succeed quickly: an impossible margin and a large budget.
    let hopeless = r#"{"delta_f": 1000.0, "max_samples": 100000000, "time_budget_ms": 600000, "max_candidates": 1000}"#;
    std::thread::scope(|scope| {
        let running = scope.spawn(|| send(c, planner::PLAN, hopeless));
        let first = progress.recv_timeout(T).unwrap().expect("a progress event");
        let event: serde_json::Value = serde_json::from_slice(&first.payload().to_bytes()).unwrap();
        assert!(event.get("phase").is_some(), "{event}");
        let sent = Instant::now();
        assert_eq!(send(c, "stop", "").unwrap()["stopped"], true);
        let e = error(running.join().unwrap());
        let latency = sent.elapsed();
        assert_eq!(e.code, ErrorCode::Cancelled, "{}", e.message);
        // Far below the 600 s budget: only the stop can have ended it.
        assert!(latency < Duration::from_secs(10), "{latency:?}");
    });
    // And the planner serves the next plan.
    assert_eq!(
        send(c, planner::PLAN, "{}").unwrap()["grasp_type"]["style"],
        "fingertip4"
    );
}

#[test]
fn the_default_config_serves_the_planner_found_beside_the_executable() {
    let port = tsukami::bus::free_loopback_port().unwrap();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let namespace = format!("default-{port}");
    let _host = spawn_tsukami(&["run", "--listen", &endpoint, "--namespace", &namespace]);
    let listing = cli_plugins_listing(&endpoint, &namespace);
    let plugins = listing["plugins"].as_array().unwrap();
    let planner = plugins
        .iter()
        .find(|p| p["roles"][0] == "grasp-planner")
        .expect("grasp-planner role");
    assert_eq!(planner["name"], "tsukami-grasp-planner");
    assert!(planner["version"].is_string());
}
