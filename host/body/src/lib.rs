//! # tsukami-body
//!
//! Robot and object models for Tsukami (Choreonoid's "Body" library in the
//! original grasp plugin): URDF loading, forward kinematics and Jacobians,
//! inverse kinematics over a chosen joint list, and collision / distance
//! queries with witness points and normals (parry3d).
//!
//! The public API speaks nalgebra; parry's glam types stay inside
//! [`convert`] and [`collision`]. No I/O happens here beyond reading model,
//! mesh, object and scene files.
//!
//! ```no_run
//! use tsukami_body::{urdf::load_urdf, kinematics::FkState, collision::RobotCollision};
//! let robot = load_urdf("models/robots/tsukami_humanoid/tsukami_humanoid.urdf".as_ref())?;
//! let mut fk = FkState::new(&robot);
//! robot.forward_kinematics(&robot.rest_positions(), &mut fk);
//! let collision = RobotCollision::new(&robot)?;
//! assert!(collision.first_self_collision(&fk, 0.0).is_none());
//! # Ok::<(), tsukami_body::BodyError>(())
//! ```
//!
//! Modules, lowest first: [`limits`] (parse limits, bounded reads),
//! [`mesh`], [`mesh_clean`], [`mesh_io`], [`ply`] and [`mesh_inline`] (triangle meshes: STL,
//! OBJ, PLY, Collada; files or base64 in a request), [`packages`] (`package://` lookup), [`model`], [`urdf_xml`] and
//! [`urdf`] (the kinematic tree, lenient or strict), [`kinematics`] (FK, Jacobians), [`ik`],
//! [`collision`] (with its fast narrow phase [`capsule_mesh`]; [`collision_matrix`]
//! proposes the link pairs a robot description may leave unchecked),
//! [`shape_spec`], [`object`] and [`scene`] (TOML files).

pub mod capsule_mesh;
pub mod collada;
pub mod collision;
pub mod collision_matrix;
pub mod compose;
pub mod convert;
pub mod error;
pub mod files;
pub mod ik;
pub mod kinematics;
pub mod limits;
pub mod mesh;
pub mod mesh_clean;
pub mod mesh_inline;
pub mod mesh_inside;
pub mod mesh_io;
pub mod model;
pub mod object;
pub mod packages;
pub mod ply;
pub mod reach;
pub mod scene;
pub mod shape_spec;
pub mod urdf;
pub mod urdf_write;
pub mod urdf_xml;

pub use error::{BodyError, LoadWarning, Result, WarningKind};
pub use model::{JointId, LinkId, RobotModel};
