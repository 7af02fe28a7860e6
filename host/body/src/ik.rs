//! Inverse kinematics for a chosen joint list: damped least squares with
//! Levenberg–Marquardt damping, limit-aware steps, a null-space pull toward a
//! rest pose, and seeded random restarts.
//!
//! The joint list decides the body parts that may move: the 7-DOF arm alone,
//! the arm plus the waist, or the arm, the waist and the virtual squat joint
//! that sets the shoulder height (the paper's section 3.4). Joints on the
//! chain but not in the list keep their value from the initial configuration.
//!
//! ```no_run
//! # use tsukami_body::{urdf::load_urdf, ik::{IkSolver, IkOptions}, kinematics::JointSelection};
//! # use nalgebra::{Isometry3, Vector3};
//! let robot = load_urdf("models/robots/tsukami_humanoid/tsukami_humanoid.urdf".as_ref()).unwrap();
//! let palm = robot.link_id("r_palm").unwrap();
//! // The joint groups come from the robot's description.toml (its `arm` list).
//! let arm_joints = ["r_shoulder_pitch", "r_shoulder_roll", "r_shoulder_yaw", "r_elbow",
//!                   "r_wrist_yaw", "r_wrist_pitch", "r_wrist_roll"];
//! let arm = JointSelection::from_names(&robot, &arm_joints).unwrap();
//! let mut solver = IkSolver::new(&robot, palm, arm, IkOptions::default()).unwrap();
//! let target = Isometry3::new(Vector3::new(0.35, -0.25, 1.0), Vector3::new(0.0, 1.57, 0.0));
//! let sol = solver.solve(&target, true, &robot.rest_positions(), None);
//! println!("ok={} after {} iterations", sol.ok, sol.iterations);
//! ```
//!
//! # Method
//! Each iteration solves `dq = Jᵀ (J Jᵀ + λ I)⁻¹ e` for the 6-D pose error `e`
//! (position; rotation vector weighted by [`IkOptions::orientation_weight`]),
//! with `λ = ½ eᵀe + λ₀` (Sugihara's Levenberg–Marquardt damping: strong far
//! from the goal, vanishing near it). A joint at a limit whose step would push
//! it further is locked and the step recomputed (an active set), then every
//! joint is clamped, so solutions are always within limits. The null-space
//! term `(I − J⁺J) k (q_rest − q)` pulls redundant joints toward the rest pose.
//! When an attempt stalls, the selected joints restart from a random in-limit
//! configuration drawn from a ChaCha8 generator seeded by [`IkOptions::seed`];
//! the result is therefore deterministic for a given seed and input. Before
//! any attempt, a target beyond the chain's reach ([`crate::reach`], a bound
//! that never refuses a reachable one) fails at once with
//! [`IkSolution::beyond_reach`] set: a whole-body planner's arm-only stage
//! costs nothing for an object on the floor.

use nalgebra::{Cholesky, Isometry3, Matrix6, Point3, Vector3, Vector6};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::error::{BodyError, Result};
use crate::kinematics::{joint_motion, JointSelection};
use crate::model::{JointId, JointKind, LinkId, RobotModel};
use crate::reach::ChainReach;

/// Solver settings.
#[derive(Debug, Clone)]
pub struct IkOptions {
    /// Iterations per attempt.
    pub max_iterations: usize,
    /// Attempts (the first from the initial configuration, the others from
    /// random configurations).
    pub max_attempts: usize,
    /// Success threshold on the position error (m).
    pub position_tolerance: f64,
    /// Success threshold on the orientation error (rad).
    pub orientation_tolerance: f64,
    /// Weight of the rotation error relative to the position error (m/rad).
    pub orientation_weight: f64,
    /// Gain of the null-space pull toward the rest pose (0 disables it).
    pub null_space_gain: f64,
    /// Minimum damping λ₀.
    pub min_damping: f64,
    /// Seed of the restart generator.
    pub seed: u64,
}

impl Default for IkOptions {
    fn default() -> Self {
        Self {
            max_iterations: 60,
            max_attempts: 50,
            position_tolerance: 1e-5,
            orientation_tolerance: 1e-4,
            orientation_weight: 0.4,
            null_space_gain: 0.05,
            min_damping: 1e-5,
            seed: 0,
        }
    }
}

/// The outcome of a solve.
#[derive(Debug, Clone)]
pub struct IkSolution {
    /// True when both errors are within tolerance.
    pub ok: bool,
    /// Full joint-position vector (mimic entries applied); the best found
    /// when `ok` is false.
    pub q: Vec<f64>,
    /// Final position error (m).
    pub position_error: f64,
    /// Final orientation error (rad; 0 for position-only targets).
    pub orientation_error: f64,
    /// Iterations over all attempts.
    pub iterations: usize,
    /// Attempts used (0 when the target is out of reach).
    pub attempts: usize,
    /// How far (m) the target lies beyond every position the selected joints
    /// can bring the link to (their limits ignored; [`crate::reach`]); when
    /// it exceeds the position tolerance no attempt is made. ≤ 0 otherwise.
    pub beyond_reach: f64,
}

/// One movable joint on the path to the target link.
#[derive(Debug, Clone)]
struct PathJoint {
    joint: JointId,
    column: usize,
    multiplier: f64,
}

/// An IK solver for one link and one joint list; reuse it across targets
/// (its buffers are allocated once).
#[derive(Debug, Clone)]
pub struct IkSolver<'m> {
    model: &'m RobotModel,
    link: LinkId,
    selection: JointSelection,
    options: IkOptions,
    /// Every joint from the root to the link (fixed ones included).
    path: Vec<JointId>,
    /// Movable joints of `path` whose master is selected.
    movers: Vec<(usize, PathJoint)>,
    poses: Vec<Isometry3<f64>>,
    cols: Vec<Vector6<f64>>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    reach: ChainReach,
}

impl<'m> IkSolver<'m> {
    /// A solver moving `link` with the joints of `selection`.
    pub fn new(
        model: &'m RobotModel,
        link: LinkId,
        selection: JointSelection,
        options: IkOptions,
    ) -> Result<Self> {
        if link >= model.links.len() {
            return Err(BodyError::UnknownLink(format!("#{link}")));
        }
        let mut path = Vec::new();
        let mut l = link;
        while let Some(j) = model.links[l].parent_joint {
            path.push(j);
            l = model.joints[j].parent;
        }
        path.reverse();
        let movers: Vec<(usize, PathJoint)> = path
            .iter()
            .enumerate()
            .filter_map(|(k, &j)| {
                let joint = &model.joints[j];
                if joint.kind == JointKind::Fixed {
                    return None;
                }
                let (master, multiplier) = joint
                    .mimic
                    .as_ref()
                    .map_or((j, 1.0), |m| (m.master, m.master_multiplier));
                selection.column(master).map(|column| {
                    (
                        k,
                        PathJoint {
                            joint: j,
                            column,
                            multiplier,
                        },
                    )
                })
            })
            .collect();
        if movers.is_empty() {
            return Err(BodyError::Request(format!(
                "none of the selected joints moves link '{}'",
                model.links[link].name
            )));
        }
        let (lower, upper) = selection
            .joints
            .iter()
            .map(|&j| {
                let lim = &model.joints[j].limits;
                match model.joints[j].kind {
                    JointKind::Continuous => (-std::f64::consts::PI, std::f64::consts::PI),
                    _ => (lim.lower, lim.upper),
                }
            })
            .unzip();
        let n = selection.len();
        let poses = vec![Isometry3::identity(); path.len() + 1];
        let reach = ChainReach::new(model, &path, movers[0].0);
        Ok(Self {
            model,
            link,
            path,
            movers,
            poses,
            cols: vec![Vector6::zeros(); n],
            lower,
            upper,
            selection,
            options,
            reach,
        })
    }

    /// The solver settings (e.g. to change the seed between solves).
    pub fn options_mut(&mut self) -> &mut IkOptions {
        &mut self.options
    }

    /// The selected joints.
    pub fn selection(&self) -> &JointSelection {
        &self.selection
    }

    /// Pose of the link for `q`, computed along its chain only (root at the
    /// identity), from `path[from]` on: the frames before it are kept from
    /// the last call (the joints before the first mover do not change
    /// during a solve, so iterations start there; the same products in the
    /// same order, so the same bits).
    fn chain_fk(&mut self, q: &[f64], from: usize) -> Isometry3<f64> {
        if from == 0 {
            self.poses[0] = Isometry3::identity();
        }
        let mut pose = self.poses[from];
        for (k, &j) in self.path.iter().enumerate().skip(from) {
            let joint = &self.model.joints[j];
            let value = match &joint.mimic {
                Some(m) => m.master_multiplier * q[m.master] + m.master_offset,
                None => q[j],
            };
            pose = pose * joint.origin * joint_motion(joint.kind, &joint.axis, value);
            self.poses[k + 1] = pose;
        }
        pose
    }

    /// Solves for `target` (pose of the link frame in the model's root
    /// frame). With `orientation == false` only the position is matched.
    /// Starts from `q_init` (full joint vector; unselected joints keep their
    /// values) and pulls toward `rest` (full vector; defaults to `q_init`).
    pub fn solve(
        &mut self,
        target: &Isometry3<f64>,
        orientation: bool,
        q_init: &[f64],
        rest: Option<&[f64]>,
    ) -> IkSolution {
        let opts = self.options.clone();
        let n = self.selection.len();
        let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
        let (mut q, rest) = self.clamped_start(q_init, rest);
        let w_o = if orientation {
            opts.orientation_weight
        } else {
            0.0
        };
        let beyond_reach = match self.out_of_reach(target, orientation, &mut q) {
            Ok(beyond) => beyond,
            Err(refused) => return refused,
        };
        // Best configuration seen so far: (score, position error, orientation error).
        let mut best = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        let mut best_q = q.clone();
        let mut iterations = 0;
        let mut dq = vec![0.0; n];
        let mut locked = vec![false; n];
        for attempt in 0..opts.max_attempts.max(1) {
            if attempt > 0 {
                for (c, &j) in self.selection.joints.iter().enumerate() {
                    q[j] = rng.random_range(self.lower[c]..=self.upper[c]);
                }
            }
            let mut history = f64::INFINITY;
            for it in 0..opts.max_iterations {
                iterations += 1;
                let (p, ep, eo) = self.pose_error(&q, target, orientation);
                let (pe, oe) = (ep.norm(), eo.norm());
                if pe + w_o * oe < best.0 {
                    best = (pe + w_o * oe, pe, oe);
                    best_q.copy_from_slice(&q);
                }
                if pe <= opts.position_tolerance && oe <= opts.orientation_tolerance {
                    self.model.apply_mimics(&mut q);
                    return IkSolution {
                        ok: true,
                        q,
                        position_error: pe,
                        orientation_error: oe,
                        iterations,
                        attempts: attempt + 1,
                        beyond_reach,
                    };
                }
                let e = Vector6::new(ep.x, ep.y, ep.z, w_o * eo.x, w_o * eo.y, w_o * eo.z);
                let energy = 0.5 * e.norm_squared();
                // Restart when ten iterations did not halve the error.
                if it % 10 == 0 {
                    if it > 0 && energy > 0.5 * history {
                        break;
                    }
                    history = energy;
                }
                self.jacobian(&p, w_o);
                let lambda = energy + opts.min_damping;
                // The damped pseudo-inverse leaks a little of the null-space
                // pull into the task; near the goal that leak would stall
                // convergence, so the pull fades out below 1 mm / ~2 mrad.
                let gain = if e.norm() > 1e-3 {
                    opts.null_space_gain
                } else {
                    0.0
                };
                self.damped_step(&e, (lambda, gain), (&rest, &q), (&mut dq, &mut locked));
                // Cap the step so a far target does not throw the arm around.
                let max_step = dq.iter().fold(0.0f64, |m, d| m.max(d.abs()));
                let scale = if max_step > 0.5 { 0.5 / max_step } else { 1.0 };
                for (c, &j) in self.selection.joints.iter().enumerate() {
                    q[j] = (q[j] + scale * dq[c]).clamp(self.lower[c], self.upper[c]);
                }
            }
        }
        self.model.apply_mimics(&mut best_q);
        IkSolution {
            ok: false,
            q: best_q,
            position_error: best.1,
            orientation_error: best.2,
            iterations,
            attempts: opts.max_attempts.max(1),
            beyond_reach,
        }
    }

    /// The start `q_init` and the rest pose (`rest`, else `q_init`; one
    /// entry per selected joint) with the selected joints within limits.
    fn clamped_start(&self, q_init: &[f64], rest: Option<&[f64]>) -> (Vec<f64>, Vec<f64>) {
        let mut q = q_init.to_vec();
        let rest: Vec<f64> = self
            .selection
            .joints
            .iter()
            .enumerate()
            .map(|(c, &j)| rest.unwrap_or(q_init)[j].clamp(self.lower[c], self.upper[c]))
            .collect();
        for (c, &j) in self.selection.joints.iter().enumerate() {
            q[j] = q[j].clamp(self.lower[c], self.upper[c]);
        }
        (q, rest)
    }

    /// Before any attempt: how far the target lies beyond the chain's reach
    /// (`Ok`, ≤ the tolerance), or the failed solution at `q` when farther.
    fn out_of_reach(
        &mut self,
        target: &Isometry3<f64>,
        orientation: bool,
        q: &mut [f64],
    ) -> Result<f64, IkSolution> {
        let target_p = Point3::from(target.translation.vector);
        let start = self.chain_fk(q, 0);
        let beyond_reach = self
            .reach
            .beyond(self.model, &self.path, &self.poses, q, &target_p);
        if beyond_reach <= self.options.position_tolerance {
            return Ok(beyond_reach);
        }
        self.model.apply_mimics(q);
        Err(IkSolution {
            ok: false,
            q: q.to_vec(),
            position_error: (target_p.coords - start.translation.vector).norm(),
            orientation_error: match orientation {
                true => (target.rotation * start.rotation.inverse()).angle(),
                false => 0.0,
            },
            iterations: 0,
            attempts: 0,
            beyond_reach,
        })
    }

    /// The link's origin for `q` and its position and rotation-vector errors
    /// to `target` (no rotation error without `orientation`).
    fn pose_error(
        &mut self,
        q: &[f64],
        target: &Isometry3<f64>,
        orientation: bool,
    ) -> (Point3<f64>, Vector3<f64>, Vector3<f64>) {
        let pose = self.chain_fk(q, self.movers[0].0);
        let p = Point3::from(pose.translation.vector);
        let ep = Point3::from(target.translation.vector) - p;
        let eo = match orientation {
            true => (target.rotation * pose.rotation.inverse()).scaled_axis(),
            false => Vector3::zeros(),
        };
        (p, ep, eo)
    }

    /// The Jacobian columns of the link's origin `p` at the poses of the last
    /// chain FK, weighted like the error (rotation rows by `w_o`).
    fn jacobian(&mut self, p: &Point3<f64>, w_o: f64) {
        self.cols.iter_mut().for_each(|c| *c = Vector6::zeros());
        for (k, pj) in &self.movers {
            let joint = &self.model.joints[pj.joint];
            let child = &self.poses[k + 1];
            let axis = child.rotation * joint.axis.into_inner();
            let col = match joint.kind {
                JointKind::Prismatic => Vector6::new(axis.x, axis.y, axis.z, 0.0, 0.0, 0.0),
                _ => {
                    let lin = axis.cross(&(p - Point3::from(child.translation.vector)));
                    Vector6::new(
                        lin.x,
                        lin.y,
                        lin.z,
                        w_o * axis.x,
                        w_o * axis.y,
                        w_o * axis.z,
                    )
                }
            };
            self.cols[pj.column] += col * pj.multiplier;
        }
    }

    /// The damped least-squares step `dq` for error `e` with damping
    /// `lambda` and null-space pull `gain` toward `rest`, a joint at a limit
    /// that the step would push further locked and the step recomputed (up
    /// to four passes).
    fn damped_step(
        &self,
        e: &Vector6<f64>,
        (lambda, gain): (f64, f64),
        (rest, q): (&[f64], &[f64]),
        (dq, locked): (&mut [f64], &mut [bool]),
    ) {
        locked.iter_mut().for_each(|l| *l = false);
        for _pass in 0..4 {
            let mut a = Matrix6::identity() * lambda;
            for (c, col) in self.cols.iter().enumerate() {
                if !locked[c] {
                    a.ger(1.0, col, col, 1.0);
                }
            }
            let Some(chol) = Cholesky::new(a) else { break };
            let y = chol.solve(e);
            let mut jz = Vector6::zeros();
            for (c, &j) in self.selection.joints.iter().enumerate() {
                if locked[c] {
                    dq[c] = 0.0;
                    continue;
                }
                let z = gain * (rest[c] - q[j]);
                dq[c] = self.cols[c].dot(&y) + z;
                jz += self.cols[c] * z;
            }
            if gain != 0.0 {
                let w = chol.solve(&jz);
                for (c, d) in dq.iter_mut().enumerate() {
                    if !locked[c] {
                        *d -= self.cols[c].dot(&w);
                    }
                }
            }
            let mut relock = false;
            for (c, &j) in self.selection.joints.iter().enumerate() {
                let at_low = q[j] <= self.lower[c] + 1e-12 && dq[c] < 0.0;
                let at_high = q[j] >= self.upper[c] - 1e-12 && dq[c] > 0.0;
                if !locked[c] && (at_low || at_high) {
                    locked[c] = true;
                    relock = true;
                }
            }
            if !relock {
                break;
            }
        }
    }

    /// The link this solver moves.
    pub fn link(&self) -> LinkId {
        self.link
    }
}
