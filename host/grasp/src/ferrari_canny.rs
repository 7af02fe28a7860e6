//! Ferrari–Canny grasp quality ε for the L1 and L∞ grasp wrench spaces,
//! eqs. (7)–(8), with `k`-sided polyhedral friction cones and 6-D convex
//! hulls ([`crate::hull`]: the vendored Qhull, built with a C compiler only).
//!
//! Each friction cone is replaced by the pyramid inscribed in it with `k`
//! edges `d_ij = f_max,i (n_i + μ (cos θ_j t1 + sin θ_j t2))`, `θ_j = 2πj/k`:
//! every edge has normal component `f_max,i`, the exact method's force limit
//! ([`crate::exact`] with [`crate::exact::ConeModel::Polyhedral`] uses the same
//! pyramid). The primitive wrenches are `w_ij = G_i d_ij` (eq. (6)).
//!
//! * **L1** (eq. (8)): `W_L1 = conv(∪_ij w_ij)` — total normal force at most
//!   `f_max`. One hull of `n·k` points.
//! * **L∞** (eq. (7)): `W_L∞ = ⊕_i conv({0} ∪ {w_ij}_j)` — every finger's
//!   normal force in `[0, f_max,i]` independently. Ferrari and Canny write the
//!   Minkowski sum of the edge sets alone, which fixes every finger at full
//!   force; including the origin matches the bound `f_n ≤ f_max` of the other
//!   methods, and only then does `ε_L∞ > 0` coincide with force closure.
//!
//! `ε` is the radius of the largest origin-centred ball inside the GWS, the
//! smallest distance from the origin to a hull facet; `0` when the origin is
//! not strictly inside (no force closure) or the hull is flat (fewer than six
//! independent wrenches). It depends on `γ` and on the reference point, like
//! any Euclidean distance in wrench space; units are newtons.
//!
//! **Cost of L∞.** The Minkowski sum has up to `(k+1)^n` candidate points. The
//! sum is built one contact at a time and pruned to its hull's vertices after
//! each addition (a vertex of `A ⊕ B` is a sum of vertices of `A` and `B`), which
//! is exact and keeps each step to a hull of `|V|·(k+1)` points; `|V|` still
//! grows (polynomially in `n` for fixed `k`, but fast in 6-D), so the method
//! refuses sets over [`FerrariCannyOptions::max_points`] candidates rather than
//! run for minutes. Measured figures are in `docs/force-closure.md`.

use nalgebra::Vector6;

use crate::exact::grasp_rank;
use crate::grasp::Grasp;
use crate::grasp_matrix::{contact_block, Wrench};
use crate::hull::{hull, Hull};

/// `|ε|` below this fraction of the largest wrench's norm is reported as 0:
/// the origin is on the hull's boundary (common with flat faces: contacts on
/// parallel faces make the exact answer lie exactly on the boundary).
pub const ZERO_TOLERANCE: f64 = 1e-9;

/// Options of the Ferrari–Canny metric.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FerrariCannyOptions {
    /// Edges of the polyhedral friction cone, `k ≥ 3`.
    pub sides: usize,
    /// Largest candidate point set one L∞ hull may be asked to process
    /// (default 5,000: four contacts with 8-sided cones, a few seconds).
    pub max_points: usize,
}

impl Default for FerrariCannyOptions {
    fn default() -> Self {
        Self {
            sides: 8,
            max_points: 5_000,
        }
    }
}

/// Why a Ferrari–Canny ε could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FerrariCannyError {
    /// A polyhedral cone needs at least three sides.
    #[error("a polyhedral friction cone needs at least 3 sides, got {0}")]
    TooFewSides(usize),
    /// The L∞ Minkowski sum grew past the point limit.
    #[error(
        "the L-infinity Minkowski sum needs a hull of {points} points, over the limit of {limit}"
    )]
    TooManyPoints {
        /// Candidate points at the step that overflowed.
        points: usize,
        /// The limit.
        limit: usize,
    },
}

/// ε for both wrench spaces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FerrariCanny {
    /// ε of `W_L1` (N).
    pub epsilon_l1: f64,
    /// ε of `W_L∞` (N).
    pub epsilon_linf: f64,
}

/// The `k` primitive wrenches of every contact, contact by contact.
pub fn primitive_wrenches(grasp: &Grasp, sides: usize) -> Result<Vec<Wrench>, FerrariCannyError> {
    if sides < 3 {
        return Err(FerrariCannyError::TooFewSides(sides));
    }
    let mu = grasp.mu();
    let mut out = Vec::with_capacity(grasp.len() * sides);
    for (c, &f_max) in grasp.contacts().iter().zip(grasp.force_limits()) {
        let g = contact_block(c, grasp.reference(), grasp.torque_scale());
        let (t1, t2) = c.tangents();
        for j in 0..sides {
            let th = std::f64::consts::TAU * j as f64 / sides as f64;
            let d = (c.normal() + (t1 * th.cos() + t2 * th.sin()) * mu) * f_max;
            out.push(g * d);
        }
    }
    Ok(out)
}

/// Smallest facet distance of the hull of `points` from the origin, or `None`
/// if no full-dimensional hull exists (flat or too few points).
/// Negative when the origin is outside.
fn hull_epsilon(points: &[Wrench]) -> Option<f64> {
    build_hull(points, false).and_then(|h| facet_epsilon(&h, points))
}

/// Smallest facet distance from the origin of a built hull of `points`.
fn facet_epsilon(h: &Hull, points: &[Wrench]) -> Option<f64> {
    // Qhull: normal·x + offset ≤ 0 inside, unit outward normal.
    let mut eps = h
        .facets
        .iter()
        .map(|f| -f.offset)
        .fold(f64::INFINITY, f64::min);
    // A facet through the origin comes out at ±1e-16 of it: rounding, not quality.
    let scale = points.iter().map(|p| p.norm()).fold(0.0, f64::max);
    if eps.abs() <= ZERO_TOLERANCE * scale {
        eps = 0.0;
    }
    eps.is_finite().then_some(eps)
}

fn build_hull(points: &[Wrench], with_vertices: bool) -> Option<Hull> {
    hull(points, with_vertices).ok()
}

/// ε of the L1 grasp wrench space (eq. (8)).
pub fn epsilon_l1(grasp: &Grasp, sides: usize) -> Result<f64, FerrariCannyError> {
    let w = primitive_wrenches(grasp, sides)?;
    Ok(hull_epsilon(&w).unwrap_or(0.0).max(0.0))
}

/// ε of the L∞ grasp wrench space (eq. (7)), by Minkowski addition with
/// pruning to hull vertices after each contact.
pub fn epsilon_linf(
    grasp: &Grasp,
    options: &FerrariCannyOptions,
) -> Result<f64, FerrariCannyError> {
    let k = options.sides;
    let w = primitive_wrenches(grasp, k)?;
    if grasp_rank(grasp) < 6 {
        // The whole sum is flat: no interior, and no hull could prune it.
        return Ok(0.0);
    }
    let mut set: Vec<Wrench> = vec![Vector6::zeros()];
    let contacts = grasp.len();
    for (i, chunk) in w.chunks(k).enumerate() {
        let candidates = set.len() * (k + 1);
        if candidates > options.max_points {
            return Err(FerrariCannyError::TooManyPoints {
                points: candidates,
                limit: options.max_points,
            });
        }
        let mut next = Vec::with_capacity(candidates);
        for v in &set {
            next.push(*v);
            next.extend(chunk.iter().map(|e| v + e));
        }
        let last = i + 1 == contacts;
        let built = build_hull(&next, !last);
        if last {
            // ε from this hull itself: re-hulling its vertices can only lose precision.
            let eps = built.and_then(|h| facet_epsilon(&h, &next));
            return Ok(eps.unwrap_or(0.0).max(0.0));
        }
        set = match built {
            Some(h) => h
                .vertices
                .iter()
                .filter_map(|&i| next.get(i))
                .copied()
                .collect(),
            // Not yet full-dimensional: keep every candidate (still few).
            None => next,
        };
    }
    // A grasp has at least two contacts, so the loop returned.
    Ok(0.0)
}

/// Both ε values with the given options.
pub fn ferrari_canny(
    grasp: &Grasp,
    options: &FerrariCannyOptions,
) -> Result<FerrariCanny, FerrariCannyError> {
    Ok(FerrariCanny {
        epsilon_l1: epsilon_l1(grasp, options.sides)?,
        epsilon_linf: epsilon_linf(grasp, options)?,
    })
}
