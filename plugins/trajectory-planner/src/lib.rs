//! Tsukami's trajectory planner: turns a planned grasp into a joint trajectory the
//! controller can play back — reach, approach, close, lift — as the
//! `trajectory-planner` plugin (`<ns>/motion/plan`, [`plugin`]).
//!
//! The algorithms are plain modules, independent of the plugin boundary and of the
//! bus:
//! - [`rrt_connect`]: bidirectional RRT-Connect (Kuffner & LaValle, ICRA 2000) over
//!   a joint subspace, with a sample budget and a seed;
//! - [`shortcut`]: random shortcut smoothing of a collision-free path;
//! - the collision test of the trees, the straight palm lines and the checks
//!   of the approach, close and lift are the planner kit's
//!   (`tsukami_planner_kit::motion_check`), shared with the grasp planner, which
//!   checks the same phases before it returns a grasp;
//! - [`timing`]: time scaling of a path within every joint's velocity limit and
//!   an acceleration limit, its corners rounded ([`blend`]) and its speed the
//!   fastest by reachability analysis ([`topp`], TOPP-RA); [`assemble`]: phases
//!   into one trajectory;
//! - [`goal`]: the request's start and grasp checked against the robot, into
//!   the kit's `Goal`;
//!   [`revalidate`]: the grasp's world version, and the grasp checked again on
//!   the current world when asked; [`squeeze`]: the grasp's squeeze as the
//!   `command` of the points from the end of `close` through the lift;
//! - [`motion`]: the whole pipeline (keeping the kit's `Clearance` from the
//!   obstacles); [`clearance`]: the smallest distance a motion kept, for the reply; [`world`]: the planner kit's world, shared
//!   with the grasp planners; [`error`]: failures and their codes.

pub mod assemble;
pub mod blend;
pub mod clearance;
pub mod error;
pub mod goal;
pub mod motion;
pub mod plugin;
pub mod revalidate;
pub mod rounding;
pub mod rrt_connect;
pub mod shortcut;
pub mod squeeze;
pub mod timing;
pub mod topp;
pub mod world;

/// The kit's motion checks under the names this crate had for them.
pub use tsukami_planner_kit::motion_check::{bodies, cartesian, checker, resolution};
