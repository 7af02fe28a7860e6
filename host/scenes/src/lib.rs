//! The paper's scenes as the requests an external client sends, and the outcomes the
//! paper reports.
//!
//! - [`requests`]: a scene file (`models/scenes/*.toml`, `tsukami-body`'s format) →
//!   the SetRobot / SetObject / SetEnv messages that set a planner up for it.
//! - [`geometry`]: message poses and `set_env` obstacles as `tsukami-body` geometry.
//! - [`paper`]: the outcome the paper reports for each scene, as a check on a Plan
//!   reply.
//! - [`world`] and [`verify`]: the world a client asked for, rebuilt from its
//!   requests, and an independent check that a Plan reply holds the object in it
//!   (exact force closure recomputed, contacts on the surface, no link sunk into
//!   anything, joint limits, `joints_used`); [`surface`] measures contacts.
//!
//! The planner's own tests, the end-to-end tests over the bus and `tsukami demo`
//! all use this crate, so the scenes are turned into messages, and judged, in one
//! place. It sits beside `tsukami-body` and `tsukami-msgs` and does no I/O beyond
//! reading scene and model files.

pub mod geometry;
pub mod paper;
pub mod requests;
pub mod surface;
pub mod verify;
pub mod world;

pub use paper::{paper_scene, PaperScene, PAPER_SCENES};
pub use requests::{scene_requests, SceneError, SceneRequests};
pub use verify::{verify, Tolerances, Verdict, Violation};
pub use world::{World, WorldError};
