//! Joint torque limits on contact forces: the forces a hand can really make.
//!
//! What: [`JointTorques`] ties each contact of a [`crate::grasp::Grasp`] to the
//! hand's actuated joints through its translational Jacobian. The static
//! torques of contact forces `f_i` (world frame, pushing into the object) are
//!
//! ```text
//! τ = Σ_i J_iᵀ f_i          and a hand can make them when |τ_j| ≤ τ_max,j
//! ```
//!
//! for every actuated joint `j` (URDF `effort`; a mimic joint's column is
//! folded into its leader's by the kinematics, so a coupled finger is limited
//! by the joint that drives it). A contact the structure carries — the palm,
//! held by the arm — has a zero Jacobian and loads no finger joint.
//!
//! Why: a per-finger force cap says a fingertip can press `f_max` along its
//! normal, but a finger that must also hold a tangential force, or two
//! contacts on one finger, load the same joints; only `τ = Jᵀ f` says whether
//! the joints can produce a set of forces. The exact programs of
//! [`crate::exact`] take these rows as linear constraints.
//!
//! How: [`JointTorques::torques`] evaluates `τ` for a force set;
//! [`JointTorques::rows`] gives, per joint, the coefficients of the local
//! contact-frame force components, which [`crate::exact`] turns into the pair
//! of inequalities `−τ_max ≤ τ_j ≤ τ_max`.
//!
//! ```
//! use nalgebra::{Matrix3xX, Vector3};
//! use tsukami_grasp::joint_torques::JointTorques;
//!
//! // One joint about z at the origin; the contact 0.05 m along x.
//! let j = vec![Matrix3xX::from_column_slice(&[0.0, 0.05, 0.0])];
//! let limits = JointTorques::new(j, vec![0.5]).unwrap();
//! let tau = limits.torques(&[Vector3::new(0.0, 10.0, 0.0)]);
//! assert!((tau[0] - 0.5).abs() < 1e-12); // 10 N at 5 cm: the full 0.5 N·m
//! ```

use nalgebra::{Matrix3, Matrix3xX, Vector3};

/// Why joint torque limits could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JointTorqueError {
    /// The Jacobians do not all have one column per effort limit.
    #[error("contact {contact}'s jacobian has {columns} columns for {joints} joints")]
    Columns {
        /// Contact index.
        contact: usize,
        /// Its number of columns.
        columns: usize,
        /// Number of effort limits.
        joints: usize,
    },
    /// An effort limit is negative or not finite.
    #[error("effort limit of joint {joint} must be finite and >= 0, got {value}")]
    BadEffort {
        /// Joint index.
        joint: usize,
        /// The value.
        value: f64,
    },
    /// A Jacobian entry is not finite.
    #[error("contact {0}'s jacobian has a non-finite entry")]
    NonFinite(usize),
}

/// Per-contact Jacobians over the actuated joints and their effort limits.
#[derive(Debug, Clone, PartialEq)]
pub struct JointTorques {
    jacobians: Vec<Matrix3xX<f64>>,
    efforts: Vec<f64>,
}

impl JointTorques {
    /// `jacobians[i]` (3×m, world frame) maps the m actuated joints' velocities
    /// to contact `i`'s point velocity; `efforts` are the m limits (N·m or N).
    pub fn new(
        jacobians: Vec<Matrix3xX<f64>>,
        efforts: Vec<f64>,
    ) -> Result<Self, JointTorqueError> {
        let m = efforts.len();
        if let Some((joint, &value)) = efforts
            .iter()
            .enumerate()
            .find(|(_, e)| !(e.is_finite() && **e >= 0.0))
        {
            return Err(JointTorqueError::BadEffort { joint, value });
        }
        for (contact, j) in jacobians.iter().enumerate() {
            if j.ncols() != m {
                return Err(JointTorqueError::Columns {
                    contact,
                    columns: j.ncols(),
                    joints: m,
                });
            }
            if !j.iter().all(|x| x.is_finite()) {
                return Err(JointTorqueError::NonFinite(contact));
            }
        }
        Ok(Self { jacobians, efforts })
    }

    /// Number of actuated joints.
    pub fn joints(&self) -> usize {
        self.efforts.len()
    }

    /// Number of contacts.
    pub fn contacts(&self) -> usize {
        self.jacobians.len()
    }

    /// Contact `i`'s Jacobian (3 × m, world frame).
    pub fn jacobian(&self, i: usize) -> &Matrix3xX<f64> {
        &self.jacobians[i]
    }

    /// The effort limits.
    pub fn efforts(&self) -> &[f64] {
        &self.efforts
    }

    /// The same Jacobians with every limit multiplied by `share` (a squeeze
    /// that may use only part of each joint's effort).
    pub fn scaled(&self, share: f64) -> Self {
        Self {
            jacobians: self.jacobians.clone(),
            efforts: self.efforts.iter().map(|e| e * share.max(0.0)).collect(),
        }
    }

    /// `τ = Σ_i J_iᵀ f_i` for world-frame forces `forces` (one per contact).
    pub fn torques(&self, forces: &[Vector3<f64>]) -> Vec<f64> {
        let mut tau = vec![0.0; self.joints()];
        for (j, f) in self.jacobians.iter().zip(forces) {
            for (t, col) in tau.iter_mut().zip(j.column_iter()) {
                *t += col.dot(f);
            }
        }
        tau
    }

    /// Row coefficients of joint torques in the contact-frame force
    /// components: `τ_j = Σ_i rows(i, frame_i)[j] · f_local,i`, where
    /// `frame_i` is contact `i`'s frame `U_i` (local → world).
    pub fn rows(&self, contact: usize, frame: &Matrix3<f64>) -> Matrix3xX<f64> {
        // (J_iᵀ U_i)ᵀ = U_iᵀ J_i: column j holds the local coefficients of τ_j.
        frame.transpose() * &self.jacobians[contact]
    }

    /// Whether contact `i` loads any joint (a palm contact loads none).
    pub fn loads(&self, contact: usize) -> bool {
        self.jacobians[contact].iter().any(|x| *x != 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torques_add_over_contacts_and_rows_agree() {
        let j0 = Matrix3xX::from_columns(&[Vector3::new(0.0, 0.07, 0.0), Vector3::zeros()]);
        let j1 = Matrix3xX::from_columns(&[Vector3::zeros(), Vector3::new(0.0, 0.0, 0.03)]);
        let t = JointTorques::new(vec![j0, j1], vec![1.0, 2.0]).unwrap();
        let f = [Vector3::new(1.0, 2.0, 3.0), Vector3::new(0.0, 1.0, 4.0)];
        let tau = t.torques(&f);
        assert!((tau[0] - 0.14).abs() < 1e-12 && (tau[1] - 0.12).abs() < 1e-12);
        // Through a rotated frame the row coefficients give the same torques.
        let r = nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 1.1).into_inner();
        let mut via_rows = [0.0; 2];
        for (i, fw) in f.iter().enumerate() {
            let local = r.transpose() * fw;
            let rows = t.rows(i, &r);
            for (k, v) in via_rows.iter_mut().enumerate() {
                *v += rows.column(k).dot(&local);
            }
        }
        assert!((via_rows[0] - tau[0]).abs() < 1e-12 && (via_rows[1] - tau[1]).abs() < 1e-12);
        assert!(t.loads(0) && t.loads(1));
    }

    #[test]
    fn rejects_bad_shapes_and_values() {
        let j = Matrix3xX::from_columns(&[Vector3::x()]);
        assert!(matches!(
            JointTorques::new(vec![j.clone()], vec![1.0, 1.0]),
            Err(JointTorqueError::Columns {
                contact: 0,
                columns: 1,
                joints: 2
            })
        ));
        assert!(matches!(
            JointTorques::new(vec![j.clone()], vec![-1.0]),
            Err(JointTorqueError::BadEffort { joint: 0, .. })
        ));
        let bad = Matrix3xX::from_columns(&[Vector3::new(f64::NAN, 0.0, 0.0)]);
        assert_eq!(
            JointTorques::new(vec![bad], vec![1.0]),
            Err(JointTorqueError::NonFinite(0))
        );
    }
}
