//! Obstacles of the environment (tables, shelves, walls) as collision bodies.
//!
//! What: [`build_obstacle`] turns one `set_env` obstacle into a
//! [`CollisionObject`], checking every dimension; errors name the obstacle's
//! index and field (`obstacles[2].shape`).
//!
//! Why: `set_env` is all-or-nothing — every obstacle is built before the
//! planner's map of obstacles is touched.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use nalgebra::{Isometry3, Vector3};
use tsukami_body::collision::{CollisionObject, Part};
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::model::Geometry;
use tsukami_msgs::planner::{Obstacle, ObstacleShape};

use crate::error::PlanError;
use crate::object::pose_to_isometry;

/// Builds obstacle `index` of a `set_env` request.
pub fn build_obstacle(index: usize, o: &Obstacle) -> Result<CollisionObject, PlanError> {
    let field = |f: &str| format!("obstacles[{index}].{f}");
    if o.name.is_empty() {
        return Err(PlanError::invalid(field("name"), "must not be empty"));
    }
    let pose = pose_to_isometry(&o.pose, &field("pose"))?;
    let positive = |v: &[f64]| v.iter().all(|x| x.is_finite() && *x > 0.0);
    let bad_size = || PlanError::invalid(field("shape"), "dimensions must be finite and > 0");
    let geometry = match &o.shape {
        ObstacleShape::Box { size } if positive(size) => Geometry::Box {
            size: Vector3::from(*size),
        },
        ObstacleShape::Cylinder { radius, height } if positive(&[*radius, *height]) => {
            Geometry::Cylinder {
                radius: *radius,
                length: *height,
            }
        }
        ObstacleShape::Capsule { radius, length }
            if positive(&[*radius]) && *length >= 0.0 && length.is_finite() =>
        {
            Geometry::Capsule {
                radius: *radius,
                length: *length,
            }
        }
        ObstacleShape::Sphere { radius } if positive(&[*radius]) => {
            Geometry::Sphere { radius: *radius }
        }
        ObstacleShape::Mesh { path, scale } => {
            let s = scale.unwrap_or(1.0);
            if !(s.is_finite() && s > 0.0) {
                return Err(PlanError::invalid(
                    field("shape.mesh.scale"),
                    format!("{s} must be > 0"),
                ));
            }
            let mesh = TriangleMesh::load(Path::new(path), Vector3::repeat(s)).map_err(|e| {
                PlanError::Model {
                    field: field("shape.mesh.path"),
                    message: e.to_string(),
                }
            })?;
            Geometry::Mesh {
                path: PathBuf::from(path),
                scale: Vector3::repeat(s),
                mesh: Arc::new(mesh),
            }
        }
        _ => return Err(bad_size()),
    };
    let part =
        Part::from_geometry(&Isometry3::identity(), &geometry).map_err(|e| PlanError::Model {
            field: field("shape"),
            message: e.to_string(),
        })?;
    Ok(CollisionObject::new(o.name.clone(), pose, vec![part]))
}
