//! Exports planned grasps as cases for the MuJoCo grasp-hold benchmark
//! (`bench/physics/`, issue #22 item 6): one JSON object per line,
//!
//! ```text
//! {"case", "family", "placement",
//!  "robot": {"urdf": ABS, "description": ABS, "hand": "right"},
//!  "object": {"mesh": ABS, "scale", "pose", "mass", "center_of_mass", "friction"},
//!  "reply": <PlanReply as the planner returns it>}
//! ```
//!
//! Sources: the paper's five scenes (`models/scenes/`, humanoid only: the
//! scenes place the humanoid) and the object benchmark of issue #10
//! (`tests/common/objects.rs`, 55 objects × 5 placements), both planned
//! in-process with the same seed. Only successfully planned replies become
//! cases; failures are counted on stderr. The object benchmark's meshes are
//! kept as binary STL files beside the output (`<out dir>/meshes/`).
//!
//! Run in release: `cargo run --release -p tsukami-grasp-planner --example
//! physics_cases -- [--robot NAME] [--seed N] [--out FILE] [--quick]
//! [--only TEXT] [--limit N] [--source all|scenes|objects]`.
//! `--quick`: the paper scenes and the first object of each family on the
//! first placement; `--only`: cases whose name contains TEXT; `--limit`: at
//! most N planned cases. Default out: `target/physics-cases/<robot>.jsonl`.

#[path = "../tests/common/objects.rs"]
mod objects;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use objects::{objects, placements, set_env, set_object};
use serde_json::{json, Value};
use tsukami_grasp_planner::planner::Planner;
use tsukami_msgs::planner::{ObjectShape, PlanOptions, SetEnv, SetObject, SetRobot};
use tsukami_planner_kit::PlannerConfig;
use tsukami_scenes::{scene_requests, PAPER_SCENES};

fn models() -> PathBuf {
    std::fs::canonicalize(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models"))
        .expect("models/ exists")
}

fn arg(args: &[String], name: &str) -> Option<String> {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .cloned()
}

fn parse<T: serde::de::DeserializeOwned>(v: Value) -> T {
    serde_json::from_value(v).expect("the exporter's own requests are valid")
}

/// The robot's URDF and description (absolute) and its first hand's name.
fn robot_files(urdf_or_name: &str) -> Value {
    let urdf = if urdf_or_name.ends_with(".urdf") {
        PathBuf::from(urdf_or_name)
    } else {
        let dir = models().join("robots").join(urdf_or_name);
        let d: toml::Value =
            toml::from_str(&std::fs::read_to_string(dir.join("description.toml")).unwrap())
                .unwrap();
        dir.join(d["urdf"].as_str().expect("description names its URDF"))
    };
    let urdf = std::fs::canonicalize(urdf).expect("the URDF exists");
    let desc = urdf.parent().unwrap().join("description.toml");
    let d: toml::Value = toml::from_str(&std::fs::read_to_string(&desc).unwrap()).unwrap();
    let hand = d["hand"][0]["name"].as_str().unwrap_or("right").to_string();
    json!({"urdf": urdf, "description": desc, "hand": hand})
}

/// The object part of a case: the mesh file behind a SetObject (model names
/// resolved under `models/objects/`), its pose, mass, centre of mass, μ.
fn object_json(req: &SetObject) -> Value {
    let (mesh, scale, friction) = match &req.shape {
        ObjectShape::Mesh { path, scale } => (PathBuf::from(path), scale.unwrap_or(1.0), None),
        // Scene files name meshes by model or path; an inline mesh never comes from one.
        ObjectShape::Inline { .. } => panic!("the physics cases are built from scene files"),
        ObjectShape::Model { name } => {
            let dir = models().join("objects").join(name);
            let m: toml::Value =
                toml::from_str(&std::fs::read_to_string(dir.join("object.toml")).unwrap()).unwrap();
            let mesh = &m["shape"]["mesh"];
            (
                dir.join(mesh["path"].as_str().expect("a mesh model")),
                mesh.get("scale")
                    .and_then(toml::Value::as_float)
                    .unwrap_or(1.0),
                m.get("friction").and_then(toml::Value::as_float),
            )
        }
    };
    let mesh = std::fs::canonicalize(&mesh).expect("the mesh file exists");
    json!({
        "mesh": mesh,
        "scale": scale,
        "pose": req.pose,
        "mass": req.mass,
        "center_of_mass": req.center_of_mass,
        "friction": req.friction.or(friction).unwrap_or(0.5),
    })
}

struct Exporter {
    planner: Planner,
    seed: u64,
    out: std::fs::File,
    limit: usize,
    written: usize,
    failed: usize,
}

impl Exporter {
    /// Plans one case and writes it when a grasp is returned.
    fn case(
        &mut self,
        name: &str,
        family: &str,
        placement: &str,
        robot: &Value,
        object: &SetObject,
        env: &SetEnv,
    ) {
        if self.written >= self.limit {
            return;
        }
        let set = self
            .planner
            .set_object(object)
            .and_then(|_| self.planner.set_env(env).map(|_| ()));
        if let Err(e) = set {
            eprintln!("  {name}: refused: {e}");
            self.failed += 1;
            return;
        }
        let opts = PlanOptions {
            seed: self.seed,
            ..PlanOptions::default()
        };
        match self
            .planner
            .plan(&opts, &AtomicBool::new(false), &mut |_| {})
        {
            Ok(reply) => {
                let line = json!({
                    "case": name,
                    "family": family,
                    "placement": placement,
                    "seed": self.seed,
                    "robot": robot,
                    "object": object_json(object),
                    "reply": reply,
                });
                writeln!(self.out, "{line}").unwrap();
                self.written += 1;
                eprintln!("  {name}: {}", reply.grasp_type.name);
            }
            Err(e) => {
                eprintln!("  {name}: no grasp: {}", e.reason());
                self.failed += 1;
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let robot_name = arg(&args, "--robot").unwrap_or_else(|| "tsukami_humanoid".into());
    let seed: u64 = arg(&args, "--seed").map_or(1, |s| s.parse().expect("--seed N"));
    let only = arg(&args, "--only").unwrap_or_default();
    let limit: usize = arg(&args, "--limit").map_or(usize::MAX, |s| s.parse().expect("--limit N"));
    let quick = args.iter().any(|a| a == "--quick");
    let source = arg(&args, "--source").unwrap_or_else(|| "all".into());
    let out_path = arg(&args, "--out").map_or_else(
        || {
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../target/physics-cases")
                .join(format!("{robot_name}.jsonl"))
        },
        PathBuf::from,
    );
    let out_dir = out_path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let meshes = out_dir.join("meshes");
    std::fs::create_dir_all(&meshes).unwrap();
    let meshes = std::fs::canonicalize(&meshes).unwrap();
    let planner = Planner::from_config(PlannerConfig::with_roots([models(), meshes.clone()]))
        .expect("the planner starts");
    let mut ex = Exporter {
        planner,
        seed,
        out: std::fs::File::create(&out_path).expect("the output file"),
        limit,
        written: 0,
        failed: 0,
    };

    // (1) The paper's scenes: they place the humanoid, so only for it.
    if robot_name == "tsukami_humanoid" && source != "objects" {
        for s in PAPER_SCENES {
            let name = format!("scene/{}", s.name);
            if !name.contains(&only) {
                continue;
            }
            let req = scene_requests(&models().join("scenes").join(format!("{}.toml", s.name)))
                .expect("the paper's scenes load");
            ex.planner.set_robot(&req.robot).unwrap();
            let robot = robot_files(&req.robot.robot);
            ex.case(&name, "paper_scene", s.name, &robot, &req.object, &req.env);
        }
    }

    // (2) The object benchmark.
    if source != "scenes" {
        let robot_req: SetRobot = parse(json!({ "robot": robot_name }));
        ex.planner.set_robot(&robot_req).unwrap();
        let robot = robot_files(&robot_name);
        let places = placements();
        let mut families_seen: Vec<&str> = Vec::new();
        for o in objects() {
            if quick && families_seen.contains(&o.family) {
                continue;
            }
            families_seen.push(o.family);
            let path = meshes.join(format!("{}.stl", o.name));
            let mut wrote = false;
            for p in places.iter().take(if quick { 1 } else { places.len() }) {
                let name = format!("object/{}/{}", o.name, p.name);
                if !name.contains(&only) {
                    continue;
                }
                if !wrote {
                    o.mesh.write_stl(&path).unwrap();
                    wrote = true;
                }
                let req: SetObject = parse(set_object(&o, p, &path.display().to_string()));
                let env: SetEnv = parse(set_env(p));
                ex.case(&name, o.family, p.name, &robot, &req, &env);
            }
        }
    }
    eprintln!(
        "{} case(s) written to {}, {} not planned (seed {seed}, robot {robot_name})",
        ex.written,
        out_path.display(),
        ex.failed
    );
}
