//! The world the viewer shows: the planner kit's, with nothing derived.
//!
//! What: [`ViewerWorld`] is the kit's world holder for a plugin that draws,
//! never plans: a `tsukami_planner_kit::Session<ViewerWorld>` keeps the robot,
//! object and obstacles the host sets (two-phase `world_prepare` /
//! `world_commit`, versions, files only inside the model roots) exactly as the
//! planners hold them.
//!
//! Why: the picture must show the bodies the grasp was planned among, loaded
//! and checked by the same code, at the same world version.
//!
//! ```
//! use tsukami_planner_kit::Session;
//! use tsukami_result_viewer::world::ViewerWorld;
//! let session = Session::<ViewerWorld>::new("models");
//! assert_eq!(session.snapshot().version, 0);
//! ```

use tsukami_msgs::planner::PlanOptions;
use tsukami_planner_kit::{
    Grasp, GraspPlanner, KitError, NoGrasp, Object, PlannerConfig, PlannerInfo, Robot, Run, World,
};

/// The kit's world with nothing derived: the viewer's world holder.
pub struct ViewerWorld;

impl GraspPlanner for ViewerWorld {
    type RobotData = ();
    type ObjectData = ();

    fn info() -> PlannerInfo {
        PlannerInfo {
            name: "tsukami-result-viewer",
            version: env!("CARGO_PKG_VERSION"),
            description: "the world as the planners see it, to draw",
        }
    }

    fn new(_config: &PlannerConfig) -> Result<Self, String> {
        Ok(ViewerWorld)
    }

    fn robot_data(&self, _robot: &Robot) -> Result<(), KitError> {
        Ok(())
    }

    fn object_data(&self, _object: &Object) -> Result<(), KitError> {
        Ok(())
    }

    fn grasp_types(&self, _robot: &Robot, _data: &()) -> Vec<String> {
        Vec::new()
    }

    /// Never called: the plugin answers no `plan` (see `crate::plugin`).
    fn plan(&self, _: &World<'_, Self>, _: &PlanOptions, _: &mut Run) -> Result<Grasp, NoGrasp> {
        Err(NoGrasp::Exhausted)
    }
}
