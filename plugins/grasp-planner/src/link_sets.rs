//! Which robot links may touch what, and the collision test built on it.
//!
//! What: [`LinkSets`] splits the links a whole-body stage moves into those
//! that may touch the object (a grasp type's contact links and the
//! `touch_allowed` ones, at most half the verification tolerance deep) and
//! those that may not; none may touch an obstacle. [`LinkSets::blocked`]
//! names the first violation of a posture.
//!
//! Why: Algorithm 1 tests every sample with it, and the planner tests each
//! nominal palm pose with it before sampling (a nominal whose open hand is in
//! the table is searched last): one definition for both.
//!
//! How: links below a waist or squat joint of the stage join the arm and
//! hand links; the tests are `tsukami_body`'s first-collision, penetration
//! and self-collision queries.

use tsukami_body::collision::CollisionObject;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{JointId, LinkId};

use crate::hand::HandModel;
use crate::verify::PENETRATION_TOLERANCE;

/// The robot's links with geometry, split by what they may do to the object.
pub struct LinkSets {
    /// Every link the stage moves — arm and hand, and the torso, head and
    /// other arm when waist or squat joints move them: none may touch an
    /// obstacle.
    pub moving: Vec<LinkId>,
    /// Contact and `touch_allowed` links: may touch the object, sink in at
    /// most half the verification tolerance.
    pub touching: Vec<LinkId>,
    /// The rest: may not touch the object.
    pub not_touching: Vec<LinkId>,
}

impl LinkSets {
    /// The sets of grasp type `t` in a stage whose joints beyond the arm are
    /// `extra_joints`: its contact links and the hand's and the type's
    /// `touch_allowed` links may touch the object.
    pub fn for_type(hand: &HandModel, t: usize, extra_joints: &[JointId]) -> Self {
        let robot = &hand.robot;
        let g = &hand.config.grasp_types[t];
        let contact_links: Vec<LinkId> = hand.types[t].contacts.iter().map(|c| c.link).collect();
        let allowed: Vec<LinkId> = hand
            .config
            .hand
            .touch_allowed
            .iter()
            .chain(g.touch_allowed.iter())
            .filter_map(|n| robot.link_id(n).ok())
            .collect();
        Self::new(hand, &contact_links, &allowed, extra_joints)
    }

    /// The sets for explicit contact and `touch_allowed` links.
    pub fn new(
        hand: &HandModel,
        contact_links: &[LinkId],
        allowed: &[LinkId],
        extra_joints: &[JointId],
    ) -> Self {
        let robot = &hand.robot;
        // Links below a waist or squat joint move with it.
        let mut below: Vec<LinkId> = extra_joints
            .iter()
            .map(|&j| robot.joints[j].child)
            .collect();
        let mut k = 0;
        while k < below.len() {
            below.extend(robot.links[below[k]].children.iter().copied());
            k += 1;
        }
        let moving: Vec<LinkId> = hand
            .arm_links
            .iter()
            .chain(hand.hand_links.iter())
            .chain(hand.body_links.iter().filter(|l| below.contains(l)))
            .copied()
            .filter(|&l| !hand.collision.link_parts(l).is_empty())
            .fold(Vec::new(), |mut v, l| {
                if !v.contains(&l) {
                    v.push(l);
                }
                v
            });
        let (touching, not_touching) = moving
            .iter()
            .partition(|l| contact_links.contains(l) || allowed.contains(l));
        Self {
            moving,
            touching,
            not_touching,
        }
    }

    /// What blocks the posture in `fk`, as `"<link> vs <what>"`: a link
    /// touching an obstacle, a link that may not touch the object touching
    /// it, a touching link sinking into it, or (`self_check`) two links.
    pub fn blocked(
        &self,
        hand: &HandModel,
        fk: &FkState,
        object: &CollisionObject,
        env: &[&CollisionObject],
        self_check: bool,
    ) -> Option<String> {
        self.blocked_by(hand, fk, object, env, self_check)
            .map(|b| b.text)
    }

    /// [`LinkSets::blocked`] with the offending link and what it meets.
    pub fn blocked_by(
        &self,
        hand: &HandModel,
        fk: &FkState,
        object: &CollisionObject,
        env: &[&CollisionObject],
        self_check: bool,
    ) -> Option<Blocked> {
        let c = &hand.collision;
        let name = |l: LinkId| hand.robot.links[l].name.as_str();
        let block = |link: LinkId, against: Against, text: String| Blocked {
            link,
            against,
            text,
        };
        if let Some(h) = c.first_collision(fk, &self.moving, env, 0.0) {
            let text = format!("{} vs {}", name(h.link), env[h.object].name);
            return Some(block(h.link, Against::Obstacle, text));
        }
        if let Some(h) = c.first_collision(fk, &self.not_touching, &[object], 0.0) {
            let text = format!("{} vs the object", name(h.link));
            return Some(block(h.link, Against::Object, text));
        }
        let tol = 0.5 * PENETRATION_TOLERANCE;
        if let Some(p) = c.first_penetration(fk, &self.touching, &[object], tol) {
            let text = format!("{} into the object", name(p.link));
            return Some(block(p.link, Against::Object, text));
        }
        if self_check {
            if let Some((a, b)) = c.first_self_collision(fk, 0.0) {
                return Some(block(
                    a,
                    Against::Robot,
                    format!("{} vs {}", name(a), name(b)),
                ));
            }
        }
        None
    }
}

/// What a link of a blocked posture meets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Against {
    /// An obstacle.
    Obstacle,
    /// The object, where the link may not touch it or sinks in too deep.
    Object,
    /// Another link of the robot.
    Robot,
}

/// The first violation of a posture ([`LinkSets::blocked_by`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Blocked {
    /// The offending link.
    pub link: LinkId,
    /// What it meets.
    pub against: Against,
    /// `"<link> vs <what>"`.
    pub text: String,
}
