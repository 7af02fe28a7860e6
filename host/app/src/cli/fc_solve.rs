//! The output side of `tsukami fc`: runs the requested methods of the grasp
//! crate on one [`Problem`] and returns serde structs whose JSON is the contract.
//!
//! # Result
//!
//! ```json
//! {"ellipsoid": {"force_closure": bool, "resists_weight": bool, "margin": f64, "time_ns": u64, …},
//!  "exact": {"force_closure": bool, "resists_weight": bool, "weight_scale": f64,
//!            "forces": [[fx,fy,fz], …], "time_ns": u64, …},
//!  "ferrari_canny": {"epsilon_l1": f64, "epsilon_linf": f64, "time_ns": u64, …}}
//! ```
//!
//! Only the requested methods appear. `margin` is the paper's `n − f` at the
//! weight (the posture is accepted when `margin ≥ δf`); `closure_margin` is
//! `n − f(0)`. A degenerate (flat) ellipsoid gives an infinite `f`; JSON has
//! no infinities, so infinite values are written as `±1.7976931348623157e308`
//! (`±f64::MAX`). `epsilon_linf` is `null`, with `linf_error` saying why, when
//! the L∞ Minkowski sum exceeds the point limit. `time_ns` is measured around
//! that method's call alone.

use std::time::Instant;

use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize, Serializer};
use tsukami_grasp::ellipsoid::{ellipsoid_test, multi_ellipsoid_test};
use tsukami_grasp::exact::{exact_test, ConeModel};
use tsukami_grasp::ferrari_canny::{epsilon_l1, epsilon_linf, FerrariCannyOptions};
use tsukami_grasp::grasp::Grasp;
use tsukami_grasp::grasp_matrix::Wrench;

use super::fc_problem::{ExactCone, Method, Problem, ProblemError};

/// Most ellipsoid combinations (`k^n`) one problem may ask for.
pub const MAX_ELLIPSOID_COMBINATIONS: u64 = 1 << 20;

/// Writes non-finite numbers as `±f64::MAX` (JSON has no infinities).
fn finite_f64<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    let y = if x.is_nan() {
        f64::MIN
    } else {
        x.clamp(f64::MIN, f64::MAX)
    };
    s.serialize_f64(y)
}

/// Ellipsoid test result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EllipsoidResult {
    /// `n − f(0) > δf` with a non-degenerate wrench set.
    pub force_closure: bool,
    /// `n − f(−w_weight) ≥ δf`.
    pub resists_weight: bool,
    /// `n − f(−w_weight)`, the paper's margin (worst combination with several ellipsoids).
    #[serde(serialize_with = "finite_f64")]
    pub margin: f64,
    /// `n − f(0)`.
    #[serde(serialize_with = "finite_f64")]
    pub closure_margin: f64,
    /// With several ellipsoids per cone: the best combination's weight margin.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub best_margin: Option<f64>,
    /// Number of ellipsoid combinations evaluated (`k^n`).
    pub combinations: u64,
    /// `G U⁻¹ Gᵀ` was singular for some combination.
    pub degenerate: bool,
    /// Time of this method's call (ns).
    pub time_ns: u64,
}

/// Exact method result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExactResult {
    /// Exact force closure.
    pub force_closure: bool,
    /// `weight_scale ≥ 1`.
    pub resists_weight: bool,
    /// Largest multiple of the weight the grasp balances.
    pub weight_scale: f64,
    /// Contact forces (world, N) balancing `weight_scale` × the weight.
    pub forces: Vec<[f64; 3]>,
    /// Internal squeeze margin `τ*` (N).
    pub squeeze_margin: f64,
    /// Numerical rank of `G`.
    pub grasp_rank: usize,
    /// Time of this method's call (ns).
    pub time_ns: u64,
}

/// Ferrari–Canny result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FerrariCannyResult {
    /// ε of the L1 wrench space (N).
    pub epsilon_l1: f64,
    /// ε of the L∞ wrench space (N); `null` when over the size limit.
    pub epsilon_linf: Option<f64>,
    /// Why `epsilon_linf` is missing.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub linf_error: Option<String>,
    /// Pyramid sides used.
    pub cone_sides: usize,
    /// Time of this method's call (ns).
    pub time_ns: u64,
}

/// One problem's answer: one entry per requested method.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ProblemResult {
    /// Ellipsoid test, if requested.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub ellipsoid: Option<EllipsoidResult>,
    /// Exact method, if requested.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub exact: Option<ExactResult>,
    /// Ferrari–Canny ε, if requested.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub ferrari_canny: Option<FerrariCannyResult>,
}

fn elapsed_ns(t: Instant) -> u64 {
    u64::try_from(t.elapsed().as_nanos()).unwrap_or(u64::MAX)
}

/// Runs the requested methods on one problem.
pub fn solve_problem(problem: &Problem) -> Result<ProblemResult, ProblemError> {
    let grasp = problem.grasp()?;
    let weight = grasp.weight_wrench(
        problem.mass,
        &Vector3::from(problem.gravity),
        &Point3::from(problem.center_of_mass),
    );
    let mut out = ProblemResult::default();
    for method in &problem.methods {
        match method {
            Method::Ellipsoid => out.ellipsoid = Some(run_ellipsoid(problem, &grasp, &weight)?),
            Method::Exact => out.exact = Some(run_exact(problem, &grasp, &weight)?),
            Method::FerrariCanny => out.ferrari_canny = Some(run_ferrari_canny(problem, &grasp)?),
        }
    }
    Ok(out)
}

/// The paper's test, eqs. (9)–(10): one ellipsoid per cone, or every combination.
fn run_ellipsoid(
    problem: &Problem,
    grasp: &Grasp,
    weight: &Wrench,
) -> Result<EllipsoidResult, ProblemError> {
    let models = problem.ellipsoid_models();
    let delta_f = problem.delta_f;
    if let [model] = models.as_slice() {
        let t0 = Instant::now();
        let t = ellipsoid_test(grasp, model, weight);
        let time_ns = elapsed_ns(t0);
        return Ok(EllipsoidResult {
            force_closure: t.force_closure(delta_f),
            resists_weight: t.resists(delta_f),
            margin: t.margin(),
            closure_margin: t.closure_margin(),
            best_margin: None,
            combinations: 1,
            degenerate: t.degenerate,
            time_ns,
        });
    }
    let t0 = Instant::now();
    let t =
        multi_ellipsoid_test(grasp, &models, weight, MAX_ELLIPSOID_COMBINATIONS).map_err(|e| {
            ProblemError::MethodFailed {
                method: "ellipsoid",
                message: e.to_string(),
            }
        })?;
    let time_ns = elapsed_ns(t0);
    Ok(EllipsoidResult {
        force_closure: t.worst.force_closure(delta_f),
        resists_weight: t.worst.resists(delta_f),
        margin: t.worst.margin(),
        closure_margin: t.worst.closure_margin(),
        best_margin: Some(t.best.margin()).filter(|m| m.is_finite()),
        combinations: t.combinations,
        degenerate: t.worst.degenerate,
        time_ns,
    })
}

/// The conic reference: closure, weight multiple and forces.
fn run_exact(
    problem: &Problem,
    grasp: &Grasp,
    weight: &Wrench,
) -> Result<ExactResult, ProblemError> {
    let cone = match problem.exact_cone {
        ExactCone::Circular => ConeModel::Circular,
        ExactCone::Polyhedral => ConeModel::Polyhedral {
            sides: problem.cone_sides,
        },
    };
    let t0 = Instant::now();
    let t = exact_test(grasp, cone, weight).map_err(|e| ProblemError::MethodFailed {
        method: "exact",
        message: e.to_string(),
    })?;
    let time_ns = elapsed_ns(t0);
    Ok(ExactResult {
        force_closure: t.closure.force_closure,
        resists_weight: t.resists_weight(),
        weight_scale: t.weight.weight_scale,
        forces: t.weight.forces.iter().map(|f| [f.x, f.y, f.z]).collect(),
        squeeze_margin: t.closure.squeeze_margin,
        grasp_rank: t.closure.grasp_rank,
        time_ns,
    })
}

/// Ferrari–Canny ε_L1 and ε_L∞ (eqs. (7)–(8)); ε_L∞ may be over its size limit.
fn run_ferrari_canny(problem: &Problem, grasp: &Grasp) -> Result<FerrariCannyResult, ProblemError> {
    let options = FerrariCannyOptions {
        sides: problem.cone_sides,
        ..FerrariCannyOptions::default()
    };
    let t0 = Instant::now();
    let l1 = epsilon_l1(grasp, options.sides);
    let linf = epsilon_linf(grasp, &options);
    let time_ns = elapsed_ns(t0);
    let epsilon_l1 = l1.map_err(|e| ProblemError::MethodFailed {
        method: "ferrari_canny",
        message: e.to_string(),
    })?;
    let (epsilon_linf, linf_error) = match linf {
        Ok(e) => (Some(e), None),
        Err(e) => (None, Some(e.to_string())),
    };
    Ok(FerrariCannyResult {
        epsilon_l1,
        epsilon_linf,
        linf_error,
        cone_sides: options.sides,
        time_ns,
    })
}
