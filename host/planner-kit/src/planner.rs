//! The one trait a planner author implements.
//!
//! What: [`GraspPlanner`] — describe the planner, derive per-robot and
//! per-object data once per world change, and `plan` on a [`World`] snapshot.
//! [`World`] is what a plan sees: one version of the robot, the object and the
//! obstacles, with the planner's derived data beside each.
//!
//! Why: everything else — parsing, validation, world state and versions,
//! dispatch, error codes, the reply, verification — is the kit's, the same for
//! every planner (MoveIt's planner plugins only solve "this request in this
//! scene" the same way).
//!
//! How: `plan` runs on `&self` and a shared snapshot, so the kit may run
//! several plans at once; a world change builds a new snapshot beside the old
//! one, and a plan under way keeps the one it started with.

use tsukami_body::collision::CollisionObject;
use tsukami_msgs::planner::{OcpBox, PlanOptions};

use crate::config::PlannerConfig;
use crate::grasp::Grasp;
use crate::object::Object;
use crate::robot::{Hand, Robot};
use crate::run::Run;
use crate::{KitError, NoGrasp};

/// Name, version and description of a planner.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlannerInfo {
    /// Plugin name, e.g. `tsukami-antipodal-planner`.
    pub name: &'static str,
    /// Its version (usually `env!("CARGO_PKG_VERSION")`).
    pub version: &'static str,
    /// One line saying what it does.
    pub description: &'static str,
}

/// A grasp planner on the kit.
pub trait GraspPlanner: Send + Sync + Sized + 'static {
    /// What the planner derives from a robot once (e.g. pre-shapes, resolved
    /// grasp types); `()` if nothing.
    type RobotData: Send + Sync + 'static;
    /// What the planner derives from an object once (e.g. OCP boxes, sampling
    /// tables); `()` if nothing.
    type ObjectData: Send + Sync + 'static;

    /// Name, version, description.
    fn info() -> PlannerInfo;

    /// Creates the planner; `config.planner` holds its own config keys.
    fn new(config: &PlannerConfig) -> Result<Self, String>;

    /// Derives the robot data (`set_robot`); an error refuses the robot.
    fn robot_data(&self, robot: &Robot) -> Result<Self::RobotData, KitError>;

    /// Derives the object data (`set_object`); an error refuses the object.
    fn object_data(&self, object: &Object) -> Result<Self::ObjectData, KitError>;

    /// The grasp-type names a request may restrict the plan to
    /// (`PlanOptions::grasp_types`). Default: the hand's grasp types.
    fn grasp_types(&self, robot: &Robot, _data: &Self::RobotData) -> Vec<String> {
        let types = &robot.hand().grasp_types.grasp_types;
        types.iter().map(|g| g.name.clone()).collect()
    }

    /// The regions `set_object` reports. Default: the bounding box.
    fn regions(&self, object: &Object, _data: &Self::ObjectData) -> Vec<OcpBox> {
        vec![object.box_region()]
    }

    /// Plans one grasp. The kit has checked the options and that a robot and
    /// an object are set; it verifies the grasp and builds the reply.
    fn plan(
        &self,
        world: &World<'_, Self>,
        opts: &PlanOptions,
        run: &mut Run,
    ) -> Result<Grasp, NoGrasp>;
}

/// One version of the world, as a plan sees it.
pub struct World<'a, P: GraspPlanner> {
    /// The version.
    pub version: u64,
    /// The robot.
    pub robot: &'a Robot,
    /// The planner's robot data.
    pub robot_data: &'a P::RobotData,
    /// The object.
    pub object: &'a Object,
    /// The planner's object data.
    pub object_data: &'a P::ObjectData,
    /// The obstacles, sorted by name.
    pub obstacles: Vec<&'a CollisionObject>,
}

impl<P: GraspPlanner> World<'_, P> {
    /// The hand to plan for.
    pub fn hand(&self) -> &Hand {
        self.robot.hand()
    }
}
