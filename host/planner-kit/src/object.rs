//! The object of the world: surface, pose, mass, friction, centre of mass.
//!
//! What: [`Object`] — the triangles in the mesh frame, the pose of that frame in
//! the world, mass, friction coefficient μ, the centre of mass (world), the
//! mesh-frame bounding box, a collision body and the warnings of the
//! `set_object` reply — built by [`Object::build`] from a `set_object` request
//! after every value passed `crate::validate` (or by [`Object::from_mesh`] in
//! process).
//!
//! Why: every planner needs the same object, checked the same way: a mass, a
//! friction or a centre of mass out of range is `invalid_value` naming the field,
//! a mesh that cannot be read is `model_error`, a mesh over [`MAX_TRIANGLES`] is
//! `invalid_value` naming the count and the limit, an inline mesh over the
//! host's `max_mesh_bytes` or not base64 is `invalid_value` naming
//! `shape.inline.data_base64` (and the limit), and nothing changes on any of
//! them. A mesh that is merely untidy is never refused: zero-area triangles are
//! dropped, open, non-manifold and inconsistently wound meshes are repaired or
//! used with a documented fallback ([`crate::mesh_topology`]), and the reply's
//! `warnings` say what was done.
//!
//! How: a model name resolves to `objects/<name>/object.toml` inside the model
//! roots; a mesh path must lie inside them; an inline mesh (base64 in the
//! request, [`load_inline`]) is decoded in memory within the host's
//! `max_mesh_bytes` and never touches the disk. The default centre of mass is the
//! centroid of the enclosed volume of a closed mesh (non-manifold ones
//! included), the convex hull's centroid for an open one, else the box centre.
//! The collision body is a parry mesh treated as a solid whenever the winding is
//! consistent, so a link inside the object is found (its inside tests compute
//! the pseudo-normal they need when asked: `tsukami_body::mesh_inside`).

use std::sync::Arc;

use nalgebra::{Isometry3, Point3, Vector3};
use parry3d_f64::shape::{SharedShape, TriMesh, TriMeshFlags};
use tsukami_body::collision::{CollisionObject, Part};
use tsukami_body::convert::to_vec;
use tsukami_body::files::FileKind;
use tsukami_body::limits::ParseLimits;
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::mesh_inline::InlineError;
use tsukami_body::mesh_inside::VertexTriangles;
use tsukami_body::mesh_io::Format;
use tsukami_body::object::ObjectModel;
use tsukami_msgs::planner::{BoxFace, FaceBlock, MeshFormat, ObjectShape, OcpBox, SetObject};

use crate::mesh_topology::{hull_centroid, prepare, Topology};
use crate::models::{relative_error, Models};
use crate::validate::{self, Limits};
use crate::KitError;

/// Most triangles accepted in an object or obstacle mesh, the one limit every
/// planner applies (the grasp planner reads it from here).
///
/// Why 2 000 000: scans of everyday objects come with 100k–1M triangles and
/// must plan as they are. Collision queries go through parry's BVH, so plan
/// time grows with the logarithm of the size; `set_object` is linear (about a
/// second per million triangles on the 2-core benchmark machine, see
/// `docs/benchmarks.md`), and a 2M-triangle mesh needs a few hundred MB while
/// it is built. The host's `max_mesh_bytes` (64 MiB: 1.3M binary-STL
/// triangles) usually bounds it first.
pub const MAX_TRIANGLES: usize = 2_000_000;

/// The display name of an inline mesh's object when the request names none.
pub const INLINE_NAME: &str = "inline";

/// Where and what an object is, beside its mesh (see [`Object::from_mesh`]).
#[derive(Clone, Copy)]
struct Placed {
    pose: Isometry3<f64>,
    mass: f64,
    mu: f64,
    com_local: Option<Point3<f64>>,
    max_size: f64,
}

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
    /// Edge topology and what was repaired.
    pub topology: Topology,
    /// Enclosed volume (m³): the mesh's when closed, else its convex hull's.
    pub volume: f64,
    /// What was done to the mesh, for the `set_object` reply.
    pub warnings: Vec<String>,
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

/// Loads a mesh file named in a request (inside the roots, size-checked,
/// cleaned); also returns the cleaning note for the reply, if it dropped
/// anything.
pub fn load_mesh(
    models: &Models,
    path: &str,
    scale: Option<f64>,
    field: &str,
) -> Result<(String, TriangleMesh, Option<String>), KitError> {
    let s = validate::scale(scale.unwrap_or(1.0), &format!("{field}.scale"))?;
    let file = models.mesh(path, &format!("{field}.path"))?;
    if let Some(n) = binary_stl_triangles(file.path()).filter(|&n| n > MAX_TRIANGLES as u64) {
        return Err(huge(&format!("{field}.path"), n));
    }
    let limits = ParseLimits {
        max_mesh_triangles: MAX_TRIANGLES,
        ..ParseLimits::default()
    };
    let (mesh, cleanup) = TriangleMesh::load_with(file.path(), Vector3::repeat(s), &limits)
        .map_err(|e| KitError::model(format!("{field}.path"), relative_error(&file, &e)))?;
    check_triangles(&mesh, field)?;
    let stem = file
        .path()
        .file_stem()
        .map_or_else(|| "object".into(), |s| s.to_string_lossy().into_owned());
    let note = cleanup
        .dropped_any()
        .then(|| format!("mesh cleaned: {}", cleanup.summary()));
    Ok((stem, mesh, note))
}

/// Decodes and loads an inline mesh of a request (`field` is the shape's,
/// `shape.inline`): the decoded bytes within the host's `max_mesh_bytes`, at
/// most [`MAX_TRIANGLES`], cleaned; nothing is read from or written to disk.
/// Also returns the cleaning note for the reply, if it dropped anything.
pub fn load_inline(
    models: &Models,
    format: MeshFormat,
    data_base64: &str,
    scale: Option<f64>,
    field: &str,
) -> Result<(TriangleMesh, Option<String>), KitError> {
    let s = validate::scale(scale.unwrap_or(1.0), &format!("{field}.scale"))?;
    let data = format!("{field}.data_base64");
    let limits = ParseLimits {
        max_mesh_triangles: MAX_TRIANGLES,
        max_mesh_bytes: models.roots().limits().mesh,
        ..ParseLimits::default()
    };
    let format = match format {
        MeshFormat::Stl => Format::Stl,
        MeshFormat::Obj => Format::Obj,
        MeshFormat::Ply => Format::Ply,
    };
    let (mesh, cleanup) =
        TriangleMesh::from_base64(data_base64, format, Vector3::repeat(s), &limits).map_err(
            |e| match e {
                InlineError::TooLarge { .. } => KitError::invalid(
                    &data,
                    format!("{e} (the host's `max_mesh_bytes`); send a smaller or decimated mesh"),
                ),
                InlineError::Triangles(m) => KitError::invalid(
                    &data,
                    format!("{m} (MAX_TRIANGLES = {MAX_TRIANGLES}); decimate it"),
                ),
                InlineError::Empty | InlineError::NotBase64(_) => {
                    KitError::invalid(&data, e.to_string())
                }
                InlineError::Mesh(m) => KitError::model(&data, m),
            },
        )?;
    check_triangles(&mesh, field)?;
    let note = cleanup
        .dropped_any()
        .then(|| format!("mesh cleaned: {}", cleanup.summary()));
    Ok((mesh, note))
}

/// `invalid_value` for a mesh over [`MAX_TRIANGLES`], naming count and limit.
fn huge(field: &str, n: u64) -> KitError {
    KitError::invalid(
        field,
        format!("the mesh has {n} triangles, more than the {MAX_TRIANGLES} accepted; decimate it"),
    )
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

fn check_triangles_before_cleaning(mesh: &TriangleMesh) -> Result<(), KitError> {
    match mesh.indices.len() {
        0 => Err(KitError::model("shape", "the mesh has no triangles")),
        n if n > MAX_TRIANGLES => Err(huge("shape", n as u64)),
        _ => Ok(()),
    }
}

fn check_triangles(mesh: &TriangleMesh, field: &str) -> Result<(), KitError> {
    if mesh.indices.len() > MAX_TRIANGLES {
        return Err(huge(field, mesh.indices.len() as u64));
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

/// The collision body of a prepared mesh: a solid (inside tests) whenever
/// the winding is consistent, closed or not. parry's mesh is built without
/// its oriented pseudo-normals; the inside tests compute the one they need
/// from the triangles around each vertex (`tsukami_body::mesh_inside`: the
/// same answers, without hashing every edge at `set_object`).
pub fn collision_body(
    name: &str,
    pose: Isometry3<f64>,
    mesh: &TriangleMesh,
    topology: &Topology,
) -> Result<CollisionObject, String> {
    let vertices = mesh.vertices.iter().map(to_vec).collect();
    let trimesh = TriMesh::with_flags(vertices, mesh.indices.clone(), TriMeshFlags::empty())
        .map_err(|e| format!("cannot build the collision mesh: {e}"))?;
    let around = topology
        .solid
        .then(|| Arc::new(VertexTriangles::new(&mesh.indices, mesh.vertices.len())));
    let part = Part {
        origin: tsukami_body::convert::to_pose(&Isometry3::identity()),
        shape: SharedShape::new(trimesh),
        solid_mesh: topology.solid,
        around,
    };
    Ok(CollisionObject::new(name, pose, vec![part]))
}

impl Object {
    /// Checks every value of `req` and builds the object.
    pub fn build(models: &Models, req: &SetObject, limits: &Limits) -> Result<Self, KitError> {
        let pose = validate::pose(&req.pose, "pose", limits)?;
        let mass = validate::mass(req.mass, "mass", limits)?;
        let (name, mesh, default_mu, note) = match &req.shape {
            ObjectShape::Model { name } => {
                let (name, mesh, mu) = load_model(models, name)?;
                (name, mesh, mu, None)
            }
            ObjectShape::Mesh { path, scale } => {
                let (stem, mesh, note) = load_mesh(models, path, *scale, "shape.mesh")?;
                (stem, mesh, 0.5, note)
            }
            ObjectShape::Inline {
                format,
                data_base64,
                scale,
            } => {
                let (mesh, note) =
                    load_inline(models, *format, data_base64, *scale, "shape.inline")?;
                (INLINE_NAME.to_string(), mesh, 0.5, note)
            }
        };
        let mu = validate::friction(req.friction.unwrap_or(default_mu), "friction", limits)?;
        let (lo, hi) = mesh.aabb();
        let com = match &req.center_of_mass {
            Some(c) => Some(validate::center_of_mass(
                c,
                &lo,
                &hi,
                "center_of_mass",
                limits,
            )?),
            None => None,
        };
        let name = req.name.clone().unwrap_or(name);
        let placed = Placed {
            pose,
            mass,
            mu,
            com_local: com,
            max_size: limits.workspace_m,
        };
        if matches!(
            req.shape,
            ObjectShape::Mesh { .. } | ObjectShape::Inline { .. }
        ) {
            // `load_mesh` / `load_inline` cleaned it: cleaning again would change nothing.
            Self::from_clean_mesh(&name, mesh, note.into_iter().collect(), &placed)
        } else {
            Self::from_mesh(&name, mesh, pose, mass, mu, com, limits.workspace_m)
        }
    }

    /// Builds an object from a mesh in its own frame (cleaned here), without
    /// files: what [`Object::build`] does after loading, for in-process use
    /// (tests, benchmarks). `com_local` is in the mesh frame; `None` takes the
    /// default (see the module documentation). `max_size` bounds the mesh's
    /// bounding-box diagonal (m).
    pub fn from_mesh(
        name: &str,
        mut mesh: TriangleMesh,
        pose: Isometry3<f64>,
        mass: f64,
        mu: f64,
        com_local: Option<Point3<f64>>,
        max_size: f64,
    ) -> Result<Self, KitError> {
        check_triangles_before_cleaning(&mesh)?;
        let cleanup = mesh.clean();
        let warnings: Vec<String> = cleanup
            .dropped_any()
            .then(|| format!("mesh cleaned: {}", cleanup.summary()))
            .into_iter()
            .collect();
        check_triangles(&mesh, "shape")?;
        let placed = Placed {
            pose,
            mass,
            mu,
            com_local,
            max_size,
        };
        Self::from_clean_mesh(name, mesh, warnings, &placed)
    }

    /// [`Object::from_mesh`] after cleaning and `check_triangles` (`warnings`
    /// says what cleaning did).
    fn from_clean_mesh(
        name: &str,
        mut mesh: TriangleMesh,
        mut warnings: Vec<String>,
        placed: &Placed,
    ) -> Result<Self, KitError> {
        let Placed {
            pose,
            mass,
            mu,
            com_local,
            max_size,
        } = *placed;
        let aabb = mesh.aabb();
        let diagonal = (aabb.1 - aabb.0).norm();
        if !(1e-3..=max_size).contains(&diagonal) {
            return Err(KitError::model(
                "shape",
                format!("the mesh is {diagonal:.3e} m across; objects must be 1 mm to the workspace size"),
            ));
        }
        let topology = prepare(&mut mesh);
        warnings.extend(topology.warnings.iter().cloned());
        let hull = (!topology.closed)
            .then(|| hull_centroid(&mesh.vertices))
            .flatten();
        let box_centre = nalgebra::center(&aabb.0, &aabb.1);
        let (default_com, volume) = match (topology.closed, hull) {
            (true, _) => (volume_centroid(&mesh), mesh.volume()),
            (false, Some((c, v))) => (Some(c), v),
            (false, None) => (None, 0.0),
        };
        let com_local = com_local.unwrap_or(default_com.unwrap_or(box_centre));
        let collision = collision_body(name, pose, &mesh, &topology)
            .map_err(|m| KitError::model("shape", m))?;
        Ok(Object {
            name: name.to_string(),
            center_of_mass: pose * com_local,
            com_local,
            mesh,
            pose,
            mass,
            mu,
            aabb,
            collision,
            topology,
            volume,
            warnings,
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;
    use tsukami_msgs::planner::pose_at;

    fn models_dir() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models")
    }

    fn b64(bytes: &[u8]) -> String {
        tsukami_body::mesh_inline::encode_base64(bytes)
    }

    fn inline(format: MeshFormat, data_base64: String, scale: Option<f64>) -> SetObject {
        SetObject {
            name: None,
            shape: ObjectShape::Inline {
                format,
                data_base64,
                scale,
            },
            mass: 0.15,
            friction: None,
            pose: pose_at([0.5, -0.25, 1.1]),
            center_of_mass: None,
        }
    }

    fn field_and_message(e: &KitError) -> (String, String) {
        match e {
            KitError::InvalidValue { field, message } | KitError::Model { field, message } => {
                (field.clone(), message.clone())
            }
            other => panic!("not a field error: {other}"),
        }
    }

    #[test]
    fn an_inline_stl_is_the_object_its_file_is() {
        let models = Models::new([models_dir()]);
        let limits = Limits::default();
        let stl = std::fs::read(models_dir().join("objects/can_350ml/can_350ml.stl")).unwrap();
        let sent =
            Object::build(&models, &inline(MeshFormat::Stl, b64(&stl), None), &limits).unwrap();
        let mut by_path = inline(MeshFormat::Stl, String::new(), None);
        by_path.shape = ObjectShape::Mesh {
            path: "objects/can_350ml/can_350ml.stl".into(),
            scale: None,
        };
        let read = Object::build(&models, &by_path, &limits).unwrap();
        assert_eq!(sent.name, INLINE_NAME);
        assert_eq!(sent.mesh.indices, read.mesh.indices);
        assert_eq!(sent.mesh.vertices, read.mesh.vertices);
        assert_eq!(sent.com_local, read.com_local);
        assert_eq!(sent.warnings, read.warnings);
        // Scaled as a path is: millimetres.
        let mm: Vec<u8> = {
            let mut m = TriangleMesh {
                vertices: read.mesh.vertices.iter().map(|v| v * 1000.0).collect(),
                indices: read.mesh.indices.clone(),
            };
            m.clean();
            let p = std::env::temp_dir().join(format!("tsukami-kit-mm-{}.stl", std::process::id()));
            m.write_stl(&p).unwrap();
            let bytes = std::fs::read(&p).unwrap();
            std::fs::remove_file(&p).ok();
            bytes
        };
        let scaled = Object::build(
            &models,
            &inline(MeshFormat::Stl, b64(&mm), Some(1e-3)),
            &limits,
        )
        .unwrap();
        assert!((scaled.volume - read.volume).abs() < 1e-3 * read.volume);
    }

    #[test]
    fn an_inline_obj_builds_and_keeps_its_name() {
        let models = Models::new([models_dir()]);
        let obj = std::fs::read(models_dir().join("objects/box/box.obj")).unwrap();
        let mut req = inline(MeshFormat::Obj, b64(&obj), None);
        req.name = Some("client box".into());
        let o = Object::build(&models, &req, &Limits::default()).unwrap();
        assert_eq!(o.name, "client box");
        assert!(o.topology.closed && o.volume > 0.0);
    }

    #[test]
    fn an_inline_ply_is_the_object_its_stl_is() {
        let models = Models::new([models_dir()]);
        let limits = Limits::default();
        let stl = models_dir().join("objects/can_350ml/can_350ml.stl");
        let can = TriangleMesh::load(&stl, Vector3::repeat(1.0)).unwrap();
        let ply = tsukami_body::ply::to_binary(&can);
        let sent = Object::build(&models, &inline(MeshFormat::Ply, b64(&ply), None), &limits);
        let sent = sent.unwrap();
        let mut by_path = inline(MeshFormat::Stl, String::new(), None);
        by_path.shape = ObjectShape::Mesh {
            path: "objects/can_350ml/can_350ml.stl".into(),
            scale: None,
        };
        let read = Object::build(&models, &by_path, &limits).unwrap();
        assert_eq!(sent.mesh, read.mesh);
        assert_eq!(sent.com_local, read.com_local);
        // A header stating more faces than accepted: refused from the header.
        let lying = format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
             property float y\nproperty float z\nelement face {}\n\
             property list uchar int vertex_indices\nend_header\n",
            MAX_TRIANGLES + 1
        );
        let req = inline(MeshFormat::Ply, b64(lying.as_bytes()), None);
        let e = Object::build(&models, &req, &limits).unwrap_err();
        let (field, message) = field_and_message(&e);
        assert_eq!(e.code(), tsukami_msgs::ErrorCode::InvalidValue);
        assert_eq!(field, "shape.inline.data_base64");
        assert!(
            message.contains("inline PLY: too large: 2000001 faces")
                && message.contains("MAX_TRIANGLES = 2000000"),
            "{message}"
        );
    }

    #[test]
    fn too_large_bad_and_garbage_inline_meshes_name_the_field() {
        let stl = std::fs::read(models_dir().join("objects/can_350ml/can_350ml.stl")).unwrap();
        let limit = stl.len() as u64 - 1;
        let sizes = tsukami_body::files::SizeLimits {
            mesh: limit,
            ..Default::default()
        };
        let small = Models::with_limits([models_dir()], sizes);
        let limits = Limits::default();
        let build = |models: &Models, req: SetObject| Object::build(models, &req, &limits);
        let e = build(&small, inline(MeshFormat::Stl, b64(&stl), None)).unwrap_err();
        let (field, message) = field_and_message(&e);
        assert_eq!(e.code(), tsukami_msgs::ErrorCode::InvalidValue);
        assert_eq!(field, "shape.inline.data_base64");
        assert!(
            message.contains(&format!("{} bytes", stl.len()))
                && message.contains(&format!(
                    "limit of {}",
                    tsukami_body::mesh_inline::size(limit)
                ))
                && message.contains("max_mesh_bytes"),
            "{message}"
        );
        let models = Models::new([models_dir()]);
        for (data, code, says) in [
            ("", "invalid_value", "no data"),
            ("%%%%", "invalid_value", "outside the alphabet at offset 0"),
            ("QUJDR", "invalid_value", "cannot be base64"),
            (
                "c29saWQgeAplbmRzb2xpZCB4Cg==",
                "model_error",
                "no triangles",
            ),
            ("AAAAAAAAAAAAAAAA", "model_error", "inline STL"),
        ] {
            let e = build(&models, inline(MeshFormat::Stl, data.into(), None)).unwrap_err();
            let (field, message) = field_and_message(&e);
            assert_eq!(e.code().as_str(), code, "{data}: {e}");
            assert_eq!(field, "shape.inline.data_base64", "{data}");
            assert!(message.contains(says), "{data}: {message}");
        }
        let e = build(
            &models,
            inline(MeshFormat::Obj, b64(b"v 1 2\nf 9 9 9\n"), None),
        );
        assert_eq!(e.unwrap_err().code().as_str(), "model_error");
        let e = build(&models, inline(MeshFormat::Stl, b64(&stl), Some(0.0))).unwrap_err();
        assert_eq!(field_and_message(&e).0, "shape.inline.scale");
    }

    #[test]
    fn an_inline_mesh_over_max_triangles_names_the_count_and_the_limit() {
        // 16 MB of OBJ: one triangle more than accepted, within max_mesh_bytes.
        let mut obj = b"v 0 0 0
"
        .to_vec();
        obj.extend(
            b"f 1 1 1
"
            .repeat(MAX_TRIANGLES + 1),
        );
        let models = Models::new([models_dir()]);
        let e = Object::build(
            &models,
            &inline(MeshFormat::Obj, b64(&obj), None),
            &Limits::default(),
        )
        .unwrap_err();
        let (field, message) = field_and_message(&e);
        assert_eq!(e.code(), tsukami_msgs::ErrorCode::InvalidValue);
        assert_eq!(field, "shape.inline.data_base64");
        assert!(
            message.contains(&format!("{} triangles", MAX_TRIANGLES + 1))
                && message.contains("MAX_TRIANGLES = 2000000"),
            "{message}"
        );
    }
}
