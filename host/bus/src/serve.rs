//! Answering queries: the request checks and reply helpers every component uses.
//!
//! What: [`parse_query`] (size limit, JSON syntax, request shape → the request type
//! or an error object naming what was wrong), [`reply_json`] (and
//! [`reply_json_on`], on a key of one's own) and [`reply_error`].
//!
//! Why: the same rules as the host's (docs/protocol.md): an oversized or malformed
//! request is answered with an error and never reaches the component's logic; an
//! empty payload stands for `{}`; a failure travels as zenoh's error reply.
//!
//! How: thin wrappers over `zenoh::query::Query`; a failed reply is logged (the
//! asker may have gone), never panics.

use serde::de::DeserializeOwned;
use serde::Serialize;
use tsukami_msgs::error::parse_request;
use tsukami_msgs::{ErrorCode, ErrorReply};
use zenoh::bytes::Encoding;
use zenoh::query::Query;
use zenoh::Wait;

/// The largest request payload a component accepts, and the host's default
/// `limits.max_payload_bytes`: one constant for both.
pub const MAX_PAYLOAD_BYTES: usize = 16 << 20;

/// The request in `query`, checked: at most [`MAX_PAYLOAD_BYTES`] (before anything
/// is copied), valid JSON, the shape of `T`. An empty payload stands for `{}`.
pub fn parse_query<T: DeserializeOwned>(query: &Query) -> Result<T, ErrorReply> {
    check_size(query)?;
    match query.payload() {
        // Contiguous (the usual case) without a copy; a fragmented payload once.
        Some(payload) => parse_payload(&payload.to_bytes()),
        None => parse_payload(b""),
    }
}

/// `payload_too_large` when `query`'s payload is over [`MAX_PAYLOAD_BYTES`]; reads
/// only the length, so a component can refuse a request in zenoh's callback
/// before queueing it.
pub fn check_size(query: &Query) -> Result<(), ErrorReply> {
    match query.payload() {
        Some(payload) => check_len(payload.len()),
        None => Ok(()),
    }
}

fn check_len(len: usize) -> Result<(), ErrorReply> {
    if len > MAX_PAYLOAD_BYTES {
        return Err(ErrorReply::new(
            ErrorCode::PayloadTooLarge,
            format!("payload of {len} bytes is over the limit of {MAX_PAYLOAD_BYTES} bytes"),
        )
        .with_details(serde_json::json!({ "limit": MAX_PAYLOAD_BYTES })));
    }
    Ok(())
}

/// [`parse_query`]'s checks on raw bytes.
pub fn parse_payload<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, ErrorReply> {
    check_len(bytes.len())?;
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return parse_request(b"{}");
    }
    parse_request(bytes)
}

/// Answers `query` with `value` as JSON, on the query's own key.
pub fn reply_json<T: Serialize>(query: &Query, value: &T) {
    reply_json_on(query, query.key_expr().as_str(), value)
}

/// Answers `query` with `value` as JSON on `key`, a key the query matches. A
/// queryable answering a wildcard query (`<ns>/*/info`) replies on its own key:
/// zenoh's default consolidation keeps one reply per key, so replies all on the
/// query's `*` would be merged into one.
pub fn reply_json_on<T: Serialize>(query: &Query, key: &str, value: &T) {
    let payload = match serde_json::to_vec(value) {
        Ok(payload) => payload,
        Err(e) => {
            let error = ErrorReply::new(ErrorCode::Internal, format!("serialising reply: {e}"));
            return reply_error(query, error);
        }
    };
    if let Err(e) = query
        .reply(key.to_owned(), payload)
        .encoding(Encoding::APPLICATION_JSON)
        .wait()
    {
        tracing::warn!(key = %query.key_expr(), "reply failed: {e}");
    }
}

/// Answers `query` with the common error object, as zenoh's error reply.
pub fn reply_error(query: &Query, error: ErrorReply) {
    tracing::debug!(key = %query.key_expr(), "error reply: {error}");
    if let Err(e) = query
        .reply_err(error.to_json_bytes())
        .encoding(Encoding::APPLICATION_JSON)
        .wait()
    {
        tracing::warn!(key = %query.key_expr(), "error reply failed: {e}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Req {
        #[serde(default)]
        n: u32,
    }

    #[test]
    fn empty_payload_is_an_empty_object() {
        assert_eq!(parse_payload::<Req>(b"").unwrap().n, 0);
        assert_eq!(parse_payload::<Req>(br#"{"n": 3}"#).unwrap().n, 3);
    }

    #[test]
    fn bad_payloads_are_named() {
        let big = vec![b' '; MAX_PAYLOAD_BYTES + 1];
        let too_large = parse_payload::<Req>(&big).unwrap_err().error;
        assert_eq!(too_large.code, ErrorCode::PayloadTooLarge);
        assert!(
            too_large.message.contains("16777216"),
            "{}",
            too_large.message
        );
        assert_eq!(too_large.details.unwrap()["limit"], MAX_PAYLOAD_BYTES);
        assert_eq!(crate::reassembly_cap(MAX_PAYLOAD_BYTES), 33 << 20);
        assert_eq!(
            parse_payload::<Req>(b"{").unwrap_err().error.code,
            ErrorCode::MalformedJson
        );
        let wrong = parse_payload::<Req>(br#"{"m": 1}"#).unwrap_err();
        assert_eq!(wrong.error.code, ErrorCode::InvalidRequest);
        assert!(wrong.error.message.contains('m'), "{wrong}");
    }
}
