//! Tsukami's trajectory planner: turns a planned grasp into a joint trajectory the
//! controller can play back — reach, approach, close, lift — as the
//! `trajectory-planner` plugin (`<ns>/motion/plan`, [`plugin`]).
//!
//! The algorithms are plain modules, independent of the plugin boundary and of the
//! bus:
//! - [`rrt_connect`]: bidirectional RRT-Connect (Kuffner & LaValle, ICRA 2000) over
//!   a joint subspace, with a sample budget and a seed;
//! - [`shortcut`]: random shortcut smoothing of a collision-free path;
//! - [`resolution`]: how finely a straight joint-space segment must be checked so
//!   that no point of any link moves more than a stated distance between checks;
//! - [`checker`]: a robot among obstacles, the object and a carried object, as the
//!   trees' collision test; [`bodies`]: its broad phase (the rigid bodies the
//!   planned joints move);
//! - [`cartesian`]: straight palm lines (approach, lift) by IK continuation;
//! - [`timing`]: time scaling of a piecewise-linear path within every joint's
//!   velocity limit and an acceleration limit; [`assemble`]: phases into one
//!   trajectory;
//! - [`goal`]: the request's start and grasp checked against the robot;
//!   [`revalidate`]: the grasp's world version, and the grasp checked again on
//!   the current world when asked; [`squeeze`]: the grasp's squeeze as the
//!   `command` of the points from the end of `close` through the lift;
//! - [`motion`]: the whole pipeline (keeping [`motion::Clearance`] from the
//!   obstacles); [`clearance`]: the smallest distance a motion kept, for the reply; [`world`]: the planner kit's world, shared
//!   with the grasp planners; [`error`]: failures and their codes.

pub mod assemble;
pub mod bodies;
pub mod cartesian;
pub mod checker;
pub mod clearance;
pub mod error;
pub mod goal;
pub mod motion;
pub mod plugin;
pub mod resolution;
pub mod revalidate;
pub mod rrt_connect;
pub mod shortcut;
pub mod squeeze;
pub mod timing;
pub mod world;
