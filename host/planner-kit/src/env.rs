//! Obstacles of the environment (tables, shelves, walls) as collision bodies.
//!
//! What: [`build_obstacle`] turns one `set_env` obstacle into a
//! [`CollisionObject`], checking every value; errors name the obstacle's index
//! and field (`obstacles[2].shape`).
//!
//! Why: one definition of a valid obstacle for every planner, with the same
//! limits as objects (workspace, mesh size and triangle count). `set_env` is
//! all-or-nothing: every obstacle is built before the world changes.
//!
//! ```
//! use tsukami_msgs::planner::{Obstacle, ObstacleShape, pose_at};
//! use tsukami_planner_kit::{env::build_obstacle, models::Models, validate::Limits};
//! let table = Obstacle { name: "table".into(), shape: ObstacleShape::Box { size: [1.0, 0.6, 0.7] },
//!     pose: pose_at([0.6, 0.0, 0.35]) };
//! let models = Models::new(vec![]);
//! assert!(build_obstacle(&models, 0, &table, &Limits::default()).is_ok());
//! let flat = Obstacle { shape: ObstacleShape::Box { size: [1.0, 0.0, 0.7] }, ..table };
//! let e = build_obstacle(&models, 3, &flat, &Limits::default()).unwrap_err();
//! assert!(e.to_string().contains("obstacles[3].shape"));
//! ```

use std::path::PathBuf;
use std::sync::Arc;

use nalgebra::{Isometry3, Vector3};
use tsukami_body::collision::{CollisionObject, Part};
use tsukami_body::model::Geometry;
use tsukami_msgs::planner::{Obstacle, ObstacleShape};

use crate::models::Models;
use crate::object::load_mesh;
use crate::validate::{self, Limits};
use crate::KitError;

fn geometry(models: &Models, shape: &ObstacleShape, limits: &Limits) -> Result<Geometry, KitError> {
    let fits = |v: &[f64]| {
        v.iter()
            .all(|x| x.is_finite() && *x > 0.0 && *x <= limits.workspace_m)
    };
    let bad = || {
        KitError::invalid(
            "shape",
            "dimensions must be finite, > 0 and within the workspace",
        )
    };
    Ok(match shape {
        ObstacleShape::Box { size } if fits(size) => Geometry::Box {
            size: Vector3::from(*size),
        },
        ObstacleShape::Cylinder { radius, height } if fits(&[*radius, *height]) => {
            Geometry::Cylinder {
                radius: *radius,
                length: *height,
            }
        }
        ObstacleShape::Capsule { radius, length }
            if fits(&[*radius]) && (*length == 0.0 || fits(&[*length])) =>
        {
            Geometry::Capsule {
                radius: *radius,
                length: *length,
            }
        }
        ObstacleShape::Sphere { radius } if fits(&[*radius]) => {
            Geometry::Sphere { radius: *radius }
        }
        ObstacleShape::Mesh { path, scale } => {
            let (_, mesh, _) = load_mesh(models, path, *scale, "shape.mesh")?;
            let s = scale.unwrap_or(1.0);
            Geometry::Mesh {
                path: PathBuf::from(path),
                scale: Vector3::repeat(s),
                mesh: Arc::new(mesh),
            }
        }
        _ => return Err(bad()),
    })
}

/// Builds obstacle `index` of a `set_env` request.
pub fn build_obstacle(
    models: &Models,
    index: usize,
    o: &Obstacle,
    limits: &Limits,
) -> Result<CollisionObject, KitError> {
    let at = |e: KitError| match e.within(&format!("obstacles[{index}]")) {
        KitError::InvalidValue { field, message } => KitError::InvalidValue {
            field,
            message: format!("obstacle `{}`: {message}", o.name),
        },
        KitError::Model { field, message } => KitError::Model {
            field,
            message: format!("obstacle `{}`: {message}", o.name),
        },
        other => other,
    };
    if o.name.is_empty() || o.name.len() > 128 {
        return Err(at(KitError::invalid("name", "must be 1 to 128 characters")));
    }
    let pose = validate::pose(&o.pose, "pose", limits).map_err(at)?;
    let g = geometry(models, &o.shape, limits).map_err(at)?;
    let part = Part::from_geometry(&Isometry3::identity(), &g)
        .map_err(|e| at(KitError::model("shape", e.to_string())))?;
    Ok(CollisionObject::new(o.name.clone(), pose, vec![part]))
}
