//! Clean shutdown on SIGINT / SIGTERM.
//!
//! What: [`Shutdown`], a flag that is raised once and can be waited on.
//!
//! Why: a component must close its zenoh session (so its queryables disappear from
//! the bus at once) and finish its current work step when it is told to stop, not be
//! torn down mid-write.
//!
//! How: [`Shutdown::on_signals`] installs the process's one signal handler (the
//! `ctrlc` crate with its `termination` feature: SIGINT, SIGTERM, SIGHUP) which raises
//! the flag; the main thread waits on it. In-process components (tests, mocks) use
//! [`Shutdown::new`] and raise it themselves.
//!
//! ```
//! use std::time::Duration;
//! let stop = tsukami_bus::Shutdown::new();
//! assert!(!stop.wait_timeout(Duration::from_millis(1)));
//! stop.trigger();
//! assert!(stop.is_triggered());
//! stop.wait();
//! ```

use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

/// A shutdown flag shared by the threads of a process. Cloning shares it.
#[derive(Debug, Clone, Default)]
pub struct Shutdown {
    inner: Arc<(Mutex<bool>, Condvar)>,
}

impl Shutdown {
    /// A flag nobody has raised yet.
    pub fn new() -> Shutdown {
        Shutdown::default()
    }

    /// A flag raised by SIGINT, SIGTERM or SIGHUP. A process has one such handler:
    /// call this once, from `main`.
    pub fn on_signals() -> anyhow::Result<Shutdown> {
        let shutdown = Shutdown::new();
        let handle = shutdown.clone();
        ctrlc::set_handler(move || {
            tracing::info!("signal received, shutting down");
            handle.trigger();
        })
        .map_err(|e| anyhow::anyhow!("installing the SIGINT/SIGTERM handler: {e}"))?;
        Ok(shutdown)
    }

    /// Raises the flag and wakes every waiter.
    pub fn trigger(&self) {
        let (flag, cond) = &*self.inner;
        *flag.lock().unwrap_or_else(|e| e.into_inner()) = true;
        cond.notify_all();
    }

    /// Whether the flag is raised.
    pub fn is_triggered(&self) -> bool {
        *self.inner.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Blocks until the flag is raised.
    pub fn wait(&self) {
        let (flag, cond) = &*self.inner;
        let mut raised = flag.lock().unwrap_or_else(|e| e.into_inner());
        while !*raised {
            raised = cond.wait(raised).unwrap_or_else(|e| e.into_inner());
        }
    }

    /// Blocks until the flag is raised or `timeout` passes; true when raised.
    pub fn wait_timeout(&self, timeout: Duration) -> bool {
        let (flag, cond) = &*self.inner;
        let raised = flag.lock().unwrap_or_else(|e| e.into_inner());
        let (raised, _) = cond
            .wait_timeout_while(raised, timeout, |r| !*r)
            .unwrap_or_else(|e| e.into_inner());
        *raised
    }
}
