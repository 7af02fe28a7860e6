//! The robot as the planner sees it: model, collision shapes, the right arm,
//! the whole-body joints and the hand.
//!
//! What: [`PlanRobot::load`] reads a URDF with `tsukami-body` and resolves the
//! joint lists of `tsukami_body::ik` ([`RIGHT_ARM`], [`WAIST`], [`SQUAT`]),
//! the palm link `r_palm` and the [`Hand`].
//!
//! Why: resolving names once, in `set_robot`, turns a robot without the
//! expected joints into a clear model error up front instead of a failure in
//! the middle of a plan.

use std::path::Path;

use tsukami_body::collision::RobotCollision;
use tsukami_body::ik::{RIGHT_ARM, SQUAT, WAIST};
use tsukami_body::model::{JointId, LinkId, RobotModel};
use tsukami_body::urdf::load_urdf;

use crate::error::PlanError;
use crate::hand::Hand;

/// The palm link whose pose the planner chooses.
pub const PALM_LINK: &str = "r_palm";

/// A loaded robot.
#[derive(Debug, Clone)]
pub struct PlanRobot {
    /// Kinematic model.
    pub model: RobotModel,
    /// Link collision shapes.
    pub collision: RobotCollision,
    /// The palm link.
    pub palm: LinkId,
    /// Arm joints, shoulder to wrist.
    pub arm: Vec<JointId>,
    /// Waist joints.
    pub waist: Vec<JointId>,
    /// The squat joint.
    pub squat: JointId,
    /// Links moved by the arm, up to and including the palm (fingers excluded).
    pub arm_links: Vec<LinkId>,
    /// The hand.
    pub hand: Hand,
}

impl PlanRobot {
    /// Loads `urdf`; errors are model errors naming the file or the missing
    /// joint / link (field `robot`).
    pub fn load(urdf: &Path) -> Result<Self, PlanError> {
        let model_err = |message: String| PlanError::Model {
            field: "robot".into(),
            message,
        };
        let model = load_urdf(urdf).map_err(|e| model_err(e.to_string()))?;
        let ids = |names: &[&str]| -> Result<Vec<JointId>, PlanError> {
            names
                .iter()
                .map(|n| {
                    model
                        .joint_id(n)
                        .map_err(|e| model_err(format!("{}: {e}", urdf.display())))
                })
                .collect()
        };
        let arm = ids(&RIGHT_ARM)?;
        let waist = ids(&WAIST)?;
        let squat = ids(&[SQUAT])?[0];
        let palm = model
            .link_id(PALM_LINK)
            .map_err(|e| model_err(format!("{}: {e}", urdf.display())))?;
        let arm_links: Vec<LinkId> = model
            .chain(palm)
            .iter()
            .filter(|j| arm.contains(j))
            .map(|&j| model.joints[j].child)
            .chain([palm])
            .collect();
        let hand =
            Hand::new(&model, palm).map_err(|m| model_err(format!("{}: {m}", urdf.display())))?;
        let collision = RobotCollision::new(&model).map_err(|e| model_err(e.to_string()))?;
        Ok(Self {
            model,
            collision,
            palm,
            arm,
            waist,
            squat,
            arm_links,
            hand,
        })
    }

    /// Joint names for ids.
    pub fn names(&self, joints: &[JointId]) -> Vec<String> {
        joints
            .iter()
            .map(|&j| self.model.joints[j].name.clone())
            .collect()
    }
}
