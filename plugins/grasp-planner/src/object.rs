//! The object to grasp, placed in the world: surface, collision body, mass,
//! friction, centre of mass and its OCP boxes.
//!
//! What: [`PlanObject::new`] checks a triangle mesh (closed, not degenerate,
//! not huge), places it at its pose, computes its centre of mass and its OCPs
//! ([`crate::ocp`]), and builds the collision body the finger-closing and
//! collision checks use.
//!
//! Why: the planner must accept meshes it has never seen; everything it needs
//! from a mesh is derived here once, at `set_object`, and a bad mesh is refused
//! with a reason before any planning starts.
//!
//! How: the mesh comes in the object's frame (from `tsukami-body`'s loaders);
//! vertices are transformed to the world once so OCPs and free faces are
//! computed against the world's vertical (the support is below).

use nalgebra::{Isometry3, Point3, Vector3};
use tsukami_body::collision::CollisionObject;
use tsukami_body::mesh::TriangleMesh;

use crate::ocp::{object_ocps, Ocp, OcpParams};

/// Largest triangle count accepted (a grasp planner needs the shape, not a scan).
pub const MAX_TRIANGLES: usize = 200_000;
/// Largest object size accepted (bounding-box diagonal, m).
pub const MAX_DIAGONAL: f64 = 2.0;
/// Smallest object size accepted (bounding-box diagonal, m).
pub const MIN_DIAGONAL: f64 = 0.005;

/// Why a mesh or object was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ObjectError {
    /// More triangles than [`MAX_TRIANGLES`].
    #[error("object `{name}`: mesh has {triangles} triangles, more than the {max} accepted; decimate it")]
    TooManyTriangles {
        /// Object name.
        name: String,
        /// Triangle count.
        triangles: usize,
        /// The limit.
        max: usize,
    },
    /// The mesh is not a closed surface.
    #[error("object `{name}`: mesh is open (not watertight): {detail}")]
    Open {
        /// Object name.
        name: String,
        /// Which check failed.
        detail: String,
    },
    /// The mesh has no area or no volume, or bad values.
    #[error("object `{name}`: mesh is degenerate: {detail}")]
    Degenerate {
        /// Object name.
        name: String,
        /// Which check failed.
        detail: String,
    },
    /// The object is too large or too small to be grasped by a hand.
    #[error(
        "object `{name}`: size {diagonal:.3} m (bounding-box diagonal) is outside [{min}, {max}] m"
    )]
    Size {
        /// Object name.
        name: String,
        /// Bounding-box diagonal (m).
        diagonal: f64,
        /// Lower limit.
        min: f64,
        /// Upper limit.
        max: f64,
    },
    /// Mass, friction, pose or centre of mass out of range.
    #[error("object `{name}`: field `{field}`: {message}")]
    Field {
        /// Object name.
        name: String,
        /// Field name.
        field: String,
        /// What is wrong.
        message: String,
    },
}

/// The object the planner grasps.
#[derive(Debug, Clone)]
pub struct PlanObject {
    /// Name.
    pub name: String,
    /// Mass (kg).
    pub mass: f64,
    /// Friction coefficient μ.
    pub mu: f64,
    /// Pose of the mesh frame in the world.
    pub pose: Isometry3<f64>,
    /// Centre of mass (world).
    pub center_of_mass: Point3<f64>,
    /// Vertices in the world frame.
    pub vertices: Vec<Point3<f64>>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// OCP boxes, one per region.
    pub ocps: Vec<Ocp>,
    /// Collision body at `pose`.
    pub collision: CollisionObject,
    /// Largest OCP edge (m): the characteristic length of wrenches (γ = 1 / length).
    pub characteristic_length: f64,
}

impl PlanObject {
    /// Checks and places an object. `center_of_mass` is in the mesh frame
    /// (default: the centroid of the enclosed volume).
    pub fn new(
        name: &str,
        mesh: &TriangleMesh,
        pose: Isometry3<f64>,
        mass: f64,
        mu: f64,
        center_of_mass: Option<Point3<f64>>,
        params: &OcpParams,
    ) -> Result<Self, ObjectError> {
        let field = |f: &str, m: String| ObjectError::Field {
            name: name.to_string(),
            field: f.to_string(),
            message: m,
        };
        if !(mass.is_finite() && mass > 0.0) {
            return Err(field("mass", format!("{mass} kg must be finite and > 0")));
        }
        if !(mu.is_finite() && mu > 0.0 && mu <= 2.0) {
            return Err(field("friction", format!("{mu} must be in (0, 2]")));
        }
        let t = pose.translation.vector;
        let q = pose.rotation.coords;
        if !t.iter().chain(q.iter()).all(|x| x.is_finite()) {
            return Err(field(
                "pose",
                "position and quaternion must be finite (got NaN or infinity)".into(),
            ));
        }
        check_mesh(name, mesh)?;
        let com_local = match center_of_mass {
            Some(c) if c.iter().all(|x| x.is_finite()) => c,
            Some(_) => return Err(field("center_of_mass", "must be finite".into())),
            None => volume_centroid(mesh).ok_or_else(|| ObjectError::Degenerate {
                name: name.to_string(),
                detail: "the enclosed volume is zero".into(),
            })?,
        };
        let vertices: Vec<Point3<f64>> = mesh.vertices.iter().map(|v| pose * v).collect();
        let ocps = object_ocps(&vertices, &mesh.indices, params);
        if ocps.is_empty() {
            return Err(ObjectError::Degenerate {
                name: name.to_string(),
                detail: "no surface area".into(),
            });
        }
        let collision = CollisionObject::from_mesh(name, pose, mesh).map_err(|detail| {
            ObjectError::Degenerate {
                name: name.to_string(),
                detail,
            }
        })?;
        let characteristic_length = ocps
            .iter()
            .map(|o| o.extents.max())
            .fold(0.0, f64::max)
            .max(0.01);
        Ok(Self {
            name: name.to_string(),
            mass,
            mu,
            pose,
            center_of_mass: pose * com_local,
            vertices,
            triangles: mesh.indices.clone(),
            ocps,
            collision,
            characteristic_length,
        })
    }
}

/// Refuses huge, open and degenerate meshes.
pub fn check_mesh(name: &str, mesh: &TriangleMesh) -> Result<(), ObjectError> {
    let degenerate = |detail: String| ObjectError::Degenerate {
        name: name.to_string(),
        detail,
    };
    if mesh.indices.len() > MAX_TRIANGLES {
        return Err(ObjectError::TooManyTriangles {
            name: name.to_string(),
            triangles: mesh.indices.len(),
            max: MAX_TRIANGLES,
        });
    }
    mesh.validate().map_err(degenerate)?;
    let diagonal = mesh.bounding_diagonal();
    if !(MIN_DIAGONAL..=MAX_DIAGONAL).contains(&diagonal) {
        return Err(ObjectError::Size {
            name: name.to_string(),
            diagonal,
            min: MIN_DIAGONAL,
            max: MAX_DIAGONAL,
        });
    }
    if !mesh.is_closed() {
        return Err(ObjectError::Open {
            name: name.to_string(),
            detail: "some edges do not belong to exactly two triangles".into(),
        });
    }
    let volume = mesh.volume().abs();
    let (lo, hi) = mesh.aabb();
    let box_volume = (hi - lo).iter().product::<f64>();
    if volume <= 1e-6 * box_volume {
        return Err(degenerate(format!(
            "encloses no volume ({volume:.3e} m³): flat or folded surface"
        )));
    }
    Ok(())
}

/// Centroid of the volume enclosed by a closed mesh (signed tetrahedra).
pub fn volume_centroid(mesh: &TriangleMesh) -> Option<Point3<f64>> {
    let mut vol = 0.0;
    let mut acc = Vector3::zeros();
    for k in 0..mesh.indices.len() {
        let [a, b, c] = mesh.triangle(k);
        let v = a.coords.dot(&b.coords.cross(&c.coords)) / 6.0;
        vol += v;
        acc += (a.coords + b.coords + c.coords) * (v / 4.0);
    }
    (vol.abs() > 1e-15).then(|| Point3::from(acc / vol))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn can_is_accepted_with_com_at_its_centre() {
        let mesh = TriangleMesh::cylinder(0.033, 0.122, 24);
        let pose = Isometry3::translation(0.5, -0.2, 1.0);
        let o =
            PlanObject::new("can", &mesh, pose, 0.15, 0.5, None, &OcpParams::default()).unwrap();
        let (lo, hi) = mesh.aabb();
        let centre = pose * Point3::from((lo.coords + hi.coords) / 2.0);
        assert!((o.center_of_mass - centre).norm() < 1e-9);
        assert_eq!(o.ocps.len(), 1);
    }

    #[test]
    fn bad_objects_are_refused_with_reasons() {
        let mesh = TriangleMesh::cylinder(0.033, 0.122, 24);
        let p = OcpParams::default();
        let id = Isometry3::identity();
        let e = PlanObject::new("can", &mesh, id, 0.0, 0.5, None, &p).unwrap_err();
        assert!(e.to_string().contains("mass"), "{e}");
        let mut nan = id;
        nan.translation.vector.x = f64::NAN;
        let e = PlanObject::new("can", &mesh, nan, 0.1, 0.5, None, &p).unwrap_err();
        assert!(e.to_string().contains("pose"), "{e}");
        let mut open = mesh.clone();
        open.indices.pop();
        let e = PlanObject::new("can", &open, id, 0.1, 0.5, None, &p).unwrap_err();
        assert!(matches!(e, ObjectError::Open { .. }), "{e}");
        let big = TriangleMesh::cuboid(Vector3::new(3.0, 1.0, 1.0));
        let e = PlanObject::new("box", &big, id, 0.1, 0.5, None, &p).unwrap_err();
        assert!(matches!(e, ObjectError::Size { .. }), "{e}");
    }
}
