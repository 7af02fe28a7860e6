//! The controller on a real zenoh bus on loopback: requests, rejections with their
//! reasons, published states that follow the trajectory at every sample time, stop
//! within one control period (also under a flood of refused requests, which must not
//! hold up the periods), and a clean exit on SIGTERM.

use std::path::Path;
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};
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
    assert_eq!(node_endpoint(&namespace), endpoint);
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

/// The endpoint of the node [`controller`] started under `namespace`.
fn node_endpoint(namespace: &str) -> String {
    let port = namespace.strip_prefix("ctl-").unwrap();
    format!("tcp/127.0.0.1:{port}")
}

fn line(joint: &str, from: f64, to: f64, time: f64) -> JointTrajectory {
    let point = |time: f64, q: f64| TrajectoryPoint {
        time,
        positions: vec![q],
        velocities: vec![],
        phase: String::new(),
        command: vec![],
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

fn stop(client: &BusClient) -> StopReply {
    let bytes = client
        .request_key(&client.keys().controller_stop(), b"", T)
        .unwrap();
    serde_json::from_slice(&bytes).unwrap()
}

fn latest_tick(client: &BusClient) -> u64 {
    let bytes = client
        .request_key(&client.keys().controller_state(), b"", T)
        .unwrap();
    serde_json::from_slice::<ControllerState>(&bytes)
        .unwrap()
        .tick
}

/// 1500 refused `execute` requests (half an unknown joint, refused by the checks,
/// half refused by the control thread: busy, or a start away from the state)
/// from 4 clients while a real-time trajectory runs: the controller's clock keeps
/// pace with the wall clock (its periods are not pushed back), every period's
/// state is published, and a stop sent mid-flood ends the run one period later.
#[test]
fn a_flood_of_refused_requests_holds_up_neither_the_periods_nor_a_stop() {
    const FLOOD: usize = 1500;
    const CLIENTS: usize = 4;
    let dt = 0.01; // 100 Hz, real time
    let (node, client) = controller(1.0);
    let (_sub, rx) = states(&client);
    let long = line("r_elbow", 0.0, -2.5, 100.0);
    let unknown = line("no_such_joint", 0.0, 0.1, 1.0);
    // Passes the model's checks; refused by the control thread (busy while the
    // run goes, then its start, -1 rad, is away from the state).
    let second = line("r_elbow", -1.0, -1.2, 1.0);
    let answered = AtomicUsize::new(0);
    let (client_ref, answered_ref) = (&client, &answered);
    let run = std::thread::scope(|s| {
        let run = s.spawn(|| (execute(&client, &long), Instant::now()));
        while rx.recv_timeout(T).unwrap().status != "executing" {}
        let (tick0, t0) = (latest_tick(&client), Instant::now());
        let flood: Vec<_> = (0..CLIENTS)
            .map(|c| {
                let bad = [&unknown, &second];
                s.spawn(move || refused(client_ref, bad, c, FLOOD / CLIENTS, answered_ref))
            })
            .collect();
        // The stop goes out when half the flood is answered.
        let stopper = s.spawn(|| {
            while answered.load(Ordering::Relaxed) < FLOOD / 2 {
                std::thread::yield_now();
            }
            (stop(&client), Instant::now())
        });
        for f in flood {
            f.join().unwrap();
        }
        let (tick1, t1) = (latest_tick(&client), Instant::now());
        let (reply, ended) = run.join().unwrap();
        let (stop_reply, stopped) = stopper.join().unwrap();
        FloodRun {
            reply: reply.unwrap(),
            stop_reply,
            stop_to_end: (ended - stopped).as_secs_f64(),
            ticks: (tick0, tick1),
            wall: (t1 - t0).as_secs_f64(),
        }
    });
    // The states of the flood's periods that arrived.
    let (tick0, tick1) = run.ticks;
    let published = rx
        .try_iter()
        .filter(|s| s.tick > tick0 && s.tick <= tick1)
        .count() as u64;
    let periods = tick1 - tick0;
    assert!(run.stop_reply.stopped);
    assert_eq!(
        run.reply.outcome,
        Some(ExecutionOutcome::Cancelled),
        "{:?}",
        run.reply
    );
    let end = run.reply.state.unwrap();
    let asked = run.reply.stop_requested_at.unwrap();
    assert_eq!(
        end.tick,
        asked + 1,
        "the run ends one period after the stop"
    );
    eprintln!(
        "flood of {FLOOD}: {:.3} s wall, {} periods ({:.3} s of controller time), \
         {published} of their states received; stop reply to end of run {:.4} s",
        run.wall,
        periods,
        periods as f64 * dt,
        run.stop_to_end
    );
    // The clock keeps pace: a period pushed back per request would leave the
    // controller's time far behind the wall's (1500 requests: 15 s).
    assert!(
        periods as f64 * dt >= 0.5 * run.wall - 2.0 * dt,
        "{periods} periods in {:.3} s of flood",
        run.wall
    );
    assert!(
        published * 10 >= periods * 9,
        "only {published} states for {periods} periods"
    );
    assert!(
        run.stop_to_end < 1.0,
        "the run ended {:.3} s after the stop reply",
        run.stop_to_end
    );
    node.shutdown();
}

/// `n` requests from one client, alternating between the two `bad` trajectories
/// (starting with `bad[c % 2]`), each refused; counted in `answered`.
fn refused(
    client: &BusClient,
    bad: [&JointTrajectory; 2],
    c: usize,
    n: usize,
    answered: &AtomicUsize,
) {
    for k in 0..n {
        let reply = execute(client, bad[(k + c) % 2]).unwrap();
        assert!(!reply.accepted, "{reply:?}");
        answered.fetch_add(1, Ordering::Relaxed);
    }
}

struct FloodRun {
    reply: ExecuteReply,
    stop_reply: StopReply,
    stop_to_end: f64,
    /// The controller's tick when the flood started and when it was answered.
    ticks: (u64, u64),
    wall: f64,
}

/// The peak resident memory of process `pid` (VmHWM), bytes.
fn peak_rss(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let line = status.lines().find(|l| l.starts_with("VmHWM:")).unwrap();
    let kib: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kib * 1024
}

/// The controller binary caps zenoh's reassembly like the host: a payload just over
/// the limit is refused `payload_too_large` naming the limit, one far over it
/// (128 MiB) is dropped by zenoh before it can grow the process, and the
/// controller keeps serving.
#[test]
fn oversized_payloads_are_refused_and_do_not_grow_the_controller() {
    use tsukami_bus::{reassembly_cap, MAX_PAYLOAD_BYTES};
    let port = free_loopback_port().unwrap();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let namespace = format!("big-{port}");
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
    let key = client.keys().controller_execute();
    let before = peak_rss(child.id());

    let over = vec![b' '; MAX_PAYLOAD_BYTES + 1024];
    let refused = client.request_key(&key, &over, T).unwrap_err();
    assert_eq!(
        refused.code(),
        Some(ErrorCode::PayloadTooLarge),
        "{refused}"
    );
    assert!(
        refused.to_string().contains(&MAX_PAYLOAD_BYTES.to_string()),
        "{refused} should name the limit"
    );
    let after_over = peak_rss(child.id());

    let huge = vec![b' '; 128 << 20];
    let dropped = client.request_key(&key, &huge, Duration::from_secs(10));
    assert!(
        matches!(dropped, Err(RequestError::Timeout { .. })),
        "{dropped:?}"
    );
    drop(huge);
    let after_huge = peak_rss(child.id());
    // Still serving, at once.
    let reply = execute(&client, &line("no_such_joint", 0.0, 0.1, 1.0)).unwrap();
    assert!(!reply.accepted);
    let mib = |b: u64| b as f64 / (1 << 20) as f64;
    eprintln!(
        "controller VmHWM: {:.1} MiB at start, {:.1} after a {} B payload, {:.1} after 128 MiB",
        mib(before),
        mib(after_over),
        over.len(),
        mib(after_huge)
    );
    let cap = reassembly_cap(MAX_PAYLOAD_BYTES) as u64;
    assert!(
        after_huge - before < 2 * cap,
        "the controller grew by {:.1} MiB",
        mib(after_huge - before)
    );
    child.kill().unwrap();
    child.wait().unwrap();
}

/// `<ns>/*/info` lists every component: each answers on its own key, so zenoh's
/// consolidation does not fold the answers into one.
#[test]
fn a_wildcard_info_query_lists_every_component() {
    let (node, controller_client) = controller(1.0);
    let namespace = controller_client.keys().namespace().to_owned();
    let probe_port = free_loopback_port().unwrap();
    let probe_endpoint = format!("tcp/127.0.0.1:{probe_port}");
    let probe_args = ComponentArgs {
        listen: vec![probe_endpoint.clone()],
        connect: vec![],
        ..ComponentArgs::connecting(&namespace, &probe_endpoint)
    };
    let probe =
        tsukami_bus::Component::start("probe", "0.0.0", "a second component", &probe_args).unwrap();
    // A client of both (peers do not forward for each other).
    let endpoints = vec![node_endpoint(&namespace), probe_endpoint];
    let bus = BusConfig {
        connect: endpoints,
        ..BusConfig::connecting("tcp/127.0.0.1:1")
    };
    let client = BusClient::connect(&bus, &namespace).unwrap();
    client.wait_for_component("controller", T).unwrap();
    client.wait_for_component("probe", T).unwrap();
    let listed = client.components(Duration::from_secs(5)).unwrap();
    let names: Vec<&str> = listed.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["controller", "probe"], "{listed:?}");
    probe.close();
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
