//! The planner's own check of a grasp before it leaves Algorithm 1.
//!
//! What: [`check_grasp`] takes the robot posed at the grasp (forward
//! kinematics already run), the object, the obstacles and the finger
//! contacts, and says whether the grasp is physically sound:
//! - no robot link (arm, body, hand) sinks into an obstacle or into the
//!   object deeper than [`PENETRATION_TOLERANCE`] (touching is how a hand
//!   holds; sinking in is not);
//! - every contact lies on the object's surface (within [`SURFACE_TOLERANCE`]),
//!   its link within [`CONTACT_GAP`] of it, and, where it lies inside a
//!   triangle, its normal within [`NORMAL_TOLERANCE`] of the triangle's
//!   inward normal.
//!
//! The exact force-closure test with the weight runs just before this, in
//! [`crate::search`]. A grasp that fails is never returned: the sample is
//! rejected with the reason ([`Rejection`]), naming the link and what it hit.
//!
//! Why: the search's own collision checks are fast filters on the way; this
//! is the one place that states the guarantees of a returned grasp, with
//! their tolerances, and checks them all on the final posture. The planner
//! kit and the independent checker (`tsukami_scenes::verify`) check again.
//!
//! How: `tsukami-body` penetration depths (a link inside a closed mesh counts
//! as deep) and its nearest-surface-point query over the object's mesh.

use nalgebra::Vector3;
use tsukami_body::collision::CollisionObject;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::LinkId;

use crate::finger_closing::FingerContact;
use crate::hand::HandModel;

/// Deepest a link may sink into the object or an obstacle (m): 1 mm.
pub const PENETRATION_TOLERANCE: f64 = 1e-3;
/// Largest distance of a contact point from the object's surface (m).
pub const SURFACE_TOLERANCE: f64 = 1e-3;
/// Largest distance of a contact's link from its contact point (m).
pub const CONTACT_GAP: f64 = 3e-3;
/// Largest angle between a contact normal and the surface's inward normal (rad): 5°.
pub const NORMAL_TOLERANCE: f64 = 0.087_266_462_599_716_48;

/// Why a grasp failed the check.
#[derive(Debug, Clone, PartialEq)]
pub enum Rejection {
    /// A link sinks into the object or an obstacle.
    Penetration {
        /// The link.
        link: LinkId,
        /// The object's or obstacle's name.
        into: String,
        /// Depth (m).
        depth: f64,
    },
    /// A contact is off the surface, its link away from it, or its normal
    /// disagrees with the surface's.
    Contact {
        /// The contact's link.
        link: LinkId,
        /// What is wrong.
        detail: String,
    },
}

impl Rejection {
    /// A short label naming the link and what it hit, for rejection counts.
    pub fn label(&self, hand: &HandModel) -> String {
        match self {
            Rejection::Penetration { link, into, .. } => {
                format!("{} into {into}", hand.robot.links[*link].name)
            }
            Rejection::Contact { link, .. } => {
                format!(
                    "contact of {} off the surface",
                    hand.robot.links[*link].name
                )
            }
        }
    }
}

/// Checks the grasp at the posture in `fk` (see the module docs).
pub fn check_grasp(
    hand: &HandModel,
    fk: &FkState,
    links: &[LinkId],
    object: &CollisionObject,
    env: &[&CollisionObject],
    contacts: &[FingerContact],
) -> Result<(), Rejection> {
    let col = &hand.collision;
    let everything: Vec<&CollisionObject> =
        std::iter::once(object).chain(env.iter().copied()).collect();
    if let Some(p) = col.first_penetration(fk, links, &everything, PENETRATION_TOLERANCE) {
        return Err(Rejection::Penetration {
            link: p.link,
            into: everything[p.object].name.clone(),
            depth: p.depth,
        });
    }
    for c in contacts {
        check_contact(hand, fk, object, c)?;
    }
    Ok(())
}

fn check_contact(
    hand: &HandModel,
    fk: &FkState,
    object: &CollisionObject,
    c: &FingerContact,
) -> Result<(), Rejection> {
    let bad = |detail: String| Rejection::Contact {
        link: c.link,
        detail,
    };
    let s = object
        .surface_point(&c.position)
        .ok_or_else(|| bad("the object has no surface to touch".into()))?;
    if s.distance > SURFACE_TOLERANCE {
        return Err(bad(format!("{:.2} mm off the surface", s.distance * 1e3)));
    }
    let gap = hand
        .collision
        .link_object_proximity(fk, c.link, object, CONTACT_GAP)
        .map(|p| p.distance);
    if gap.is_none() {
        return Err(bad(format!("its link is more than {CONTACT_GAP} m away")));
    }
    if s.on_face {
        // Inward normal of the triangle; an open or inconsistently wound mesh
        // may have it either way round, so compare with the nearer sense.
        let inward: Vector3<f64> = -s.normal;
        let cos = c.normal.dot(&inward);
        let cos = if object.is_solid() { cos } else { cos.abs() };
        if cos < NORMAL_TOLERANCE.cos() {
            return Err(bad(format!(
                "normal {:.1}° from the surface's",
                cos.clamp(-1.0, 1.0).acos().to_degrees()
            )));
        }
    }
    Ok(())
}
