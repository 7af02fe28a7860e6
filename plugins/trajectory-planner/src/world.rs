//! The world the trajectory planner plans in: the planner kit's, unchanged.
//!
//! What: [`SharedWorld`] is the kit's world-only holder
//! ([`tsukami_planner_kit::world_only`]) named for this plugin: a
//! `Session<SharedWorld>` keeps the robot, object and obstacles the host sets
//! exactly as the grasp planners hold them.
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

use tsukami_planner_kit::world_only::{WorldOnly, WorldOnlyInfo};
use tsukami_planner_kit::PlannerInfo;

/// Names the trajectory planner's world holder.
pub struct Motion;

impl WorldOnlyInfo for Motion {
    const INFO: PlannerInfo = PlannerInfo {
        name: "tsukami-trajectory-planner",
        version: env!("CARGO_PKG_VERSION"),
        description: "collision-free reach, approach, close and lift to a planned grasp",
    };
}

/// The kit's world with nothing derived: the trajectory planner's world holder.
pub type SharedWorld = WorldOnly<Motion>;
