//! The world the trajectory planner plans in: the planner kit's, unchanged.
//!
//! What: [`SharedWorld`] is the kit's world holder for a plugin that plans
//! motions, not grasps: it derives nothing from the robot or the object and
//! never answers a grasp `plan`. A `tsukami_planner_kit::Session<SharedWorld>`
//! then keeps the robot, object and obstacles the host sets (two-phase
//! `world_prepare` / `world_commit`, versions, validation, files inside the
//! model roots) exactly as the grasp planners do.
//!
//! Why: the trajectory planner must move among the same bodies, at the same
//! world version, as the grasp it is given was planned in; sharing the kit's
//! world code means it cannot load or check them differently.
//!
//! ```
//! use tsukami_planner_kit::Session;
//! use tsukami_trajectory_planner::world::SharedWorld;
//! let session = Session::<SharedWorld>::new("models");
//! assert_eq!(session.snapshot().version, 0);
//! ```

use tsukami_msgs::planner::PlanOptions;
use tsukami_planner_kit::{
    GraspPlanner, KitError, NoGrasp, Object, PlannerConfig, PlannerInfo, Robot, Run, World,
};

/// The kit's world with nothing derived: the trajectory planner's world holder.
pub struct SharedWorld;

impl GraspPlanner for SharedWorld {
    type RobotData = ();
    type ObjectData = ();

    fn info() -> PlannerInfo {
        PlannerInfo {
            name: "tsukami-trajectory-planner",
            version: env!("CARGO_PKG_VERSION"),
            description: "collision-free reach, approach, close and lift to a planned grasp",
        }
    }

    fn new(_config: &PlannerConfig) -> Result<Self, String> {
        Ok(SharedWorld)
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

    /// Never called: the plugin answers `plan` with a motion (see `crate::plugin`).
    fn plan(&self, _: &World<'_, Self>, _: &PlanOptions, _: &mut Run) -> Result<Grasp, NoGrasp> {
        Err(NoGrasp::Exhausted)
    }
}

use tsukami_planner_kit::Grasp;
