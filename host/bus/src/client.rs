//! A small blocking bus client: what the CLI, the demo, the tests, the benches and
//! the components use to send commands and read replies.
//!
//! What: [`BusClient`] (a session under one namespace) and [`RequestError`] (error
//! reply, timeout, or zenoh failure, told apart).
//!
//! Why: every caller needs the same three outcomes of a query, and a timeout must be
//! an error, never a hang.
//!
//! How: one `get` per request with zenoh's own timeout, sent to every matching
//! queryable (target `All`, consolidation `None`); the replies are collected until
//! all have answered or the timeout. One reply is the answer; two or more are
//! `conflicting_responders` — a process declaring a key it does not own cannot
//! silently answer in the real one's place. An error reply's payload is parsed as
//! the common error object.

use crate::config::BusConfig;
use anyhow::{anyhow, Result};
use std::time::{Duration, Instant};
use tsukami_msgs::{ErrorCode, ErrorReply, KeySpace};
use zenoh::bytes::Encoding;
use zenoh::query::{ConsolidationMode, QueryTarget, Reply};
use zenoh::Wait;

/// Why a request failed.
#[derive(Debug, thiserror::Error)]
pub enum RequestError {
    /// The other side answered with an error object.
    #[error("{0}")]
    Reply(ErrorReply),
    /// Nobody answered in time (no host, no plugin for the role, or too slow).
    #[error("no reply from {key} within {timeout:?}")]
    Timeout {
        /// The key queried.
        key: String,
        /// How long we waited.
        timeout: Duration,
    },
    /// Two or more responders answered (code `conflicting_responders`; the error
    /// object names the key and what each answered).
    #[error("{0}")]
    Conflict(ErrorReply),
    /// zenoh itself failed.
    #[error("bus error on {key}: {message}")]
    Bus {
        /// The key queried.
        key: String,
        /// zenoh's message.
        message: String,
    },
}

impl RequestError {
    /// The error code, when the other side sent one.
    pub fn code(&self) -> Option<ErrorCode> {
        match self {
            RequestError::Reply(reply) | RequestError::Conflict(reply) => Some(reply.error.code),
            _ => None,
        }
    }
}

/// A connection to the bus under one namespace.
pub struct BusClient {
    session: zenoh::Session,
    keys: KeySpace,
}

impl BusClient {
    /// Joins the bus (the built-in config connects to loopback only).
    pub fn connect(bus: &BusConfig, namespace: &str) -> Result<BusClient> {
        Ok(BusClient::on_session(bus.open()?, namespace))
    }

    /// A client on a session that is already open (e.g. a component's own).
    pub fn on_session(session: zenoh::Session, namespace: &str) -> BusClient {
        BusClient {
            session,
            keys: KeySpace::new(namespace),
        }
    }

    /// The key space.
    pub fn keys(&self) -> &KeySpace {
        &self.keys
    }

    /// The zenoh session (for subscriptions in tests and tools).
    pub fn session(&self) -> &zenoh::Session {
        &self.session
    }

    /// Queries `key` (a full key) with `payload` and returns the one reply's bytes
    /// (see [`query`]: two responders are an error, never a race).
    pub fn request_key(
        &self,
        key: &str,
        payload: &[u8],
        timeout: Duration,
    ) -> Result<Vec<u8>, RequestError> {
        query(&self.session, key, payload, timeout)
    }

    /// Sends `command` to `role`'s plugin (`<ns>/<role prefix>/<command>`).
    pub fn command(
        &self,
        role: &str,
        command: &str,
        payload: &[u8],
        timeout: Duration,
    ) -> Result<Vec<u8>, RequestError> {
        self.request_key(&self.keys.command(role, command), payload, timeout)
    }

    /// Waits until a host answers `host/plugins`, then returns its listing. zenoh
    /// drops a query sent before the other side's queryable has propagated, so we
    /// ask again until `deadline` rather than sleeping a guessed time.
    pub fn wait_for_host(&self, deadline: Duration) -> Result<tsukami_msgs::host::PluginsReply> {
        let bytes = self
            .wait_for(&self.keys.host_plugins(), deadline)
            .map_err(|e| anyhow!("no Tsukami host answered: {e}"))?;
        Ok(serde_json::from_slice(&bytes)?)
    }

    /// Waits until component `name` answers `<ns>/<name>/info`, then returns it.
    pub fn wait_for_component(
        &self,
        name: &str,
        deadline: Duration,
    ) -> Result<tsukami_msgs::component::ComponentInfo> {
        let bytes = self
            .wait_for(&self.keys.component_info(name), deadline)
            .map_err(|e| anyhow!("component `{name}` did not answer: {e}"))?;
        Ok(serde_json::from_slice(&bytes)?)
    }

    /// Every component answering `<ns>/*/info` within `timeout`, sorted by name
    /// (every reply is kept: zenoh's consolidation is off for this query). Error
    /// replies and replies that are not a component's info (e.g. a host's
    /// `unknown_command` for a role prefix) are left out.
    pub fn components(
        &self,
        timeout: Duration,
    ) -> Result<Vec<tsukami_msgs::component::ComponentInfo>, RequestError> {
        let key = self.keys.component_info_all();
        let replies = self
            .session
            .get(&key)
            .consolidation(zenoh::query::ConsolidationMode::None)
            .timeout(timeout)
            .wait()
            .map_err(|e| RequestError::Bus {
                key: key.clone(),
                message: e.to_string(),
            })?;
        let mut found = vec![];
        while let Ok(reply) = replies.recv() {
            let Ok(sample) = reply.result() else { continue };
            if let Ok(info) = serde_json::from_slice::<tsukami_msgs::component::ComponentInfo>(
                &sample.payload().to_bytes(),
            ) {
                found.push(info);
            }
        }
        found.sort_by(|a, b| a.name.cmp(&b.name));
        Ok(found)
    }

    /// Queries `key` with an empty payload until something answers (an error reply
    /// counts as an answer) or `deadline` passes; returns the first successful reply.
    pub fn wait_for(&self, key: &str, deadline: Duration) -> Result<Vec<u8>, RequestError> {
        let start = Instant::now();
        loop {
            let left = deadline.saturating_sub(start.elapsed());
            if left.is_zero() {
                return Err(RequestError::Timeout {
                    key: key.to_owned(),
                    timeout: deadline,
                });
            }
            match self.request_key(key, b"", left.min(Duration::from_millis(250))) {
                Err(RequestError::Timeout { .. }) => continue,
                other => return other,
            }
        }
    }

    /// Closes the session.
    pub fn close(self) {
        let _ = self.session.close().wait();
    }
}

/// Queries `key` on `session` with `payload` and returns the one reply's bytes.
///
/// The query goes to every queryable matching `key` (target `All`, no
/// consolidation) and every reply is kept until all have answered or `timeout`
/// passes. Exactly one reply is the answer (an error reply is
/// [`RequestError::Reply`]); none is [`RequestError::Timeout`]; two or more are
/// [`RequestError::Conflict`], naming the key and each reply. A `no_plugin`, and
/// any answer of the host's `<ns>/*/stop` fallback for a prefix it does not serve
/// (`details.fallback: true`), stands aside when someone else answers.
pub fn query(
    session: &zenoh::Session,
    key: &str,
    payload: &[u8],
    timeout: Duration,
) -> Result<Vec<u8>, RequestError> {
    let replies = session
        .get(key)
        .payload(payload.to_vec())
        .encoding(Encoding::APPLICATION_JSON)
        .target(QueryTarget::All)
        .consolidation(ConsolidationMode::None)
        .timeout(timeout)
        .wait()
        .map_err(|e| RequestError::Bus {
            key: key.to_owned(),
            message: e.to_string(),
        })?;
    // The channel ends once every queryable the query reached has answered (or
    // dropped it), or at the timeout.
    let mut answers = vec![];
    while let Ok(reply) = replies.recv() {
        answers.push(Answer::of(&reply));
    }
    decide(key, timeout, answers)
}

/// One reply, sorted.
#[derive(Debug)]
enum Answer {
    /// A successful reply's bytes.
    Value(Vec<u8>),
    /// An error reply.
    Error(ErrorReply),
    /// zenoh's own `Timeout` error: a queryable did not answer in time.
    ZenohTimeout,
}

impl Answer {
    fn of(reply: &Reply) -> Answer {
        match reply.result() {
            Ok(sample) => Answer::Value(sample.payload().to_bytes().into_owned()),
            Err(err) => {
                let bytes = err.payload().to_bytes();
                if bytes.as_ref() == b"Timeout" {
                    return Answer::ZenohTimeout;
                }
                Answer::Error(serde_json::from_slice(&bytes).unwrap_or_else(|_| {
                    ErrorReply::new(
                        ErrorCode::Internal,
                        String::from_utf8_lossy(&bytes).into_owned(),
                    )
                }))
            }
        }
    }

    /// "Not mine", which yields to any other answer: a `no_plugin` error, or any
    /// error the host's `<ns>/*/stop` fallback sends (`details.fallback: true`).
    fn stands_aside(&self) -> bool {
        let Answer::Error(e) = self else {
            return false;
        };
        let fallback = e
            .error
            .details
            .as_ref()
            .is_some_and(|d| d["fallback"] == true);
        e.error.code == ErrorCode::NoPlugin || fallback
    }

    /// What a person reads of it in a conflict.
    fn summary(&self) -> String {
        match self {
            Answer::Value(bytes) => format!("a reply of {} bytes", bytes.len()),
            Answer::Error(e) => format!("an error reply `{}`", e.error.code.as_str()),
            Answer::ZenohTimeout => "no reply in time".to_owned(),
        }
    }
}

/// The outcome of a query from all its replies (see [`query`]).
fn decide(key: &str, timeout: Duration, answers: Vec<Answer>) -> Result<Vec<u8>, RequestError> {
    let (mut real, aside): (Vec<Answer>, Vec<Answer>) = answers
        .into_iter()
        .filter(|a| !matches!(a, Answer::ZenohTimeout))
        .partition(|a| !a.stands_aside());
    if real.is_empty() {
        real = aside;
    }
    if real.len() > 1 {
        return Err(conflict(key, &real));
    }
    match real.pop() {
        Some(Answer::Value(bytes)) => Ok(bytes),
        Some(Answer::Error(error)) => Err(RequestError::Reply(error)),
        Some(Answer::ZenohTimeout) | None => Err(RequestError::Timeout {
            key: key.to_owned(),
            timeout,
        }),
    }
}

/// `conflicting_responders` for `key`, naming each answer.
fn conflict(key: &str, answers: &[Answer]) -> RequestError {
    let each: Vec<String> = answers.iter().map(Answer::summary).collect();
    RequestError::Conflict(
        ErrorReply::new(
            ErrorCode::ConflictingResponders,
            format!(
                "{} responders answered {key} ({}): another process on the bus declares this key, \
                 so no answer can be trusted; stop the other process or use a namespace of your own",
                each.len(),
                each.join(", ")
            ),
        )
        .with_details(serde_json::json!({ "key": key, "responders": each })),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: Duration = Duration::from_secs(1);

    fn no_plugin() -> Answer {
        Answer::Error(ErrorReply::new(ErrorCode::NoPlugin, "no plugin fills role"))
    }

    #[test]
    fn one_answer_is_the_answer_and_none_is_a_timeout() {
        assert_eq!(
            decide("k", T, vec![Answer::Value(b"1".to_vec())]).unwrap(),
            b"1"
        );
        let aside = decide("k", T, vec![no_plugin(), Answer::Value(b"2".to_vec())]);
        assert_eq!(aside.unwrap(), b"2");
        let refused = ErrorReply::new(ErrorCode::MalformedJson, "x")
            .with_details(serde_json::json!({"fallback": true}));
        let fallback = vec![Answer::Error(refused), Answer::Value(b"3".to_vec())];
        assert_eq!(decide("k", T, fallback).unwrap(), b"3");
        let alone = decide("k", T, vec![no_plugin(), Answer::ZenohTimeout]).unwrap_err();
        assert_eq!(alone.code(), Some(ErrorCode::NoPlugin));
        let none = decide("k", T, vec![Answer::ZenohTimeout]).unwrap_err();
        assert!(matches!(none, RequestError::Timeout { .. }), "{none}");
    }

    #[test]
    fn two_answers_are_a_conflict_naming_the_key_and_each() {
        let busy = Answer::Error(ErrorReply::new(ErrorCode::Busy, "queue full"));
        let e = decide("ns/motion/plan", T, vec![Answer::Value(vec![0; 7]), busy]).unwrap_err();
        assert_eq!(e.code(), Some(ErrorCode::ConflictingResponders));
        let message = e.to_string();
        assert!(message.contains("ns/motion/plan"), "{message}");
        assert!(
            message.contains("7 bytes") && message.contains("`busy`"),
            "{message}"
        );
        let RequestError::Conflict(reply) = e else {
            unreachable!()
        };
        assert_eq!(
            reply.error.details.unwrap()["responders"]
                .as_array()
                .unwrap()
                .len(),
            2
        );
    }
}
