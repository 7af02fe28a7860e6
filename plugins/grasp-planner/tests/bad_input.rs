//! Bad requests get clear errors and never lose the state already set;
//! cancellation and progress reporting.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::Vector3;
use tsukami_body::mesh::TriangleMesh;
use tsukami_grasp_planner::planner::{PlanError, Planner};
use tsukami_msgs::planner::{
    pose_at, ObjectShape, Obstacle, ObstacleShape, PlanOptions, PlanPhase, Pose, RemoveEnv, SetEnv,
    SetObject, SetRobot,
};
use tsukami_scenes::{scene_requests, verify, Tolerances, World};

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tsukami-planner-tests-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A planner reading models from `models/` and from this test's temp folder
/// (the meshes it writes); nothing else is readable.
fn planner() -> Planner {
    let roots = [models(), tmp("x").parent().unwrap().to_path_buf()];
    let config = tsukami_planner_kit::PlannerConfig::with_roots(roots);
    Planner::from_config(config).unwrap()
}

fn ready() -> Planner {
    let req = scene_requests(&models().join("scenes/can_breast.toml")).unwrap();
    let p = planner();
    p.set_robot(&req.robot).unwrap();
    p.set_object(&req.object).unwrap();
    p.set_env(&req.env).unwrap();
    p
}

fn mesh_object(path: &Path, mass: f64) -> SetObject {
    SetObject {
        name: None,
        shape: ObjectShape::Mesh {
            path: path.display().to_string(),
            scale: None,
        },
        mass,
        friction: None,
        pose: pose_at([0.5, -0.25, 1.1]),
        center_of_mass: None,
    }
}

fn plan(p: &mut Planner) -> Result<tsukami_msgs::planner::PlanReply, PlanError> {
    p.plan(
        &PlanOptions::default(),
        &AtomicBool::new(false),
        &mut |_| {},
    )
}

#[test]
fn plan_without_robot_or_object_says_so() {
    let mut p = Planner::new(models());
    assert!(matches!(
        plan(&mut p),
        Err(PlanError::NotReady {
            missing: "robot",
            ..
        })
    ));
    p.set_robot(&SetRobot {
        robot: "tsukami_humanoid".into(),
        grasp_types: None,
        package_dirs: Vec::new(),
    })
    .unwrap();
    let e = plan(&mut p).unwrap_err();
    assert!(matches!(
        e,
        PlanError::NotReady {
            missing: "object",
            ..
        }
    ));
    assert_eq!(e.reason(), "no_object");
    assert!(e.to_string().contains("set_object"));
}

#[test]
fn bad_objects_are_refused_and_the_state_is_kept() {
    let mut p = ready();
    let before = p.snapshot().object.as_ref().unwrap().0.name.clone();
    let can = TriangleMesh::cylinder(0.033, 0.122, 24);

    // Unknown model name.
    let e = p
        .set_object(&SetObject {
            shape: ObjectShape::Model {
                name: "no_such_thing".into(),
            },
            ..mesh_object(Path::new("x"), 0.1)
        })
        .unwrap_err();
    assert_eq!(e.reason(), "bad_model");
    assert!(e.to_string().contains("no_such_thing"), "{e}");

    // Mass <= 0.
    let good = tmp("can.stl");
    can.write_stl(&good).unwrap();
    for m in [0.0, -1.0, f64::NAN] {
        let e = p.set_object(&mesh_object(&good, m)).unwrap_err();
        assert!(e.to_string().contains("mass"), "{e}");
    }

    // NaN pose.
    let mut req = mesh_object(&good, 0.1);
    req.pose.position[1] = f64::NAN;
    let e = p.set_object(&req).unwrap_err();
    assert!(e.to_string().contains("pose"), "{e}");

    // An open mesh is no longer refused (tests/meshes.rs plans on one).

    // Degenerate: a flat, closed, two-sided sheet encloses no volume.
    let mut flat = TriangleMesh::cuboid(Vector3::new(0.1, 0.1, 0.05));
    for v in &mut flat.vertices {
        v.z = 0.0;
    }
    let path = tmp("flat.obj");
    flat.write_obj(&path).unwrap();
    let e = p.set_object(&mesh_object(&path, 0.1)).unwrap_err();
    assert_eq!(e.reason(), "bad_model");
    let m = e.to_string();
    assert!(m.contains("degenerate") || m.contains("open"), "{e}");

    // Over the triangle limit: refused before the mesh is cleaned, naming
    // the count and the limit (the one constant, in the planner kit).
    let limit = tsukami_planner_kit::object::MAX_TRIANGLES;
    let soup = TriangleMesh {
        vertices: can.vertices.clone(),
        indices: vec![can.indices[0]; limit + 1],
    };
    let id = nalgebra::Isometry3::identity();
    let e = tsukami_planner_kit::Object::from_mesh("soup", soup, id, 0.1, 0.5, None, 100.0)
        .unwrap_err();
    assert_eq!(e.to_call_error().code, "invalid_value");
    let m = e.to_string();
    assert!(
        m.contains(&(limit + 1).to_string()) && m.contains(&limit.to_string()),
        "{e}"
    );

    // Missing file.
    let e = p
        .set_object(&mesh_object(Path::new("/nonexistent/x.stl"), 0.1))
        .unwrap_err();
    assert!(e.to_string().contains("/nonexistent/x.stl"), "{e}");

    // The can set first is still there and plans.
    assert_eq!(p.snapshot().object.as_ref().unwrap().0.name, before);
    plan(&mut p).unwrap();
}

#[test]
fn unseen_mesh_is_planned() {
    // A mesh that is not in models/: a 60 mm jar written on the fly.
    let mut p = ready();
    let mesh = TriangleMesh::lathe(&[(0.03, 0.0), (0.03, 0.10), (0.02, 0.12)], 20);
    let path = tmp("unseen.obj");
    mesh.write_obj(&path).unwrap();
    let mut req = mesh_object(&path, 0.12);
    req.pose = pose_at([0.52, -0.25, 1.10]);
    let s = p.set_object(&req).unwrap();
    assert!(!s.regions.is_empty());
    let r = plan(&mut p).unwrap();
    // The independent checker, in the world of the requests the planner got: the
    // exact test recomputed from the reply, contacts on the jar, nothing sunk in.
    let scene = scene_requests(&models().join("scenes/can_breast.toml")).unwrap();
    let world = World::from_requests(&models(), &scene.robot, &req, &scene.env).unwrap();
    let verdict = verify(&world, &r, &Tolerances::default());
    assert!(verdict.is_ok(), "{verdict}");
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn bad_env_and_options_are_refused() {
    let p = ready();
    let n = p
        .remove_env(&RemoveEnv {
            names: vec![],
            all: false,
        })
        .unwrap()
        .obstacles
        .len();
    let e = p
        .set_env(&SetEnv {
            obstacles: vec![Obstacle {
                name: "wall".into(),
                shape: ObstacleShape::Box {
                    size: [1.0, -1.0, 1.0],
                },
                pose: Pose::IDENTITY,
            }],
            replace: true,
        })
        .unwrap_err();
    assert!(e.to_string().contains("wall"), "{e}");
    let e = p
        .remove_env(&RemoveEnv {
            names: vec!["nope".into()],
            all: false,
        })
        .unwrap_err();
    assert!(e.to_string().contains("nope"));
    // Nothing was replaced or removed.
    let after = p
        .remove_env(&RemoveEnv {
            names: vec![],
            all: false,
        })
        .unwrap();
    assert_eq!(after.obstacles.len(), n);

    let e = p
        .plan(
            &PlanOptions {
                grasp_types: Some(vec!["pinch".into()]),
                ..PlanOptions::default()
            },
            &AtomicBool::new(false),
            &mut |_| {},
        )
        .unwrap_err();
    assert_eq!(e.reason(), "bad_value");

    for (hold, field) in [
        (
            r#""pose_error": {"samples": 65}"#,
            "hold.pose_error.samples",
        ),
        (
            r#""pose_error": {"position": -0.001}"#,
            "hold.pose_error.position",
        ),
        (
            r#""pose_error": {"rotation_deg": 45}"#,
            "hold.pose_error.rotation_deg",
        ),
        (r#""max_turn_deg": 0"#, "hold.max_turn_deg"),
        (r#""max_shift_mm": 1e9"#, "hold.max_shift_mm"),
    ] {
        let opts: PlanOptions =
            serde_json::from_str(&format!(r#"{{"hold": {{{hold}}}}}"#)).unwrap();
        let e = p
            .plan(&opts, &AtomicBool::new(false), &mut |_| {})
            .unwrap_err();
        assert_eq!(e.reason(), "bad_value", "{hold}");
        assert!(e.to_string().contains(field), "{hold}: {e}");
    }
}

#[test]
fn heavy_or_huge_objects_fit_no_grasp_type() {
    let mut p = ready();
    let path = tmp("can2.stl");
    TriangleMesh::cylinder(0.033, 0.122, 24)
        .write_stl(&path)
        .unwrap();
    p.set_object(&mesh_object(&path, 5.0)).unwrap();
    let e = plan(&mut p).unwrap_err();
    assert_eq!(e.reason(), "no_grasp_type");
    assert!(e.to_string().contains("heavier"), "{e}");
    let path = tmp("big.stl");
    TriangleMesh::cuboid(Vector3::new(0.5, 0.5, 0.5))
        .write_stl(&path)
        .unwrap();
    p.set_object(&mesh_object(&path, 0.1)).unwrap();
    let e = plan(&mut p).unwrap_err();
    assert!(e.to_string().contains("GRCmax"), "{e}");
}

#[test]
fn far_object_is_unreachable_even_with_squat() {
    let mut p = ready();
    let path = tmp("far.stl");
    TriangleMesh::cylinder(0.033, 0.122, 24)
        .write_stl(&path)
        .unwrap();
    let mut req = mesh_object(&path, 0.15);
    req.pose = pose_at([2.0, -0.25, 1.0]);
    p.set_object(&req).unwrap();
    let e = plan(&mut p).unwrap_err();
    assert_eq!(e.reason(), "unreachable");
    assert!(e.to_string().contains("squat_z"), "{e}");
}

#[test]
fn cancel_stops_the_plan_and_progress_is_reported() {
    let mut p = ready();
    // An unreachable margin keeps Algorithm 1 sampling until stopped.
    let cancel = AtomicBool::new(false);
    let mut events = Vec::new();
    let r = p.plan(
        &PlanOptions {
            max_samples: 100_000,
            time_budget_ms: Some(600_000),
            delta_f: Some(1000.0),
            ..PlanOptions::default()
        },
        &cancel,
        &mut |e| {
            events.push(e.phase);
            if e.phase == PlanPhase::Search && e.samples >= 32 {
                cancel.store(true, Ordering::Relaxed);
            }
        },
    );
    match r {
        Err(PlanError::NoGrasp {
            no_grasp: tsukami_planner_kit::NoGrasp::Stopped(tsukami_planner_kit::Stop::Cancelled),
            ..
        }) => {}
        other => panic!("expected a cancelled plan, got {other:?}"),
    }
    assert_eq!(events.first(), Some(&PlanPhase::Selection));
    assert!(events.contains(&PlanPhase::Search));
    // The state survives: plan again.
    plan(&mut p).unwrap();
}

#[test]
fn bad_robots_are_refused_and_the_state_is_kept() {
    let mut p = ready();
    let e = p
        .set_robot(&SetRobot {
            robot: "no_such_robot".into(),
            grasp_types: None,
            package_dirs: Vec::new(),
        })
        .unwrap_err();
    assert_eq!(e.reason(), "bad_model");
    // A grasp-type file with a misspelt key names it.
    let cfg = models().join("robots/tsukami_humanoid/grasp_types.toml");
    let text = std::fs::read_to_string(&cfg)
        .unwrap()
        .replacen("closing_step", "closing_stepp", 1);
    let bad = tmp("grasp_types_typo.toml");
    std::fs::write(&bad, text).unwrap();
    let e = p
        .set_robot(&SetRobot {
            robot: "tsukami_humanoid".into(),
            grasp_types: Some(bad.display().to_string()),
            package_dirs: Vec::new(),
        })
        .unwrap_err();
    assert_eq!(e.reason(), "bad_model");
    assert!(e.to_string().contains("closing_stepp"), "{e}");
    // A joint name that is not in the robot.
    let text =
        std::fs::read_to_string(&cfg)
            .unwrap()
            .replacen("\"r_index_j3\"", "\"r_index_j9\"", 1);
    std::fs::write(&bad, text).unwrap();
    let e = p
        .set_robot(&SetRobot {
            robot: "tsukami_humanoid".into(),
            grasp_types: Some(bad.display().to_string()),
            package_dirs: Vec::new(),
        })
        .unwrap_err();
    assert!(e.to_string().contains("r_index_j9"), "{e}");
    plan(&mut p).unwrap();
}
