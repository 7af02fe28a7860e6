//! The collision test of a motion: a robot among obstacles, for a subset of its
//! joints.
//!
//! What: [`RobotWorld`] answers [`Validity`] (is this configuration of the planned
//! joints free of self-collision and of collision with every obstacle?) and its
//! [`Resolution`] answers [`SegmentSteps`] (how many checks a straight segment needs so that no link
//! point moves more than `max_travel` between two of them, see
//! [`crate::resolution`]).
//!
//! Why: RRT-Connect and shortcutting work on the planned joints only (arm; arm +
//! waist; arm + waist + squat); the rest of the robot stays where the start put it,
//! and mimic joints follow their masters. One value holds that mapping, the forward
//! kinematics scratch space and the obstacles, so the planner's inner loop
//! allocates nothing per check.
//!
//! How: a configuration of the planned joints is written into the full joint
//! vector, mimics are applied, forward kinematics runs once, then
//! `RobotCollision::first_self_collision` and `first_collision` against the
//! obstacles with the margin decide. Every check is counted.

use nalgebra::Isometry3;
use tsukami_body::collision::{CollisionObject, RobotCollision};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{JointId, LinkId, RobotModel};

use crate::resolution::SweepBound;
use crate::rrt_connect::{SegmentSteps, Validity};

/// Default largest travel of any link point between two checks of a segment:
/// half of the thinnest obstacle the planner promises not to skip (1 cm).
pub const DEFAULT_MAX_TRAVEL: f64 = 0.005;

/// A robot, the joints being planned, and the obstacles.
pub struct RobotWorld<'a> {
    model: &'a RobotModel,
    collision: &'a RobotCollision,
    obstacles: Vec<&'a CollisionObject>,
    links: Vec<LinkId>,
    joints: Vec<JointId>,
    base: Vec<f64>,
    margin: f64,
    sweep: SweepBound,
    max_travel: f64,
    fk: FkState,
    scratch: Vec<f64>,
    checks: usize,
}

impl<'a> RobotWorld<'a> {
    /// Plans `joints` of `model`, starting from the full configuration `base`
    /// (the other joints keep their values), among `obstacles`, with a clearance
    /// `margin` (m).
    pub fn new(
        model: &'a RobotModel,
        collision: &'a RobotCollision,
        obstacles: Vec<&'a CollisionObject>,
        joints: Vec<JointId>,
        base: Vec<f64>,
        margin: f64,
    ) -> Self {
        let links = (0..model.links.len())
            .filter(|&l| !collision.link_parts(l).is_empty())
            .collect();
        RobotWorld {
            model,
            collision,
            obstacles,
            links,
            joints,
            scratch: base.clone(),
            base,
            margin,
            sweep: SweepBound::new(model),
            max_travel: DEFAULT_MAX_TRAVEL,
            fk: FkState::new(model),
            checks: 0,
        }
    }

    /// Sets the largest travel of any link point between two checks (m).
    pub fn with_max_travel(mut self, max_travel: f64) -> Self {
        self.max_travel = max_travel;
        self
    }

    /// The full joint vector for a configuration of the planned joints.
    pub fn full(&self, q: &[f64]) -> Vec<f64> {
        let mut full = self.base.clone();
        for (&j, &v) in self.joints.iter().zip(q) {
            full[j] = v;
        }
        self.model.apply_mimics(&mut full);
        full
    }

    /// The planned joints' values in a full joint vector.
    pub fn project(&self, full: &[f64]) -> Vec<f64> {
        self.joints.iter().map(|&j| full[j]).collect()
    }

    /// Lower and upper limits of the planned joints.
    pub fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let lim = |j: &JointId| self.model.joints[*j].limits;
        (
            self.joints
                .iter()
                .map(|j| lim(j).lower.max(-std::f64::consts::TAU))
                .collect(),
            self.joints
                .iter()
                .map(|j| lim(j).upper.min(std::f64::consts::TAU))
                .collect(),
        )
    }

    /// The segment resolution: steps that keep every link point's travel under
    /// the world's `max_travel`.
    pub fn resolution(&self) -> Resolution<'a> {
        Resolution {
            model: self.model,
            joints: self.joints.clone(),
            base: self.base.clone(),
            sweep: self.sweep.clone(),
            max_travel: self.max_travel,
        }
    }

    /// Number of configurations checked so far.
    pub fn checks(&self) -> usize {
        self.checks
    }

    /// The pose of `link` for a configuration of the planned joints.
    pub fn link_pose(&mut self, q: &[f64], link: LinkId) -> Isometry3<f64> {
        self.scratch = self.full(q);
        self.model.forward_kinematics(&self.scratch, &mut self.fk);
        *self.fk.pose(link)
    }
}

impl Validity for RobotWorld<'_> {
    fn is_valid(&mut self, q: &[f64]) -> bool {
        self.checks += 1;
        for (&j, &v) in self.joints.iter().zip(q) {
            self.scratch[j] = v;
        }
        self.model.apply_mimics(&mut self.scratch);
        self.model.forward_kinematics(&self.scratch, &mut self.fk);
        self.collision
            .first_self_collision(&self.fk, self.margin)
            .is_none()
            && self
                .collision
                .first_collision(&self.fk, &self.links, &self.obstacles, self.margin)
                .is_none()
    }
}

/// The segment resolution of a [`RobotWorld`], as a value of its own so that a
/// planner can hold it while the world is borrowed for checks.
#[derive(Clone)]
pub struct Resolution<'a> {
    model: &'a RobotModel,
    joints: Vec<JointId>,
    base: Vec<f64>,
    sweep: SweepBound,
    max_travel: f64,
}

impl SegmentSteps for Resolution<'_> {
    fn steps(&self, a: &[f64], b: &[f64]) -> usize {
        let full = |q: &[f64]| {
            let mut f = self.base.clone();
            for (&j, &v) in self.joints.iter().zip(q) {
                f[j] = v;
            }
            self.model.apply_mimics(&mut f);
            f
        };
        self.sweep.steps(&full(a), &full(b), self.max_travel)
    }
}
