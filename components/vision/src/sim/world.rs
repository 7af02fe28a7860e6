//! The shapes the simulator renders, in the world frame.
//!
//! What: [`SimWorld`] is a list of labelled bodies, each a set of parry shapes
//! with world poses.
//!
//! Why: the renderer needs flat, posed shapes; the testbed needs to add and
//! move objects; the label of the first body a ray hits tells which object a
//! pixel shows (for occlusion fractions).
//!
//! How: bodies come from [`tsukami_body`]'s collision objects (scene objects
//! and obstacles: meshes with their BVH, boxes, cylinders) and from the robot
//! model's link shapes after forward kinematics. Links whose shapes contain
//! the camera (the head around it) are left out.

use nalgebra::{Isometry3, Point3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Pose;
use parry3d_f64::shape::SharedShape;
use tsukami_body::collision::{CollisionObject, Part, RobotCollision};
use tsukami_body::convert::{to_pose, to_vec};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{LinkId, RobotModel};

use crate::error::Result;

/// One shape placed in the world.
#[derive(Clone)]
pub struct SimShape {
    /// World pose of the shape.
    pub pose: Pose,
    /// The shape.
    pub shape: SharedShape,
    /// Its world bounding box.
    pub aabb: Aabb,
}

/// A labelled rigid body.
#[derive(Clone)]
pub struct SimBody {
    /// Name (object, obstacle or link name).
    pub name: String,
    /// Its shapes.
    pub shapes: Vec<SimShape>,
}

/// Everything the camera can see.
#[derive(Clone, Default)]
pub struct SimWorld {
    /// The bodies; a pixel's label is the index of its body plus one.
    pub bodies: Vec<SimBody>,
}

impl std::fmt::Debug for SimWorld {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names: Vec<&str> = self.bodies.iter().map(|b| b.name.as_str()).collect();
        f.debug_struct("SimWorld").field("bodies", &names).finish()
    }
}

fn placed(world: Pose, part: &Part) -> SimShape {
    let pose = world * part.origin;
    SimShape {
        aabb: part.shape.compute_aabb(&pose),
        pose,
        shape: part.shape.clone(),
    }
}

impl SimWorld {
    /// Adds a collision object (at its own world pose); returns its body index.
    pub fn add_object(&mut self, object: &CollisionObject) -> usize {
        let world = to_pose(object.pose());
        self.bodies.push(SimBody {
            name: object.name.clone(),
            shapes: object.parts().iter().map(|p| placed(world, p)).collect(),
        });
        self.bodies.len() - 1
    }

    /// Adds the robot's links at configuration `q` with its root at `base`,
    /// leaving out links whose shapes contain `camera` (world frame).
    pub fn add_robot(
        &mut self,
        robot: &RobotModel,
        q: &[f64],
        base: &Isometry3<f64>,
        camera: &Point3<f64>,
    ) -> Result<()> {
        let collision = RobotCollision::new(robot)?;
        self.add_robot_shapes(robot, &collision, q, base, camera);
        Ok(())
    }

    /// [`SimWorld::add_robot`] with the link shapes already built; returns
    /// the link of each body added, in order.
    pub fn add_robot_shapes(
        &mut self,
        robot: &RobotModel,
        collision: &RobotCollision,
        q: &[f64],
        base: &Isometry3<f64>,
        camera: &Point3<f64>,
    ) -> Vec<LinkId> {
        let mut added = Vec::new();
        let mut fk = FkState::new(robot);
        fk.base = *base;
        robot.forward_kinematics(q, &mut fk);
        let cam = to_vec(camera);
        for (link, info) in robot.links.iter().enumerate() {
            let parts = collision.link_parts(link);
            if parts.is_empty() {
                continue;
            }
            let world = to_pose(fk.pose(link));
            let shapes: Vec<SimShape> = parts.iter().map(|p| placed(world, p)).collect();
            let contains = shapes.iter().any(|s| {
                s.shape.contains_point(&s.pose, cam)
                    || s.shape.distance_to_point(&s.pose, cam, true) < 0.01
            });
            if !contains {
                self.bodies.push(SimBody {
                    name: info.name.clone(),
                    shapes,
                });
                added.push(link);
            }
        }
        added
    }

    /// The index of the body named `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }
}
