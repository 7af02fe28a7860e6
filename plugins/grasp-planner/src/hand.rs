//! The robot as the planner sees it: the kinematic model, its collision
//! shapes, and the grasp-type configuration resolved to joint and link ids.
//!
//! What: [`HandModel`] bundles a [`RobotModel`], its [`RobotCollision`] and a
//! checked [`GraspTypeConfig`], with the id lists every later step needs (arm,
//! wrist, waist and squat joints; the hand's links and joints; per grasp type
//! the posture and contact joints as ids).
//!
//! Why: resolving names once at `set_robot` keeps the planning loop free of
//! string look-ups and turns every misspelt name into one clear error up front.
//!
//! How: [`HandModel::from_robot`] takes the world's robot (the planner kit
//! resolved the description and checked the grasp types against the model)
//! and resolves each grasp type's contacts to ids.

use tsukami_body::collision::RobotCollision;
use tsukami_body::model::{JointId, LinkId, RobotModel};
use tsukami_planner_kit::{KitError, Robot};

use crate::grasp_type::GraspTypeConfig;

/// A contact of a grasp type, resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedContact {
    /// Contacting link.
    pub link: LinkId,
    /// Joint that closes it.
    pub joint: JointId,
    /// Joints perturbed by Δa.
    pub perturb: Vec<JointId>,
    /// Independent joints of the finger (from the palm to the link), for the force limit.
    pub finger_joints: Vec<JointId>,
}

/// A grasp type with ids instead of names.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedType {
    /// Reference posture: `(joint, angle)`.
    pub posture: Vec<(JointId, f64)>,
    /// Contacts.
    pub contacts: Vec<ResolvedContact>,
}

/// The robot, its collision shapes and its grasp types.
#[derive(Debug, Clone)]
pub struct HandModel {
    /// Kinematic model.
    pub robot: RobotModel,
    /// Link collision shapes.
    pub collision: RobotCollision,
    /// The grasp-type file.
    pub config: GraspTypeConfig,
    /// Finger closing stops when the link–object distance is under this (m).
    pub contact_distance: f64,
    /// Cap on a finger's normal force (N), from the robot description.
    pub max_finger_force: f64,
    /// Servo position error at full effort (rad or m), from the description.
    pub servo_saturation: f64,
    /// Palm link.
    pub palm: LinkId,
    /// Arm joints.
    pub arm: Vec<JointId>,
    /// Wrist joints.
    pub wrist: Vec<JointId>,
    /// Waist joints.
    pub waist: Vec<JointId>,
    /// Squat (shoulder height) joint.
    pub squat: Option<JointId>,
    /// Links of the hand (the palm and every link below it).
    pub hand_links: Vec<LinkId>,
    /// Independent joints of the hand.
    pub hand_joints: Vec<JointId>,
    /// Links moved by the arm joints, not in the hand.
    pub arm_links: Vec<LinkId>,
    /// Links not moved by the arm (torso, head, legs), with geometry.
    pub body_links: Vec<LinkId>,
    /// Grasp types, in the config's order.
    pub types: Vec<ResolvedType>,
}

impl HandModel {
    /// The paper planner's view of the world's robot (its first hand).
    pub fn from_robot(robot: &Robot) -> Result<Self, KitError> {
        let hand = robot.hand();
        let model = &robot.model;
        let id = |n: &str| {
            model
                .joint_id(n)
                .map_err(|e| KitError::model("robot", e.to_string()))
        };
        let mut types = Vec::new();
        for g in &hand.grasp_types.grasp_types {
            let posture = g
                .posture
                .iter()
                .map(|(n, v)| Ok((id(n)?, *v)))
                .collect::<Result<Vec<_>, KitError>>()?;
            let mut contacts = Vec::new();
            for c in &g.contacts {
                let link = model
                    .link_id(&c.link)
                    .map_err(|e| KitError::model("robot", e.to_string()))?;
                let finger_joints = model
                    .independent_chain(link)
                    .into_iter()
                    .filter(|j| hand.links.contains(&model.joints[*j].child))
                    .collect();
                let perturb = c.perturb.iter().map(|n| id(n)).collect::<Result<_, _>>()?;
                contacts.push(ResolvedContact {
                    link,
                    joint: id(&c.joint)?,
                    perturb,
                    finger_joints,
                });
            }
            types.push(ResolvedType { posture, contacts });
        }
        Ok(Self {
            robot: model.clone(),
            collision: hand.collision.clone(),
            config: hand.grasp_types.clone(),
            contact_distance: hand.contact_distance,
            max_finger_force: hand.max_finger_force,
            servo_saturation: hand.servo_saturation,
            palm: hand.palm,
            arm: hand.arm.clone(),
            wrist: hand.wrist.clone(),
            waist: robot.waist.clone(),
            squat: robot.whole_body.first().copied(),
            hand_links: hand.links.clone(),
            hand_joints: hand.joints.clone(),
            arm_links: hand.arm_links.clone(),
            body_links: hand.body_links.clone(),
            types,
        })
    }

    /// Names of joints.
    pub fn names(&self, joints: &[JointId]) -> Vec<String> {
        joints
            .iter()
            .map(|&j| self.robot.joints[j].name.clone())
            .collect()
    }

    /// Sets the hand joints of `q` to the reference posture of grasp type `t`
    /// (unlisted hand joints 0, clamped to limits) and applies mimics.
    pub fn set_posture(&self, t: usize, q: &mut [f64]) {
        for &j in &self.hand_joints {
            let l = &self.robot.joints[j].limits;
            q[j] = 0.0f64.clamp(l.lower, l.upper);
        }
        for &(j, v) in &self.types[t].posture {
            let l = &self.robot.joints[j].limits;
            q[j] = v.clamp(l.lower, l.upper);
        }
        self.robot.apply_mimics(q);
    }
}
