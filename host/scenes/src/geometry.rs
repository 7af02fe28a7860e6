//! Message geometry ↔ body geometry: poses and environment obstacles.
//!
//! Every planner turns `set_env` obstacles and message poses into `tsukami-body`
//! collision objects and isometries; this module does it once, validating every value
//! and naming the field that was wrong, so two planners cannot disagree on what a
//! valid obstacle is.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tsukami_body::collision::{CollisionObject, Part};
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::model::Geometry;
use tsukami_msgs::planner::{Obstacle, ObstacleShape};
use tsukami_msgs::Pose;

/// A message pose as an isometry. The error names the bad part (`position` or
/// `quaternion`) and why.
pub fn pose_to_isometry(pose: &Pose) -> Result<Isometry3<f64>, String> {
    pose.validate()
        .map_err(|part| format!("{part}: must be finite (and the quaternion of unit norm)"))?;
    let [x, y, z, w] = pose.quaternion;
    Ok(Isometry3::from_parts(
        Translation3::from(Vector3::from(pose.position)),
        UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)),
    ))
}

/// An isometry as a message pose.
pub fn isometry_to_pose(iso: &Isometry3<f64>) -> Pose {
    let q = iso.rotation;
    Pose {
        position: [iso.translation.x, iso.translation.y, iso.translation.z],
        quaternion: [q.i, q.j, q.k, q.w],
    }
}

/// Why an obstacle could not be built; `field` is relative to the obstacle
/// (`pose`, `shape`, `shape.mesh.path`, …).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ObstacleError {
    /// A value is out of range.
    #[error("{field}: {message}")]
    Invalid {
        /// The field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A mesh file could not be read or used.
    #[error("{field}: {message}")]
    Model {
        /// The field.
        field: String,
        /// What is wrong.
        message: String,
    },
}

fn invalid(field: &str, message: impl Into<String>) -> ObstacleError {
    ObstacleError::Invalid {
        field: field.to_owned(),
        message: message.into(),
    }
}

/// Builds the collision object of one `set_env` obstacle, checking every dimension.
pub fn build_obstacle(o: &Obstacle) -> Result<CollisionObject, ObstacleError> {
    if o.name.is_empty() {
        return Err(invalid("name", "must not be empty"));
    }
    let pose = pose_to_isometry(&o.pose).map_err(|m| invalid("pose", m))?;
    let positive = |v: &[f64]| v.iter().all(|x| x.is_finite() && *x > 0.0);
    let bad_size = || invalid("shape", "dimensions must be finite and > 0");
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
            if positive(&[*radius]) && length.is_finite() && *length >= 0.0 =>
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
                return Err(invalid("shape.mesh.scale", format!("{s} must be > 0")));
            }
            let mesh = TriangleMesh::load(Path::new(path), Vector3::repeat(s)).map_err(|e| {
                ObstacleError::Model {
                    field: "shape.mesh.path".to_owned(),
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
    let part = Part::from_geometry(&Isometry3::identity(), &geometry).map_err(|e| {
        ObstacleError::Model {
            field: "shape".to_owned(),
            message: e.to_string(),
        }
    })?;
    Ok(CollisionObject::new(o.name.clone(), pose, vec![part]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(shape: ObstacleShape) -> Obstacle {
        Obstacle {
            name: "table".into(),
            shape,
            pose: Pose::IDENTITY,
        }
    }

    #[test]
    fn poses_round_trip() {
        let pose = Pose {
            position: [0.1, -0.2, 0.3],
            quaternion: [
                0.0,
                0.0,
                std::f64::consts::FRAC_1_SQRT_2,
                std::f64::consts::FRAC_1_SQRT_2,
            ],
        };
        let back = isometry_to_pose(&pose_to_isometry(&pose).unwrap());
        for (a, b) in pose
            .position
            .iter()
            .chain(&pose.quaternion)
            .zip(back.position.iter().chain(&back.quaternion))
        {
            assert!((a - b).abs() < 1e-8);
        }
        let nan = Pose {
            position: [f64::NAN, 0.0, 0.0],
            ..Pose::IDENTITY
        };
        assert!(pose_to_isometry(&nan).unwrap_err().contains("position"));
    }

    #[test]
    fn bad_obstacles_name_the_field() {
        assert!(build_obstacle(&table(ObstacleShape::Box {
            size: [1.0, 0.6, 0.7]
        }))
        .is_ok());
        let e = build_obstacle(&table(ObstacleShape::Box {
            size: [1.0, -0.6, 0.7],
        }))
        .unwrap_err();
        assert!(
            matches!(&e, ObstacleError::Invalid { field, .. } if field == "shape"),
            "{e}"
        );
        let e = build_obstacle(&table(ObstacleShape::Mesh {
            path: "/nonexistent/t.stl".into(),
            scale: None,
        }))
        .unwrap_err();
        assert!(
            matches!(&e, ObstacleError::Model { field, .. } if field == "shape.mesh.path"),
            "{e}"
        );
        let mut unnamed = table(ObstacleShape::Sphere { radius: 0.1 });
        unnamed.name.clear();
        assert!(build_obstacle(&unnamed)
            .unwrap_err()
            .to_string()
            .starts_with("name"));
    }
}
