//! Collision passes of a configuration against the world.
//!
//! What: [`Pass`] names one check; [`first_failure`] runs a list of them on a
//! configuration (forward kinematics once) and returns the first that fails,
//! as the short reason a planner records with `Run::reject`.

use tsukami_body::collision::CollisionObject;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::LinkId;

use crate::robot::Hand;

/// One collision check.
pub enum Pass<'a> {
    /// These links must be clear of these bodies (obstacles or the object).
    Clear {
        /// Links checked.
        links: &'a [LinkId],
        /// Bodies.
        bodies: &'a [&'a CollisionObject],
        /// Reason recorded when it fails.
        reason: &'static str,
    },
    /// No pair of links may collide (pairs of body links are allowed).
    SelfCollision,
}

impl<'a> Pass<'a> {
    /// [`Pass::Clear`] of `links` against `bodies`, failing with `reason`.
    pub fn clear(
        links: &'a [LinkId],
        bodies: &'a [&'a CollisionObject],
        reason: &'static str,
    ) -> Self {
        Pass::Clear {
            links,
            bodies,
            reason,
        }
    }
}

/// The reason of the first pass that fails on the poses in `fk`, if any.
pub fn first_failure(hand: &Hand, fk: &FkState, passes: &[Pass<'_>]) -> Option<&'static str> {
    passes.iter().find_map(|p| match p {
        Pass::Clear {
            links,
            bodies,
            reason,
        } => hand
            .collision
            .first_collision(fk, links, bodies, 0.0)
            .map(|_| *reason),
        Pass::SelfCollision => hand
            .collision
            .first_self_collision(fk, 0.0)
            .map(|_| "self-collision"),
    })
}

/// The arm's and the hand's links (what must stay clear of obstacles).
pub fn arm_and_hand(hand: &Hand) -> Vec<LinkId> {
    hand.arm_links.iter().chain(&hand.links).copied().collect()
}
