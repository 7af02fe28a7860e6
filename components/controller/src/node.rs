//! The controller on the bus: requests in, joint states out, periods paced.
//!
//! What: [`ControllerNode`] serves `<ns>/controller/execute` (checked, then run;
//! with `wait` the reply comes when the run ends), `<ns>/controller/stop` (answered
//! at once; the run ends at the next period), `<ns>/controller/state` (the latest
//! state, to a query) and publishes the state there every control period.
//!
//! Why: one thread owns the [`Executor`], so requests are handled in arrival order
//! between periods and nothing is shared but a stop flag and the latest state; zenoh's
//! callbacks only parse and hand over.
//!
//! How: the control thread runs one period per `dt / speed` of wall time while a
//! trajectory runs (`speed` = ∞: as fast as it can) and one per `dt` while idle; it
//! waits on its request channel between periods, so a request is taken at once.
//! Shutting down ends a running trajectory as a fault and answers its caller.

use crate::executor::Executor;
use anyhow::Result;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tsukami_bus::serve::{parse_query, reply_error, reply_json};
use tsukami_bus::{Component, Shutdown};
use tsukami_msgs::controller::{ControllerState, ExecuteReply, ExecuteRequest, ExecutionOutcome};
use tsukami_msgs::host::StopReply;
use zenoh::pubsub::Publisher;
use zenoh::query::{Query, Queryable};
use zenoh::Wait;

/// How the controller runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeOptions {
    /// Controller time per wall time while a trajectory runs: 1 is real time,
    /// 10 ten times faster, `f64::INFINITY` as fast as the machine goes.
    pub speed: f64,
    /// How far (rad or m) a trajectory's first point may be from the current state.
    pub start_tolerance: f64,
}

impl Default for NodeOptions {
    fn default() -> Self {
        NodeOptions {
            speed: 1.0,
            start_tolerance: 0.01,
        }
    }
}

/// A request handed from zenoh's callback to the control thread.
struct ExecuteJob {
    request: ExecuteRequest,
    query: Query,
}

/// What the callbacks share with the control thread.
#[derive(Default)]
struct Shared {
    /// Held by the control thread for the whole of a period's step, so a stop is
    /// either seen by this period or recorded with this period's tick.
    control: Mutex<ControlFlags>,
    latest: Mutex<Option<ControllerState>>,
}

#[derive(Default)]
struct ControlFlags {
    /// The tick of the last completed period.
    tick: u64,
    running: bool,
    /// Set by a stop: the tick at which it arrived.
    stop_requested_at: Option<u64>,
}

impl Shared {
    fn flags(&self) -> std::sync::MutexGuard<'_, ControlFlags> {
        self.control.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// The controller component, serving until [`ControllerNode::shutdown`].
pub struct ControllerNode {
    component: Component,
    queryables: Vec<Queryable<()>>,
    thread: Option<JoinHandle<()>>,
    shutdown: Shutdown,
}

impl ControllerNode {
    /// Serves `executor` on `component`'s session.
    pub fn start(
        component: Component,
        executor: Executor,
        options: NodeOptions,
    ) -> Result<ControllerNode> {
        anyhow::ensure!(
            options.speed > 0.0,
            "speed {} must be positive (1 = real time)",
            options.speed
        );
        anyhow::ensure!(
            options.start_tolerance >= 0.0 && options.start_tolerance.is_finite(),
            "start tolerance {} must be a non-negative number",
            options.start_tolerance
        );
        let keys = component.keys().clone();
        let shared = Arc::new(Shared::default());
        *shared.latest.lock().unwrap_or_else(|e| e.into_inner()) = Some(executor.state());
        let (jobs, queue) = mpsc::channel::<ExecuteJob>();
        let publisher = component.publisher(&keys.controller_state())?;
        let queryables = vec![
            serve_execute(&component, jobs)?,
            serve_stop(&component, shared.clone())?,
            serve_state(&component, shared.clone())?,
        ];
        let shutdown = Shutdown::new();
        let control = ControlLoop {
            executor,
            options,
            shared,
            publisher,
            waiting: None,
            shutdown: shutdown.clone(),
        };
        let thread = std::thread::Builder::new()
            .name("controller".into())
            .spawn(move || control.run(queue))?;
        Ok(ControllerNode {
            component,
            queryables,
            thread: Some(thread),
            shutdown,
        })
    }

    /// Stops the control thread (a running trajectory ends as a fault and its caller
    /// is answered), then leaves the bus.
    pub fn shutdown(mut self) {
        self.shutdown.trigger();
        if let Some(thread) = self.thread.take() {
            if thread.join().is_err() {
                tracing::error!("the control thread panicked");
            }
        }
        self.queryables.clear();
        self.component.close();
    }
}

fn serve_execute(component: &Component, jobs: Sender<ExecuteJob>) -> Result<Queryable<()>> {
    let jobs = Mutex::new(jobs);
    let key = component.keys().controller_execute();
    component.serve_query(&key, move |query| {
        match parse_query::<ExecuteRequest>(&query) {
            Ok(request) => {
                let sent = jobs
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .send(ExecuteJob { request, query });
                if let Err(mpsc::SendError(job)) = sent {
                    reply_rejected(&job.query, "the controller is shutting down".into());
                }
            }
            Err(error) => reply_error(&query, error),
        }
    })
}

fn serve_stop(component: &Component, shared: Arc<Shared>) -> Result<Queryable<()>> {
    component.serve(
        &component.keys().controller_stop(),
        move |_: serde_json::Value| {
            let mut flags = shared.flags();
            let running = flags.running;
            if running && flags.stop_requested_at.is_none() {
                flags.stop_requested_at = Some(flags.tick);
            }
            Ok(StopReply {
                stopped: running,
                command: running.then(|| "execute".to_owned()),
            })
        },
    )
}

fn serve_state(component: &Component, shared: Arc<Shared>) -> Result<Queryable<()>> {
    component.serve(
        &component.keys().controller_state(),
        move |_: serde_json::Value| {
            let latest = shared
                .latest
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .clone();
            latest.ok_or_else(|| {
                tsukami_msgs::ErrorReply::new(tsukami_msgs::ErrorCode::NotReady, "no state yet")
            })
        },
    )
}

fn reply_rejected(query: &Query, reason: String) {
    tracing::info!(%reason, "trajectory rejected");
    reply_json(
        query,
        &ExecuteReply {
            accepted: false,
            reason: Some(reason),
            outcome: None,
            state: None,
            stop_requested_at: None,
        },
    );
}

/// The control thread's state.
struct ControlLoop {
    executor: Executor,
    options: NodeOptions,
    shared: Arc<Shared>,
    publisher: Publisher<'static>,
    /// The caller waiting for the running trajectory's end.
    waiting: Option<Query>,
    shutdown: Shutdown,
}

impl ControlLoop {
    fn run(mut self, queue: Receiver<ExecuteJob>) {
        let idle_period = Duration::from_secs_f64(self.executor.dt());
        let run_period = Duration::from_secs_f64(self.executor.dt() / self.options.speed);
        let mut next = Instant::now();
        loop {
            if self.shutdown.is_triggered() {
                if let Some(outcome) = self.executor.fault() {
                    self.shared.flags().running = false;
                    self.publish();
                    self.end_run(
                        outcome,
                        Some("the controller shut down mid-run".into()),
                        None,
                    );
                }
                return;
            }
            let period = if self.executor.is_running() {
                run_period
            } else {
                idle_period
            };
            next += period;
            let now = Instant::now();
            if next < now {
                next = now; // behind: do not try to catch up in a burst
            }
            match queue.recv_timeout(next - now) {
                Ok(job) => {
                    self.take(job);
                    continue;
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    std::thread::sleep(next.saturating_duration_since(Instant::now()))
                }
            }
            self.period();
        }
    }

    /// A new request: start it, or refuse it with the reason.
    fn take(&mut self, job: ExecuteJob) {
        match self
            .executor
            .start(&job.request.trajectory, self.options.start_tolerance)
        {
            Ok(()) => {
                tracing::info!(
                    joints = job.request.trajectory.joint_names.len(),
                    points = job.request.trajectory.points.len(),
                    tick = self.executor.tick(),
                    "trajectory accepted"
                );
                let mut flags = self.shared.flags();
                flags.running = true;
                flags.stop_requested_at = None;
                drop(flags);
                if job.request.wait {
                    self.waiting = Some(job.query);
                } else {
                    reply_json(&job.query, &accepted_reply());
                }
            }
            Err(reason) => reply_rejected(&job.query, reason),
        }
    }

    /// One control period: honour a stop or advance, then publish.
    fn period(&mut self) {
        let mut flags = self.shared.flags();
        let stop_requested_at = flags.stop_requested_at.take();
        let ended = match stop_requested_at {
            Some(_) => self.executor.cancel(),
            None => self.executor.step(),
        };
        flags.tick = self.executor.tick();
        if ended.is_some() {
            flags.running = false;
        }
        drop(flags);
        self.publish();
        if let Some(outcome) = ended {
            self.end_run(outcome, None, stop_requested_at);
        }
    }

    fn publish(&self) {
        let state = self.executor.state();
        match serde_json::to_vec(&state) {
            Ok(bytes) => {
                if let Err(e) = self.publisher.put(bytes).wait() {
                    tracing::warn!("publishing the state: {e}");
                }
            }
            Err(e) => tracing::error!("serialising the state: {e}"),
        }
        *self.shared.latest.lock().unwrap_or_else(|e| e.into_inner()) = Some(state);
    }

    fn end_run(
        &mut self,
        outcome: ExecutionOutcome,
        reason: Option<String>,
        stop_requested_at: Option<u64>,
    ) {
        let state = self.executor.state();
        tracing::info!(?outcome, tick = state.tick, "trajectory ended");
        if let Some(query) = self.waiting.take() {
            reply_json(
                &query,
                &ExecuteReply {
                    accepted: true,
                    reason,
                    outcome: Some(outcome),
                    state: Some(state),
                    stop_requested_at,
                },
            );
        }
    }
}

fn accepted_reply() -> ExecuteReply {
    ExecuteReply {
        accepted: true,
        reason: None,
        outcome: None,
        state: None,
        stop_requested_at: None,
    }
}
