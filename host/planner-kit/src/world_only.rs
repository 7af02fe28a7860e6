//! The kit's world for a plugin that plans no grasps.
//!
//! What: [`WorldOnly`] is a [`GraspPlanner`] that derives nothing from the
//! robot or the object and answers no grasp `plan`; a
//! `Session<WorldOnly<I>>` then holds the robot, object and obstacles the host
//! sets (two-phase `world_prepare` / `world_commit`, versions, validation,
//! files only inside the model roots) exactly as the grasp planners do.
//! [`WorldOnlyInfo`] names the plugin.
//!
//! Why: the trajectory planner and the result viewer must see the bodies the
//! grasp was planned among, at the same world version, loaded and checked by
//! the same code; one holder for both keeps them from drifting apart.
//!
//! ```
//! use tsukami_planner_kit::world_only::{WorldOnly, WorldOnlyInfo};
//! use tsukami_planner_kit::{GraspPlanner, PlannerInfo, Session};
//! struct Mine;
//! impl WorldOnlyInfo for Mine {
//!     const INFO: PlannerInfo = PlannerInfo {
//!         name: "my-viewer",
//!         version: "0.1.0",
//!         description: "draws the world",
//!     };
//! }
//! assert_eq!(WorldOnly::<Mine>::info().name, "my-viewer");
//! let _session = Session::<WorldOnly<Mine>>::new("models");
//! ```

use std::marker::PhantomData;

use tsukami_msgs::planner::PlanOptions;

use crate::Grasp;
use crate::{
    GraspPlanner, KitError, NoGrasp, Object, PlannerConfig, PlannerInfo, Robot, Run, World,
};

/// Names a world-only plugin.
pub trait WorldOnlyInfo: Send + Sync + 'static {
    /// The plugin's name, version and description.
    const INFO: PlannerInfo;
}

/// The kit's world with nothing derived, for the plugin `I` names.
pub struct WorldOnly<I>(PhantomData<I>);

impl<I: WorldOnlyInfo> WorldOnly<I> {
    /// The world session of a plugin whose config is `config`: the kit's keys
    /// (model roots, limits) for the world, the plugin's own keys left to it.
    pub fn session(config: &PlannerConfig) -> Result<crate::Session<Self>, String> {
        let mut world = config.clone();
        world.planner = toml::Table::new();
        crate::Session::from_config(world)
    }
}

impl<I: WorldOnlyInfo> GraspPlanner for WorldOnly<I> {
    type RobotData = ();
    type ObjectData = ();

    fn info() -> PlannerInfo {
        I::INFO
    }

    fn new(_config: &PlannerConfig) -> Result<Self, String> {
        Ok(WorldOnly(PhantomData))
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

    /// Never called by a world-only plugin, which answers its own commands;
    /// a grasp `plan` finds nothing.
    fn plan(&self, _: &World<'_, Self>, _: &PlanOptions, _: &mut Run) -> Result<Grasp, NoGrasp> {
        Err(NoGrasp::Exhausted)
    }
}
