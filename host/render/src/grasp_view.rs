//! The scene of one planned grasp, as a [`Drawing`].
//!
//! What: [`GraspView`] — the robot at the planned posture (hand links in the
//! hand colour), the object at its pose, the obstacles, and at each contact a
//! red marker and a translucent friction cone of half-angle `atan μ`.
//!
//! Why: the parts a person checks a grasp by: where the fingers touch, how
//! wide the cones are, what the hand is near.
//!
//! How: forward kinematics places every link's collision parts; the cone's
//! apex is the contact and it opens out of the object (against the inward
//! normal), as the fingertip sees it.

use nalgebra::{Isometry3, Point3, Vector3};
use tsukami_body::collision::{CollisionObject, RobotCollision};
use tsukami_body::kinematics::FkState;
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::model::{LinkId, RobotModel};
use tsukami_msgs::planner::PlanReply;

use crate::drawing::{Drawing, Rgba};

/// Where a grasp picture's camera sits relative to what it looks at by
/// default (m, world frame): to the robot's right, in front, a little above.
pub const DEFAULT_EYE: [f64; 3] = [0.15, -0.55, 0.25];

/// Radius of a contact marker (m).
pub const CONTACT_RADIUS: f64 = 0.006;
/// Height of a friction cone (m).
pub const CONE_HEIGHT: f64 = 0.03;

/// One contact of the grasp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactMark {
    /// Contact point on the object's surface (world).
    pub position: Point3<f64>,
    /// Unit normal pointing into the object.
    pub normal: Vector3<f64>,
    /// Friction coefficient.
    pub mu: f64,
}

/// What one grasp picture shows.
pub struct GraspView<'a> {
    /// The robot.
    pub model: &'a RobotModel,
    /// Its collision shapes (drawn as the robot).
    pub collision: &'a RobotCollision,
    /// Joint positions, indexed like `model.joints`.
    pub q: &'a [f64],
    /// Links drawn in the hand colour.
    pub hand_links: &'a [LinkId],
    /// The object's mesh and pose, if any.
    pub object: Option<(&'a TriangleMesh, Isometry3<f64>)>,
    /// The obstacles (tables, shelves).
    pub obstacles: &'a [CollisionObject],
    /// The grasp's contacts.
    pub contacts: &'a [ContactMark],
}

impl GraspView<'_> {
    /// The drawing of this view.
    pub fn drawing(&self) -> Drawing {
        let mut d = Drawing::default();
        let mut fk = FkState::new(self.model);
        self.model.forward_kinematics(self.q, &mut fk);
        for (id, link) in self.model.links.iter().enumerate() {
            let color = if self.hand_links.contains(&id) {
                Rgba::HAND
            } else {
                Rgba::ROBOT
            };
            for part in self.collision.link_parts(id) {
                d.part(&format!("link {}", link.name), color, fk.pose(id), part);
            }
        }
        if let Some((mesh, pose)) = self.object {
            d.mesh("object", Rgba::OBJECT, &pose, mesh);
        }
        for o in self.obstacles {
            for part in o.parts() {
                d.part(
                    &format!("obstacle {}", o.name),
                    Rgba::OBSTACLE,
                    o.pose(),
                    part,
                );
            }
        }
        for (i, c) in self.contacts.iter().enumerate() {
            d.marker(
                &format!("contact {i}"),
                Rgba::CONTACT,
                &c.position,
                CONTACT_RADIUS,
            );
            let out = -c.normal.normalize();
            d.cone(
                &format!("friction cone {i}"),
                Rgba::CONE,
                &c.position,
                &out,
                c.mu.atan(),
                CONE_HEIGHT,
            );
        }
        d
    }
}

/// The robot's joint positions of a Plan reply: its rest posture with the
/// reply's joints set. An unknown or mimic joint is an error naming it.
pub fn posture(model: &RobotModel, reply: &PlanReply) -> Result<Vec<f64>, String> {
    let mut q = model.rest_positions();
    for (name, &value) in &reply.joint_positions {
        let j = model
            .joint_id(name)
            .map_err(|e| format!("joint_positions.{name}: {e}"))?;
        q[j] = value;
    }
    Ok(q)
}

/// The contacts of a Plan reply, with its friction coefficient.
pub fn contact_marks(reply: &PlanReply) -> Vec<ContactMark> {
    reply
        .contacts
        .iter()
        .map(|c| ContactMark {
            position: Point3::from(c.position),
            normal: Vector3::from(c.normal),
            mu: reply.mu,
        })
        .collect()
}

/// What a grasp picture looks at: midway between the centre of the object's
/// box (at `pose`) and the contacts' centroid; the box centre without
/// contacts; the object's origin if the mesh has no finite box.
pub fn look_at(
    mesh: &TriangleMesh,
    pose: &Isometry3<f64>,
    contacts: &[ContactMark],
) -> Point3<f64> {
    let (lo, hi) = mesh.vertices.iter().fold(
        (
            Point3::from([f64::INFINITY; 3]),
            Point3::from([f64::NEG_INFINITY; 3]),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    let center = pose * nalgebra::center(&lo, &hi);
    if !center.coords.iter().all(|c| c.is_finite()) {
        return Point3::from(pose.translation.vector);
    }
    if contacts.is_empty() {
        return center;
    }
    let sum = contacts
        .iter()
        .fold(Vector3::zeros(), |s, c| s + c.position.coords);
    Point3::from((center.coords + sum / contacts.len() as f64) / 2.0)
}
