//! The components end to end: the host (`tsukami run`), the vision
//! (`tsukami-vision serve`, its simulated head camera rendering the can scene) and the
//! controller (`tsukami-controller`) as separate processes on a real zenoh bus on
//! loopback: vision finds the can in a simulated depth image (within 5 mm and 3° of
//! the scene file's pose, modulo the can's spin), the planner plans with the detected
//! pose, the grasp posture goes to the controller
//! as a two-point trajectory, the controller's published state ends at the grasp;
//! killing the controller mid-run makes the execute request fail with a timeout
//! error; a restarted controller serves again. Once peer to peer, once with every
//! process connected through a zenoh router (`tsukami router`).
//!
//! A mock-only variant (in-process host, mock vision, mock controller) is the
//! headless planner test: it checks what the planner would send to the robot.

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use tsukami::bus::{free_loopback_port, BusConfig};
use tsukami::client::{BusClient, RequestError};
use tsukami::demo::motion::StateStream;
use tsukami_bus::ComponentArgs;
use tsukami_e2e::mocks::{MockController, MockVision};
use tsukami_e2e::{
    component_exe, models_dir, planner_entry, plugin_file, spawn_tsukami, test_config, ChildGuard,
    TestBus,
};
use tsukami_msgs::controller::{ControllerState, ExecuteReply, ExecutionOutcome};
use tsukami_msgs::keys::{planner, ROLE_GRASP_PLANNER, ROLE_TRAJECTORY_PLANNER};
use tsukami_msgs::motion::MotionExecuteReply;
use tsukami_msgs::motion::{JointTrajectory, TrajectoryPoint};
use tsukami_msgs::vision::ObjectPose;
use tsukami_msgs::Pose;
use tsukami_scenes::{scene_requests, SceneRequests};

const T: Duration = Duration::from_secs(60);
/// How much faster than real time the controller runs in these tests.
const SPEED: &str = "20";

/// How the processes of one test meet.
struct Topology {
    namespace: String,
    /// Extra arguments of `tsukami run`.
    host_args: Vec<String>,
    /// Bus arguments of `tsukami-controller`.
    controller_args: Vec<String>,
    /// Bus arguments of `tsukami-vision serve`.
    vision_args: Vec<String>,
    client: BusConfig,
    _router: Option<ChildGuard>,
    dir: PathBuf,
}

fn endpoint(port: u16) -> String {
    format!("tcp/127.0.0.1:{port}")
}

fn scratch_dir(tag: &str, port: u16) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tsukami-{tag}-{port}"));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Peer to peer: the host, the controller and the vision each listen on a port of
/// their own; the components connect to the host, the client to all three.
fn peer_to_peer() -> Topology {
    let (host, controller, vision) = (
        endpoint(free_loopback_port().unwrap()),
        endpoint(free_loopback_port().unwrap()),
        endpoint(free_loopback_port().unwrap()),
    );
    let port = free_loopback_port().unwrap();
    let namespace = format!("p2p-{port}");
    Topology {
        host_args: vec!["--listen".into(), host.clone()],
        controller_args: ["--listen", &controller, "--connect", &host]
            .map(String::from)
            .to_vec(),
        vision_args: ["--listen", &vision, "--connect", &host]
            .map(String::from)
            .to_vec(),
        client: BusConfig {
            connect: vec![host, controller, vision],
            ..BusConfig::connecting("tcp/127.0.0.1:1")
        },
        namespace,
        _router: None,
        dir: scratch_dir("p2p", port),
    }
}

/// Through a router: `tsukami router` on loopback, every process a zenoh client of
/// it, configured by a zenoh json5 file (as on two machines, see docs/components.md).
fn through_router() -> Topology {
    let port = free_loopback_port().unwrap();
    let router = spawn_tsukami(&["router", "--listen", &endpoint(port)]);
    let dir = scratch_dir("router", port);
    let config = dir.join("client.json5");
    std::fs::write(
        &config,
        format!(
            "{{\n  mode: \"client\",\n  connect: {{ endpoints: [\"{}\"] }},\n  scouting: {{ multicast: {{ enabled: false }}, gossip: {{ enabled: false }} }},\n}}\n",
            endpoint(port)
        ),
    )
    .unwrap();
    let client = BusConfig {
        zenoh_config: Some(config.clone()),
        ..BusConfig::connecting("tcp/127.0.0.1:1")
    };
    wait_for_router(&client);
    let namespace = format!("router-{port}");
    let file = config.display().to_string();
    Topology {
        host_args: vec!["--zenoh-config".into(), file.clone()],
        controller_args: vec!["--zenoh-config".into(), file.clone()],
        vision_args: vec!["--zenoh-config".into(), file],
        client,
        namespace,
        _router: Some(router),
        dir,
    }
}

/// A zenoh client cannot open its session before the router listens: retry.
fn wait_for_router(client: &BusConfig) {
    let start = Instant::now();
    while client.open().map(|s| drop(s)).is_err() {
        assert!(start.elapsed() < T, "the router never came up");
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn controller_exe() -> PathBuf {
    component_exe("tsukami-controller", "tsukami-controller")
}

/// `tsukami-vision serve` with its simulated head camera on the can scene (the
/// frame is rendered from `models/scenes/can_breast.toml`, 1 mm depth noise).
fn spawn_vision(t: &Topology) -> ChildGuard {
    let models = models_dir().display().to_string();
    let scene = models_dir()
        .join("scenes/can_breast.toml")
        .display()
        .to_string();
    let mut args = vec![
        "serve",
        "--namespace",
        &t.namespace,
        "--models",
        &models,
        "--scene",
        &scene,
    ];
    args.extend(t.vision_args.iter().map(String::as_str));
    ChildGuard(
        Command::new(component_exe("tsukami-vision", "tsukami-vision"))
            .args(&args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawning tsukami-vision"),
    )
}

fn spawn_controller(t: &Topology) -> ChildGuard {
    let models = models_dir().display().to_string();
    let mut args = vec![
        "--namespace",
        &t.namespace,
        "--models-dir",
        &models,
        "--speed",
        SPEED,
    ];
    args.extend(t.controller_args.iter().map(String::as_str));
    ChildGuard(
        Command::new(controller_exe())
            .args(&args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawning tsukami-controller"),
    )
}

fn spawn_host(t: &Topology) -> ChildGuard {
    spawn_host_with(t, &[("grasp-planner", "tsukami_grasp_planner")])
}

/// `tsukami run` over `t` with the plugins `(role, library)`.
fn spawn_host_with(t: &Topology, plugins: &[(&str, &str)]) -> ChildGuard {
    let config = t.dir.join("host.toml");
    let mut text = format!("namespace = \"{}\"\n", t.namespace);
    for (role, lib) in plugins {
        text += &format!(
            "\n[[plugin]]\nrole = \"{role}\"\npath = {:?}\n[plugin.config]\nmodels_dir = {:?}\n",
            plugin_file(lib),
            models_dir()
        );
    }
    std::fs::write(&config, text).unwrap();
    let mut args = vec![
        "run",
        "--config",
        config.to_str().unwrap(),
        "--namespace",
        &t.namespace,
    ];
    args.extend(t.host_args.iter().map(String::as_str));
    spawn_tsukami(&args)
}

fn can_scene() -> SceneRequests {
    scene_requests(&models_dir().join("scenes/can_breast.toml")).unwrap()
}

fn json(reply: Result<Vec<u8>, RequestError>) -> serde_json::Value {
    serde_json::from_slice(&reply.expect("a reply")).expect("reply is JSON")
}

/// Vision → SetObject → Plan: the detected pose and the planned joint positions.
fn detect_and_plan(
    client: &BusClient,
    scene: &SceneRequests,
) -> (ObjectPose, serde_json::Map<String, serde_json::Value>) {
    let keys = client.keys();
    let detected: ObjectPose = serde_json::from_value(json(client.request_key(
        &keys.vision_detect(),
        br#"{"object": "can_350ml", "seed": 1}"#,
        T,
    )))
    .unwrap();
    let send = |command: &str, payload: &serde_json::Value| {
        json(client.command(
            ROLE_GRASP_PLANNER,
            command,
            payload.to_string().as_bytes(),
            T,
        ))
    };
    send(
        planner::SET_ROBOT,
        &serde_json::to_value(&scene.robot).unwrap(),
    );
    let mut object = serde_json::to_value(&scene.object).unwrap();
    object["pose"] = serde_json::to_value(detected.pose).unwrap();
    send(planner::SET_OBJECT, &object);
    send(planner::SET_ENV, &serde_json::to_value(&scene.env).unwrap());
    let plan = send(planner::PLAN, &serde_json::json!({"seed": 1}));
    let joints = plan["joint_positions"]
        .as_object()
        .expect("joint_positions")
        .clone();
    (detected, joints)
}

fn isometry(p: &Pose) -> Isometry3<f64> {
    let [x, y, z, w] = p.quaternion;
    Isometry3::from_parts(
        Translation3::from(Vector3::from(p.position)),
        UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)),
    )
}

/// Position (m) and orientation (rad) error of a detected can against the truth,
/// modulo its symmetry: the can reports a continuous axis (any spin about it is the
/// same can), so what counts is where its axis point goes and where its axis points
/// (under each of its discrete symmetries, if any).
fn can_error(detected: &ObjectPose, truth: &Pose) -> (f64, f64) {
    let symmetry = detected
        .symmetry
        .as_ref()
        .expect("the can reports its symmetry");
    let axis = symmetry.axis.as_ref().expect("the can has a symmetry axis");
    let (point, direction) = (
        Point3::from(axis.point),
        Vector3::from(axis.direction).normalize(),
    );
    let estimate = isometry(&detected.pose);
    let truth = isometry(truth);
    let identity = Pose {
        position: [0.0; 3],
        quaternion: [0.0, 0.0, 0.0, 1.0],
    };
    std::iter::once(&identity)
        .chain(&symmetry.discrete)
        .map(|g| {
            let t = truth * isometry(g);
            let dist = (estimate * point - t * point).norm();
            let angle = (estimate * direction).angle(&(t * direction));
            (dist, angle)
        })
        .fold((f64::INFINITY, f64::INFINITY), |best, e| {
            if e.1 < best.1 {
                e
            } else {
                best
            }
        })
}

/// From the controller's current state to `goal` (its joints the controller
/// drives), slow enough for every joint (at most 0.25 rad/s or m/s).
fn two_points(
    state: &ControllerState,
    goal: &serde_json::Map<String, serde_json::Value>,
    min_time: f64,
) -> JointTrajectory {
    let mut names = Vec::new();
    let (mut start, mut end) = (Vec::new(), Vec::new());
    for (name, value) in goal {
        if let Some(i) = state.joint_names.iter().position(|n| n == name) {
            names.push(name.clone());
            start.push(state.positions[i]);
            end.push(value.as_f64().unwrap());
        }
    }
    let widest = start
        .iter()
        .zip(&end)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let time = (widest / 0.25).max(min_time);
    let point = |time: f64, positions: Vec<f64>| TrajectoryPoint {
        time,
        positions,
        velocities: vec![],
        phase: String::new(),
        command: vec![],
    };
    JointTrajectory {
        joint_names: names,
        points: vec![point(0.0, start), point(time, end)],
    }
}

fn current_state(client: &BusClient) -> ControllerState {
    let bytes = client
        .wait_for(&client.keys().controller_state(), T)
        .expect("the controller answers its state");
    serde_json::from_slice(&bytes).unwrap()
}

fn execute(
    client: &BusClient,
    trajectory: &JointTrajectory,
    timeout: Duration,
) -> Result<ExecuteReply, RequestError> {
    let request = serde_json::json!({ "trajectory": trajectory });
    client
        .request_key(
            &client.keys().controller_execute(),
            request.to_string().as_bytes(),
            timeout,
        )
        .map(|bytes| serde_json::from_slice(&bytes).unwrap())
}

/// Runs `trajectory` and checks that the reply and the last published state end at
/// its last point.
fn execute_to_the_end(client: &BusClient, states: &StateStream, trajectory: &JointTrajectory) {
    let reply = execute(client, trajectory, T).unwrap();
    assert!(reply.accepted, "{:?}", reply.reason);
    assert_eq!(reply.outcome, Some(ExecutionOutcome::Done));
    let goal = &trajectory.points[1].positions;
    let end = reply.state.unwrap();
    let last_published = loop {
        let state = states.next(T).expect("states are published");
        if state.tick == end.tick {
            break state;
        }
    };
    assert_eq!(last_published.status, "done");
    for (name, want) in trajectory.joint_names.iter().zip(goal) {
        let i = end.joint_names.iter().position(|n| n == name).unwrap();
        assert!((end.positions[i] - want).abs() < 1e-6, "{name}");
        assert!((last_published.positions[i] - want).abs() < 1e-6, "{name}");
    }
}

/// The whole run over `t`.
fn vision_plan_execute_kill_restart(t: Topology) {
    let _host = spawn_host(&t);
    let mut controller = spawn_controller(&t);
    let _vision = spawn_vision(&t);
    let scene = can_scene();
    let client = BusClient::connect(&t.client, &t.namespace).unwrap();
    client.wait_for_host(T).unwrap();
    let info = client.wait_for_component("controller", T).unwrap();
    assert_eq!(info.version, env!("CARGO_PKG_VERSION"));
    client.wait_for_component("vision", T).unwrap();
    // `<ns>/*/info` lists both components (each answers on its own key).
    let listed = client.components(Duration::from_secs(5)).unwrap();
    let names: Vec<&str> = listed.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["controller", "vision"], "{listed:?}");
    let states = StateStream::subscribe(&client).unwrap();

    let (detected, goal) = detect_and_plan(&client, &scene);
    let (dist, angle) = can_error(&detected, &scene.object.pose);
    assert!(
        dist < 0.005 && angle.to_degrees() < 3.0,
        "the can detected {:.2} mm and {:.2}° off the scene's pose: {detected:?}",
        dist * 1e3,
        angle.to_degrees()
    );
    assert!(detected.confidence >= 0.8, "{detected:?}");
    let rest = current_state(&client);
    let to_grasp = two_points(&rest, &goal, 1.0);
    execute_to_the_end(&client, &states, &to_grasp);

    // Kill the controller mid-run: the request fails with a timeout, it does not hang.
    let back = two_points(&current_state(&client), &to_grasp_start(&to_grasp), 200.0);
    let timeout = Duration::from_secs(5);
    let started = Instant::now();
    let failed = std::thread::scope(|s| {
        let request = s.spawn(|| execute(&client, &back, timeout));
        while states.next(T).expect("states").status != "executing" {}
        controller.0.kill().unwrap();
        controller.0.wait().unwrap();
        request.join().unwrap()
    });
    assert!(
        matches!(failed, Err(RequestError::Timeout { .. })),
        "{failed:?}"
    );
    assert!(
        started.elapsed() < timeout + Duration::from_secs(5),
        "{:?}",
        started.elapsed()
    );

    // A restarted controller serves again (from its rest state: a new process).
    let _controller = spawn_controller(&t);
    client.wait_for_component("controller", T).unwrap();
    let again = two_points(&current_state(&client), &goal, 1.0);
    execute_to_the_end(&client, &states, &again);
}

/// The start of a two-point trajectory as a goal map.
fn to_grasp_start(trajectory: &JointTrajectory) -> serde_json::Map<String, serde_json::Value> {
    trajectory
        .joint_names
        .iter()
        .zip(&trajectory.points[0].positions)
        .map(|(n, &q)| (n.clone(), q.into()))
        .collect()
}

#[test]
fn vision_plan_and_controller_peer_to_peer() {
    vision_plan_execute_kill_restart(peer_to_peer());
}

#[test]
fn vision_plan_and_controller_through_a_router() {
    vision_plan_execute_kill_restart(through_router());
}

/// `motion/execute` on a real controller: the can at breast height is
/// planned, then one call plans its motion from the controller's state and runs
/// it; the reply carries the motion and the controller's outcome, and the
/// controller ends at the motion's last point.
#[test]
fn motion_execute_plans_and_runs_on_the_controller() {
    let t = peer_to_peer();
    let _host = spawn_host_with(
        &t,
        &[
            ("grasp-planner", "tsukami_grasp_planner"),
            ("trajectory-planner", "tsukami_trajectory_planner"),
        ],
    );
    let _controller = spawn_controller(&t);
    let client = BusClient::connect(&t.client, &t.namespace).unwrap();
    client.wait_for_host(T).unwrap();
    client.wait_for_component("controller", T).unwrap();
    let scene = tsukami_scenes::paper_scene("can_breast").unwrap();
    let outcome = tsukami::scenes::run_scene(&client, &models_dir(), scene, 0, T);
    let grasp = outcome.result.expect("the can is grasped");
    let request =
        serde_json::json!({ "plan": { "grasp": grasp, "seed": 1, "retreat_distance": 0.05 } });
    let bytes = client
        .command(
            ROLE_TRAJECTORY_PLANNER,
            "execute",
            request.to_string().as_bytes(),
            T,
        )
        .expect("motion/execute answers");
    let reply: MotionExecuteReply = serde_json::from_slice(&bytes).unwrap();
    assert_eq!(reply.plan.start_source, "controller");
    let mut phases: Vec<&str> = reply
        .plan
        .trajectory
        .points
        .iter()
        .map(|p| p.phase.as_str())
        .collect();
    phases.dedup();
    assert_eq!(phases, ["reach", "approach", "close", "lift", "retreat"]);
    let run = &reply.execution;
    assert!(run.accepted, "{:?}", run.reason);
    assert_eq!(run.outcome, Some(ExecutionOutcome::Done));
    let end = run.state.as_ref().expect("the final state");
    let t = &reply.plan.trajectory;
    let last = t.points.last().unwrap();
    for (k, name) in t.joint_names.iter().enumerate() {
        let i = end.joint_names.iter().position(|n| n == name).unwrap();
        assert!(
            (end.positions[i] - last.positions[k]).abs() < 1e-6,
            "{name}"
        );
        // The squeezed fingers stay commanded beyond contact.
        let commanded = last.command.get(k).unwrap_or(&last.positions[k]);
        assert!(
            (end.commanded[i] - commanded).abs() < 1e-6,
            "{name} commanded"
        );
    }
    // A bad request names its field; the plugin keeps serving.
    let bad = serde_json::json!({ "plan": { "grasp": grasp, "retreat_distance": 1.0 } });
    let e = client
        .command(
            ROLE_TRAJECTORY_PLANNER,
            "execute",
            bad.to_string().as_bytes(),
            T,
        )
        .unwrap_err();
    assert!(format!("{e:?}").contains("retreat_distance"), "{e:?}");
}

#[test]
fn headless_plan_with_mock_components() {
    let bus = TestBus::start(test_config(vec![planner_entry()]));
    // Peer to peer: each mock listens on a port of its own, the client connects to
    // the host and to both.
    let namespace = bus.client.keys().namespace().to_owned();
    let listening = |port: u16| ComponentArgs {
        listen: vec![endpoint(port)],
        ..ComponentArgs::connecting(&namespace, &bus.endpoint)
    };
    let (vision_args, controller_args) = (
        listening(free_loopback_port().unwrap()),
        listening(free_loopback_port().unwrap()),
    );
    let scene = can_scene();
    let vision = MockVision::start(&vision_args, "can_350ml", scene.object.pose).unwrap();
    let controller = MockController::start(&controller_args).unwrap();
    let client_bus = BusConfig {
        connect: vec![
            bus.endpoint.clone(),
            vision_args.listen[0].clone(),
            controller_args.listen[0].clone(),
        ],
        ..BusConfig::connecting("tcp/127.0.0.1:1")
    };
    let client = BusClient::connect(&client_bus, &namespace).unwrap();
    client.wait_for_host(T).unwrap();
    client.wait_for_component("vision", T).unwrap();
    client.wait_for_component("controller", T).unwrap();
    // The mock vision says what the real one says of an object it cannot see.
    let missing = client
        .request_key(
            &client.keys().vision_detect(),
            br#"{"object": "pet_bottle"}"#,
            T,
        )
        .unwrap_err();
    assert_eq!(missing.code(), Some(tsukami_msgs::ErrorCode::Infeasible));

    let (detected, goal) = detect_and_plan(&client, &scene);
    assert_eq!(detected.pose, scene.object.pose);
    let rest = ControllerState {
        joint_names: goal.keys().cloned().collect(),
        positions: vec![0.0; goal.len()],
        commanded: vec![],
        status: "idle".into(),
        time: 0.0,
        velocities: vec![],
        tick: 0,
        trajectory_time: None,
    };
    let trajectory = two_points(&rest, &goal, 1.0);
    let reply = execute(&client, &trajectory, T).unwrap();
    assert_eq!(reply.outcome, Some(ExecutionOutcome::Done));
    let received = controller.wait_for(1, T);
    assert_eq!(received.len(), 1);
    assert_eq!(received[0].trajectory, trajectory);
    // The planner's grasp reaches the controller unchanged.
    for (name, q) in trajectory
        .joint_names
        .iter()
        .zip(&received[0].trajectory.points[1].positions)
    {
        assert_eq!(goal[name].as_f64().unwrap(), *q);
    }
    vision.close();
    controller.close();
}
