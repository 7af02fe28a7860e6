//! Scene files (`models/scenes/*.toml`) as planner requests.
//!
//! What: [`scene_requests`] reads a scene file of `tsukami-body`'s format and
//! returns the [`SetRobot`], [`SetObject`] and [`SetEnv`] messages that set the
//! planner up for it, in the robot's frame.
//!
//! Why: the paper's scenarios live in `models/scenes/`; the tests, the bench and
//! the demo drive the planner with exactly the messages an external client
//! would send, so a scene file is turned into messages rather than into
//! planner internals.
//!
//! How: the file is loaded and validated by `tsukami_body::scene::Scene::load`
//! (poses, models), and its TOML is read again for the model names and the
//! obstacle shapes; each part of an obstacle becomes one obstacle named
//! `obstacle/k`. Object models are sent by name when they are plain names
//! (resolved under `models/objects/` by the planner) and as mesh paths
//! otherwise.

use std::path::Path;

use nalgebra::Isometry3;
use tsukami_body::model::Geometry;
use tsukami_body::scene::{Scene, SceneFile};
use tsukami_body::shape_spec::ShapeSpec;
use tsukami_msgs::planner::{
    ObjectShape, Obstacle, ObstacleShape, Pose, SetEnv, SetObject, SetRobot,
};

/// The requests for one scene.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneRequests {
    /// Scene name.
    pub name: String,
    /// Robot request.
    pub robot: SetRobot,
    /// Object request (the scene's first object).
    pub object: SetObject,
    /// Obstacles.
    pub env: SetEnv,
}

/// Errors reading a scene.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The body crate refused the scene.
    #[error("scene: {0}")]
    Body(#[from] tsukami_body::BodyError),
    /// Something the planner cannot express.
    #[error("scene {file}: {message}")]
    Unsupported {
        /// Scene file.
        file: String,
        /// What.
        message: String,
    },
}

fn to_pose(i: &Isometry3<f64>) -> Pose {
    let q = i.rotation;
    Pose {
        position: [i.translation.x, i.translation.y, i.translation.z],
        quaternion: [q.i, q.j, q.k, q.w],
    }
}

/// Reads `path` and builds the planner's requests.
pub fn scene_requests(path: &Path) -> Result<SceneRequests, SceneError> {
    let scene = Scene::load(path)?;
    let unsupported = |m: String| SceneError::Unsupported {
        file: path.display().to_string(),
        message: m,
    };
    let text = std::fs::read_to_string(path).map_err(|e| unsupported(e.to_string()))?;
    let file: SceneFile = toml::from_str(&text).map_err(|e| unsupported(e.to_string()))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let obj = scene
        .objects
        .first()
        .ok_or_else(|| unsupported("the scene has no object".into()))?;
    let spec = &file.objects[0];
    let shape = match (&spec.model, &obj.model.geometry) {
        (Some(name), _) if !name.contains('/') && !name.ends_with(".toml") => {
            ObjectShape::Model { name: name.clone() }
        }
        (_, Geometry::Mesh { path, scale, .. }) => ObjectShape::Mesh {
            path: path.display().to_string(),
            scale: Some(scale.x),
        },
        _ => return Err(unsupported("objects must be meshes or model names".into())),
    };
    let object = SetObject {
        name: Some(obj.name.clone()),
        shape,
        mass: obj.model.mass,
        friction: Some(obj.model.friction),
        pose: to_pose(&scene.to_robot_frame(&obj.pose)),
        center_of_mass: None,
    };
    let mut obstacles = Vec::new();
    for o in &file.obstacles {
        let pose = o
            .pose
            .to_isometry(path, &format!("obstacles.{}.pose", o.name))?;
        for (k, part) in o.parts.iter().enumerate() {
            let field = format!("obstacles.{}.parts.{k}", o.name);
            let local = part.pose.to_isometry(path, &field)?;
            let shape = match &part.shape {
                ShapeSpec::Box { size } => ObstacleShape::Box { size: *size },
                ShapeSpec::Cylinder { radius, length } => ObstacleShape::Cylinder {
                    radius: *radius,
                    height: *length,
                },
                ShapeSpec::Capsule { radius, length } => ObstacleShape::Capsule {
                    radius: *radius,
                    length: *length,
                },
                ShapeSpec::Sphere { radius } => ObstacleShape::Sphere { radius: *radius },
                ShapeSpec::Mesh { path: p, scale } => {
                    let s = scale.unwrap_or([1.0; 3]);
                    if s[0] != s[1] || s[1] != s[2] {
                        return Err(unsupported(format!("{field}: non-uniform mesh scale")));
                    }
                    ObstacleShape::Mesh {
                        path: base.join(p).display().to_string(),
                        scale: Some(s[0]),
                    }
                }
            };
            obstacles.push(Obstacle {
                name: format!("{}/{k}", o.name),
                shape,
                pose: to_pose(&scene.to_robot_frame(&(pose * local))),
            });
        }
    }
    Ok(SceneRequests {
        name: scene.name.clone(),
        robot: SetRobot {
            robot: scene.robot_path.display().to_string(),
            grasp_types: None,
            package_dirs: Vec::new(),
        },
        object,
        env: SetEnv {
            obstacles,
            replace: true,
        },
    })
}
