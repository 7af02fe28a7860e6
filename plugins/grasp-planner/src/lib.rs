//! # tsukami-grasp-planner
//!
//! The paper's grasp planner (Harada, Tsuji et al., "Grasp Planning for a
//! Humanoid Hand", section 3 and Algorithm 1) as a library and a plugin.
//!
//! Pipeline, one module per step:
//! [`ocp`] (object boxes and free faces) → [`selection`] (eqs. (1)–(5), score
//! (3)) → [`palm_pose`] (nominal palm pose, section 3.2) → [`search`]
//! (Algorithm 1, with [`finger_closing`]) → [`whole_body`] (section 3.4
//! fallback), driven by the [`planner::Planner`] state machine. The hand's
//! reference postures come from [`grasp_type`] (a TOML file, see
//! `docs/grasp-types.md`), resolved against the robot in [`hand`]; objects are
//! checked and placed in [`object`]; [`scene`] turns a scene file of `models/`
//! into planner requests.
//!
//! The algorithm does no I/O beyond loading model files through
//! `tsukami-body`; the plugin adapter only (de)serialises messages.

pub mod finger_closing;
pub mod grasp_type;
pub mod hand;
pub mod object;
pub mod ocp;
pub mod palm_pose;
pub mod planner;
pub mod scene;
pub mod search;
pub mod selection;
pub mod whole_body;
