//! How each grasp style's contacts are checked beyond force closure.
//!
//! What: [`style_check`] applies the rule of a grasp's style to its contacts.
//! An **envelope** (`envelope4`) must wrap: some finger contact presses the
//! object toward the palm (its inward normal at least [`WRAP_SLOPE`] against
//! the approach — the finger reached past the object's silhouette, beyond
//! its middle as seen from the palm), opposed along the approach by the palm
//! (a palm contact, required when the grasp type says `palm_contact`) or by a
//! contact pressing away from the palm. Fingertip styles (`fingertip3`,
//! `fingertip4`) have no rule beyond the hold test; when their type says
//! `palm_contact`, the palm must be among the contacts too.
//!
//! Why: closure and the disturbance set are necessary, not sufficient: an
//! "envelope" whose fingers all lie on the near side of the object squeezes
//! it out of the hand as soon as the servos press (the physics benchmark,
//! `bench/physics`: 34 of 36 such grasps). The rule says what the grasp type
//! promises; the planner and the verification apply the same function.
//!
//! How: pure geometry on the contacts' inward normals and the approach
//! direction in the world.
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_msgs::planner::GraspStyle;
//! use tsukami_planner_kit::blocks::wrap::{style_check, StyleRule};
//! let a = Vector3::z(); // the palm pushes along +z into the object
//! let palm = (0usize, Point3::origin(), Vector3::z());
//! let far = (1usize, Point3::new(0.0, 0.0, 0.06), -Vector3::z());
//! let side = (2usize, Point3::new(0.03, 0.0, 0.03), -Vector3::x());
//! let rule = StyleRule { style: GraspStyle::Envelope4, palm_contact: true, palm: 0, approach: a };
//! assert!(style_check(&rule, &[palm, far, side]).is_ok());
//! assert!(style_check(&rule, &[palm, side]).is_err()); // nothing wraps past the middle
//! assert!(style_check(&rule, &[far, side]).is_err()); // the palm does not press
//! ```

use nalgebra::Vector3;
use tsukami_body::model::LinkId;
use tsukami_msgs::planner::GraspStyle;

use crate::blocks::hold::HoldContact;

/// The least component (against or along the approach) of a unit inward
/// normal that counts as pressing toward or away from the palm: sin 15°.
pub const WRAP_SLOPE: f64 = 0.2588;

/// What the rule of one grasp needs to know.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StyleRule {
    /// The grasp's style.
    pub style: GraspStyle,
    /// The grasp type requires the palm among the contacts.
    pub palm_contact: bool,
    /// The palm link.
    pub palm: LinkId,
    /// The approach direction in the world (from the palm into the object).
    pub approach: Vector3<f64>,
}

/// `Err` with the reason when `contacts` break the style's rule.
pub fn style_check(rule: &StyleRule, contacts: &[HoldContact]) -> Result<(), String> {
    let on_palm = contacts.iter().any(|c| c.0 == rule.palm);
    if rule.palm_contact && !on_palm {
        return Err("the palm does not touch the object".into());
    }
    if rule.style != GraspStyle::Envelope4 {
        return Ok(());
    }
    let a = rule.approach.normalize();
    let wraps = contacts
        .iter()
        .any(|c| c.0 != rule.palm && c.2.dot(&a) <= -WRAP_SLOPE);
    if !wraps {
        return Err("no finger wraps past the object's middle toward the palm".into());
    }
    let opposed = on_palm || contacts.iter().any(|c| c.2.dot(&a) >= WRAP_SLOPE);
    if !opposed {
        return Err("nothing opposes the wrapping fingers along the approach".into());
    }
    Ok(())
}
