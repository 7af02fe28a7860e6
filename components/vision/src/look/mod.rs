//! Looking before reaching: the postures a robot takes to see an object, and
//! the search through them.
//!
//! What: a [`Looker`] turns an expected object position ([`Target`]) into
//! views — postures of the whole robot ([`View`]) — in a fixed order
//! ([`STANCES`]): the head aimed at it; crouched; crouched and leaning
//! further over it; leaning; the upper body turned left, then right. In every
//! view the robot's own body is kept out of the object's part of the image:
//! the waist bends forward until the chest is out of it, and the arms are
//! moved out of it ([`Looker::clear_arm`]). [`Looker::look`] takes the views
//! one by one, at most [`MAX_VIEWS`], until the object is found and not
//! mostly hidden ([`ACCEPT_OCCLUDED`]), and answers the best detection with
//! every view it took.
//!
//! Why: one view from the rest posture did not see the object in two of the
//! paper's five scenes: `can_waist` (the head tilted to its limit, the chest
//! cut the can in half) and `fridge_pet` (the fridge's upper shelf hid the
//! bottle on the lower one from a standing robot). The paper's robot looks
//! before it reaches: it turns its head, bends and crouches to see.
//!
//! How: only the robot's own geometry is used to plan a view (it is known
//! before the image is taken; what else is in the way is found out by
//! looking): the sight check ([`sight`]) projects the links into the image.
//! The body joints are the head camera's ([`HeadCamera`]: bend, turn, lift);
//! each stance sets the lift and the turn, then takes the least forward bend
//! (of [`BEND_STEPS`] steps) with which the head, aimed, has the target
//! within 5° of its optical axis and no link that moves with the camera hides
//! it — plus the stance's extra bend. A posture that puts a link into a
//! known obstacle, or collides with itself where the rest posture does not,
//! is not taken; a view equal to one already taken is skipped. Everything is
//! deterministic: the same target gives the same views.
//!
//! ```
//! use std::path::Path;
//! use nalgebra::Point3;
//! use tsukami_body::urdf::load_urdf;
//! use tsukami_vision::camera::Intrinsics;
//! use tsukami_vision::look::{Looker, Target, STANCES};
//! use tsukami_vision::sim::head::HeadCamera;
//! let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/../../models/robots/tsukami_humanoid/tsukami_humanoid.urdf");
//! let head = HeadCamera::new(load_urdf(Path::new(urdf)).unwrap(), Intrinsics::head_camera()).unwrap();
//! let looker = Looker::new(head, Vec::new()).unwrap();
//! // A can at breast height, front right: the head alone looks at it.
//! let breast = Target { centre: Point3::new(0.52, -0.25, 1.16), radius: 0.067 };
//! let view = looker.view(&STANCES[0], &breast).unwrap();
//! assert_eq!(view.name, "aim");
//! assert_eq!(view.hidden.hidden, 0, "nothing of the robot in front of the can");
//! // At waist height the waist bends, until the chest is (nearly) out of the picture.
//! let waist = Target { centre: Point3::new(0.36, -0.25, 0.84), radius: 0.067 };
//! let view = looker.view(&STANCES[0], &waist).unwrap();
//! assert!(view.q[looker.head.waist.unwrap()] > 0.5);
//! assert!(view.hidden.fraction() < 0.05, "{:?}", view.hidden);
//! ```

pub mod arm;
pub mod sight;

use nalgebra::Point3;
use tsukami_body::collision::{CollisionObject, RobotCollision};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::LinkId;

use crate::camera::Camera;
use crate::detect::{Detection, Outcome};
use crate::error::Result;
use crate::sim::head::{HeadCamera, AIMED, BEND_STEPS};
use sight::Hidden;

/// The most views one look takes (the number of [`STANCES`]).
pub const MAX_VIEWS: usize = 6;

/// A detection hiding at most this fraction of the object's visible surface
/// ends the look; a more hidden one is kept while other views are tried.
pub const ACCEPT_OCCLUDED: f64 = 0.5;

/// The sphere the sight check keeps free of the robot is the object's
/// bounding sphere grown by this factor.
pub const MARGIN: f64 = 1.5;

/// Deepest a look posture may put a link into a known obstacle (m): touching.
const PENETRATION: f64 = 1e-3;

/// Whether `outcome` ends a look: found, hiding at most [`ACCEPT_OCCLUDED`].
fn accepts(outcome: &Outcome) -> bool {
    matches!(outcome, Outcome::Found(d) if d.verdict.occluded_fraction() <= ACCEPT_OCCLUDED)
}

/// Where the object is expected: a point of it (its centre, roughly) in the
/// robot's base frame, and its bounding radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Target {
    /// Base frame (m).
    pub centre: Point3<f64>,
    /// Largest distance of the object's surface from `centre` (m).
    pub radius: f64,
}

/// A kind of view: how the body stands before the head is aimed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stance {
    /// Its name in replies.
    pub name: &'static str,
    /// How far down the lift goes: 0 rest, 1 its limit.
    pub lower: f64,
    /// The upper body's turn (rad, positive to the left), within its limits.
    pub turn: f64,
    /// Bend steps beyond the least that sees the target.
    pub lean: usize,
}

/// The views of a look, in the order they are tried.
pub const STANCES: [Stance; MAX_VIEWS] = [
    Stance {
        name: "aim",
        lower: 0.0,
        turn: 0.0,
        lean: 0,
    },
    Stance {
        name: "crouch",
        lower: 1.0,
        turn: 0.0,
        lean: 0,
    },
    Stance {
        name: "crouch_lean",
        lower: 1.0,
        turn: 0.0,
        lean: 2,
    },
    Stance {
        name: "lean",
        lower: 0.0,
        turn: 0.0,
        lean: 2,
    },
    Stance {
        name: "turn_left",
        lower: 0.0,
        turn: 0.35,
        lean: 0,
    },
    Stance {
        name: "turn_right",
        lower: 0.0,
        turn: -0.35,
        lean: 0,
    },
];

/// One view: a posture of the whole robot.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    /// The stance's name.
    pub name: &'static str,
    /// Joint positions (the model's order).
    pub q: Vec<f64>,
    /// The camera at `q` (pose in the base frame).
    pub camera: Camera,
    /// Angle (rad) between the optical axis and the target.
    pub off_axis: f64,
    /// What the robot's own links hide of the target at `q`.
    pub hidden: Hidden,
}

/// One view taken, and what was seen in it.
#[derive(Debug, Clone)]
pub struct Attempt {
    /// The view.
    pub view: View,
    /// The detection in its frame.
    pub outcome: Outcome,
}

/// What a look saw.
#[derive(Debug, Clone)]
pub struct Looked {
    /// The views taken, in order, with their detections.
    pub attempts: Vec<Attempt>,
    /// The attempt whose detection is the answer: the first found and not
    /// mostly hidden, else the most confident found; `None` when no view
    /// found the object.
    pub chosen: Option<usize>,
}

impl Looked {
    /// The chosen detection.
    pub fn found(&self) -> Option<&Detection> {
        let attempt = &self.attempts[self.chosen?];
        match &attempt.outcome {
            Outcome::Found(d) => Some(d),
            Outcome::NotFound(_) => None,
        }
    }
}

/// Plans the views of a robot's head camera.
#[derive(Debug, Clone)]
pub struct Looker {
    /// The head camera and its robot.
    pub head: HeadCamera,
    collision: RobotCollision,
    obstacles: Vec<CollisionObject>,
    rest: Vec<f64>,
    rest_self_collisions: Vec<(LinkId, LinkId)>,
}

impl Looker {
    /// A looker for `head`'s robot among `obstacles` (base frame; the
    /// postures that would go into them are not taken).
    pub fn new(head: HeadCamera, obstacles: Vec<CollisionObject>) -> Result<Self> {
        let collision = RobotCollision::new(&head.robot)?;
        let rest = head.robot.rest_positions();
        let mut fk = FkState::new(&head.robot);
        head.robot.forward_kinematics(&rest, &mut fk);
        let rest_self_collisions = collision.self_collisions(&fk, 0.0);
        Ok(Looker {
            head,
            collision,
            obstacles,
            rest,
            rest_self_collisions,
        })
    }

    fn fk(&self, q: &[f64]) -> FkState {
        let mut fk = FkState::new(&self.head.robot);
        self.head.robot.forward_kinematics(q, &mut fk);
        fk
    }

    /// Whether the robot may take posture `q`: no link sunk into a known
    /// obstacle, no two links overlapping that do not at rest.
    pub fn allowed(&self, q: &[f64]) -> bool {
        self.colliding(q).is_empty()
    }

    /// The links that keep posture `q` from being taken: the first sunk into
    /// a known obstacle, and those of the overlapping pairs that do not
    /// overlap at rest.
    pub fn colliding(&self, q: &[f64]) -> Vec<LinkId> {
        let fk = self.fk(q);
        let links: Vec<LinkId> = (0..self.head.robot.links.len()).collect();
        let obstacles: Vec<&CollisionObject> = self.obstacles.iter().collect();
        let mut out: Vec<LinkId> = self
            .collision
            .first_penetration(&fk, &links, &obstacles, PENETRATION)
            .map(|p| p.link)
            .into_iter()
            .collect();
        for (a, b) in self.collision.self_collisions(&fk, 0.0) {
            if !self.rest_self_collisions.contains(&(a, b)) {
                out.extend([a, b]);
            }
        }
        out
    }

    /// Whether `link` moves only with the camera (the chest, the head, an arm
    /// fixed to the chest): the arm clearing cannot move it.
    fn moves_with_camera(&self, link: LinkId) -> bool {
        let robot = &self.head.robot;
        robot
            .independent_chain(link)
            .iter()
            .all(|&j| self.head.carries_camera(j))
    }

    /// The view of `stance` on `target`; `None` when its posture may not be
    /// taken.
    pub fn view(&self, stance: &Stance, target: &Target) -> Option<View> {
        let head = &self.head;
        let mut q = self.rest.clone();
        if let Some(l) = head.lift {
            q[l] = self.lowered(l, stance.lower);
        }
        if let Some(t) = head.turn {
            let lim = head.robot.joints[t].limits;
            q[t] = stance.turn.clamp(lim.lower, lim.upper);
        }
        let bend = self.least_bend(&mut q, target) + stance.lean;
        if let Some(w) = head.waist {
            q[w] = head.bend(bend.min(BEND_STEPS));
        }
        let off_axis = head.aim(&mut q, &target.centre);
        let hidden = self.clear_arm(&mut q, target);
        self.allowed(&q).then(|| View {
            name: stance.name,
            camera: head.camera(&q),
            q,
            off_axis,
            hidden,
        })
    }

    /// Joint `l` moved `fraction` of the way from rest to the limit that
    /// lowers the camera.
    fn lowered(&self, l: usize, fraction: f64) -> f64 {
        let lim = self.head.robot.joints[l].limits;
        let height = |v: f64| {
            let mut q = self.rest.clone();
            q[l] = v;
            self.head.pose(&q).translation.z
        };
        let down = if height(lim.lower) <= height(lim.upper) {
            lim.lower
        } else {
            lim.upper
        };
        self.rest[l] + (down - self.rest[l]) * fraction.clamp(0.0, 1.0)
    }

    /// The least bend step (0 without a waist) at which the head, aimed from
    /// `q`, has `target` within 5° of its axis and no link moving with the
    /// camera hides it; else the step hiding the least, then nearest the
    /// axis.
    fn least_bend(&self, q: &mut [f64], target: &Target) -> usize {
        let Some(w) = self.head.waist else { return 0 };
        let mut best = (usize::MAX, f64::INFINITY, 0);
        for i in 0..=BEND_STEPS {
            q[w] = self.head.bend(i);
            let off = self.head.aim(q, &target.centre);
            let hidden = self.hidden(q, target);
            let body: usize = hidden
                .by_link
                .iter()
                .filter(|(link, _)| self.moves_with_camera(*link))
                .map(|(_, n)| n)
                .sum();
            if off < AIMED && body == 0 {
                return i;
            }
            let aimed = off.max(AIMED);
            if (body, aimed) < (best.0, best.1) {
                best = (body, aimed, i);
            }
        }
        best.2
    }

    /// Takes the views of [`STANCES`] on `target` one by one, at most
    /// `max_views` (and [`MAX_VIEWS`]), detecting with `see` in each, until
    /// one finds the object hiding at most [`ACCEPT_OCCLUDED`] of it.
    pub fn look(
        &self,
        target: &Target,
        max_views: usize,
        mut see: impl FnMut(&View) -> Result<Outcome>,
    ) -> Result<Looked> {
        let mut attempts: Vec<Attempt> = Vec::new();
        for stance in &STANCES {
            if attempts.len() >= max_views.clamp(1, MAX_VIEWS) {
                break;
            }
            let Some(view) = self.view(stance, target) else {
                continue;
            };
            if attempts.iter().any(|a| a.view.q == view.q) {
                continue;
            }
            let outcome = see(&view)?;
            let done = accepts(&outcome);
            attempts.push(Attempt { view, outcome });
            if done {
                break;
            }
        }
        // The look ended on an accepted view, else the most confident found.
        let accepted = attempts.last().is_some_and(|a| accepts(&a.outcome));
        let chosen = if accepted {
            Some(attempts.len() - 1)
        } else {
            attempts
                .iter()
                .enumerate()
                .filter_map(|(i, a)| match &a.outcome {
                    Outcome::Found(d) => Some((i, d.confidence)),
                    Outcome::NotFound(_) => None,
                })
                .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
                .map(|(i, _)| i)
        };
        Ok(Looked { attempts, chosen })
    }
}
