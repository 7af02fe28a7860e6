//! Meshes as they come (issue #10): a closed non-manifold mug, an open noisy
//! scan (also one wound at random), a mesh with duplicate vertices and
//! zero-area triangles, a binary STL of a million triangles — each written to a
//! file, loaded through `set_object` like a user's mesh, and planned on; the
//! `set_object` reply says what was done (`warnings`), and every grasp is
//! checked by the independent checker (`tsukami_scenes::verify`).

#[path = "common/objects.rs"]
mod objects;

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use objects::{mug, scan, set_env, set_object, sphere_with, BenchObject, Placement};
use serde_json::json;
use tsukami_body::mesh::TriangleMesh;
use tsukami_grasp_planner::planner::Planner;
use tsukami_msgs::planner::{ObjectSummary, PlanOptions, PlanReply, SetEnv, SetObject, SetRobot};
use tsukami_scenes::{verify, Tolerances, World};

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

fn tmp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tsukami-meshes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::canonicalize(dir).unwrap()
}

fn robot() -> SetRobot {
    serde_json::from_value(json!({"robot": "tsukami_humanoid"})).unwrap()
}

fn planner() -> Planner {
    let config = tsukami_planner_kit::PlannerConfig::with_roots([models(), tmp_dir()]);
    let p = Planner::from_config(config).unwrap();
    p.set_robot(&robot()).unwrap();
    p
}

fn object(name: &str, mesh: TriangleMesh, mass: f64) -> BenchObject {
    BenchObject {
        name: name.into(),
        family: if name.starts_with("scan") {
            "scan"
        } else {
            "test"
        },
        mesh,
        mass,
        flat: false,
    }
}

/// The paper's breast-height counter (`models/scenes/can_breast.toml`).
fn counter() -> Placement {
    Placement {
        name: "counter_1.10",
        top: 1.10,
        xy: [0.52, -0.25],
        yaw: 0.0,
        lying: false,
        obstacles: json!([{"name": "counter", "shape": {"box": {"size": [0.45, 1.0, 1.10]}},
                           "pose": {"position": [0.70, -0.20, 0.55]}}]),
    }
}

/// Sets `o` (read from `path`) on the counter and plans with `seed`.
fn set_and_plan(
    p: &Planner,
    o: &BenchObject,
    path: &Path,
    seed: u64,
) -> (ObjectSummary, PlanReply, SetObject, SetEnv) {
    let place = &counter();
    let req: SetObject =
        serde_json::from_value(set_object(o, place, &path.display().to_string())).unwrap();
    let env: SetEnv = serde_json::from_value(set_env(place)).unwrap();
    let summary = p.set_object(&req).unwrap();
    p.set_env(&env).unwrap();
    let opts = PlanOptions {
        seed,
        ..PlanOptions::default()
    };
    let reply = p
        .plan(&opts, &AtomicBool::new(false), &mut |_| {})
        .unwrap_or_else(|e| panic!("{}: {e}", o.name));
    (summary, reply, req, env)
}

fn assert_verified(req: &SetObject, env: &SetEnv, reply: &PlanReply) {
    let world = World::from_requests(&models(), &robot(), req, env).unwrap();
    let verdict = verify(&world, reply, &Tolerances::default());
    assert!(
        verdict.is_ok(),
        "{}: {verdict}",
        req.name.as_deref().unwrap_or("?")
    );
}

#[test]
fn a_closed_non_manifold_mug_is_accepted_and_planned() {
    let p = planner();
    // A can-sized mug (the benchmark has shorter ones; see docs/benchmarks.md).
    let o = object("mug", mug(0.033, 0.122), 0.15);
    let path = tmp_dir().join("mug.stl");
    o.mesh.write_stl(&path).unwrap();
    let (s, r, req, env) = set_and_plan(&p, &o, &path, 1);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("non-manifold") && w.contains("solid")),
        "{:?}",
        s.warnings
    );
    assert_verified(&req, &env, &r);
}

#[test]
fn an_open_scan_is_accepted_with_its_fallback_and_planned() {
    let p = planner();
    let o = object(
        "scan",
        scan(TriangleMesh::cylinder(0.033, 0.12, 48), 0.0008, 7, false),
        0.3,
    );
    let path = tmp_dir().join("scan.stl");
    o.mesh.write_stl(&path).unwrap();
    let (s, r, req, env) = set_and_plan(&p, &o, &path, 1);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("open mesh: 48 boundary edges")),
        "{:?}",
        s.warnings
    );
    assert_verified(&req, &env, &r);

    // The same scan wound at random: re-wound, said so, and planned (the
    // checker reads the file's own winding, so it judges only the first).
    let o = object(
        "scan_miswound",
        scan(TriangleMesh::cylinder(0.033, 0.12, 48), 0.0008, 7, true),
        0.3,
    );
    let path = tmp_dir().join("scan_miswound.obj");
    o.mesh.write_obj(&path).unwrap();
    let (s, r, ..) = set_and_plan(&p, &o, &path, 1);
    assert!(
        s.warnings.iter().any(|w| w.contains("flipped")),
        "{:?}",
        s.warnings
    );
    assert!(
        s.warnings.iter().any(|w| w.contains("open mesh")),
        "{:?}",
        s.warnings
    );
    assert!(r.force_closure.exact_resists_weight);
}

#[test]
fn duplicate_vertices_and_zero_area_triangles_are_cleaned_and_said() {
    let p = planner();
    let mut m = TriangleMesh::cylinder(0.033, 0.122, 32);
    // Every vertex repeated (an STL-like soup) and three zero-area triangles.
    let n = m.vertices.len() as u32;
    m.vertices.extend(m.vertices.clone());
    for t in m.indices.iter_mut().step_by(2) {
        *t = t.map(|i| i + n);
    }
    m.indices.push([0, 1, n + 1]); // 1 and n + 1 are the same point
    m.indices.push([2, 2, 3]);
    m.indices.push([4, n + 4, 5]);
    let o = object("soup", m, 0.2);
    let path = tmp_dir().join("soup.obj");
    o.mesh.write_obj(&path).unwrap();
    let (s, r, req, env) = set_and_plan(&p, &o, &path, 1);
    assert!(
        s.warnings.iter().any(|w| w.contains("dropped 3 zero-area")),
        "{:?}",
        s.warnings
    );
    assert_eq!(s.triangles, 4 * 32);
    assert_verified(&req, &env, &r);
}

#[test]
fn a_million_triangle_binary_stl_loads_and_plans() {
    let p = planner();
    let o = object("sphere_1m", sphere_with(1_000_000, 0.035), 0.15);
    let path = tmp_dir().join("sphere_1m.stl");
    o.mesh.write_stl(&path).unwrap();
    let (s, r, req, env) = set_and_plan(&p, &o, &path, 1);
    assert!(s.triangles >= 1_000_000, "{}", s.triangles);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_verified(&req, &env, &r);
    std::fs::remove_file(&path).unwrap();
}

/// A 10 mm pen standing on the counter: thinner than the 12 mm the small
/// fingertip types once required (refused as `no_grasp_type`); the thumb tip
/// and the finger tips meet, and the grasp is planned and verified.
#[test]
fn a_pen_thinner_than_a_finger_is_planned() {
    let p = planner();
    let o = object("pen", TriangleMesh::cylinder(0.005, 0.14, 24), 0.02);
    let path = tmp_dir().join("pen.stl");
    o.mesh.write_stl(&path).unwrap();
    let (_, r, req, env) = set_and_plan(&p, &o, &path, 1);
    assert!(
        r.grasp_type.name.ends_with("_small"),
        "{}",
        r.grasp_type.name
    );
    assert_verified(&req, &env, &r);
}
