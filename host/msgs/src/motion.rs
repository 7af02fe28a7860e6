//! Trajectory-planner messages (`<ns>/motion/plan`).

use crate::common::JointMap;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Request of `<ns>/motion/plan`: from a start state to a planned grasp.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MotionPlanRequest {
    /// Joint positions at the start (joints not given are taken as 0).
    pub start: JointMap,
    /// The grasp planner's Plan reply (its `joint_positions` is the goal).
    pub grasp: serde_json::Value,
    /// Height to lift the object after closing the hand, metres.
    #[serde(default = "default_lift")]
    pub lift_height: f64,
}

fn default_lift() -> f64 {
    0.05
}

/// A joint trajectory: named joints, timed waypoints. The trajectory planner makes
/// them and `<ns>/controller/execute` runs them.
///
/// Between two waypoints the controller interpolates linearly in joint space, or by
/// cubic Hermite segments when every waypoint gives `velocities`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JointTrajectory {
    /// Joint names, the order of every waypoint's `positions`.
    pub joint_names: Vec<String>,
    /// Waypoints in time order.
    pub points: Vec<TrajectoryPoint>,
}

/// One waypoint of a [`JointTrajectory`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TrajectoryPoint {
    /// Time from the trajectory's start, seconds (also accepted as `time_from_start`).
    #[serde(alias = "time_from_start")]
    pub time: f64,
    /// Joint positions in `joint_names` order.
    pub positions: Vec<f64>,
    /// Joint velocities in `joint_names` order; empty for none (then the controller
    /// interpolates linearly between positions).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub velocities: Vec<f64>,
    /// Which phase this point belongs to: `approach`, `grasp`, `close` or `lift`
    /// (empty when the maker has no phases).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub phase: String,
}
