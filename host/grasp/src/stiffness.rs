//! How far a held object moves under a load: the grasp's stiffness.
//!
//! What: [`GraspStiffness`] is the 6×6 stiffness of an object held by
//! contacts on servoed fingers: each finger joint a spring of stiffness
//! `k_j` (a position servo: its effort over the position error at which it
//! saturates), each contact a pad of stiffness `k_p`, the contacts sticking.
//! [`GraspStiffness::displacement`] gives the object's small motion (shift of
//! the reference point and rotation vector) under an external wrench.
//!
//! Why: the hold test asks whether forces *exist* that balance a
//! disturbance; a real hand makes them by deflecting its servos and pads, and
//! the object moves meanwhile. Three fingertips on weak joints balance the
//! weight yet let the object turn by 15° before the forces build up — the
//! physics benchmark's most frequent failure. The stiffness says how much.
//!
//! How (Cutkosky and Kao's grasp stiffness, without the preload's geometric
//! terms): the object's twist `δx` moves contact point `i` by `Gᵢᵀ δx`
//! (`Gᵢ = [I; [pᵢ − r]×]`, unscaled torques). With the finger joints'
//! Jacobians stacked in `J` (3n × m) and the joint springs `K_q`, the
//! contact forces are `f = K_c Gᵀ δx`, `K_c = k_p I − k_p² J (K_q + k_p JᵀJ)⁻¹ Jᵀ`:
//! a pad in series with the finger it sits on, the fingers coupled through
//! shared joints; a palm contact (a zero Jacobian) is the pad alone. The
//! object's stiffness is `K = G K_c Gᵀ`, and a wrench `w` moves it by
//! `δx = K⁻¹ w` (`None` when `K` is singular: some motion is not resisted),
//! and each contact's force changes by `δfᵢ = −(K_c Gᵀ δx)ᵢ`
//! ([`GraspStiffness::force_change`]): the forces the hand really makes under
//! the load, which must stay inside the friction cones for the object to
//! stay put.
//!
//! ```
//! use nalgebra::{Matrix3xX, Point3, Vector3};
//! use tsukami_grasp::grasp_matrix::Wrench;
//! use tsukami_grasp::stiffness::GraspStiffness;
//! // Two pads on rigid mounts squeezing a box along x, a third pushing up from
//! // below: no joints, pads of 1000 N/m.
//! let points = [Point3::new(0.03, 0.0, 0.0), Point3::new(-0.03, 0.0, 0.0), Point3::new(0.0, 0.0, -0.03)];
//! let jac = vec![Matrix3xX::zeros(0); 3];
//! let k = GraspStiffness::new(&points, &Point3::origin(), &jac, &[], 1000.0).unwrap();
//! // 3 N down: three pads share it, 1 mm each.
//! let w = Wrench::new(0.0, 0.0, -3.0, 0.0, 0.0, 0.0);
//! let d = k.displacement(&w).unwrap();
//! assert!((d.shift.z + 0.001).abs() < 1e-9 && d.turn.norm() < 1e-9);
//! // The pads push back 1 N up each: the forces balance the pull.
//! let df = k.force_change(&w).unwrap();
//! assert!(df.iter().all(|f| (f.z - 1.0).abs() < 1e-9));
//! ```

use nalgebra::{DMatrix, Matrix3xX, Matrix6, Point3, Vector3};

use crate::contact::Contact;
use crate::grasp_matrix::{contact_block, Wrench};

/// A held object's small motion under a load.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Displacement {
    /// Shift of the reference point, m.
    pub shift: Vector3<f64>,
    /// Rotation vector (axis × angle), rad.
    pub turn: Vector3<f64>,
}

/// The 6×6 stiffness of a grasp (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct GraspStiffness {
    stiffness: Matrix6<f64>,
    /// `K_c Gᵀ` (3n × 6): the contact forces' change per object twist.
    response: DMatrix<f64>,
}

impl GraspStiffness {
    /// The stiffness of contacts at `points` about `reference`; `jacobians[i]`
    /// (3 × m, world frame) maps the m finger joints to point `i`'s velocity,
    /// `joint_stiffness` the joints' springs (N·m/rad or N/m), `pad` the pads'
    /// stiffness (N/m). `None` when sizes disagree or a value is not positive
    /// and finite.
    pub fn new(
        points: &[Point3<f64>],
        reference: &Point3<f64>,
        jacobians: &[Matrix3xX<f64>],
        joint_stiffness: &[f64],
        pad: f64,
    ) -> Option<Self> {
        let (n, m) = (points.len(), joint_stiffness.len());
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if jacobians.len() != n
            || jacobians.iter().any(|j| j.ncols() != m)
            || !positive(pad)
            || !joint_stiffness.iter().all(|&k| positive(k))
        {
            return None;
        }
        let mut j = DMatrix::zeros(3 * n, m);
        for (i, ji) in jacobians.iter().enumerate() {
            j.view_mut((3 * i, 0), (3, m)).copy_from(ji);
        }
        // K_c = k_p I − k_p² J (K_q + k_p JᵀJ)⁻¹ Jᵀ.
        let mut inner = j.transpose() * &j * pad;
        for (d, k) in joint_stiffness.iter().enumerate() {
            inner[(d, d)] += k;
        }
        let solved = inner.cholesky()?.solve(&j.transpose());
        let kc = DMatrix::identity(3 * n, 3 * n) * pad - &j * solved * (pad * pad);
        let mut g = DMatrix::zeros(6, 3 * n);
        for (i, p) in points.iter().enumerate() {
            let c = Contact::new(*p, Vector3::z()).ok()?;
            g.view_mut((0, 3 * i), (6, 3))
                .copy_from(&contact_block(&c, reference, 1.0));
        }
        let response = kc * g.transpose();
        let k = &g * &response;
        Some(Self {
            stiffness: Matrix6::from_iterator(k.iter().copied()),
            response,
        })
    }

    /// The 6×6 matrix (force; torque about the reference) per (shift; rotation).
    pub fn matrix(&self) -> &Matrix6<f64> {
        &self.stiffness
    }

    /// The motion under the external wrench `w` (force; unscaled torque
    /// about the reference), or `None` when some motion is not resisted.
    pub fn displacement(&self, w: &Wrench) -> Option<Displacement> {
        let x = self.stiffness.cholesky()?.solve(w);
        x.iter().all(|v| v.is_finite()).then(|| Displacement {
            shift: x.fixed_rows::<3>(0).into_owned(),
            turn: x.fixed_rows::<3>(3).into_owned(),
        })
    }

    /// The change of each contact's force on the object when an external
    /// wrench `w` is applied: the object moves by `δx = K⁻¹ w` and the pads
    /// and fingers push back, `δf = −K_c Gᵀ δx` (so `Σ δfᵢ` balances `w`).
    /// The forces a compliant hand really makes, not merely forces that
    /// exist; `None` when some motion is not resisted.
    pub fn force_change(&self, w: &Wrench) -> Option<Vec<Vector3<f64>>> {
        let x = self.stiffness.cholesky()?.solve(w);
        let x = DMatrix::from_column_slice(6, 1, x.as_slice());
        let df = -(&self.response * x);
        let n = df.nrows() / 3;
        let out: Vec<Vector3<f64>> = (0..n)
            .map(|i| Vector3::new(df[3 * i], df[3 * i + 1], df[3 * i + 2]))
            .collect();
        out.iter()
            .all(|v| v.iter().all(|c| c.is_finite()))
            .then_some(out)
    }
}
