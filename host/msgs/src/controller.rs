//! Robot-controller component messages (`<ns>/controller/...`).
//!
//! `execute` takes a [`JointTrajectory`]; the controller checks it against the robot
//! model (known joints, position and velocity limits, increasing times, a start at
//! the current state) and either rejects it with the reason or runs it, publishing
//! [`ControllerState`] on `<ns>/controller/state` every control period. With `wait`
//! (the default) the reply comes when the run ends and says how it ended; `stop`
//! cancels the run within one control period.

use crate::motion::JointTrajectory;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Request of `<ns>/controller/execute`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExecuteRequest {
    /// The trajectory to run.
    pub trajectory: JointTrajectory,
    /// Reply when the run ends (`true`, the default: the reply carries the outcome
    /// and the final state) or as soon as the trajectory is accepted (`false`: follow
    /// the run on `<ns>/controller/state`).
    #[serde(default = "default_wait")]
    pub wait: bool,
}

fn default_wait() -> bool {
    true
}

/// How an accepted trajectory's run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ExecutionOutcome {
    /// The last waypoint was reached.
    Done,
    /// A `stop` cancelled the run; the robot holds where it stopped.
    Cancelled,
    /// The controller could not finish (e.g. it was shut down mid-run).
    Fault,
}

/// Reply of `<ns>/controller/execute`: accepted, or rejected with the reason.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExecuteReply {
    /// Whether the controller took the trajectory.
    pub accepted: bool,
    /// Why not, when rejected (unknown joint, limit violation, too fast, …), or what
    /// went wrong on a fault.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// How the run ended (only when the request waited for it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outcome: Option<ExecutionOutcome>,
    /// The state when the run ended (only when the request waited for it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub state: Option<ControllerState>,
    /// Control period at which a `stop` arrived, when one did: the run ended at
    /// `state.tick`, at most one period later.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stop_requested_at: Option<u64>,
}

/// Publication on `<ns>/controller/state` (and the reply to a query on that key).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ControllerState {
    /// Joint names, the order of `positions`.
    pub joint_names: Vec<String>,
    /// Current joint positions.
    pub positions: Vec<f64>,
    /// What the controller commands now, `joint_names` order: the running
    /// trajectory's interpolated `command` (its `positions` where a point has
    /// none), held after the run ends until the next one. It differs from
    /// `positions` only where a trajectory squeezes (a finger stopped by the
    /// object, commanded beyond it). Empty from controllers that predate it.
    #[serde(default)]
    pub commanded: Vec<f64>,
    /// `idle`, `executing`, or how the last run ended: `done`, `cancelled`, `error`.
    pub status: String,
    /// Controller time, seconds (`tick` control periods since the controller started).
    pub time: f64,
    /// Current joint velocities, `joint_names` order.
    #[serde(default)]
    pub velocities: Vec<f64>,
    /// Control periods since the controller started.
    #[serde(default)]
    pub tick: u64,
    /// Time from the running trajectory's start, seconds (while executing, and in
    /// the state that ends a run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trajectory_time: Option<f64>,
}
