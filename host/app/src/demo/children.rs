//! The demo's child processes: the vision and controller components.
//!
//! What: [`locate`] finds a component binary beside the running `tsukami`
//! executable; [`Supervisor::spawn`] starts it with its output going to a log file
//! and returns a [`ComponentProcess`] guard, which [`ComponentProcess::wait_ready`]
//! waits on until the component answers `<ns>/<name>/info`.
//!
//! Why: the demo must never leave a component running behind it nor hang on one
//! that did not start. A guard kills its child when dropped (every return and
//! every panic); [`Supervisor::kill_on_signals`] kills every child still running
//! on SIGINT, SIGTERM or SIGHUP before the demo exits; on Linux each child also
//! gets SIGKILL from the kernel if the demo itself dies (`PR_SET_PDEATHSIG`).
//!
//! How: the running children live in one list shared by the guards and the signal
//! thread; waiting asks `info` in short rounds and checks between rounds whether
//! the child exited, so a crash is reported at once with its log file.
//!
//! ```
//! use std::path::Path;
//! let missing = tsukami::demo::children::locate(Some(Path::new("/nonexistent")), "tsukami-vision");
//! assert_eq!(
//!     missing.unwrap_err(),
//!     "tsukami-vision not found in /nonexistent (build it: cargo build -p tsukami-vision)"
//! );
//! ```

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::client::{BusClient, RequestError};

/// The component binary `name` (its cargo package has the same name) in `dir`,
/// by default beside the running executable; or why it is not there, naming the
/// folder and the command that builds it.
pub fn locate(dir: Option<&Path>, name: &str) -> Result<PathBuf, String> {
    let exe = std::env::current_exe().map_err(|e| format!("where is tsukami? {e}"))?;
    let beside = exe.parent().unwrap_or(Path::new("."));
    let dir = dir.unwrap_or(beside);
    let file = dir.join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    if file.is_file() {
        return Ok(file);
    }
    let release = if dir.ends_with("release") {
        " --release"
    } else {
        ""
    };
    Err(format!(
        "{name} not found in {} (build it: cargo build{release} -p {name})",
        dir.display()
    ))
}

/// The running children, shared by their guards and the signal thread.
#[derive(Clone, Default)]
pub struct Supervisor {
    children: Arc<Mutex<Vec<(u64, Child)>>>,
    next_id: Arc<AtomicU64>,
}

impl Supervisor {
    /// A supervisor with no children.
    pub fn new() -> Supervisor {
        Supervisor::default()
    }

    /// On SIGINT, SIGTERM or SIGHUP: kills every running child and exits with
    /// status 130. Fails when the process already has a signal handler.
    pub fn kill_on_signals(&self) -> anyhow::Result<()> {
        let shutdown = tsukami_bus::Shutdown::on_signals()?;
        let supervisor = self.clone();
        std::thread::Builder::new()
            .name("demo-signals".into())
            .spawn(move || {
                shutdown.wait();
                supervisor.kill_all();
                eprintln!("tsukami demo: interrupted; the components were stopped");
                std::process::exit(130);
            })?;
        Ok(())
    }

    /// Starts `exe args` as component `name`, its standard output and error
    /// going to `log` (created, or truncated).
    pub fn spawn(
        &self,
        name: &str,
        exe: &Path,
        args: &[String],
        log: &Path,
    ) -> Result<ComponentProcess, String> {
        let file = File::create(log).map_err(|e| format!("{}: {e}", log.display()))?;
        let err = file
            .try_clone()
            .map_err(|e| format!("{}: {e}", log.display()))?;
        let mut command = Command::new(exe);
        command
            .args(args)
            .stdin(Stdio::null())
            .stdout(file)
            .stderr(err);
        die_with_parent(&mut command);
        let child = command
            .spawn()
            .map_err(|e| format!("starting {}: {e}", exe.display()))?;
        let id = self.next_id.fetch_add(1, Ordering::Relaxed);
        self.lock().push((id, child));
        Ok(ComponentProcess {
            id,
            name: name.to_owned(),
            log: log.to_owned(),
            supervisor: self.clone(),
        })
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<(u64, Child)>> {
        self.children.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn kill_all(&self) {
        for (_, mut child) in self.lock().drain(..) {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// On Linux, the child gets SIGKILL when the thread that started it ends — the
/// demo's main thread, so when the demo dies, however it dies.
#[cfg(target_os = "linux")]
fn die_with_parent(command: &mut Command) {
    use std::os::unix::process::CommandExt;
    // SAFETY: the closure runs in the forked child before exec and only makes one
    // async-signal-safe system call (prctl).
    unsafe {
        command.pre_exec(|| {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) == -1 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
}

#[cfg(not(target_os = "linux"))]
fn die_with_parent(_command: &mut Command) {}

/// A running component; killed when dropped.
pub struct ComponentProcess {
    id: u64,
    name: String,
    log: PathBuf,
    supervisor: Supervisor,
}

impl ComponentProcess {
    /// The component's name on the bus (`vision`, `controller`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Where its output goes.
    pub fn log(&self) -> &Path {
        &self.log
    }

    /// How the child exited, if it did.
    fn exited(&self) -> Option<ExitStatus> {
        let mut children = self.supervisor.lock();
        let (_, child) = children.iter_mut().find(|(id, _)| *id == self.id)?;
        child.try_wait().ok().flatten()
    }

    /// Waits until the component answers `<ns>/<name>/info` on `client`'s bus;
    /// fails when it exits first or `deadline` passes.
    pub fn wait_ready(&self, client: &BusClient, deadline: Duration) -> Result<(), String> {
        let key = client.keys().component_info(&self.name);
        let start = Instant::now();
        loop {
            if let Some(status) = self.exited() {
                return Err(format!(
                    "{} exited ({status}) before answering; its log: {}",
                    self.name,
                    self.log.display()
                ));
            }
            let left = deadline.saturating_sub(start.elapsed());
            if left.is_zero() {
                return Err(format!(
                    "{} did not answer {key} within {deadline:?}; its log: {}",
                    self.name,
                    self.log.display()
                ));
            }
            match client.request_key(&key, b"", left.min(Duration::from_millis(250))) {
                Err(RequestError::Timeout { .. }) => continue,
                Ok(_) => return Ok(()),
                Err(e) => return Err(format!("{}: {e}", self.name)),
            }
        }
    }
}

impl Drop for ComponentProcess {
    fn drop(&mut self) {
        let mut children = self.supervisor.lock();
        if let Some(i) = children.iter().position(|(id, _)| *id == self.id) {
            let (_, mut child) = children.swap_remove(i);
            drop(children);
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dropped_guard_kills_its_child() {
        let supervisor = Supervisor::new();
        let log = std::env::temp_dir().join(format!("tsukami-demo-child-{}", std::process::id()));
        let guard = supervisor
            .spawn("sleeper", Path::new("sleep"), &["600".into()], &log)
            .unwrap();
        let pid = supervisor.lock()[0].1.id();
        assert!(guard.exited().is_none());
        drop(guard);
        assert!(supervisor.lock().is_empty());
        // The process is gone (reaped): no /proc entry is left.
        assert!(!Path::new(&format!("/proc/{pid}")).exists());
        std::fs::remove_file(&log).unwrap();
    }

    #[test]
    fn a_child_that_exits_is_reported_with_its_log() {
        let supervisor = Supervisor::new();
        let log = std::env::temp_dir().join(format!("tsukami-demo-exit-{}", std::process::id()));
        let guard = supervisor
            .spawn("controller", Path::new("true"), &[], &log)
            .unwrap();
        let port = crate::bus::free_loopback_port().unwrap();
        let bus = crate::bus::BusConfig::listening(&format!("tcp/127.0.0.1:{port}"));
        let client = BusClient::connect(&bus, "demo-child-test").unwrap();
        let err = guard
            .wait_ready(&client, Duration::from_secs(30))
            .unwrap_err();
        assert!(
            err.contains("exited") && err.contains(&log.display().to_string()),
            "{err}"
        );
        drop(guard);
        client.close();
        std::fs::remove_file(&log).unwrap();
    }
}
