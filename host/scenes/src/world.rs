//! The world a grasp is checked in, rebuilt from the requests a client sent.
//!
//! What: [`World::from_requests`] loads, from the same SetRobot / SetObject /
//! SetEnv messages a planner received, the robot model and its collision shapes,
//! the hand's palm link and arm joints (the `[hand]` table of its grasp-type
//! file), the object's surface, pose, mass, μ and centre of mass, and the
//! obstacles.
//!
//! Why: the grasp checker ([`crate::verify`]) must judge a Plan reply against the
//! truth the client asked for, not against the planner's view of it: a reply
//! that reports a lighter object or a different μ is itself wrong. Only
//! `tsukami-body` (models, meshes, collision) is used here, never a planner's code.
//!
//! How: names resolve under `models_dir` as the planners resolve them
//! (`robots/<name>/<name>.urdf`, `objects/<name>/object.toml`; an inline mesh
//! is decoded in memory, `tsukami_body::mesh_inline`); meshes and
//! primitives become one closed triangle mesh, which is both the surface the
//! contacts are measured against and the collision body. The world frame is the
//! robot's `base_link` frame, the frame of every message.

use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Point3, Vector3};
use tsukami_body::collision::{CollisionObject, RobotCollision};
use tsukami_body::limits::ParseLimits;
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::mesh_io::Format;
use tsukami_body::model::{JointId, LinkId, RobotModel};
use tsukami_body::object::ObjectModel;
use tsukami_msgs::planner::{MeshFormat, ObjectShape, SetEnv, SetObject, SetRobot};

use crate::geometry::{build_obstacle, pose_to_isometry};

/// Friction coefficient of a mesh object whose request gives none (the planners'
/// documented default, `SetObject::friction`).
pub const DEFAULT_FRICTION: f64 = 0.5;

/// The robot: kinematics, collision shapes and the hand's parts.
#[derive(Debug, Clone)]
pub struct RobotWorld {
    /// The model.
    pub model: RobotModel,
    /// Collision shapes of its links.
    pub collision: RobotCollision,
    /// The palm link (`hand palm_link`).
    pub palm: LinkId,
    /// The arm joints (`hand arm`): the reply may move them without
    /// listing them in `joints_used`.
    pub arm_joints: Vec<JointId>,
    /// Links at and below the palm (the hand).
    pub hand_links: Vec<LinkId>,
}

/// The object to hold.
#[derive(Debug, Clone)]
pub struct ObjectWorld {
    /// Name.
    pub name: String,
    /// Surface in the object frame.
    pub mesh: TriangleMesh,
    /// Pose of the object frame in the world.
    pub pose: Isometry3<f64>,
    /// Collision body at `pose`.
    pub collision: CollisionObject,
    /// Mass (kg).
    pub mass: f64,
    /// Friction coefficient μ.
    pub mu: f64,
    /// Centre of mass in the world.
    pub center_of_mass: Point3<f64>,
}

/// Everything a Plan reply is checked against.
#[derive(Debug, Clone)]
pub struct World {
    /// The robot.
    pub robot: RobotWorld,
    /// The object.
    pub object: ObjectWorld,
    /// The obstacles, named as in SetEnv.
    pub obstacles: Vec<CollisionObject>,
}

/// Why a world could not be built; `field` names the request field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct WorldError {
    /// The request field (`set_robot.robot`, `set_object.shape`, `set_env.obstacles.table/0`, …).
    pub field: String,
    /// What is wrong.
    pub message: String,
}

fn err(field: &str, message: impl ToString) -> WorldError {
    WorldError {
        field: field.to_owned(),
        message: message.to_string(),
    }
}

fn plain_name(s: &str) -> bool {
    !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

impl World {
    /// The world of a planner that received `robot`, `object` and `env`
    /// (`env` with `replace: true`, as a fresh planner would hold it).
    pub fn from_requests(
        models_dir: &Path,
        robot: &SetRobot,
        object: &SetObject,
        env: &SetEnv,
    ) -> Result<World, WorldError> {
        let robot = load_robot(models_dir, robot)?;
        let object = load_object(models_dir, object)?;
        let obstacles = env
            .obstacles
            .iter()
            .map(|o| {
                build_obstacle(o).map_err(|e| err(&format!("set_env.obstacles.{}", o.name), e))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(World {
            robot,
            object,
            obstacles,
        })
    }

    /// The same world with the object's mass multiplied by `factor` (a heavier
    /// object the same reply must hold).
    pub fn with_mass_scaled(mut self, factor: f64) -> World {
        self.object.mass *= factor;
        self
    }
}

fn load_robot(models_dir: &Path, req: &SetRobot) -> Result<RobotWorld, WorldError> {
    let field = "set_robot.robot";
    let urdf = if req.robot.ends_with(".urdf") {
        PathBuf::from(&req.robot)
    } else if plain_name(&req.robot) {
        models_dir
            .join("robots")
            .join(&req.robot)
            .join(format!("{}.urdf", req.robot))
    } else {
        return Err(err(field, "neither a .urdf path nor a robot name"));
    };
    // The robot description beside the URDF names the URDF, the palm and the arm.
    let description = urdf.with_file_name("description.toml");
    let (urdf_name, palm_name, arm_names, allowed) = read_hand_table(&description)?;
    let urdf = urdf.with_file_name(urdf_name);
    let model = tsukami_body::urdf::load_urdf(&urdf).map_err(|e| err(field, e))?;
    let mut collision = RobotCollision::new(&model).map_err(|e| err(field, e))?;
    for [a, b] in &allowed {
        let id = |n: &str| {
            model
                .link_id(n)
                .map_err(|e| err(field, format!("allowed_collisions: {e}")))
        };
        collision.allow(id(a)?, id(b)?);
    }
    let palm = model
        .link_id(&palm_name)
        .map_err(|e| err("set_robot.robot", format!("hand palm_link: {e}")))?;
    let arm_joints = arm_names
        .iter()
        .map(|n| model.joint_id(n))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| err("set_robot.robot", format!("hand arm: {e}")))?;
    let mut hand_links = vec![palm];
    let mut k = 0;
    while k < hand_links.len() {
        hand_links.extend(model.links[hand_links[k]].children.iter().copied());
        k += 1;
    }
    Ok(RobotWorld {
        model,
        collision,
        palm,
        arm_joints,
        hand_links,
    })
}

/// What the checker reads of a robot description: the URDF, the first hand's
/// palm link and arm joints, the `allowed_collisions` pairs.
type HandTable = (String, String, Vec<String>, Vec<[String; 2]>);

/// `urdf`, the first `[[hand]]`'s `palm_link` and `arm`, and the
/// `allowed_collisions` of a robot description (`description.toml`).
fn read_hand_table(path: &Path) -> Result<HandTable, WorldError> {
    let field = "set_robot.robot";
    let text = std::fs::read_to_string(path)
        .map_err(|e| err(field, format!("{}: {e}", path.display())))?;
    let table: toml::Table = toml::from_str(&text).map_err(|e| {
        err(
            field,
            format!("{}: not TOML: {}", path.display(), e.message()),
        )
    })?;
    let urdf = table
        .get("urdf")
        .and_then(|v| v.as_str())
        .ok_or_else(|| err(field, "urdf: missing or not a string"))?;
    let hand = table
        .get("hand")
        .and_then(|h| h.as_array())
        .and_then(|a| a.first())
        .and_then(|h| h.as_table())
        .ok_or_else(|| err(field, format!("{}: no [[hand]]", path.display())))?;
    let palm = hand
        .get("palm_link")
        .and_then(|v| v.as_str())
        .ok_or_else(|| err(field, "hand palm_link: missing or not a string"))?;
    let arm = hand
        .get("arm")
        .and_then(|v| v.as_array())
        .and_then(|a| a.iter().map(|v| v.as_str().map(str::to_owned)).collect())
        .ok_or_else(|| err(field, "hand arm: missing or not a list of names"))?;
    let pair = |v: &toml::Value| -> Option<[String; 2]> {
        match v.as_array()?.as_slice() {
            [a, b] => Some([a.as_str()?.to_owned(), b.as_str()?.to_owned()]),
            _ => None,
        }
    };
    let allowed = match table.get("allowed_collisions") {
        None => Vec::new(),
        Some(v) => v
            .as_array()
            .and_then(|a| a.iter().map(pair).collect())
            .ok_or_else(|| err(field, "allowed_collisions: not a list of link-name pairs"))?,
    };
    Ok((urdf.to_owned(), palm.to_owned(), arm, allowed))
}

fn load_object(models_dir: &Path, req: &SetObject) -> Result<ObjectWorld, WorldError> {
    let pose = pose_to_isometry(&req.pose).map_err(|m| err("set_object.pose", m))?;
    if !(req.mass.is_finite() && req.mass > 0.0) {
        return Err(err("set_object.mass", format!("{} must be > 0", req.mass)));
    }
    let (name, mesh, default_mu) = match &req.shape {
        ObjectShape::Model { name } => {
            if !plain_name(name) {
                return Err(err("set_object.shape.model.name", "not a model name"));
            }
            let path = models_dir.join("objects").join(name).join("object.toml");
            let m = ObjectModel::load(&path).map_err(|e| err("set_object.shape.model.name", e))?;
            (m.name.clone(), m.mesh, m.friction)
        }
        ObjectShape::Mesh { path, scale } => {
            let s = scale.unwrap_or(1.0);
            let mesh = TriangleMesh::load(Path::new(path), Vector3::repeat(s))
                .map_err(|e| err("set_object.shape.mesh.path", e))?;
            (path.clone(), mesh, DEFAULT_FRICTION)
        }
        ObjectShape::Inline {
            format,
            data_base64,
            scale,
        } => {
            let field = "set_object.shape.inline.data_base64";
            let format = match format {
                MeshFormat::Stl => Format::Stl,
                MeshFormat::Obj => Format::Obj,
                MeshFormat::Ply => Format::Ply,
            };
            let s = Vector3::repeat(scale.unwrap_or(1.0));
            let (mesh, _) =
                TriangleMesh::from_base64(data_base64, format, s, &ParseLimits::default())
                    .map_err(|e| err(field, e))?;
            ("inline".to_owned(), mesh, DEFAULT_FRICTION)
        }
    };
    let mu = req.friction.unwrap_or(default_mu);
    let com_local = match req.center_of_mass {
        Some(c) => Point3::from(c),
        None => volume_centroid(&mesh)
            .ok_or_else(|| err("set_object.shape", "the mesh encloses no volume"))?,
    };
    let collision = CollisionObject::from_mesh(name.clone(), pose, &mesh)
        .map_err(|e| err("set_object.shape", e))?;
    Ok(ObjectWorld {
        name: req.name.clone().unwrap_or(name),
        center_of_mass: pose * com_local,
        mesh,
        pose,
        collision,
        mass: req.mass,
        mu,
    })
}

/// Centroid of the volume a closed mesh encloses (signed tetrahedra from the origin).
fn volume_centroid(mesh: &TriangleMesh) -> Option<Point3<f64>> {
    let (volume, moment) = (0..mesh.indices.len()).fold((0.0, Vector3::zeros()), |(v, m), k| {
        let [a, b, c] = mesh.triangle(k);
        let t = a.coords.dot(&b.coords.cross(&c.coords)) / 6.0;
        (v + t, m + (a.coords + b.coords + c.coords) * (t / 4.0))
    });
    (volume.abs() > 1e-15).then(|| Point3::from(moment / volume))
}

#[cfg(test)]
mod tests {
    use super::*;
    use tsukami_body::mesh_inline::encode_base64;

    #[test]
    fn an_inline_object_is_the_object_its_model_is() {
        let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
        let r = crate::scene_requests(&models.join("scenes/can_breast.toml")).unwrap();
        let by_model = World::from_requests(&models, &r.robot, &r.object, &r.env).unwrap();
        let stl = std::fs::read(models.join("objects/can_350ml/can_350ml.stl")).unwrap();
        let mut object = r.object.clone();
        object.shape = ObjectShape::Inline {
            format: MeshFormat::Stl,
            data_base64: encode_base64(&stl),
            scale: None,
        };
        let inline = World::from_requests(&models, &r.robot, &object, &r.env).unwrap();
        assert_eq!(inline.object.mesh.indices, by_model.object.mesh.indices);
        assert_eq!(inline.object.center_of_mass, by_model.object.center_of_mass);
        assert_eq!(inline.object.mu, by_model.object.mu);
        object.shape = ObjectShape::Inline {
            format: MeshFormat::Obj,
            data_base64: "%%%%".into(),
            scale: None,
        };
        let e = World::from_requests(&models, &r.robot, &object, &r.env).unwrap_err();
        assert_eq!(e.field, "set_object.shape.inline.data_base64");
        assert!(e.message.contains("not base64"), "{}", e.message);
    }
}
