//! A grasp's whole motion: reach, approach, close, lift — planned, checked, timed.
//!
//! What: [`plan_motion`] turns a start configuration and a grasp into one timed
//! trajectory over the joints the grasp uses (body joints, arm, hand):
//! - **reach**: the hand opens where it is, then RRT-Connect
//!   ([`crate::rrt_connect`]) and shortcutting ([`crate::shortcut`]) move the
//!   body and arm joints to the pre-grasp posture, clear of the obstacles and the
//!   object;
//! - **approach**: the palm moves in a straight line along the approach vector
//!   from `pregrasp_distance` out to the grasp pose ([`crate::cartesian`]);
//! - **close**: the fingers move from open (as wide as [`OPENINGS`] allows
//!   there: fully straight if nothing is in the way) to the grasp's angles;
//! - **lift**: the palm moves `lift_height` straight up with the object attached.
//!
//! A grasp with a `squeeze` gives the last `close` point and every `lift` point
//! a `command` ([`crate::squeeze`]): the squeezed fingers commanded to their
//! targets beyond contact, held through the lift. Every check below runs on the
//! points' positions, the physical posture; the command is not a posture.
//!
//! Why: every phase is checked at the same resolution ([`crate::resolution`]: no
//! point of any link, or of the carried object, moves more than `max_travel`
//! between two checks), against the obstacles, the object, the robot itself and
//! — after closing — the carried object, so no returned trajectory passes
//! through anything; when one cannot be found the error names why.
//!
//! How: the rules per phase ([`crate::checker`]): reach — every link clear of
//! every obstacle and of the object; approach and close — the hand's links may
//! touch the object up to `touch_tolerance` (the fingers close on it; the palm
//! of an envelope grasp rests on it), every other link clear; lift — the object
//! moves with the palm, clear of every obstacle (those it rests on count once it
//! has risen `support_clearance`) and of every link but the hand's.

use nalgebra::Vector3;
use tsukami_body::collision::CollisionObject;
use tsukami_body::model::{JointId, RobotModel};
use tsukami_msgs::motion::{JointTrajectory, MotionGrasp};
use tsukami_planner_kit::validate::Limits;
use tsukami_planner_kit::World;

use crate::assemble::{assemble, Phase};
use crate::cartesian::{palm_line, Line};
use crate::checker::{Attached, Collision, ObjectRule, RobotWorld, DEFAULT_MAX_TRAVEL};
use crate::error::MotionError;
use crate::goal::{resolve, Goal};
use crate::rrt_connect::{lerp_into, plan_counted, Problem, RrtError, RrtParams, SegmentSteps};
use crate::shortcut::shortcut;
use crate::timing;
use crate::world::SharedWorld;

/// The planner's settings (plugin config keys of the same names).
#[derive(Debug, Clone, PartialEq)]
pub struct MotionConfig {
    /// Acceleration limit of every joint when a request gives none (rad/s², m/s²).
    pub acceleration: f64,
    /// Velocity limit of a joint whose URDF gives none (rad/s, m/s).
    pub default_velocity: f64,
    /// Longest interval between two trajectory points (s).
    pub sample_dt: f64,
    /// Largest travel of any link point between two collision checks (m).
    pub max_travel: f64,
    /// How deep a hand link may sink into the object while approaching and closing (m).
    pub touch_tolerance: f64,
    /// Shortcut attempts on the reach path.
    pub shortcut_attempts: usize,
    /// Longest RRT-Connect extension (joint units).
    pub rrt_step: f64,
    /// Largest palm travel between two IK solutions on a straight line (m).
    pub line_step: f64,
    /// How far the carried object rises before its supports are checked (m).
    pub support_clearance: f64,
    /// Safety distances from the obstacles when a request gives none.
    pub clearance: Clearance,
}

/// Safety distances every motion keeps from the obstacles (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearance {
    /// Every link but the hand's, in every phase.
    pub body: f64,
    /// The hand's links in the reach and the approach (from `close` on, the hand
    /// may touch what the object rests on).
    pub hand: f64,
}

impl Default for Clearance {
    fn default() -> Self {
        Clearance {
            body: 0.010,
            hand: 0.003,
        }
    }
}

impl Default for MotionConfig {
    fn default() -> Self {
        MotionConfig {
            acceleration: 2.0,
            default_velocity: 1.0,
            sample_dt: 0.05,
            max_travel: DEFAULT_MAX_TRAVEL,
            touch_tolerance: 0.001,
            shortcut_attempts: 50,
            rrt_step: 0.15,
            line_step: 0.005,
            support_clearance: 0.002,
            clearance: Clearance::default(),
        }
    }
}

/// One motion query, its values already checked.
#[derive(Debug, Clone)]
pub struct MotionQuery<'a> {
    /// The grasp.
    pub grasp: &'a MotionGrasp,
    /// The start (full joint vector).
    pub start: Vec<f64>,
    /// Lift height (m).
    pub lift_height: f64,
    /// Pre-grasp distance (m).
    pub pregrasp_distance: f64,
    /// Seed of the reach planner.
    pub seed: u64,
    /// Sample budget of the reach planner.
    pub max_samples: usize,
    /// Acceleration limit (rad/s², m/s²).
    pub acceleration: f64,
    /// Check the grasp again on this world first (it was planned on another
    /// version): [`crate::revalidate::recheck`].
    pub recheck: bool,
    /// Safety distances from the obstacles.
    pub clearance: Clearance,
}

/// A planned motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// The timed trajectory.
    pub trajectory: JointTrajectory,
    /// Samples the reach planner drew.
    pub samples: usize,
    /// Configurations checked.
    pub checks: usize,
}

/// Switches a phase of the pipeline off, for comparisons (benchmarks).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Variant {
    /// Skip shortcutting the reach path.
    pub no_shortcut: bool,
}

/// Checks a polyline (values of `world`'s joints) at `world`'s resolution,
/// its first point included; the first collision found, if any.
pub fn check_path(world: &mut RobotWorld<'_>, path: &[Vec<f64>]) -> Result<(), Collision> {
    let res = world.resolution();
    if let Some(c) = path.first().and_then(|q| world.first_hit(q)) {
        return Err(c);
    }
    for w in path.windows(2) {
        let n = res.steps(&w[0], &w[1]);
        if n == usize::MAX {
            return Err(Collision {
                link: "(segment)".into(),
                with: "no finite sweep bound".into(),
            });
        }
        let mut q = w[0].clone();
        for i in 1..=n {
            lerp_into(&w[0], &w[1], i as f64 / n as f64, &mut q);
            if let Some(c) = world.first_hit(&q) {
                return Err(c);
            }
        }
    }
    Ok(())
}

fn project(full: &[f64], joints: &[JointId]) -> Vec<f64> {
    joints.iter().map(|&j| full[j]).collect()
}

/// Everything the phases share.
struct Scene<'a> {
    model: &'a RobotModel,
    world: &'a World<'a, SharedWorld>,
    goal: Goal,
    joints: Vec<JointId>,
    env: Vec<&'a CollisionObject>,
    cfg: &'a MotionConfig,
    clearance: Clearance,
    checks: usize,
}

impl<'a> Scene<'a> {
    /// The robot among `obstacles`, the hand keeping `hand_clearance` from
    /// them, every other link the body clearance.
    fn robot_world(
        &self,
        obstacles: Vec<&'a CollisionObject>,
        joints: Vec<JointId>,
        base: &[f64],
        hand_clearance: f64,
    ) -> RobotWorld<'a> {
        let hand = self.world.robot.hand();
        RobotWorld::new(
            self.model,
            &hand.collision,
            obstacles,
            joints,
            base.to_vec(),
            0.0,
        )
        .with_max_travel(self.cfg.max_travel)
        .with_clearance(&hand.links, hand_clearance, self.clearance.body)
    }

    /// Every link clear of the obstacles and the object, by the clearances.
    fn free(&self, joints: Vec<JointId>, base: &[f64]) -> RobotWorld<'a> {
        let mut all = self.env.clone();
        all.push(&self.world.object.collision);
        self.robot_world(all, joints, base, self.clearance.hand)
    }

    /// Hand links may touch the object; the hand keeps `hand_clearance` from
    /// the obstacles (the approach: the hand's; closing: none).
    fn touching(&self, base: &[f64], hand_clearance: f64) -> RobotWorld<'a> {
        let hand = self.world.robot.hand();
        self.robot_world(self.env.clone(), self.joints.clone(), base, hand_clearance)
            .with_object(ObjectRule {
                body: &self.world.object.collision,
                touching: hand.links.clone(),
                tolerance: self.cfg.touch_tolerance,
            })
    }

    /// The object carried by the palm from the grasp on.
    fn carrying(&self) -> RobotWorld<'a> {
        let hand = self.world.robot.hand();
        let object = self.world.object;
        let relative = self.goal.palm.inverse() * object.pose;
        let radius = object
            .mesh
            .vertices
            .iter()
            .map(|v| (relative * v).coords.norm())
            .fold(0.0, f64::max);
        let supports = (0..self.env.len())
            .filter(|&i| {
                object
                    .collision
                    .intersects(self.env[i], self.cfg.support_clearance)
            })
            .collect();
        let attached = Attached {
            body: object.collision.clone(),
            link: hand.palm,
            relative,
            radius,
            holding: hand.links.clone(),
            supports,
            origin: object.pose.translation.vector,
            clearance: self.cfg.support_clearance,
        };
        self.robot_world(
            self.env.clone(),
            self.joints.clone(),
            &self.goal.closed,
            0.0,
        )
        .with_attached(attached)
    }

    fn check(&mut self, mut world: RobotWorld<'_>, path: &[Vec<f64>]) -> Result<(), Collision> {
        let out = check_path(&mut world, path);
        self.checks += world.checks();
        out
    }

    fn p(&self, full: &[f64]) -> Vec<f64> {
        project(full, &self.joints)
    }
}

fn infeasible(reason: &'static str, what: &str, c: &Collision) -> MotionError {
    MotionError::infeasible(reason, format!("{what}: {c}"))
}

/// The query's goal on `world`, checked again on it first when the query asks
/// ([`crate::revalidate::recheck`]).
fn goal_of(
    world: &World<'_, SharedWorld>,
    query: &MotionQuery<'_>,
    limits: &Limits,
) -> Result<Goal, MotionError> {
    let goal = resolve(world.robot, query.grasp, &query.start, limits)?;
    if query.recheck {
        crate::revalidate::recheck(world, query.grasp, &goal)?;
    }
    Ok(goal)
}

/// Plans the motion of `query` in `world`. `cancelled` is polled once per reach
/// sample; `progress` hears each phase as it starts, with the samples drawn.
pub fn plan_motion(
    world: &World<'_, SharedWorld>,
    query: &MotionQuery<'_>,
    cfg: &MotionConfig,
    limits: &Limits,
    variant: Variant,
    cancelled: &dyn Fn() -> bool,
    progress: &mut dyn FnMut(&str, usize),
) -> Result<Motion, MotionError> {
    let model = &world.robot.model;
    let goal = goal_of(world, query, limits)?;
    let mut joints = goal.reach.clone();
    joints.extend(
        goal.hand
            .iter()
            .copied()
            .filter(|j| !goal.reach.contains(j)),
    );
    let mut s = Scene {
        model,
        world,
        goal,
        joints,
        env: world.obstacles.clone(),
        cfg,
        clearance: query.clearance,
        checks: 0,
    };
    let w = s.free(s.joints.clone(), &query.start);
    s.check(w, &[s.p(&query.start)])
        .map_err(|c| infeasible("start_in_collision", "the start posture collides", &c))?;
    let w = s.touching(&s.goal.closed, 0.0);
    s.check(w, &[s.p(&s.goal.closed)])
        .map_err(|c| infeasible("goal_in_collision", "the grasp posture collides", &c))?;
    progress("approach", 0);
    let approach = open_and_approach(&mut s, query.pregrasp_distance)?;
    let mut start_open = query.start.clone();
    for &j in &s.goal.hand {
        start_open[j] = s.goal.open[j];
    }
    model.apply_mimics(&mut start_open);
    let opening = [s.p(&query.start), s.p(&start_open)];
    let w = s.free(s.joints.clone(), &query.start);
    s.check(w, &opening).map_err(|c| {
        infeasible(
            "start_in_collision",
            "opening the hand at the start collides",
            &c,
        )
    })?;
    progress("reach", 0);
    let (reach, samples) =
        reach_path(&mut s, query, &start_open, &approach[0], variant, cancelled)?;
    let mut reach_phase = vec![opening[0].clone()];
    reach_phase.extend(reach.iter().map(|q| s.p(q)));
    progress("close", samples);
    let close = close_clear(&mut s)?;
    progress("lift", samples);
    let lift = lift_path(&mut s, query.lift_height)?;
    progress("timing", samples);
    let trajectory = timed(
        &s,
        query,
        [
            reach_phase,
            approach.iter().map(|q| s.p(q)).collect(),
            close,
            lift,
        ],
    );
    progress("done", samples);
    Ok(Motion {
        trajectory,
        samples,
        checks: s.checks,
    })
}

/// How far the hand opens for the approach, tried in order: as wide as the
/// obstacles and the object let it (1: fingers straight).
pub const OPENINGS: [f64; 4] = [1.0, 0.75, 0.5, 0.25];

/// The close from the current opening to the grasp's angles, its postures
/// (the opening first), with no link of the hand sinking into the object or
/// hitting anything: all joints together, or else in the grasp planner's
/// order ([`Goal::sequential_close`]); the first failure when neither works.
fn close_clear(s: &mut Scene<'_>) -> Result<Vec<Vec<f64>>, MotionError> {
    let open = s.p(&s.goal.open);
    let linear = vec![open.clone(), s.p(&s.goal.closed)];
    let mut sequential = vec![open];
    sequential.extend(s.goal.sequential_close(s.model).iter().map(|q| s.p(q)));
    let mut first = None;
    for path in [linear, sequential] {
        let w = s.touching(&s.goal.open, 0.0);
        match s.check(w, &path) {
            Ok(()) => return Ok(path),
            Err(c) => {
                first.get_or_insert(c);
            }
        }
    }
    let c = first.expect("two paths were tried");
    Err(infeasible("close_blocked", "closing the hand collides", &c))
}

/// Opens the hand as wide as [`OPENINGS`] allows at the grasp, along the
/// approach and while the fingers close from it (a finger opened wide may
/// sweep through the object on its way back); the approach path. The widest
/// opening's failure when none works.
fn open_and_approach(s: &mut Scene<'_>, distance: f64) -> Result<Vec<Vec<f64>>, MotionError> {
    let mut first = None;
    for opening in OPENINGS {
        s.goal.open_by(s.model, opening);
        let w = s.touching(&s.goal.open, s.clearance.hand);
        let tried = s
            .check(w, &[s.p(&s.goal.open)])
            .map_err(|c| {
                infeasible(
                    "goal_in_collision",
                    "the grasp posture with the hand open collides",
                    &c,
                )
            })
            .and_then(|()| approach_path(s, distance))
            .and_then(|path| close_clear(s).map(|_| path));
        match tried {
            Ok(path) => return Ok(path),
            Err(e) => {
                first.get_or_insert(e);
            }
        }
    }
    Err(first.expect("OPENINGS is not empty"))
}

/// The approach, pre-grasp first, grasp (hand open) last, as full configurations.
fn approach_path(s: &mut Scene<'_>, distance: f64) -> Result<Vec<Vec<f64>>, MotionError> {
    let hand = s.world.robot.hand();
    let line = Line {
        start: s.goal.palm,
        direction: -s.goal.approach,
        length: distance,
        step: s.cfg.line_step,
    };
    let mut path = palm_line(s.model, hand.palm, &s.goal.reach, &s.goal.open, &line).ok_or_else(|| {
        MotionError::infeasible(
            "pregrasp_unreachable",
            format!("the palm cannot back {distance} m out of the grasp along the approach vector {:?} (no IK solution on the line)", s.goal.approach.as_slice()),
        )
    })?;
    path.reverse();
    path.push(s.goal.open.clone());
    let projected: Vec<Vec<f64>> = path.iter().map(|q| s.p(q)).collect();
    let w = s.touching(&s.goal.open, s.clearance.hand);
    s.check(w, &projected).map_err(|c| {
        infeasible(
            "approach_blocked",
            "the straight approach to the grasp collides",
            &c,
        )
    })?;
    Ok(path)
}

/// The reach from the start (hand open) to the pre-grasp, as full configurations.
fn reach_path(
    s: &mut Scene<'_>,
    query: &MotionQuery<'_>,
    start_open: &[f64],
    pre: &[f64],
    variant: Variant,
    cancelled: &dyn Fn() -> bool,
) -> Result<(Vec<Vec<f64>>, usize), MotionError> {
    let mut w = s.free(s.goal.reach.clone(), start_open);
    let (lower, upper) = w.bounds();
    let (a, b) = (
        project(start_open, &s.goal.reach),
        project(pre, &s.goal.reach),
    );
    let problem = Problem {
        lower: &lower,
        upper: &upper,
        start: &a,
        goal: &b,
    };
    let params = RrtParams {
        max_samples: query.max_samples,
        step: s.cfg.rrt_step,
        seed: query.seed,
    };
    let res = w.resolution();
    let planned = plan_counted(&problem, &params, &mut w, &res, cancelled);
    let (path, samples) = match planned {
        Ok(found) => found,
        Err(e) => {
            s.checks += w.checks();
            return Err(reach_error(e, &mut w, &a, &b, query.seed));
        }
    };
    let path = if variant.no_shortcut {
        path
    } else {
        shortcut(path, s.cfg.shortcut_attempts, query.seed, &mut w, &res)
    };
    s.checks += w.checks();
    Ok((path.iter().map(|q| w.full(q)).collect(), samples))
}

fn reach_error(
    e: RrtError,
    w: &mut RobotWorld<'_>,
    a: &[f64],
    b: &[f64],
    seed: u64,
) -> MotionError {
    let named = |w: &mut RobotWorld<'_>, q: &[f64]| {
        w.first_hit(q).map_or_else(
            || "it is outside the joint limits".to_owned(),
            |c| c.to_string(),
        )
    };
    match e {
        RrtError::StartInvalid => MotionError::infeasible("start_in_collision", format!("the start posture (hand open): {}", named(w, a))),
        RrtError::GoalInvalid => MotionError::infeasible("goal_in_collision", format!("the pre-grasp posture: {}", named(w, b))),
        RrtError::Exhausted { samples } => MotionError::Infeasible {
            reason: "no_path",
            message: format!("no collision-free reach to the pre-grasp posture within {samples} samples (seed {seed})"),
            samples: samples.min(u32::MAX as usize) as u32,
        },
        RrtError::Cancelled => MotionError::Cancelled,
    }
}

/// The lift, grasp first, as trajectory-joint values.
fn lift_path(s: &mut Scene<'_>, height: f64) -> Result<Vec<Vec<f64>>, MotionError> {
    let mut path = vec![s.p(&s.goal.closed)];
    if height <= 0.0 {
        return Ok(path);
    }
    let hand = s.world.robot.hand();
    let line = Line {
        start: s.goal.palm,
        direction: Vector3::z(),
        length: height,
        step: s.cfg.line_step,
    };
    let up =
        palm_line(s.model, hand.palm, &s.goal.reach, &s.goal.closed, &line).ok_or_else(|| {
            MotionError::infeasible(
                "lift_unreachable",
                format!(
                    "the palm cannot rise {height} m from the grasp (no IK solution on the line)"
                ),
            )
        })?;
    path.extend(up.iter().map(|q| s.p(q)));
    let w = s.carrying();
    s.check(w, &path)
        .map_err(|c| infeasible("lift_blocked", "lifting the object collides", &c))?;
    Ok(path)
}

/// The phases timed and joined, with the grasp's squeeze as the command from
/// the end of `close` on.
fn timed(s: &Scene<'_>, query: &MotionQuery<'_>, paths: [Vec<Vec<f64>>; 4]) -> JointTrajectory {
    let velocity = s
        .joints
        .iter()
        .map(|&j| {
            let v = s.model.joints[j].limits.velocity;
            if v.is_finite() && v > 0.0 {
                v
            } else {
                s.cfg.default_velocity
            }
        })
        .collect();
    let limits = timing::Limits {
        velocity,
        acceleration: vec![query.acceleration; s.joints.len()],
        sample_dt: s.cfg.sample_dt,
    };
    let names = s
        .joints
        .iter()
        .map(|&j| s.model.joints[j].name.clone())
        .collect();
    let [reach, approach, close, lift] = paths;
    let phases = [
        Phase {
            name: "reach",
            path: reach,
        },
        Phase {
            name: "approach",
            path: approach,
        },
        Phase {
            name: "close",
            path: close,
        },
        Phase {
            name: "lift",
            path: lift,
        },
    ];
    let mut trajectory = assemble(names, &phases, &limits);
    crate::squeeze::apply(s.model, &s.joints, &s.goal.squeeze, &mut trajectory);
    trajectory
}
