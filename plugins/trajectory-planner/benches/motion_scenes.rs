//! Motion planning time per paper scene, p50 and p99 over 32 seeds (in-process,
//! no bus), and the same with shortcutting switched off, in the same run.
//!
//! Run: `cargo bench -p tsukami-trajectory-planner --bench motion_scenes`
//! (`-- can_breast fridge_pet` runs only the scenes named).
//! Targets (issue #13): table scenes p50 < 50 ms, fridge p50 < 300 ms.
//! The grasp comes from the paper's planner (seed 0); the motion starts at rest.

#[path = "../tests/common/grasps.rs"]
mod grasps;

use std::time::Instant;

use tsukami_msgs::motion::MotionGrasp;
use tsukami_planner_kit::validate::Limits;
use tsukami_planner_kit::Session;
use tsukami_trajectory_planner::motion::{plan_motion, MotionConfig, MotionQuery, Variant};
use tsukami_trajectory_planner::world::SharedWorld;

const SCENES: [&str; 5] = [
    "can_breast",
    "can_waist",
    "heavy_low",
    "fridge_pet",
    "vase_table",
];
const SEEDS: u64 = 32;

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[i]
}

fn times(
    world: &Session<SharedWorld>,
    grasp: &MotionGrasp,
    variant: Variant,
) -> (Vec<f64>, u32, f64, usize) {
    let snapshot = world.snapshot();
    let w = snapshot.world().unwrap();
    let cfg = MotionConfig::default();
    let mut out = Vec::new();
    let (mut ok, mut duration, mut checks) = (0, 0.0, 0);
    for seed in 0..SEEDS {
        let query = MotionQuery::new(grasp, w.robot.model.rest_positions(), seed);
        let t = Instant::now();
        let r = plan_motion(
            &w,
            &query,
            &cfg,
            &Limits::default(),
            variant,
            &|| false,
            &mut |_, _| {},
        );
        out.push(t.elapsed().as_secs_f64() * 1e3);
        match r {
            Err(e) if ok == 0 && seed == 0 => eprintln!("seed 0 failed: {e}"),
            Err(_) => {}
            Ok(m) => {
                ok += 1;
                duration += m.trajectory.points.last().unwrap().time;
                checks += m.checks;
            }
        }
    }
    out.sort_by(f64::total_cmp);
    let n = ok.max(1);
    (out, ok, duration / f64::from(n), checks / n as usize)
}

fn main() {
    println!("| scene | p50 ms | p99 ms | ok | trajectory s | checks | no shortcut: p50 ms | p99 ms | trajectory s | checks | p50 ratio (shortcut / none) |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let only: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    for scene in SCENES {
        if !only.is_empty() && !only.iter().any(|o| o == scene) {
            continue;
        }
        let (world, grasp) = grasps::scene(scene, 0);
        let (a, ok_a, dur_a, checks_a) = times(&world, &grasp, Variant::default());
        let (b, _, dur_b, checks_b) = times(&world, &grasp, Variant { no_shortcut: true });
        let (pa, pb) = (percentile(&a, 0.5), percentile(&b, 0.5));
        println!(
            "| {scene} | {pa:.1} | {:.1} | {ok_a}/{SEEDS} | {dur_a:.2} | {checks_a} | {pb:.1} | {:.1} | {dur_b:.2} | {checks_b} | {:.2} |",
            percentile(&a, 0.99),
            percentile(&b, 0.99),
            pa / pb
        );
    }
}
