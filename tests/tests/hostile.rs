//! A hostile corpus against a real host with the real grasp planner over a real
//! bus: garbage payloads, hostile model paths and files (FIFOs, device symlinks,
//! sparse files, paths out of the roots, procfs), stop storms and bounded floods.
//! After every case the host still answers, plans the same grasp as before the
//! corpus, no reply carries a planted secret or an absolute folder, and the
//! process's VmRSS stays under the bound of docs/protocol.md ("Limits").

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use tsukami::client::{BusClient, RequestError};
use tsukami_e2e::{models_dir, planner_entry, test_config, TestBus};
use tsukami_msgs::keys::{planner, ROLE_GRASP_PLANNER};
use tsukami_scenes::scene_requests;

const SECRET: &str = "TSUKAMI-PLANTED-SECRET-7f3a";
const CASE_LIMIT: Duration = Duration::from_secs(10);

struct TempDir(PathBuf);
impl Drop for TempDir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

fn send(c: &BusClient, command: &str, payload: &[u8]) -> Result<String, String> {
    match c.command(ROLE_GRASP_PLANNER, command, payload, CASE_LIMIT) {
        Ok(bytes) => Ok(String::from_utf8_lossy(&bytes).into_owned()),
        Err(RequestError::Reply(reply)) => Err(serde_json::to_string(&reply).unwrap()),
        Err(other) => panic!("{command}: no well-formed reply: {other}"),
    }
}

/// The reply without its timing fields (wall-clock figures vary between runs).
fn without_timing(mut v: serde_json::Value) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(map) => {
                map.retain(|k, _| !(k.ends_with("_ms") || k.contains("time") || k == "stats"));
                map.values_mut().for_each(strip);
            }
            serde_json::Value::Array(items) => items.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut v);
    v
}

fn vm_rss_bytes() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let line = status.lines().find(|l| l.starts_with("VmRSS:")).unwrap();
    let kb: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kb * 1024
}

/// Hostile files in a temp folder that is itself a model root, and a secret outside.
fn hostile_files(root: &Path, outside: &Path) -> Vec<String> {
    std::fs::create_dir_all(root).unwrap();
    std::fs::create_dir_all(outside).unwrap();
    let secret = outside.join("secret.toml");
    std::fs::write(&secret, format!("a = 1\nb = 2\nkey = \"{SECRET}\"\n")).unwrap();
    let link = |target: &Path, name: &str| {
        std::os::unix::fs::symlink(target, root.join(name)).unwrap();
    };
    link(Path::new("/dev/zero"), "zero.stl");
    link(Path::new("/dev/urandom"), "random.urdf");
    link(Path::new("/proc/self/environ"), "environ.toml");
    link(&secret, "secret-link.toml");
    let fifo = std::ffi::CString::new(root.join("fifo.stl").to_string_lossy().as_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path; mkfifo only creates a node.
    assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0);
    let sparse = std::fs::File::create(root.join("sparse.stl")).unwrap();
    sparse.set_len(1 << 30).unwrap();
    let deep = format!(
        "<robot name=\"d\">{}{}</robot>",
        "<a>".repeat(10_000),
        "</a>".repeat(10_000)
    );
    std::fs::write(root.join("deep.urdf"), deep).unwrap();
    let mut many = String::from("<robot name=\"m\"><link name=\"l0\"/>");
    for i in 1..100_000 {
        many.push_str(&format!(
            "<link name=\"l{i}\"/><joint name=\"j{i}\" type=\"fixed\"><parent link=\"l{}\"/><child link=\"l{i}\"/></joint>",
            i - 1
        ));
    }
    many.push_str("</robot>");
    std::fs::write(root.join("many.urdf"), many).unwrap();
    let mut nan = b"solid n\n".to_vec();
    nan.extend_from_slice(b"facet normal 0 0 1\nouter loop\nvertex NaN 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid n\n");
    std::fs::write(root.join("nan.stl"), nan).unwrap();
    std::fs::write(root.join("bad.toml"), format!("x = \"{SECRET}\"\n[[[\n")).unwrap();
    let mut paths: Vec<String> = [
        "zero.stl",
        "random.urdf",
        "environ.toml",
        "secret-link.toml",
        "fifo.stl",
        "sparse.stl",
        "deep.urdf",
        "many.urdf",
        "nan.stl",
        "bad.toml",
    ]
    .iter()
    .map(|n| root.join(n).display().to_string())
    .collect();
    // The same files named relative to their root.
    paths.extend(
        [
            "zero.stl",
            "random.urdf",
            "environ.toml",
            "secret-link.toml",
            "fifo.stl",
            "sparse.stl",
            "deep.urdf",
            "many.urdf",
            "nan.stl",
            "bad.toml",
        ]
        .map(String::from),
    );
    paths.extend([
        secret.display().to_string(),
        "../../../../etc/passwd".into(),
        "/etc/passwd".into(),
        "/etc/shadow".into(),
        "/proc/self/environ".into(),
        "/proc/self/cmdline".into(),
        "/proc/self/fd/0".into(),
        "/dev/zero".into(),
        "/dev/urandom".into(),
        "robots/../../../etc/passwd".into(),
        "".into(),
        "x".repeat(5000),
    ]);
    paths
}

#[test]
fn the_host_survives_a_hostile_corpus_unchanged() {
    let base =
        TempDir(std::env::temp_dir().join(format!("tsukami-hostile-{}", std::process::id())));
    let root = base.0.join("root");
    let outside = base.0.join("outside");
    let paths = hostile_files(&root, &outside);
    let mut config = test_config(vec![planner_entry()]);
    config.models.roots = vec![models_dir(), root.clone()];
    config.limits.max_queue = 4;
    config.limits.max_payload_bytes = 1 << 20;
    let limits = config.limits.clone();
    let bus = TestBus::start(config);
    let c = &bus.client;

    let req = scene_requests(&models_dir().join("scenes/can_breast.toml")).unwrap();
    let robot = serde_json::to_value(&req.robot).unwrap();
    let object = serde_json::to_value(&req.object).unwrap();
    send(c, planner::SET_ROBOT, robot.to_string().as_bytes()).unwrap();
    send(c, planner::SET_OBJECT, object.to_string().as_bytes()).unwrap();
    send(
        c,
        planner::SET_ENV,
        serde_json::to_string(&req.env).unwrap().as_bytes(),
    )
    .unwrap();
    let plan = br#"{"seed": 1}"#;
    let parse = |s: &str| without_timing(serde_json::from_str(s).unwrap());
    let baseline = parse(&send(c, planner::PLAN, plan).expect("the baseline plan succeeds"));
    // Bound of docs/protocol.md with P = 1, L = 2 links, F taken as 8 M plus the
    // largest model files, B as measured now (host and test client in one process).
    let m = limits.max_payload_bytes as u64;
    let bound = vm_rss_bytes()
        + (limits.max_queue as u64 + 2) * m
        + 2 * (2 * m + (1 << 20))
        + 8 * m
        + limits.max_mesh_bytes
        + limits.max_urdf_bytes;

    let mut cases: Vec<(String, &str, Vec<u8>)> = vec![];
    let garbage: Vec<Vec<u8>> = vec![
        b"[]".to_vec(),
        b"1".to_vec(),
        b"\"x\"".to_vec(),
        b"null".to_vec(),
        b"{".to_vec(),
        b"\xff\xfe".to_vec(),
        b"{\"a\":NaN}".to_vec(),
        b"{\"mass\":1e400}".to_vec(),
        "[".repeat(100_000).into_bytes(),
        vec![b'{'; 50_000],
        vec![b' '; 1 << 21],
        format!("{{\"x\":\"{}\"}}", "a".repeat(2 << 20)).into_bytes(),
        br#"{"unknown": 1}"#.to_vec(),
        br#"{"pose": {"position": [1e308, 0, 0], "quaternion": [0,0,0,1]}}"#.to_vec(),
    ];
    for command in [
        planner::SET_ROBOT,
        planner::SET_OBJECT,
        planner::SET_ENV,
        planner::PLAN,
        "stop",
        "remove_env",
        "nonsense",
    ] {
        for (i, g) in garbage.iter().enumerate() {
            cases.push((format!("{command} garbage {i}"), command, g.clone()));
        }
    }
    for p in &paths {
        let mut r = robot.clone();
        r["robot"] = p.as_str().into();
        cases.push((
            format!("robot {p:.60}"),
            planner::SET_ROBOT,
            r.to_string().into_bytes(),
        ));
        let mut r = robot.clone();
        r["grasp_types"] = p.as_str().into();
        cases.push((
            format!("grasp_types {p:.60}"),
            planner::SET_ROBOT,
            r.to_string().into_bytes(),
        ));
        let mut o = object.clone();
        o["shape"] = serde_json::json!({"mesh": {"path": p}});
        cases.push((
            format!("mesh {p:.60}"),
            planner::SET_OBJECT,
            o.to_string().into_bytes(),
        ));
        let env = serde_json::json!({"obstacles": [{"name": "o", "shape": {"mesh": {"path": p}},
            "pose": {"position": [0.5, 0, 0], "quaternion": [0, 0, 0, 1]}}]});
        cases.push((
            format!("obstacle {p:.60}"),
            planner::SET_ENV,
            env.to_string().into_bytes(),
        ));
    }
    for (field, value) in [
        ("mass", serde_json::json!(-1.0)),
        ("friction", serde_json::json!(50.0)),
        ("center_of_mass", serde_json::json!([10.0, 0, 0])),
    ] {
        let mut o = object.clone();
        o[field] = value;
        cases.push((
            format!("object {field}"),
            planner::SET_OBJECT,
            o.to_string().into_bytes(),
        ));
    }
    for budget in [0u64, u64::MAX] {
        cases.push((
            format!("plan samples {budget}"),
            planner::PLAN,
            format!("{{\"max_samples\": {budget}}}").into_bytes(),
        ));
    }
    for i in 0..80 {
        cases.push((format!("stop storm {i}"), "stop", b"{}".to_vec()));
    }
    assert!(cases.len() >= 300, "{} cases", cases.len());

    let absolute = [
        base.0.display().to_string(),
        models_dir().canonicalize().unwrap().display().to_string(),
    ];
    for (i, (name, command, payload)) in cases.iter().enumerate() {
        let start = Instant::now();
        let reply = match send(c, command, payload) {
            Ok(s) | Err(s) => s,
        };
        assert!(!reply.contains(SECRET), "{name}: secret in {reply:.300}");
        assert!(
            !reply.contains("root:"),
            "{name}: passwd content in {reply:.300}"
        );
        for a in &absolute {
            // (A path the request itself gave may be echoed back; no other.)
            let asked = String::from_utf8_lossy(payload).contains(a.as_str());
            assert!(
                asked || !reply.contains(a.as_str()),
                "{name}: absolute folder in {reply:.300}"
            );
        }
        assert!(
            start.elapsed() < CASE_LIMIT,
            "{name}: {:?}",
            start.elapsed()
        );
        if i % 4 == 0 || command.starts_with("set") {
            let again = parse(&match send(c, planner::PLAN, plan) {
                Ok(s) | Err(s) => s,
            });
            assert_eq!(again, baseline, "{name}: the plan changed");
        }
        let rss = vm_rss_bytes();
        assert!(rss < bound, "{name}: VmRSS {rss} over the bound {bound}");
    }
    // A bounded flood: more plans at once than the queue holds; every one gets a
    // reply (a grasp or `busy`), and the host still plans the same grasp.
    let replies: Vec<String> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..12)
            .map(|_| {
                s.spawn(|| match send(c, planner::PLAN, plan) {
                    Ok(s) | Err(s) => s,
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert!(
        replies.iter().any(|r| r.contains("\"busy\"")),
        "the queue limit answered busy"
    );
    let again = parse(&match send(c, planner::PLAN, plan) {
        Ok(s) | Err(s) => s,
    });
    assert_eq!(again, baseline, "after the flood");
}
