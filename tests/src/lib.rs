//! Support for the end-to-end tests: private hosts on free loopback ports, the real
//! plugin files cargo built, and the real `tsukami` binary.
//!
//! Every host here listens on `tcp/127.0.0.1:<free port>` with multicast scouting
//! off, under a namespace of its own, so tests run in parallel without seeing each
//! other and nothing leaves the machine.
//!
//! [`mocks`]: a mock vision and a mock controller for headless tests.
//! [`hostile`]: the garbage payloads and reply checks of the hostile corpora.

pub mod hostile;
pub mod mocks;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;
use tsukami::bus::{free_loopback_port, BusConfig};
use tsukami::client::BusClient;
use tsukami::config::{HostConfig, PluginEntryConfig};
use tsukami::server::RunningHost;

/// The folder cargo puts this test binary in (`target/<profile>/deps`) and its parent.
fn build_dirs() -> Vec<PathBuf> {
    let exe = std::env::current_exe().expect("current_exe");
    let deps = exe.parent().expect("test binary folder").to_owned();
    let profile = deps
        .parent()
        .map(Path::to_owned)
        .unwrap_or_else(|| deps.clone());
    vec![deps, profile]
}

/// The library file cargo built for plugin crate `lib_name` (e.g. `tsukami_test_slow`).
pub fn plugin_file(lib_name: &str) -> PathBuf {
    let file = tsukami_plugin_api_file_name(lib_name);
    build_dirs()
        .into_iter()
        .map(|d| d.join(&file))
        .find(|p| p.is_file())
        .unwrap_or_else(|| {
            panic!("{file} was not built; is its crate a dev-dependency of tsukami-e2e?")
        })
}

fn tsukami_plugin_api_file_name(lib_name: &str) -> String {
    format!(
        "{}{lib_name}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    )
}

/// A config entry loading `lib_name`'s file for `role`.
pub fn plugin_entry(role: &str, lib_name: &str) -> PluginEntryConfig {
    PluginEntryConfig {
        role: role.to_owned(),
        library: None,
        path: Some(plugin_file(lib_name)),
        config: None,
        workers: None,
    }
}

/// The repository's `models/` folder.
pub fn models_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../models")
}

/// A config entry loading the built-in grasp planner with the repository's models.
pub fn planner_entry() -> PluginEntryConfig {
    grasp_planner_entry("tsukami_grasp_planner")
}

/// A config entry loading `lib_name`'s file for `role`, handing the plugin the
/// repository's models (`models_dir`) and the extra config keys `extra`.
pub fn models_entry(role: &str, lib_name: &str, extra: &[(&str, &str)]) -> PluginEntryConfig {
    let mut entry = plugin_entry(role, lib_name);
    let mut table = toml::Table::new();
    table.insert(
        "models_dir".into(),
        models_dir().display().to_string().into(),
    );
    for (k, v) in extra {
        table.insert((*k).into(), (*v).into());
    }
    entry.config = Some(table);
    entry
}

/// A config entry filling the `grasp-planner` role with plugin `lib_name`, handing it
/// the repository's models (`models_dir`).
pub fn grasp_planner_entry(lib_name: &str) -> PluginEntryConfig {
    models_entry(tsukami_msgs::keys::ROLE_GRASP_PLANNER, lib_name, &[])
}

/// A config entry loading the trajectory planner with the repository's models.
pub fn motion_entry() -> PluginEntryConfig {
    models_entry(
        tsukami_msgs::keys::ROLE_TRAJECTORY_PLANNER,
        "tsukami_trajectory_planner",
        &[],
    )
}

/// A config entry loading the result viewer with the repository's models, its
/// live view on a free loopback port.
pub fn viewer_entry() -> PluginEntryConfig {
    models_entry(
        tsukami_msgs::keys::ROLE_RESULT_VIEWER,
        "tsukami_result_viewer",
        &[("web", "127.0.0.1:0")],
    )
}

/// A host on a free loopback port with its own namespace, plus a connected client.
pub struct TestBus {
    /// The running host (dropped last).
    pub host: RunningHost,
    /// A client on its own zenoh session.
    pub client: BusClient,
    /// The endpoint the host listens on.
    pub endpoint: String,
}

/// A host config on a free port, under a unique namespace, with `plugins`.
pub fn test_config(plugins: Vec<PluginEntryConfig>) -> HostConfig {
    let port = free_loopback_port().expect("free port");
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let mut config = HostConfig::empty(&format!("test-{port}"), BusConfig::listening(&endpoint));
    config.plugins = plugins;
    config
}

/// How many fresh ports [`TestBus::start`] tries when the port it was given was
/// taken between picking it and binding it.
const PORT_ATTEMPTS: usize = 8;

/// Whether a host failed to start because its port was already bound (the OS's
/// `AddrInUse` message, "Address already in use (os error 98)" on Linux, as
/// zenoh passes it on in its error chain).
fn address_in_use(message: &str) -> bool {
    message.contains("already in use") || message.contains("AddrInUse")
}

/// Starts a host with `config`; when its port was taken meanwhile (a free port is
/// picked, released, then bound by the host: another test or process may bind it
/// in between), moves the host and its namespace to a fresh port and tries again.
fn start_host(mut config: HostConfig) -> (RunningHost, HostConfig) {
    for attempt in 1..=PORT_ATTEMPTS {
        match RunningHost::start(&config) {
            Ok(host) => return (host, config),
            Err(e) if address_in_use(&format!("{e:#}")) && attempt < PORT_ATTEMPTS => {
                let port = free_loopback_port().expect("free port");
                config.bus = BusConfig::listening(&format!("tcp/127.0.0.1:{port}"));
                config.namespace = format!("test-{port}");
            }
            Err(e) => panic!("host starts: {e:#}"),
        }
    }
    unreachable!("the last attempt returns or panics")
}

impl TestBus {
    /// Starts a host with `config` and waits until it answers on the bus. A port
    /// taken meanwhile is replaced by a fresh one (see [`start_host`]).
    pub fn start(config: HostConfig) -> TestBus {
        let (host, config) = start_host(config);
        let endpoint = config.bus.listen[0].clone();
        let client = BusClient::connect(&BusConfig::connecting(&endpoint), &config.namespace)
            .expect("client connects");
        client
            .wait_for_host(Duration::from_secs(20))
            .expect("host answers");
        TestBus {
            host,
            client,
            endpoint,
        }
    }
}

/// The `tsukami` binary of this build. Cargo builds it for `cargo test --workspace`
/// (the app has integration tests); when a narrower command did not, build it.
pub fn tsukami_exe() -> PathBuf {
    let name = format!("tsukami{}", std::env::consts::EXE_SUFFIX);
    if let Some(found) = build_dirs()
        .into_iter()
        .map(|d| d.join(&name))
        .find(|p| p.is_file())
    {
        return found;
    }
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let status = Command::new(cargo)
        .args(["build", "-p", "tsukami"])
        .status()
        .expect("running cargo build");
    assert!(status.success(), "cargo build -p tsukami failed");
    build_dirs()
        .into_iter()
        .map(|d| d.join(&name))
        .find(|p| p.is_file())
        .expect("tsukami binary after build")
}

/// The binary `name` of package `package` (a component: `tsukami-vision`,
/// `tsukami-controller`), beside [`tsukami_exe`], brought up to date by
/// `cargo build` once per test process: `cargo test -p tsukami-e2e` builds this
/// package's binaries only (a dev-dependency builds a package's library, not its
/// binaries), and a binary left over from an earlier build may be stale.
pub fn component_exe(package: &str, name: &str) -> PathBuf {
    static BUILT: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());
    let dir = tsukami_exe().parent().unwrap().to_owned();
    let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    if !built.iter().any(|p| p == package) {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
        let mut build = Command::new(cargo);
        build.args(["build", "-p", package, "--bin", name]);
        if dir.file_name().is_some_and(|d| d == "release") {
            build.arg("--release");
        }
        let status = build.status().expect("running cargo build");
        assert!(status.success(), "cargo build -p {package} failed");
        built.push(package.to_owned());
    }
    dir.join(format!("{name}{}", std::env::consts::EXE_SUFFIX))
}

/// A child process killed when dropped.
pub struct ChildGuard(pub Child);

impl Drop for ChildGuard {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts `tsukami <args>` as a child process with its output piped.
pub fn spawn_tsukami(args: &[&str]) -> ChildGuard {
    let child = Command::new(tsukami_exe())
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawning tsukami");
    ChildGuard(child)
}

/// Runs `tsukami plugins` against `endpoint` until a host answers (a query sent before
/// the host's queryable exists goes unanswered), and returns the parsed listing.
pub fn cli_plugins_listing(endpoint: &str, namespace: &str) -> serde_json::Value {
    for _ in 0..60 {
        let out = Command::new(tsukami_exe())
            .args([
                "plugins",
                "--connect",
                endpoint,
                "--namespace",
                namespace,
                "--timeout-ms",
                "500",
            ])
            .output()
            .expect("running tsukami plugins");
        if out.status.success() {
            return serde_json::from_slice(&out.stdout).expect("tsukami plugins prints JSON");
        }
    }
    panic!("`tsukami plugins` never got an answer from {endpoint}");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_port_taken_before_the_host_binds_it_is_replaced() {
        // Someone else holds the port the config names.
        let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let port = taken.local_addr().unwrap().port();
        let mut config = test_config(vec![]);
        let endpoint = format!("tcp/127.0.0.1:{port}");
        config.bus = BusConfig::listening(&endpoint);
        let bus = TestBus::start(config);
        assert_ne!(bus.endpoint, endpoint);
        let listing = bus.client.wait_for_host(Duration::from_secs(20)).unwrap();
        assert!(listing.plugins.is_empty());
        drop(taken);
    }
}
