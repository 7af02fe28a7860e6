//! The planner's errors and their wire codes.
//!
//! What: [`PlanError`], one variant per way a request can fail, each naming
//! the field, file or element that was wrong.
//!
//! Why: a planner plugin answers failures with the bus's error codes
//! (`tsukami_msgs::ErrorCode` wire names: `not_ready`, `invalid_value`,
//! `model_error`, `infeasible`, `cancelled`, …). Keeping the mapping here, next
//! to the variants, means the FFI adapter only calls [`PlanError::code`] and
//! [`PlanError::details`].
//!
//! How: algorithms return `Result<_, PlanError>`; the adapter turns the error
//! into `CallError { code, message, details_json }`.

use tsukami_msgs::ErrorCode;

/// Why a request failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// `plan` before `set_robot`.
    #[error("no robot: send set_robot first")]
    NoRobot,
    /// `plan` before `set_object`.
    #[error("no object: send set_object first")]
    NoObject,
    /// A model name that does not resolve to a file under the models folder.
    #[error("unknown {kind} `{name}`: {path} does not exist")]
    UnknownModel {
        /// `"robot"` or `"object"`.
        kind: &'static str,
        /// The requested name.
        name: String,
        /// The path that was looked for.
        path: String,
    },
    /// A model file could not be read or lacks what this planner needs.
    #[error("{field}: {message}")]
    Model {
        /// Request field that named the model (`robot`, `shape`, …).
        field: String,
        /// What was wrong (the body crate's message names the file).
        message: String,
    },
    /// A value out of range in a request.
    #[error("invalid `{field}`: {message}")]
    InvalidValue {
        /// Path of the offending field (`mass`, `obstacles[0].shape`, …).
        field: String,
        /// What was wrong with it.
        message: String,
    },
    /// No grasp found: valid input, but nothing passed every check.
    #[error("no grasp found after {samples} samples: {reason}")]
    Infeasible {
        /// Samples drawn.
        samples: u32,
        /// The most frequent reason samples were rejected.
        reason: String,
    },
    /// The caller asked the plan to stop.
    #[error("plan was stopped")]
    Cancelled,
}

impl PlanError {
    /// A value error on `field`.
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        PlanError::InvalidValue {
            field: field.into(),
            message: message.into(),
        }
    }

    /// The bus error code of this error.
    pub fn code(&self) -> ErrorCode {
        match self {
            PlanError::NoRobot | PlanError::NoObject => ErrorCode::NotReady,
            PlanError::UnknownModel { .. } | PlanError::Model { .. } => ErrorCode::ModelError,
            PlanError::InvalidValue { .. } => ErrorCode::InvalidValue,
            PlanError::Infeasible { .. } => ErrorCode::Infeasible,
            PlanError::Cancelled => ErrorCode::Cancelled,
        }
    }

    /// Structured details for the error reply (`details` on the wire).
    pub fn details(&self) -> serde_json::Value {
        match self {
            PlanError::UnknownModel { kind, name, path } => {
                serde_json::json!({ "kind": kind, "name": name, "path": path })
            }
            PlanError::Model { field, .. } | PlanError::InvalidValue { field, .. } => {
                serde_json::json!({ "field": field })
            }
            PlanError::Infeasible { samples, reason } => {
                serde_json::json!({ "samples": samples, "reason": reason })
            }
            PlanError::NoRobot => serde_json::json!({ "missing": "set_robot" }),
            PlanError::NoObject => serde_json::json!({ "missing": "set_object" }),
            PlanError::Cancelled => serde_json::json!({}),
        }
    }
}
