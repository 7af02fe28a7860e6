//! Scenes: a TOML file that places the robot, the objects to grasp and the
//! obstacles (tables, counters, a fridge with shelves and a door).
//!
//! ```toml
//! name = "can_waist"
//! description = "350 ml can on a 0.72 m table"
//! [robot]
//! model = "../robots/tsukami_humanoid/tsukami_humanoid.urdf"
//! base = { xyz = [0, 0, 0] }
//!
//! [[objects]]
//! name = "can"
//! model = "can_350ml"            # models/objects/can_350ml/object.toml
//! pose = { xyz = [0.40, -0.22, 0.72] }
//!
//! [[obstacles]]
//! name = "table"
//! pose = { xyz = [0.55, -0.2, 0.0] }
//! parts = [ { shape = { box = { size = [0.6, 1.0, 0.03] } }, pose = { xyz = [0, 0, 0.705] } } ]
//! ```
//! Paths are relative to the scene file. An object is either `model = NAME`
//! (looked up as `../objects/NAME/object.toml` from the scene's folder, or a
//! path to an object TOML) or an inline `shape` with `mass` and `friction`;
//! `mass` and `friction` given beside a model override the model's values.
//! Unknown keys are errors.

use std::path::{Path, PathBuf};

use nalgebra::Isometry3;
use serde::{Deserialize, Serialize};

use crate::collision::{CollisionObject, Part};
use crate::error::{BodyError, Result};
use crate::model::RobotModel;
use crate::object::ObjectModel;
use crate::shape_spec::{PoseSpec, ShapeSpec};

/// `[robot]` of a scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// URDF path, relative to the scene file.
    pub model: PathBuf,
    /// Pose of the robot's root link in the world.
    #[serde(default)]
    pub base: PoseSpec,
}

/// `[[objects]]` of a scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Name in the scene.
    pub name: String,
    /// Object model name or path to an object TOML.
    #[serde(default)]
    pub model: Option<String>,
    /// Inline shape (instead of `model`).
    #[serde(default)]
    pub shape: Option<ShapeSpec>,
    /// Mass override (kg).
    #[serde(default)]
    pub mass: Option<f64>,
    /// Friction override.
    #[serde(default)]
    pub friction: Option<f64>,
    /// Pose of the object frame in the world.
    pub pose: PoseSpec,
}

/// One shape of an obstacle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartSpec {
    /// The shape.
    pub shape: ShapeSpec,
    /// Pose in the obstacle frame.
    #[serde(default)]
    pub pose: PoseSpec,
}

/// `[[obstacles]]` of a scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSpec {
    /// Name.
    pub name: String,
    /// Pose of the obstacle frame in the world.
    #[serde(default)]
    pub pose: PoseSpec,
    /// Its shapes.
    pub parts: Vec<PartSpec>,
}

/// The TOML form of a scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Scene name.
    #[serde(default)]
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// The robot.
    pub robot: RobotSpec,
    /// Objects to grasp.
    #[serde(default)]
    pub objects: Vec<ObjectSpec>,
    /// Obstacles.
    #[serde(default)]
    pub obstacles: Vec<ObstacleSpec>,
}

/// An object placed in a scene.
#[derive(Debug, Clone)]
pub struct SceneObject {
    /// Name in the scene.
    pub name: String,
    /// The object model (mass and friction after overrides).
    pub model: ObjectModel,
    /// Pose in the world.
    pub pose: Isometry3<f64>,
    /// Collision body at `pose`.
    pub collision: CollisionObject,
}

/// A loaded scene.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Scene name.
    pub name: String,
    /// Description.
    pub description: String,
    /// The scene file.
    pub source: PathBuf,
    /// The robot model.
    pub robot: RobotModel,
    /// The URDF path.
    pub robot_path: PathBuf,
    /// Pose of the robot's root link in the world.
    pub robot_base: Isometry3<f64>,
    /// Objects.
    pub objects: Vec<SceneObject>,
    /// Obstacles.
    pub obstacles: Vec<CollisionObject>,
}

impl Scene {
    /// Loads a scene file, its robot, objects and obstacles.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| BodyError::Io {
            file: path.to_path_buf(),
            source,
        })?;
        let file: SceneFile = toml::from_str(&text).map_err(|e| BodyError::Toml {
            file: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let robot_path = dir.join(&file.robot.model);
        let robot = crate::urdf::load_urdf(&robot_path)?;
        let robot_base = file.robot.base.to_isometry(path, "robot.base")?;
        let mut objects = Vec::new();
        for (i, spec) in file.objects.iter().enumerate() {
            let field = format!("objects[{i}] ('{}')", spec.name);
            let mut model = match (&spec.model, &spec.shape) {
                (Some(name), None) => {
                    let candidate = if name.ends_with(".toml") {
                        dir.join(name)
                    } else {
                        dir.join("../objects").join(name).join("object.toml")
                    };
                    if !candidate.is_file() {
                        return Err(BodyError::Invalid {
                            file: path.to_path_buf(),
                            element: format!("{field}.model"),
                            message: format!("object model file {} not found", candidate.display()),
                        });
                    }
                    ObjectModel::load(&candidate)?
                }
                (None, Some(shape)) => {
                    let geometry = shape.to_geometry(path, &format!("{field}.shape"), dir)?;
                    let need = |v: Option<f64>, what: &str| {
                        v.ok_or_else(|| BodyError::Invalid {
                            file: path.to_path_buf(),
                            element: format!("{field}.{what}"),
                            message: "required with an inline shape".into(),
                        })
                    };
                    ObjectModel::new(
                        spec.name.clone(),
                        String::new(),
                        path,
                        geometry,
                        need(spec.mass, "mass")?,
                        need(spec.friction, "friction")?,
                    )?
                }
                _ => {
                    return Err(BodyError::Invalid {
                        file: path.to_path_buf(),
                        element: field,
                        message: "give exactly one of `model` and `shape`".into(),
                    })
                }
            };
            if spec.mass.is_some() || spec.friction.is_some() {
                model = ObjectModel::new(
                    model.name.clone(),
                    model.description.clone(),
                    path,
                    model.geometry.clone(),
                    spec.mass.unwrap_or(model.mass),
                    spec.friction.unwrap_or(model.friction),
                )?;
            }
            let pose = spec.pose.to_isometry(path, &format!("{field}.pose"))?;
            let mut collision = model.collision_object(pose)?;
            collision.name = spec.name.clone();
            objects.push(SceneObject {
                name: spec.name.clone(),
                model,
                pose,
                collision,
            });
        }
        let mut obstacles = Vec::new();
        for (i, spec) in file.obstacles.iter().enumerate() {
            let field = format!("obstacles[{i}] ('{}')", spec.name);
            let pose = spec.pose.to_isometry(path, &format!("{field}.pose"))?;
            let parts = spec
                .parts
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let pf = format!("{field}.parts[{k}]");
                    let g = p.shape.to_geometry(path, &format!("{pf}.shape"), dir)?;
                    let o = p.pose.to_isometry(path, &format!("{pf}.pose"))?;
                    Part::from_geometry(&o, &g)
                })
                .collect::<Result<Vec<_>>>()?;
            if parts.is_empty() {
                return Err(BodyError::Invalid {
                    file: path.to_path_buf(),
                    element: field,
                    message: "an obstacle needs at least one part".into(),
                });
            }
            obstacles.push(CollisionObject::new(spec.name.clone(), pose, parts));
        }
        Ok(Self {
            name: file.name.unwrap_or_else(|| {
                path.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            }),
            description: file.description.unwrap_or_default(),
            source: path.to_path_buf(),
            robot,
            robot_path,
            robot_base,
            objects,
            obstacles,
        })
    }

    /// The object with this name.
    pub fn object(&self, name: &str) -> Option<&SceneObject> {
        self.objects.iter().find(|o| o.name == name)
    }

    /// References to the obstacles, for collision queries.
    pub fn obstacle_refs(&self) -> Vec<&CollisionObject> {
        self.obstacles.iter().collect()
    }

    /// A world pose expressed in the robot's root frame (IK targets are in
    /// the root frame).
    pub fn to_robot_frame(&self, world: &Isometry3<f64>) -> Isometry3<f64> {
        self.robot_base.inverse() * world
    }
}
