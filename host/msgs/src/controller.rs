//! Robot-controller component messages (`<ns>/controller/...`).

use crate::motion::JointTrajectory;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Request of `<ns>/controller/execute`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExecuteRequest {
    /// The trajectory to run.
    pub trajectory: JointTrajectory,
}

/// Reply of `<ns>/controller/execute`: accepted, or rejected with the reason.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExecuteReply {
    /// Whether the controller took the trajectory.
    pub accepted: bool,
    /// Why not, when rejected (unknown joint, limit violation, too fast, …).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// Publication on `<ns>/controller/state`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ControllerState {
    /// Joint names, the order of `positions`.
    pub joint_names: Vec<String>,
    /// Current joint positions.
    pub positions: Vec<f64>,
    /// `idle`, `executing`, `done` or `error`.
    pub status: String,
    /// Controller time, seconds.
    pub time: f64,
}
