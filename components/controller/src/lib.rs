//! # tsukami-controller
//!
//! The robot-controller component (`tsukami-controller`): the process the joint
//! trajectories go to, as the robot's controller boards were in the paper's
//! experiment. It holds the robot's joint state, checks every trajectory against the
//! robot model before anything moves, runs it by interpolation at a fixed control
//! rate (real time, or faster for tests and simulation), and publishes the state
//! every period.
//!
//! | key | kind | payload → reply |
//! |---|---|---|
//! | `<ns>/controller/execute` | queryable | [`ExecuteRequest`](tsukami_msgs::controller::ExecuteRequest) → [`ExecuteReply`](tsukami_msgs::controller::ExecuteReply) (accepted and how the run ended, or rejected with the reason) |
//! | `<ns>/controller/stop` | queryable | `{}` → `{"stopped": bool}`; the run ends within one control period |
//! | `<ns>/controller/state` | publication, and queryable for the latest | [`ControllerState`](tsukami_msgs::controller::ControllerState) every period |
//! | `<ns>/controller/info` | queryable | name, version, keys |
//!
//! Modules, lowest first: [`joints`] (the commandable joints and limits from the
//! URDF), [`interpolate`] (linear and cubic Hermite segments), [`trajectory`] (the
//! checks), [`executor`] (state and control periods, no bus, no clock), [`node`]
//! (the bus and the pacing).

pub mod executor;
pub mod interpolate;
pub mod joints;
pub mod node;
pub mod trajectory;

pub use executor::Executor;
pub use joints::JointTable;
pub use node::{ControllerNode, NodeOptions};

/// The component's name: its key prefix and what `<ns>/controller/info` reports.
pub const NAME: &str = "controller";
/// One-line description for `<ns>/controller/info`.
pub const DESCRIPTION: &str =
    "robot controller: checks joint trajectories against the robot model and executes them";

/// Starts a controller for `table` on a session opened from `bus` (used by the
/// binary; tests may call it to run the real node in-process).
pub fn start(
    bus: &tsukami_bus::ComponentArgs,
    executor: Executor,
    options: NodeOptions,
) -> anyhow::Result<ControllerNode> {
    let component =
        tsukami_bus::Component::start(NAME, env!("CARGO_PKG_VERSION"), DESCRIPTION, bus)?;
    ControllerNode::start(component, executor, options)
}
