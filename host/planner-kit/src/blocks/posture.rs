//! A grasp type's reference posture as joint values, optionally opened.
//!
//! [`posture`] gives the hand joint values of a grasp type with its flexion
//! scaled by `s` (1 = the reference posture, 0 = fingers straight; joints that
//! flex no finger, e.g. the thumb's opposition, keep their value), clamped to
//! the joint limits. A family over `s` is a pre-shape family from open to closed.

use tsukami_body::model::JointId;

use crate::grasp_types::GraspType;
use crate::robot::{Hand, Robot};

/// `(joint, value)` of grasp type `g` with flexion scaled by `s`.
pub fn posture(robot: &Robot, hand: &Hand, g: &GraspType, s: f64) -> Vec<(JointId, f64)> {
    let flexes = |j: JointId| hand.fingers.iter().any(|f| f.flex.contains(&j));
    g.posture
        .iter()
        .filter_map(|(name, &v)| robot.model.joint_id(name).ok().map(|j| (j, v)))
        .map(|(j, v)| {
            let lim = robot.model.joints[j].limits;
            let v = if flexes(j) { v * s } else { v };
            (j, v.clamp(lim.lower, lim.upper))
        })
        .collect()
}
