//! The object to grasp, placed in the world: surface, collision body, mass,
//! friction, centre of mass and its OCP boxes.
//!
//! What: [`PlanObject::new`] takes the planner kit's [`Object`] (mesh cleaned,
//! wound consistently, its collision body and centre of mass decided there,
//! see `tsukami_planner_kit::mesh_topology`), checks what this planner needs
//! on top (a hand-sized object with some volume), transforms the vertices to
//! the world and computes the OCPs ([`crate::ocp`]).
//!
//! Why: the planner must accept meshes it has never seen, open and
//! non-manifold ones included; everything it needs from a mesh is derived
//! here once, at `set_object`, and an object no hand can hold is refused with
//! a reason before any planning starts.
//!
//! How: vertices are transformed to the world once so OCPs and free faces are
//! computed against the world's vertical (the support is below). The
//! collision body is the kit's (shared, not rebuilt), so the planner, the
//! kit's verification and the reply agree on what is inside the object.

use nalgebra::{Isometry3, Point3};
use tsukami_body::collision::CollisionObject;
use tsukami_body::mesh::TriangleMesh;
use tsukami_planner_kit::Object;

use crate::edges::SharpEdges;
use crate::ocp::{object_ocps, Ocp, OcpParams};

/// Largest object size accepted (bounding-box diagonal, m).
pub const MAX_DIAGONAL: f64 = 2.0;
/// Smallest object size accepted (bounding-box diagonal, m).
pub const MIN_DIAGONAL: f64 = 0.005;

/// Why an object was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ObjectError {
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
    /// Collision body at `pose` (the kit's).
    pub collision: CollisionObject,
    /// Largest OCP edge (m): the characteristic length of wrenches (γ = 1 / length).
    pub characteristic_length: f64,
    /// Height of the lowest vertex (m, world): where a support under it is.
    pub lowest: f64,
    /// Its sharp edges (world frame): where fingertips slide off.
    pub edges: SharpEdges,
}

impl PlanObject {
    /// Checks the kit's object for this planner and computes its OCPs.
    pub fn new(o: &Object, params: &OcpParams) -> Result<Self, ObjectError> {
        let name = o.name.as_str();
        let field = |f: &str, m: String| ObjectError::Field {
            name: name.to_string(),
            field: f.to_string(),
            message: m,
        };
        if !(o.mass.is_finite() && o.mass > 0.0) {
            return Err(field(
                "mass",
                format!("{} kg must be finite and > 0", o.mass),
            ));
        }
        if !(o.mu.is_finite() && o.mu > 0.0 && o.mu <= 2.0) {
            return Err(field("friction", format!("{} must be in (0, 2]", o.mu)));
        }
        check_mesh(name, &o.mesh, o.volume)?;
        let vertices: Vec<Point3<f64>> = o.mesh.vertices.iter().map(|v| o.pose * v).collect();
        let ocps = object_ocps(&vertices, &o.mesh.indices, params);
        if ocps.is_empty() {
            return Err(ObjectError::Degenerate {
                name: name.to_string(),
                detail: "no surface area".into(),
            });
        }
        let characteristic_length = ocps
            .iter()
            .map(|o| o.extents.max())
            .fold(0.0, f64::max)
            .max(0.01);
        Ok(Self {
            name: name.to_string(),
            mass: o.mass,
            mu: o.mu,
            pose: o.pose,
            center_of_mass: o.center_of_mass,
            triangles: o.mesh.indices.clone(),
            ocps,
            collision: o.collision.clone(),
            characteristic_length,
            lowest: vertices.iter().map(|v| v.z).fold(f64::INFINITY, f64::min),
            edges: SharpEdges::new(&vertices, &o.mesh.indices),
            vertices,
        })
    }
}

/// Refuses objects no hand can hold: out of [`MIN_DIAGONAL`, `MAX_DIAGONAL`],
/// or flat (`volume`, the enclosed or convex-hull volume, next to nothing).
/// Open and non-manifold meshes are fine (the kit decided how to use them).
pub fn check_mesh(name: &str, mesh: &TriangleMesh, volume: f64) -> Result<(), ObjectError> {
    let diagonal = mesh.bounding_diagonal();
    if !(MIN_DIAGONAL..=MAX_DIAGONAL).contains(&diagonal) {
        return Err(ObjectError::Size {
            name: name.to_string(),
            diagonal,
            min: MIN_DIAGONAL,
            max: MAX_DIAGONAL,
        });
    }
    let (lo, hi) = mesh.aabb();
    let box_volume = (hi - lo).iter().product::<f64>();
    if !(volume.abs() > 1e-6 * box_volume) {
        return Err(ObjectError::Degenerate {
            name: name.to_string(),
            detail: format!("encloses no volume ({volume:.3e} m³): flat or folded surface"),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn kit(mesh: TriangleMesh, pose: Isometry3<f64>, mass: f64) -> Object {
        Object::from_mesh("o", mesh, pose, mass, 0.5, None, 100.0).unwrap()
    }

    #[test]
    fn can_is_accepted_with_com_at_its_centre() {
        let mesh = TriangleMesh::cylinder(0.033, 0.122, 24);
        let pose = Isometry3::translation(0.5, -0.2, 1.0);
        let o = PlanObject::new(&kit(mesh.clone(), pose, 0.15), &OcpParams::default()).unwrap();
        let (lo, hi) = mesh.aabb();
        let centre = pose * Point3::from((lo.coords + hi.coords) / 2.0);
        assert!((o.center_of_mass - centre).norm() < 1e-9);
        assert_eq!(o.ocps.len(), 1);
    }

    #[test]
    fn open_and_non_manifold_objects_are_accepted() {
        let p = OcpParams::default();
        let id = Isometry3::identity();
        // An open can (top cap missing): planned on, with the hull's centroid.
        let mut open = TriangleMesh::cylinder(0.033, 0.122, 24);
        let top = open.vertices.len() as u32 - 1;
        open.indices.retain(|t| !t.contains(&top));
        let o = kit(open, id, 0.15);
        assert!(
            !o.topology.closed && o.collision.is_solid(),
            "{:?}",
            o.topology
        );
        assert!(
            (o.center_of_mass.z - 0.061).abs() < 1e-3,
            "{}",
            o.center_of_mass
        );
        assert!(PlanObject::new(&o, &p).is_ok());
        // A mug whose handle (a box) touches the body along an edge.
        let mut mug = TriangleMesh::cuboid(Vector3::new(0.0625, 0.0625, 0.125));
        let n = mug.vertices.len() as u32;
        let handle = mug.clone();
        mug.vertices.extend(
            handle
                .vertices
                .iter()
                .map(|v| v + Vector3::new(0.0625, 0.0625, 0.0)),
        );
        mug.indices
            .extend(handle.indices.iter().map(|t| t.map(|i| i + n)));
        let o = kit(mug, id, 0.3);
        assert!(
            o.topology.non_manifold_edges > 0 && o.topology.closed,
            "{:?}",
            o.topology
        );
        assert!(
            o.warnings.iter().any(|w| w.contains("non-manifold")),
            "{:?}",
            o.warnings
        );
        assert!(PlanObject::new(&o, &p).is_ok());
    }

    #[test]
    fn bad_objects_are_refused_with_reasons() {
        let mesh = TriangleMesh::cylinder(0.033, 0.122, 24);
        let p = OcpParams::default();
        let id = Isometry3::identity();
        let mut light = kit(mesh.clone(), id, 0.1);
        light.mass = 0.0;
        let e = PlanObject::new(&light, &p).unwrap_err();
        assert!(e.to_string().contains("mass"), "{e}");
        let big = TriangleMesh::cuboid(Vector3::new(3.0, 1.0, 1.0));
        let e = PlanObject::new(&kit(big, id, 0.1), &p).unwrap_err();
        assert!(matches!(e, ObjectError::Size { .. }), "{e}");
        // A flat sheet (two triangles): open, no volume.
        let sheet = TriangleMesh {
            vertices: vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(0.1, 0.0, 0.0),
                Point3::new(0.1, 0.1, 0.0),
                Point3::new(0.0, 0.1, 0.0),
            ],
            indices: vec![[0, 1, 2], [0, 2, 3]],
        };
        let e = PlanObject::new(&kit(sheet, id, 0.1), &p).unwrap_err();
        assert!(matches!(e, ObjectError::Degenerate { .. }), "{e}");
    }
}
