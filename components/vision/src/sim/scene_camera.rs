//! The component's camera when no real one is attached: the head camera of a
//! scene file's robot, rendering the scene.
//!
//! What: [`SceneCamera::render`] renders a noisy frame with the robot in a
//! given posture (a view of a look, [`crate::look`]); [`SceneCamera::target`]
//! is where the scene has an object; [`SceneCamera::frame`] is the first view
//! of a look at it.
//!
//! Why: `<ns>/vision/detect` without an image must still see something, and
//! what it sees must be what the scene file says, so vision → plan can be run
//! end to end without hardware — the robot's own body, in the posture it
//! looks from, included.
//!
//! How: [`SimWorld`] of the scene's obstacles, objects and robot links at the
//! posture; [`render`] with the [`NoiseModel`]; seeded. The [`Looker`] knows
//! the scene's obstacles and objects (in the robot's base frame), so that no
//! view bends the robot into them.

use std::path::Path;

use nalgebra::Point3;
use tsukami_body::collision::CollisionObject;
use tsukami_body::scene::{Scene, SceneObject};

use super::head::HeadCamera;
use super::noise::NoiseModel;
use super::render::render;
use super::world::SimWorld;
use crate::camera::{Camera, Intrinsics};
use crate::depth::DepthImage;
use crate::error::Result;
use crate::look::{Looker, Target, STANCES};

/// A simulated head camera looking at a scene.
pub struct SceneCamera {
    scene: Scene,
    /// The views' planner, with the robot's head camera.
    pub looker: Looker,
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
        let to_base = scene.robot_base.inverse();
        let known = scene
            .obstacles
            .iter()
            .chain(scene.objects.iter().map(|o| &o.collision));
        let obstacles: Vec<CollisionObject> = known
            .map(|o| {
                let mut o = o.clone();
                o.set_pose(to_base * o.pose());
                o
            })
            .collect();
        let looker = Looker::new(head, obstacles)?;
        Ok(SceneCamera {
            scene,
            looker,
            noise,
        })
    }

    /// The scene's name.
    pub fn name(&self) -> &str {
        &self.scene.name
    }

    /// The scene object whose model (or scene name) is `name`, else the first.
    fn object(&self, name: &str) -> Option<&SceneObject> {
        self.scene
            .objects
            .iter()
            .find(|o| o.model.name == name || o.name == name)
            .or(self.scene.objects.first())
    }

    /// Where the scene has the object whose model (or scene name) is
    /// `object`, else its first object: the centre of the model's box, in
    /// the robot's base frame, with `radius`. Straight ahead of the head at
    /// rest, 1 m off, in a scene without objects.
    pub fn target(&self, object: &str, radius: f64) -> Target {
        let centre = match self.object(object) {
            Some(o) => {
                let (lo, hi) = o.model.mesh.aabb();
                self.scene.robot_base.inverse() * (o.pose * nalgebra::center(&lo, &hi))
            }
            None => {
                let rest = self
                    .looker
                    .head
                    .camera(&self.looker.head.robot.rest_positions());
                rest.pose * Point3::new(0.0, 0.0, 1.0)
            }
        };
        Target { centre, radius }
    }

    /// A frame of the first view of a look at `object` (see
    /// [`SceneCamera::target`]; its radius from the model's box): the image
    /// and the camera (pose in the robot's base frame).
    pub fn frame(&self, object: &str, seed: u64) -> Result<(DepthImage, Camera)> {
        let radius = self.object(object).map_or(0.1, |o| {
            let (lo, hi) = o.model.mesh.aabb();
            0.5 * (hi - lo).norm()
        });
        let target = self.target(object, radius);
        let q = match self.looker.view(&STANCES[0], &target) {
            Some(view) => view.q,
            None => self.looker.head.look_at(&target.centre),
        };
        self.render(&q, seed)
    }

    /// A frame with the robot at `q`: the image and the camera (pose in the
    /// robot's base frame).
    pub fn render(&self, q: &[f64], seed: u64) -> Result<(DepthImage, Camera)> {
        let camera = self.looker.head.camera(q);
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
        world.add_robot(&self.scene.robot, q, &self.scene.robot_base, &centre)?;
        let rendered = render(&world, &world_camera, &self.noise, seed)?;
        Ok((rendered.image, camera))
    }
}
