//! The component's camera when no real one is attached: the head camera of a
//! scene file's robot, rendering the scene.
//!
//! What: [`SceneCamera::frame`] turns the head toward the object asked for
//! (or the scene's first object) and renders a noisy frame.
//!
//! Why: `<ns>/vision/detect` without an image must still see something, and
//! what it sees must be what the scene file says, so vision → plan can be run
//! end to end without hardware.
//!
//! How: [`SimWorld`] of the scene's obstacles, objects and robot links;
//! [`HeadCamera::look_at`]; [`render`] with the [`NoiseModel`]; seeded.

use std::path::Path;

use nalgebra::Point3;
use tsukami_body::scene::Scene;

use super::head::HeadCamera;
use super::noise::NoiseModel;
use super::render::render;
use super::world::SimWorld;
use crate::camera::{Camera, Intrinsics};
use crate::depth::DepthImage;
use crate::error::Result;

/// A simulated head camera looking at a scene.
pub struct SceneCamera {
    scene: Scene,
    head: HeadCamera,
    /// The noise of its frames.
    pub noise: NoiseModel,
}

impl std::fmt::Debug for SceneCamera {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneCamera")
            .field("scene", &self.scene.name)
            .finish()
    }
}

impl SceneCamera {
    /// Loads a scene file (robot, objects, obstacles).
    pub fn load(path: &Path, noise: NoiseModel) -> Result<Self> {
        let scene = Scene::load(path)?;
        let head = HeadCamera::new(scene.robot.clone(), Intrinsics::head_camera())?;
        Ok(SceneCamera { scene, head, noise })
    }

    /// The scene's name.
    pub fn name(&self) -> &str {
        &self.scene.name
    }

    /// A frame with the head looking at the scene object whose model is
    /// `object` (else the first object, else straight ahead): the image and
    /// the camera (pose in the robot's base frame).
    pub fn frame(&self, object: &str, seed: u64) -> Result<(DepthImage, Camera)> {
        let target = self
            .scene
            .objects
            .iter()
            .find(|o| o.model.name == object || o.name == object)
            .or(self.scene.objects.first());
        let q = match target {
            Some(o) => {
                let (lo, hi) = o.model.mesh.aabb();
                let c = o.pose * nalgebra::center(&lo, &hi);
                self.head.look_at(&(self.scene.robot_base.inverse() * c))
            }
            None => self.head.robot.rest_positions(),
        };
        let camera = self.head.camera(&q);
        let world_camera = Camera {
            intrinsics: camera.intrinsics,
            pose: self.scene.robot_base * camera.pose,
        };
        let mut world = SimWorld::default();
        for o in &self.scene.obstacles {
            world.add_object(o);
        }
        for o in &self.scene.objects {
            world.add_object(&o.collision);
        }
        let centre = Point3::from(world_camera.pose.translation.vector);
        world.add_robot(&self.scene.robot, &q, &self.scene.robot_base, &centre)?;
        let rendered = render(&world, &world_camera, &self.noise, seed)?;
        Ok((rendered.image, camera))
    }
}
