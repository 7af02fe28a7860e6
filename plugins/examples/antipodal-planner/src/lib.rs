//! # tsukami-antipodal-planner
//!
//! A second, simpler `grasp-planner` plugin for Tsukami — and **the template
//! for writing one**. It is built only against the `host/` crates
//! (`tsukami-plugin-api`, `tsukami-msgs`, `tsukami-body`, `tsukami-grasp`), so
//! it shows what a third party has to write; the host swaps it in for the
//! built-in planner by configuration alone:
//!
//! ```toml
//! [[plugin]]
//! role = "grasp-planner"
//! library = "tsukami_antipodal_planner"
//! [plugin.config]
//! models_dir = "models"
//! ```
//!
//! ## The algorithm
//! Antipodal pinch search: sample pairs of surface points with opposing
//! normals ([`antipodal`]), open the hand's thumb–index–middle pinch just
//! wider than the pair and place the palm on it ([`hand`]), solve arm IK
//! (then arm + waist, then arm + waist + squat), reject collisions, close the
//! three fingers until they touch, and accept the first grasp whose contacts
//! resist the object's weight in the exact friction-cone test ([`planner`]).
//!
//! ## How the crate is laid out (copy this)
//! | module | holds | I/O |
//! |---|---|---|
//! | [`error`] | [`PlanError`]: one variant per failure, its wire code and details | none |
//! | [`object`], [`env`](mod@env), [`robot`] | the state built by `set_object`, `set_env`, `set_robot` | model files only |
//! | [`antipodal`], [`hand`] | the algorithm's pieces | none |
//! | [`planner`] | [`AntipodalPlanner`]: owned state, one method per command, `plan` | none |
//! | [`plugin`] | the FFI adapter: parse, dispatch, map errors, progress, cancel | — |
//!
//! Rules the template follows:
//! - **state** is owned by the planner and changed through `&mut self` only;
//!   the host calls a plugin one command at a time;
//! - **validation** happens before any state changes, and every error names
//!   the field (`mass`, `obstacles[1].shape`, `max_samples`);
//! - **cancellation**: `plan` polls the `&AtomicBool` of
//!   `CallContext::cancel_flag` once per sample and returns `cancelled`;
//! - **progress**: `plan` reports through a callback, which the adapter
//!   forwards to `ctx.host().progress(json)`;
//! - **error codes** are `tsukami_msgs::ErrorCode` wire names (`not_ready`,
//!   `invalid_value`, `model_error`, `infeasible`, `cancelled`,
//!   `unknown_command`); details go in `details_json`;
//! - **config** is TOML text given to `new`: `models_dir`, falling back to
//!   the `TSUKAMI_MODELS` environment variable, then `models`.

pub mod antipodal;
pub mod env;
pub mod error;
pub mod hand;
pub mod object;
pub mod planner;
pub mod plugin;
pub mod robot;

pub use error::PlanError;
pub use planner::{AntipodalPlanner, PlannerParams};
pub use plugin::AntipodalPlugin;
