//! Objects over the bus (issue #26): a client in another process than the host
//! — this test, over zenoh on loopback, to a `tsukami run` child process — sends
//! its own mesh inline in `set_object` (`shape.inline`: base64 of a binary STL,
//! an OBJ or a PLY file) and plans on it.
//!
//! Every world-aware plugin (grasp planner, trajectory planner, result viewer)
//! takes the inline mesh: the grasp is the one the model of the same mesh gets,
//! and the motion to it plans. `tsukami set-object --inline` sends a file of the
//! client's disk, outside the host's model roots, the same way. A mesh over the
//! host's `max_mesh_bytes` is refused naming the field and the limit, one over
//! `max_payload_bytes` is `payload_too_large`, bad base64 and garbage meshes are
//! refused saying what was wrong without quoting the data; after every refusal
//! the world version and the plan stay as they were.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use serde_json::{json, Value};
use tsukami::client::{BusClient, RequestError};
use tsukami::config::HostConfig;
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::mesh_inline::encode_base64;
use tsukami_e2e::{
    models_dir, motion_entry, planner_entry, spawn_tsukami, test_config, tsukami_exe, viewer_entry,
    ChildGuard,
};
use tsukami_msgs::keys::{ROLE_GRASP_PLANNER, ROLE_RESULT_VIEWER, ROLE_TRAJECTORY_PLANNER};
use tsukami_scenes::scene_requests;

const T: Duration = Duration::from_secs(120);
const PLAN: &str = r#"{"seed": 1}"#;

struct TempDir(PathBuf);
impl Drop for TempDir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

fn temp_dir(tag: &str) -> TempDir {
    let dir = std::env::temp_dir().join(format!("tsukami-inline-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    TempDir(dir)
}

/// `tsukami run` on `config` (written to `dir`) as a child process, and a client
/// of this process once the host answers.
fn host_process(dir: &Path, config: &HostConfig) -> (ChildGuard, BusClient) {
    let file = dir.join("host.toml");
    std::fs::write(&file, toml::to_string(config).unwrap()).unwrap();
    let child = spawn_tsukami(&[
        "run",
        "--config",
        file.to_str().unwrap(),
        "--namespace",
        &config.namespace,
    ]);
    let bus = tsukami::bus::BusConfig::connecting(&config.bus.listen[0]);
    let client = BusClient::connect(&bus, &config.namespace).unwrap();
    client.wait_for_host(T).expect("the host process answers");
    (child, client)
}

fn world(c: &BusClient, command: &str, payload: &[u8]) -> Result<Value, RequestError> {
    let bytes = c.request_key(&c.keys().world(command), payload, T)?;
    Ok(serde_json::from_slice(&bytes).unwrap())
}

fn plan(c: &BusClient) -> Value {
    let bytes = c
        .command(ROLE_GRASP_PLANNER, "plan", PLAN.as_bytes(), T)
        .unwrap_or_else(|e| panic!("the plan fails: {e}"));
    serde_json::from_slice(&bytes).unwrap()
}

/// The can scene's requests, the object sent with `shape`.
fn scene_with(shape: Value) -> (Value, Value, Value) {
    let r = scene_requests(&models_dir().join("scenes/can_breast.toml")).unwrap();
    let mut object = serde_json::to_value(&r.object).unwrap();
    object["shape"] = shape;
    (
        serde_json::to_value(&r.robot).unwrap(),
        object,
        serde_json::to_value(&r.env).unwrap(),
    )
}

fn can_stl() -> Vec<u8> {
    std::fs::read(models_dir().join("objects/can_350ml/can_350ml.stl")).unwrap()
}

/// The can as a scanner or MeshLab would send it: a binary PLY of the same
/// triangles.
fn can_ply() -> Vec<u8> {
    let path = models_dir().join("objects/can_350ml/can_350ml.stl");
    let can = TriangleMesh::load(&path, nalgebra::Vector3::repeat(1.0)).unwrap();
    tsukami_body::ply::to_binary(&can)
}

fn inline(format: &str, bytes: &[u8]) -> Value {
    json!({"inline": {"format": format, "data_base64": encode_base64(bytes)}})
}

/// Sets the scene with `shape` as the object: the `set_object` reply.
fn set_scene(c: &BusClient, shape: Value) -> Value {
    let (robot, object, env) = scene_with(shape);
    world(c, "set_robot", robot.to_string().as_bytes()).unwrap();
    let reply = world(c, "set_object", object.to_string().as_bytes())
        .unwrap_or_else(|e| panic!("set_object: {e}"));
    world(c, "set_env", env.to_string().as_bytes()).unwrap();
    reply
}

/// What a grasp is, without the names and versions that differ by design.
fn grasp_of(reply: &Value) -> Value {
    json!([
        reply["grasp_type"],
        reply["palm_pose"],
        reply["joint_positions"]
    ])
}

#[test]
fn an_inline_mesh_from_another_process_plans_on_every_plugin() {
    let dir = temp_dir("plans");
    let config = test_config(vec![planner_entry(), motion_entry(), viewer_entry()]);
    let (_host, c) = host_process(&dir.0, &config);
    // The can's model, by name: the grasp to match.
    set_scene(&c, json!({"model": {"name": "can_350ml"}}));
    let by_model = plan(&c);
    // The same can as a client on another machine sends it: its STL's bytes.
    let summary = set_scene(&c, inline("stl", &can_stl()));
    assert_eq!(summary["name"], "can", "the request's name: {summary}");
    assert_eq!(summary["triangles"], 480, "{summary}");
    let v = summary["world_version"].as_u64().unwrap();
    let state = world(&c, "get", b"{}").unwrap();
    assert_eq!(state["version"], v + 1, "set_env came after it");
    assert_eq!(state["object"]["shape"]["inline"]["format"], "stl");
    assert_eq!(
        state["plugins"].as_array().unwrap().len(),
        3,
        "every plugin took it: {}",
        state["plugins"]
    );
    // The viewer holds the same world (it draws the inline object).
    let viewer = c
        .command(ROLE_RESULT_VIEWER, "state", b"{}", T)
        .expect("viewer/state");
    let viewer: Value = serde_json::from_slice(&viewer).unwrap();
    assert_eq!(viewer["world_version"], v + 1);
    let grasp = plan(&c);
    assert_eq!(grasp["world_version"], v + 1);
    assert_eq!(grasp_of(&grasp), grasp_of(&by_model));
    // The trajectory planner plans the motion to it, on the same world.
    let request = serde_json::to_vec(&json!({"grasp": grasp, "seed": 1})).unwrap();
    let motion = c
        .command(ROLE_TRAJECTORY_PLANNER, "plan", &request, T)
        .unwrap_or_else(|e| panic!("the motion to the inline object's grasp: {e}"));
    let motion: Value = serde_json::from_slice(&motion).unwrap();
    assert_eq!(motion["world_version"], v + 1);
    // An OBJ inline is taken too.
    let obj = std::fs::read(models_dir().join("objects/box/box.obj")).unwrap();
    let (_, mut object, _) = scene_with(inline("obj", &obj));
    object["name"] = "client box".into();
    let r = world(&c, "set_object", object.to_string().as_bytes()).unwrap();
    assert_eq!(
        (r["name"].clone(), r["triangles"].clone()),
        (json!("client box"), json!(12))
    );
    // `tsukami set-object --inline`, another process again, sends a file the
    // host could not read itself: it lies outside the host's model roots.
    let copy = dir.0.join("my_can.stl");
    std::fs::write(&copy, can_stl()).unwrap();
    let (_, mut object, _) = scene_with(json!({"mesh": {"path": copy}}));
    object.as_object_mut().unwrap().remove("name");
    let refused = world(&c, "set_object", object.to_string().as_bytes()).unwrap_err();
    assert_eq!(refused.code().map(|c| c.as_str()), Some("model_error"));
    object["shape"]["mesh"]["scale"] = 1.0.into();
    let r = set_object_inline_cli(&config, &object);
    assert_eq!(r["name"], "my_can", "{r}");
    let again = plan(&c);
    assert_eq!(again["world_version"], r["world_version"]);
    assert_eq!(grasp_of(&again), grasp_of(&by_model));
}

#[test]
fn an_inline_ply_plans_the_grasp_of_its_model_from_json_and_from_the_cli() {
    let dir = temp_dir("ply");
    let config = test_config(vec![planner_entry()]);
    let (_host, c) = host_process(&dir.0, &config);
    set_scene(&c, json!({"model": {"name": "can_350ml"}}));
    let by_model = plan(&c);
    // The can's mesh as a PLY, base64 in the request.
    let summary = set_scene(&c, inline("ply", &can_ply()));
    assert_eq!(summary["triangles"], 480, "{summary}");
    let state = world(&c, "get", b"{}").unwrap();
    assert_eq!(state["object"]["shape"]["inline"]["format"], "ply");
    let grasp = plan(&c);
    assert_eq!(grasp["world_version"], state["version"]);
    assert_eq!(grasp_of(&grasp), grasp_of(&by_model));
    // `tsukami set-object --inline` takes a `.ply` of the client's disk by its
    // extension.
    let copy = dir.0.join("Scanned_Can.PLY");
    std::fs::write(&copy, can_ply()).unwrap();
    let (_, mut object, _) = scene_with(json!({"mesh": {"path": copy}}));
    object.as_object_mut().unwrap().remove("name");
    let r = set_object_inline_cli(&config, &object);
    assert_eq!(r["name"], "Scanned_Can", "{r}");
    let state = world(&c, "get", b"{}").unwrap();
    assert_eq!(state["object"]["shape"]["inline"]["format"], "ply");
    let again = plan(&c);
    assert_eq!(again["world_version"], r["world_version"]);
    assert_eq!(grasp_of(&again), grasp_of(&by_model));
}

/// A binary STL of a UV sphere with about `triangles` triangles.
fn sphere_stl(dir: &Path, triangles: usize) -> Vec<u8> {
    let rings = ((triangles / 2) as f64).sqrt() as usize;
    let path = dir.join("sphere.stl");
    TriangleMesh::uv_sphere(0.04, rings, rings)
        .write_stl(&path)
        .unwrap();
    std::fs::read(&path).unwrap()
}

#[test]
fn too_large_bad_and_garbage_inline_meshes_are_refused_and_the_world_stays() {
    const MESH_LIMIT: u64 = 32 << 10;
    let dir = temp_dir("refused");
    let mut config = test_config(vec![planner_entry()]);
    config.limits.max_mesh_bytes = MESH_LIMIT;
    config.limits.max_payload_bytes = 1 << 20;
    let (_host, c) = host_process(&dir.0, &config);
    set_scene(&c, inline("stl", &can_stl()));
    let baseline = plan(&c);
    let version = world(&c, "get", b"{}").unwrap()["version"].clone();
    let big = sphere_stl(&dir.0, 1000);
    assert!(big.len() as u64 > MESH_LIMIT && big.len() < 1 << 19);
    let mut truncated = can_stl();
    truncated.truncate(truncated.len() - 10);
    // One triangle, every corner NaN: nothing usable is left after cleaning.
    let mut nan = vec![0u8; 80];
    nan.extend_from_slice(&1u32.to_le_bytes());
    nan.extend_from_slice(&[0u8; 12]);
    for _ in 0..9 {
        nan.extend_from_slice(&f32::NAN.to_le_bytes());
    }
    nan.extend_from_slice(&[0, 0]);
    let huge = vec![b'A'; 2 << 20];
    let vertex = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
    let lying_ply = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n\
        property float x\nproperty float y\nproperty float z\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n";
    let bad_index_ply = format!(
        "ply\nformat ascii 1.0\n{vertex}element face 1\n\
         property list uchar int vertex_indices\nend_header\n\
         0 0 0\n1 0 0\n0 1 0\n3 0 1 3 TSUKAMI-GARBAGE\n"
    );
    let point_cloud =
        format!("ply\nformat ascii 1.0\n{vertex}end_header\n0 0 0\n1 0 0\nTSUKAMI-GARBAGE\n");
    let cases: Vec<(&str, Value, &str, Vec<String>)> = vec![
        (
            "over max_mesh_bytes",
            inline("stl", &big),
            "invalid_value",
            vec![
                "shape.inline.data_base64".into(),
                format!("{} bytes) decoded", big.len()),
                "more than the limit of 32.0 KiB (32768 bytes)".into(),
                "max_mesh_bytes".into(),
            ],
        ),
        (
            "over max_payload_bytes",
            json!({"inline": {"format": "stl", "data_base64": String::from_utf8(huge).unwrap()}}),
            "payload_too_large",
            vec!["1048576".into()],
        ),
        (
            "not base64",
            json!({"inline": {"format": "stl", "data_base64": "c29saWQ*eA=="}}),
            "invalid_value",
            vec![
                "shape.inline.data_base64".into(),
                "outside the alphabet at offset 7".into(),
            ],
        ),
        (
            "no data",
            json!({"inline": {"format": "stl", "data_base64": ""}}),
            "invalid_value",
            vec!["shape.inline.data_base64".into(), "no data".into()],
        ),
        (
            "garbage bytes",
            inline("stl", b"TSUKAMI-GARBAGE \x00\x01\x02 not a mesh at all"),
            "model_error",
            vec!["shape.inline.data_base64".into(), "inline STL".into()],
        ),
        (
            "truncated binary STL",
            inline("stl", &truncated),
            "model_error",
            vec!["inline STL".into()],
        ),
        (
            "non-finite vertex",
            inline("stl", &nan),
            "model_error",
            vec!["shape.inline".into(), "non-finite".into()],
        ),
        (
            "an STL sent as OBJ",
            inline("obj", &can_stl()),
            "model_error",
            vec!["inline OBJ".into()],
        ),
        (
            "unknown format",
            json!({"inline": {"format": "off", "data_base64": "T0ZGCg=="}}),
            "invalid_request",
            vec![
                "shape.inline.format".into(),
                "unknown variant `off`, expected one of `stl`, `obj`, `ply`".into(),
            ],
        ),
        (
            "a PLY header claiming 10^12 vertices",
            inline("ply", lying_ply.as_bytes()),
            "invalid_value",
            vec![
                "shape.inline.data_base64".into(),
                "inline PLY: too large: 1000000000000 vertices".into(),
                "MAX_TRIANGLES".into(),
            ],
        ),
        (
            "a PLY face naming a missing vertex",
            inline("ply", bad_index_ply.as_bytes()),
            "model_error",
            vec![
                "shape.inline.data_base64".into(),
                "inline PLY".into(),
                "face 0 (line 13): corner 2 of 3 names a vertex outside the 3 of the file".into(),
            ],
        ),
        (
            "a truncated PLY",
            inline("ply", &can_ply()[..1000]),
            "model_error",
            vec!["inline PLY".into(), "do not fit".into()],
        ),
        (
            "a PLY point cloud",
            inline("ply", point_cloud.as_bytes()),
            "model_error",
            vec!["inline PLY".into(), "a point cloud, not a mesh".into()],
        ),
        (
            "a path beside the data",
            json!({"inline": {"format": "stl", "data_base64": "cGx5Cg==", "path": "x.stl"}}),
            "invalid_request",
            vec!["path".into()],
        ),
    ];
    for (name, shape, code, says) in cases {
        let (_, object, _) = scene_with(shape);
        let e = world(&c, "set_object", object.to_string().as_bytes()).expect_err(name);
        let RequestError::Reply(reply) = &e else {
            panic!("{name}: no error reply: {e}");
        };
        let text = serde_json::to_string(reply).unwrap();
        assert_eq!(reply.error.code.as_str(), code, "{name}: {text}");
        for s in says {
            assert!(text.contains(&s), "{name}: `{s}` not in {text}");
        }
        assert!(!text.contains("TSUKAMI-GARBAGE"), "{name}: {text}");
        assert!(text.len() < 2000, "{name}: a long reply: {text:.300}");
        let state = world(&c, "get", b"{}").unwrap();
        assert_eq!(state["version"], version, "{name}: the version moved");
        assert_eq!(
            state["object"]["shape"]["inline"]["format"], "stl",
            "{name}"
        );
    }
    let again = plan(&c);
    assert_eq!(again["world_version"], baseline["world_version"]);
    assert_eq!(grasp_of(&again), grasp_of(&baseline), "the plan changed");
}

/// `tsukami set-object --inline OBJECT` against the test host: its reply.
fn set_object_inline_cli(config: &HostConfig, object: &Value) -> Value {
    let out = Command::new(tsukami_exe())
        .args(["set-object", "--inline", &object.to_string()])
        .args([
            "--connect",
            &config.bus.listen[0],
            "--namespace",
            &config.namespace,
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}
