//! The guarantees of a returned grasp, checked on its final posture.
//!
//! What: [`check_grasp`] takes the robot posed at the grasp (forward
//! kinematics already run), the links to check, the object, the obstacles and
//! the finger contacts, and says whether the grasp is physically sound:
//! - no link sinks into an obstacle or into the object deeper than
//!   [`PENETRATION_TOLERANCE`] (touching is how a hand holds; sinking in is
//!   not);
//! - every contact lies on the object's surface (within [`SURFACE_TOLERANCE`]),
//!   its link within [`CONTACT_GAP`] of it, and its normal within
//!   [`NORMAL_TOLERANCE`] of the surface's normal cone there (the triangle's
//!   normal inside a face; the cone of the faces meeting at an edge or a
//!   vertex, as the independent checker has it);
//! - no two links of the robot overlap, but the pairs its collision shapes
//!   allow (adjacent links and the description's `allowed_collisions`).
//!
//! A failure names the link and what it hit ([`Rejection`]).
//!
//! Why: one statement of the guarantees, with their tolerances, for every
//! planner: a planner may call it on its candidates (the paper's planner does,
//! before the exact force-closure program), and the kit calls it on every
//! grasp a planner returns ([`crate::verify`]), so a new or wrong planner's
//! grasp never leaves unchecked. The independent checker
//! (`tsukami_scenes::verify`) checks again, with its own code.
//!
//! How: `tsukami-body` penetration depths (a link inside a closed mesh counts
//! as deep) and its nearest-surface-point query over the object's mesh.
//!
//! ```
//! use tsukami_planner_kit::blocks::grasp_check::{Rejection, PENETRATION_TOLERANCE};
//! let r = Rejection::Contact { link: 0, detail: "1.50 mm off the surface".into() };
//! assert!(matches!(r, Rejection::Contact { .. }));
//! assert!(PENETRATION_TOLERANCE <= 1e-3);
//! ```

use nalgebra::{Point3, Vector3};
use tsukami_body::collision::{CollisionObject, RobotCollision};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{LinkId, RobotModel};

/// A contact to check: the touching link, the point on the object, the
/// inward unit normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    /// The touching link.
    pub link: LinkId,
    /// The contact point (world frame).
    pub position: Point3<f64>,
    /// Unit normal into the object (world frame).
    pub normal: Vector3<f64>,
}

impl From<&crate::grasp::FingerContact> for ContactPoint {
    fn from(c: &crate::grasp::FingerContact) -> Self {
        Self {
            link: c.link,
            position: c.position,
            normal: c.normal,
        }
    }
}

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
    /// Two links of the robot overlap (a pair not allowed to).
    SelfCollision {
        /// One link.
        link: LinkId,
        /// The other.
        other: LinkId,
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
    pub fn label(&self, model: &RobotModel) -> String {
        match self {
            Rejection::Penetration { link, into, .. } => {
                format!("{} into {into}", model.links[*link].name)
            }
            Rejection::SelfCollision { link, other } => {
                format!(
                    "{} vs {}",
                    model.links[*link].name, model.links[*other].name
                )
            }
            Rejection::Contact { link, .. } => {
                format!("contact of {} off the surface", model.links[*link].name)
            }
        }
    }

    /// The whole reason, for an error message.
    pub fn describe(&self, model: &RobotModel) -> String {
        match self {
            Rejection::Penetration { link, into, depth } => format!(
                "link `{}` is {:.2} mm inside `{into}` (at most {} mm)",
                model.links[*link].name,
                depth * 1e3,
                PENETRATION_TOLERANCE * 1e3
            ),
            Rejection::SelfCollision { link, other } => format!(
                "link `{}` overlaps link `{}` (neither adjacent nor in `allowed_collisions`)",
                model.links[*link].name, model.links[*other].name
            ),
            Rejection::Contact { link, detail } => {
                format!(
                    "the contact of link `{}`: {detail}",
                    model.links[*link].name
                )
            }
        }
    }
}

/// [`check_grasp`] in a planner's world: its hand's collision shapes, its
/// object and its obstacles, for `links` posed in `fk` and the kit's contacts.
pub fn check_in<P: crate::planner::GraspPlanner>(
    world: &crate::planner::World<'_, P>,
    fk: &FkState,
    links: &[LinkId],
    contacts: &[crate::grasp::FingerContact],
) -> Result<(), Rejection> {
    let points: Vec<ContactPoint> = contacts.iter().map(ContactPoint::from).collect();
    let (col, object) = (&world.hand().collision, &world.object.collision);
    check_grasp(col, fk, links, object, &world.obstacles, &points)
}

/// Checks the grasp at the posture in `fk` (see the module docs): `links`
/// against the object and `env`, the whole robot against itself, then every
/// contact.
pub fn check_grasp(
    col: &RobotCollision,
    fk: &FkState,
    links: &[LinkId],
    object: &CollisionObject,
    env: &[&CollisionObject],
    contacts: &[ContactPoint],
) -> Result<(), Rejection> {
    let everything: Vec<&CollisionObject> =
        std::iter::once(object).chain(env.iter().copied()).collect();
    if let Some(p) = col.first_penetration(fk, links, &everything, PENETRATION_TOLERANCE) {
        return Err(Rejection::Penetration {
            link: p.link,
            into: everything[p.object].name.clone(),
            depth: p.depth,
        });
    }
    if let Some((link, other)) = col.first_self_collision(fk, 0.0) {
        return Err(Rejection::SelfCollision { link, other });
    }
    for c in contacts {
        check_contact(col, fk, object, c)?;
    }
    Ok(())
}

fn check_contact(
    col: &RobotCollision,
    fk: &FkState,
    object: &CollisionObject,
    c: &ContactPoint,
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
    let gap = col
        .link_object_proximity(fk, c.link, object, CONTACT_GAP)
        .map(|p| p.distance);
    if gap.is_none() {
        return Err(bad(format!("its link is more than {CONTACT_GAP} m away")));
    }
    // The contact's outward direction against the surface's normal cone there
    // (one normal inside a face, the meeting faces' at an edge or a vertex);
    // an open or inconsistently wound mesh may have its normals either way
    // round, so its faces are compared in the nearer sense.
    let out: Vector3<f64> = -c.normal;
    let angle = match object.is_solid() {
        true => angle_to_cone(&out, &s.normals),
        false => {
            let sense: Vec<Vector3<f64>> =
                s.normals.iter().map(|n| n * n.dot(&out).signum()).collect();
            angle_to_cone(&out, &sense)
        }
    };
    if angle > NORMAL_TOLERANCE {
        return Err(bad(format!(
            "normal {:.1}° from the surface's",
            angle.to_degrees()
        )));
    }
    Ok(())
}

/// Angle (rad) from the unit vector `v` to the cone spanned by the unit
/// `normals`, or an upper bound of it: the nearest normal, or the nearest
/// point of a sector between two of them (a vertex's cone is the union of
/// its pairs' sectors here; the exact cone can only be nearer).
fn angle_to_cone(v: &Vector3<f64>, normals: &[Vector3<f64>]) -> f64 {
    let angle = |a: &Vector3<f64>, b: &Vector3<f64>| a.dot(b).clamp(-1.0, 1.0).acos();
    let mut best = std::f64::consts::PI;
    for (i, a) in normals.iter().enumerate() {
        best = best.min(angle(v, a));
        for b in &normals[i + 1..] {
            // v projected on the plane of a and b, when it falls between them.
            let Some(m) = a.cross(b).try_normalize(1e-12) else {
                continue;
            };
            let Some(p) = (v - m * m.dot(v)).try_normalize(1e-12) else {
                continue;
            };
            if a.cross(&p).dot(&m) >= 0.0 && p.cross(b).dot(&m) >= 0.0 {
                best = best.min(angle(v, &p));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_normal_cone_of_an_edge_holds_its_sector() {
        let (a, b) = (Vector3::x(), Vector3::y());
        let at = |v: Vector3<f64>| angle_to_cone(&v.normalize(), &[a, b]);
        assert!(at(Vector3::new(1.0, 1.0, 0.0)) < 1e-12);
        assert!((at(Vector3::new(1.0, 0.0, 1.0)) - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
        assert!((at(Vector3::new(1.0, 1.0, 0.1)) - (0.1f64 / 2f64.sqrt()).atan()).abs() < 1e-12);
        assert!((at(-Vector3::x()) - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // One face: the angle to its normal.
        assert!((angle_to_cone(&Vector3::z(), &[a]) - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(angle_to_cone(&Vector3::z(), &[]), std::f64::consts::PI);
    }
}
