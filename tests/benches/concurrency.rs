//! Plans per second with 1, 2 and 4 concurrent clients against a host whose
//! planner has a pool of 1, 2 and 4 workers, on the paper's can scene
//! (`can_breast`), over the bus; the ratio to the pool of 1 is printed; then the
//! 4-client / 1-client ratio of the host's default config (a pool of one worker
//! per core). Then,
//! when `TSUKAMI_BEFORE` names the `tsukami` binary of an older build (with its
//! planner plugin beside it and `TSUKAMI_BEFORE_MODELS` its models folder),
//! plan p50 over the bus per paper scene, that build against this one, in the
//! same run, with how many of each build's grasps pass the independent check
//! (`tsukami_scenes::verify`: penetration, contacts on the surface, exact force
//! closure with the weight) on this build's world.
//!
//! Run: `cargo bench -p tsukami-e2e --bench concurrency`.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use tsukami::bus::{free_loopback_port, BusConfig};
use tsukami::client::BusClient;
use tsukami_e2e::{models_dir, planner_entry, test_config, ChildGuard, TestBus};
use tsukami_msgs::keys::{planner, ROLE_GRASP_PLANNER};
use tsukami_msgs::planner::{PlanOptions, PlanReply};
use tsukami_scenes::{scene_requests, verify, Tolerances, World, PAPER_SCENES};

const T: Duration = Duration::from_secs(120);
const PLANS_PER_CLIENT: u64 = 100;
const SEEDS: u64 = 32;

/// Sets `scene` from `models`' scenes folder (each build reads its own models:
/// their grasp-type files differ between versions).
fn set_scene(c: &BusClient, models: &Path, scene: &str) {
    let req = scene_requests(&models.join("scenes").join(format!("{scene}.toml"))).unwrap();
    for (cmd, body) in [
        (planner::SET_ROBOT, serde_json::to_vec(&req.robot).unwrap()),
        (
            planner::SET_OBJECT,
            serde_json::to_vec(&req.object).unwrap(),
        ),
        (planner::SET_ENV, serde_json::to_vec(&req.env).unwrap()),
    ] {
        c.command(ROLE_GRASP_PLANNER, cmd, &body, T).expect(cmd);
    }
}

/// One plan's round trip, and its reply when it found a grasp (an `infeasible`
/// or other error reply still counts its time: the bench reports the failures).
fn plan_reply(c: &BusClient, seed: u64) -> (Duration, Option<Vec<u8>>) {
    let body = serde_json::to_vec(&PlanOptions {
        seed,
        ..PlanOptions::default()
    })
    .unwrap();
    let start = Instant::now();
    let reply = c.command(ROLE_GRASP_PLANNER, planner::PLAN, &body, T).ok();
    (start.elapsed(), reply)
}

fn plan(c: &BusClient, seed: u64) -> (Duration, bool) {
    let (t, reply) = plan_reply(c, seed);
    (t, reply.is_some())
}

/// How many of `replies` (found grasps) pass the independent check on `world`.
fn verified(world: &World, replies: &[Vec<u8>]) -> usize {
    replies
        .iter()
        .filter(|r| {
            serde_json::from_slice::<PlanReply>(r)
                .is_ok_and(|reply| verify(world, &reply, &Tolerances::default()).is_ok())
        })
        .count()
}

/// Plans per second with `clients` clients, each on its own session.
fn throughput(bus: &TestBus, clients: u64) -> f64 {
    let namespace = bus.client.keys().namespace().to_owned();
    let sessions: Vec<BusClient> = (0..clients)
        .map(|_| BusClient::connect(&BusConfig::connecting(&bus.endpoint), &namespace).unwrap())
        .collect();
    let start = Instant::now();
    std::thread::scope(|s| {
        for (k, c) in sessions.iter().enumerate() {
            s.spawn(move || {
                for i in 0..PLANS_PER_CLIENT {
                    plan(c, 1000 * k as u64 + i);
                }
            });
        }
    });
    (clients * PLANS_PER_CLIENT) as f64 / start.elapsed().as_secs_f64()
}

fn median_ms(mut t: Vec<Duration>) -> f64 {
    t.sort();
    t[t.len() / 2].as_secs_f64() * 1e3
}

fn pool_table() {
    println!("plans/s on can_breast over the bus ({PLANS_PER_CLIENT} plans per client; ratio to pool 1):");
    println!(
        "{:>8} {:>16} {:>16} {:>16}",
        "clients", "pool 1", "pool 2", "pool 4"
    );
    let mut rows = vec![vec![0.0; 3]; 3];
    for (p, pool) in [1usize, 2, 4].into_iter().enumerate() {
        let mut entry = planner_entry();
        entry.workers = Some(pool);
        let bus = TestBus::start(test_config(vec![entry]));
        set_scene(&bus.client, &models_dir(), "can_breast");
        assert!(plan(&bus.client, 0).1, "can_breast plans");
        for (c, clients) in [1u64, 2, 4].into_iter().enumerate() {
            rows[c][p] = throughput(&bus, clients);
        }
    }
    for (c, clients) in [1, 2, 4].into_iter().enumerate() {
        let r = &rows[c];
        println!(
            "{clients:>8} {:>9.1} (1.00x) {:>9.1} ({:.2}x) {:>9.1} ({:.2}x)",
            r[0],
            r[1],
            r[1] / r[0],
            r[2],
            r[2] / r[0]
        );
    }
}

/// The host's default config (the planner's pool: one worker per core): 4
/// clients' throughput over 1 client's.
fn default_ratio() {
    let workers = tsukami::world::default_workers();
    let bus = TestBus::start(test_config(vec![planner_entry()]));
    set_scene(&bus.client, &models_dir(), "can_breast");
    assert!(plan(&bus.client, 0).1, "can_breast plans");
    let (one, four) = (throughput(&bus, 1), throughput(&bus, 4));
    println!(
        "default config (pool = {workers}, the cores): 1 client {one:.1} plans/s, 4 clients \
         {four:.1} plans/s: 4 / 1 = {:.2}x",
        four / one
    );
}

/// p50 per scene over the bus against an older build's host process.
fn before_after(before: &str, before_models: &str) {
    let port = free_loopback_port().unwrap();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let namespace = format!("before-{port}");
    let child = Command::new(before)
        .args(["run", "--listen", &endpoint, "--namespace", &namespace])
        .env("TSUKAMI_MODELS", before_models)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("the older tsukami starts");
    let _guard = ChildGuard(child);
    let old = BusClient::connect(&BusConfig::connecting(&endpoint), &namespace).unwrap();
    old.wait_for_host(Duration::from_secs(30))
        .expect("the older host answers");
    let new = TestBus::start(test_config(vec![planner_entry()]));
    println!("plan p50 over the bus, {SEEDS} seeds, older build vs this build (same run);");
    println!(
        "verified: replies with a grasp that pass tsukami_scenes::verify on this build's world"
    );
    println!(
        "{:<11} {:>10} {:>10} {:>9} {:>13}",
        "scene", "before ms", "after ms", "after/bef", "verified b/a"
    );
    for scene in PAPER_SCENES {
        let (mut p50, mut ok) = (Vec::new(), Vec::new());
        let path = models_dir()
            .join("scenes")
            .join(format!("{}.toml", scene.name));
        let r = scene_requests(&path).unwrap();
        let world = World::from_requests(&models_dir(), &r.robot, &r.object, &r.env).unwrap();
        for (c, models) in [
            (&old, Path::new(before_models)),
            (&new.client, &models_dir()),
        ] {
            set_scene(c, models, scene.name);
            let (times, replies): (Vec<_>, Vec<_>) = (0..SEEDS).map(|s| plan_reply(c, s)).unzip();
            let found: Vec<Vec<u8>> = replies.into_iter().flatten().collect();
            ok.push(verified(&world, &found));
            p50.push(median_ms(times));
        }
        println!(
            "{:<11} {:>10.2} {:>10.2} {:>8.2}x {:>6}/{:<6}",
            scene.name,
            p50[0],
            p50[1],
            p50[1] / p50[0],
            ok[0],
            ok[1]
        );
    }
}

fn main() {
    pool_table();
    default_ratio();
    match (
        std::env::var("TSUKAMI_BEFORE"),
        std::env::var("TSUKAMI_BEFORE_MODELS"),
    ) {
        (Ok(exe), Ok(models)) => before_after(&exe, &models),
        _ => println!("(set TSUKAMI_BEFORE and TSUKAMI_BEFORE_MODELS for the before/after table)"),
    }
}
