//! Answering a zenoh query, shared by the role routes ([`crate::server`]) and
//! the world hub ([`crate::world`]).
//!
//! What: [`reply_json`] and [`reply_error`] (the reply, or the error object,
//! as JSON; the latter is `tsukami-bus`'s, as the components answer), [`check_payload`] (size, JSON syntax, an object at the top, before
//! anything reaches a plugin) and [`ResultOut`] (a role's answers published
//! after they are sent, for the result viewer).
//!
//! Why: the server and the world hub answer queries the same way; kept in
//! their own file, the server imports the world hub and the hub imports only
//! this, so there is no import cycle between the two.
//!
//! How: replies carry `application/json`; a failed reply or publication is
//! logged, never raised (the client has gone). The payload is checked in place
//! through zenoh's reader, not copied.

use std::io::Read;

use tsukami_msgs::keys::KeySpace;
use tsukami_msgs::{ErrorCode, ErrorReply};
use zenoh::bytes::Encoding;
use zenoh::query::Query;
use zenoh::Wait;

/// Answers `query` with the error object `error` (the components' own).
pub(crate) use tsukami_bus::serve::reply_error;

/// Where a role's answers are published after they are sent (`<ns>/<prefix>/result/<command>`,
/// the reply's JSON or `{"error": …}`), so the result viewer follows plans it did not
/// ask for. zenoh's default for a put drops rather than waits on congestion: never
/// delays the worker.
pub(crate) struct ResultOut {
    pub(crate) session: zenoh::Session,
    pub(crate) keys: KeySpace,
    /// The role (or `world`) whose prefix the results go under.
    pub(crate) role: String,
}

impl ResultOut {
    /// Publishes `bytes` as the result of `command` (dropped, and logged, if
    /// zenoh cannot send it now).
    pub(crate) fn publish(&self, command: &str, bytes: Vec<u8>) {
        let key = self.keys.command(&self.role, &format!("result/{command}"));
        let put = self.session.put(&key, bytes);
        if let Err(e) = put.encoding(Encoding::APPLICATION_JSON).wait() {
            tracing::debug!("result not published on {key}: {e}");
        }
    }
}

/// Answers `query` with `payload`, a JSON document.
pub(crate) fn reply_json(query: &Query, payload: Vec<u8>) {
    if let Err(e) = query
        .reply(query.key_expr().clone(), payload)
        .encoding(Encoding::APPLICATION_JSON)
        .wait()
    {
        tracing::warn!("reply on {} failed: {e}", query.key_expr());
    }
}

/// Checks a request before it reaches a plugin: size, JSON syntax, and a JSON
/// object at the top (every command takes one). An empty or all-blank payload
/// stands for `{}`. The payload is read in place, not copied.
pub(crate) fn check_payload(query: &Query, max_bytes: usize) -> Result<(), ErrorReply> {
    let Some(payload) = query.payload() else {
        return Ok(());
    };
    if payload.len() > max_bytes {
        return Err(ErrorReply::new(
            ErrorCode::PayloadTooLarge,
            format!(
                "payload is {} bytes; this host accepts at most {max_bytes} (limits.max_payload_bytes)",
                payload.len()
            ),
        )
        .with_details(serde_json::json!({ "limit": max_bytes })));
    }
    check_json_object(std::io::BufReader::with_capacity(
        64 * 1024,
        payload.reader(),
    ))
}

/// `Ok` for blank input or one JSON object; `malformed_json` for anything that is
/// not JSON, `invalid_request` for JSON that is not an object.
fn check_json_object(mut reader: impl Read) -> Result<(), ErrorReply> {
    let malformed = |e: &dyn std::fmt::Display| {
        ErrorReply::new(
            ErrorCode::MalformedJson,
            format!("payload is not valid JSON: {e}"),
        )
    };
    let mut first = [0u8; 1];
    loop {
        match reader.read(&mut first) {
            Ok(0) => return Ok(()),
            Ok(_) if first[0].is_ascii_whitespace() => continue,
            Ok(_) => break,
            Err(e) => return Err(malformed(&e)),
        }
    }
    let mut json = serde_json::Deserializer::from_reader(std::io::Cursor::new(first).chain(reader));
    serde::de::Deserialize::deserialize(&mut json)
        .map(|_: serde::de::IgnoredAny| ())
        .and_then(|()| json.end())
        .map_err(|e| malformed(&e))?;
    if first[0] != b'{' {
        return Err(ErrorReply::new(
            ErrorCode::InvalidRequest,
            "the payload must be a JSON object (`{...}`); an empty payload stands for `{}`",
        ));
    }
    Ok(())
}
