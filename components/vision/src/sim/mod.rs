//! A depth-camera simulator for the robot's head camera.
//!
//! - [`world`]: the shapes to render (a scene file's objects and obstacles,
//!   the robot's own links), with their world poses.
//! - [`head`]: the head camera of a robot model — its pose for a head
//!   configuration, and the head configuration that looks at a point.
//! - [`render`]: ray casting the shapes (parry3d) into a depth image and a
//!   label image.
//! - [`noise`]: the documented noise model applied to the rendered depths.
//! - [`scene_camera`]: the component's camera when none is attached.
//! - [`testbed`]: objects at random resting poses on a table, with an
//!   occluder placed to hide a given fraction of the target — what the
//!   accuracy benchmark and the tests render.

pub mod head;
pub mod noise;
pub mod render;
pub mod scene_camera;
pub mod testbed;
pub mod world;
