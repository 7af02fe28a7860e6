//! # tsukami-antipodal-planner
//!
//! A second `grasp-planner` plugin for Tsukami — and **the template for
//! writing one**. It implements the planner kit's one trait
//! (`tsukami_planner_kit::GraspPlanner`) and exports it with one macro; the
//! kit owns the world, validation, dispatch, error codes, the reply and the
//! verification of every grasp. Walk-through: `docs/plugins.md`.
//!
//! The host swaps it in for the built-in planner by configuration alone:
//!
//! ```toml
//! [[plugin]]
//! role = "grasp-planner"
//! library = "tsukami_antipodal_planner"
//! ```
//!
//! ## The algorithm
//! Antipodal pinch search: sample pairs of surface points with opposing
//! normals ([`antipodal`]), open the hand's fingertip pinch (from its grasp
//! types) just wider than the pair and place the palm on it ([`pinch`]),
//! solve the IK of each whole-body stage, reject collisions, close the fingers
//! until they touch, and accept the first grasp whose contacts resist the
//! object's weight in the exact friction-cone test ([`planner`]).
//!
//! | module | holds |
//! |---|---|
//! | [`antipodal`] | antipodal point pairs on a mesh |
//! | [`pinch`] | the pinch pre-shapes, derived once per robot |
//! | [`planner`] | [`Antipodal`]: the `GraspPlanner` impl, the search loop |

pub mod antipodal;
pub mod pinch;
pub mod planner;

pub use planner::Antipodal;

/// The planner with its world, for in-process use (tests, benchmarks).
pub type AntipodalPlanner = tsukami_planner_kit::Session<Antipodal>;
/// The planner as a plugin.
pub type AntipodalPlugin = tsukami_planner_kit::KitPlugin<Antipodal>;

tsukami_planner_kit::export_planner!(Antipodal);
