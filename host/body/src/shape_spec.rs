//! Shapes and poses as written in object and scene TOML files.
//!
//! ```toml
//! shape = { box = { size = [0.6, 1.2, 0.03] } }
//! shape = { cylinder = { radius = 0.033, length = 0.122 } }
//! shape = { mesh = { path = "can_350ml.stl", scale = [1.0, 1.0, 1.0] } }
//! pose = { xyz = [0.45, -0.2, 0.7], rpy = [0.0, 0.0, 1.57] }
//! ```
//! Cylinders and capsules are along z and centred, as in URDF; mesh paths
//! are relative to the TOML file.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{BodyError, Result};
use crate::mesh::TriangleMesh;
use crate::model::Geometry;

/// A pose: translation (m) and roll-pitch-yaw (rad, URDF convention).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// Translation.
    #[serde(default)]
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw.
    #[serde(default)]
    pub rpy: [f64; 3],
}

impl PoseSpec {
    /// The isometry, or an error naming `file` and `field` if a value is not finite.
    pub fn to_isometry(&self, file: &Path, field: &str) -> Result<Isometry3<f64>> {
        if !self.xyz.iter().chain(&self.rpy).all(|v| v.is_finite()) {
            return Err(BodyError::Invalid {
                file: file.to_path_buf(),
                element: field.to_string(),
                message: format!("non-finite value in pose {self:?}"),
            });
        }
        Ok(Isometry3::from_parts(
            Translation3::new(self.xyz[0], self.xyz[1], self.xyz[2]),
            UnitQuaternion::from_euler_angles(self.rpy[0], self.rpy[1], self.rpy[2]),
        ))
    }
}

/// A shape in a TOML file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeSpec {
    /// A box, centred.
    Box {
        /// Edge lengths (m).
        size: [f64; 3],
    },
    /// A cylinder along z, centred.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Length (m).
        length: f64,
    },
    /// A capsule along z, centred (`length` of the cylindrical part).
    Capsule {
        /// Radius (m).
        radius: f64,
        /// Length of the cylindrical part (m).
        length: f64,
    },
    /// A sphere, centred.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// A triangle mesh file (STL, OBJ, PLY or Collada).
    Mesh {
        /// Path, relative to the TOML file.
        path: PathBuf,
        /// Scale per axis (default 1).
        #[serde(default)]
        scale: Option<[f64; 3]>,
    },
}

impl ShapeSpec {
    /// Validates the numbers, loads meshes (relative to `base_dir`) and
    /// returns the geometry. `file` and `field` name the place for errors.
    pub fn to_geometry(&self, file: &Path, field: &str, base_dir: &Path) -> Result<Geometry> {
        let bad = |message: String| BodyError::Invalid {
            file: file.to_path_buf(),
            element: field.to_string(),
            message,
        };
        let pos = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(bad(format!("{name} = {v} must be finite and > 0")))
            }
        };
        Ok(match self {
            ShapeSpec::Box { size } => Geometry::Box {
                size: Vector3::new(
                    pos("size", size[0])?,
                    pos("size", size[1])?,
                    pos("size", size[2])?,
                ),
            },
            ShapeSpec::Cylinder { radius, length } => Geometry::Cylinder {
                radius: pos("radius", *radius)?,
                length: pos("length", *length)?,
            },
            ShapeSpec::Capsule { radius, length } => Geometry::Capsule {
                radius: pos("radius", *radius)?,
                length: if length.is_finite() && *length >= 0.0 {
                    *length
                } else {
                    return Err(bad(format!("length = {length} must be finite and >= 0")));
                },
            },
            ShapeSpec::Sphere { radius } => Geometry::Sphere {
                radius: pos("radius", *radius)?,
            },
            ShapeSpec::Mesh { path, scale } => {
                let s = scale.unwrap_or([1.0; 3]);
                let scale = Vector3::new(s[0], s[1], s[2]);
                let full = base_dir.join(path);
                if !full.is_file() {
                    return Err(BodyError::MissingMesh {
                        file: file.to_path_buf(),
                        element: field.to_string(),
                        mesh: full,
                    });
                }
                let mesh = TriangleMesh::load(&full, scale)?;
                Geometry::Mesh {
                    path: full,
                    scale,
                    mesh: Arc::new(mesh),
                }
            }
        })
    }
}

/// A triangle mesh of a geometry (primitives are tessellated), in the
/// geometry's frame; used to expose every object's surface as triangles.
pub fn geometry_mesh(geometry: &Geometry) -> TriangleMesh {
    const SEGMENTS: usize = 48;
    match geometry {
        Geometry::Box { size } => TriangleMesh::cuboid(*size),
        Geometry::Cylinder { radius, length } => {
            let h = length / 2.0;
            TriangleMesh::lathe(&[(*radius, -h), (*radius, h)], SEGMENTS)
        }
        Geometry::Capsule { radius, length } => {
            let h = length / 2.0;
            let mut profile = Vec::new();
            for i in 1..8 {
                let t = std::f64::consts::FRAC_PI_2 * i as f64 / 8.0;
                profile.push((radius * t.sin(), -h - radius * t.cos()));
            }
            for i in 0..=8 {
                let t = std::f64::consts::FRAC_PI_2 * i as f64 / 8.0;
                profile.push((radius * t.cos(), h + radius * t.sin()));
            }
            profile.pop(); // the top pole is the cap centre
            let mut m = TriangleMesh::lathe(&profile, SEGMENTS);
            let n = m.vertices.len();
            m.vertices[n - 2].z = -h - radius;
            m.vertices[n - 1].z = h + radius;
            m
        }
        Geometry::Sphere { radius } => TriangleMesh::uv_sphere(*radius, 16, SEGMENTS),
        Geometry::Mesh { mesh, .. } => (**mesh).clone(),
    }
}
