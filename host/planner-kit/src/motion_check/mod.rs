//! Motion checks the grasp planners and the trajectory planner share.
//!
//! What: a robot among obstacles as a collision test ([`checker`], with its
//! broad phase [`bodies`] and the segment resolution [`resolution`], behind
//! the two traits of [`path`]); straight palm lines by IK continuation
//! ([`cartesian`]); the grasp a motion ends in ([`goal`]); and the last phases
//! of a grasp's motion — approach, close, lift — checked ([`phases`]).
//!
//! Why: a grasp is executable only when its approach, its closing and its lift
//! are free. The grasp planner checks them before it returns a grasp, and the
//! trajectory planner plans them, with the same code: what the planner
//! promises is what the motion does (MoveIt's planning scene plays this part).
//!
//! How: every check is at a stated resolution (no point of any link moves more
//! than `max_travel` between two checks), against the obstacles, the object,
//! the robot itself (every link pair but adjacent ones and the description's
//! `allowed_collisions`) and, after closing, the carried object.
//!
//! ```
//! use tsukami_planner_kit::motion_check::phases::{PhaseParams, OPENINGS};
//! let p = PhaseParams::default();
//! assert_eq!((p.clearance.body, p.clearance.hand), (0.010, 0.003));
//! assert_eq!(OPENINGS[0], 1.0);
//! ```

pub mod bodies;
pub mod cartesian;
pub mod checker;
pub mod goal;
pub mod path;
pub mod phases;
pub mod resolution;
