//! Grasp mechanics for Tsukami: contact frames, the grasp matrix, three
//! force-closure tests side by side, grasp quality and finger force limits.
//!
//! The paper this project implements (Harada, Tsuji et al., "Grasp planning
//! for a humanoid hand", section 3.3) decides force closure with one quadratic
//! inequality by approximating every friction cone with an ellipsoid. This
//! crate offers that test next to an exact reference and the quality metric
//! grasp-planning users know, all on the same [`grasp::Grasp`]:
//!
//! | module | what | cost (4 contacts) |
//! | --- | --- | --- |
//! | [`ellipsoid`] | the paper's eqs. (9)–(10), margin `n − f` | ~0.3 µs, no allocation |
//! | [`exact`] | second-order cone programs (clarabel): exact closure, weight scale, forces | ~0.2 ms |
//! | [`ferrari_canny`] | ε of the L1 and L∞ wrench spaces, 6-D hulls ([`hull`]: vendored Qhull) | ε_L1 ~3 ms, ε_L∞ seconds |
//! | [`hold`] | closure + a disturbance set (±x/±y/±z weight, torques) with joint torque limits and a friction reserve; the squeeze | ~0.2 ms a disturbance |
//! | [`stiffness`] | the grasp's 6×6 stiffness from servoed finger joints and pads; the object's motion under a load | a few µs |
//! | [`superposition`] | a cheap sufficient test of one disturbance: a squeeze plus the least-norm forces | a few µs |
//!
//! Supporting modules: [`contact`] (contacts and contact frames `U_i`),
//! [`grasp_matrix`] (eq. (6), `G` with torque scale `γ`), [`finger_force`]
//! (per-contact force limits from a finger Jacobian and joint efforts),
//! [`joint_torques`] (`τ = Σ Jᵢᵀ fᵢ` within the joints' efforts, as rows of
//! the exact programs) and
//! [`hull`] (6-D convex hulls). Pure functions only: the JSON contract of the
//! `tsukami fc` command lives in the CLI (`host/app/src/cli/fc_problem.rs`).
//!
//! Conventions: world frame, metres, newtons. Contact normals point **into**
//! the object. Wrenches are `[f; γ τ]` with torques about a reference point —
//! the centre of mass in `tsukami fc` — and `γ = 1 / characteristic_length`.
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_grasp::{contact::Contact, ellipsoid, exact, grasp::Grasp};
//!
//! // Three fingers at 120° on the equator of a 30 mm sphere.
//! let contacts: Vec<Contact> = (0..3)
//!     .map(|i| {
//!         let a = i as f64 * std::f64::consts::TAU / 3.0;
//!         let out = Vector3::new(a.cos(), a.sin(), 0.0);
//!         Contact::new(Point3::from(out * 0.03), -out).unwrap()
//!     })
//!     .collect();
//! let grasp = Grasp::new(contacts, 0.5, 10.0, 0.03, Point3::origin()).unwrap();
//! let weight = grasp.weight_wrench(0.1, &Vector3::new(0.0, 0.0, -9.81), &Point3::origin());
//!
//! let fast = ellipsoid::ellipsoid_test(&grasp, &ellipsoid::EllipsoidModel::default(), &weight);
//! assert!(fast.force_closure(0.0) && fast.resists(0.0));
//! let reference = exact::exact_test(&grasp, exact::ConeModel::Circular, &weight).unwrap();
//! assert!(reference.closure.force_closure && reference.resists_weight());
//! ```

pub mod contact;
pub mod ellipsoid;
pub mod exact;
pub mod ferrari_canny;
pub mod finger_force;
pub mod grasp;
pub mod grasp_matrix;
pub mod hold;
pub mod hull;
pub mod joint_torques;
pub mod stiffness;
pub mod superposition;
