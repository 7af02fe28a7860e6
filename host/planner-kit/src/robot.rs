//! The robot of the world: its model, collision shapes and description, with
//! every name resolved to an id.
//!
//! What: [`Robot`] — the URDF model, the [`Hand`]s of the description (palm,
//! arm, wrist, fingers, the links each group moves, grasp types), and the
//! joints the whole-body fallback adds; [`Robot::stages`] lists the joint sets
//! of the fallback (arm; arm + waist; arm + waist + whole body).
//!
//! Why: resolving names once, at `set_robot`, turns a misspelt name into one
//! clear model error up front, and leaves plans free of string look-ups. Every
//! planner gets the same robot.
//!
//! How: [`Robot::load`] reads the description, the URDF and the grasp types
//! through [`crate::models::Models`] (inside the model roots, bounded), then
//! [`Hand::new`] resolves each hand.

use nalgebra::Point3;
use tsukami_body::collision::RobotCollision;
use tsukami_body::files::FileKind;
use tsukami_body::model::{Geometry, JointId, LinkId, RobotModel};
use tsukami_body::packages::PackagePath;
use tsukami_msgs::planner::{RobotSummary, SetRobot, WholeBody};

use crate::description::{Description, HandSpec};
use crate::grasp_types::GraspTypeConfig;
use crate::models::Models;
use crate::KitError;

/// One finger, resolved.
#[derive(Debug, Clone)]
pub struct Finger {
    /// Short name.
    pub name: String,
    /// The fingertip link.
    pub tip: LinkId,
    /// Links from the palm (excluded) to the tip.
    pub links: Vec<LinkId>,
    /// Independent joints from the palm to the tip (for force limits).
    pub joints: Vec<JointId>,
    /// Joints that flex it, base to tip.
    pub flex: Vec<JointId>,
    /// Centre of the fingertip pad in the tip link's frame (its first
    /// collision shape) and the pad's radius, m.
    pub pad: (Point3<f64>, f64),
}

/// One hand, resolved against the model.
#[derive(Debug, Clone)]
pub struct Hand {
    /// Name from the description.
    pub name: String,
    /// The palm link.
    pub palm: LinkId,
    /// Arm joints, shoulder to wrist.
    pub arm: Vec<JointId>,
    /// Wrist joints.
    pub wrist: Vec<JointId>,
    /// The palm and every link below it.
    pub links: Vec<LinkId>,
    /// Independent joints of the hand.
    pub joints: Vec<JointId>,
    /// Links moved by the arm, not in the hand.
    pub arm_links: Vec<LinkId>,
    /// Links the arm does not move (torso, head, legs) that have geometry.
    pub body_links: Vec<LinkId>,
    /// Collision shapes. Every pair of links is checked for self-collision
    /// but adjacent ones (a link and its nearest ancestor with geometry, and
    /// links rigidly attached) and the description's `allowed_collisions`.
    pub collision: RobotCollision,
    /// The fingers.
    pub fingers: Vec<Finger>,
    /// Touch distance, m.
    pub contact_distance: f64,
    /// Links besides the contacts allowed to touch the object.
    pub touch_allowed: Vec<LinkId>,
    /// Force cap per finger, N (an upper bound; the joints' torques limit first).
    pub max_finger_force: f64,
    /// Servo position error at full effort (rad or m), for squeeze targets.
    pub servo_saturation: f64,
    /// The hand's grasp types.
    pub grasp_types: GraspTypeConfig,
}

/// The joints of one whole-body stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Stage {
    /// Every joint the stage moves (extra joints first, then the arm).
    pub joints: Vec<JointId>,
    /// The joints beyond the arm.
    pub extra: Vec<JointId>,
}

/// The robot of the world.
#[derive(Debug, Clone)]
pub struct Robot {
    /// Kinematic model.
    pub model: RobotModel,
    /// Hands, in the description's order.
    pub hands: Vec<Hand>,
    /// Joints the fallback adds first.
    pub waist: Vec<JointId>,
    /// Joints the fallback adds last.
    pub whole_body: Vec<JointId>,
    /// The description file, relative to its model root.
    pub description_name: String,
    /// Per joint (by id), its acceleration limit from the description's
    /// `[acceleration]` table, if it states one.
    pub acceleration: Vec<Option<f64>>,
    /// Per joint (by id), its jerk limit from the description's `[jerk]`
    /// table, if it states one.
    pub jerk: Vec<Option<f64>>,
    /// The description's safety distances, if it states them.
    pub clearance: crate::description::ClearanceSpec,
}

fn below(model: &RobotModel, root: LinkId) -> Vec<LinkId> {
    let mut out = vec![root];
    let mut k = 0;
    while k < out.len() {
        out.extend(model.links[out[k]].children.iter().copied());
        k += 1;
    }
    out
}

/// The description's `table` limits (acceleration, jerk) per joint id: a
/// named joint's own, else the hand's for a joint below a palm, else the
/// default.
fn per_joint(
    model: &RobotModel,
    hands: &[Hand],
    spec: &crate::description::AccelerationSpec,
    table: &str,
) -> Result<Vec<Option<f64>>, KitError> {
    let mut out: Vec<Option<f64>> = (0..model.joints.len())
        .map(|j| {
            let in_hand = hands
                .iter()
                .any(|h| h.links.contains(&model.joints[j].child));
            if in_hand {
                spec.hand.or(spec.default)
            } else {
                spec.default
            }
        })
        .collect();
    for (name, &v) in &spec.joints {
        let key = format!("{table}.joints.{name}");
        let j = ids(model, std::slice::from_ref(name), &key)?[0];
        out[j] = Some(v);
    }
    Ok(out)
}

fn ids(model: &RobotModel, names: &[String], key: &str) -> Result<Vec<JointId>, KitError> {
    names
        .iter()
        .map(|n| {
            model.joint_id(n).map_err(|_| {
                KitError::model("robot", format!("{key}: joint `{n}` is not in the URDF"))
            })
        })
        .collect()
}

fn link(model: &RobotModel, name: &str, key: &str) -> Result<LinkId, KitError> {
    model
        .link_id(name)
        .map_err(|_| KitError::model("robot", format!("{key}: link `{name}` is not in the URDF")))
}

impl Finger {
    fn new(
        model: &RobotModel,
        spec: &crate::description::FingerSpec,
        hand_links: &[LinkId],
        key: &str,
    ) -> Result<Self, KitError> {
        let tip = link(model, &spec.tip, key)?;
        let chain: Vec<JointId> = model
            .chain(tip)
            .iter()
            .copied()
            .filter(|&j| hand_links.contains(&model.joints[j].child))
            .collect();
        if !hand_links.contains(&tip) || chain.is_empty() {
            return Err(KitError::model(
                "robot",
                format!("{key}: `{}` is not below the palm", spec.tip),
            ));
        }
        let links = chain.iter().map(|&j| model.joints[j].child).collect();
        let joints: Vec<JointId> = chain
            .iter()
            .copied()
            .filter(|&j| model.joints[j].is_independent())
            .collect();
        let flex = ids(model, &spec.flex, key)?;
        if let Some(&j) = flex.iter().find(|j| !joints.contains(j)) {
            return Err(KitError::model(
                "robot",
                format!(
                    "{key}.flex: `{}` is not an independent joint of this finger",
                    model.joints[j].name
                ),
            ));
        }
        let pad = model.links[tip]
            .collisions
            .first()
            .map_or((Point3::origin(), 0.008), |c| {
                let r = match c.geometry {
                    Geometry::Capsule { radius, .. } | Geometry::Sphere { radius } => radius,
                    _ => 0.008,
                };
                (Point3::from(c.origin.translation.vector), r)
            });
        Ok(Finger {
            name: spec.name.clone(),
            pad,
            tip,
            links,
            joints,
            flex,
        })
    }
}

impl Hand {
    /// Resolves hand `index` of a description against `model`.
    pub fn new(
        model: &RobotModel,
        spec: &HandSpec,
        index: usize,
        grasp_types: GraspTypeConfig,
    ) -> Result<Self, KitError> {
        let key = |k: &str| format!("hand[{index}].{k}");
        let palm = link(model, &spec.palm_link, &key("palm_link"))?;
        let arm = ids(model, &spec.arm, &key("arm"))?;
        let wrist = ids(model, &spec.wrist, &key("wrist"))?;
        let links = below(model, palm);
        let joints = (0..model.joints.len())
            .filter(|&j| model.joints[j].is_independent() && links.contains(&model.joints[j].child))
            .collect();
        let arm_links: Vec<LinkId> = below(model, model.joints[arm[0]].child)
            .into_iter()
            .filter(|l| !links.contains(l))
            .collect();
        let collision =
            RobotCollision::new(model).map_err(|e| KitError::model("robot", e.to_string()))?;
        let body_links: Vec<LinkId> = (0..model.links.len())
            .filter(|l| {
                !links.contains(l) && !arm_links.contains(l) && !collision.link_parts(*l).is_empty()
            })
            .collect();
        let fingers = spec
            .fingers
            .iter()
            .enumerate()
            .map(|(k, f)| Finger::new(model, f, &links, &key(&format!("fingers[{k}]"))))
            .collect::<Result<_, _>>()?;
        let touch_allowed = spec
            .touch_allowed
            .iter()
            .map(|n| link(model, n, &key("touch_allowed")))
            .collect::<Result<_, _>>()?;
        Ok(Hand {
            name: spec.name.clone(),
            palm,
            arm,
            wrist,
            links,
            joints,
            arm_links,
            body_links,
            collision,
            fingers,
            contact_distance: spec.contact_distance,
            touch_allowed,
            max_finger_force: spec.max_finger_force,
            servo_saturation: spec.servo_saturation,
            grasp_types,
        })
    }
}

/// The `package://` search folders of a SetRobot request, each resolved
/// inside the model roots (step 4 of `docs/robots.md`'s search order).
fn package_path(models: &Models, dirs: &[String]) -> Result<PackagePath, KitError> {
    if dirs.len() > SetRobot::MAX_PACKAGE_DIRS {
        return Err(KitError::invalid(
            "package_dirs",
            format!(
                "{} folders given, at most {} allowed",
                dirs.len(),
                SetRobot::MAX_PACKAGE_DIRS
            ),
        ));
    }
    let resolved = dirs
        .iter()
        .enumerate()
        .map(|(i, dir)| {
            models
                .roots()
                .resolve_dir(dir)
                .map_err(|e| KitError::model(format!("package_dirs[{i}]"), e.to_string()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(PackagePath::default().with_dirs(resolved))
}

impl Robot {
    /// Loads the robot `req` names: its description, URDF and grasp types
    /// (`req.grasp_types` overrides the first hand's file).
    pub fn load(models: &Models, req: &SetRobot) -> Result<Self, KitError> {
        let file = models.robot_description(&req.robot)?;
        let text = models.read(&file, FileKind::Toml, "robot")?;
        let description = Description::parse(&text, file.name())?;
        let urdf = models.beside(&file, &description.urdf, "robot")?;
        let xml = models.read(&urdf, FileKind::Urdf, "robot")?;
        let options = tsukami_body::urdf::LoadOptions {
            packages: package_path(models, &req.package_dirs)?,
            ..Default::default()
        };
        let model = tsukami_body::urdf::parse_urdf_with(&xml, urdf.path(), &options)
            .map(|loaded| loaded.model)
            // The loader names the file by its absolute path: named relative to
            // its root instead, nothing quoted from it.
            .map_err(|e| KitError::model("robot", crate::models::relative_error(&urdf, &e)))?;
        let mut hands = Vec::new();
        for (i, spec) in description.hands.iter().enumerate() {
            let (gt_file, field) = match (&req.grasp_types, i) {
                (Some(path), 0) => (
                    models
                        .roots()
                        .resolve(path)
                        .map_err(|e| KitError::model("grasp_types", e.to_string()))?,
                    "grasp_types",
                ),
                _ => (models.beside(&file, &spec.grasp_types, "robot")?, "robot"),
            };
            let text = models.read(&gt_file, FileKind::Toml, field)?;
            let types = GraspTypeConfig::parse(&text, gt_file.name())
                .map_err(|e| KitError::model(field, e.to_string()))?;
            if types.hand.is_present() {
                return Err(KitError::model(
                    field,
                    format!(
                        "{}: the [hand] table moved to the robot description ({})",
                        gt_file.name(),
                        file.name()
                    ),
                ));
            }
            types
                .check_against(&model)
                .map_err(|e| KitError::model(field, format!("{}: {e}", gt_file.name())))?;
            let mut types = types;
            types.hand.touch_allowed = spec.touch_allowed.clone();
            hands.push(Hand::new(&model, spec, i, types)?);
        }
        for (k, [a, b]) in description.allowed_collisions.iter().enumerate() {
            let key = format!("allowed_collisions[{k}]");
            let (a, b) = (link(&model, a, &key)?, link(&model, b, &key)?);
            hands.iter_mut().for_each(|h| h.collision.allow(a, b));
        }
        let waist = ids(&model, &description.waist, "waist")?;
        let whole_body = ids(&model, &description.whole_body, "whole_body")?;
        let acceleration = per_joint(&model, &hands, &description.acceleration, "acceleration")?;
        let jerk = per_joint(&model, &hands, &description.jerk, "jerk")?;
        Ok(Robot {
            model,
            hands,
            waist,
            whole_body,
            description_name: file.name().to_owned(),
            acceleration,
            jerk,
            clearance: description.clearance,
        })
    }

    /// The closing joints of the hand's grasp type `grasp_type` (its
    /// contacts' `joint`s, in the type's order); none for a type it does not
    /// list.
    pub fn closing_joints(&self, grasp_type: &str) -> Vec<JointId> {
        self.hand()
            .grasp_types
            .grasp_types
            .iter()
            .find(|g| g.name == grasp_type)
            .map(|g| {
                g.contacts
                    .iter()
                    .filter_map(|c| self.model.joint_id(&c.joint).ok())
                    .collect()
            })
            .unwrap_or_default()
    }

    /// The hand planners use: the description's first.
    pub fn hand(&self) -> &Hand {
        &self.hands[0]
    }

    /// Joint names of ids.
    pub fn names(&self, joints: &[JointId]) -> Vec<String> {
        joints
            .iter()
            .map(|&j| self.model.joints[j].name.clone())
            .collect()
    }

    /// The joint sets of the whole-body fallback for `hand`, as far as
    /// `allowed` goes; empty groups add no stage (section 3.4).
    pub fn stages(&self, hand: &Hand, allowed: WholeBody) -> Vec<Stage> {
        let mut out = vec![Stage {
            joints: hand.arm.clone(),
            extra: vec![],
        }];
        let mut extra: Vec<JointId> = Vec::new();
        let groups = [
            (WholeBody::Waist, &self.waist),
            (WholeBody::Squat, &self.whole_body),
        ];
        for (level, group) in groups {
            let allowed_here = matches!(
                (allowed, level),
                (WholeBody::Squat, _) | (WholeBody::Waist, WholeBody::Waist)
            );
            let new: Vec<JointId> = group
                .iter()
                .copied()
                .filter(|j| !hand.arm.contains(j))
                .collect();
            if !allowed_here || new.is_empty() {
                continue;
            }
            extra.extend(new);
            out.push(Stage {
                joints: [extra.clone(), hand.arm.clone()].concat(),
                extra: extra.clone(),
            });
        }
        out
    }

    /// What `set_robot` answers (`grasp_types`: the names the planner offers).
    pub fn summary(&self, grasp_types: Vec<String>) -> RobotSummary {
        let hand = self.hand();
        let body: Vec<JointId> = self.waist.iter().chain(&self.whole_body).copied().collect();
        RobotSummary {
            name: self.model.name.clone(),
            arm_joints: self.names(&hand.arm),
            body_joints: self.names(&body),
            hand_joints: self.names(&hand.joints),
            grasp_types,
            world_version: 0,
        }
    }
}
