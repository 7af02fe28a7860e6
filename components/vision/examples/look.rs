//! One look at a scene, explained: a debugging aid for the views of a look.
//!
//! `cargo run --release -p tsukami-vision --example look -- SCENE [OBJECT] [SEED]`
//!
//! Loads `models/scenes/SCENE.toml`, looks for OBJECT (default: the scene's
//! first object's model) as `<ns>/vision/look` does, and prints each view
//! taken: its posture (the joints away from rest), how far the target is
//! off the optical axis, what the robot's own links hide of it, and the
//! detection (confidence and occlusion, or why not found), then which view
//! was chosen.

use std::path::PathBuf;
use std::time::Instant;

use tsukami_body::files::ModelRoots;
use tsukami_body::scene::Scene;
use tsukami_vision::detect::{detect_with, DetectParams, Detector, Outcome};
use tsukami_vision::look::{View, MAX_VIEWS};
use tsukami_vision::sim::noise::NoiseModel;
use tsukami_vision::sim::scene_camera::SceneCamera;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let models = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let file = models.join(format!(
        "scenes/{}.toml",
        a.get(1).map_or("fridge_pet", |s| s)
    ));
    let object = a.get(2).cloned().unwrap_or_else(|| {
        Scene::load(&file).expect("scene").objects[0]
            .model
            .name
            .clone()
    });
    let seed: u64 = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(0);
    let camera = SceneCamera::load(&file, NoiseModel::default()).expect("scene camera");
    let mut detector = Detector::new(ModelRoots::new([models]), DetectParams::default());
    let template = detector.template(&object).expect("object model");
    let target = camera.target(&object, template.radius);
    println!(
        "{object}: expected at {:.3?}, radius {:.3} m",
        target.centre.coords.as_slice(),
        template.radius
    );
    let start = Instant::now();
    let looked = camera
        .looker
        .look(&target, MAX_VIEWS, |view| {
            let (image, cam) = camera.render(&view.q, seed)?;
            let outcome = detect_with(&template, &image, &cam, &detector.params);
            if let Ok(outcome) = &outcome {
                describe(&camera, view, outcome);
            }
            outcome
        })
        .expect("look");
    println!(
        "chosen view: {:?}, {:.0} ms",
        looked.chosen,
        start.elapsed().as_secs_f64() * 1e3
    );
}

fn describe(camera: &SceneCamera, view: &View, outcome: &Outcome) {
    let robot = &camera.looker.head.robot;
    let rest = robot.rest_positions();
    let moved: Vec<String> = robot
        .joints
        .iter()
        .enumerate()
        .filter(|(j, joint)| joint.is_movable() && (view.q[*j] - rest[*j]).abs() > 1e-9)
        .map(|(j, joint)| format!("{}={:.2}", joint.name, view.q[j]))
        .collect();
    let hiding: Vec<String> = view
        .hidden
        .by_link
        .iter()
        .map(|(l, n)| format!("{}:{n}", robot.links[*l].name))
        .collect();
    println!(
        "view {:<12} {:.1}° off axis, self-hidden {}/{} {hiding:?}\n    {}",
        view.name,
        view.off_axis.to_degrees(),
        view.hidden.hidden,
        view.hidden.pixels,
        moved.join(" ")
    );
    match outcome {
        Outcome::Found(d) => println!(
            "    found: confidence {:.3}, occluded {:.2}, at {:.4?}",
            d.confidence,
            d.verdict.occluded_fraction(),
            d.pose.translation.vector.as_slice()
        ),
        Outcome::NotFound(n) => println!("    not found: {}", n.reason),
    }
}
