//! Iterative closest point against an object template: point-to-plane
//! (the default) and point-to-point (the reference it is compared with).
//!
//! What: [`refine`] improves a pose of the template so that the measured
//! points lie on its surface, and reports the fit.
//!
//! Why: the hypotheses of [`crate::hypotheses`] are a few degrees and
//! centimetres off; ICP brings them to the accuracy of the data.
//!
//! How: every iteration maps the measured points into the object frame with
//! the current pose, pairs each with its nearest surface sample (k-d tree),
//! drops pairs farther than the current gate and pairs whose model normal
//! faces away from the camera (a point on the back of the model cannot have
//! been seen), and solves for a small motion:
//! - point-to-plane (Chen & Medioni): minimise Σ w ((x + ω×x + v − m)·n)²,
//!   linear in (ω, v); a 6×6 normal system, damped so that motions the
//!   surface does not constrain (a can's spin) stay zero;
//! - point-to-point (Besl & McKay): the Kabsch rotation from the SVD of the
//!   cross-covariance (nalgebra).
//!
//! Weights are Huber's (scale `huber`). The gate shrinks geometrically from
//! `gate_start` to `gate_end`.
//!
//! ```
//! use nalgebra::{Isometry3, Point3, Vector3};
//! use tsukami_body::model::Geometry;
//! use tsukami_body::object::ObjectModel;
//! use tsukami_vision::icp::{refine, IcpParams};
//! use tsukami_vision::template::ObjectTemplate;
//! let geometry = Geometry::Box { size: Vector3::new(0.06, 0.1, 0.16) };
//! let model = ObjectModel::new("box".into(), String::new(), "box.obj".as_ref(), geometry, 0.2, 0.5).unwrap();
//! let t = ObjectTemplate::from_model("box", model, 0.004).unwrap();
//! let truth = Isometry3::new(Vector3::new(0.5, 0.0, 0.8), Vector3::new(0.0, 0.0, 0.3));
//! let seen: Vec<Point3<f64>> = t.points.iter().map(|p| truth * p).collect();
//! let start = Isometry3::new(Vector3::new(0.51, 0.008, 0.79), Vector3::new(0.0, 0.05, 0.25));
//! let fit = refine(&t, &seen, None, start, &IcpParams::default());
//! assert!((fit.pose.translation.vector - truth.translation.vector).norm() < 1e-4);
//! ```

use nalgebra::{
    Isometry3, Matrix3, Matrix6, Point3, Translation3, UnitQuaternion, Vector3, Vector6,
};

use crate::template::ObjectTemplate;

/// The error metric.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IcpMode {
    /// Point-to-plane (default).
    PointToPlane,
    /// Point-to-point (Kabsch/SVD), for comparison.
    PointToPoint,
}

/// ICP settings.
#[derive(Debug, Clone, PartialEq)]
pub struct IcpParams {
    /// Metric.
    pub mode: IcpMode,
    /// Most iterations.
    pub iterations: usize,
    /// Pair gate at the first iteration (m).
    pub gate_start: f64,
    /// Pair gate from which on it stops shrinking (m).
    pub gate_end: f64,
    /// Huber scale (m).
    pub huber: f64,
    /// Stop when an update moves less than this (m, and rad).
    pub converged: f64,
    /// Pair through the template's lookup grid ([`crate::lookup`]: faster,
    /// off by up to a cell) instead of the exact k-d tree search; the grid
    /// pairs nothing farther than `template::LOOKUP_MARGIN`, so `gate_start`
    /// should not exceed it.
    pub fast_pairing: bool,
}

impl Default for IcpParams {
    fn default() -> Self {
        IcpParams {
            mode: IcpMode::PointToPlane,
            iterations: 30,
            gate_start: 0.03,
            gate_end: 0.006,
            huber: 0.002,
            converged: 1e-5,
            fast_pairing: false,
        }
    }
}

/// A fitted pose and how well it fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IcpFit {
    /// Object frame → base frame.
    pub pose: Isometry3<f64>,
    /// RMS point-to-surface distance of the paired points (m).
    pub rms: f64,
    /// Points paired at the last iteration.
    pub paired: usize,
    /// Points given.
    pub total: usize,
    /// Iterations run.
    pub iterations: usize,
}

impl IcpFit {
    /// Fraction of the given points that were paired.
    pub fn fraction(&self) -> f64 {
        self.paired as f64 / self.total.max(1) as f64
    }
}

struct Pair {
    x: Vector3<f64>,
    m: Vector3<f64>,
    n: Vector3<f64>,
}

/// Refines `start` (object → base) so that `points` (base frame) lie on the
/// template's surface. `camera` (base frame), when given, rejects pairs on
/// the model's far side.
pub fn refine(
    template: &ObjectTemplate,
    points: &[Point3<f64>],
    camera: Option<Point3<f64>>,
    start: Isometry3<f64>,
    params: &IcpParams,
) -> IcpFit {
    let mut inv = start.inverse(); // base → object
    let iterations = params.iterations.max(1);
    let shrink =
        (params.gate_end / params.gate_start).powf(1.0 / (iterations as f64 * 0.3).max(1.0));
    let mut gate = params.gate_start;
    let mut pairs = Vec::with_capacity(points.len());
    let mut fit = IcpFit {
        pose: start,
        rms: f64::INFINITY,
        paired: 0,
        total: points.len(),
        iterations: 0,
    };
    for it in 0..iterations {
        collect_pairs(
            template,
            points,
            camera.map(|c| inv * c),
            (&inv, gate, params.fast_pairing),
            &mut pairs,
        );
        fit.iterations = it + 1;
        if pairs.len() < 6 {
            fit.paired = pairs.len();
            break;
        }
        let step = match params.mode {
            IcpMode::PointToPlane => point_to_plane_step(&pairs, params.huber),
            IcpMode::PointToPoint => point_to_point_step(&pairs),
        };
        let Some(step) = step else { break };
        inv = step * inv;
        let moved = step.translation.vector.norm() + step.rotation.angle() * template.radius;
        gate = (gate * shrink).max(params.gate_end);
        if moved < params.converged && gate <= params.gate_end {
            break;
        }
    }
    // Final residuals at the final pose.
    collect_pairs(
        template,
        points,
        camera.map(|c| inv * c),
        (&inv, params.gate_end, params.fast_pairing),
        &mut pairs,
    );
    fit.paired = pairs.len();
    fit.rms = if pairs.is_empty() {
        f64::INFINITY
    } else {
        let s: f64 = pairs.iter().map(|p| (p.x - p.m).dot(&p.n).powi(2)).sum();
        (s / pairs.len() as f64).sqrt()
    };
    fit.pose = inv.inverse();
    fit
}

fn collect_pairs(
    template: &ObjectTemplate,
    points: &[Point3<f64>],
    camera_obj: Option<Point3<f64>>,
    (inv, gate, fast): (&Isometry3<f64>, f64, bool),
    pairs: &mut Vec<Pair>,
) {
    pairs.clear();
    let gate2 = gate * gate;
    for p in points {
        let x = inv * p;
        let (j, d2) = template.pair(&x, fast);
        if d2 > gate2 {
            continue;
        }
        let m = template.points[j];
        let n = template.normals[j];
        if let Some(c) = camera_obj {
            if n.dot(&(c - m)) < 0.0 {
                continue;
            }
        }
        pairs.push(Pair {
            x: x.coords,
            m: m.coords,
            n,
        });
    }
}

fn huber(r: f64, k: f64) -> f64 {
    if r.abs() <= k {
        1.0
    } else {
        k / r.abs()
    }
}

/// The small motion (applied in the object frame) of one point-to-plane step.
fn point_to_plane_step(pairs: &[Pair], k: f64) -> Option<Isometry3<f64>> {
    let mut a = Matrix6::zeros();
    let mut b = Vector6::zeros();
    for p in pairs {
        let r = (p.x - p.m).dot(&p.n);
        let w = huber(r, k);
        let c = p.x.cross(&p.n);
        let j = Vector6::new(c.x, c.y, c.z, p.n.x, p.n.y, p.n.z);
        a += j * j.transpose() * w;
        b -= j * (r * w);
    }
    let damping = 1e-6 * a.trace().max(1e-12);
    for i in 0..6 {
        a[(i, i)] += damping;
    }
    let delta = a.cholesky()?.solve(&b);
    if !delta.iter().all(|v| v.is_finite()) {
        return None;
    }
    let rot = UnitQuaternion::from_scaled_axis(Vector3::new(delta[0], delta[1], delta[2]));
    Some(Isometry3::from_parts(
        Translation3::new(delta[3], delta[4], delta[5]),
        rot,
    ))
}

/// The Kabsch motion taking the measured points onto their pairs.
fn point_to_point_step(pairs: &[Pair]) -> Option<Isometry3<f64>> {
    let n = pairs.len() as f64;
    let cx = pairs.iter().map(|p| p.x).sum::<Vector3<f64>>() / n;
    let cm = pairs.iter().map(|p| p.m).sum::<Vector3<f64>>() / n;
    let mut h = Matrix3::zeros();
    for p in pairs {
        h += (p.x - cx) * (p.m - cm).transpose();
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut d = Matrix3::identity();
    if (vt.transpose() * u.transpose()).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
    }
    let r = vt.transpose() * d * u.transpose();
    let rot = UnitQuaternion::from_matrix(&r);
    let t = cm - rot * cx;
    Some(Isometry3::from_parts(Translation3::from(t), rot))
}
