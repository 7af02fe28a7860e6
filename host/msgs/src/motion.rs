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

/// A joint trajectory: named joints, timed waypoints.
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
    /// Time from the trajectory's start, seconds.
    pub time: f64,
    /// Joint positions in `joint_names` order.
    pub positions: Vec<f64>,
    /// Which phase this point belongs to: `approach`, `grasp`, `close` or `lift`.
    pub phase: String,
}
