//! The largest normal force a finger can press with at a contact, from its
//! translational Jacobian and its joints' effort limits — the per-contact
//! `f_max` the force-closure methods accept instead of one fixed value.
//!
//! Pressing the object with force `f·n` (n: inward normal) at the contact point
//! loads the finger's joints with the static torques `τ = Jᵀ (f·n)`, where `J`
//! (3×k) maps the k joint velocities to the contact point's linear velocity in
//! the same frame as `n`. With effort limits `τ_max,j`, the largest admissible
//! force is
//!
//! ```text
//! f_max = min_j  τ_max,j / |(Jᵀ n)_j|     over joints with (Jᵀ n)_j ≠ 0
//! ```
//!
//! A joint whose axis the normal force does not load (`(Jᵀ n)_j = 0`) sets no
//! limit; if no joint is loaded at all the structure carries the force and the
//! limit is infinite ([`FingerForce::unlimited`]). The Jacobian comes from the
//! kinematics crate (`tsukami-body`); this module is pure arithmetic.
//!
//! ```
//! use nalgebra::{DVector, Matrix3xX, Vector3};
//! use tsukami_grasp::finger_force::max_finger_force;
//!
//! // One revolute joint about z, contact 0.05 m along x: pushing along y loads it.
//! let j = Matrix3xX::from_column_slice(&[0.0, 0.05, 0.0]);
//! let f = max_finger_force(&j, &DVector::from_element(1, 0.5), &Vector3::y()).unwrap();
//! assert!((f.force - 10.0).abs() < 1e-12); // 0.5 N·m / 0.05 m
//! ```

use nalgebra::{DVector, Matrix3xX, Vector3};

/// Why a finger force limit could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FingerForceError {
    /// The Jacobian has a different number of columns than there are limits.
    #[error("jacobian has {columns} columns but {limits} effort limits were given")]
    DimensionMismatch {
        /// Columns of `J`.
        columns: usize,
        /// Length of the effort-limit vector.
        limits: usize,
    },
    /// An effort limit is negative or not finite.
    #[error("effort limit of joint {joint} must be non-negative and finite, got {value}")]
    BadEffort {
        /// Joint index.
        joint: usize,
        /// The rejected value.
        value: f64,
    },
    /// The Jacobian or the direction has a non-finite entry.
    #[error("jacobian or normal has a non-finite entry")]
    NonFinite,
}

/// The force limit and the joint that sets it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerForce {
    /// Largest force (N) along the direction; `+∞` when no joint is loaded.
    pub force: f64,
    /// The joint whose limit is reached first, if any.
    pub limiting_joint: Option<usize>,
}

impl FingerForce {
    /// Whether no joint limits the force.
    pub fn unlimited(&self) -> bool {
        self.limiting_joint.is_none()
    }
}

/// The largest `f ≥ 0` with `|(Jᵀ (f·direction))_j| ≤ τ_max,j` for every joint.
///
/// `jacobian` is the finger's 3×k translational Jacobian at the contact point,
/// `efforts` the k joint effort limits (N·m or N), `direction` the unit inward
/// normal (the direction the finger pushes), in the Jacobian's frame.
pub fn max_finger_force(
    jacobian: &Matrix3xX<f64>,
    efforts: &DVector<f64>,
    direction: &Vector3<f64>,
) -> Result<FingerForce, FingerForceError> {
    if jacobian.ncols() != efforts.len() {
        return Err(FingerForceError::DimensionMismatch {
            columns: jacobian.ncols(),
            limits: efforts.len(),
        });
    }
    if let Some((joint, &value)) = efforts
        .iter()
        .enumerate()
        .find(|(_, t)| !(t.is_finite() && **t >= 0.0))
    {
        return Err(FingerForceError::BadEffort { joint, value });
    }
    if !jacobian
        .iter()
        .chain(direction.iter())
        .all(|x| x.is_finite())
    {
        return Err(FingerForceError::NonFinite);
    }
    // Joint torque per newton of normal force.
    let load = jacobian.transpose() * direction;
    let mut best = FingerForce {
        force: f64::INFINITY,
        limiting_joint: None,
    };
    let scale = jacobian.norm().max(f64::MIN_POSITIVE);
    for (j, (&g, &tau)) in load.iter().zip(efforts.iter()).enumerate() {
        // Loads at rounding level (an axis exactly along the normal) set no limit.
        if g.abs() <= 1e-12 * scale {
            continue;
        }
        let f = tau / g.abs();
        if f < best.force {
            best = FingerForce {
                force: f,
                limiting_joint: Some(j),
            };
        }
    }
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_link_planar_finger() {
        // Joints about z at the origin and at (0.04, 0, 0); contact at (0.07, 0, 0).
        // J columns: z × (p − o_j) = (0, 0.07, 0) and (0, 0.03, 0).
        let j =
            Matrix3xX::from_columns(&[Vector3::new(0.0, 0.07, 0.0), Vector3::new(0.0, 0.03, 0.0)]);
        let tau = DVector::from_vec(vec![1.4, 0.3]);
        let f = max_finger_force(&j, &tau, &Vector3::y()).unwrap();
        // 1.4 / 0.07 = 20 N, 0.3 / 0.03 = 10 N: the distal joint limits.
        assert!((f.force - 10.0).abs() < 1e-12);
        assert_eq!(f.limiting_joint, Some(1));
        // Pushing along x loads neither joint.
        let free = max_finger_force(&j, &tau, &Vector3::x()).unwrap();
        assert!(free.unlimited() && free.force.is_infinite());
        // At 45° the load per newton drops by √2.
        let d = Vector3::new(1.0, 1.0, 0.0).normalize();
        let f45 = max_finger_force(&j, &tau, &d).unwrap();
        assert!((f45.force - 10.0 * 2f64.sqrt()).abs() < 1e-9);
    }

    #[test]
    fn rejects_bad_input() {
        let j = Matrix3xX::from_columns(&[Vector3::new(0.0, 0.07, 0.0)]);
        assert!(matches!(
            max_finger_force(&j, &DVector::from_vec(vec![1.0, 2.0]), &Vector3::y()),
            Err(FingerForceError::DimensionMismatch {
                columns: 1,
                limits: 2
            })
        ));
        assert!(matches!(
            max_finger_force(&j, &DVector::from_vec(vec![-1.0]), &Vector3::y()),
            Err(FingerForceError::BadEffort { joint: 0, .. })
        ));
        assert_eq!(
            max_finger_force(
                &j,
                &DVector::from_vec(vec![1.0]),
                &Vector3::new(f64::NAN, 0.0, 0.0)
            ),
            Err(FingerForceError::NonFinite)
        );
    }
}
