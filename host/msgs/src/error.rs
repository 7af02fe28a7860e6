//! The common error object every reply may carry instead of its result.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Machine-readable error category. Clients switch on this; the message is for people.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ErrorCode {
    /// The payload is not valid JSON.
    MalformedJson,
    /// The JSON is valid but does not match the request type (wrong type, missing or unknown field).
    InvalidRequest,
    /// A value is out of its allowed range (negative mass, NaN pose, …).
    InvalidValue,
    /// The payload is larger than the host accepts.
    PayloadTooLarge,
    /// The plugin's request queue is full (`limits.max_queue`); retry later.
    Busy,
    /// The command is not one the plugin knows.
    UnknownCommand,
    /// No loaded plugin fills the role the key addresses.
    NoPlugin,
    /// A model, mesh or object could not be found or read.
    ModelError,
    /// The request needs state that has not been set yet (e.g. Plan before SetRobot).
    NotReady,
    /// The request is valid but cannot be satisfied (no grasp type fits, unreachable, …).
    Infeasible,
    /// The call was cancelled by a Stop.
    Cancelled,
    /// A request to another component timed out (it did not answer in time).
    Timeout,
    /// The request's own wall-clock limit (e.g. a plan's `time_budget_ms`) ran
    /// out before it finished; distinct from [`ErrorCode::Timeout`].
    TimeLimit,
    /// The plugin panicked; the host caught it and keeps serving.
    PluginPanicked,
    /// Two or more processes answered one request: another process declares the
    /// same key, so no reply can be trusted to be the real one's.
    ConflictingResponders,
    /// Any other failure inside a plugin or component.
    Internal,
}

impl ErrorCode {
    /// The snake_case name used on the wire.
    pub fn as_str(self) -> &'static str {
        match self {
            ErrorCode::MalformedJson => "malformed_json",
            ErrorCode::InvalidRequest => "invalid_request",
            ErrorCode::InvalidValue => "invalid_value",
            ErrorCode::PayloadTooLarge => "payload_too_large",
            ErrorCode::Busy => "busy",
            ErrorCode::UnknownCommand => "unknown_command",
            ErrorCode::NoPlugin => "no_plugin",
            ErrorCode::ModelError => "model_error",
            ErrorCode::NotReady => "not_ready",
            ErrorCode::Infeasible => "infeasible",
            ErrorCode::Cancelled => "cancelled",
            ErrorCode::Timeout => "timeout",
            ErrorCode::TimeLimit => "time_limit",
            ErrorCode::PluginPanicked => "plugin_panicked",
            ErrorCode::ConflictingResponders => "conflicting_responders",
            ErrorCode::Internal => "internal",
        }
    }

    /// Parses a wire name; unknown names map to [`ErrorCode::Internal`].
    pub fn from_wire(name: &str) -> ErrorCode {
        serde_json::from_value(serde_json::Value::String(name.to_owned()))
            .unwrap_or(ErrorCode::Internal)
    }
}

/// The error object: `{"error": {"code": …, "message": …, "details": …}}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ErrorReply {
    /// The error itself.
    pub error: ErrorBody,
}

/// Code, human message and optional structured details of an error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ErrorBody {
    /// Machine-readable category.
    pub code: ErrorCode,
    /// What was wrong, naming the field, file or element.
    pub message: String,
    /// Extra structured information (e.g. `{"field": "mass"}`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub details: Option<serde_json::Value>,
}

impl ErrorReply {
    /// An error with a code and message.
    pub fn new(code: ErrorCode, message: impl Into<String>) -> Self {
        ErrorReply {
            error: ErrorBody {
                code,
                message: message.into(),
                details: None,
            },
        }
    }

    /// Adds structured details.
    pub fn with_details(mut self, details: serde_json::Value) -> Self {
        self.error.details = Some(details);
        self
    }

    /// Serialises to the JSON bytes sent on the bus.
    pub fn to_json_bytes(&self) -> Vec<u8> {
        // Serialising plain strings and enums into a Vec cannot fail.
        serde_json::to_vec(self).unwrap_or_default()
    }
}

impl fmt::Display for ErrorReply {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.error.code.as_str(), self.error.message)
    }
}

impl std::error::Error for ErrorReply {}

/// Parses a request payload into `T`, turning every failure into an [`ErrorReply`]
/// that names what was wrong: `malformed_json` for bad syntax, `invalid_request` with
/// the JSON path of the offending field for wrong types, missing or unknown fields.
pub fn parse_request<T: serde::de::DeserializeOwned>(payload: &[u8]) -> Result<T, ErrorReply> {
    let value: serde_json::Value = serde_json::from_slice(payload).map_err(|e| {
        ErrorReply::new(
            ErrorCode::MalformedJson,
            format!("payload is not valid JSON: {e}"),
        )
    })?;
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        ErrorReply::new(
            ErrorCode::InvalidRequest,
            format!("invalid request at `{path}`: {}", e.inner()),
        )
        .with_details(serde_json::json!({ "field": path }))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Sample {
        mass: f64,
        name: String,
    }

    #[test]
    fn malformed_json_is_named() {
        let err = parse_request::<Sample>(b"{not json").unwrap_err();
        assert_eq!(err.error.code, ErrorCode::MalformedJson);
    }

    #[test]
    fn wrong_type_names_the_field() {
        let err = parse_request::<Sample>(br#"{"mass": "heavy", "name": "can"}"#).unwrap_err();
        assert_eq!(err.error.code, ErrorCode::InvalidRequest);
        assert!(err.error.message.contains("mass"), "{}", err.error.message);
        assert_eq!(err.error.details.unwrap()["field"], "mass");
    }

    #[test]
    fn unknown_field_is_refused() {
        let err =
            parse_request::<Sample>(br#"{"mass": 1.0, "name": "x", "colour": 1}"#).unwrap_err();
        assert!(
            err.error.message.contains("colour"),
            "{}",
            err.error.message
        );
    }

    #[test]
    fn error_codes_round_trip_their_wire_names() {
        for code in [
            ErrorCode::MalformedJson,
            ErrorCode::PluginPanicked,
            ErrorCode::NotReady,
            ErrorCode::TimeLimit,
            ErrorCode::ConflictingResponders,
        ] {
            assert_eq!(ErrorCode::from_wire(code.as_str()), code);
        }
        assert_eq!(ErrorCode::from_wire("no-such-code"), ErrorCode::Internal);
    }
}
