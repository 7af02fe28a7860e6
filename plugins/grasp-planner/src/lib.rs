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
//! into planner requests. [`plugin`] is the FFI adapter (the `grasp-planner`
//! role), exported with `tsukami-plugin-api`'s `export_plugin!`.
//!
//! The algorithm does no I/O beyond loading model files through
//! `tsukami-body`; the plugin adapter only (de)serialises messages.
//!
//! ```no_run
//! use std::sync::atomic::AtomicBool;
//! use tsukami_grasp_planner::planner::Planner;
//! use tsukami_scenes::scene_requests;
//! let req = scene_requests("models/scenes/can_breast.toml".as_ref()).unwrap();
//! let mut planner = Planner::new("models");
//! planner.set_robot(&req.robot).unwrap();
//! planner.set_object(&req.object).unwrap();
//! planner.set_env(&req.env).unwrap();
//! let grasp = planner
//!     .plan(&Default::default(), &AtomicBool::new(false), &mut |_| {})
//!     .unwrap();
//! assert_eq!(grasp.grasp_type.name, "fingertip4_mid");
//! ```

pub mod finger_closing;
pub mod grasp_type;
pub mod hand;
pub mod object;
pub mod ocp;
pub mod palm_pose;
pub mod planner;
pub mod plugin;
pub mod search;
pub mod selection;
pub mod whole_body;
