//! A motion request checked against the robot: start, grasp posture, joints.
//!
//! What: [`start_state`] checks the request's start joints and writes them over
//! the default start; [`resolve`] turns the request's grasp (a Plan reply's
//! fields) into a [`Goal`]: the joints the reach moves, the hand's joints, the
//! grasp posture with the hand closed and open, the palm pose and the approach
//! direction.
//!
//! Why: validate everything before planning: an unknown joint, a value outside
//! its limits, an unknown grasp type or a palm pose that disagrees with the joint
//! positions is the client's mistake and is named as such (`invalid_value` with
//! the field), never a path that ends somewhere else.
//!
//! Mimic joints in the grasp (a Plan reply lists them) must agree with their
//! masters.
//!
//! How: the reach joints are the hand's arm, the `joints_used` (each must be one
//! of the description's waist or whole-body joints), and any other joint the
//! grasp sets to a value other than the start's. The open hand has every finger's
//! flex joints at 0 (clamped into their limits) and the grasp type's other
//! closing joints (e.g. the thumb's opposition) at the type's reference posture,
//! where the grasp planner started closing them, or part way there
//! ([`Goal::open_by`]); the remaining hand joints are at their grasp values. The approach direction is the
//! grasp type's `approach` (palm frame) turned by the palm pose, unless the
//! request gives one. The grasp's `squeeze` is checked against the hand
//! ([`crate::squeeze::targets`]).

use nalgebra::{Isometry3, Vector3};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{JointId, RobotModel};
use tsukami_msgs::common::JointMap;
use tsukami_msgs::motion::MotionGrasp;
use tsukami_planner_kit::validate::{self, Limits};
use tsukami_planner_kit::Robot;

pub use tsukami_planner_kit::motion_check::goal::Goal;

use crate::error::MotionError;

/// How far the request's palm pose may be from the one its joint positions give.
pub const PALM_POSITION_TOLERANCE: f64 = 0.005;
/// The same for the orientation, rad.
pub const PALM_ANGLE_TOLERANCE: f64 = 0.05;

fn joint_value(
    model: &RobotModel,
    name: &str,
    value: f64,
    field: &str,
) -> Result<JointId, MotionError> {
    let field = format!("{field}.{name}");
    let j = model.joint_id(name).map_err(|_| {
        MotionError::invalid(
            &field,
            format!("robot `{}` has no joint `{name}`", model.name),
        )
    })?;
    let joint = &model.joints[j];
    if !joint.is_movable() {
        return Err(MotionError::invalid(
            &field,
            "is a fixed joint and cannot be set",
        ));
    }
    let lim = joint.limits;
    if !value.is_finite() || value < lim.lower - 1e-6 || value > lim.upper + 1e-6 {
        return Err(MotionError::invalid(
            &field,
            format!(
                "{value} is outside the joint's limits [{}, {}]",
                lim.lower, lim.upper
            ),
        ));
    }
    Ok(j)
}

fn write_joints(
    model: &RobotModel,
    joints: &JointMap,
    field: &str,
    q: &mut [f64],
) -> Result<Vec<JointId>, MotionError> {
    let mut set = Vec::with_capacity(joints.len());
    let mut mimics = Vec::new();
    for (name, &v) in joints {
        let j = joint_value(model, name, v, field)?;
        if model.joints[j].mimic.is_some() {
            mimics.push((name, j, v));
            continue;
        }
        let lim = model.joints[j].limits;
        q[j] = v.clamp(lim.lower, lim.upper);
        set.push(j);
    }
    model.apply_mimics(q);
    // A mimic joint follows its master; a value given for it must agree.
    if let Some((name, j, v)) = mimics
        .into_iter()
        .find(|&(_, j, v)| (q[j] - v).abs() > 1e-6)
    {
        return Err(MotionError::invalid(
            format!("{field}.{name}"),
            format!(
                "{v} disagrees with its master joint, which puts this mimic joint at {}",
                q[j]
            ),
        ));
    }
    Ok(set)
}

/// The start: `default` (full joint vector) with the request's `start` joints
/// written over it.
pub fn start_state(
    model: &RobotModel,
    default: &[f64],
    start: Option<&JointMap>,
) -> Result<Vec<f64>, MotionError> {
    let mut q = default.to_vec();
    if let Some(start) = start {
        write_joints(model, start, "start", &mut q)?;
    }
    model.apply_mimics(&mut q);
    Ok(q)
}

/// The joints the reach moves: the body joints the grasp uses, the arm, and any
/// other non-hand joint the grasp moves away from the start.
fn reach_joints(
    robot: &Robot,
    grasp: &MotionGrasp,
    set: &[JointId],
    start: &[f64],
    closed: &[f64],
) -> Result<Vec<JointId>, MotionError> {
    let hand = robot.hand();
    let body: Vec<JointId> = robot
        .waist
        .iter()
        .chain(&robot.whole_body)
        .copied()
        .collect();
    let mut used = Vec::new();
    for (i, name) in grasp.joints_used.iter().enumerate() {
        match robot.model.joint_id(name).ok().filter(|j| body.contains(j)) {
            Some(j) if !used.contains(&j) => used.push(j),
            Some(_) => {}
            None => {
                return Err(MotionError::invalid(
                    format!("grasp.joints_used[{i}]"),
                    format!("`{name}` is not one of the robot's waist or whole-body joints"),
                ))
            }
        }
    }
    let moved = set.iter().copied().filter(|&j| {
        !hand.joints.contains(&j) && !hand.arm.contains(&j) && (closed[j] - start[j]).abs() > 1e-9
    });
    let mut reach: Vec<JointId> = body.iter().copied().filter(|j| used.contains(j)).collect();
    for j in moved {
        if !reach.contains(&j) {
            reach.push(j);
        }
    }
    reach.extend(hand.arm.iter().copied());
    Ok(reach)
}

fn approach_direction(
    robot: &Robot,
    grasp: &MotionGrasp,
    palm: &Isometry3<f64>,
) -> Result<Vector3<f64>, MotionError> {
    if let Some(a) = grasp.approach {
        let v = Vector3::from(a);
        let n = v.norm();
        if !n.is_finite() || n < 1e-9 {
            return Err(MotionError::invalid(
                "grasp.approach",
                "must be a finite, non-zero vector",
            ));
        }
        return Ok(v / n);
    }
    let types = &robot.hand().grasp_types.grasp_types;
    let name = &grasp.grasp_type.name;
    let g = types.iter().find(|g| &g.name == name).ok_or_else(|| {
        let known: Vec<&str> = types.iter().map(|g| g.name.as_str()).collect();
        MotionError::invalid(
            "grasp.grasp_type.name",
            format!("unknown grasp type `{name}`; the hand has {known:?}"),
        )
    })?;
    Ok(palm.rotation * g.approach())
}

/// Resolves `grasp` from the full `start` configuration.
pub fn resolve(
    robot: &Robot,
    grasp: &MotionGrasp,
    start: &[f64],
    limits: &Limits,
) -> Result<Goal, MotionError> {
    let model = &robot.model;
    let hand = robot.hand();
    let mut closed = start.to_vec();
    let set = write_joints(
        model,
        &grasp.joint_positions,
        "grasp.joint_positions",
        &mut closed,
    )?;
    if let Some(&j) = hand.arm.iter().find(|j| !set.contains(j)) {
        return Err(MotionError::invalid(
            "grasp.joint_positions",
            format!("the arm joint `{}` is missing", model.joints[j].name),
        ));
    }
    let given = validate::pose(&grasp.palm_pose, "grasp.palm_pose", limits)
        .map_err(|e| MotionError::invalid("grasp.palm_pose", e.to_string()))?;
    let mut fk = FkState::new(model);
    model.forward_kinematics(&closed, &mut fk);
    let palm = *fk.pose(hand.palm);
    let off = (palm.translation.vector - given.translation.vector).norm();
    let turn = palm.rotation.angle_to(&given.rotation);
    if off > PALM_POSITION_TOLERANCE || turn > PALM_ANGLE_TOLERANCE {
        return Err(MotionError::invalid(
            "grasp.palm_pose",
            format!("does not match grasp.joint_positions: they put the palm {:.1} mm and {turn:.3} rad away", off * 1e3),
        ));
    }
    let reach = reach_joints(robot, grasp, &set, start, &closed)?;
    let approach = approach_direction(robot, grasp, &palm)?;
    let squeeze = crate::squeeze::targets(model, &hand.joints, &grasp.squeeze)?;
    let mut goal = Goal::new(robot, closed, reach, &grasp.grasp_type.name, approach);
    goal.squeeze = squeeze;
    Ok(goal)
}
