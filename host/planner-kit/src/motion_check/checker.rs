//! The collision test of a motion: a robot among obstacles, for a subset of its
//! joints.
//!
//! What: [`RobotWorld`] answers [`Validity`] (is this configuration of the planned
//! joints free of self-collision and of collision with every obstacle?) and its
//! [`Resolution`] answers [`SegmentSteps`] (how many checks a straight segment needs so that no link
//! point moves more than `max_travel` between two of them, see
//! [`super::resolution`]).
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
//! obstacles with the margin decide (each link keeps its clearance from the
//! obstacles, [`RobotWorld::with_clearance`]). Two optional rules serve the grasp's last
//! phases: [`ObjectRule`] (the object to grasp, which some hand links may touch
//! up to a depth while the hand closes on it) and [`Attached`] (the grasped object
//! moving with the hand, checked against the obstacles and the rest of the robot).
//! [`RobotWorld::first_hit`] names what collides. The first check of a world
//! covers every link; later ones only the links the planned joints move (the
//! others keep the pose the first check saw), and only link pairs that move
//! relative to each other (two links past the same last planned joint — the
//! fingers of a hand the reach carries — keep the relative pose the first
//! check saw). Each check places the links once (world pose and AABB of every part,
//! `tsukami_body::collision::Placement`); pairs whose AABBs are apart skip the
//! exact test. Every check is counted.

use nalgebra::{Isometry3, Vector3};
use tsukami_body::collision::{CollisionObject, Placement, RobotCollision};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{JointId, LinkId, RobotModel};

use super::bodies::Bodies;
use super::path::{SegmentSteps, Validity};
use super::resolution::SweepBound;

/// Default largest travel of any link point between two checks of a segment:
/// half of the thinnest obstacle the planner promises not to skip (1 cm).
pub const DEFAULT_MAX_TRAVEL: f64 = 0.005;

/// A robot, the joints being planned, and the obstacles.
pub struct RobotWorld<'a> {
    model: &'a RobotModel,
    collision: &'a RobotCollision,
    /// The link pairs checked for self-collision at the first check.
    all_pairs: Vec<(LinkId, LinkId)>,
    /// The rigid bodies the planned joints move: every check after the first.
    bodies: Bodies,
    obstacles: Vec<&'a CollisionObject>,
    links: Vec<LinkId>,
    /// Links with geometry that the planned joints move.
    moving: Vec<LinkId>,
    /// The links' parts at the configuration checked last.
    placement: Placement,
    /// Scratch: the moving links near an obstacle.
    near: Vec<LinkId>,
    joints: Vec<JointId>,
    base: Vec<f64>,
    margin: f64,
    /// Per link: the distance it must keep from every obstacle (m).
    clearance: Vec<f64>,
    /// The largest of `clearance` (the broad phase's reach).
    max_clearance: f64,
    sweep: SweepBound,
    max_travel: f64,
    fk: FkState,
    scratch: Vec<f64>,
    checks: usize,
    object: Option<ObjectRule<'a>>,
    /// Links that may not touch the object (all; moving), with `object`.
    strict: [Vec<LinkId>; 2],
    attached: Option<Attached>,
    /// Links checked against the attached object, with `attached`.
    carrying: Vec<LinkId>,
}

/// The object to grasp as a body some hand links may touch.
#[derive(Clone)]
pub struct ObjectRule<'a> {
    /// The object.
    pub body: &'a CollisionObject,
    /// Links that may touch it (checked for depth, not overlap).
    pub touching: Vec<LinkId>,
    /// How deep a touching link may sink into the object (m).
    pub tolerance: f64,
}

/// A grasped object carried by a link.
#[derive(Clone)]
pub struct Attached {
    /// The object, moved with the link.
    pub body: CollisionObject,
    /// The link holding it.
    pub link: LinkId,
    /// The object's pose in the link's frame.
    pub relative: Isometry3<f64>,
    /// The farthest any point of the object is from the link's frame origin (m).
    pub radius: f64,
    /// Links not checked against it (the hand holding it).
    pub holding: Vec<LinkId>,
    /// Obstacles it rests on at the grasp (indices into the world's obstacles),
    /// not checked until it has moved `clearance` away from its grasp pose.
    pub supports: Vec<usize>,
    /// The object's position at the grasp.
    pub origin: Vector3<f64>,
    /// Distance after which the supports are checked too (m).
    pub clearance: f64,
}

/// What a configuration collides with: a link and the other body.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Collision {
    /// The robot link (or `grasped object`).
    pub link: String,
    /// The other body: an obstacle's name, `object`, or `link <name>`.
    pub with: String,
}

impl std::fmt::Display for Collision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "`{}` collides with {}", self.link, self.with)
    }
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
        let links: Vec<LinkId> = (0..model.links.len())
            .filter(|&l| !collision.link_parts(l).is_empty())
            .collect();
        let bodies = Bodies::new(model, collision, &links, &joints);
        RobotWorld {
            model,
            collision,
            all_pairs: collision.self_pairs(),
            moving: bodies.moving_links(),
            bodies,
            placement: Placement::default(),
            near: Vec::new(),
            obstacles,
            links,
            joints,
            scratch: base.clone(),
            base,
            margin,
            clearance: vec![margin; model.links.len()],
            max_clearance: margin,
            sweep: SweepBound::new(model),
            max_travel: DEFAULT_MAX_TRAVEL,
            fk: FkState::new(model),
            checks: 0,
            object: None,
            strict: [Vec::new(), Vec::new()],
            attached: None,
            carrying: Vec::new(),
        }
    }

    /// Adds the object to grasp, which `rule.touching` links may touch.
    pub fn with_object(mut self, rule: ObjectRule<'a>) -> Self {
        let strict = |links: &[LinkId]| {
            links
                .iter()
                .copied()
                .filter(|l| !rule.touching.contains(l))
                .collect()
        };
        self.strict = [strict(&self.links), strict(&self.moving)];
        self.object = Some(rule);
        self
    }

    /// Attaches a grasped object to a link; the segment resolution then counts
    /// the object's reach from that link.
    pub fn with_attached(mut self, attached: Attached) -> Self {
        self.sweep = SweepBound::with_attached(self.model, &[(attached.link, attached.radius)]);
        self.carrying = self
            .links
            .iter()
            .copied()
            .filter(|l| !attached.holding.contains(l))
            .collect();
        self.attached = Some(attached);
        self
    }

    /// The safety distance from the obstacles: `hand` for the `hand_links`,
    /// `body` for every other link (m); the self-collision margin is unchanged.
    pub fn with_clearance(mut self, hand_links: &[LinkId], hand: f64, body: f64) -> Self {
        for (l, c) in self.clearance.iter_mut().enumerate() {
            *c = if hand_links.contains(&l) { hand } else { body };
        }
        self.max_clearance = hand.max(body);
        self
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

impl RobotWorld<'_> {
    /// What the configuration `q` of the planned joints collides with, if anything.
    pub fn first_hit(&mut self, q: &[f64]) -> Option<Collision> {
        self.checks += 1;
        for (&j, &v) in self.joints.iter().zip(q) {
            self.scratch[j] = v;
        }
        self.model.apply_mimics(&mut self.scratch);
        self.model.forward_kinematics(&self.scratch, &mut self.fk);
        let name = |l: LinkId| self.model.links[l].name.clone();
        // Links the planned joints do not move stay where the first check saw them.
        let first = self.checks == 1;
        let self_hit = if first {
            self.collision
                .place(&self.fk, &self.links, &mut self.placement);
            self.collision
                .placed_self_collision(&self.placement, &self.all_pairs, self.margin)
        } else {
            self.collision
                .place(&self.fk, &self.moving, &mut self.placement);
            self.bodies.update(&self.placement);
            self.bodies
                .first_self_collision(self.collision, &self.placement, self.margin)
        };
        if let Some((a, b)) = self_hit {
            return Some(Collision {
                link: name(a),
                with: format!("link `{}`", name(b)),
            });
        }
        for body in &self.obstacles {
            let links = if first {
                &self.links
            } else {
                self.bodies.near(body, self.max_clearance, &mut self.near);
                &self.near
            };
            let hit = links.iter().find_map(|&l| {
                self.collision
                    .placed_collision(&self.placement, &[l], &[*body], self.clearance[l])
            });
            if let Some(hit) = hit {
                return Some(Collision {
                    link: name(hit.link),
                    with: format!("obstacle `{}`", body.name),
                });
            }
        }
        self.object_hit(first).or_else(|| self.attached_hit())
    }

    fn object_hit(&self, first: bool) -> Option<Collision> {
        let rule = self.object.as_ref()?;
        let name = |l: LinkId| self.model.links[l].name.clone();
        let strict = &self.strict[usize::from(!first)];
        let hit = self
            .collision
            .placed_collision(&self.placement, strict, &[rule.body], self.margin)
            .map(|h| h.link)
            .or_else(|| {
                self.collision
                    .first_penetration(&self.fk, &rule.touching, &[rule.body], rule.tolerance)
                    .map(|p| p.link)
            })?;
        Some(Collision {
            link: name(hit),
            with: "the object".into(),
        })
    }

    fn attached_hit(&mut self) -> Option<Collision> {
        let at = self.attached.as_mut()?;
        let pose = self.fk.pose(at.link) * at.relative;
        at.body.set_pose(pose);
        let raised = (pose.translation.vector - at.origin).norm() >= at.clearance;
        let carried = "the grasped object".to_owned();
        for (i, o) in self.obstacles.iter().enumerate() {
            if (raised || !at.supports.contains(&i)) && at.body.intersects(o, self.margin) {
                return Some(Collision {
                    link: carried,
                    with: format!("obstacle `{}`", o.name),
                });
            }
        }
        // The carried object moves: every link but the hand's, every check.
        let hit = self.collision.placed_collision(
            &self.placement,
            &self.carrying,
            &[&at.body],
            self.margin,
        )?;
        Some(Collision {
            link: self.model.links[hit.link].name.clone(),
            with: carried,
        })
    }
}

impl Validity for RobotWorld<'_> {
    fn is_valid(&mut self, q: &[f64]) -> bool {
        self.first_hit(q).is_none()
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
