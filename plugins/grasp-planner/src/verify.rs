//! The planner's check of a candidate grasp before the exact force-closure
//! program: the kit's one statement of a returned grasp's guarantees
//! ([`tsukami_planner_kit::blocks::grasp_check`]: no link more than 1 mm into
//! the object or an obstacle, every contact on the surface with its normal
//! agreeing), applied to the stage's moving links and this planner's contacts.
//! A grasp that fails is never returned: the sample is rejected with the
//! reason ([`Rejection`]). The kit checks every returned grasp again, and the
//! independent checker (`tsukami_scenes::verify`) once more.

use tsukami_body::collision::CollisionObject;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::LinkId;
pub use tsukami_planner_kit::blocks::grasp_check::{
    ContactPoint, Rejection, CONTACT_GAP, NORMAL_TOLERANCE, PENETRATION_TOLERANCE,
    SURFACE_TOLERANCE,
};

use crate::finger_closing::FingerContact;
use crate::hand::HandModel;

/// Checks the grasp at the posture in `fk`: `links` against the object and
/// `env`, then every contact (see the kit's module).
pub fn check_grasp(
    hand: &HandModel,
    fk: &FkState,
    links: &[LinkId],
    object: &CollisionObject,
    env: &[&CollisionObject],
    contacts: &[FingerContact],
) -> Result<(), Rejection> {
    let points: Vec<ContactPoint> = contacts
        .iter()
        .map(|c| ContactPoint {
            link: c.link,
            position: c.position,
            normal: c.normal,
        })
        .collect();
    tsukami_planner_kit::blocks::grasp_check::check_grasp(
        &hand.collision,
        fk,
        links,
        object,
        env,
        &points,
    )
}
