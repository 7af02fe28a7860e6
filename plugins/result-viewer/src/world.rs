//! The world the viewer shows: the planner kit's, with nothing derived.
//!
//! What: [`ViewerWorld`] is the kit's world-only holder
//! ([`tsukami_planner_kit::world_only`]) named for this plugin: a
//! `Session<ViewerWorld>` keeps the robot, object and obstacles the host sets
//! exactly as the planners hold them.
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

use tsukami_planner_kit::world_only::{WorldOnly, WorldOnlyInfo};
use tsukami_planner_kit::PlannerInfo;

/// Names the viewer's world holder.
pub struct Viewer;

impl WorldOnlyInfo for Viewer {
    const INFO: PlannerInfo = PlannerInfo {
        name: "tsukami-result-viewer",
        version: env!("CARGO_PKG_VERSION"),
        description: "the world as the planners see it, to draw",
    };
}

/// The kit's world with nothing derived: the viewer's world holder.
pub type ViewerWorld = WorldOnly<Viewer>;
