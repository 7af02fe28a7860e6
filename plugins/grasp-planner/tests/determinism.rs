//! Same seed and world, same reply, under any load (issue #10, "deterministic by
//! default"): each scene is planned once on a quiet machine and once while
//! other threads keep every core busy, and the two replies must be equal byte
//! for byte once the timing fields (`timing_ms`, the only wall-clock figures)
//! are zeroed. Failed plans compare their error code, message and details the
//! same way. No sleeps: the hogs spin until the second plan has finished.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

use tsukami_grasp_planner::planner::Planner;
use tsukami_msgs::planner::{PhaseTiming, PlanOptions, WholeBody};
use tsukami_scenes::scene_requests;

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

fn setup(scene: &str) -> Planner {
    let req = scene_requests(&models().join("scenes").join(format!("{scene}.toml"))).unwrap();
    let p = Planner::new(models());
    p.set_robot(&req.robot).unwrap();
    p.set_object(&req.object).unwrap();
    p.set_env(&req.env).unwrap();
    p
}

/// The reply (or the error's wire form) as JSON bytes, timing zeroed.
fn plan_bytes(p: &Planner, opts: &PlanOptions) -> Vec<u8> {
    match p.plan(opts, &AtomicBool::new(false), &mut |_| {}) {
        Ok(mut r) => {
            r.timing_ms = PhaseTiming::default();
            serde_json::to_vec(&r).unwrap()
        }
        Err(e) => {
            let wire = e.to_call_error();
            format!("{}|{}|{}", wire.code, wire.message, wire.details_json).into_bytes()
        }
    }
}

/// Threads that keep `n` cores busy until `stop` is raised; each counts its
/// spins into `work` so the loop cannot be optimised away and the test can
/// see that the hogs really ran.
fn hogs(
    n: usize,
    stop: &Arc<AtomicBool>,
    work: &Arc<AtomicU64>,
) -> Vec<std::thread::JoinHandle<()>> {
    (0..n)
        .map(|_| {
            let (stop, work) = (stop.clone(), work.clone());
            std::thread::spawn(move || {
                let mut x = 1u64;
                while !stop.load(Ordering::Relaxed) {
                    for _ in 0..10_000 {
                        x = std::hint::black_box(
                            x.wrapping_mul(6364136223846793005).wrapping_add(1),
                        );
                    }
                    work.fetch_add(1, Ordering::Relaxed);
                }
            })
        })
        .collect()
}

fn same_under_load(scene: &str, opts: PlanOptions) {
    let p = setup(scene);
    let quiet = plan_bytes(&p, &opts);
    let cores = std::thread::available_parallelism().map_or(2, |n| n.get());
    let stop = Arc::new(AtomicBool::new(false));
    let work = Arc::new(AtomicU64::new(0));
    let threads = hogs(2 * cores, &stop, &work);
    // Wait (spinning, no sleep) until every hog has done some work.
    while work.load(Ordering::Relaxed) < 2 * cores as u64 {
        std::hint::spin_loop();
    }
    let loaded = plan_bytes(&p, &opts);
    stop.store(true, Ordering::Relaxed);
    for t in threads {
        t.join().unwrap();
    }
    assert!(work.load(Ordering::Relaxed) > 2 * cores as u64);
    assert_eq!(
        String::from_utf8_lossy(&quiet),
        String::from_utf8_lossy(&loaded),
        "{scene}: the reply changed under load"
    );
}

#[test]
fn a_grasp_is_the_same_under_load() {
    same_under_load(
        "can_waist",
        PlanOptions {
            seed: 11,
            ..PlanOptions::default()
        },
    );
}

#[test]
fn a_squatting_grasp_is_the_same_under_load() {
    same_under_load(
        "fridge_pet",
        PlanOptions {
            seed: 5,
            ..PlanOptions::default()
        },
    );
}

#[test]
fn an_infeasible_plan_fails_the_same_way_under_load() {
    // Arm only cannot reach the fridge shelf: the same error, counts and
    // blockers with or without load.
    same_under_load(
        "fridge_pet",
        PlanOptions {
            seed: 2,
            whole_body: WholeBody::ArmOnly,
            max_samples: 50,
            ..PlanOptions::default()
        },
    );
}

#[test]
fn a_request_time_limit_running_out_is_time_limit_not_timeout() {
    // Only a request that sets a wall-clock limit can get it; the code is its
    // own (`timeout` means a component did not answer).
    let p = setup("can_waist");
    let hopeless = PlanOptions {
        delta_f: Some(1000.0),
        max_samples: 1_000_000,
        max_candidates: 1000,
        time_budget_ms: Some(1),
        ..PlanOptions::default()
    };
    let e = p
        .plan(&hopeless, &AtomicBool::new(false), &mut |_| {})
        .unwrap_err();
    let wire = e.to_call_error();
    assert_eq!(wire.code, "time_limit", "{}", wire.message);
    assert!(
        wire.details_json.contains("out_of_time"),
        "{}",
        wire.details_json
    );
}
