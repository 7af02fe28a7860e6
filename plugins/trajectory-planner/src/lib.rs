//! Tsukami's trajectory planner: turns a planned grasp into a joint trajectory the
//! controller can play back — reach, approach, close, lift (and retreat).
//!
//! The algorithms are plain modules, independent of the plugin boundary and of the
//! bus:
//! - [`rrt_connect`]: bidirectional RRT-Connect (Kuffner & LaValle, ICRA 2000) over
//!   a joint subspace, with a sample budget and a seed;
//! - [`shortcut`]: random shortcut smoothing of a collision-free path;
//! - [`resolution`]: how finely a straight joint-space segment must be checked so
//!   that no point of any link moves more than a stated distance between checks;
//! - [`checker`]: a robot among obstacles as the trees' collision test;
//! - [`timing`]: time scaling of a piecewise-linear path within every joint's
//!   velocity limit and an acceleration limit.

pub mod checker;
pub mod resolution;
pub mod rrt_connect;
pub mod shortcut;
pub mod timing;
