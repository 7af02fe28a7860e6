//! The controller on a real zenoh bus on loopback: requests, rejections with their
//! reasons, published states that follow the trajectory at every sample time, stop
//! within one control period, and a clean exit on SIGTERM.

use std::path::Path;
use std::process::Command;
use std::sync::mpsc;
use std::time::Duration;
use tsukami_bus::{free_loopback_port, BusClient, BusConfig, ComponentArgs, RequestError};
use tsukami_controller::{ControllerNode, Executor, JointTable, NodeOptions};
use tsukami_msgs::controller::{ControllerState, ExecuteReply, ExecutionOutcome};
use tsukami_msgs::host::StopReply;
use tsukami_msgs::motion::{JointTrajectory, TrajectoryPoint};
use tsukami_msgs::ErrorCode;
use zenoh::Wait;

const T: Duration = Duration::from_secs(30);

fn models() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

/// A controller node in this process on a free port, and a client connected to it.
fn controller(speed: f64) -> (ControllerNode, BusClient) {
    let port = free_loopback_port().unwrap();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let namespace = format!("ctl-{port}");
    let args = ComponentArgs {
        listen: vec![endpoint.clone()],
        connect: vec![],
        ..ComponentArgs::connecting(&namespace, &endpoint)
    };
    let table = JointTable::load("tsukami_humanoid", &models()).unwrap();
    let executor = Executor::new(table, 100.0, None).unwrap();
    let options = NodeOptions {
        speed,
        start_tolerance: 0.01,
    };
    let node = tsukami_controller::start(&args, executor, options).unwrap();
    let client = BusClient::connect(&BusConfig::connecting(&endpoint), &namespace).unwrap();
    client.wait_for_component("controller", T).unwrap();
    (node, client)
}

fn line(joint: &str, from: f64, to: f64, time: f64) -> JointTrajectory {
    let point = |time: f64, q: f64| TrajectoryPoint {
        time,
        positions: vec![q],
        velocities: vec![],
        phase: String::new(),
    };
    JointTrajectory {
        joint_names: vec![joint.into()],
        points: vec![point(0.0, from), point(time, to)],
    }
}

fn execute(client: &BusClient, trajectory: &JointTrajectory) -> Result<ExecuteReply, RequestError> {
    let request = serde_json::json!({ "trajectory": trajectory });
    client
        .request_key(
            &client.keys().controller_execute(),
            request.to_string().as_bytes(),
            T,
        )
        .map(|bytes| serde_json::from_slice(&bytes).unwrap())
}

fn states(
    client: &BusClient,
) -> (
    zenoh::pubsub::Subscriber<()>,
    mpsc::Receiver<ControllerState>,
) {
    let (tx, rx) = mpsc::channel();
    let tx = std::sync::Mutex::new(tx);
    let subscriber = client
        .session()
        .declare_subscriber(client.keys().controller_state())
        .callback(move |sample| {
            let state = serde_json::from_slice(&sample.payload().to_bytes()).unwrap();
            let _ = tx.lock().unwrap().send(state);
        })
        .wait()
        .unwrap();
    (subscriber, rx)
}

fn elbow(state: &ControllerState) -> f64 {
    state.positions[state
        .joint_names
        .iter()
        .position(|n| n == "r_elbow")
        .unwrap()]
}

#[test]
fn rejections_say_why_and_runs_follow_the_trajectory() {
    let (node, client) = controller(20.0);
    let info = client.wait_for_component("controller", T).unwrap();
    for key in ["execute", "stop", "state", "info"] {
        assert!(
            info.keys
                .iter()
                .any(|k| k.ends_with(&format!("controller/{key}"))),
            "{info:?}"
        );
    }
    let malformed = client
        .request_key(
            &client.keys().controller_execute(),
            br#"{"trajectory": 3}"#,
            T,
        )
        .unwrap_err();
    assert_eq!(malformed.code(), Some(ErrorCode::InvalidRequest));
    for (trajectory, why) in [
        (line("r_elbow", 0.0, 0.5, 2.0), "outside its limits"),
        (line("r_elbow", 0.0, -2.0, 0.5), "velocity limit"),
        (
            line("no_such_joint", 0.0, 0.1, 1.0),
            "unknown joint `no_such_joint`",
        ),
        (line("r_elbow", -1.0, -1.5, 1.0), "starts at -1"),
        (line("r_elbow", 0.0, -0.5, 0.0), "strictly increase"),
    ] {
        let reply = execute(&client, &trajectory).unwrap();
        assert!(!reply.accepted);
        let reason = reply.reason.unwrap();
        assert!(reason.contains(why), "{reason} should say {why}");
    }

    let (_sub, rx) = states(&client);
    let reply = execute(&client, &line("r_elbow", 0.0, -1.5, 1.0)).unwrap();
    assert_eq!(reply.outcome, Some(ExecutionOutcome::Done), "{reply:?}");
    let end = reply.state.unwrap();
    assert_eq!(elbow(&end), -1.5);
    // Every state published during the run is on the line at its sample time, and
    // the samples are one period (10 ms: 100 Hz) apart.
    let mut seen = 0;
    let mut previous: Option<ControllerState> = None;
    loop {
        let state = rx.recv_timeout(T).unwrap();
        if let Some(t) = state.trajectory_time {
            assert!((elbow(&state) - (-1.5 * t)).abs() < 1e-6, "{state:?}");
            if let Some(p) = &previous {
                let periods = (state.tick - p.tick) as f64;
                assert!((state.time - p.time - 0.01 * periods).abs() < 1e-9);
            }
            seen += 1;
            previous = Some(state.clone());
        }
        if state.tick == end.tick {
            break;
        }
    }
    assert!(seen > 50, "only {seen} of 100 states arrived");
    // The state holds where the run ended; the next run starts from there.
    let held = serde_json::from_slice::<ControllerState>(
        &client
            .request_key(&client.keys().controller_state(), b"", T)
            .unwrap(),
    )
    .unwrap();
    assert_eq!(elbow(&held), -1.5);
    let reply = execute(&client, &line("r_elbow", -1.5, -1.0, 0.5)).unwrap();
    assert_eq!(reply.outcome, Some(ExecutionOutcome::Done));
    node.shutdown();
}

#[test]
fn stop_ends_the_run_within_one_period() {
    let (node, client) = controller(10.0);
    let (_sub, rx) = states(&client);
    // 100 s of trajectory, 10 s at 10x: plenty of time to stop it.
    let long = line("r_elbow", 0.0, -2.5, 100.0);
    let reply = std::thread::scope(|s| {
        let run = s.spawn(|| execute(&client, &long));
        while rx.recv_timeout(T).unwrap().status != "executing" {}
        let stop: StopReply = serde_json::from_slice(
            &client
                .request_key(&client.keys().controller_stop(), b"", T)
                .unwrap(),
        )
        .unwrap();
        assert!(stop.stopped);
        run.join().unwrap().unwrap()
    });
    assert_eq!(reply.outcome, Some(ExecutionOutcome::Cancelled));
    let end = reply.state.unwrap();
    let asked = reply.stop_requested_at.unwrap();
    assert_eq!(
        end.tick,
        asked + 1,
        "stopped one period after the stop arrived"
    );
    let t = end.trajectory_time.unwrap();
    assert!(t < 50.0, "stopped early, at {t} s");
    assert!((elbow(&end) - (-0.025 * t)).abs() < 1e-6);
    assert_eq!(end.status, "cancelled");
    // Nothing to stop now.
    let idle: StopReply = serde_json::from_slice(
        &client
            .request_key(&client.keys().controller_stop(), b"", T)
            .unwrap(),
    )
    .unwrap();
    assert!(!idle.stopped);
    node.shutdown();
}

#[test]
fn sigterm_ends_the_run_as_a_fault_and_exits_cleanly() {
    let port = free_loopback_port().unwrap();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let namespace = format!("term-{port}");
    let mut child = Command::new(env!("CARGO_BIN_EXE_tsukami-controller"))
        .args([
            "--listen",
            &endpoint,
            "--namespace",
            &namespace,
            "--models-dir",
        ])
        .arg(models())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let client = BusClient::connect(&BusConfig::connecting(&endpoint), &namespace).unwrap();
    client.wait_for_component("controller", T).unwrap();
    let (_sub, rx) = states(&client);
    let reply = std::thread::scope(|s| {
        let run = s.spawn(|| execute(&client, &line("r_elbow", 0.0, -2.5, 100.0)));
        while rx.recv_timeout(T).unwrap().status != "executing" {}
        // SAFETY: kill(2) on our own child's pid; no memory is shared.
        let sent = unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
        assert_eq!(sent, 0, "kill: {}", std::io::Error::last_os_error());
        run.join().unwrap().unwrap()
    });
    assert_eq!(reply.outcome, Some(ExecutionOutcome::Fault));
    assert!(reply.reason.unwrap().contains("shut down"));
    assert!(child.wait().unwrap().success());
}
