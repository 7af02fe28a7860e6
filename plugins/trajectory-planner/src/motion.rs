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
//! - **lift**: the palm moves `lift_height` straight up with the object attached;
//! - **retreat** (when asked): the palm moves `retreat_distance` straight back
//!   against the approach vector, the object still attached.
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

use tsukami_body::model::JointId;
use tsukami_msgs::motion::{JointTrajectory, MotionGrasp};
use tsukami_planner_kit::motion_check::checker::RobotWorld;
pub use tsukami_planner_kit::motion_check::phases::{check_path, Clearance, OPENINGS};
use tsukami_planner_kit::motion_check::phases::{check_phases, Blocked, PhaseParams, PhaseScene};
use tsukami_planner_kit::validate::Limits;
use tsukami_planner_kit::World;

use crate::assemble::{assemble, Phase};
use crate::error::MotionError;
use crate::goal::{resolve, Goal};
use crate::rounding::timed_phase;
use crate::rrt_connect::{plan_counted, Problem, RrtError, RrtParams};
use crate::shortcut::shortcut;
use crate::timing;
use crate::world::SharedWorld;

/// The planner's settings (plugin config keys of the same names).
#[derive(Debug, Clone, PartialEq)]
pub struct MotionConfig {
    /// Acceleration limit of a joint when neither the request nor the robot
    /// description gives one (rad/s², m/s²).
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
    /// How far a rounded corner of a phase's path may pass from its waypoint
    /// (joint units; [`crate::blend`]); a rounding that collides is tried at a
    /// quarter of it, then not at all (the motion stops at that phase's
    /// waypoints).
    pub blend_deviation: f64,
}

impl Default for MotionConfig {
    fn default() -> Self {
        // The phase checks' settings are the kit's, which the grasp planner
        // checks a grasp's phases with.
        let phases = PhaseParams::default();
        MotionConfig {
            acceleration: 2.0,
            default_velocity: 1.0,
            sample_dt: 0.05,
            max_travel: phases.max_travel,
            touch_tolerance: phases.touch_tolerance,
            shortcut_attempts: 50,
            rrt_step: 0.15,
            line_step: phases.line_step,
            support_clearance: phases.support_clearance,
            clearance: phases.clearance,
            blend_deviation: 0.2,
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
    /// Retreat after the lift (m; 0: none).
    pub retreat_distance: f64,
    /// Seed of the reach planner.
    pub seed: u64,
    /// Sample budget of the reach planner.
    pub max_samples: usize,
    /// The request's acceleration limit of every joint (rad/s², m/s²); `None`:
    /// each joint's from the robot description, else the config's.
    pub acceleration: Option<f64>,
    /// Check the grasp again on this world first (it was planned on another
    /// version): [`crate::revalidate::recheck`].
    pub recheck: bool,
    /// Safety distances from the obstacles.
    pub clearance: Clearance,
}

impl<'a> MotionQuery<'a> {
    /// The query of `grasp` from the full configuration `start` with the
    /// request's defaults (5 cm pre-grasp and lift, no retreat, 5000 reach
    /// samples, the default clearances, the robot's accelerations), `seed`.
    pub fn new(grasp: &'a MotionGrasp, start: Vec<f64>, seed: u64) -> Self {
        MotionQuery {
            grasp,
            start,
            lift_height: tsukami_msgs::motion::DEFAULT_LIFT_HEIGHT,
            pregrasp_distance: tsukami_msgs::motion::DEFAULT_PREGRASP_DISTANCE,
            retreat_distance: 0.0,
            seed,
            max_samples: 5000,
            acceleration: None,
            recheck: false,
            clearance: Clearance::default(),
        }
    }
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

fn project(full: &[f64], joints: &[JointId]) -> Vec<f64> {
    joints.iter().map(|&j| full[j]).collect()
}

fn blocked(b: Blocked) -> MotionError {
    MotionError::infeasible(b.reason, b.message)
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
    let goal = goal_of(world, query, limits)?;
    let params = PhaseParams {
        max_travel: cfg.max_travel,
        touch_tolerance: cfg.touch_tolerance,
        line_step: cfg.line_step,
        support_clearance: cfg.support_clearance,
        clearance: query.clearance,
        pregrasp_distance: query.pregrasp_distance,
        lift_height: query.lift_height,
        retreat_distance: query.retreat_distance,
    };
    let mut s = PhaseScene::new(
        world.robot,
        world.object,
        world.obstacles.clone(),
        goal,
        params,
    );
    let w = s.free(s.joints.clone(), &query.start);
    s.check(w, &[s.p(&query.start)]).map_err(|c| {
        MotionError::infeasible(
            "start_in_collision",
            format!("the start posture collides: {c}"),
        )
    })?;
    progress("approach", 0);
    let phases = check_phases(&mut s).map_err(blocked)?;
    let mut start_open = query.start.clone();
    for &j in &s.goal.hand {
        start_open[j] = s.goal.open[j];
    }
    s.model().apply_mimics(&mut start_open);
    let opening = [s.p(&query.start), s.p(&start_open)];
    let w = s.free(s.joints.clone(), &query.start);
    s.check(w, &opening).map_err(|c| {
        MotionError::infeasible(
            "start_in_collision",
            format!("opening the hand at the start collides: {c}"),
        )
    })?;
    progress("reach", 0);
    let (reach, samples) = reach_path(
        &mut s,
        query,
        &start_open,
        &phases.approach[0],
        variant,
        cfg,
        cancelled,
    )?;
    let mut reach_phase = vec![opening[0].clone()];
    reach_phase.extend(reach.iter().map(|q| s.p(q)));
    progress("close", samples);
    progress("lift", samples);
    progress("timing", samples);
    let approach = phases.approach.iter().map(|q| s.p(q)).collect();
    let trajectory = timed(
        &mut s,
        query,
        cfg,
        [
            reach_phase,
            approach,
            phases.close,
            phases.lift,
            phases.retreat,
        ],
    );
    progress("done", samples);
    Ok(Motion {
        trajectory,
        samples,
        checks: s.checks,
    })
}

/// The reach from the start (hand open) to the pre-grasp, as full configurations.
fn reach_path(
    s: &mut PhaseScene<'_>,
    query: &MotionQuery<'_>,
    start_open: &[f64],
    pre: &[f64],
    variant: Variant,
    cfg: &MotionConfig,
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
        step: cfg.rrt_step,
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
        shortcut(path, cfg.shortcut_attempts, query.seed, &mut w, &res)
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

/// The phases timed and joined, with the grasp's squeeze as the command from
/// the end of `close` on. Each phase's corners are rounded as much as
/// [`MotionConfig::blend_deviation`] allows without a collision
/// ([`crate::rounding::timed_phase`]).
fn timed(
    s: &mut PhaseScene<'_>,
    query: &MotionQuery<'_>,
    cfg: &MotionConfig,
    paths: [Vec<Vec<f64>>; 5],
) -> JointTrajectory {
    let limits = joint_limits(s.robot, &s.joints, cfg, query.acceleration);
    let names = s
        .joints
        .iter()
        .map(|&j| s.model().joints[j].name.clone())
        .collect();
    let (open, hand) = (s.goal.open.clone(), s.params.clearance.hand);
    let worlds = [
        s.free(s.joints.clone(), &query.start),
        s.touching(&open, hand),
        s.touching(&open, 0.0),
        s.carrying(),
        s.carrying(),
    ];
    let mut phases = Vec::with_capacity(5);
    for ((name, path), world) in ["reach", "approach", "close", "lift", "retreat"]
        .into_iter()
        .zip(paths)
        .zip(worlds)
    {
        // No retreat asked: the phase is the lifted posture alone.
        if name == "retreat" && path.len() < 2 {
            continue;
        }
        let points = timed_phase(s, world, &path, &limits, cfg.blend_deviation);
        phases.push(Phase { name, points });
    }
    let mut trajectory = assemble(names, &phases);
    crate::squeeze::apply(s.model(), &s.joints, &s.goal.squeeze, &mut trajectory);
    trajectory
}

/// [`plan_motion`] with the default config and world limits, every phase
/// (no variant), never cancelled, no progress: for tests, examples and
/// benchmarks.
pub fn plan_default(
    world: &World<'_, SharedWorld>,
    query: &MotionQuery<'_>,
) -> Result<Motion, MotionError> {
    plan_motion(
        world,
        query,
        &MotionConfig::default(),
        &Limits::default(),
        Variant::default(),
        &|| false,
        &mut |_, _| {},
    )
}

/// The time scaling's limits of `joints`: each joint's URDF velocity (the
/// config's `default_velocity` when it states none), its acceleration —
/// `acceleration` (a request's) when given, else the robot description's,
/// else the config's — and its jerk when the description states one.
pub fn joint_limits(
    robot: &tsukami_planner_kit::Robot,
    joints: &[JointId],
    cfg: &MotionConfig,
    acceleration: Option<f64>,
) -> timing::Limits {
    let velocity = joints
        .iter()
        .map(|&j| {
            let v = robot.model.joints[j].limits.velocity;
            if v.is_finite() && v > 0.0 {
                v
            } else {
                cfg.default_velocity
            }
        })
        .collect();
    let acceleration = joints
        .iter()
        .map(|&j| {
            acceleration
                .or(robot.acceleration.get(j).copied().flatten())
                .unwrap_or(cfg.acceleration)
        })
        .collect();
    // Jerk: the description's, for every joint or none (a joint it leaves
    // out is not limited).
    let jerk = match joints
        .iter()
        .any(|&j| robot.jerk.get(j).copied().flatten().is_some())
    {
        true => joints
            .iter()
            .map(|&j| {
                robot
                    .jerk
                    .get(j)
                    .copied()
                    .flatten()
                    .unwrap_or(f64::INFINITY)
            })
            .collect(),
        false => Vec::new(),
    };
    timing::Limits {
        velocity,
        acceleration,
        sample_dt: cfg.sample_dt,
        jerk,
    }
}
