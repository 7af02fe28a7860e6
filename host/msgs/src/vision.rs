//! Vision component messages (`<ns>/vision/...`).
//!
//! `<ns>/vision/detect` takes a [`DetectRequest`] and answers an [`ObjectPose`],
//! or an error: `infeasible` with `details.reason = "not_found"` when the object
//! is not in the image (a wrong or absent object is never reported as a
//! confident pose), `invalid_value` for a bad image or camera. A found pose is
//! also published on `<ns>/vision/pose/<object>`.
//!
//! `<ns>/vision/look` takes a [`LookRequest`] and answers a [`LookReply`]: the
//! component looks for the object with the robot's head camera — head aimed
//! where it is expected, the arms and the body out of the view, other views
//! (crouched, leaning, turned) where one does not see it — and answers the
//! pose with the views it took. A detect request without an image looks the
//! same way and answers the pose alone.

use std::collections::BTreeMap;

use crate::common::Pose;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Request of `<ns>/vision/detect`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DetectRequest {
    /// The object model to look for (a name from `models/objects`).
    pub object: String,
    /// The depth image to look in. Without one, the component takes a frame from
    /// its own camera (its depth-camera simulator when no camera is attached).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image: Option<DepthFrame>,
    /// Send a found pose on as the object's pose (`set_object` to the world), so
    /// vision → plan needs no hand-copied numbers. Default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub set_object: bool,
    /// Report a pose only at this confidence or more (default: the component's, 0.8).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_confidence: Option<f64>,
    /// Seed of a simulated frame's noise (default: the component's frame counter).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

/// Request of `<ns>/vision/look`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LookRequest {
    /// The object model to look for (a name from `models/objects`).
    pub object: String,
    /// Where the object is expected: a point of it, its centre roughly, in the
    /// robot's base frame (m). The head is aimed there. Default: where the
    /// component's world has it (the simulated camera's scene file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub expected: Option<[f64; 3]>,
    /// The most views to take, 1 to 6 (default 6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_views: Option<u32>,
    /// Send a found pose on as the object's pose, as in `DetectRequest`.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub set_object: bool,
    /// Report a pose only at this confidence or more (default: the component's, 0.8).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_confidence: Option<f64>,
    /// Seed of the simulated frames' noise (default: the component's frame counter).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

/// Reply of `<ns>/vision/look`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LookReply {
    /// The object as found (what `<ns>/vision/detect` replies).
    pub pose: ObjectPose,
    /// The index in `views` of the view it was found in.
    pub view: u32,
    /// The views taken, in order.
    pub views: Vec<LookView>,
}

/// One view a look took: the robot's posture and what the camera saw.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LookView {
    /// The kind of view: `aim`, `crouch`, `lean`, `turn_left`, `turn_right`,
    /// `crouch_lean`.
    pub name: String,
    /// The joints of the posture away from rest: name → position (rad, or m
    /// for a prismatic joint).
    pub joints: BTreeMap<String, f64>,
    /// Pose of the camera's optical frame in the robot's base frame.
    pub camera_pose: Pose,
    /// Fraction of the object's part of the image (its bounding sphere grown
    /// 1.5 times) that the robot's own links hide: 0 when the arms and the
    /// body are out of the view.
    pub self_hidden: f64,
    /// Whether the object was found in this view.
    pub found: bool,
    /// The detection's confidence, or its best candidate's when not found.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub confidence: Option<f64>,
    /// Fraction of the found object's visible surface hidden by something in front.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub occluded: Option<f64>,
    /// Why it was not found.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// A depth image with the camera that took it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DepthFrame {
    /// How `data` is encoded.
    pub encoding: DepthEncoding,
    /// The image bytes, base64 (standard alphabet, with padding).
    pub data: String,
    /// The camera.
    pub camera: CameraInfo,
}

/// Encodings of a depth image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DepthEncoding {
    /// A 16-bit greyscale PNG in millimetres; 0 = no measurement.
    Png16Mm,
    /// Raw little-endian float32 in metres, row-major; 0, NaN or negative = no measurement.
    F32LeM,
}

/// A pinhole camera: intrinsics and where it is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CameraInfo {
    /// Pinhole intrinsics.
    pub intrinsics: CameraIntrinsics,
    /// Pose of the optical frame (z forward, x right, y down) in the robot's base frame.
    pub camera_pose: Pose,
}

/// Pinhole intrinsics in pixels; pixel `(u, v)` has its centre at `(u, v)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CameraIntrinsics {
    /// Image width (pixels).
    pub width: u32,
    /// Image height (pixels).
    pub height: u32,
    /// Focal length along x (pixels).
    pub fx: f64,
    /// Focal length along y (pixels).
    pub fy: f64,
    /// Principal point x (pixels).
    pub cx: f64,
    /// Principal point y (pixels).
    pub cy: f64,
}

/// Reply of `<ns>/vision/detect`, and the payload of `<ns>/vision/pose/<object>`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ObjectPose {
    /// The object model.
    pub object: String,
    /// Pose in the robot's base frame. For a symmetric object, one member of the
    /// set of equivalent poses (see `symmetry`).
    pub pose: Pose,
    /// RMS distance between the fitted model and the measured points, metres.
    pub fit_error: f64,
    /// Confidence in [0, 1]: the fraction of the segment's points the model
    /// explains, times the fraction of the model's visible surface the image agrees with.
    #[serde(default)]
    pub confidence: f64,
    /// Measured points in the final fit.
    #[serde(default)]
    pub points: u64,
    /// Fraction of the model's visible surface hidden by something in front.
    #[serde(default)]
    pub occluded: f64,
    /// The object's symmetry: the pose is reported modulo these motions. Absent
    /// for an object without symmetry.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub symmetry: Option<Symmetry>,
    /// The key the pose was sent on to (`set_object` in the request), if it was.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sent_to: Option<String>,
}

/// The motions of the object frame that leave the object unchanged: `pose ∘ m`
/// for any of them is as valid as `pose`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Symmetry {
    /// A continuous rotation axis (object frame): any rotation about it is a symmetry.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<SymmetryAxis>,
    /// Discrete symmetries (object frame), besides the identity.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub discrete: Vec<Pose>,
    /// In words, and how the reported member was chosen.
    pub note: String,
}

/// A line in the object frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SymmetryAxis {
    /// A point on the axis (m).
    pub point: [f64; 3],
    /// Unit direction.
    pub direction: [f64; 3],
}
