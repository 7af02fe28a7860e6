//! # tsukami-vision
//!
//! The vision component of Tsukami: the pose of a known object from a depth
//! image, and a depth-camera simulator for the robot's head camera.
//!
//! Pipeline ([`detect`]): back-project the depth image ([`cloud`]), remove the
//! supporting planes by RANSAC ([`plane`]), cut what is left into
//! object-sized segments ([`segment`], [`cluster`]), start ICP from each
//! segment's principal axes and from the model's resting poses on the plane
//! ([`hypotheses`], [`resting`]), rank the coarse fits by a quick check of
//! the model's visible surface against the image, refine the best by
//! point-to-plane ICP against the model's surface ([`icp`], [`template`],
//! [`lookup`]) and by visible-surface agreement ([`freespace`]), and judge
//! the result against the image ([`verify`]): a pose is reported only when
//! the model explains the measured points and the image does not see through
//! where the model would be. Symmetric objects are reported modulo their
//! symmetry ([`symmetry`]).
//!
//! The simulator ([`sim`]) renders a scene file by ray casting its meshes and
//! primitives with parry3d, seen from the head camera of the robot model, with
//! the noise model documented in [`sim::noise`].
//!
//! The bus side ([`service`]) answers `<ns>/vision/detect` and publishes
//! `<ns>/vision/pose/<object>`; the binary `tsukami-vision` runs it, and also
//! renders and detects from files.

pub mod camera;
pub mod cli;
pub mod cloud;
pub mod cluster;
pub mod convert;
pub mod depth;
pub mod detect;
pub mod error;
pub mod freespace;
pub mod hypotheses;
pub mod icp;
pub mod look;
pub mod lookup;
pub mod plane;
pub mod resting;
pub mod segment;
pub mod service;
pub mod sim;
pub mod symmetry;
pub mod template;
pub mod verify;

pub use camera::{Camera, Intrinsics};
pub use depth::DepthImage;
pub use detect::{Detection, Detector, Outcome};
pub use error::{Result, VisionError};
