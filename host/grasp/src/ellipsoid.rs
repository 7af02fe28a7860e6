//! The paper's fast force-closure test: friction cones approximated by
//! ellipsoids, eqs. (9)–(10) (Harada, Tsuji et al., section 3.3.2).
//!
//! # Eq. (9): one ellipsoid per contact
//!
//! The contact force `f_i` is restricted to the ellipsoid
//!
//! ```text
//! (f_i − c_i n_i)ᵀ U_i S U_iᵀ (f_i − c_i n_i) ≤ 1                              (eq. (9))
//! ```
//!
//! centred at `c_i n_i` on the inward normal, with tangential semi-axes
//! `a_i = μ c_i / √2` and normal semi-axis `b_i = α c_i`. The paper typesets
//! `S = diag[μf/√2, μf/√2, αf]`, the semi-axes themselves; with those entries
//! the left-hand side has units of N³, not a pure number, so the paper's `S` is
//! read here as the **inverse squares of the semi-axes**,
//! `S = diag[1/a², 1/a², 1/b²]`, which makes eq. (9) the standard ellipsoid.
//! Because the two tangential semi-axes are equal, the ellipsoid's shape matrix
//! does not depend on which tangents `U_i` holds:
//! `Q_i = (U_i S U_iᵀ)⁻¹ = a² I + (b² − a²) n nᵀ` — the hot path uses that.
//!
//! **Fitting the cone.** In units of `c`, the ellipsoid's tangential radius at
//! normal force `c(1 + z)` is `√(1 − z²/α²)/√2` and the cone's is `μ(1 + z)`.
//! `(1 + z)² − (1 − z²/α²)/2` has its minimum `1/2 − 1/(1 + 1/(2α²))` at
//! `z = −1/(1 + 1/(2α²))`, which is `≥ 0` exactly when `α ≤ 1/√2`: the paper's
//! tangential `1/√2` admits normal semi-axes up to `1/√2` (the ellipsoid then
//! touches the cone along a circle). [`DEFAULT_ALPHA`] is that largest value.
//!
//! **Fitting the force bound.** The paper calls the centre `f_max`; then the
//! ellipsoid reaches normal force `(1 + α) f_max`, beyond the contract's bound
//! `f_n ≤ f_max`. [`EllipsoidModel::inscribed`] (the default) puts the centre
//! at `c = f_max/(1 + α)`, so the ellipsoid spans `f_n ∈ [(1−α)c, f_max]`: with
//! `α = 1/√2` it touches both the cone and the bound, the largest ellipsoid of
//! the paper's shape inside the exact bounded cone. [`EllipsoidModel::paper`]
//! keeps the literal `c = f_max`. Force closure does not depend on this choice
//! (scaling every ellipsoid scales `w0` and `G U⁻¹ Gᵀ` together); the weight
//! test and its margin do.
//!
//! # Eq. (10): the wrench set
//!
//! With `u_i` in the unit ball, `f_i = c_i n_i + L_i u_i` (`L_i L_iᵀ = Q_i`).
//! Replacing "each `‖u_i‖ ≤ 1`" by "`Σ ‖u_i‖² ≤ n`" turns the Minkowski sum of the
//! contact ellipsoids into one ellipsoid in wrench space, the image of that
//! ball under `G`:
//!
//! ```text
//! f(p_1..p_n) = (w − w0)ᵀ (G U⁻¹ Gᵀ)⁻¹ (w − w0) ≤ n,   w0 = Σ c_i G_i n_i          (eq. (10))
//! ```
//!
//! with `G U⁻¹ Gᵀ = Σ_i G_i Q_i G_iᵀ`, a 6×6 sum — the 3n×3n block matrix is
//! never formed, and one Cholesky factorisation of the 6×6 answers both
//! questions below without heap allocation. `w` is the wrench the contact
//! forces must produce: to hold the object against an external wrench `w_ext`
//! (its weight), `w = −w_ext`.
//!
//! * **Force closure**: the origin strictly inside the approximate wrench set,
//!   `n − f(0) > δf`. Degenerate `G U⁻¹ Gᵀ` (the set is flat in some wrench
//!   direction, e.g. nothing resists torque about the line through two
//!   contacts) is never force closure.
//! * **Resisting the weight**: `n − f(−w_ext) ≥ δf`. The paper's planner
//!   accepts a posture when `n − f ≥ δf` (Algorithm 1).
//!
//! # How it relates to the exact cone
//!
//! Each ellipsoid lies inside its (bounded) friction cone, so the true Minkowski
//! sum of the ellipsoids is an **inner** approximation of the exact wrench set.
//! Eq. (10) with threshold `n`, however, is an **outer** approximation of that
//! sum (`Σ‖u_i‖² ≤ n` contains the product of the unit balls), so the test can
//! accept wrenches no cone-respecting forces produce: false positives are
//! possible, and `δf` trades them for false negatives. With `δf = n − 1` the
//! test is inner (`Σ‖u_i‖² ≤ 1` implies every `‖u_i‖ ≤ 1`): no false
//! positives, at the price of many false negatives. `docs/force-closure.md`
//! gives the measured agreement and the `δf` that removed every false positive
//! on random grasps.
//!
//! # Several ellipsoids per cone
//!
//! [`multi_ellipsoid_test`] takes `k` ellipsoid models per contact (e.g. one
//! centred at `c n` and one at `c n/2`, scaled down with it) and evaluates
//! eq. (10) for **every combination** of one ellipsoid per contact: `k^n`
//! combinations, each one 6×6 accumulation and Cholesky (≈ 0.1–0.2 µs), so two
//! ellipsoids on five fingers cost 32 single tests and on ten fingers 1,024.
//! As the issue asks, the grasp passes only if every combination passes (the
//! worst margin is the result): a conservative rule. The best margin (the
//! union reading, "some combination passes", which is what the Minkowski sum
//! of unions of ellipsoids means) is returned beside it.

use core::f64::consts::FRAC_1_SQRT_2;

use nalgebra::{Cholesky, Matrix3, Matrix6, SymmetricEigen, Vector3, Vector6};

use crate::contact::Contact;
use crate::grasp::Grasp;
use crate::grasp_matrix::{torque_map, Wrench};

/// Default normal semi-axis ratio `α = 1/√2`: the largest for which the
/// paper's ellipsoid stays inside the Coulomb cone (see the module docs).
pub const DEFAULT_ALPHA: f64 = FRAC_1_SQRT_2;

/// Relative pivot size below which `G U⁻¹ Gᵀ` counts as singular.
const SINGULAR_PIVOT: f64 = 1e-10;

/// Why an ellipsoid test could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EllipsoidError {
    /// `α` is not positive and finite.
    #[error("ellipsoid normal semi-axis ratio alpha must be positive and finite, got {0}")]
    BadAlpha(f64),
    /// The centre fraction is not positive and finite.
    #[error("ellipsoid centre fraction must be positive and finite, got {0}")]
    BadCentre(f64),
    /// No ellipsoid models were given to the multi-ellipsoid test.
    #[error("the multi-ellipsoid test needs at least one ellipsoid per contact")]
    NoModels,
    /// `k^n` exceeds the allowed number of combinations.
    #[error("{models}^{contacts} ellipsoid combinations exceed the limit of {limit}")]
    TooManyCombinations {
        /// Ellipsoids per contact `k`.
        models: usize,
        /// Contacts `n`.
        contacts: usize,
        /// The limit given.
        limit: u64,
    },
}

/// One ellipsoid of the paper's shape, relative to a contact's force limit:
/// centre `c = centre_fraction · f_max` on the normal, tangential semi-axes
/// `μ c/√2`, normal semi-axis `α c`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EllipsoidModel {
    /// Normal semi-axis over centre distance, `α` (≤ 1/√2 keeps the ellipsoid in the cone).
    pub alpha: f64,
    /// Normal force at the ellipsoid's centre over the contact's `f_max`.
    pub centre_fraction: f64,
}

impl Default for EllipsoidModel {
    fn default() -> Self {
        Self::inscribed(DEFAULT_ALPHA)
    }
}

impl EllipsoidModel {
    /// Centre at `f_max/(1 + α)`: the ellipsoid reaches exactly `f_n = f_max`.
    pub fn inscribed(alpha: f64) -> Self {
        Self {
            alpha,
            centre_fraction: 1.0 / (1.0 + alpha),
        }
    }

    /// The paper's literal placement: centre at `f_max` (reaches `(1 + α) f_max`).
    pub fn paper(alpha: f64) -> Self {
        Self {
            alpha,
            centre_fraction: 1.0,
        }
    }

    /// The same ellipsoid shrunk towards the cone's apex by `scale` (centre and
    /// semi-axes alike): still inside the cone and the force bound if this one is.
    pub fn scaled(self, scale: f64) -> Self {
        Self {
            alpha: self.alpha,
            centre_fraction: self.centre_fraction * scale,
        }
    }

    /// Checks that `α` and the centre fraction are positive and finite.
    pub fn validate(&self) -> Result<(), EllipsoidError> {
        if !(self.alpha.is_finite() && self.alpha > 0.0) {
            return Err(EllipsoidError::BadAlpha(self.alpha));
        }
        if !(self.centre_fraction.is_finite() && self.centre_fraction > 0.0) {
            return Err(EllipsoidError::BadCentre(self.centre_fraction));
        }
        Ok(())
    }

    /// `(c, a, b)`: centre normal force, tangential and normal semi-axes (N).
    #[inline]
    pub fn axes(&self, mu: f64, f_max: f64) -> (f64, f64, f64) {
        let c = self.centre_fraction * f_max;
        (c, mu * c * FRAC_1_SQRT_2, self.alpha * c)
    }

    /// `U_i S U_iᵀ` with `S = diag[1/a², 1/a², 1/b²]`, the matrix of eq. (9).
    pub fn weight_matrix(&self, contact: &Contact, mu: f64, f_max: f64) -> Matrix3<f64> {
        let (_, a, b) = self.axes(mu, f_max);
        let u = contact.frame();
        u * Matrix3::from_diagonal(&Vector3::new(1.0 / (a * a), 1.0 / (a * a), 1.0 / (b * b)))
            * u.transpose()
    }

    /// `Q_i = (U_i S U_iᵀ)⁻¹ = a² I + (b² − a²) n nᵀ`.
    #[inline]
    pub fn shape_matrix(&self, normal: &Vector3<f64>, mu: f64, f_max: f64) -> Matrix3<f64> {
        let (_, a, b) = self.axes(mu, f_max);
        let a2 = a * a;
        Matrix3::from_diagonal_element(a2) + normal * normal.transpose() * (b * b - a2)
    }

    /// Whether `force` satisfies eq. (9) at `contact`.
    pub fn contains(&self, contact: &Contact, mu: f64, f_max: f64, force: &Vector3<f64>) -> bool {
        let (c, _, _) = self.axes(mu, f_max);
        let d = force - contact.normal() * c;
        (d.transpose() * self.weight_matrix(contact, mu, f_max) * d)[0] <= 1.0
    }
}

/// The two values of eq. (10) for one grasp: at `w = 0` (force closure) and
/// at the wrench the contacts must produce against the external wrench.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EllipsoidTest {
    /// `f(0)`; `+∞` when `G U⁻¹ Gᵀ` is singular.
    pub closure_value: f64,
    /// `f(−w_ext)`; `+∞` when the wrench is outside a degenerate set.
    pub wrench_value: f64,
    /// Number of contacts `n`, the paper's threshold.
    pub contacts: usize,
    /// Whether `G U⁻¹ Gᵀ` was singular (the wrench set is flat).
    pub degenerate: bool,
}

impl EllipsoidTest {
    /// `n − f(0)`.
    pub fn closure_margin(&self) -> f64 {
        self.contacts as f64 - self.closure_value
    }

    /// `n − f(−w_ext)`, the paper's margin (compared with `δf` in Algorithm 1).
    pub fn margin(&self) -> f64 {
        self.contacts as f64 - self.wrench_value
    }

    /// Force closure with threshold `δf`: `n − f(0) > δf` and a non-flat set.
    pub fn force_closure(&self, delta_f: f64) -> bool {
        !self.degenerate && self.closure_margin() > delta_f
    }

    /// The external wrench is resisted with threshold `δf`: `n − f(−w_ext) ≥ δf`.
    pub fn resists(&self, delta_f: f64) -> bool {
        self.margin() >= delta_f
    }
}

/// `G_i Q_i G_iᵀ` and `c_i G_i n_i` for one contact.
#[inline]
fn contact_terms(
    contact: &Contact,
    f_max: f64,
    grasp: &Grasp,
    model: &EllipsoidModel,
) -> (Matrix6<f64>, Vector6<f64>) {
    let n = contact.normal();
    let q = model.shape_matrix(n, grasp.mu(), f_max);
    let p = torque_map(contact.position(), grasp.reference(), grasp.torque_scale());
    let pq = p * q;
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&q);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&pq);
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(&pq.transpose());
    // P Q Pᵀ with Pᵀ = −P (skew-symmetric).
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-(pq * p)));
    let c = model.centre_fraction * f_max;
    let t = p * n * c;
    (m, Vector6::new(n.x * c, n.y * c, n.z * c, t.x, t.y, t.z))
}

/// Evaluates `(d₀ᵀ M⁻¹ d₀, d₁ᵀ M⁻¹ d₁)` with `d₀ = −w0`, `d₁ = w − w0`.
fn evaluate(
    m: Matrix6<f64>,
    w0: &Vector6<f64>,
    w: &Vector6<f64>,
    contacts: usize,
) -> EllipsoidTest {
    let d0 = -w0;
    let d1 = w - w0;
    let diag = m.diagonal();
    if let Some(chol) = Cholesky::new(m) {
        let l = chol.l_dirty();
        let regular = (0..6).all(|k| l[(k, k)] * l[(k, k)] > SINGULAR_PIVOT * diag[k]);
        if regular {
            // dᵀ M⁻¹ d = ‖L⁻¹ d‖².
            let y0 = l
                .solve_lower_triangular(&d0)
                .unwrap_or_else(|| Vector6::repeat(f64::INFINITY));
            let y1 = l
                .solve_lower_triangular(&d1)
                .unwrap_or_else(|| Vector6::repeat(f64::INFINITY));
            return EllipsoidTest {
                closure_value: y0.norm_squared(),
                wrench_value: y1.norm_squared(),
                contacts,
                degenerate: false,
            };
        }
    }
    // Flat wrench set: never force closure; a wrench may still lie in it.
    EllipsoidTest {
        closure_value: f64::INFINITY,
        wrench_value: pseudo_quadratic(&m, &d1),
        contacts,
        degenerate: true,
    }
}

/// `dᵀ M⁺ d` if `d` lies in the range of the singular PSD `M`, else `+∞`.
fn pseudo_quadratic(m: &Matrix6<f64>, d: &Vector6<f64>) -> f64 {
    let eig = SymmetricEigen::new(*m);
    let largest = eig.eigenvalues.iter().fold(0.0_f64, |a, &b| a.max(b.abs()));
    if largest <= 0.0 {
        return if d.norm() == 0.0 { 0.0 } else { f64::INFINITY };
    }
    let tol = SINGULAR_PIVOT * largest;
    let scale = d.norm().max(f64::MIN_POSITIVE);
    let mut value = 0.0;
    for k in 0..6 {
        let proj = eig.eigenvectors.column(k).dot(d);
        if eig.eigenvalues[k] > tol {
            value += proj * proj / eig.eigenvalues[k];
        } else if proj.abs() > 1e-9 * scale {
            return f64::INFINITY;
        }
    }
    value
}

/// Eq. (10) for `grasp` with one ellipsoid model on every contact, at `w = 0`
/// (force closure) and at `w = −external` (holding against `external`, e.g.
/// the weight wrench). Allocation-free; about 0.3 µs for four contacts.
pub fn ellipsoid_test(grasp: &Grasp, model: &EllipsoidModel, external: &Wrench) -> EllipsoidTest {
    let mut m = Matrix6::zeros();
    let mut w0 = Vector6::zeros();
    for (contact, &f_max) in grasp.contacts().iter().zip(grasp.force_limits()) {
        let (mi, wi) = contact_terms(contact, f_max, grasp, model);
        m += mi;
        w0 += wi;
    }
    evaluate(m, &w0, &(-external), grasp.len())
}

/// The left-hand side of eq. (10), `f(p_1..p_n)`, for the wrench `w` the
/// contact forces must produce (`+∞` outside a degenerate set).
pub fn ellipsoid_value(grasp: &Grasp, model: &EllipsoidModel, w: &Wrench) -> f64 {
    ellipsoid_test(grasp, model, &(-w)).wrench_value
}

/// Result of [`multi_ellipsoid_test`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MultiEllipsoidTest {
    /// Largest `f` over all combinations (smallest margins): "every combination must pass".
    pub worst: EllipsoidTest,
    /// Smallest `f` over all combinations: "some combination passes".
    pub best: EllipsoidTest,
    /// Number of combinations evaluated, `k^n`.
    pub combinations: u64,
}

/// Eq. (10) for every combination of one ellipsoid per contact out of
/// `models` (`k^n` Cholesky factorisations; refused above `max_combinations`).
pub fn multi_ellipsoid_test(
    grasp: &Grasp,
    models: &[EllipsoidModel],
    external: &Wrench,
    max_combinations: u64,
) -> Result<MultiEllipsoidTest, EllipsoidError> {
    if models.is_empty() {
        return Err(EllipsoidError::NoModels);
    }
    for m in models {
        m.validate()?;
    }
    let k = models.len();
    let n = grasp.len();
    let combinations = (0..n)
        .try_fold(1_u64, |acc, _| acc.checked_mul(k as u64))
        .filter(|&c| c <= max_combinations)
        .ok_or(EllipsoidError::TooManyCombinations {
            models: k,
            contacts: n,
            limit: max_combinations,
        })?;
    // Per contact and model: (G_i Q G_iᵀ, c G_i n_i), row-major by contact.
    let terms: Vec<(Matrix6<f64>, Vector6<f64>)> = grasp
        .contacts()
        .iter()
        .zip(grasp.force_limits())
        .flat_map(|(c, &f)| models.iter().map(move |m| contact_terms(c, f, grasp, m)))
        .collect();
    let w = -external;
    let mut digits = vec![0_usize; n];
    let mut worst: Option<EllipsoidTest> = None;
    let mut best: Option<EllipsoidTest> = None;
    for _ in 0..combinations {
        let mut m = Matrix6::zeros();
        let mut w0 = Vector6::zeros();
        for (i, &d) in digits.iter().enumerate() {
            let (mi, wi) = &terms[i * k + d];
            m += mi;
            w0 += wi;
        }
        let t = evaluate(m, &w0, &w, n);
        worst = Some(match worst {
            None => t,
            Some(a) => EllipsoidTest {
                closure_value: a.closure_value.max(t.closure_value),
                wrench_value: a.wrench_value.max(t.wrench_value),
                contacts: n,
                degenerate: a.degenerate || t.degenerate,
            },
        });
        best = Some(match best {
            None => t,
            Some(a) => EllipsoidTest {
                closure_value: a.closure_value.min(t.closure_value),
                wrench_value: a.wrench_value.min(t.wrench_value),
                contacts: n,
                degenerate: a.degenerate && t.degenerate,
            },
        });
        // Next combination (mixed-radix counter).
        for d in digits.iter_mut() {
            *d += 1;
            if *d < k {
                break;
            }
            *d = 0;
        }
    }
    // `combinations ≥ 1`, so both are set.
    match (worst, best) {
        (Some(worst), Some(best)) => Ok(MultiEllipsoidTest {
            worst,
            best,
            combinations,
        }),
        _ => Err(EllipsoidError::NoModels),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    fn contact(p: [f64; 3], n: [f64; 3]) -> Contact {
        Contact::new(Point3::from(p), Vector3::from(n).normalize()).unwrap()
    }

    #[test]
    fn default_ellipsoid_lies_inside_cone_and_bound() {
        let c = contact([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
        let model = EllipsoidModel::default();
        let (mu, f_max) = (0.4, 10.0);
        let (centre, a, b) = model.axes(mu, f_max);
        assert!((centre + b - f_max).abs() < 1e-12);
        // Sample the ellipsoid's surface and check the cone and the bound.
        for i in 0..64 {
            for j in 0..33 {
                let th = i as f64 / 64.0 * std::f64::consts::TAU;
                let ph = j as f64 / 32.0 * std::f64::consts::PI;
                let f = Vector3::new(
                    a * ph.sin() * th.cos(),
                    a * ph.sin() * th.sin(),
                    centre + b * ph.cos(),
                );
                let towards_centre = Vector3::new(0.0, 0.0, centre)
                    + (f - Vector3::new(0.0, 0.0, centre)) * (1.0 - 1e-9);
                assert!(model.contains(&c, mu, f_max, &towards_centre));
                assert!(f.xy().norm() <= mu * f.z + 1e-9, "outside the cone at {f}");
                assert!(f.z <= f_max + 1e-9);
            }
        }
        // A larger alpha pokes out of the cone.
        let fat = EllipsoidModel::inscribed(0.9);
        let (centre, a, b) = fat.axes(mu, f_max);
        let z = -1.0 / (1.0 + 1.0 / (2.0 * 0.81)); // the tangency height for α = 0.9
        let f = Vector3::new(
            a * (1.0 - z * z * centre * centre / (b * b)).sqrt(),
            0.0,
            centre * (1.0 + z),
        );
        assert!(f.xy().norm() > mu * f.z);
    }

    #[test]
    fn shape_matrix_is_the_inverse_of_eq_9() {
        let c = contact([0.1, 0.2, 0.3], [1.0, -2.0, 0.5]);
        let m = EllipsoidModel::paper(0.6);
        let q = m.shape_matrix(c.normal(), 0.7, 3.0);
        let s = m.weight_matrix(&c, 0.7, 3.0);
        assert!((q * s - Matrix3::identity()).norm() < 1e-9);
    }

    #[test]
    fn value_does_not_depend_on_reference_or_torque_scale() {
        let cs = vec![
            contact([0.03, 0.0, 0.01], [-1.0, 0.1, 0.0]),
            contact([-0.02, 0.03, 0.0], [0.5, -1.0, 0.0]),
            contact([-0.02, -0.03, -0.01], [0.5, 1.0, 0.2]),
        ];
        let g1 = Grasp::new(cs.clone(), 0.5, 10.0, 0.05, Point3::origin()).unwrap();
        let g2 = Grasp::new(cs, 0.5, 10.0, 0.2, Point3::new(0.01, -0.02, 0.05)).unwrap();
        let m = EllipsoidModel::default();
        let weight = Vector3::new(0.0, 0.0, -1.0);
        let com = Point3::new(0.0, 0.0, 0.01);
        let t1 = ellipsoid_test(&g1, &m, &g1.weight_wrench(0.2, &weight, &com));
        let t2 = ellipsoid_test(&g2, &m, &g2.weight_wrench(0.2, &weight, &com));
        assert!((t1.closure_value - t2.closure_value).abs() < 1e-9 * t1.closure_value.max(1.0));
        assert!((t1.wrench_value - t2.wrench_value).abs() < 1e-9 * t1.wrench_value.max(1.0));
    }

    #[test]
    fn single_model_multi_test_equals_single_test() {
        let cs = vec![
            contact([0.03, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            contact([-0.015, 0.026, 0.0], [0.5, -0.866, 0.0]),
            contact([-0.015, -0.026, 0.0], [0.5, 0.866, 0.0]),
        ];
        let g = Grasp::new(cs, 0.5, 10.0, 0.03, Point3::origin()).unwrap();
        let m = EllipsoidModel::default();
        let w = Wrench::new(0.0, 0.0, -2.0, 0.0, 0.0, 0.0);
        let single = ellipsoid_test(&g, &m, &w);
        let multi = multi_ellipsoid_test(&g, &[m], &w, 10).unwrap();
        assert_eq!(multi.combinations, 1);
        assert_eq!(multi.worst, single);
        let two = multi_ellipsoid_test(&g, &[m, m.scaled(0.5)], &w, 10).unwrap();
        assert_eq!(two.combinations, 8);
        assert!(two.worst.margin() <= single.margin() && two.best.margin() >= two.worst.margin());
        assert!(matches!(
            multi_ellipsoid_test(&g, &[m, m], &w, 7),
            Err(EllipsoidError::TooManyCombinations { .. })
        ));
    }
}
