//! Following the bus: the results the host publishes and the components' streams.
//!
//! What: [`follow`] starts one thread per followed key — the object's
//! summary with its OCP boxes (`<ns>/world/result/set_object`), grasp plan
//! results (`<ns>/planner/result/plan`), motion results (`<ns>/motion/result/plan`),
//! the controller's state (`<ns>/controller/state`) and the vision poses
//! (`<ns>/vision/pose/*`) — each putting what arrives into the [`Board`].
//!
//! Why: the viewer shows plans it did not ask for; the host publishes every
//! answer of a role after sending it (`docs/protocol.md`, "Result viewer"),
//! so following costs the planners nothing.
//!
//! How: a thread waits on its subscription (through the host: plugins do not
//! link zenoh) in short slices so it notices [`Board::close`], parses the
//! message and swaps it in; an unreadable message is counted and dropped.

use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use serde::de::DeserializeOwned;
use tsukami_msgs::ErrorReply;
use tsukami_plugin_api::{Host, LogLevel};

use crate::latest::{Board, Latest, Outcome};

/// How long a follower waits for a message before looking at the close flag.
const SLICE: Duration = Duration::from_millis(100);

/// Keys followed (relative to the namespace) and what each fills.
const FOLLOWED: [(&str, Kind); 5] = [
    ("world/result/set_object", Kind::Object),
    ("planner/result/plan", Kind::Plan),
    ("motion/result/plan", Kind::Motion),
    ("controller/state", Kind::Controller),
    ("vision/pose/*", Kind::Vision),
];

#[derive(Debug, Clone, Copy)]
enum Kind {
    Plan,
    Motion,
    Controller,
    Vision,
    Object,
}

/// A reply or an error reply, as published on a result key.
fn outcome<T: DeserializeOwned>(bytes: &[u8]) -> Option<Outcome<T>> {
    if let Ok(reply) = serde_json::from_slice::<T>(bytes) {
        return Some(Outcome::Done(reply));
    }
    let e = serde_json::from_slice::<ErrorReply>(bytes).ok()?.error;
    Some(Outcome::Failed(format!(
        "{}: {}",
        e.code.as_str(),
        e.message
    )))
}

/// Puts one message of `kind` into `latest`; false if it was unreadable.
fn store(kind: Kind, bytes: &[u8], latest: &mut Latest) -> bool {
    match kind {
        Kind::Plan => outcome(bytes).map(|o| {
            latest.plan = Some(Arc::new(o));
            latest.plans += 1;
        }),
        Kind::Motion => outcome(bytes).map(|o| {
            latest.motion = Some(Arc::new(o));
            latest.motions += 1;
        }),
        Kind::Controller => serde_json::from_slice(bytes)
            .ok()
            .map(|s| latest.controller = Some(Arc::new(s))),
        Kind::Vision => serde_json::from_slice(bytes)
            .ok()
            .map(|p| latest.vision = Some(Arc::new(p))),
        Kind::Object => serde_json::from_slice(bytes)
            .ok()
            .map(|o| latest.object = Some(Arc::new(o))),
    }
    .is_some()
}

/// Starts the followers; they end once `board` is closed.
pub fn follow(host: &Host, board: &Arc<Board>) -> Result<Vec<JoinHandle<()>>, String> {
    let mut threads = Vec::new();
    for (key, kind) in FOLLOWED {
        let mut subscription = host.subscribe(key)?;
        let (board, host) = (board.clone(), host.clone());
        let thread = std::thread::Builder::new()
            .name(format!("viewer-follow-{key}"))
            .spawn(move || {
                while !board.is_closed() {
                    let Some((_, bytes)) = subscription.recv_timeout(SLICE) else {
                        continue;
                    };
                    // Parse outside the lock; swap inside.
                    let mut parsed = Latest::default();
                    if store(kind, &bytes, &mut parsed) {
                        board.update(|l| merge(kind, parsed, l));
                    } else {
                        host.log(LogLevel::Debug, &format!("unreadable message on {key}"));
                        board.update(|l| l.unreadable += 1);
                    }
                }
            })
            .map_err(|e| format!("starting the follower of {key}: {e}"))?;
        threads.push(thread);
    }
    Ok(threads)
}

/// Moves the one slot of `kind` from `parsed` into `latest`.
fn merge(kind: Kind, parsed: Latest, latest: &mut Latest) {
    match kind {
        Kind::Plan => {
            latest.plan = parsed.plan;
            latest.plans += 1;
        }
        Kind::Motion => {
            latest.motion = parsed.motion;
            latest.motions += 1;
        }
        Kind::Controller => latest.controller = parsed.controller,
        Kind::Vision => latest.vision = parsed.vision,
        Kind::Object => latest.object = parsed.object,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_replies_and_garbage_are_told_apart() {
        let mut l = Latest::default();
        let err = br#"{"error": {"code": "infeasible", "message": "no grasp"}}"#;
        assert!(store(Kind::Plan, err, &mut l));
        assert_eq!(
            l.plan.as_deref(),
            Some(&Outcome::Failed("infeasible: no grasp".into()))
        );
        assert!(!store(Kind::Plan, b"[1, 2]", &mut l));
        assert!(!store(Kind::Controller, b"{}", &mut l));
        assert_eq!(l.plans, 1);
    }
}
