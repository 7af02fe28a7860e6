//! A cheap sufficient test that a grasp balances a disturbance: a squeeze
//! plus the least-norm forces that carry the disturbance.
//!
//! What: [`Superposition`] holds a grasp's internal forces `f₀` (`G f₀ = 0`,
//! inside every cone: a squeeze) and its grasp matrix's pseudo-inverse.
//! [`Superposition::resists`] asks whether some `α ≥ 0` makes
//! `f = α f₀ + s f_p`, with `f_p = −G⁺ w` the least-norm forces balancing
//! the disturbance `w` and `s` a safety factor, satisfy every constraint of
//! the exact program: each force inside its friction cone, under its normal
//! force limit, and every joint torque `τ = Σ Jᵢᵀ fᵢ` within its effort.
//!
//! Why: the hold test solves one conic program per disturbance (about 250 µs
//! each, twelve disturbances by default). For a good grasp the squeeze
//! absorbs what the least-norm forces lack, and this answer costs a few
//! microseconds. It is sound (a `true` exhibits forces that balance `s w`
//! within every constraint) but not complete: a `false` says only that this
//! family of forces does not do it, and the exact program decides.
//!
//! How: every constraint is concave in `α` (a cone's slack
//! `μ f_n − ‖f_t‖` is linear minus convex; a torque's `effort − |τ|` linear
//! minus absolute), so their minimum `φ(α)` is concave and a golden-section
//! search over `[0, α_max]` finds its maximum; `α_max` is where the first
//! normal force reaches its limit. The forces are feasible when that maximum
//! is non-negative.
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_grasp::{contact::Contact, grasp::Grasp, grasp_matrix::Wrench};
//! use tsukami_grasp::superposition::Superposition;
//! // Two pads squeezing a 60 mm box along x, 20 N each: a squeeze.
//! let c = |x: f64| Contact::new(Point3::new(x, 0.0, 0.0), Vector3::new(-x.signum(), 0.0, 0.0)).unwrap();
//! let grasp = Grasp::new(vec![c(0.03), c(-0.03)], 0.5, 20.0, 0.03, Point3::origin()).unwrap();
//! let f0 = [Vector3::new(-10.0, 0.0, 0.0), Vector3::new(10.0, 0.0, 0.0)];
//! let s = Superposition::new(&grasp, &f0, None).unwrap();
//! // 1 kg pulling down: 4.9 N of friction per pad needs at least 9.8 N of squeeze.
//! assert!(s.resists(&Wrench::new(0.0, 0.0, -9.81, 0.0, 0.0, 0.0), 1.0));
//! // 3 kg needs 29 N per pad, beyond the 20 N limit.
//! assert!(!s.resists(&Wrench::new(0.0, 0.0, -29.4, 0.0, 0.0, 0.0), 1.0));
//! ```

use nalgebra::{DMatrix, DVector, Vector3};

use crate::grasp::Grasp;
use crate::grasp_matrix::{grasp_matrix, Wrench};
use crate::joint_torques::JointTorques;

/// Golden-section iterations: the bracket shrinks by 0.618 each, to 1e-13 of
/// its width.
const ITERATIONS: usize = 64;

/// A squeeze and the grasp matrix's pseudo-inverse, ready for many
/// disturbances (module docs).
#[derive(Debug, Clone)]
pub struct Superposition {
    /// `−G⁺` (3n × 6, world-frame forces).
    minus_pinv: DMatrix<f64>,
    /// The squeeze, stacked (3n).
    squeeze: DVector<f64>,
    /// Unit inward normals.
    normals: Vec<Vector3<f64>>,
    limits: Vec<f64>,
    mu: f64,
    /// `Jᵢᵀ` stacked: row j holds τ_j's coefficients (m × 3n), and the efforts.
    joints: Option<(DMatrix<f64>, Vec<f64>)>,
}

impl Superposition {
    /// The test for `grasp` (its μ and force limits are the ones checked)
    /// with squeeze `f0` (world frame, one per contact), under `joints`' torque
    /// limits when given; `None` when the sizes disagree or `G` has no
    /// pseudo-inverse.
    pub fn new(grasp: &Grasp, f0: &[Vector3<f64>], joints: Option<&JointTorques>) -> Option<Self> {
        let n = grasp.len();
        if f0.len() != n || joints.is_some_and(|j| j.contacts() != n) {
            return None;
        }
        let g = grasp_matrix(grasp.contacts(), grasp.reference(), grasp.torque_scale());
        let g = DMatrix::from_iterator(6, 3 * n, g.iter().copied());
        let pinv = g.pseudo_inverse(1e-12).ok()?;
        let squeeze = DVector::from_iterator(3 * n, f0.iter().flat_map(|f| [f.x, f.y, f.z]));
        let joints = joints.map(|t| {
            let unit = |i: usize, k: usize| {
                let mut f = vec![Vector3::zeros(); n];
                f[i][k] = 1.0;
                t.torques(&f)
            };
            let mut jt = DMatrix::zeros(t.joints(), 3 * n);
            for i in 0..n {
                for k in 0..3 {
                    for (j, tau) in unit(i, k).into_iter().enumerate() {
                        jt[(j, 3 * i + k)] = tau;
                    }
                }
            }
            (jt, t.efforts().to_vec())
        });
        Some(Self {
            minus_pinv: -pinv,
            squeeze,
            normals: grasp.contacts().iter().map(|c| *c.normal()).collect(),
            limits: grasp.force_limits().to_vec(),
            mu: grasp.mu(),
            joints,
        })
    }

    /// Whether `α f₀ + safety · (−G⁺ w)` satisfies every constraint for some
    /// `α ≥ 0` (module docs): then the grasp balances `safety · w`.
    pub fn resists(&self, w: &Wrench, safety: f64) -> bool {
        let w = DVector::from_column_slice(w.as_slice());
        let fp = &self.minus_pinv * w * safety;
        let tau = self
            .joints
            .as_ref()
            .map(|(jt, _)| (jt * &self.squeeze, jt * &fp));
        let phi = |a: f64| self.slack(a, &fp, tau.as_ref());
        let (mut lo, mut hi) = (0.0, self.alpha_max(&fp));
        if !hi.is_finite() || hi < 0.0 {
            return false;
        }
        let r = 0.5 * (5f64.sqrt() - 1.0);
        let (mut x1, mut x2) = (hi - r * (hi - lo), lo + r * (hi - lo));
        let (mut p1, mut p2) = (phi(x1), phi(x2));
        for _ in 0..ITERATIONS {
            if p1 >= 0.0 || p2 >= 0.0 {
                return true;
            }
            if p1 < p2 {
                lo = x1;
                (x1, p1) = (x2, p2);
                x2 = lo + r * (hi - lo);
                p2 = phi(x2);
            } else {
                hi = x2;
                (x2, p2) = (x1, p1);
                x1 = hi - r * (hi - lo);
                p1 = phi(x1);
            }
        }
        p1 >= 0.0 || p2 >= 0.0
    }

    /// The largest `α` before a normal force passes its limit.
    fn alpha_max(&self, fp: &DVector<f64>) -> f64 {
        (0..self.normals.len())
            .map(|i| {
                let (a, b) = (self.normal_part(&self.squeeze, i), self.normal_part(fp, i));
                match a > 0.0 {
                    true => (self.limits[i] - b) / a,
                    false => f64::INFINITY,
                }
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn normal_part(&self, f: &DVector<f64>, i: usize) -> f64 {
        self.normals[i].dot(&f.fixed_rows::<3>(3 * i).into_owned())
    }

    /// `φ(α)`: the smallest slack of every constraint at `α f₀ + f_p`
    /// (newtons for forces, the joints' units for torques).
    fn slack(&self, a: f64, fp: &DVector<f64>, tau: Option<&(DVector<f64>, DVector<f64>)>) -> f64 {
        let mut worst = f64::INFINITY;
        for (i, n) in self.normals.iter().enumerate() {
            let f: Vector3<f64> = self.squeeze.fixed_rows::<3>(3 * i).into_owned() * a
                + fp.fixed_rows::<3>(3 * i).into_owned();
            let fnorm = n.dot(&f);
            let ft = (f - n * fnorm).norm();
            worst = worst.min(self.mu * fnorm - ft).min(self.limits[i] - fnorm);
        }
        if let (Some((t0, tp)), Some((_, efforts))) = (tau, self.joints.as_ref()) {
            for (j, e) in efforts.iter().enumerate() {
                worst = worst.min(e - (t0[j] * a + tp[j]).abs());
            }
        }
        worst
    }
}
