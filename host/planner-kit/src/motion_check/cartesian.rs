//! Straight palm lines: the approach and the lift.
//!
//! What: [`palm_line`] follows a straight line of palm poses — a translation
//! along a direction, the orientation kept — with the planned joints, and
//! returns a configuration every `step` metres along it.
//!
//! Why: the last centimetres to a grasp and the first after it must be straight
//! in Cartesian space (the fingers slide onto the object along the approach
//! vector; the object leaves its support straight up), which a joint-space
//! planner does not give.
//!
//! How: each pose is solved by the body crate's damped least-squares IK from the
//! previous configuration, one attempt, pulled toward the previous
//! configuration, so consecutive solutions stay on one branch; a step whose
//! solution fails the tolerance or jumps (any joint more than `MAX_JUMP`) is
//! halved, up to [`SUBDIVISIONS`] times, before the line ends with `None`. Straight joint-space segments join the poses; the palm deviates
//! from the line between them by far less than the step.

use nalgebra::{Isometry3, Translation3, Vector3};
use tsukami_body::ik::{IkOptions, IkSolver};
use tsukami_body::kinematics::JointSelection;
use tsukami_body::model::{JointId, LinkId, RobotModel};

/// Largest joint change between two consecutive poses of a line (rad or m).
pub const MAX_JUMP: f64 = 0.15;

/// A straight line of palm poses.
#[derive(Debug, Clone, Copy)]
pub struct Line {
    /// The palm pose at the line's start.
    pub start: Isometry3<f64>,
    /// Unit direction of travel (world frame).
    pub direction: Vector3<f64>,
    /// Length, metres.
    pub length: f64,
    /// Largest distance between two solved poses, metres.
    pub step: f64,
}

/// Follows `line` with `joints` moving `palm`, from the full configuration
/// `from` (whose palm pose is the line's start). Returns the configurations
/// after `from`, the last at the line's end; `None` if the IK fails or jumps.
pub fn palm_line(
    model: &RobotModel,
    palm: LinkId,
    joints: &[JointId],
    from: &[f64],
    line: &Line,
) -> Option<Vec<Vec<f64>>> {
    let (start_pose, direction, length, step) =
        (&line.start, &line.direction, line.length, line.step);
    let selection = JointSelection::new(model, joints).ok()?;
    let options = IkOptions {
        max_attempts: 1,
        max_iterations: 100,
        position_tolerance: 1e-4,
        orientation_tolerance: 1e-3,
        null_space_gain: 0.0,
        ..IkOptions::default()
    };
    let mut solver = IkSolver::new(model, palm, selection, options).ok()?;
    let n = (length / step).ceil().max(1.0) as usize;
    let mut q = from.to_vec();
    let mut out = Vec::with_capacity(n);
    let pose = |s: f64| Translation3::from(direction * s) * start_pose;
    for i in 1..=n {
        let (s0, s1) = (
            length * (i - 1) as f64 / n as f64,
            length * i as f64 / n as f64,
        );
        q = step_to(&mut solver, joints, &q, (s0, s1), &pose, SUBDIVISIONS)?;
        out.push(q.clone());
    }
    Some(out)
}

/// How many times a step the IK cannot take at once is halved.
pub const SUBDIVISIONS: usize = 3;

/// The configuration at line position `s1` from `q` at `s0`: one IK solve,
/// or, when it fails or jumps, the two halves in turn (`depth` more times).
fn step_to(
    solver: &mut IkSolver<'_>,
    joints: &[JointId],
    q: &[f64],
    (s0, s1): (f64, f64),
    pose: &dyn Fn(f64) -> Isometry3<f64>,
    depth: usize,
) -> Option<Vec<f64>> {
    let sol = solver.solve(&pose(s1), true, q, Some(q));
    let jump = joints
        .iter()
        .map(|&j| (sol.q[j] - q[j]).abs())
        .fold(0.0, f64::max);
    if sol.ok && jump <= MAX_JUMP {
        return Some(sol.q);
    }
    if depth == 0 {
        return None;
    }
    let mid = 0.5 * (s0 + s1);
    let half = step_to(solver, joints, q, (s0, mid), pose, depth - 1)?;
    step_to(solver, joints, &half, (mid, s1), pose, depth - 1)
}
