//! Nothing blocks the planner: the plan round trip (client → host → grasp
//! planner → client) with and without the result viewer loaded, measured in
//! the same run, interleaved. With the viewer, one page follows the live
//! updates and one "slow browser" has opened the event stream and never
//! reads it.
//!
//! Run: `cargo bench -p tsukami-e2e --bench viewer`. Prints p50 and p99 of
//! each and the ratio with / without (target: within a few per cent; the
//! viewer only listens to the results the host publishes after replying).

use std::io::{BufRead, BufReader, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use tsukami::scenes::run_scene;
use tsukami_e2e::{models_dir, planner_entry, test_config, viewer_entry, TestBus};
use tsukami_msgs::keys::{ROLE_GRASP_PLANNER, ROLE_RESULT_VIEWER};
use tsukami_scenes::paper_scene;

const PLANS: u64 = 300;
const WARM_UP: u64 = 20;
const CHANGES: usize = 40;
const T: Duration = Duration::from_secs(60);

/// A bus with `can_breast` set up and planned once.
fn bus(with_viewer: bool) -> TestBus {
    let mut plugins = vec![planner_entry()];
    if with_viewer {
        plugins.push(viewer_entry());
    }
    let bus = TestBus::start(test_config(plugins));
    let scene = paper_scene("can_breast").unwrap();
    assert!(run_scene(&bus.client, &models_dir(), scene, 0, T).ok);
    bus
}

/// Opens `/events` on the viewer at `addr` (`host:port`).
fn event_stream(addr: &str) -> TcpStream {
    let mut s = TcpStream::connect(addr).expect("the viewer's web server");
    write!(s, "GET /events HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    s
}

fn plan_once(bus: &TestBus, seed: u64) -> Duration {
    let body = format!("{{\"seed\": {seed}}}");
    let start = Instant::now();
    bus.client
        .command(ROLE_GRASP_PLANNER, "plan", body.as_bytes(), T)
        .expect("a plan");
    start.elapsed()
}

fn ms(sorted: &[Duration], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize].as_secs_f64() * 1e3
}

fn main() {
    let without = bus(false);
    let with = bus(true);
    let state = with
        .client
        .command(ROLE_RESULT_VIEWER, "state", b"{}", T)
        .unwrap();
    let state: serde_json::Value = serde_json::from_slice(&state).unwrap();
    let url = state["web"]["url"].as_str().unwrap();
    let addr = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_owned();
    // A page that reads every event, and one that never reads.
    let reader = event_stream(&addr);
    let events = std::thread::spawn(move || BufReader::new(reader).lines().count());
    let _stalled = event_stream(&addr);

    let (mut a, mut b) = (Vec::new(), Vec::new());
    for seed in 0..WARM_UP + PLANS {
        let (x, y) = (plan_once(&without, seed), plan_once(&with, seed));
        if seed >= WARM_UP {
            a.push(x);
            b.push(y);
        }
    }
    a.sort();
    b.sort();
    let state = with
        .client
        .command(ROLE_RESULT_VIEWER, "state", b"{}", T)
        .unwrap();
    let state: serde_json::Value = serde_json::from_slice(&state).unwrap();
    println!("plan round trip, can_breast, {PLANS} seeds after {WARM_UP} warm-up, interleaved (release):");
    println!(
        "  {:<44} p50 {:>7.2} ms   p99 {:>7.2} ms",
        "without the viewer",
        ms(&a, 0.5),
        ms(&a, 0.99)
    );
    println!(
        "  {:<44} p50 {:>7.2} ms   p99 {:>7.2} ms",
        "with the viewer (1 page reading, 1 stalled)",
        ms(&b, 0.5),
        ms(&b, 0.99)
    );
    println!(
        "  ratio with / without: p50 {:.3}x   p99 {:.3}x",
        ms(&b, 0.5) / ms(&a, 0.5),
        ms(&b, 0.99) / ms(&a, 0.99)
    );
    println!(
        "  the viewer followed {} plans, sent {} events to {} pages",
        state["counts"]["plans"], state["web"]["events_sent"], state["web"]["event_clients"]
    );

    // World changes go to every world-aware plugin: the viewer loads the object too.
    let scene =
        tsukami_scenes::scene_requests(&models_dir().join("scenes/can_breast.toml")).unwrap();
    let object = serde_json::to_vec(&scene.object).unwrap();
    let set_object = |bus: &TestBus| {
        let start = Instant::now();
        bus.client
            .command(ROLE_GRASP_PLANNER, "set_object", &object, T)
            .expect("set_object");
        start.elapsed()
    };
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..CHANGES {
        a.push(set_object(&without));
        b.push(set_object(&with));
    }
    a.sort();
    b.sort();
    println!("set_object round trip (can_350ml), {CHANGES} times, interleaved:");
    println!("  {:<44} p50 {:>7.2} ms", "without the viewer", ms(&a, 0.5));
    println!("  {:<44} p50 {:>7.2} ms", "with the viewer", ms(&b, 0.5));
    println!(
        "  ratio with / without: p50 {:.3}x",
        ms(&b, 0.5) / ms(&a, 0.5)
    );
    drop(with);
    drop(without);
    let _ = events.join();
}
