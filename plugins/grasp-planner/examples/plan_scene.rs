//! Plans one scene of `models/scenes/` and prints the reply as JSON.
//! Usage: `plan_scene models/scenes/can_breast.toml [SEED]`.
use std::sync::atomic::AtomicBool;
use tsukami_msgs::planner::PlanOptions;
use {tsukami_grasp_planner::planner::Planner, tsukami_scenes::scene_requests};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = &std::fs::canonicalize(args.first().ok_or("usage: plan_scene SCENE.toml [SEED]")?)?;
    let seed = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(0);
    let req = scene_requests(path)?;
    let models = path
        .parent()
        .and_then(|p| p.parent())
        .ok_or("scene must be in models/scenes")?;
    let p = Planner::new(models);
    p.set_robot(&req.robot)?;
    let obj = p.set_object(&req.object)?;
    eprintln!(
        "{} regions: {}",
        obj.regions.len(),
        serde_json::to_string(&obj.regions)?
    );
    p.set_env(&req.env)?;
    let t = std::time::Instant::now();
    let r = p.plan(
        &PlanOptions {
            seed,
            ..Default::default()
        },
        &AtomicBool::new(false),
        &mut |_| {},
    );
    eprintln!("{:.2} ms", t.elapsed().as_secs_f64() * 1e3);
    match r {
        Ok(r) => println!("{}", serde_json::to_string_pretty(&r)?),
        Err(e) => println!("ERROR [{}] {e}", e.reason()),
    }
    Ok(())
}
