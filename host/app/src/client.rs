//! A small blocking bus client: what the CLI, the demo, the tests and the benches use
//! to send commands and read replies.

use crate::bus::BusConfig;
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
        Ok(BusClient {
            session: bus.open()?,
            keys: KeySpace::new(namespace),
        })
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
        let start = Instant::now();
        loop {
            let left = deadline.saturating_sub(start.elapsed());
            if left.is_zero() {
                return Err(anyhow!(
                    "no Tsukami host answered on {} within {deadline:?}",
                    self.keys.host_plugins()
                ));
            }
            match self.request_key(
                &self.keys.host_plugins(),
                b"",
                left.min(Duration::from_millis(250)),
            ) {
                Ok(bytes) => return Ok(serde_json::from_slice(&bytes)?),
                Err(RequestError::Timeout { .. }) => continue,
                Err(e) => return Err(e.into()),
            }
        }
    }

    /// Closes the session.
    pub fn close(self) {
        let _ = self.session.close().wait();
    }
}
