//! Exports each paper scene's motion (the paper's planner's grasp, seed 0;
//! `plan_motion` from rest, seed 1, request defaults) for the comparison of its
//! timing with `toppra`'s (`bench/toppra/compare.py`): per phase its duration
//! and the positions of its points — the path the controller follows — with the
//! joints' velocity and acceleration limits the timing used.
//!
//! Run: `cargo run --release -p tsukami-trajectory-planner --example
//! timing_export -- OUT.json` (`bash bench/toppra/run.sh` runs both).

#[allow(dead_code)]
#[path = "../tests/common/grasps.rs"]
mod grasps;

use serde_json::json;
use tsukami_trajectory_planner::motion::{joint_limits, plan_default, MotionConfig, MotionQuery};

const SCENES: [&str; 5] = [
    "can_breast",
    "can_waist",
    "heavy_low",
    "fridge_pet",
    "vase_table",
];

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "target/timing_export.json".into());
    let cfg = MotionConfig::default();
    let mut scenes = Vec::new();
    for scene in SCENES {
        let (world, grasp) = grasps::scene(scene, 0);
        let snapshot = world.snapshot();
        let w = snapshot.world().expect("a world");
        let query = MotionQuery::new(&grasp, w.robot.model.rest_positions(), 1);
        let m = plan_default(&w, &query).unwrap_or_else(|e| panic!("{scene}: {e}"));
        let t = &m.trajectory;
        let ids: Vec<usize> = t
            .joint_names
            .iter()
            .map(|n| w.robot.model.joint_id(n).expect("a trajectory joint"))
            .collect();
        let limits = joint_limits(w.robot, &ids, &cfg, None);
        let mut phases = Vec::new();
        for name in ["reach", "approach", "close", "lift"] {
            let first = t
                .points
                .iter()
                .position(|p| p.phase == name)
                .expect("a phase");
            let last = t
                .points
                .iter()
                .rposition(|p| p.phase == name)
                .expect("a phase");
            let from = first.saturating_sub(1);
            let start = if first > 0 { t.points[from].time } else { 0.0 };
            let positions: Vec<&Vec<f64>> =
                t.points[from..=last].iter().map(|p| &p.positions).collect();
            phases.push(json!({
                "name": name,
                "duration": t.points[last].time - start,
                "positions": positions,
            }));
        }
        scenes.push(json!({
            "scene": scene,
            "joints": t.joint_names,
            "velocity": limits.velocity,
            "acceleration": limits.acceleration,
            "phases": phases,
        }));
    }
    std::fs::write(&out, serde_json::to_vec_pretty(&scenes).expect("json")).expect("write");
    println!("wrote {out}");
}
