//! Whole-body fallback (section 3.4): the joint lists tried in turn.
//!
//! What: [`stages`] returns the arm's joint list, then the arm plus the waist
//! joints, then the arm, waist and squat joint (the paper's virtual joint that
//! moves the shoulder height), as far as [`WholeBody`] allows.
//!
//! Why: "failing to find a feasible grasping posture using arm/hand kinematics
//! alone, the planner attempts to search the one using full body kinematics" —
//! joints that move without losing balance are added to the arm's list and IK
//! is solved over the longer list. The reply names the joints added.
//!
//! How: the planner runs the nominal-pose IK and Algorithm 1 once per stage and
//! stops at the first stage that yields a grasp.

use tsukami_body::model::JointId;
use tsukami_msgs::planner::WholeBody;

use crate::hand::HandModel;

/// Which joints are added to the arm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Stage {
    /// Arm only.
    Arm,
    /// Arm and waist.
    Waist,
    /// Arm, waist and squat.
    Squat,
}

/// One stage: its joint list (arm first) and the joints beyond the arm.
#[derive(Debug, Clone, PartialEq)]
pub struct StageJoints {
    /// The stage.
    pub stage: Stage,
    /// Every joint IK may move.
    pub joints: Vec<JointId>,
    /// The joints beyond the arm.
    pub extra: Vec<JointId>,
}

/// The stages allowed by `allowed`, in the order they are tried; a stage that
/// adds nothing (no waist joints in the model) is skipped.
pub fn stages(hand: &HandModel, allowed: WholeBody) -> Vec<StageJoints> {
    let mut out = vec![StageJoints {
        stage: Stage::Arm,
        joints: hand.arm.clone(),
        extra: Vec::new(),
    }];
    if allowed != WholeBody::ArmOnly && !hand.waist.is_empty() {
        let mut extra = hand.waist.clone();
        extra.retain(|j| !hand.arm.contains(j));
        out.push(StageJoints {
            stage: Stage::Waist,
            joints: [extra.clone(), hand.arm.clone()].concat(),
            extra,
        });
    }
    if allowed == WholeBody::Squat {
        if let Some(s) = hand.squat {
            let mut extra = hand.waist.clone();
            extra.push(s);
            extra.retain(|j| !hand.arm.contains(j));
            out.push(StageJoints {
                stage: Stage::Squat,
                joints: [extra.clone(), hand.arm.clone()].concat(),
                extra,
            });
        }
    }
    out
}
