//! The last phases of a grasp's motion, checked: approach, close, lift.
//!
//! What: [`check_phases`] takes a [`Goal`] in a world (robot, object,
//! obstacles) and finds, or refuses with a [`Blocked`] reason, the straight
//! approach from the pre-grasp to the grasp with the hand open, the closing of
//! the fingers from that opening, and the straight lift with the object
//! attached. [`PhaseScene`] holds what the checks share; the trajectory
//! planner plans its reach with it too.
//!
//! Why: a grasp whose approach, closing or lift is blocked cannot be executed,
//! however well it holds. The grasp planner runs these checks before it
//! returns a grasp (a blocked one is a rejection and the search moves on), and
//! the trajectory planner plans the same phases with the same functions, so
//! a returned grasp's phases are the ones the motion will take.
//!
//! How: every phase is checked at the same resolution ([`super::resolution`]:
//! no point of any link, or of the carried object, moves more than
//! `max_travel` between two checks), by [`super::checker::RobotWorld`]:
//! approach and close — the hand's links may touch the object up to
//! `touch_tolerance` (the fingers close on it; the palm of an envelope grasp
//! rests on it), every other link clear, the hand keeping its clearance from
//! the obstacles on the approach; lift — the object moves with the palm, clear
//! of every obstacle (those it rests on count once it has risen
//! `support_clearance`) and of every link but the hand's. The hand opens as
//! wide as [`OPENINGS`] allows; the closing is all joints together or else in
//! the grasp planner's order ([`Goal::sequential_close`]).

use std::fmt;

use nalgebra::Vector3;
use tsukami_body::collision::CollisionObject;
use tsukami_body::model::{JointId, RobotModel};

use super::cartesian::{palm_line, Line};
use super::checker::{Attached, Collision, ObjectRule, RobotWorld, DEFAULT_MAX_TRAVEL};
use super::goal::Goal;
use super::path::{lerp_into, SegmentSteps};
use crate::{Object, Robot};

/// How far the hand opens for the approach, tried in order: as wide as the
/// obstacles and the object let it (1: fingers straight).
pub const OPENINGS: [f64; 5] = [1.0, 0.75, 0.5, 0.25, 0.1];

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

impl Clearance {
    /// These distances with those `robot`'s description states over them.
    pub fn for_robot(self, robot: &Robot) -> Clearance {
        Clearance {
            body: robot.clearance.body.unwrap_or(self.body),
            hand: robot.clearance.hand.unwrap_or(self.hand),
        }
    }
}

/// The settings of the phase checks (the trajectory planner's config keys of
/// the same names; the grasp planner uses the defaults).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseParams {
    /// Largest travel of any link point between two collision checks (m).
    pub max_travel: f64,
    /// How deep a hand link may sink into the object while approaching and closing (m).
    pub touch_tolerance: f64,
    /// Largest palm travel between two IK solutions on a straight line (m).
    pub line_step: f64,
    /// How far the carried object rises before its supports are checked (m).
    pub support_clearance: f64,
    /// Safety distances from the obstacles.
    pub clearance: Clearance,
    /// How far back along the approach the pre-grasp palm pose is (m).
    pub pregrasp_distance: f64,
    /// How high the lift goes (m).
    pub lift_height: f64,
    /// How far the palm moves back against the approach after the lift,
    /// carrying the object (m; 0: no retreat).
    pub retreat_distance: f64,
}

impl Default for PhaseParams {
    fn default() -> Self {
        PhaseParams {
            max_travel: DEFAULT_MAX_TRAVEL,
            touch_tolerance: 0.001,
            line_step: 0.005,
            support_clearance: 0.002,
            clearance: Clearance::default(),
            pregrasp_distance: tsukami_msgs::motion::DEFAULT_PREGRASP_DISTANCE,
            lift_height: tsukami_msgs::motion::DEFAULT_LIFT_HEIGHT,
            retreat_distance: 0.0,
        }
    }
}

/// Why a phase cannot be taken: a wire reason (`approach_blocked`,
/// `close_blocked`, `lift_blocked`, `pregrasp_unreachable`,
/// `lift_unreachable`, `goal_in_collision`) and what blocks it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Blocked {
    /// The reason, as the trajectory planner's `details.reason`.
    pub reason: &'static str,
    /// What collides or fails, with the links and obstacles named.
    pub message: String,
}

impl fmt::Display for Blocked {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.reason, self.message)
    }
}

fn blocked(reason: &'static str, what: &str, c: &Collision) -> Blocked {
    Blocked {
        reason,
        message: format!("{what}: {c}"),
    }
}

/// The approach, close and lift of a grasp, as full configurations (approach,
/// lift) and as values of the scene's joints (close).
#[derive(Debug, Clone)]
pub struct Phases {
    /// Pre-grasp first, grasp (hand open) last.
    pub approach: Vec<Vec<f64>>,
    /// From the opening to the grasp's angles (scene joints).
    pub close: Vec<Vec<f64>>,
    /// Grasp first, lifted last (scene joints).
    pub lift: Vec<Vec<f64>>,
    /// Lifted first, retreated last (scene joints); the lifted posture alone
    /// when there is no retreat.
    pub retreat: Vec<Vec<f64>>,
}

/// Checks a polyline (values of `world`'s joints) at `world`'s resolution,
/// its first point included; the first collision found, if any.
pub fn check_path(world: &mut RobotWorld<'_>, path: &[Vec<f64>]) -> Result<(), Collision> {
    first_blocked(world, path).map_err(|(_, c)| c)
}

/// [`check_path`], naming where: the index `k` of the first segment
/// `path[k] → path[k + 1]` that collides (0 also when the first point does).
pub fn first_blocked(
    world: &mut RobotWorld<'_>,
    path: &[Vec<f64>],
) -> Result<(), (usize, Collision)> {
    let res = world.resolution();
    if let Some(c) = path.first().and_then(|q| world.first_hit(q)) {
        return Err((0, c));
    }
    for (k, w) in path.windows(2).enumerate() {
        let n = res.steps(&w[0], &w[1]);
        if n == usize::MAX {
            let c = Collision {
                link: "(segment)".into(),
                with: "no finite sweep bound".into(),
            };
            return Err((k, c));
        }
        let mut q = w[0].clone();
        for i in 1..=n {
            lerp_into(&w[0], &w[1], i as f64 / n as f64, &mut q);
            if let Some(c) = world.first_hit(&q) {
                return Err((k, c));
            }
        }
    }
    Ok(())
}

/// Everything the phase checks share: the robot, the object, the obstacles,
/// the goal, the joints a trajectory moves and the checks counted.
pub struct PhaseScene<'a> {
    /// The robot.
    pub robot: &'a Robot,
    /// The object to grasp.
    pub object: &'a Object,
    /// The obstacles.
    pub env: Vec<&'a CollisionObject>,
    /// The grasp.
    pub goal: Goal,
    /// The joints the phases move: the reach's, then the hand's.
    pub joints: Vec<JointId>,
    /// The settings.
    pub params: PhaseParams,
    /// Configurations checked so far.
    pub checks: usize,
}

impl<'a> PhaseScene<'a> {
    /// The scene of `goal`, its joints the reach's then the hand's.
    pub fn new(
        robot: &'a Robot,
        object: &'a Object,
        env: Vec<&'a CollisionObject>,
        goal: Goal,
        params: PhaseParams,
    ) -> Self {
        let mut joints = goal.reach.clone();
        joints.extend(
            goal.hand
                .iter()
                .copied()
                .filter(|j| !goal.reach.contains(j)),
        );
        PhaseScene {
            robot,
            object,
            env,
            goal,
            joints,
            params,
            checks: 0,
        }
    }

    /// The robot model.
    pub fn model(&self) -> &'a RobotModel {
        &self.robot.model
    }

    /// The robot among `obstacles`, the hand keeping `hand_clearance` from
    /// them, every other link the body clearance.
    pub fn robot_world(
        &self,
        obstacles: Vec<&'a CollisionObject>,
        joints: Vec<JointId>,
        base: &[f64],
        hand_clearance: f64,
    ) -> RobotWorld<'a> {
        let hand = self.robot.hand();
        RobotWorld::new(
            self.model(),
            &hand.collision,
            obstacles,
            joints,
            base.to_vec(),
            0.0,
        )
        .with_max_travel(self.params.max_travel)
        .with_clearance(&hand.links, hand_clearance, self.params.clearance.body)
    }

    /// Every link clear of the obstacles and the object, by the clearances.
    pub fn free(&self, joints: Vec<JointId>, base: &[f64]) -> RobotWorld<'a> {
        let mut all = self.env.clone();
        all.push(&self.object.collision);
        self.robot_world(all, joints, base, self.params.clearance.hand)
    }

    /// Hand links may touch the object; the hand keeps `hand_clearance` from
    /// the obstacles (the approach: the hand's; closing: none).
    pub fn touching(&self, base: &[f64], hand_clearance: f64) -> RobotWorld<'a> {
        let hand = self.robot.hand();
        self.robot_world(self.env.clone(), self.joints.clone(), base, hand_clearance)
            .with_object(ObjectRule {
                body: &self.object.collision,
                touching: hand.links.clone(),
                tolerance: self.params.touch_tolerance,
            })
    }

    /// The object carried by the palm from the grasp on.
    pub fn carrying(&self) -> RobotWorld<'a> {
        let hand = self.robot.hand();
        let object = self.object;
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
                    .intersects(self.env[i], self.params.support_clearance)
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
            clearance: self.params.support_clearance,
        };
        self.robot_world(
            self.env.clone(),
            self.joints.clone(),
            &self.goal.closed,
            0.0,
        )
        .with_attached(attached)
    }

    /// Checks `path` in `world`, counting the checks.
    pub fn check(&mut self, mut world: RobotWorld<'_>, path: &[Vec<f64>]) -> Result<(), Collision> {
        let out = check_path(&mut world, path);
        self.checks += world.checks();
        out
    }

    /// The scene's joint values of a full configuration.
    pub fn p(&self, full: &[f64]) -> Vec<f64> {
        self.joints.iter().map(|&j| full[j]).collect()
    }
}

/// The approach, close and lift of `s.goal` (the goal opened as wide as the
/// approach and the closing allow), or why one is blocked: the grasp posture
/// first, then the widest opening's failure when none works.
pub fn check_phases(s: &mut PhaseScene<'_>) -> Result<Phases, Blocked> {
    let w = s.touching(&s.goal.closed, 0.0);
    s.check(w, &[s.p(&s.goal.closed)])
        .map_err(|c| blocked("goal_in_collision", "the grasp posture collides", &c))?;
    let approach = open_and_approach(s)?;
    let close = close_clear(s)?;
    let (lift, lifted) = lift_path(s)?;
    let retreat = retreat_path(s, &lifted)?;
    Ok(Phases {
        approach,
        close,
        lift,
        retreat,
    })
}

/// The close from the current opening to the grasp's angles, its postures
/// (the opening first), with no link of the hand sinking into the object or
/// hitting anything: all joints together, or else in the grasp planner's
/// order ([`Goal::sequential_close`]); the first failure when neither works.
pub fn close_clear(s: &mut PhaseScene<'_>) -> Result<Vec<Vec<f64>>, Blocked> {
    let open = s.p(&s.goal.open);
    let linear = vec![open.clone(), s.p(&s.goal.closed)];
    let mut sequential = vec![open];
    sequential.extend(s.goal.sequential_close(s.model()).iter().map(|q| s.p(q)));
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
    Err(blocked("close_blocked", "closing the hand collides", &c))
}

/// Opens the hand as wide as [`OPENINGS`] allows at the grasp, along the
/// approach and while the fingers close from it (a finger opened wide may
/// sweep through the object on its way back); the approach path. The widest
/// opening's failure when none works.
pub fn open_and_approach(s: &mut PhaseScene<'_>) -> Result<Vec<Vec<f64>>, Blocked> {
    let mut first = None;
    for opening in OPENINGS {
        s.goal.open_by(s.model(), opening);
        let w = s.touching(&s.goal.open, s.params.clearance.hand);
        let tried = s
            .check(w, &[s.p(&s.goal.open)])
            .map_err(|c| {
                blocked(
                    "goal_in_collision",
                    "the grasp posture with the hand open collides",
                    &c,
                )
            })
            .and_then(|()| approach_path(s))
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
fn approach_path(s: &mut PhaseScene<'_>) -> Result<Vec<Vec<f64>>, Blocked> {
    let hand = s.robot.hand();
    let distance = s.params.pregrasp_distance;
    let line = Line {
        start: s.goal.palm,
        direction: -s.goal.approach,
        length: distance,
        step: s.params.line_step,
    };
    let mut path = palm_line(s.model(), hand.palm, &s.goal.reach, &s.goal.open, &line)
        .ok_or_else(|| Blocked {
            reason: "pregrasp_unreachable",
            message: format!("the palm cannot back {distance} m out of the grasp along the approach vector {:?} (no IK solution on the line)", s.goal.approach.as_slice()),
        })?;
    path.reverse();
    path.push(s.goal.open.clone());
    let projected: Vec<Vec<f64>> = path.iter().map(|q| s.p(q)).collect();
    let w = s.touching(&s.goal.open, s.params.clearance.hand);
    s.check(w, &projected).map_err(|c| {
        blocked(
            "approach_blocked",
            "the straight approach to the grasp collides",
            &c,
        )
    })?;
    Ok(path)
}

/// The lift, grasp first, as scene-joint values, and the lifted posture (full).
pub fn lift_path(s: &mut PhaseScene<'_>) -> Result<(Vec<Vec<f64>>, Vec<f64>), Blocked> {
    let height = s.params.lift_height;
    let line = Line {
        start: s.goal.palm,
        direction: Vector3::z(),
        length: height,
        step: s.params.line_step,
    };
    let from = s.goal.closed.clone();
    carried_line(s, &from, &line, "lift")
}

/// The retreat from the lifted posture `lifted` (full): the palm
/// `retreat_distance` straight back against the approach, the object carried;
/// scene-joint values, the lifted posture first.
pub fn retreat_path(s: &mut PhaseScene<'_>, lifted: &[f64]) -> Result<Vec<Vec<f64>>, Blocked> {
    let line = Line {
        start: nalgebra::Translation3::from(Vector3::z() * s.params.lift_height.max(0.0))
            * s.goal.palm,
        direction: -s.goal.approach,
        length: s.params.retreat_distance,
        step: s.params.line_step,
    };
    carried_line(s, lifted, &line, "retreat").map(|(path, _)| path)
}

/// A straight palm line from the full posture `from` with the object carried
/// ([`PhaseScene::carrying`]): its scene-joint values (`from` first) and its
/// last full posture; `<what>_unreachable` or `<what>_blocked` otherwise.
fn carried_line(
    s: &mut PhaseScene<'_>,
    from: &[f64],
    line: &Line,
    what: &'static str,
) -> Result<(Vec<Vec<f64>>, Vec<f64>), Blocked> {
    let mut path = vec![s.p(from)];
    if line.length <= 0.0 {
        return Ok((path, from.to_vec()));
    }
    let hand = s.robot.hand();
    let (unreachable, blocked_reason) = match what {
        "lift" => ("lift_unreachable", "lift_blocked"),
        _ => ("retreat_unreachable", "retreat_blocked"),
    };
    let length = line.length;
    let up = palm_line(s.model(), hand.palm, &s.goal.reach, from, line).ok_or_else(|| Blocked {
        reason: unreachable,
        message: format!(
            "the palm cannot move {length} m in the {what} (no IK solution on the line)"
        ),
    })?;
    path.extend(up.iter().map(|q| s.p(q)));
    let w = s.carrying();
    s.check(w, &path).map_err(|c| {
        blocked(
            blocked_reason,
            &format!("the {what} with the object collides"),
            &c,
        )
    })?;
    let last = up.last().cloned().unwrap_or_else(|| from.to_vec());
    Ok((path, last))
}
