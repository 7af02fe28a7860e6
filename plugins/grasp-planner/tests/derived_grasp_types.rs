//! The humanoid's grasp types derived from its kinematics
//! (`tsukami_planner_kit::grasp_derive`, `tsukami model grasp-types`) instead
//! of the hand-written file, on the paper's five scenes: each plan must give
//! the outcome the paper reports and pass the independent check
//! (`PaperScene::check`: style, approach, squat, regions, then
//! `tsukami_scenes::verify`).

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use tsukami_grasp_planner::planner::Planner;
use tsukami_msgs::planner::{PlanOptions, SetRobot};
use tsukami_planner_kit::description::Description;
use tsukami_planner_kit::grasp_derive::{derive, to_toml, DeriveOptions};
use tsukami_planner_kit::grasp_types::GraspTypeConfig;
use tsukami_planner_kit::{Hand, PlannerConfig};
use tsukami_scenes::{paper_scene, scene_requests, World};

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

/// The derived file, written to a fresh model root; the root and the file's
/// path inside it.
fn derived_file() -> (PathBuf, String) {
    let dir = models().join("robots/tsukami_humanoid");
    let text = std::fs::read_to_string(dir.join("description.toml")).unwrap();
    let d = Description::parse(&text, "description.toml").unwrap();
    let model = tsukami_body::urdf::load_urdf(&dir.join(&d.urdf)).unwrap();
    let empty = GraspTypeConfig {
        hand: Default::default(),
        grasp_types: Vec::new(),
    };
    let hand = Hand::new(&model, &d.hands[0], 0, empty).unwrap();
    let derived = derive(&model, &hand, &DeriveOptions::default()).unwrap();
    let root = std::env::temp_dir().join(format!("tsukami-derived-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    let root = std::fs::canonicalize(root).unwrap();
    let file = root.join("derived_grasp_types.toml");
    std::fs::write(&file, to_toml(&derived.config, &[])).unwrap();
    (root, file.display().to_string())
}

#[test]
fn derived_humanoid_grasp_types_reproduce_the_papers_outcomes() {
    let (root, file) = derived_file();
    let mut failures = Vec::new();
    for name in [
        "can_breast",
        "can_waist",
        "heavy_low",
        "fridge_pet",
        "vase_table",
    ] {
        let path = models().join("scenes").join(format!("{name}.toml"));
        let req = scene_requests(&path).unwrap();
        let p = Planner::from_config(PlannerConfig::with_roots([models(), root.clone()])).unwrap();
        let robot = SetRobot {
            grasp_types: Some(file.clone()),
            ..req.robot.clone()
        };
        p.set_robot(&robot).unwrap();
        let regions = p.set_object(&req.object).unwrap().regions.len();
        p.set_env(&req.env).unwrap();
        let world = World::from_requests(&models(), &req.robot, &req.object, &req.env).unwrap();
        let scene = paper_scene(name).unwrap();
        for seed in [0, 1] {
            let opts = PlanOptions {
                seed,
                ..PlanOptions::default()
            };
            let outcome = p
                .plan(&opts, &AtomicBool::new(false), &mut |_| {})
                .map_err(|e| e.to_string())
                .and_then(|r| scene.check(&world, &r, regions).map(|()| r.grasp_type.name));
            match outcome {
                Ok(t) => println!("{name} seed {seed}: {t}"),
                Err(e) => failures.push(format!("{name} seed {seed}: {e}")),
            }
        }
    }
    std::fs::remove_dir_all(&root).ok();
    assert!(failures.is_empty(), "{failures:#?}");
}
