//! The exact reference: force closure and the weight test as conic programs
//! (solved with `clarabel`), with exact friction cones and force limits.
//!
//! # Contact model
//!
//! Each contact force, in its contact frame `f = U_i [f_t1, f_t2, f_n]`, obeys
//!
//! * Coulomb friction, exactly: `‖(f_t1, f_t2)‖ ≤ μ f_n` (a second-order cone),
//!   or with [`ConeModel::Polyhedral`] the `k`-sided pyramid inscribed in it
//!   (edges on the circular cone, `k` facets at distance `μ cos(π/k) f_n`) —
//!   the same pyramid [`crate::ferrari_canny`] uses, to compare like with like;
//! * the force limit `f_n ≤ f_max,i` on the **normal component** — "|f| bounded by
//!   f_max along the normal" in the contract. This is the model a finger's joint
//!   torques give (they bound the force it presses with), it is what the
//!   Ferrari–Canny pyramid with edges of normal component `f_max` describes, and
//!   it keeps the force set a truncated cone. (`‖f‖ ≤ f_max` would be the
//!   alternative; it is not used.)
//!
//! # Force closure
//!
//! Force closure — every wrench can be resisted, `G(K) = R⁶` — holds exactly
//! when `G` has rank 6 and some internal force (`G f = 0`) lies strictly inside
//! every cone (Murray, Li & Sastry, *A Mathematical Introduction to Robotic
//! Manipulation*, Prop. 5.2). Proof sketch: with such an `f₀`, `G` maps the open
//! set `int K` around `f₀` onto an open set around `0`, and a cone that contains
//! a neighbourhood of 0 is everything; conversely take `f₁ ∈ int K`, balance
//! `−G f₁` with some `f₂ ∈ K`, and `f₁ + f₂ ∈ int K` is internal. So one small
//! conic program decides it exactly:
//!
//! ```text
//! maximise τ  s.t.  Σ G_i U_i f_i = 0,  ‖f_t,i‖ ≤ μ f_n,i − τ,  f_n,i ≤ f_max,i
//! ```
//!
//! plus a rank test of `G Gᵀ` (6×6 eigenvalues). Closure is `τ* > 0` and rank 6.
//! `τ*` (newtons) — how far inside its cone every finger can squeeze — is
//! returned as [`ExactClosure::squeeze_margin`]. This was preferred to
//! "largest ball of wrenches resistible": containment of a ball in a Minkowski
//! sum of cones is a min–max over directions, not one convex program, and the
//! 12-direction (±e_k) variant needs 12 copies of the variables for the same
//! yes/no answer.
//!
//! # Holding the weight
//!
//! ```text
//! maximise s  s.t.  Σ G_i U_i f_i + s·w_ext = 0,  ‖f_t,i‖ ≤ μ f_n,i,  f_n,i ≤ f_max,i
//! ```
//!
//! `s*` is the largest multiple of the external wrench (the weight at the centre
//! of mass) the grasp can balance; the forces that do it are returned in the
//! world frame. The weight is resisted when `s* ≥ 1`.
//!
//! Both programs have `3n + 1` variables; clarabel solves them in a few tens of
//! iterations (see the bench `force_closure`).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{Matrix6, SymmetricEigen, Vector3};

use crate::grasp::Grasp;
use crate::grasp_matrix::{contact_block, Wrench};
use crate::joint_torques::JointTorques;

/// Smallest eigenvalue of `G Gᵀ` relative to its largest for `G` to count as rank 6.
pub const RANK_TOLERANCE: f64 = 1e-12;

/// Relative squeeze margin `τ*/(μ·min f_max)` above which the conic solution
/// counts as strictly inside the cones (clarabel's accuracy is ~1e-8).
pub const SQUEEZE_TOLERANCE: f64 = 1e-7;

/// The friction cone model of the exact method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ConeModel {
    /// The exact Coulomb cone `‖f_t‖ ≤ μ f_n` (second-order cone).
    #[default]
    Circular,
    /// The pyramid with `sides` edges inscribed in the Coulomb cone (linear constraints).
    Polyhedral {
        /// Number of edges, ≥ 3.
        sides: usize,
    },
}

/// Why the exact method failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExactError {
    /// A polyhedral cone needs at least three sides.
    #[error("a polyhedral friction cone needs at least 3 sides, got {0}")]
    TooFewSides(usize),
    /// The external wrench is not finite.
    #[error("the external wrench has a non-finite component")]
    BadWrench,
    /// The solver could not be set up.
    #[error("conic solver setup failed: {0}")]
    Setup(String),
    /// The solver stopped without a solution.
    #[error("conic solver stopped with status {0}")]
    Solver(String),
}

/// Exact force-closure decision.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactClosure {
    /// `G` has rank 6 and some internal force lies strictly inside every cone.
    pub force_closure: bool,
    /// `τ*` (N): how far inside its cone every contact force can be while the
    /// forces balance each other. `≤ 0` when no internal squeeze exists.
    pub squeeze_margin: f64,
    /// Numerical rank of `G` (0–6).
    pub grasp_rank: usize,
    /// The internal forces (world frame, N) of the squeeze `τ*`: they balance
    /// each other (`G f = 0`).
    pub forces: Vec<Vector3<f64>>,
}

/// Exact weight test.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactWeight {
    /// Largest `s` with `G f + s·w_ext = 0` feasible (`≥ 0`).
    pub weight_scale: f64,
    /// Contact forces (world frame, N) balancing `weight_scale · w_ext`.
    pub forces: Vec<Vector3<f64>>,
    /// The program's dual for the balance rows: a wrench-space direction `y`
    /// whose [`weight_scale_bound`] is `weight_scale` for this grasp, and an
    /// upper bound of it for any other (a nearby grasp's is often tight).
    pub certificate: Wrench,
}

/// Both exact answers for one grasp.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactTest {
    /// Force closure.
    pub closure: ExactClosure,
    /// Weight scale and forces.
    pub weight: ExactWeight,
}

impl ExactTest {
    /// Whether the external wrench itself (scale 1) can be balanced.
    pub fn resists_weight(&self) -> bool {
        self.weight.weight_scale >= 1.0
    }
}

/// Numerical rank of `G` from the eigenvalues of the 6×6 `G Gᵀ`.
pub fn grasp_rank(grasp: &Grasp) -> usize {
    let mut ggt = Matrix6::zeros();
    for c in grasp.contacts() {
        let g = contact_block(c, grasp.reference(), grasp.torque_scale());
        ggt += g * g.transpose();
    }
    let eig = SymmetricEigen::new(ggt).eigenvalues;
    let largest = eig.max();
    eig.iter()
        .filter(|&&l| l > RANK_TOLERANCE * largest)
        .count()
}

/// Which extra scalar variable the program maximises.
enum Extra<'a> {
    /// `τ`, subtracted from every cone constraint (force closure).
    Squeeze,
    /// `s`, multiplying the external wrench in the balance (weight test).
    Scale(&'a Wrench),
}

/// Builds and solves one of the two programs; returns `(x, extra*)`.
fn solve(
    grasp: &Grasp,
    cone: ConeModel,
    extra: Extra<'_>,
    joints: Option<&JointTorques>,
) -> Result<(Vec<f64>, f64, Wrench), ExactError> {
    let n = grasp.len();
    let nv = 3 * n + 1;
    let xe = 3 * n; // index of the extra variable
    let mu = grasp.mu();
    let (mut ri, mut ci, mut vals) = (Vec::new(), Vec::new(), Vec::new());
    let mut b = Vec::new();
    let mut cones = Vec::new();
    let mut row = 0;
    let push = |r: usize,
                c: usize,
                v: f64,
                ri: &mut Vec<usize>,
                ci: &mut Vec<usize>,
                vals: &mut Vec<f64>| {
        if v != 0.0 {
            ri.push(r);
            ci.push(c);
            vals.push(v);
        }
    };

    // Balance: Σ G_i U_i f_i (+ s w_ext) = 0  (slack in the zero cone).
    for (i, c) in grasp.contacts().iter().enumerate() {
        let gu = contact_block(c, grasp.reference(), grasp.torque_scale()) * c.frame();
        for r in 0..6 {
            for k in 0..3 {
                push(row + r, 3 * i + k, gu[(r, k)], &mut ri, &mut ci, &mut vals);
            }
        }
    }
    if let Extra::Scale(w) = extra {
        for r in 0..6 {
            push(row + r, xe, w[r], &mut ri, &mut ci, &mut vals);
        }
    }
    b.extend([0.0; 6]);
    cones.push(SupportedConeT::ZeroConeT(6));
    row += 6;

    // Force limits: f_max,i − f_n,i ≥ 0.
    for (i, &f_max) in grasp.force_limits().iter().enumerate() {
        push(row + i, 3 * i + 2, 1.0, &mut ri, &mut ci, &mut vals);
        b.push(f_max);
    }
    cones.push(SupportedConeT::NonnegativeConeT(n));
    row += n;

    // Joint torques: τ_max,j ∓ Σ_i (J_iᵀ U_i f_i)_j ≥ 0 (both signs).
    if let Some(t) = joints {
        if t.contacts() != n {
            return Err(ExactError::Setup(format!(
                "joint torque limits for {} contacts, the grasp has {n}",
                t.contacts()
            )));
        }
        let m = t.joints();
        for (i, c) in grasp.contacts().iter().enumerate() {
            let rows = t.rows(i, &c.frame());
            for j in 0..m {
                for k in 0..3 {
                    push(
                        row + j,
                        3 * i + k,
                        rows[(k, j)],
                        &mut ri,
                        &mut ci,
                        &mut vals,
                    );
                    push(
                        row + m + j,
                        3 * i + k,
                        -rows[(k, j)],
                        &mut ri,
                        &mut ci,
                        &mut vals,
                    );
                }
            }
        }
        b.extend(t.efforts().iter().chain(t.efforts()));
        cones.push(SupportedConeT::NonnegativeConeT(2 * m));
        row += 2 * m;
    }

    // Friction: slack = b − A x inside the cone; τ enters with +1 in A.
    let squeeze = matches!(extra, Extra::Squeeze);
    match cone {
        ConeModel::Circular => {
            for i in 0..n {
                // (μ f_n − τ, f_t1, f_t2) ∈ SOC₃
                push(row, 3 * i + 2, -mu, &mut ri, &mut ci, &mut vals);
                if squeeze {
                    push(row, xe, 1.0, &mut ri, &mut ci, &mut vals);
                }
                push(row + 1, 3 * i, -1.0, &mut ri, &mut ci, &mut vals);
                push(row + 2, 3 * i + 1, -1.0, &mut ri, &mut ci, &mut vals);
                b.extend([0.0; 3]);
                cones.push(SupportedConeT::SecondOrderConeT(3));
                row += 3;
            }
        }
        ConeModel::Polyhedral { sides } => {
            if sides < 3 {
                return Err(ExactError::TooFewSides(sides));
            }
            let half = std::f64::consts::PI / sides as f64;
            let reach = mu * half.cos();
            for i in 0..n {
                for j in 0..sides {
                    // Facet between edges j and j+1: its outward normal is at angle θ_j + π/k.
                    let phi = 2.0 * half * j as f64 + half;
                    // μ cos(π/k) f_n − (cos φ f_t1 + sin φ f_t2) − τ ≥ 0
                    push(row, 3 * i, phi.cos(), &mut ri, &mut ci, &mut vals);
                    push(row, 3 * i + 1, phi.sin(), &mut ri, &mut ci, &mut vals);
                    push(row, 3 * i + 2, -reach, &mut ri, &mut ci, &mut vals);
                    if squeeze {
                        push(row, xe, 1.0, &mut ri, &mut ci, &mut vals);
                    }
                    b.push(0.0);
                    row += 1;
                }
            }
            cones.push(SupportedConeT::NonnegativeConeT(n * sides));
        }
    }

    let a = CscMatrix::new_from_triplets(row, nv, ri, ci, vals);
    // Without iterative refinement first (a quarter faster; the solver's
    // stopping test is on the true residuals, so a `Solved` answer meets the
    // same tolerances); anything short of `Solved` is solved again with it.
    let fast = run_clarabel(&a, &b, &cones, xe, false)?;
    match fast {
        Some(answer) => Ok(answer),
        None => run_clarabel(&a, &b, &cones, xe, true)?
            .ok_or_else(|| ExactError::Solver("AlmostSolved".into())),
    }
}

/// Maximises variable `xe` subject to `b − A x ∈ cones`: `(x, x[xe], the
/// balance rows' dual)`; `None` when the solver is only `AlmostSolved` and
/// a refined solve should be tried (or, with `refine`, is accepted as is).
fn run_clarabel(
    a: &CscMatrix<f64>,
    b: &[f64],
    cones: &[SupportedConeT<f64>],
    xe: usize,
    refine: bool,
) -> Result<Option<(Vec<f64>, f64, Wrench)>, ExactError> {
    let nv = a.n;
    let p = CscMatrix::zeros((nv, nv));
    let mut q = vec![0.0; nv];
    q[xe] = -1.0;
    let settings = DefaultSettings {
        verbose: false,
        iterative_refinement_enable: refine,
        ..DefaultSettings::default()
    };
    let mut solver = DefaultSolver::new(&p, &q, a, b, cones, settings)
        .map_err(|e| ExactError::Setup(e.to_string()))?;
    solver.solve();
    let answer = || {
        let x = solver.solution.x.clone();
        let z = &solver.solution.z;
        let dual = Wrench::from_fn(|r, _| z[r]);
        (x[xe], dual, x)
    };
    match (solver.solution.status, refine) {
        (SolverStatus::Solved, _) | (SolverStatus::AlmostSolved, true) => {
            let (e, dual, x) = answer();
            Ok(Some((x, e, dual)))
        }
        (_, false) => Ok(None),
        (other, true) => Err(ExactError::Solver(format!("{other:?}"))),
    }
}

/// Exact force closure with cone model `cone` (see the module docs).
pub fn exact_force_closure(grasp: &Grasp, cone: ConeModel) -> Result<ExactClosure, ExactError> {
    exact_force_closure_with(grasp, cone, None)
}

/// [`exact_force_closure`] with the internal forces also limited by the
/// joints' torques (`joints`; [`crate::joint_torques`]): the largest squeeze
/// the hand can make, and its forces.
pub fn exact_force_closure_with(
    grasp: &Grasp,
    cone: ConeModel,
    joints: Option<&JointTorques>,
) -> Result<ExactClosure, ExactError> {
    let grasp_rank = grasp_rank(grasp);
    let (x, tau, _) = solve(grasp, cone, Extra::Squeeze, joints)?;
    let f_min = grasp
        .force_limits()
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let force_closure = grasp_rank == 6 && tau > SQUEEZE_TOLERANCE * grasp.mu() * f_min;
    Ok(ExactClosure {
        force_closure,
        squeeze_margin: tau,
        grasp_rank,
        forces: world_forces(grasp, &x),
    })
}

/// The world-frame contact forces of a solution `x` (local components).
fn world_forces(grasp: &Grasp, x: &[f64]) -> Vec<Vector3<f64>> {
    grasp
        .contacts()
        .iter()
        .enumerate()
        .map(|(i, c)| c.frame() * Vector3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]))
        .collect()
}

/// The largest multiple of `external` (e.g. the weight wrench) the grasp can
/// balance with cone model `cone`, and the world-frame contact forces doing it.
pub fn exact_weight_scale(
    grasp: &Grasp,
    cone: ConeModel,
    external: &Wrench,
) -> Result<ExactWeight, ExactError> {
    exact_weight_scale_with(grasp, cone, external, None)
}

/// [`exact_weight_scale`] with the contact forces also limited by the joints'
/// torques (`joints`; [`crate::joint_torques`]).
pub fn exact_weight_scale_with(
    grasp: &Grasp,
    cone: ConeModel,
    external: &Wrench,
    joints: Option<&JointTorques>,
) -> Result<ExactWeight, ExactError> {
    if !external.iter().all(|x| x.is_finite()) {
        return Err(ExactError::BadWrench);
    }
    let (x, s, certificate) = solve(grasp, cone, Extra::Scale(external), joints)?;
    let forces = world_forces(grasp, &x);
    Ok(ExactWeight {
        weight_scale: s.max(0.0),
        forces,
        certificate,
    })
}

/// An upper bound of [`exact_weight_scale`]'s `s*` (circular cones, or the
/// pyramids inscribed in them) from any wrench-space direction `y`, in a few
/// flops: weak duality. The balance `Σ G_i f_i = −s·w` gives
/// `s·(−y·w) = Σ y·G_i f_i ≤ Σ h_i(y)`, where `h_i(y) = f_max,i (g_n +
/// μ‖g_t‖)⁺` with `g = (G_i U_i)ᵀ y` is the most contact `i`'s truncated cone
/// can push along `y`; `y` and `−y` are both tried. With the certificate of a
/// nearby grasp ([`ExactWeight::certificate`]) the bound is often tight, so a
/// search rejects most grasps that cannot hold the weight without solving
/// the conic program. `+∞` when neither sign of `y` opposes `w`.
pub fn weight_scale_bound(grasp: &Grasp, external: &Wrench, y: &Wrench) -> f64 {
    let mu = grasp.mu();
    let mut push = [0.0f64; 2];
    for (c, &f_max) in grasp.contacts().iter().zip(grasp.force_limits()) {
        let gu = contact_block(c, grasp.reference(), grasp.torque_scale()) * c.frame();
        let g = gu.transpose() * y;
        let tangential = g[0].hypot(g[1]);
        push[0] += f_max * (g[2] + mu * tangential).max(0.0);
        push[1] += f_max * (-g[2] + mu * tangential).max(0.0);
    }
    let yw = y.dot(external);
    match yw {
        _ if yw < 0.0 => push[0] / -yw,
        _ if yw > 0.0 => push[1] / yw,
        _ => f64::INFINITY,
    }
}

/// Both exact programs for one grasp.
pub fn exact_test(
    grasp: &Grasp,
    cone: ConeModel,
    external: &Wrench,
) -> Result<ExactTest, ExactError> {
    Ok(ExactTest {
        closure: exact_force_closure(grasp, cone)?,
        weight: exact_weight_scale(grasp, cone, external)?,
    })
}
