//! Plan time of the antipodal planner on the can scenes (in-process, no bus),
//! with the seed changing every iteration.

use std::hint::black_box;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use criterion::{criterion_group, criterion_main, Criterion};
use tsukami_antipodal_planner::AntipodalPlanner;
use tsukami_msgs::planner::PlanOptions;

fn planner_for(scene: &str) -> AntipodalPlanner {
    let models = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../models");
    let req = tsukami_scenes::scene_requests(&models.join("scenes").join(scene)).expect("scene");
    let p = AntipodalPlanner::new(models);
    p.set_robot(&req.robot).expect("robot");
    p.set_object(&req.object).expect("object");
    p.set_env(&req.env).expect("env");
    p
}

fn bench(c: &mut Criterion) {
    for scene in ["can_breast", "can_waist"] {
        let planner = planner_for(&format!("{scene}.toml"));
        let cancel = AtomicBool::new(false);
        let mut seed = 0u64;
        c.bench_function(&format!("antipodal_plan/{scene}"), |b| {
            b.iter(|| {
                seed += 1;
                let opts = PlanOptions {
                    seed,
                    ..PlanOptions::default()
                };
                black_box(planner.plan(&opts, &cancel, &mut |_| {}).ok())
            })
        });
        // Success rate and p50 / p90 over seeds 0–63.
        let mut times = Vec::new();
        let mut ok = 0;
        for seed in 0..64 {
            let opts = PlanOptions {
                seed,
                ..PlanOptions::default()
            };
            let t = std::time::Instant::now();
            if planner.plan(&opts, &cancel, &mut |_| {}).is_ok() {
                ok += 1;
            }
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        println!(
            "{scene}: {ok}/64 ok, p50 {:.2} ms, p90 {:.2} ms",
            times[32], times[57]
        );
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
