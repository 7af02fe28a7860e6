//! A small blocking bus client: what the CLI, the demo, the tests, the benches and
//! the components use to send commands and read replies.
//!
//! What: [`BusClient`] (a session under one namespace) and [`RequestError`] (error
//! reply, timeout, or zenoh failure, told apart).
//!
//! Why: every caller needs the same three outcomes of a query, and a timeout must be
//! an error, never a hang.
//!
//! How: one `get` per request with zenoh's own timeout; the first reply wins; an
//! error reply's payload is parsed as the common error object.

use crate::config::BusConfig;
use anyhow::{anyhow, Result};
use std::time::{Duration, Instant};
use tsukami_msgs::{ErrorCode, ErrorReply, KeySpace};
use zenoh::bytes::Encoding;
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
            RequestError::Reply(reply) => Some(reply.error.code),
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

    /// Queries `key` (a full key) with `payload` and returns the first reply's bytes.
    pub fn request_key(
        &self,
        key: &str,
        payload: &[u8],
        timeout: Duration,
    ) -> Result<Vec<u8>, RequestError> {
        let bus_error = |e: zenoh::Error| RequestError::Bus {
            key: key.to_owned(),
            message: e.to_string(),
        };
        let replies = self
            .session
            .get(key)
            .payload(payload.to_vec())
            .encoding(Encoding::APPLICATION_JSON)
            .timeout(timeout)
            .wait()
            .map_err(bus_error)?;
        let reply = replies.recv().map_err(|_| RequestError::Timeout {
            key: key.to_owned(),
            timeout,
        })?;
        match reply.result() {
            Ok(sample) => Ok(sample.payload().to_bytes().into_owned()),
            Err(err) => {
                let bytes = err.payload().to_bytes();
                // zenoh's own answer when a queryable it routed the query to did
                // not reply in time.
                if bytes.as_ref() == b"Timeout" {
                    return Err(RequestError::Timeout {
                        key: key.to_owned(),
                        timeout,
                    });
                }
                Err(RequestError::Reply(
                    serde_json::from_slice(&bytes).unwrap_or_else(|_| {
                        ErrorReply::new(
                            ErrorCode::Internal,
                            String::from_utf8_lossy(&bytes).into_owned(),
                        )
                    }),
                ))
            }
        }
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
