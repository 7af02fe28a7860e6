//! Forward kinematics and Jacobians.
//!
//! [`FkState`] is a reusable buffer of link poses; [`RobotModel::forward_kinematics`]
//! fills it in one pass over the topologically ordered links with no
//! allocation, so it can sit in a planner's inner loop:
//!
//! ```no_run
//! # use tsukami_body::{urdf::load_urdf, kinematics::FkState};
//! let robot = load_urdf("models/robots/tsukami_humanoid/tsukami_humanoid.urdf".as_ref()).unwrap();
//! let mut fk = FkState::new(&robot);
//! let q = robot.rest_positions();
//! robot.forward_kinematics(&q, &mut fk);
//! let palm = fk.pose(robot.link_id("r_palm").unwrap());
//! ```
//!
//! Jacobians ([`RobotModel::jacobian`]) are taken for a point fixed on a link
//! and a chosen list of independent joints ([`JointSelection`]); a mimic joint
//! on the chain adds `multiplier ×` its column to its master's column.

use nalgebra::{Isometry3, Matrix6xX, Point3, Translation3, UnitQuaternion, Vector3, Vector6};

use crate::error::{BodyError, Result};
use crate::model::{JointId, JointKind, LinkId, RobotModel};

/// Link poses for one joint configuration (a reusable buffer).
#[derive(Debug, Clone)]
pub struct FkState {
    /// Pose of the root link in the world (identity unless set).
    pub base: Isometry3<f64>,
    /// Pose of every link in the world, indexed by [`LinkId`].
    pub poses: Vec<Isometry3<f64>>,
}

impl FkState {
    /// A buffer sized for `model`, root at the identity.
    pub fn new(model: &RobotModel) -> Self {
        Self {
            base: Isometry3::identity(),
            poses: vec![Isometry3::identity(); model.links.len()],
        }
    }

    /// Pose of a link after the last [`RobotModel::forward_kinematics`].
    #[inline]
    pub fn pose(&self, link: LinkId) -> &Isometry3<f64> {
        &self.poses[link]
    }
}

/// The motion of joint `kind` about/along `axis` by `value`, as a transform
/// of the child frame relative to the joint frame.
#[inline]
pub(crate) fn joint_motion(
    kind: JointKind,
    axis: &nalgebra::Unit<Vector3<f64>>,
    value: f64,
) -> Isometry3<f64> {
    match kind {
        JointKind::Revolute | JointKind::Continuous => Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(axis, value),
        ),
        JointKind::Prismatic => Isometry3::from_parts(
            Translation3::from(axis.into_inner() * value),
            UnitQuaternion::identity(),
        ),
        JointKind::Fixed => Isometry3::identity(),
    }
}

/// A list of independent joints chosen as the columns of a Jacobian or the
/// unknowns of an IK problem.
#[derive(Debug, Clone)]
pub struct JointSelection {
    /// The selected joints, in column order.
    pub joints: Vec<JointId>,
    /// For every joint of the model, its column, or `usize::MAX`.
    column_of: Vec<usize>,
}

impl JointSelection {
    /// Selects joints by id. Fixed and mimic joints are refused (mimic joints
    /// are folded into their masters automatically).
    pub fn new(model: &RobotModel, joints: &[JointId]) -> Result<Self> {
        let mut column_of = vec![usize::MAX; model.joints.len()];
        for (c, &j) in joints.iter().enumerate() {
            let joint = model
                .joints
                .get(j)
                .ok_or_else(|| BodyError::UnknownJoint(format!("#{j}")))?;
            if joint.kind == JointKind::Fixed {
                return Err(BodyError::Request(format!(
                    "joint '{}' is fixed and cannot be selected",
                    joint.name
                )));
            }
            if let Some(m) = &joint.mimic {
                return Err(BodyError::Request(format!(
                    "joint '{}' mimics '{}': select its master instead",
                    joint.name, m.joint_name
                )));
            }
            if column_of[j] != usize::MAX {
                return Err(BodyError::Request(format!(
                    "joint '{}' is selected twice",
                    joint.name
                )));
            }
            column_of[j] = c;
        }
        Ok(Self {
            joints: joints.to_vec(),
            column_of,
        })
    }

    /// Selects joints by name.
    pub fn from_names<S: AsRef<str>>(model: &RobotModel, names: &[S]) -> Result<Self> {
        let ids = names
            .iter()
            .map(|n| model.joint_id(n.as_ref()))
            .collect::<Result<Vec<_>>>()?;
        Self::new(model, &ids)
    }

    /// Number of selected joints (Jacobian columns).
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// True when nothing is selected.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Column of joint `j`, if selected.
    #[inline]
    pub fn column(&self, j: JointId) -> Option<usize> {
        self.column_of.get(j).copied().filter(|&c| c != usize::MAX)
    }
}

impl RobotModel {
    /// Computes the world pose of every link for joint positions `q` (one
    /// entry per joint; mimic entries are recomputed from their masters, not
    /// read). `fk.base` places the root. Allocation-free.
    pub fn forward_kinematics(&self, q: &[f64], fk: &mut FkState) {
        debug_assert_eq!(q.len(), self.joints.len());
        fk.poses[0] = fk.base;
        self.forward_kinematics_from(q, fk, 0);
    }

    /// [`RobotModel::forward_kinematics`] for the joints from `first` on,
    /// when only they changed since `fk` was last computed for `q`: joints
    /// are numbered parents first, so the poses before `first` stand (the
    /// same products as a full pass, so the same bits). A finger closing
    /// moves one joint of the hand, near the end of the list.
    pub fn forward_kinematics_from(&self, q: &[f64], fk: &mut FkState, first: JointId) {
        debug_assert_eq!(q.len(), self.joints.len());
        for (j, joint) in self.joints.iter().enumerate().skip(first) {
            let value = match &joint.mimic {
                Some(m) => m.master_multiplier * q[m.master] + m.master_offset,
                None => q[j],
            };
            let local = joint.origin * joint_motion(joint.kind, &joint.axis, value);
            fk.poses[j + 1] = fk.poses[joint.parent] * local;
        }
    }

    /// The 6 × n Jacobian (rows: linear velocity, angular velocity, both in
    /// the world frame) of the point `point` (in `link`'s frame) with respect
    /// to the selected joints, at the configuration last computed in `fk`.
    pub fn jacobian(
        &self,
        fk: &FkState,
        link: LinkId,
        point: &Point3<f64>,
        selection: &JointSelection,
    ) -> Matrix6xX<f64> {
        let mut cols = vec![Vector6::zeros(); selection.len()];
        self.jacobian_columns(fk, link, &(fk.poses[link] * point), selection, &mut cols);
        if cols.is_empty() {
            // nalgebra's `from_columns` refuses an empty list.
            return Matrix6xX::zeros(0);
        }
        Matrix6xX::from_columns(&cols)
    }

    /// Allocation-free Jacobian: writes one column per selected joint into
    /// `out` (length `selection.len()`), for a world point `p_world` moving
    /// with `link`.
    pub fn jacobian_columns(
        &self,
        fk: &FkState,
        link: LinkId,
        p_world: &Point3<f64>,
        selection: &JointSelection,
        out: &mut [Vector6<f64>],
    ) {
        out.iter_mut().for_each(|c| *c = Vector6::zeros());
        for &j in self.chain(link) {
            let joint = &self.joints[j];
            let (master, mult) = match &joint.mimic {
                Some(m) => (m.master, m.master_multiplier),
                None => (j, 1.0),
            };
            let Some(c) = selection.column(master) else {
                continue;
            };
            // The child frame shares the joint's axis and (for revolute
            // joints) its origin.
            let child = &fk.poses[joint.child];
            let axis = child.rotation * joint.axis.into_inner();
            let col = match joint.kind {
                JointKind::Revolute | JointKind::Continuous => {
                    let lin = axis.cross(&(p_world - Point3::from(child.translation.vector)));
                    Vector6::new(lin.x, lin.y, lin.z, axis.x, axis.y, axis.z)
                }
                JointKind::Prismatic => Vector6::new(axis.x, axis.y, axis.z, 0.0, 0.0, 0.0),
                JointKind::Fixed => continue,
            };
            out[c] += col * mult;
        }
    }
}
