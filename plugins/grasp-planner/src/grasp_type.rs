//! The hand's grasp types (section 3.1): reference postures and their
//! grasping rectangular convexes (GRC).
//!
//! The format belongs to the hand, not to this planner: it lives in the planner
//! kit (`tsukami_planner_kit::grasp_types`, documented in
//! `docs/grasp-types.md`) and is re-exported here for the planner's modules.
//! This file imports nothing from the rest of the planner (no import cycle
//! with `selection`).

pub use tsukami_planner_kit::grasp_types::*;

#[cfg(test)]
pub(crate) mod tests {
    /// A one-type file for unit tests of this crate.
    pub(crate) const MINIMAL: &str = r#"
[[grasp_type]]
name = "fingertip3_mid"
style = "fingertip3"
size = "mid"
mass = [0.0, 0.3]
approach = [0, 0, 1]
closing_step = 0.02
posture = { f1 = 0.3 }
contacts = [{ link = "l1", joint = "f1" }]
grc_max = { position = [0.05, 0, 0.06], size = [0.10, 0.20, 0.30] }
grc_min = { position = [0.05, 0, 0.06], size = [0.02, 0.02, 0.02] }
grc_des = { position = [0.05, 0, 0.06], size = [0.06, 0.06, 0.10] }
"#;
}
