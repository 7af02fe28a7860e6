//! Building blocks a planner may call or ignore: finger closing, finger force,
//! collision passes, the hold rule and its re-check under pose errors, whole-body IK stages, grasp-type postures and surface
//! sampling. Each works on the kit's
//! [`crate::Robot`] / [`crate::Hand`] and knows nothing of any planner.

pub mod closing;
pub mod collision;
pub mod force;
pub mod grasp_check;
pub mod hold;
pub mod posture;
pub mod robust;
pub mod stages;
pub mod surface;
pub mod wrap;
