//! The robot model: links and joints in topological order, their limits,
//! mimic couplings, inertials and geometry.
//!
//! A [`RobotModel`] is built by `crate::urdf` (`load_urdf`, or
//! `RobotModel::from_urdf_str`, defined there). Its links are stored root first in
//! depth-first order, and joint `j` is always the parent joint of link `j + 1`,
//! so forward kinematics is one pass over an array ([`crate::kinematics`]).
//! Joint positions are a plain `&[f64]` with one entry per joint (fixed joints
//! included, their entry unused); the entries of mimic joints are ignored and
//! recomputed from their masters.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use nalgebra::{Isometry3, Matrix3, Unit, Vector3};

use crate::error::{BodyError, Result};
use crate::mesh::TriangleMesh;

/// Index of a link in [`RobotModel::links`] (0 is the root).
pub type LinkId = usize;
/// Index of a joint in [`RobotModel::joints`]; joint `j`'s child is link `j + 1`.
pub type JointId = usize;

/// Kind of a joint (the URDF types this crate supports).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the axis, limited.
    Revolute,
    /// Rotation about the axis, unlimited.
    Continuous,
    /// Translation along the axis.
    Prismatic,
    /// No motion.
    Fixed,
}

impl JointKind {
    /// The URDF name of the type.
    pub fn as_str(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Continuous => "continuous",
            JointKind::Prismatic => "prismatic",
            JointKind::Fixed => "fixed",
        }
    }
}

/// Joint limits. Continuous joints have infinite position limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimits {
    /// Lower position limit (rad or m).
    pub lower: f64,
    /// Upper position limit (rad or m).
    pub upper: f64,
    /// Maximum effort (N·m or N); it bounds finger forces in the grasp test.
    pub effort: f64,
    /// Maximum velocity (rad/s or m/s).
    pub velocity: f64,
}

/// A mimic coupling: `q = multiplier * q[joint] + offset`.
#[derive(Debug, Clone, PartialEq)]
pub struct Mimic {
    /// The master joint as written in the file.
    pub joint_name: String,
    /// Multiplier as written in the file.
    pub multiplier: f64,
    /// Offset as written in the file.
    pub offset: f64,
    /// The independent joint at the end of the mimic chain (a mimic of a
    /// mimic is resolved to the first non-mimic master).
    pub master: JointId,
    /// Multiplier relative to `master`.
    pub master_multiplier: f64,
    /// Offset relative to `master`.
    pub master_offset: f64,
}

/// A joint of the tree.
#[derive(Debug, Clone)]
pub struct Joint {
    /// Joint name.
    pub name: String,
    /// Joint type.
    pub kind: JointKind,
    /// Parent link.
    pub parent: LinkId,
    /// Child link (always `index + 1`).
    pub child: LinkId,
    /// Pose of the joint frame in the parent link frame.
    pub origin: Isometry3<f64>,
    /// Unit axis in the joint frame.
    pub axis: Unit<Vector3<f64>>,
    /// Limits (position, effort, velocity).
    pub limits: JointLimits,
    /// Mimic coupling, if this joint follows another one.
    pub mimic: Option<Mimic>,
}

impl Joint {
    /// True for joints that move (not fixed).
    pub fn is_movable(&self) -> bool {
        self.kind != JointKind::Fixed
    }

    /// True for joints that can be set independently (movable, not mimic).
    pub fn is_independent(&self) -> bool {
        self.is_movable() && self.mimic.is_none()
    }
}

/// Mass properties of a link.
#[derive(Debug, Clone, PartialEq)]
pub struct Inertial {
    /// Mass (kg).
    pub mass: f64,
    /// Pose of the centre of mass frame in the link frame.
    pub origin: Isometry3<f64>,
    /// Inertia tensor about the centre of mass, in the inertial frame.
    pub inertia: Matrix3<f64>,
}

/// A primitive or mesh shape, in the frame of its [`GeometryElement`].
#[derive(Debug, Clone)]
pub enum Geometry {
    /// A box with these edge lengths, centred.
    Box {
        /// Edge lengths (m).
        size: Vector3<f64>,
    },
    /// A cylinder along z, centred.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Length (m).
        length: f64,
    },
    /// A capsule along z, centred; `length` is that of the cylindrical part.
    Capsule {
        /// Radius (m).
        radius: f64,
        /// Length of the cylindrical part (m).
        length: f64,
    },
    /// A sphere, centred.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// A triangle mesh (already scaled).
    Mesh {
        /// The resolved mesh file.
        path: PathBuf,
        /// The scale applied.
        scale: Vector3<f64>,
        /// The loaded, validated mesh.
        mesh: Arc<TriangleMesh>,
    },
}

/// A geometry placed in a link frame (a URDF `<visual>` or `<collision>`).
#[derive(Debug, Clone)]
pub struct GeometryElement {
    /// Optional element name.
    pub name: Option<String>,
    /// Pose of the geometry in the link frame.
    pub origin: Isometry3<f64>,
    /// The shape.
    pub geometry: Geometry,
}

/// A link of the tree.
#[derive(Debug, Clone)]
pub struct Link {
    /// Link name.
    pub name: String,
    /// Parent link (`None` for the root).
    pub parent: Option<LinkId>,
    /// Joint connecting the parent (`Some(id - 1)` for every non-root link).
    pub parent_joint: Option<JointId>,
    /// Child links.
    pub children: Vec<LinkId>,
    /// Mass properties (mass 0 when the file gives none).
    pub inertial: Inertial,
    /// Visual geometry.
    pub visuals: Vec<GeometryElement>,
    /// Collision geometry.
    pub collisions: Vec<GeometryElement>,
}

/// A robot: a tree of links joined by joints, stored in topological order.
#[derive(Debug, Clone)]
pub struct RobotModel {
    /// Robot name from the file.
    pub name: String,
    /// The file it was loaded from (empty for an in-memory string).
    pub source: PathBuf,
    /// Links, root first, depth-first.
    pub links: Vec<Link>,
    /// Joints; `joints[j].child == j + 1`.
    pub joints: Vec<Joint>,
    /// For every link, the movable joints from the root to it, root first.
    pub(crate) chains: Vec<Vec<JointId>>,
    link_index: HashMap<String, LinkId>,
    joint_index: HashMap<String, JointId>,
}

impl RobotModel {
    pub(crate) fn assemble(
        name: String,
        source: PathBuf,
        links: Vec<Link>,
        joints: Vec<Joint>,
    ) -> Self {
        let link_index = links
            .iter()
            .enumerate()
            .map(|(i, l)| (l.name.clone(), i))
            .collect();
        let joint_index = joints
            .iter()
            .enumerate()
            .map(|(i, j)| (j.name.clone(), i))
            .collect();
        let mut chains: Vec<Vec<JointId>> = vec![Vec::new(); links.len()];
        for (j, joint) in joints.iter().enumerate() {
            let mut chain = chains[joint.parent].clone();
            if joint.is_movable() {
                chain.push(j);
            }
            chains[joint.child] = chain;
        }
        Self {
            name,
            source,
            links,
            joints,
            chains,
            link_index,
            joint_index,
        }
    }

    /// Number of joints (the length of a joint-position vector).
    pub fn dof_len(&self) -> usize {
        self.joints.len()
    }

    /// The link with this name.
    pub fn link_id(&self, name: &str) -> Result<LinkId> {
        self.link_index
            .get(name)
            .copied()
            .ok_or_else(|| BodyError::UnknownLink(name.to_string()))
    }

    /// The joint with this name.
    pub fn joint_id(&self, name: &str) -> Result<JointId> {
        self.joint_index
            .get(name)
            .copied()
            .ok_or_else(|| BodyError::UnknownJoint(name.to_string()))
    }

    /// The movable joints between the root and `link`, root first.
    pub fn chain(&self, link: LinkId) -> &[JointId] {
        &self.chains[link]
    }

    /// The independent (movable, non-mimic) joints between the root and
    /// `link`, root first; mimic joints on the way are folded into their
    /// masters.
    pub fn independent_chain(&self, link: LinkId) -> Vec<JointId> {
        let mut out = Vec::new();
        for &j in &self.chains[link] {
            let m = self.joints[j].mimic.as_ref().map_or(j, |m| m.master);
            if !out.contains(&m) {
                out.push(m);
            }
        }
        out
    }

    /// A joint-position vector of zeros clamped into the limits (the model's
    /// rest pose).
    pub fn rest_positions(&self) -> Vec<f64> {
        let mut q: Vec<f64> = self
            .joints
            .iter()
            .map(|j| 0.0f64.clamp(j.limits.lower, j.limits.upper))
            .collect();
        self.apply_mimics(&mut q);
        q
    }

    /// Overwrites the entries of mimic joints from their masters.
    pub fn apply_mimics(&self, q: &mut [f64]) {
        for (j, joint) in self.joints.iter().enumerate() {
            if let Some(m) = &joint.mimic {
                q[j] = m.master_multiplier * q[m.master] + m.master_offset;
            }
        }
    }

    /// Builds a joint-position vector from `(name, value)` pairs: joints not
    /// given are 0 (clamped to nothing: limits are not enforced here), mimic
    /// joints follow their masters. Giving a mimic or fixed joint, an unknown
    /// joint, or a non-finite value is an error.
    pub fn positions_from_named<'a>(
        &self,
        values: impl IntoIterator<Item = (&'a str, f64)>,
    ) -> Result<Vec<f64>> {
        let mut q = vec![0.0; self.joints.len()];
        for (name, value) in values {
            let j = self.joint_id(name)?;
            let joint = &self.joints[j];
            if let Some(m) = &joint.mimic {
                return Err(BodyError::Request(format!(
                    "joint '{name}' mimics '{}' and cannot be set directly",
                    m.joint_name
                )));
            }
            if joint.kind == JointKind::Fixed {
                return Err(BodyError::Request(format!(
                    "joint '{name}' is fixed and cannot be set"
                )));
            }
            if !value.is_finite() {
                return Err(BodyError::Request(format!(
                    "joint '{name}': value {value} is not finite"
                )));
            }
            q[j] = value;
        }
        self.apply_mimics(&mut q);
        Ok(q)
    }

    /// Total mass of the robot (kg).
    pub fn total_mass(&self) -> f64 {
        self.links.iter().map(|l| l.inertial.mass).sum()
    }
}
