//! Vision component messages (`<ns>/vision/...`).

use crate::common::Pose;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Request of `<ns>/vision/detect`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DetectRequest {
    /// The object model to look for (a name from `models/objects`).
    pub object: String,
}

/// Reply of `<ns>/vision/detect`, and the payload of `<ns>/vision/pose/<object>`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ObjectPose {
    /// The object model.
    pub object: String,
    /// Pose in the robot's base frame.
    pub pose: Pose,
    /// RMS distance between the fitted model and the measured points, metres.
    pub fit_error: f64,
}
