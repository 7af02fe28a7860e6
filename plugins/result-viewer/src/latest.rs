//! What the viewer last heard on the bus: one slot per kind, newest wins.
//!
//! What: [`Latest`] — the last grasp plan outcome, motion outcome, controller
//! state, vision pose and object summary — behind [`Board`], which also counts changes
//! (the *generation*) so the web page's event streams know when to send.
//!
//! Why: the viewer must never slow the planners down nor grow with the
//! traffic: a result replaces the previous one (bounded memory), and a writer
//! holds the lock only to swap a value in, never while drawing or sending.
//!
//! How: a `Mutex` around the slots and a `Condvar` woken on every change and
//! on close; readers clone what they need (`Arc`s) and drop the lock.
//!
//! ```
//! use tsukami_result_viewer::latest::{Board, Outcome};
//! let board = Board::default();
//! let g = board.generation();
//! board.update(|l| l.plan = Some(Outcome::Failed("infeasible: no grasp".into()).into()));
//! assert_eq!(board.wait_past(g, std::time::Duration::ZERO), Some(g + 1));
//! ```

use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use tsukami_msgs::controller::ControllerState;
use tsukami_msgs::motion::MotionPlanReply;
use tsukami_msgs::planner::{ObjectSummary, PlanReply};
use tsukami_msgs::vision::ObjectPose;

/// A result or why there is none.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome<T> {
    /// The reply.
    Done(T),
    /// The error reply's `code: message`.
    Failed(String),
}

/// The newest of everything followed.
#[derive(Debug, Clone, Default)]
pub struct Latest {
    /// The last grasp plan outcome.
    pub plan: Option<Arc<Outcome<PlanReply>>>,
    /// The last motion plan outcome.
    pub motion: Option<Arc<Outcome<MotionPlanReply>>>,
    /// The controller's last published state.
    pub controller: Option<Arc<ControllerState>>,
    /// The vision component's last published pose.
    pub vision: Option<Arc<ObjectPose>>,
    /// The last accepted `set_object`'s summary (its OCP boxes).
    pub object: Option<Arc<ObjectSummary>>,
    /// Plan outcomes received so far.
    pub plans: u64,
    /// Motion outcomes received so far.
    pub motions: u64,
    /// Messages that were not the JSON their key promises (dropped).
    pub unreadable: u64,
}

struct Inner {
    latest: Latest,
    generation: u64,
    closed: bool,
}

/// [`Latest`] with a change counter and a wake-up for waiters.
pub struct Board {
    inner: Mutex<Inner>,
    changed: Condvar,
}

impl Default for Board {
    fn default() -> Self {
        Board {
            inner: Mutex::new(Inner {
                latest: Latest::default(),
                generation: 0,
                closed: false,
            }),
            changed: Condvar::new(),
        }
    }
}

impl Board {
    fn lock(&self) -> MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Changes the slots with `f` and wakes every waiter.
    pub fn update(&self, f: impl FnOnce(&mut Latest)) {
        let mut inner = self.lock();
        f(&mut inner.latest);
        inner.generation += 1;
        drop(inner);
        self.changed.notify_all();
    }

    /// Counts a change made elsewhere (the world) and wakes every waiter.
    pub fn touch(&self) {
        self.update(|_| {});
    }

    /// A copy of the slots (cheap: `Arc`s and counters) and their generation.
    pub fn read(&self) -> (Latest, u64) {
        let inner = self.lock();
        (inner.latest.clone(), inner.generation)
    }

    /// The current generation.
    pub fn generation(&self) -> u64 {
        self.lock().generation
    }

    /// Waits at most `timeout` for a generation past `seen`: the new one, or
    /// `None` on timeout or once closed.
    pub fn wait_past(&self, seen: u64, timeout: Duration) -> Option<u64> {
        let end = Instant::now() + timeout;
        let mut inner = self.lock();
        loop {
            if inner.closed {
                return None;
            }
            if inner.generation != seen {
                return Some(inner.generation);
            }
            let left = end.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return None;
            }
            inner = self
                .changed
                .wait_timeout(inner, left)
                .unwrap_or_else(|p| p.into_inner())
                .0;
        }
    }

    /// Ends every wait (the plugin is going away).
    pub fn close(&self) {
        self.lock().closed = true;
        self.changed.notify_all();
    }

    /// True once closed.
    pub fn is_closed(&self) -> bool {
        self.lock().closed
    }
}
