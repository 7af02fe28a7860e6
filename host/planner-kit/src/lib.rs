//! # tsukami-planner-kit
//!
//! What every Tsukami grasp planner shares, so that a planner author writes
//! only the planning idea.
//!
//! A planner implements one trait, [`GraspPlanner`] (derive data from the robot
//! and the object once; `plan` on a [`World`] with a [`Run`]), and exports it
//! with [`export_planner!`]. The kit owns the rest:
//! - **the world** ([`snapshot`]): robot, object and obstacles, versioned; the
//!   host's two-phase world changes (`world_prepare` / `world_commit`) or local
//!   `set_*` commands; plans run on a snapshot, several at once;
//! - **the robot description** ([`description`], [`robot`]): joint groups,
//!   hands, fingers and grasp types ([`grasp_types`]) by name, from
//!   `models/robots/<name>/description.toml`;
//! - **validation** ([`validate`], [`object`], [`env`]): every value checked,
//!   object meshes as they come ([`mesh_topology`]: open, non-manifold, wound
//!   at random — repaired or used with a documented fallback, never refused),
//!   every file read inside the model roots ([`models`]), before state changes;
//! - **dispatch and errors** ([`session`], [`error`]): one command table, one
//!   mapping to the wire's error codes;
//! - **the reply and verification** ([`grasp`], [`verify`]): every grasp is
//!   re-verified (exact force closure with the object's weight) before it leaves;
//! - **building blocks** ([`blocks`]): finger closing, finger force, collision
//!   passes, whole-body IK stages — call them or not;
//! - **motion checks** ([`motion_check`]): the approach, closing and lift of a
//!   grasp checked as the trajectory planner will take them;
//! - **a conformance suite** ([`conformance`]) any planner plugin runs.
//!
//! `docs/plugins.md` walks through a planner with
//! `plugins/examples/antipodal-planner` as the worked example.
//!
//! ```no_run
//! use tsukami_planner_kit::*;
//! use tsukami_msgs::planner::PlanOptions;
//!
//! pub struct Nothing;
//! impl GraspPlanner for Nothing {
//!     type RobotData = ();
//!     type ObjectData = ();
//!     fn info() -> PlannerInfo {
//!         PlannerInfo { name: "nothing", version: "0.1.0", description: "never finds a grasp" }
//!     }
//!     fn new(_: &PlannerConfig) -> Result<Self, String> { Ok(Nothing) }
//!     fn robot_data(&self, _: &Robot) -> Result<(), KitError> { Ok(()) }
//!     fn object_data(&self, _: &Object) -> Result<(), KitError> { Ok(()) }
//!     fn plan(&self, _: &World<'_, Self>, _: &PlanOptions, run: &mut Run) -> Result<Grasp, NoGrasp> {
//!         run.sample()?;
//!         run.reject("no idea");
//!         Err(NoGrasp::Exhausted)
//!     }
//! }
//! export_planner!(Nothing);
//! # fn main() {}
//! ```

pub mod blocks;
pub mod config;
pub mod conformance;
pub mod description;
pub mod env;
pub mod error;
pub mod grasp;
pub mod grasp_derive;
pub mod grasp_types;
pub mod mesh_topology;
pub mod models;
pub mod motion_check;
pub mod object;
pub mod planner;
pub mod plugin;
pub mod robot;
pub mod run;
pub mod session;
pub mod snapshot;
pub mod validate;
pub mod verify;
pub mod world_only;

pub use config::PlannerConfig;
pub use error::{KitError, NoGrasp, Stop};
pub use grasp::{FingerContact, Grasp};
pub use object::Object;
pub use planner::{GraspPlanner, PlannerInfo, World};
pub use plugin::KitPlugin;
pub use robot::{Finger, Hand, Robot, Stage};
pub use run::Run;
pub use session::Session;

#[doc(hidden)]
pub mod __private {
    pub use tsukami_plugin_api::export_plugin;
}
