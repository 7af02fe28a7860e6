//! Trajectory-planner messages (`<ns>/motion/plan`).

use crate::common::{JointMap, Pose};
use crate::planner::{ContactReply, JointSqueeze};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Request of `<ns>/motion/plan`: from a start state to a planned grasp, through
/// reach, approach, close and lift.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MotionPlanRequest {
    /// Joint positions at the start. Joints not given keep the default start: the
    /// controller's last published state when one answers on `<ns>/controller/state`,
    /// else the robot's rest posture.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<JointMap>,
    /// The grasp: a grasp planner's Plan reply, inline (its other fields are ignored).
    pub grasp: MotionGrasp,
    /// Height to lift the object after closing the hand, metres (0 to 0.5).
    #[serde(default = "default_lift")]
    pub lift_height: f64,
    /// How far back along the approach vector the pre-grasp palm pose is, metres
    /// (0.005 to 0.3); the approach is a straight line from there to the grasp.
    #[serde(default = "default_pregrasp")]
    pub pregrasp_distance: f64,
    /// After the lift, how far the palm moves straight back against the
    /// approach vector, carrying the object (a `retreat` phase), metres (0 to
    /// 0.3; 0, the default: no retreat).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub retreat_distance: f64,
    /// Seed of the reach planner's samples (same seed and world, same trajectory).
    #[serde(default)]
    pub seed: u64,
    /// Sample budget of the reach planner (RRT-Connect), 1 to the host's limit.
    #[serde(default = "default_motion_samples")]
    pub max_samples: u32,
    /// Acceleration limit of every joint (rad/s² or m/s²); default: each joint's
    /// from the robot description's `[acceleration]` table, else the plugin's
    /// configured `acceleration`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_acceleration: Option<f64>,
    /// Accept a grasp planned on another world version by checking it again on
    /// the current world (no link in the object, an obstacle or the robot
    /// itself; every contact on the object's surface; force closure with the
    /// weight) and refusing it when it fails. Default: a grasp of another
    /// version is refused (`invalid_value`, `details.reason = "world_changed"`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub revalidate: bool,
    /// Safety distances from the obstacles; default: the robot description's
    /// `[clearance]`, else the plugin's configured ones (10 mm for every link but
    /// the hand's, 3 mm for the hand until `close`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance: Option<ClearanceRequest>,
}

/// The safety distances of a motion request, metres (0 to 0.1); a missing one
/// keeps the plugin's.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ClearanceRequest {
    /// Every link but the hand's, in every phase, from every obstacle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<f64>,
    /// The hand's links from every obstacle in the reach and the approach.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hand: Option<f64>,
}

/// The default `lift_height` of a motion request (m); the grasp planner checks
/// the lift a grasp implies over this height.
pub const DEFAULT_LIFT_HEIGHT: f64 = 0.05;

/// The default `pregrasp_distance` of a motion request (m); the grasp planner
/// checks the approach a grasp implies over this distance.
pub const DEFAULT_PREGRASP_DISTANCE: f64 = 0.05;

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

fn default_lift() -> f64 {
    DEFAULT_LIFT_HEIGHT
}

fn default_pregrasp() -> f64 {
    DEFAULT_PREGRASP_DISTANCE
}

fn default_motion_samples() -> u32 {
    5000
}

/// The grasp a motion plan ends in: the fields of a Plan reply it uses. Other
/// fields are ignored, so a whole Plan reply may be passed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct MotionGrasp {
    /// The grasp type (its `name` selects the approach vector of the hand's
    /// grasp-type file).
    pub grasp_type: MotionGraspType,
    /// Palm pose in the world frame; must agree with `joint_positions`.
    pub palm_pose: Pose,
    /// The grasp posture: every joint the grasp sets (waist, squat, arm, hand).
    pub joint_positions: JointMap,
    /// Joints used beyond the arm (waist and squat joints); the reach moves these
    /// and the arm.
    #[serde(default)]
    pub joints_used: Vec<String>,
    /// Direction the palm moves in along the approach, world frame; default: the
    /// grasp type's approach vector turned by the palm pose.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub approach: Option<[f64; 3]>,
    /// The world version the grasp was planned on (the Plan reply's). A grasp of
    /// another version than the world's is refused unless the request asks to
    /// `revalidate` it.
    pub world_version: u64,
    /// The finger contacts (the Plan reply's); needed only to `revalidate`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contacts: Vec<ContactReply>,
    /// Length (m) scaling torques to forces (the Plan reply's), for `revalidate`;
    /// default: the object's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub characteristic_length: Option<f64>,
    /// The squeeze beyond contact (the Plan reply's `squeeze`): per independent
    /// hand joint, the torque a torque-controlled hand applies and the target a
    /// position-controlled hand commands. When given, the trajectory's last
    /// `close` point and every `lift` point carry
    /// [`command`](TrajectoryPoint::command) with each squeezed joint at its
    /// `target` (a mimic joint of the trajectory at its leader's target through
    /// the URDF's multiplier and offset), so the squeeze is applied from the end
    /// of `close` and held through the lift; a torque-controlled hand applies
    /// each `torque` over the same points. Every entry's joint must be one of
    /// the hand's independent joints, named once, its numbers finite and its
    /// `target` within the joint's limits. Empty: no squeeze, the fingers are
    /// commanded to the grasp posture.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub squeeze: Vec<JointSqueeze>,
}

/// The grasp type of a [`MotionGrasp`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct MotionGraspType {
    /// Name from the hand's grasp-type file (e.g. `"envelope4_mid"`).
    pub name: String,
}

/// Reply of `<ns>/motion/plan`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MotionPlanReply {
    /// The trajectory, as `<ns>/controller/execute` takes it; every point's
    /// `phase` is `reach`, `approach`, `close`, `lift` or (when asked)
    /// `retreat`; when the grasp has a `squeeze`, the last `close` point and
    /// every `lift` and `retreat` point carry `command`.
    pub trajectory: JointTrajectory,
    /// Where the start came from: `request`, `controller` or `rest` (joints the
    /// request named come from it in every case).
    pub start_source: String,
    /// Samples the reach planner drew.
    pub samples: u32,
    /// Configurations checked for collision, over all phases.
    pub checks: u64,
    /// Planning time, milliseconds.
    pub planning_ms: f64,
    /// The world version (robot, object, obstacles) the motion was planned on.
    pub world_version: u64,
    /// The smallest distance from a robot link to an obstacle over the
    /// trajectory's points, and where; absent when the world has no obstacle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance: Option<ClearanceReport>,
}

/// Request of `<ns>/motion/execute`: plan a motion and hand it to the
/// controller (`<ns>/controller/execute`) in one call.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MotionExecuteRequest {
    /// The motion to plan, as `<ns>/motion/plan` takes it.
    pub plan: MotionPlanRequest,
    /// Reply when the run ends (`true`, the default: the reply carries the
    /// outcome and the final state) or as soon as the controller accepts the
    /// trajectory (`false`).
    #[serde(default = "default_true")]
    pub wait: bool,
}

fn default_true() -> bool {
    true
}

/// Reply of `<ns>/motion/execute`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MotionExecuteReply {
    /// The planned motion, as `<ns>/motion/plan` replies it.
    pub plan: MotionPlanReply,
    /// The controller's reply to the trajectory (accepted or not, and with
    /// `wait` the outcome and the final state).
    pub execution: crate::controller::ExecuteReply,
}

/// Where a motion comes nearest to the obstacles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ClearanceReport {
    /// The distance, metres (at most 1; negative would be an overlap).
    pub distance: f64,
    /// The robot link (empty when nothing is within 1 m).
    pub link: String,
    /// The obstacle.
    pub obstacle: String,
    /// The trajectory phase of the point (`reach`, `approach`, `close`, `lift`).
    pub phase: String,
    /// The point's time from the trajectory's start, seconds.
    pub time: f64,
}

/// `<ns>/motion/progress`: published while a motion is planned.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct MotionProgress {
    /// Phase being planned: `reach`, `approach`, `close`, `lift`, `timing`, `done`.
    pub phase: String,
    /// Samples the reach planner drew so far.
    pub samples: u32,
    /// Milliseconds since the request started.
    pub elapsed_ms: f64,
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
    /// Joint positions in `joint_names` order: the physical posture at this
    /// point (what every collision and limit check is about).
    pub positions: Vec<f64>,
    /// Joint velocities in `joint_names` order; empty for none (then the controller
    /// interpolates linearly between positions).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub velocities: Vec<f64>,
    /// Which phase this point belongs to: the trajectory planner's `reach`,
    /// `approach`, `close`, `lift` (empty when the maker has no phases).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub phase: String,
    /// The positions a position controller commands at this point, in
    /// `joint_names` order, where they differ from `positions`; empty: command
    /// `positions`. A squeezed finger is stopped by the object at `positions`
    /// while its command lies beyond, inside the object: the servo error between
    /// the two is what presses (the trajectory planner sets it from the grasp's
    /// `squeeze`, on the last `close` point and every `lift` point). The
    /// controller interpolates commands between points as it does positions (a
    /// point without one commands its positions), so a command that first
    /// appears at the end of `close` is ramped in over that point's segment.
    /// Every value is finite and within its joint's limits.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub command: Vec<f64>,
}
