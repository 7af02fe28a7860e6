//! The hand's grasp types (section 3.1): reference postures and their
//! grasping rectangular convexes (GRC).
//!
//! The format belongs to the hand, not to this planner: it lives in the planner
//! kit (`tsukami_planner_kit::grasp_types`, documented in
//! `docs/grasp-types.md`) and is re-exported here for the planner's modules.
//! This file imports nothing from the rest of the planner (no import cycle
//! with `selection`).

pub use tsukami_planner_kit::grasp_types::*;
