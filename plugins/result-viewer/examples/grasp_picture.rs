//! Plans one scene of `models/scenes/` with the built-in planner and writes
//! the grasp as a picture and as a glTF binary.
//! Usage: `grasp_picture SCENE.toml OUT.png [OUT.glb] [SEED]`.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use nalgebra::{Point3, Vector3};
use tsukami_grasp_planner::planner::Planner;
use tsukami_msgs::planner::PlanOptions;
use tsukami_result_viewer::grasp_view::{contact_marks, posture, GraspView};
use tsukami_result_viewer::render::{render, Camera};
use tsukami_scenes::{scene_requests, World};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: grasp_picture SCENE.toml OUT.png [OUT.glb] [SEED]";
    let scene = &std::fs::canonicalize(args.first().ok_or(usage)?)?;
    let png = args.get(1).ok_or(usage)?;
    let seed = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(0);
    let models = scene
        .parent()
        .and_then(Path::parent)
        .ok_or("scene must be in models/scenes")?;
    let req = scene_requests(scene)?;
    let p = Planner::new(models);
    p.set_robot(&req.robot)?;
    p.set_object(&req.object)?;
    p.set_env(&req.env)?;
    let options = PlanOptions {
        seed,
        ..Default::default()
    };
    let reply = p.plan(&options, &AtomicBool::new(false), &mut |_| {})?;
    let world = World::from_requests(models, &req.robot, &req.object, &req.env)?;
    let q = posture(&world.robot.model, &reply)?;
    let contacts = contact_marks(&reply);
    let drawing = GraspView {
        model: &world.robot.model,
        collision: &world.robot.collision,
        q: &q,
        hand_links: &world.robot.hand_links,
        object: Some((&world.object.mesh, world.object.pose)),
        obstacles: &world.obstacles,
        contacts: &contacts,
    }
    .drawing();
    let target = Point3::from(world.object.pose.translation.vector);
    let camera = Camera::looking_at(
        target + Vector3::new(0.15, -0.55, 0.25),
        target,
        Vector3::z(),
    );
    let t = std::time::Instant::now();
    let picture = render(&drawing, &camera, 800, 600);
    eprintln!(
        "{} triangles rendered in {:.1} ms",
        drawing.triangle_count(),
        t.elapsed().as_secs_f64() * 1e3
    );
    std::fs::write(png, picture.to_png()?)?;
    if let Some(glb) = args.get(2) {
        std::fs::write(glb, tsukami_result_viewer::glb::to_glb(&drawing))?;
    }
    Ok(())
}
