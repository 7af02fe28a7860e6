//! The paper's planner as a `grasp-planner` plugin.
//!
//! The planner kit's adapter does everything a plugin does (parse, dispatch,
//! world changes from the host, error codes, progress, cancel): this file only
//! names the type and exports it. Plugin config keys: `docs/plugins.md`.

use crate::planner::Paper;

/// The paper's planner behind the plugin interface.
pub type GraspPlannerPlugin = tsukami_planner_kit::KitPlugin<Paper>;

tsukami_planner_kit::export_planner!(Paper);
