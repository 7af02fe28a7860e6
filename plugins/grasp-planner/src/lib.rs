//! # tsukami-grasp-planner
//!
//! The paper's grasp planner (Harada, Tsuji et al., "Grasp Planning for a
//! Humanoid Hand", section 3 and Algorithm 1) as a library and a plugin.
//!
//! Pipeline, one module per step:
//! [`ocp`] (object boxes and free faces) → [`selection`] (eqs. (1)–(5), score
//! (3)) → [`palm_pose`] (nominal palm pose, section 3.2; [`tilt`] for the
//! approaches at an angle tried when the paper's fail) → [`search`]
//! (Algorithm 1, with [`finger_closing`]) → [`whole_body`] (section 3.4
//! fallback), driven by [`planner::Paper`], the planner kit's `GraspPlanner`.
//! The hand's reference postures are the kit's grasp types ([`grasp_type`],
//! `docs/grasp-types.md`), resolved to ids in [`hand`]; the object's OCPs are
//! built in [`object`]. [`plugin`] exports the planner with the kit's
//! `export_planner!`; the kit owns the world, validation, dispatch, error codes,
//! the reply and the final verification.
//!
//! The algorithm does no I/O: the kit reads every model file.
//!
//! ```no_run
//! use std::sync::atomic::AtomicBool;
//! use tsukami_grasp_planner::planner::Planner;
//! use tsukami_scenes::scene_requests;
//! let req = scene_requests("models/scenes/can_breast.toml".as_ref()).unwrap();
//! let planner = Planner::new("models");
//! planner.set_robot(&req.robot).unwrap();
//! planner.set_object(&req.object).unwrap();
//! planner.set_env(&req.env).unwrap();
//! let grasp = planner
//!     .plan(&Default::default(), &AtomicBool::new(false), &mut |_| {})
//!     .unwrap();
//! assert_eq!(grasp.grasp_type.name, "fingertip4_mid");
//! ```

pub mod clearance;
pub mod closing_speed;
pub mod edges;
pub mod finger_closing;
pub mod grasp_type;
pub mod hand;
pub mod link_sets;
pub mod object;
pub mod ocp;
pub mod palm_pose;
pub mod planner;
pub mod plugin;
pub mod search;
pub mod selection;
pub mod support;
pub mod tight_box;
pub mod tilt;
pub mod verify;
pub mod whole_body;
