//! The controller on the bus: requests in, joint states out, periods paced.
//!
//! What: [`ControllerNode`] serves `<ns>/controller/execute` (checked, then run;
//! with `wait` the reply comes when the run ends), `<ns>/controller/stop` (answered
//! at once; the run ends at the next period), `<ns>/controller/state` (the latest
//! state, to a query) and publishes the state there every control period.
//!
//! Why: one thread owns the [`Executor`], so requests are handled in arrival order
//! between periods and nothing is shared but a stop flag and the latest state; zenoh's
//! callbacks only parse and hand over. The control period is kept whatever arrives:
//! a flood of requests, good or bad, can neither delay a period nor a stop.
//!
//! How: three stages. zenoh's callback parses a request and queues it (at most
//! [`EXECUTE_QUEUE`] waiting; more are refused `busy`). A checker thread runs the
//! checks that need only the robot model ([`Plan::for_robot`]) and answers a
//! refused trajectory itself. The control thread runs one period at each deadline —
//! deadlines `dt / speed` apart while a trajectory runs (`speed` = ∞: back to back)
//! and `dt` apart while idle — and between deadlines takes checked requests (the
//! start and busy checks are a few comparisons), so a request never moves the next
//! deadline. Stop is a flag every period reads. Shutting down ends a running
//! trajectory as a fault and answers its caller.

use crate::executor::Executor;
use crate::joints::JointTable;
use crate::trajectory::Plan;
use anyhow::Result;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, SyncSender, TrySendError};
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

/// How many `execute` requests may wait to be checked; more are refused `busy`
/// (the host's default `limits.max_queue`).
pub const EXECUTE_QUEUE: usize = 8;

/// A request handed from zenoh's callback to the checker thread.
struct ExecuteJob {
    request: ExecuteRequest,
    query: Query,
}

/// A request whose trajectory passed the robot-model checks, handed from the
/// checker thread to the control thread.
struct CheckedJob {
    plan: Plan,
    wait: bool,
    joints: usize,
    points: usize,
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
        let (jobs, requests) = mpsc::sync_channel::<ExecuteJob>(EXECUTE_QUEUE);
        let (checked, queue) = mpsc::sync_channel::<CheckedJob>(1);
        let table = executor.table().clone();
        std::thread::Builder::new()
            .name("controller-check".into())
            .spawn(move || check_requests(&table, requests, checked))?;
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

fn serve_execute(component: &Component, jobs: SyncSender<ExecuteJob>) -> Result<Queryable<()>> {
    let key = component.keys().controller_execute();
    component.serve_query(&key, move |query| {
        match parse_query::<ExecuteRequest>(&query) {
            Ok(request) => match jobs.try_send(ExecuteJob { request, query }) {
                Ok(()) => {}
                Err(TrySendError::Full(job)) => reply_error(
                    &job.query,
                    tsukami_msgs::ErrorReply::new(
                        tsukami_msgs::ErrorCode::Busy,
                        format!(
                            "the controller has {EXECUTE_QUEUE} execute requests waiting to be checked; retry later"
                        ),
                    ),
                ),
                Err(TrySendError::Disconnected(job)) => {
                    reply_rejected(&job.query, "the controller is shutting down".into())
                }
            },
            Err(error) => reply_error(&query, error),
        }
    })
}

/// The checker thread: the robot-model checks of every request, in arrival order;
/// a refused one is answered here, a passed one goes on to the control thread.
/// Ends when zenoh drops the `execute` callback (and with it `requests`' sender).
fn check_requests(
    table: &JointTable,
    requests: Receiver<ExecuteJob>,
    checked: SyncSender<CheckedJob>,
) {
    for job in requests {
        let trajectory = &job.request.trajectory;
        match Plan::for_robot(trajectory, table) {
            Ok(plan) => {
                let job = CheckedJob {
                    plan,
                    wait: job.request.wait,
                    joints: trajectory.joint_names.len(),
                    points: trajectory.points.len(),
                    query: job.query,
                };
                if let Err(mpsc::SendError(job)) = checked.send(job) {
                    reply_rejected(&job.query, "the controller is shutting down".into());
                }
            }
            Err(reason) => reply_rejected(&job.query, reason),
        }
    }
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
    /// Periods at their deadlines; checked requests taken between them. Handling a
    /// request never moves a deadline, so the period holds under any request load.
    fn run(mut self, queue: Receiver<CheckedJob>) {
        let mut next = Instant::now() + self.period_length();
        let mut open = true;
        loop {
            if self.shutdown.is_triggered() {
                return self.shut_down();
            }
            let now = Instant::now();
            if now >= next {
                self.period();
                next = next_deadline(next, self.period_length(), Instant::now());
            }
            let wait = next.saturating_duration_since(Instant::now());
            if !open {
                std::thread::sleep(wait);
                continue;
            }
            match queue.recv_timeout(wait) {
                Ok(job) => self.take(job),
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => open = false,
            }
        }
    }

    /// Wall time of the coming period: `dt / speed` while a trajectory runs, `dt`
    /// while idle.
    fn period_length(&self) -> Duration {
        let dt = self.executor.dt();
        if self.executor.is_running() {
            Duration::from_secs_f64(dt / self.options.speed)
        } else {
            Duration::from_secs_f64(dt)
        }
    }

    fn shut_down(&mut self) {
        if let Some(outcome) = self.executor.fault() {
            self.shared.flags().running = false;
            self.publish();
            self.end_run(
                outcome,
                Some("the controller shut down mid-run".into()),
                None,
            );
        }
    }

    /// A checked request: start it, or refuse it with the reason (busy, or its
    /// start away from the current state).
    fn take(&mut self, job: CheckedJob) {
        match self
            .executor
            .start_plan(job.plan, self.options.start_tolerance)
        {
            Ok(()) => {
                tracing::info!(
                    joints = job.joints,
                    points = job.points,
                    tick = self.executor.tick(),
                    "trajectory accepted"
                );
                let mut flags = self.shared.flags();
                flags.running = true;
                flags.stop_requested_at = None;
                drop(flags);
                if job.wait {
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

/// The deadline after `previous`, one `period` later; when the thread is already
/// past it, now (one period at once, no burst to catch up).
fn next_deadline(previous: Instant, period: Duration, now: Instant) -> Instant {
    (previous + period).max(now)
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
