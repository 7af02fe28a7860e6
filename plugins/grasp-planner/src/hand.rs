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
//! How: [`HandModel::new`] takes ownership of the model and the config;
//! [`HandModel::load`] reads both files (the config defaults to
//! `grasp_types.toml` beside the URDF).

use std::path::{Path, PathBuf};

use tsukami_body::collision::RobotCollision;
use tsukami_body::model::{JointId, LinkId, RobotModel};

use crate::grasp_type::{GraspTypeConfig, GraspTypeError};

/// Errors building a [`HandModel`].
#[derive(Debug, thiserror::Error)]
pub enum HandError {
    /// The robot model could not be loaded.
    #[error("robot model: {0}")]
    Body(#[from] tsukami_body::BodyError),
    /// The grasp-type file is wrong.
    #[error(transparent)]
    GraspTypes(#[from] GraspTypeError),
}

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
    /// Where the grasp types came from.
    pub config_path: PathBuf,
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
    /// Loads a URDF and a grasp-type file (default: `grasp_types.toml` beside the URDF).
    pub fn load(urdf: &Path, grasp_types: Option<&Path>) -> Result<Self, HandError> {
        let robot = tsukami_body::urdf::load_urdf(urdf)?;
        let cfg_path = grasp_types.map(Path::to_path_buf).unwrap_or_else(|| {
            urdf.parent()
                .unwrap_or(Path::new("."))
                .join("grasp_types.toml")
        });
        let config = GraspTypeConfig::load(&cfg_path)?;
        Self::new(robot, config, cfg_path)
    }

    /// Checks `config` against `robot` and resolves every name.
    pub fn new(
        robot: RobotModel,
        config: GraspTypeConfig,
        config_path: PathBuf,
    ) -> Result<Self, HandError> {
        config.check_against(&robot)?;
        let collision = RobotCollision::new(&robot)?;
        let id = |n: &str| robot.joint_id(n);
        let h = &config.hand;
        let palm = robot.link_id(&h.palm_link)?;
        let arm = h
            .arm_joints
            .iter()
            .map(|n| id(n))
            .collect::<Result<Vec<_>, _>>()?;
        let wrist = h
            .wrist_joints
            .iter()
            .map(|n| id(n))
            .collect::<Result<Vec<_>, _>>()?;
        let waist = h
            .waist_joints
            .iter()
            .map(|n| id(n))
            .collect::<Result<Vec<_>, _>>()?;
        let squat = h.squat_joint.as_deref().map(id).transpose()?;
        let below = |root: LinkId| -> Vec<LinkId> {
            let mut out = vec![root];
            let mut k = 0;
            while k < out.len() {
                out.extend(robot.links[out[k]].children.iter().copied());
                k += 1;
            }
            out
        };
        let hand_links = below(palm);
        let hand_joints: Vec<JointId> = robot
            .joints
            .iter()
            .enumerate()
            .filter(|(_, j)| j.is_independent() && hand_links.contains(&j.child))
            .map(|(i, _)| i)
            .collect();
        let first_arm_child = robot.joints[arm[0]].child;
        let arm_links: Vec<LinkId> = below(first_arm_child)
            .into_iter()
            .filter(|l| !hand_links.contains(l))
            .collect();
        let body_links: Vec<LinkId> = (0..robot.links.len())
            .filter(|l| {
                !hand_links.contains(l)
                    && !arm_links.contains(l)
                    && !collision.link_parts(*l).is_empty()
            })
            .collect();
        // Torso, head and legs move only through the waist and squat joints,
        // whose limits are the robot's business: only pairs involving the arm
        // or the hand are checked for self-collision.
        let mut collision = collision;
        for (i, &a) in body_links.iter().enumerate() {
            for &b in &body_links[i + 1..] {
                collision.allow(a, b);
            }
        }
        let mut types = Vec::new();
        for g in &config.grasp_types {
            let posture = g
                .posture
                .iter()
                .map(|(n, v)| Ok((id(n)?, *v)))
                .collect::<Result<Vec<_>, tsukami_body::BodyError>>()?;
            let mut contacts = Vec::new();
            for c in &g.contacts {
                let link = robot.link_id(&c.link)?;
                let finger_joints = robot
                    .independent_chain(link)
                    .into_iter()
                    .filter(|j| hand_links.contains(&robot.joints[*j].child))
                    .collect();
                contacts.push(ResolvedContact {
                    link,
                    joint: id(&c.joint)?,
                    perturb: c
                        .perturb
                        .iter()
                        .map(|n| id(n))
                        .collect::<Result<Vec<_>, _>>()?,
                    finger_joints,
                });
            }
            types.push(ResolvedType { posture, contacts });
        }
        Ok(Self {
            robot,
            collision,
            config,
            config_path,
            palm,
            arm,
            wrist,
            waist,
            squat,
            hand_links,
            hand_joints,
            arm_links,
            body_links,
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
