//! A grasp's world version against the world's, and the grasp checked again on
//! the current world when the request asks for it.
//!
//! What: [`admit`] refuses a grasp planned on another world version
//! ([`MotionError::WorldChanged`], naming both) unless the request sets
//! `revalidate`; [`recheck`] then checks the grasp posture on the current
//! world with the planner kit's verification of every grasp
//! ([`tsukami_planner_kit::verify::verify`]): no link more than 1 mm into the
//! object or an obstacle, no self-collision, every contact on the object's
//! surface next to its link with its normal agreeing, and the default hold
//! test (force closure, the disturbance set within the joints' torques, the
//! style's rule: docs/force-closure.md). A grasp that fails is `infeasible`
//! (`grasp_invalid`) with the check's reason.
//!
//! Why: the world changes between a grasp plan and its motion (the object
//! moved, an obstacle came). A grasp of the old world may close the hand on
//! air; refusing it, or checking it with the very rules the grasp planner's
//! replies were held to, keeps the grasp and its motion on one world.
//!
//! How: the grasp's joints are the resolved goal's closed posture; its
//! contacts come from the Plan reply's `contacts` (link names resolved on the
//! current robot), its characteristic length from the reply when given.

use nalgebra::{Point3, Vector3};
use tsukami_msgs::motion::MotionGrasp;
use tsukami_msgs::planner::BoxFace;
use tsukami_planner_kit::grasp::{FingerContact, Grasp};
use tsukami_planner_kit::World;

use crate::error::MotionError;
use crate::goal::Goal;
use crate::world::SharedWorld;

/// Whether the grasp may be planned on the world of `version`: `Ok(false)` when
/// it was planned on it, `Ok(true)` when it must be [`recheck`]ed first
/// (another version, `revalidate` set), the refusal otherwise.
pub fn admit(grasp: &MotionGrasp, version: u64, revalidate: bool) -> Result<bool, MotionError> {
    match (grasp.world_version == version, revalidate) {
        (true, _) => Ok(false),
        (false, true) => Ok(true),
        (false, false) => Err(MotionError::WorldChanged {
            grasp: grasp.world_version,
            world: version,
        }),
    }
}

/// The grasp's contacts on the current robot, `invalid_value` naming a
/// contact whose link is unknown or whose numbers are not finite.
fn contacts(
    world: &World<'_, SharedWorld>,
    grasp: &MotionGrasp,
) -> Result<Vec<FingerContact>, MotionError> {
    if grasp.contacts.is_empty() {
        return Err(MotionError::invalid(
            "grasp.contacts",
            "re-validating a grasp needs the Plan reply's contacts",
        ));
    }
    let model = &world.robot.model;
    grasp
        .contacts
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let field = format!("grasp.contacts[{i}]");
            let link = model.link_id(&c.link).map_err(|_| {
                MotionError::invalid(&field, format!("link `{}` is not in the robot", c.link))
            })?;
            let finite = c.position.iter().chain(&c.normal).all(|v| v.is_finite());
            if !finite || !c.f_max.is_finite() {
                return Err(MotionError::invalid(&field, "a value is not finite"));
            }
            Ok(FingerContact {
                link,
                position: Point3::from(c.position),
                normal: Vector3::from(c.normal),
                f_max: c.f_max,
            })
        })
        .collect()
}

/// Checks the grasp at `goal`'s closed posture on the current world (see the
/// module docs); `grasp_invalid` naming what fails.
pub fn recheck(
    world: &World<'_, SharedWorld>,
    grasp: &MotionGrasp,
    goal: &Goal,
) -> Result<(), MotionError> {
    let hand = world.hand();
    let grasp_type = hand
        .grasp_types
        .grasp_types
        .iter()
        .find(|t| t.name == grasp.grasp_type.name)
        .ok_or_else(|| {
            MotionError::invalid("grasp.grasp_type.name", "not a grasp type of the hand")
        })?;
    let extra = goal
        .reach
        .iter()
        .copied()
        .filter(|j| !hand.arm.contains(j))
        .collect();
    let kit_grasp = Grasp {
        grasp_type: grasp_type.to_ref(),
        region: 0,
        face: BoxFace::PosX,
        tilt: None,
        q: goal.closed.clone(),
        joints: goal.reach.clone(),
        extra,
        contacts: contacts(world, grasp)?,
        characteristic_length: grasp.characteristic_length,
    };
    // The default hold test: a re-validated grasp must hold as a new one would.
    let hold = tsukami_msgs::planner::HoldRequest::default();
    tsukami_planner_kit::verify::verify(world, &kit_grasp, &hold)
        .map(|_| ())
        .map_err(|why| {
            MotionError::infeasible(
                "grasp_invalid",
                format!(
                    "the grasp planned on world version {} does not hold on version {}: {why}",
                    grasp.world_version, world.version
                ),
            )
        })
}
