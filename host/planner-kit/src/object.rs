//! The object of the world: surface, pose, mass, friction, centre of mass.
//!
//! What: [`Object`] — the triangles in the mesh frame, the pose of that frame in
//! the world, mass, friction coefficient μ, the centre of mass (world), the
//! mesh-frame bounding box and a collision body — built by [`Object::build`]
//! from a `set_object` request after every value passed `crate::validate`.
//!
//! Why: every planner needs the same object, checked the same way: a mass, a
//! friction or a centre of mass out of range is `invalid_value` naming the field,
//! a mesh that cannot be used is `model_error`, and nothing changes on either.
//!
//! How: a model name resolves to `objects/<name>/object.toml` inside the model
//! roots; a mesh path must lie inside them. The default centre of mass is the
//! centroid of the enclosed volume of a closed mesh, else the box centre.

use nalgebra::{Isometry3, Point3, Vector3};
use tsukami_body::collision::CollisionObject;
use tsukami_body::files::FileKind;
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::object::ObjectModel;
use tsukami_msgs::planner::{BoxFace, FaceBlock, ObjectShape, OcpBox, SetObject};

use crate::models::{relative_error, Models};
use crate::validate::{self, Limits};
use crate::KitError;

/// Most triangles accepted in an object or obstacle mesh.
pub const MAX_TRIANGLES: usize = 200_000;

/// A placed, checked object.
#[derive(Debug, Clone)]
pub struct Object {
    /// Display name.
    pub name: String,
    /// Surface in the mesh frame.
    pub mesh: TriangleMesh,
    /// Pose of the mesh frame in the world.
    pub pose: Isometry3<f64>,
    /// Mass, kg.
    pub mass: f64,
    /// Friction coefficient μ.
    pub mu: f64,
    /// Centre of mass, mesh frame.
    pub com_local: Point3<f64>,
    /// Centre of mass, world frame.
    pub center_of_mass: Point3<f64>,
    /// Bounding box of the mesh, mesh frame: lower and upper corners.
    pub aabb: (Point3<f64>, Point3<f64>),
    /// Collision body at `pose`.
    pub collision: CollisionObject,
}

/// Centroid of the volume a closed, outward-oriented mesh encloses
/// (divergence theorem over origin-based tetrahedra); `None` if not positive.
pub fn volume_centroid(mesh: &TriangleMesh) -> Option<Point3<f64>> {
    let mut volume = 0.0;
    let mut moment = Vector3::zeros();
    for k in 0..mesh.indices.len() {
        let [a, b, c] = mesh.triangle(k);
        let v = a.coords.dot(&b.coords.cross(&c.coords)) / 6.0;
        volume += v;
        moment += v * (a.coords + b.coords + c.coords) / 4.0;
    }
    (volume > 1e-12).then(|| Point3::from(moment / volume))
}

/// Loads a mesh file named in a request (inside the roots, size-checked).
pub fn load_mesh(
    models: &Models,
    path: &str,
    scale: Option<f64>,
    field: &str,
) -> Result<(String, TriangleMesh), KitError> {
    let s = validate::scale(scale.unwrap_or(1.0), &format!("{field}.scale"))?;
    let file = models.mesh(path, &format!("{field}.path"))?;
    if let Some(n) = binary_stl_triangles(file.path()).filter(|&n| n > MAX_TRIANGLES as u64) {
        return Err(KitError::model(format!("{field}.path"), huge(n)));
    }
    let mesh = TriangleMesh::load(file.path(), Vector3::repeat(s))
        .map_err(|e| KitError::model(format!("{field}.path"), relative_error(&file, &e)))?;
    check_triangles(&mesh, field)?;
    let stem = file
        .path()
        .file_stem()
        .map_or_else(|| "object".into(), |s| s.to_string_lossy().into_owned());
    Ok((stem, mesh))
}

fn huge(n: u64) -> String {
    format!("mesh is huge: {n} triangles, more than the {MAX_TRIANGLES} accepted; decimate it")
}

/// The triangle count a binary STL's header states (`None` if not a binary
/// STL); read before loading, so a huge mesh is refused without parsing it.
fn binary_stl_triangles(path: &std::path::Path) -> Option<u64> {
    use std::io::Read;
    if !path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("stl"))
    {
        return None;
    }
    let mut head = [0u8; 84];
    let mut f = std::fs::File::open(path).ok()?;
    f.read_exact(&mut head).ok()?;
    let n = u64::from(u32::from_le_bytes([head[80], head[81], head[82], head[83]]));
    (f.metadata().ok()?.len() == 84 + 50 * n).then_some(n)
}

fn check_triangles(mesh: &TriangleMesh, field: &str) -> Result<(), KitError> {
    if mesh.indices.len() > MAX_TRIANGLES {
        return Err(KitError::model(field, huge(mesh.indices.len() as u64)));
    }
    mesh.validate().map_err(|m| KitError::model(field, m))
}

fn load_model(models: &Models, name: &str) -> Result<(String, TriangleMesh, f64), KitError> {
    let field = "shape.model.name";
    let file = models.object(name)?;
    models.check_size(&file, FileKind::Toml, field)?;
    let m = ObjectModel::load(file.path())
        .map_err(|e| KitError::model(field, relative_error(&file, &e)))?;
    check_triangles(&m.mesh, "shape.model")?;
    Ok((m.name, m.mesh, m.friction))
}

impl Object {
    /// Checks every value of `req` and builds the object.
    pub fn build(models: &Models, req: &SetObject, limits: &Limits) -> Result<Self, KitError> {
        let pose = validate::pose(&req.pose, "pose", limits)?;
        let mass = validate::mass(req.mass, "mass", limits)?;
        let (name, mesh, default_mu) = match &req.shape {
            ObjectShape::Model { name } => load_model(models, name)?,
            ObjectShape::Mesh { path, scale } => {
                let (stem, mesh) = load_mesh(models, path, *scale, "shape.mesh")?;
                (stem, mesh, 0.5)
            }
        };
        let mu = validate::friction(req.friction.unwrap_or(default_mu), "friction", limits)?;
        let aabb = mesh.aabb();
        let diagonal = (aabb.1 - aabb.0).norm();
        if !(1e-3..=limits.workspace_m).contains(&diagonal) {
            return Err(KitError::model(
                "shape",
                format!("the mesh is {diagonal:.3e} m across; objects must be 1 mm to the workspace size"),
            ));
        }
        let com_local = match &req.center_of_mass {
            Some(c) => validate::center_of_mass(c, &aabb.0, &aabb.1, "center_of_mass", limits)?,
            None if mesh.is_closed() => {
                volume_centroid(&mesh).unwrap_or_else(|| nalgebra::center(&aabb.0, &aabb.1))
            }
            None => nalgebra::center(&aabb.0, &aabb.1),
        };
        let name = req.name.clone().unwrap_or(name);
        let collision = CollisionObject::from_mesh(&name, pose, &mesh)
            .map_err(|m| KitError::model("shape", m))?;
        Ok(Object {
            name,
            center_of_mass: pose * com_local,
            com_local,
            mesh,
            pose,
            mass,
            mu,
            aabb,
            collision,
        })
    }

    /// Edge lengths of the bounding box (mesh-frame axes).
    pub fn extents(&self) -> Vector3<f64> {
        self.aabb.1 - self.aabb.0
    }

    /// The largest box edge, at least 1 cm: the characteristic length that
    /// scales torques to forces (γ = 1 / length, eq. (6)).
    pub fn characteristic_length(&self) -> f64 {
        self.extents().max().max(0.01)
    }

    /// The bounding box as one region: faces whose outward normal points down
    /// rest on a support.
    pub fn box_region(&self) -> OcpBox {
        let centre = nalgebra::center(&self.aabb.0, &self.aabb.1);
        let pose = self.pose * Isometry3::translation(centre.x, centre.y, centre.z);
        let (mut free, mut blocked) = (Vec::new(), Vec::new());
        for face in BoxFace::ALL {
            let mut n = Vector3::zeros();
            n[face.axis()] = face.sign();
            if (pose.rotation * n).z < -0.9 {
                blocked.push((face, FaceBlock::Support));
            } else {
                free.push(face);
            }
        }
        let e = self.extents();
        OcpBox {
            region: 0,
            pose: validate::to_pose(&pose),
            extents: [e.x, e.y, e.z],
            free_faces: free,
            blocked_faces: blocked,
        }
    }

    /// The box face whose outward normal is most opposed to `approach` (the
    /// direction the palm moves toward the object, world frame).
    pub fn face_toward(&self, approach: &Vector3<f64>) -> BoxFace {
        let local = self.pose.rotation.inverse() * approach;
        let axis = (0..3)
            .max_by(|&a, &b| local[a].abs().total_cmp(&local[b].abs()))
            .unwrap_or(0);
        BoxFace::from_axis(axis, local[axis] < 0.0)
    }
}
