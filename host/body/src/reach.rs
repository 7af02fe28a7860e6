//! How far a kinematic chain can reach: a sound bound that lets inverse
//! kinematics refuse a target no configuration can touch, without iterating.
//!
//! What: [`ChainReach`] holds, for the movable joints from the first one an IK
//! solver moves down to its link (the *pivots*), the largest distance from each
//! pivot's origin to the link's origin. [`ChainReach::beyond`] tells how far a
//! target position lies outside the set the chain can reach (≤ 0: maybe
//! reachable).
//!
//! Why: a whole-body planner tries the arm alone first, then the arm and the
//! waist, then a squat; for a low or far object most of the first stages'
//! targets are out of reach, and a damped-least-squares IK only learns that
//! after all its restarts. The bound answers in a few flops and never refuses
//! a reachable target, so every solution is the same as without it.
//!
//! How: a revolute joint turns everything after it about an axis through its
//! origin, so the distance from its origin to the next pivot's origin is the
//! same in every configuration; a prismatic joint adds at most its travel. The
//! sum of these lengths from pivot `i` on bounds the link's distance from
//! pivot `i`. The first pivot, when it turns, does better: the next pivot stays
//! on one circle about its axis, so the link lies within the rest of the
//! chain's reach of that circle (a torus, not a ball: a waist that only turns
//! about the vertical cannot lower the shoulder). Joint limits are ignored,
//! which keeps the bound sound and loose.
//!
//! ```
//! use nalgebra::Isometry3;
//! use tsukami_body::ik::{IkOptions, IkSolver};
//! use tsukami_body::kinematics::JointSelection;
//! let urdf = r#"<robot name="arm">
//!   <link name="base"/><link name="upper"/><link name="tip"/>
//!   <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
//!     <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
//!   <joint name="elbow" type="revolute"><parent link="upper"/><child link="tip"/>
//!     <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
//! </robot>"#;
//! let robot = tsukami_body::urdf::parse_urdf(urdf, "arm.urdf".as_ref()).unwrap();
//! let tip = robot.link_id("tip").unwrap();
//! let sel = JointSelection::from_names(&robot, &["shoulder", "elbow"]).unwrap();
//! let mut ik = IkSolver::new(&robot, tip, sel, IkOptions::default()).unwrap();
//! // The tip stays on the circle of radius 0.3 m about the shoulder's axis.
//! let far = Isometry3::translation(0.5, 0.0, 0.0);
//! let sol = ik.solve(&far, false, &robot.rest_positions(), None);
//! assert!(!sol.ok);
//! assert!((sol.beyond_reach - 0.2).abs() < 1e-12);
//! assert_eq!(sol.attempts, 0);
//! ```

use nalgebra::{Isometry3, Point3, Vector3};

use crate::kinematics::joint_motion;
use crate::model::{JointId, JointKind, RobotModel};

/// The reach of a chain from its first moving joint (see the module docs).
#[derive(Debug, Clone)]
pub struct ChainReach {
    /// Indices into the chain's joint path of its movable joints from the
    /// first one that moves on.
    pivots: Vec<usize>,
    /// `suffix[i]`: the farthest the link's origin can be from pivot `i`'s
    /// origin (m); `suffix[pivots.len()]` is 0.
    suffix: Vec<f64>,
}

impl ChainReach {
    /// The reach of the chain `path` (every joint from the root to the link,
    /// fixed ones included) from `path[first]`, the first joint that moves.
    pub fn new(model: &RobotModel, path: &[JointId], first: usize) -> Self {
        let pivots: Vec<usize> = (first..path.len())
            .filter(|&k| model.joints[path[k]].is_movable())
            .collect();
        // Origins with every joint at 0: the distances between consecutive
        // pivots do not depend on the values (for a prismatic joint, beyond
        // its travel, added below).
        let frames = chain_frames(model, path, |_| 0.0);
        let origin = |k: usize| match k < path.len() {
            true => {
                (frames[k] * model.joints[path[k]].origin)
                    .translation
                    .vector
            }
            false => frames[path.len()].translation.vector,
        };
        let mut suffix = vec![0.0; pivots.len() + 1];
        for i in (0..pivots.len()).rev() {
            let next = pivots.get(i + 1).copied().unwrap_or(path.len());
            let length = (origin(next) - origin(pivots[i])).norm() + travel(model, path[pivots[i]]);
            suffix[i] = suffix[i + 1] + length;
        }
        Self { pivots, suffix }
    }

    /// How far (m) the point `target` lies beyond every position the link's
    /// origin can take; ≤ 0 when it may be reachable. `frames[k]` is the pose
    /// of the frame before `path[k]` (its parent link's) at the current
    /// configuration, `frames[path.len()]` the link's: the joints before the
    /// first pivot hold still, so that pivot's axis is where it is now.
    pub fn beyond(
        &self,
        model: &RobotModel,
        path: &[JointId],
        frames: &[Isometry3<f64>],
        q: &[f64],
        target: &Point3<f64>,
    ) -> f64 {
        let Some(&k0) = self.pivots.first() else {
            return f64::NEG_INFINITY;
        };
        let joint = &model.joints[path[k0]];
        let frame = frames[k0] * joint.origin;
        let o = frame.translation.vector;
        let t = target.coords;
        if !turns(joint.kind) {
            return (t - o).norm() - self.suffix[0];
        }
        let axis = frame.rotation * joint.axis.into_inner();
        // The next pivot (or the link) circles the axis through `o`: in the
        // axis' meridian half-plane (height along it, distance from it) the
        // circle is one point, and the target must be within the rest of the
        // chain's reach of it (a torus).
        let next = self.origin(model, path, frames, 1) - o;
        let along = axis.dot(&next);
        let radius = (next - axis * along).norm();
        let height = axis.dot(&(t - o));
        let across = ((t - o) - axis * height).norm();
        let torus = (height - along).hypot(across - radius) - self.suffix[1];
        torus.max(self.second_pivot_bound(model, path, frames, q, (o, axis), t))
    }

    /// The origin of pivot `i` (the link's when `i` is past the last one).
    fn origin(
        &self,
        model: &RobotModel,
        path: &[JointId],
        frames: &[Isometry3<f64>],
        i: usize,
    ) -> Vector3<f64> {
        match self.pivots.get(i) {
            Some(&k) => {
                (frames[k] * model.joints[path[k]].origin)
                    .translation
                    .vector
            }
            None => frames[path.len()].translation.vector,
        }
    }

    /// When the second pivot turns about an axis through a point of the
    /// first one's axis (a waist's yaw then pitch, a shoulder's pitch then
    /// roll), the third pivot's height along the first axis is set by the
    /// second joint alone, within its limits: in the first axis' meridian
    /// half-plane the third pivot stays on an arc of a circle, and the target
    /// must be within the rest of the chain's reach of that arc.
    fn second_pivot_bound(
        &self,
        model: &RobotModel,
        path: &[JointId],
        frames: &[Isometry3<f64>],
        q: &[f64],
        (o, a0): (Vector3<f64>, Vector3<f64>),
        t: Vector3<f64>,
    ) -> f64 {
        let Some(&k1) = self.pivots.get(1) else {
            return f64::NEG_INFINITY;
        };
        let joint = &model.joints[path[k1]];
        let frame = frames[k1] * joint.origin;
        let o1 = frame.translation.vector - o;
        let s0 = a0.dot(&o1);
        if !turns(joint.kind) || (o1 - a0 * s0).norm() > 1e-9 {
            return f64::NEG_INFINITY;
        }
        let a1 = frame.rotation * joint.axis.into_inner();
        let c = self.origin(model, path, frames, 2) - frame.translation.vector;
        // Height of the third pivot above `o1` along a0 as the second joint
        // turns by δ from now: A + B cos δ + C sin δ (Rodrigues' formula).
        let (a, b, cc) = (
            a0.dot(&a1) * a1.dot(&c),
            a0.dot(&c) - a0.dot(&a1) * a1.dot(&c),
            a0.dot(&a1.cross(&c)),
        );
        let (lo, hi) = value_range(model, path[k1]);
        let now = joint_value(model, path[k1], q);
        let (h_min, h_max) = sinusoid_range((a, b, cc), (lo - now, hi - now));
        let r = c.norm();
        if r < 1e-12 {
            return f64::NEG_INFINITY;
        }
        let phi = |h: f64| (h / r).clamp(-1.0, 1.0).acos();
        let h_t = a0.dot(&(t - o));
        let rho_t = ((t - o) - a0 * h_t).norm();
        meridian_distance((h_t, rho_t), (s0, 0.0), r, (phi(h_max), phi(h_min))) - self.suffix[2]
    }
}

/// Distance in a meridian half-plane (height along an axis, distance from
/// it) from the point `p` to the arc of the circle about `centre` of radius
/// `r` whose angles from the axis direction lie in `(from, to)` ⊂ [0, π].
fn meridian_distance(p: (f64, f64), centre: (f64, f64), r: f64, (from, to): (f64, f64)) -> f64 {
    let (dh, drho) = (p.0 - centre.0, p.1 - centre.1);
    let angle = drho.atan2(dh);
    if (from..=to).contains(&angle) {
        return (dh.hypot(drho) - r).abs();
    }
    let end = |phi: f64| (dh - r * phi.cos()).hypot(drho - r * phi.sin());
    end(from).min(end(to))
}

/// The range of `A + B cos δ + C sin δ` over `δ ∈ [d0, d1]`.
fn sinusoid_range((a, b, c): (f64, f64, f64), (d0, d1): (f64, f64)) -> (f64, f64) {
    let amplitude = b.hypot(c);
    // A full turn (or an interval that is not a number): the whole swing.
    if (d1 - d0).partial_cmp(&std::f64::consts::TAU) != Some(std::cmp::Ordering::Less) {
        return (a - amplitude, a + amplitude);
    }
    let f = |d: f64| a + b * d.cos() + c * d.sin();
    let (mut lo, mut hi) = (f(d0).min(f(d1)), f(d0).max(f(d1)));
    // Extremes at δ* = atan2(C, B) + kπ inside the interval.
    let star = c.atan2(b);
    let pi = std::f64::consts::PI;
    let mut d = star + ((d0 - star) / pi).ceil() * pi;
    while d <= d1 {
        lo = lo.min(f(d));
        hi = hi.max(f(d));
        d += pi;
    }
    (lo, hi)
}

fn turns(kind: JointKind) -> bool {
    matches!(kind, JointKind::Revolute | JointKind::Continuous)
}

/// The joint's value in `q` (its mimic coupling applied).
fn joint_value(model: &RobotModel, j: JointId, q: &[f64]) -> f64 {
    match &model.joints[j].mimic {
        Some(m) => m.master_multiplier * q[m.master] + m.master_offset,
        None => q[j],
    }
}

/// The values the joint can take (its mimic coupling applied); a full turn
/// each way for a continuous joint or one without finite limits.
fn value_range(model: &RobotModel, j: JointId) -> (f64, f64) {
    let joint = &model.joints[j];
    let (limits, m, c) = match &joint.mimic {
        Some(mm) => (
            &model.joints[mm.master],
            mm.master_multiplier,
            mm.master_offset,
        ),
        None => (joint, 1.0, 0.0),
    };
    let (lo, hi) = (limits.limits.lower, limits.limits.upper);
    if limits.kind == JointKind::Continuous || !(lo.is_finite() && hi.is_finite()) {
        return (-std::f64::consts::TAU, std::f64::consts::TAU);
    }
    let (a, b) = (m * lo + c, m * hi + c);
    (a.min(b), a.max(b))
}

/// The poses of the frames along `path` (root at the identity) with joint
/// values from `value`: `[k]` before `path[k]`, the last after all of them.
pub(crate) fn chain_frames(
    model: &RobotModel,
    path: &[JointId],
    value: impl Fn(JointId) -> f64,
) -> Vec<Isometry3<f64>> {
    let mut frames = Vec::with_capacity(path.len() + 1);
    let mut pose = Isometry3::identity();
    for &j in path {
        frames.push(pose);
        let joint = &model.joints[j];
        pose = pose * joint.origin * joint_motion(joint.kind, &joint.axis, value(j));
    }
    frames.push(pose);
    frames
}

/// The largest displacement a prismatic joint can make from 0 (its mimic
/// coupling applied); 0 for a joint that turns.
fn travel(model: &RobotModel, j: JointId) -> f64 {
    let joint = &model.joints[j];
    if joint.kind != JointKind::Prismatic {
        return 0.0;
    }
    let (lo, hi, m, c) = match &joint.mimic {
        Some(mm) => {
            let l = &model.joints[mm.master].limits;
            (l.lower, l.upper, mm.master_multiplier, mm.master_offset)
        }
        None => (joint.limits.lower, joint.limits.upper, 1.0, 0.0),
    };
    let t = (m * lo + c).abs().max((m * hi + c).abs());
    match t.is_finite() {
        true => t,
        false => f64::INFINITY,
    }
}
