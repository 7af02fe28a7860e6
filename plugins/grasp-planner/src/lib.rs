//! The paper's grasp planner (Harada, Tsuji et al., "Grasp Planning for a Humanoid Hand").
pub mod grasp_type;
pub mod ocp;
pub mod selection;
