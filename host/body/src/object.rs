//! Graspable objects: a shape (mesh or primitive) with mass and friction,
//! described by a small TOML file beside its mesh.
//!
//! `models/objects/can_350ml/object.toml`:
//! ```toml
//! name = "can_350ml"
//! description = "350 ml beverage can, 66 mm x 122 mm"
//! shape = { mesh = { path = "can_350ml.stl" } }
//! mass = 0.15
//! friction = 0.5
//! ```
//! [`ObjectModel::load`] validates it (unknown keys are errors) and exposes
//! the object's triangles in the object frame ([`ObjectModel::mesh`]) for
//! the planner's convex boxes, and whether the surface is closed.

use std::path::{Path, PathBuf};

use nalgebra::Isometry3;
use serde::{Deserialize, Serialize};

use crate::collision::{CollisionObject, Part};
use crate::error::{BodyError, Result};
use crate::mesh::TriangleMesh;
use crate::model::Geometry;
use crate::shape_spec::{geometry_mesh, ShapeSpec};

/// The TOML form of an object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectFile {
    /// Object name (defaults to the folder name).
    #[serde(default)]
    pub name: Option<String>,
    /// Free text: what it is, its dimensions and their source.
    #[serde(default)]
    pub description: Option<String>,
    /// Shape in the object frame.
    pub shape: ShapeSpec,
    /// Mass (kg).
    pub mass: f64,
    /// Coulomb friction coefficient μ against the fingers.
    pub friction: f64,
}

/// A loaded object: geometry, triangles, mass and friction.
#[derive(Debug, Clone)]
pub struct ObjectModel {
    /// Name.
    pub name: String,
    /// Description from the file.
    pub description: String,
    /// The file it came from (empty when built in code).
    pub source: PathBuf,
    /// Collision geometry in the object frame.
    pub geometry: Geometry,
    /// Surface triangles in the object frame (tessellated for primitives).
    pub mesh: TriangleMesh,
    /// Mass (kg).
    pub mass: f64,
    /// Friction coefficient μ.
    pub friction: f64,
}

impl ObjectModel {
    /// Loads `object.toml` (or any object TOML file).
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| BodyError::Io {
            file: path.to_path_buf(),
            source,
        })?;
        let file: ObjectFile = toml::from_str(&text).map_err(|e| BodyError::Toml {
            file: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let default_name = path
            .parent()
            .and_then(|p| p.file_name())
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let base = path.parent().unwrap_or(Path::new("."));
        let geometry = file.shape.to_geometry(path, "shape", base)?;
        Self::new(
            file.name.unwrap_or(default_name),
            file.description.unwrap_or_default(),
            path,
            geometry,
            file.mass,
            file.friction,
        )
    }

    /// Builds an object in code; `source` is used in error messages.
    pub fn new(
        name: String,
        description: String,
        source: &Path,
        geometry: Geometry,
        mass: f64,
        friction: f64,
    ) -> Result<Self> {
        let bad = |element: &str, message: String| BodyError::Invalid {
            file: source.to_path_buf(),
            element: element.to_string(),
            message,
        };
        if !(mass.is_finite() && mass > 0.0) {
            return Err(bad("mass", format!("{mass} must be finite and > 0")));
        }
        if !(friction.is_finite() && friction >= 0.0) {
            return Err(bad(
                "friction",
                format!("{friction} must be finite and >= 0"),
            ));
        }
        let mesh = geometry_mesh(&geometry);
        Ok(Self {
            name,
            description,
            source: source.to_path_buf(),
            geometry,
            mesh,
            mass,
            friction,
        })
    }

    /// True when the surface is closed (a solid); open meshes should be
    /// refused where a solid is needed.
    pub fn is_closed(&self) -> bool {
        match &self.geometry {
            Geometry::Mesh { mesh, .. } => mesh.is_closed(),
            _ => true,
        }
    }

    /// A collision body of this object at `pose` in the world.
    pub fn collision_object(&self, pose: Isometry3<f64>) -> Result<CollisionObject> {
        let part = Part::from_geometry(&Isometry3::identity(), &self.geometry)?;
        Ok(CollisionObject::new(self.name.clone(), pose, vec![part]))
    }
}
