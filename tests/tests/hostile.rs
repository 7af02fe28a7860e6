//! A hostile corpus against a real `tsukami run` child process (the binary cargo
//! built) with the real grasp planner, over a real zenoh bus on loopback: garbage
//! payloads on every command, hostile model paths and files (FIFOs, device and
//! procfs symlinks, a 1 GiB sparse file, 10k-deep and 100k-link URDF, NaN mesh,
//! paths out of the roots), inline meshes that are not base64 or not meshes,
//! bad values, stop storms (alone and during a plan) and a bounded flood.
//!
//! The host runs in its own process so that an abort, a stack overflow or the OOM
//! killer ends the child, not the test, and the test reports it (exit status and the
//! end of the child's standard error). After every case the child still runs and
//! answers, every reply is well formed (a JSON object or an error object, never
//! `internal` or `plugin_panicked`), a plan gives exactly the baseline grasp (every
//! plan that succeeds is compared, including the flood's), no reply carries the
//! secret planted in a file outside the roots and in the child's own environment, or
//! an absolute folder, and the child's VmRSS stays under the bound of
//! docs/protocol.md ("Limits"); at the end its VmHWM (peak RSS) does too.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use tsukami::bus::free_loopback_port;
use tsukami::bus::BusConfig;
use tsukami::client::{BusClient, RequestError};
use tsukami::config::HostConfig;
use tsukami_bus::Component;
use tsukami_e2e::hostile::{check_well_formed, garbage};
use tsukami_e2e::{
    models_dir, planner_entry, plugin_entry, test_config, tsukami_exe, ChildGuard, TestBus,
};
use tsukami_msgs::host::StopReply;
use tsukami_msgs::keys::{planner, ROLE_GRASP_PLANNER};
use tsukami_scenes::scene_requests;

const SECRET: &str = "TSUKAMI-PLANTED-SECRET-7f3a";
const CASE_LIMIT: Duration = Duration::from_secs(10);
const MIB: u64 = 1 << 20;

struct TempDir(PathBuf);
impl Drop for TempDir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

impl TempDir {
    fn new(tag: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("tsukami-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }
}

/// A `tsukami run` child process serving one namespace on a loopback port. Its
/// standard input is a pipe nobody writes (so `/proc/self/fd/0` would block a
/// reader), its environment holds [`SECRET`], its standard error goes to a file.
struct ChildHost {
    child: ChildGuard,
    log: PathBuf,
    namespace: String,
    endpoint: String,
}

impl ChildHost {
    /// Writes `config` as a host config file in `dir`, starts `tsukami run` on it and
    /// connects a client once the host answers. A port taken between picking and
    /// binding it is replaced by a fresh one.
    fn start(dir: &Path, mut config: HostConfig) -> (ChildHost, BusClient) {
        const ATTEMPTS: usize = 8;
        for attempt in 1..=ATTEMPTS {
            let mut host = ChildHost::spawn(dir, &config);
            match host.connect() {
                Ok(client) => return (host, client),
                Err(log) if log.contains("already in use") && attempt < ATTEMPTS => {
                    let fresh = test_config(vec![]);
                    config.bus = fresh.bus;
                    config.namespace = fresh.namespace;
                }
                Err(log) => panic!("`tsukami run` did not come up: {log}"),
            }
        }
        unreachable!("the last attempt returns or panics")
    }

    fn spawn(dir: &Path, config: &HostConfig) -> ChildHost {
        let namespace = config.namespace.clone();
        let file = dir.join(format!("{namespace}.toml"));
        std::fs::write(&file, toml::to_string(config).expect("config as TOML")).unwrap();
        let log = dir.join(format!("{namespace}.log"));
        let child = Command::new(tsukami_exe())
            .args(["run", "--config", file.to_str().unwrap()])
            .args(["--namespace", &namespace])
            .env("TSUKAMI_HOSTILE_SECRET", SECRET)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log).unwrap())
            .spawn()
            .expect("spawning tsukami run");
        ChildHost {
            child: ChildGuard(child),
            log,
            namespace,
            endpoint: config.bus.listen[0].clone(),
        }
    }

    /// A client once the host answers `host/plugins`; `Err` (with the child's log)
    /// when the child exited first or did not answer within a minute.
    fn connect(&mut self) -> Result<BusClient, String> {
        let start = Instant::now();
        let address = self.endpoint.trim_start_matches("tcp/").to_owned();
        while std::net::TcpStream::connect(&address).is_err() {
            if let Some(dead) = self.exited() {
                return Err(dead);
            }
            if start.elapsed() > Duration::from_secs(60) {
                return Err(format!("not listening after 60 s; {}", self.log_tail()));
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let client = BusClient::connect(&BusConfig::connecting(&self.endpoint), &self.namespace)
            .map_err(|e| format!("client: {e:#}"))?;
        while start.elapsed() < Duration::from_secs(60) {
            if let Some(dead) = self.exited() {
                return Err(dead);
            }
            if client.wait_for_host(Duration::from_millis(500)).is_ok() {
                return Ok(client);
            }
        }
        Err(format!("no answer after 60 s; {}", self.log_tail()))
    }

    /// `Some(exit status and log)` once the child has exited.
    fn exited(&mut self) -> Option<String> {
        let status = self.child.0.try_wait().expect("try_wait")?;
        Some(format!("the host exited: {status}; {}", self.log_tail()))
    }

    fn log_tail(&self) -> String {
        let log = std::fs::read_to_string(&self.log).unwrap_or_default();
        let tail: String = log.chars().rev().take(3000).collect();
        format!(
            "its standard error ends:\n{}",
            tail.chars().rev().collect::<String>()
        )
    }

    /// Panics naming `case`, the request's failure and whether the child still runs.
    fn no_reply(&mut self, case: &str, error: RequestError) -> ! {
        match self.exited() {
            Some(dead) => panic!("{case}: killed the host ({error}); {dead}"),
            None => panic!("{case}: no well-formed reply ({error}); the host still runs"),
        }
    }

    /// `(VmRSS, VmHWM)` of the child, bytes (`/proc/<pid>/status`).
    fn memory(&self) -> (u64, u64) {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.0.id()))
            .expect("the host's /proc status");
        let field = |name: &str| {
            let line = status.lines().find(|l| l.starts_with(name)).unwrap();
            line.split_whitespace()
                .nth(1)
                .unwrap()
                .parse::<u64>()
                .unwrap()
                * 1024
        };
        (field("VmRSS:"), field("VmHWM:"))
    }
}

/// What a request got: `Ok(reply)` or `Ok(Err(error reply))` as JSON text, or the
/// request's failure (no reply in time, bus error).
type Outcome = Result<Result<String, String>, RequestError>;

fn send(c: &BusClient, command: &str, payload: &[u8]) -> Outcome {
    match c.command(ROLE_GRASP_PLANNER, command, payload, CASE_LIMIT) {
        Ok(bytes) => Ok(Ok(String::from_utf8_lossy(&bytes).into_owned())),
        Err(RequestError::Reply(reply)) => Ok(Err(serde_json::to_string(&reply).unwrap())),
        Err(other) => Err(other),
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

/// The mesh size limit of the test host, and the most triangles a binary STL
/// within it holds (80-byte header, 4-byte count, 50 bytes a triangle).
const MESH_LIMIT: u64 = 4 << 20;
const BIG_TRIANGLES: usize = (MESH_LIMIT as usize - 84) / 50;

/// A binary STL of `n` small triangles on a grid 1 mm apart.
fn write_binary_stl(path: &Path, n: usize) {
    let mut bytes = vec![0u8; 80];
    bytes.extend_from_slice(&(n as u32).to_le_bytes());
    for i in 0..n {
        let (x, y) = ((i % 300) as f32 * 1e-3, (i / 300) as f32 * 1e-3);
        let corners = [
            [0.0f32, 0.0, 1.0],
            [x, y, 0.0],
            [x + 1e-3, y, 0.0],
            [x, y + 1e-3, 1e-4],
        ];
        for v in corners.iter().flatten() {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes.extend_from_slice(&[0, 0]);
    }
    std::fs::write(path, bytes).unwrap();
}

/// Robots `deep` (10,000-deep XML) and `many` (100,000 links, within the URDF size
/// limit) under `root/robots/`, each with the humanoid's description and grasp
/// types, so that the URDF parser itself gets them.
fn hostile_robots(root: &Path) {
    let humanoid = models_dir().join("robots/tsukami_humanoid");
    let description = std::fs::read_to_string(humanoid.join("description.toml")).unwrap();
    let deep = format!(
        "<robot name=\"d\">{}{}</robot>",
        "<a>".repeat(10_000),
        "</a>".repeat(10_000)
    );
    let links: String = (0..100_000)
        .map(|i| format!("<link name=\"l{i}\"/>"))
        .collect();
    let many = format!("<robot name=\"m\">{links}</robot>");
    for (name, urdf) in [("deep", deep), ("many", many)] {
        let dir = root.join("robots").join(name);
        std::fs::create_dir_all(&dir).unwrap();
        let text = description.replace("tsukami_humanoid.urdf", &format!("{name}.urdf"));
        assert_ne!(text, description);
        std::fs::write(dir.join("description.toml"), text).unwrap();
        std::fs::copy(
            humanoid.join("grasp_types.toml"),
            dir.join("grasp_types.toml"),
        )
        .unwrap();
        std::fs::write(dir.join(format!("{name}.urdf")), urdf).unwrap();
    }
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
    hostile_robots(root);
    write_binary_stl(&root.join("big.stl"), BIG_TRIANGLES);
    write_binary_stl(&root.join("over.stl"), BIG_TRIANGLES + 1);
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
        "deep".into(),
        "many".into(),
        "over.stl".into(),
        "".into(),
        "x".repeat(5000),
    ]);
    paths
}

/// One request of the corpus: its name, command and payload.
struct Case {
    name: String,
    command: &'static str,
    payload: Vec<u8>,
}

fn case(name: String, command: &'static str, payload: Vec<u8>) -> Case {
    Case {
        name,
        command,
        payload,
    }
}

/// Every hostile path as a robot, a grasp-type file, an object mesh and an obstacle
/// mesh.
fn path_cases(
    robot: &serde_json::Value,
    object: &serde_json::Value,
    paths: &[String],
) -> Vec<Case> {
    let mut cases = vec![];
    for p in paths {
        let mut r = robot.clone();
        r["robot"] = p.as_str().into();
        cases.push(case(
            format!("robot {p:.60}"),
            planner::SET_ROBOT,
            r.to_string().into_bytes(),
        ));
        let mut r = robot.clone();
        r["grasp_types"] = p.as_str().into();
        let name = format!("grasp_types {p:.60}");
        cases.push(case(name, planner::SET_ROBOT, r.to_string().into_bytes()));
        let mut o = object.clone();
        o["shape"] = serde_json::json!({"mesh": {"path": p}});
        cases.push(case(
            format!("mesh {p:.60}"),
            planner::SET_OBJECT,
            o.to_string().into_bytes(),
        ));
        let env = serde_json::json!({"obstacles": [{"name": "o", "shape": {"mesh": {"path": p}},
            "pose": {"position": [0.5, 0, 0], "quaternion": [0, 0, 0, 1]}}]});
        let name = format!("obstacle {p:.60}");
        cases.push(case(name, planner::SET_ENV, env.to_string().into_bytes()));
    }
    cases
}

/// PLY files the host must refuse before allocating for them or reading past
/// them: a header claiming 10^12 vertices, one whose skipped element claims
/// 2^64 - 1 records, a face list claiming four billion corners, a face naming a
/// vertex that does not exist, and a header that never ends.
fn hostile_plys() -> [(&'static str, Vec<u8>); 5] {
    let header = |vertices: &str, other: &str, list: &str| {
        format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex {vertices}\nproperty float x\n\
             property float y\nproperty float z\n{other}element face 1\n\
             property list {list} int vertex_indices\nend_header\n"
        )
        .into_bytes()
    };
    let mut corners = header("3", "", "uint");
    corners.extend_from_slice(&[0u8; 36]);
    corners.extend_from_slice(&u32::MAX.to_le_bytes());
    let mut bad_index = header("3", "", "uchar");
    bad_index.extend_from_slice(&[0u8; 36]);
    bad_index.push(3);
    for i in [0i32, 1, i32::MAX] {
        bad_index.extend_from_slice(&i.to_le_bytes());
    }
    let mut endless = b"ply\n".to_vec();
    endless.extend(b"comment x\n".repeat(10_000));
    [
        ("ply vertices", header("1000000000000", "", "uchar")),
        (
            "ply skipped",
            header(
                "0",
                "element e 18446744073709551615\nproperty char a\n",
                "uchar",
            ),
        ),
        ("ply corners", corners),
        ("ply bad index", bad_index),
        ("ply endless header", endless),
    ]
}

/// Inline meshes (`shape.inline`) the host must refuse without changing
/// anything: not base64, no string, zeros, a count the bytes do not hold, an OBJ
/// asking for a material library outside the roots, indices out of range, NaN,
/// and hostile PLY files ([`hostile_plys`]).
fn inline_cases(object: &serde_json::Value) -> Vec<Case> {
    let b64 = tsukami_body::mesh_inline::encode_base64;
    let mut lying = vec![0u8; 80];
    lying.extend_from_slice(&u32::MAX.to_le_bytes());
    lying.extend_from_slice(&[0u8; 50]);
    let shapes = [
        (
            "not base64",
            "stl",
            serde_json::json!("%%%% not base64 %%%%"),
        ),
        ("not a string", "stl", serde_json::json!([1, 2, 3])),
        ("zeros", "stl", b64(&vec![0u8; 700 << 10]).into()),
        ("lying count", "stl", b64(&lying).into()),
        (
            "obj passwd",
            "obj",
            b64(b"mtllib ../../../../etc/passwd
usemtl root
")
            .into(),
        ),
        (
            "obj bad index",
            "obj",
            b64(b"v 0 0 0
v 1 0 0
v 0 1 0
f 1 2 4000000000
f -9 -8 -7
")
            .into(),
        ),
        (
            "nan",
            "stl",
            b64(b"solid n
facet normal 0 0 1
outer loop
vertex NaN 0 0
vertex 1 0 0
vertex 0 1 0
endloop
endfacet
endsolid n
")
            .into(),
        ),
    ];
    let plys = hostile_plys().map(|(name, bytes)| (name, "ply", b64(&bytes).into()));
    shapes
        .into_iter()
        .chain(plys)
        .map(|(name, format, data)| {
            let mut o = object.clone();
            o["shape"] = serde_json::json!({"inline": {"format": format, "data_base64": data}});
            case(
                format!("inline {name}"),
                planner::SET_OBJECT,
                o.to_string().into_bytes(),
            )
        })
        .collect()
}

/// The whole sequential corpus: garbage on every command, hostile paths, bad
/// values, impossible budgets, a stop storm.
fn corpus(robot: &serde_json::Value, object: &serde_json::Value, paths: &[String]) -> Vec<Case> {
    let mut cases = vec![];
    for command in [
        planner::SET_ROBOT,
        planner::SET_OBJECT,
        planner::SET_ENV,
        planner::PLAN,
        "stop",
        "remove_env",
        "nonsense",
    ] {
        for (i, g) in garbage().into_iter().enumerate() {
            cases.push(case(format!("{command} garbage {i}"), command, g));
        }
    }
    cases.extend(path_cases(robot, object, paths));
    for (field, value) in [
        ("mass", serde_json::json!(-1.0)),
        ("friction", serde_json::json!(50.0)),
        ("center_of_mass", serde_json::json!([10.0, 0, 0])),
    ] {
        let mut o = object.clone();
        o[field] = value;
        cases.push(case(
            format!("object {field}"),
            planner::SET_OBJECT,
            o.to_string().into_bytes(),
        ));
    }
    cases.extend(inline_cases(object));
    for budget in [0u64, u64::MAX] {
        let payload = format!("{{\"max_samples\": {budget}}}").into_bytes();
        cases.push(case(
            format!("plan samples {budget}"),
            planner::PLAN,
            payload,
        ));
    }
    for i in 0..80 {
        cases.push(case(format!("stop storm {i}"), "stop", b"{}".to_vec()));
    }
    cases
}

/// Cases whose files must reach the parser or the size check (so the corpus
/// keeps testing them), and what their refusal says.
const REACHED: [(&str, &str); 14] = [
    ("inline not base64", "outside the alphabet"),
    ("inline zeros", "inline STL"),
    ("inline nan", "non-finite"),
    ("inline ply vertices", "1000000000000 vertices, more than"),
    ("inline ply skipped", "18446744073709551615 records"),
    ("inline ply corners", "4294967293 triangles by face 0"),
    (
        "inline ply bad index",
        "corner 2 of 3 names a vertex outside",
    ),
    ("inline ply endless header", "no `end_header` within"),
    ("robot deep", "nested deeper than"),
    ("robot many", "more than 10000 links"),
    ("mesh nan.stl", "non-finite"),
    ("obstacle nan.stl", "non-finite"),
    ("obstacle over.stl", "more than the limit"),
    ("mesh sparse.stl", "more than the limit"),
];

/// The child under test, its client, the baseline plan and the checks every reply
/// goes through.
struct Under {
    host: ChildHost,
    client: BusClient,
    baseline: serde_json::Value,
    /// Absolute folders no reply may name unless the request did.
    absolute: Vec<String>,
    /// The RSS bound (bytes) and the largest VmRSS seen, with its case.
    bound: u64,
    peak: (u64, String),
}

const PLAN: &[u8] = br#"{"seed": 1}"#;

fn parse(s: &str) -> serde_json::Value {
    without_timing(serde_json::from_str(s).unwrap())
}

impl Under {
    /// Sends one request and checks its reply: well formed, in time, no secret, no
    /// password file, no absolute folder the request did not name.
    fn ask(&mut self, name: &str, command: &str, payload: &[u8]) -> Result<String, String> {
        let start = Instant::now();
        let reply =
            send(&self.client, command, payload).unwrap_or_else(|e| self.host.no_reply(name, e));
        assert!(
            start.elapsed() < CASE_LIMIT,
            "{name}: {:?}",
            start.elapsed()
        );
        check_well_formed(name, &reply);
        let (Ok(text) | Err(text)) = &reply;
        assert!(!text.contains(SECRET), "{name}: secret in {text:.300}");
        assert!(
            !text.contains("root:"),
            "{name}: passwd content in {text:.300}"
        );
        for a in &self.absolute {
            let asked = String::from_utf8_lossy(payload).contains(a.as_str());
            assert!(
                asked || !text.contains(a.as_str()),
                "{name}: absolute folder in {text:.300}"
            );
        }
        reply
    }

    /// The host still runs, plans exactly the baseline grasp, and its VmRSS is under
    /// the bound.
    fn check_unchanged(&mut self, name: &str) {
        let again = self.ask(&format!("plan after {name}"), planner::PLAN, PLAN);
        let again = again.unwrap_or_else(|e| panic!("{name}: the plan now fails: {e:.300}"));
        assert_eq!(parse(&again), self.baseline, "{name}: the plan changed");
        if let Some(dead) = self.host.exited() {
            panic!("{name}: {dead}");
        }
        let (rss, _) = self.host.memory();
        assert!(
            rss < self.bound,
            "{name}: VmRSS {rss} over the bound {}",
            self.bound
        );
        if rss > self.peak.0 {
            self.peak = (rss, name.to_owned());
        }
    }
}

/// Starts the child with the test limits and the hostile root, sets the can scene
/// and plans the baseline.
fn start_under(base: &Path, root: &Path) -> Under {
    let mut config = test_config(vec![planner_entry()]);
    config.models.roots = vec![models_dir(), root.to_owned()];
    config.limits.max_queue = 4;
    config.limits.max_payload_bytes = 1 << 20;
    config.limits.max_mesh_bytes = MESH_LIMIT;
    config.limits.max_urdf_bytes = 3 << 20;
    let limits = config.limits.clone();
    let (host, client) = ChildHost::start(base, config);
    let req = scene_requests(&models_dir().join("scenes/can_breast.toml")).unwrap();
    let mut under = Under {
        host,
        client,
        baseline: serde_json::Value::Null,
        absolute: vec![
            base.display().to_string(),
            models_dir().canonicalize().unwrap().display().to_string(),
        ],
        bound: u64::MAX,
        peak: (0, String::new()),
    };
    for (command, payload) in [
        (
            planner::SET_ROBOT,
            serde_json::to_string(&req.robot).unwrap(),
        ),
        (
            planner::SET_OBJECT,
            serde_json::to_string(&req.object).unwrap(),
        ),
        (planner::SET_ENV, serde_json::to_string(&req.env).unwrap()),
    ] {
        under
            .ask(command, command, payload.as_bytes())
            .expect("the scene is accepted");
    }
    let baseline = under
        .ask("baseline", planner::PLAN, PLAN)
        .expect("the baseline plan succeeds");
    under.baseline = parse(&baseline);
    // docs/protocol.md, "Limits": RSS ≤ B + P(Q + 2)M + L(2M + 1 MiB) + P·F, with
    // P = 1 plugin, L = 1 client link, F = 8M + 12·max_mesh_bytes +
    // 12·max_urdf_bytes, and B the child's peak (VmHWM) so far: the host with its
    // plugin and scene loaded, after one plan.
    let m = limits.max_payload_bytes as u64;
    let (_, b) = under.host.memory();
    under.bound = b
        + (limits.max_queue as u64 + 2) * m
        + (2 * m + MIB)
        + 8 * m
        + 12 * limits.max_mesh_bytes
        + 12 * limits.max_urdf_bytes;
    eprintln!(
        "hostile: B = VmHWM after the baseline = {} MiB; bound {} MiB",
        b / MIB,
        under.bound / MIB
    );
    under
}

/// Stops sent while a plan runs: the plan answers the baseline or `cancelled`,
/// every stop answers `{"stopped": …}`.
fn stops_during_plans(under: &mut Under, rounds: usize, stops: usize) -> usize {
    for round in 0..rounds {
        let c = &under.client;
        let (plan, replies) = std::thread::scope(|s| {
            let plan = s.spawn(|| send(c, planner::PLAN, PLAN));
            let replies: Vec<Outcome> = (0..stops).map(|_| send(c, "stop", b"{}")).collect();
            (plan.join().unwrap(), replies)
        });
        let name = format!("stop storm during plan {round}");
        for reply in replies {
            let reply = reply.unwrap_or_else(|e| under.host.no_reply(&name, e));
            let text = reply.unwrap_or_else(|e| panic!("{name}: stop refused: {e}"));
            let v: serde_json::Value = serde_json::from_str(&text).unwrap();
            assert!(v["stopped"].is_boolean(), "{name}: {text}");
        }
        match plan.unwrap_or_else(|e| under.host.no_reply(&name, e)) {
            Ok(text) => assert_eq!(parse(&text), under.baseline, "{name}: the plan changed"),
            Err(e) => assert!(e.contains("\"cancelled\""), "{name}: {e:.300}"),
        }
        under.check_unchanged(&name);
    }
    rounds * (stops + 1)
}

/// The largest mesh the test limits accept, as an obstacle far from the scene:
/// accepted, then removed; the host then plans the baseline grasp again, two world
/// versions later. Its load is the `F` term of the memory bound.
fn largest_accepted_mesh(under: &mut Under) {
    let env = serde_json::json!({"obstacles": [{"name": "big", "shape": {"mesh": {"path": "big.stl"}},
        "pose": {"position": [5.0, 5.0, 0.0], "quaternion": [0, 0, 0, 1]}}]});
    let name = format!("obstacle of {BIG_TRIANGLES} triangles");
    let before = under.host.memory();
    let added = under.ask(&name, planner::SET_ENV, env.to_string().as_bytes());
    added.unwrap_or_else(|e| panic!("{name}: a mesh within the limits is refused: {e:.300}"));
    let held = under.host.memory();
    let removed = under.ask("remove it", planner::REMOVE_ENV, br#"{"names": ["big"]}"#);
    removed.unwrap_or_else(|e| panic!("remove_env: {e:.300}"));
    let after = under.host.memory();
    eprintln!(
        "hostile: {name} (VmRSS, VmHWM) MiB: before {:?}, held {:?}, removed {:?}",
        (before.0 / MIB, before.1 / MIB),
        (held.0 / MIB, held.1 / MIB),
        (after.0 / MIB, after.1 / MIB)
    );
    let version = under.baseline["world_version"]
        .as_u64()
        .expect("world_version");
    under.baseline["world_version"] = (version + 2).into();
    under.check_unchanged(&name);
}

/// More plans at once than the queue holds: each gets the baseline grasp or `busy`,
/// and at least one gets `busy`.
fn flood(under: &mut Under, plans: usize) {
    let c = &under.client;
    let replies: Vec<Outcome> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..plans)
            .map(|_| s.spawn(|| send(c, planner::PLAN, PLAN)))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let mut busy = 0;
    for reply in replies {
        match reply.unwrap_or_else(|e| under.host.no_reply("flood", e)) {
            Ok(text) => assert_eq!(parse(&text), under.baseline, "a flood plan changed"),
            Err(e) if e.contains("\"busy\"") => busy += 1,
            Err(e) => panic!("flood: {e:.300}"),
        }
    }
    assert!(busy > 0, "the queue limit never answered busy");
    under.check_unchanged("flood");
}

#[test]
fn a_tsukami_run_process_survives_a_hostile_corpus_unchanged() {
    let started = Instant::now();
    let base = TempDir::new("hostile");
    let (root, outside) = (base.0.join("root"), base.0.join("outside"));
    let paths = hostile_files(&root, &outside);
    let mut under = start_under(&base.0, &root);
    let req = scene_requests(&models_dir().join("scenes/can_breast.toml")).unwrap();
    let robot = serde_json::to_value(&req.robot).unwrap();
    let object = serde_json::to_value(&req.object).unwrap();
    let cases = corpus(&robot, &object, &paths);
    for c in &cases {
        // Refused or not, no case may change the state: the plan stays the same.
        let reply = under.ask(&c.name, c.command, &c.payload);
        if let Some((_, expected)) = REACHED.iter().find(|(name, _)| *name == c.name) {
            let (Ok(text) | Err(text)) = &reply;
            assert!(text.contains(expected), "{}: {text:.300}", c.name);
        }
        under.check_unchanged(&c.name);
    }
    largest_accepted_mesh(&mut under);
    let storm = stops_during_plans(&mut under, 4, 20);
    flood(&mut under, 12);
    let total = cases.len() + 2 + storm + 12;
    assert!(total >= 300, "{total} cases");
    let (rss, hwm) = under.host.memory();
    assert!(
        hwm < under.bound,
        "VmHWM {hwm} over the bound {}",
        under.bound
    );
    assert!(under.host.exited().is_none(), "the host is still running");
    eprintln!(
        "hostile: {total} cases in {:.0?}; VmRSS now {} MiB, largest after a case {} MiB ({}), VmHWM {} MiB; bound {} MiB",
        started.elapsed(),
        rss / MIB,
        under.peak.0 / MIB,
        under.peak.1,
        hwm / MIB,
        under.bound / MIB
    );
}

/// `stop` on a role nobody serves — a built-in role without a plugin, an unknown
/// role, an absent component — is answered `no_plugin` naming the role, never left
/// unanswered; a component that serves its own `stop` still gets its queries alone.
#[test]
fn stop_on_a_role_nobody_serves_is_answered_no_plugin_naming_it() {
    let bus = TestBus::start(test_config(vec![]));
    let namespace = bus.host.keys().namespace().to_owned();
    for role in [
        "grasp-planner",
        "trajectory-planner",
        "no-such-role",
        "controller",
        "host",
    ] {
        let reply = bus
            .client
            .command(role, "stop", b"{}", Duration::from_secs(10))
            .expect_err("nothing to stop");
        let RequestError::Reply(reply) = reply else {
            panic!("stop on {role}: no reply: {reply}");
        };
        let prefix = tsukami_msgs::keys::role_prefix(role);
        assert_eq!(reply.error.code.as_str(), "no_plugin", "{role}: {reply}");
        assert!(
            reply.error.message.contains(&format!("`{prefix}`")),
            "{reply}"
        );
        assert_eq!(reply.error.details.as_ref().unwrap()["role"], prefix);
        // A garbage payload is still refused as such.
        let garbage = bus
            .client
            .command(role, "stop", b"{", Duration::from_secs(10));
        let code = garbage.expect_err("garbage").code().map(|c| c.as_str());
        assert_eq!(code, Some("malformed_json"), "{role}");
    }
    // A component serving `<ns>/gadget/stop` itself: every stop reaches it, and the
    // host's fallback never answers in its place.
    let gadget = format!("tcp/127.0.0.1:{}", free_loopback_port().unwrap());
    let session = BusConfig::listening(&gadget).open().unwrap();
    let component = Component::on_session(session, &namespace, "gadget", "0", "test").unwrap();
    let key = component.keys().command("gadget", "stop");
    let _stop = component
        .serve(
            &key,
            |_: serde_json::Value| -> Result<StopReply, tsukami_msgs::ErrorReply> {
                Ok(StopReply {
                    stopped: true,
                    command: Some("gadget".into()),
                })
            },
        )
        .unwrap();
    let client_bus = BusConfig {
        connect: vec![bus.endpoint.clone(), gadget],
        ..BusConfig::connecting(&bus.endpoint)
    };
    let client = BusClient::connect(&client_bus, &namespace).unwrap();
    client
        .wait_for_component("gadget", Duration::from_secs(20))
        .expect("the gadget answers");
    for i in 0..20 {
        let reply = client.command("gadget", "stop", b"{}", Duration::from_secs(10));
        let reply: StopReply =
            serde_json::from_slice(&reply.unwrap_or_else(|e| panic!("{i}: {e}"))).unwrap();
        assert_eq!(reply.command.as_deref(), Some("gadget"));
    }
}

/// Payload sizes around the host's two limits (built-in bus config,
/// `max_payload_bytes` = M = 1 MiB): up to zenoh's reassembly cap of 2M + 1 MiB the
/// host gets the request and answers `payload_too_large`; above the cap zenoh drops
/// the message while reassembling it, the host never sees it, and the client's
/// query ends at its own timeout with no reply. The link survives: the same client
/// is answered at once afterwards.
#[test]
fn a_payload_over_the_reassembly_cap_gets_no_reply_and_the_link_survives() {
    let mut config = test_config(vec![plugin_entry("test-slow", "tsukami_test_slow")]);
    config.limits.max_payload_bytes = 1 << 20;
    let bus = TestBus::start(config);
    let c = &bus.client;
    let m = 1usize << 20;
    let payload = |len: usize| format!("{{\"x\":\"{}\"}}", "a".repeat(len - 8)).into_bytes();
    let timeout = Duration::from_secs(5);
    for len in [m + 1, 2 * m, 2 * m + m / 2, 3 * m - 4096] {
        let reply = c.command("test-slow", "echo", &payload(len), timeout);
        let code = reply.expect_err("too large").code().map(|c| c.as_str());
        assert_eq!(code, Some("payload_too_large"), "{len} bytes");
    }
    for len in [3 * m + 4096, 8 * m] {
        let start = Instant::now();
        match c.command("test-slow", "echo", &payload(len), timeout) {
            Err(RequestError::Timeout { .. }) => assert!(start.elapsed() >= timeout / 2),
            other => panic!("{len} bytes over the cap: expected no reply, got {other:?}"),
        }
        // The same session and link still work.
        let echo = c
            .command("test-slow", "echo", b"{}", timeout)
            .expect("echo after");
        assert_eq!(echo, b"{}", "{len}");
    }
}
