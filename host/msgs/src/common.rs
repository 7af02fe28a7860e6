//! Small value types used by several messages.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A rigid pose: position in metres and orientation as a unit quaternion `[x, y, z, w]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Pose {
    /// Position `[x, y, z]` in metres.
    pub position: [f64; 3],
    /// Orientation as a unit quaternion `[x, y, z, w]`.
    #[serde(default = "identity_quaternion")]
    pub quaternion: [f64; 4],
}

fn identity_quaternion() -> [f64; 4] {
    [0.0, 0.0, 0.0, 1.0]
}

impl Pose {
    /// The pose at the origin with no rotation.
    pub const IDENTITY: Pose = Pose {
        position: [0.0; 3],
        quaternion: [0.0, 0.0, 0.0, 1.0],
    };

    /// Checks that every number is finite and the quaternion has a usable norm.
    ///
    /// Returns the name of the offending field (`"position"` or `"quaternion"`).
    pub fn validate(&self) -> Result<(), &'static str> {
        if self.position.iter().any(|v| !v.is_finite()) {
            return Err("position");
        }
        let norm2: f64 = self.quaternion.iter().map(|v| v * v).sum();
        if self.quaternion.iter().any(|v| !v.is_finite()) || !(0.5..=2.0).contains(&norm2) {
            return Err("quaternion");
        }
        Ok(())
    }
}

/// Joint values by joint name (radians for revolute joints, metres for prismatic ones).
pub type JointMap = BTreeMap<String, f64>;
