//! Every way a motion request fails, and its mapping to the wire's error codes.
//!
//! What: [`MotionError`] — a bad value (`invalid_value`, naming the field), a
//! grasp of another world version (`invalid_value`, reason `world_changed`,
//! both versions in `details`), an
//! impossible motion (`infeasible`, with a stable `reason` word and a message
//! naming the link and the body it hits), a stop (`cancelled`), or the kit's own
//! errors (`not_ready` before a robot and an object are set).
//!
//! Why: a client must tell "fix your request" from "this grasp cannot be
//! reached from here" from "nothing to plan in yet", and see why.
//!
//! ```
//! use tsukami_trajectory_planner::error::MotionError;
//! let e = MotionError::infeasible("goal_in_collision", "the grasp posture collides");
//! let wire = e.to_call_error(3);
//! assert_eq!(wire.code, "infeasible");
//! assert!(wire.details_json.contains(r#""reason":"goal_in_collision""#));
//! ```

use tsukami_msgs::ErrorCode;
use tsukami_planner_kit::KitError;
use tsukami_plugin_api::CallError;

/// Why no trajectory was returned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MotionError {
    /// A request value is wrong.
    #[error("invalid `{field}`: {message}")]
    Invalid {
        /// The request field (JSON path).
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// No collision-free motion: the start or goal collides, or no path.
    #[error("{message}")]
    Infeasible {
        /// Stable machine-readable word: `start_in_collision`, `goal_in_collision`,
        /// `pregrasp_unreachable`, `approach_blocked`, `close_blocked`,
        /// `lift_unreachable`, `lift_blocked`, `no_path`, `grasp_invalid` (a
        /// re-validated grasp fails on the current world).
        reason: &'static str,
        /// What happened, naming the link and the body it hits.
        message: String,
        /// Samples the reach planner drew.
        samples: u32,
    },
    /// The grasp was planned on another world version and the request did not
    /// ask to re-validate it.
    #[error(
        "the grasp was planned on world version {grasp}, but the world is at version {world}: \
         plan the grasp again, or set `revalidate` to check it on version {world}"
    )]
    WorldChanged {
        /// The grasp's `world_version`.
        grasp: u64,
        /// The current world's version.
        world: u64,
    },
    /// A `stop` arrived.
    #[error("motion planning cancelled by stop")]
    Cancelled,
    /// The kit's world is not ready (no robot or no object).
    #[error(transparent)]
    Kit(#[from] KitError),
}

impl MotionError {
    /// An [`MotionError::Invalid`].
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        MotionError::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    /// An [`MotionError::Infeasible`] with no samples drawn.
    pub fn infeasible(reason: &'static str, message: impl Into<String>) -> Self {
        MotionError::Infeasible {
            reason,
            message: message.into(),
            samples: 0,
        }
    }

    /// The bus error: code, message and details (`reason`, `field` or
    /// `samples`, and the world version planned on).
    pub fn to_call_error(&self, world_version: u64) -> CallError {
        let (code, details) = match self {
            MotionError::Kit(k) => return k.to_call_error(),
            MotionError::Invalid { field, .. } => (
                ErrorCode::InvalidValue,
                serde_json::json!({ "reason": "bad_value", "field": field }),
            ),
            MotionError::Infeasible {
                reason, samples, ..
            } => (
                ErrorCode::Infeasible,
                serde_json::json!({ "reason": reason, "samples": samples }),
            ),
            MotionError::WorldChanged { grasp, .. } => (
                ErrorCode::InvalidValue,
                serde_json::json!({
                    "reason": "world_changed",
                    "field": "grasp.world_version",
                    "grasp_world_version": grasp,
                }),
            ),
            MotionError::Cancelled => (
                ErrorCode::Cancelled,
                serde_json::json!({ "reason": "cancelled" }),
            ),
        };
        let mut details = details;
        details["world_version"] = world_version.into();
        let mut e = CallError::new(code.as_str(), self.to_string());
        e.details_json = details.to_string();
        e
    }
}
