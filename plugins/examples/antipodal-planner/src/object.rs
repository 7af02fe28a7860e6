//! The object to grasp: its surface, mass, friction and bounding box.
//!
//! What: [`PlanObject`] holds the object's triangles (mesh frame), its world
//! pose, centre of mass, mass, friction coefficient, its bounding box (the one
//! "OCP region" this planner reports) and a collision body for distance
//! queries. [`pose_to_isometry`] checks and converts a message pose.
//!
//! Why: everything the search needs about the object is computed once, in
//! `set_object`, so a plan only reads it.
//!
//! How: build it with [`PlanObject::new`] from a loaded
//! [`TriangleMesh`]; every bad value is an error naming the request field.

use nalgebra::{Isometry3, Point3, Vector3};
use tsukami_body::collision::CollisionObject;
use tsukami_body::mesh::TriangleMesh;
use tsukami_msgs::planner::{BoxFace, FaceBlock, OcpBox, Pose};

use crate::error::PlanError;

/// A placed, checked object.
#[derive(Debug, Clone)]
pub struct PlanObject {
    /// Display name.
    pub name: String,
    /// Surface in the mesh frame.
    pub mesh: TriangleMesh,
    /// Pose of the mesh frame in the world.
    pub pose: Isometry3<f64>,
    /// Mass (kg).
    pub mass: f64,
    /// Friction coefficient μ.
    pub mu: f64,
    /// Centre of mass in the world frame.
    pub center_of_mass: Point3<f64>,
    /// Centre of the bounding box in the mesh frame.
    pub box_center: Point3<f64>,
    /// Full edge lengths of the bounding box (mesh-frame axes).
    pub box_extents: Vector3<f64>,
    /// Collision body at `pose`.
    pub collision: CollisionObject,
    /// Cumulative triangle areas, for area-weighted surface sampling.
    pub cumulative_area: Vec<f64>,
}

/// Checks a message pose (finite, unit-ish quaternion) and converts it;
/// errors name `field`.
pub fn pose_to_isometry(pose: &Pose, field: &str) -> Result<Isometry3<f64>, PlanError> {
    tsukami_scenes::geometry::pose_to_isometry(pose).map_err(|message| {
        let (part, why) = message.split_once(": ").unwrap_or(("", message.as_str()));
        PlanError::invalid(format!("{field}.{part}"), why)
    })
}

/// Converts an isometry to a message pose.
pub fn isometry_to_pose(iso: &Isometry3<f64>) -> Pose {
    tsukami_scenes::geometry::isometry_to_pose(iso)
}

/// Centroid of the volume enclosed by a closed, outward-oriented mesh
/// (divergence theorem over origin-based tetrahedra); `None` when the volume
/// is not positive.
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

impl PlanObject {
    /// Checks the values and builds the object. `center_of_mass` is in the
    /// mesh frame (default: the volume centroid of a closed mesh, else the
    /// bounding-box centre).
    pub fn new(
        name: &str,
        mesh: TriangleMesh,
        pose: Isometry3<f64>,
        mass: f64,
        mu: f64,
        center_of_mass: Option<[f64; 3]>,
    ) -> Result<Self, PlanError> {
        if !(mass.is_finite() && mass > 0.0) {
            return Err(PlanError::invalid(
                "mass",
                format!("{mass} must be finite and > 0"),
            ));
        }
        if !(mu.is_finite() && mu > 0.0) {
            return Err(PlanError::invalid(
                "friction",
                format!("{mu} must be finite and > 0"),
            ));
        }
        mesh.validate().map_err(|m| PlanError::Model {
            field: "shape".into(),
            message: m,
        })?;
        let (lo, hi) = mesh.aabb();
        let box_center = nalgebra::center(&lo, &hi);
        let box_extents = hi - lo;
        let com_local = match center_of_mass {
            Some(c) if c.iter().all(|v| v.is_finite()) => Point3::from(c),
            Some(_) => return Err(PlanError::invalid("center_of_mass", "must be finite")),
            None if mesh.is_closed() => volume_centroid(&mesh).unwrap_or(box_center),
            None => box_center,
        };
        let collision =
            CollisionObject::from_mesh(name, pose, &mesh).map_err(|m| PlanError::Model {
                field: "shape".into(),
                message: m,
            })?;
        let mut acc = 0.0;
        let cumulative_area = (0..mesh.indices.len())
            .map(|k| {
                acc += mesh.triangle_area(k);
                acc
            })
            .collect();
        Ok(Self {
            name: name.to_owned(),
            center_of_mass: pose * com_local,
            mesh,
            pose,
            mass,
            mu,
            box_center,
            box_extents,
            collision,
            cumulative_area,
        })
    }

    /// Largest box edge (m): the characteristic length γ⁻¹ of wrenches, eq. (6).
    pub fn characteristic_length(&self) -> f64 {
        self.box_extents.max()
    }

    /// The bounding box in the world frame (its rotation is the object's).
    pub fn box_pose(&self) -> Isometry3<f64> {
        self.pose * Isometry3::translation(self.box_center.x, self.box_center.y, self.box_center.z)
    }

    /// The face of the box whose outward normal is most opposed to `approach`
    /// (the direction the palm moves toward the object, world frame).
    pub fn face_toward(&self, approach: &Vector3<f64>) -> BoxFace {
        let local = self.pose.rotation.inverse() * approach;
        let axis = (0..3)
            .max_by(|&a, &b| local[a].abs().total_cmp(&local[b].abs()))
            .unwrap_or(0);
        // The hand comes from the side the approach points away from.
        BoxFace::from_axis(axis, local[axis] < 0.0)
    }

    /// The box as the one region of `set_object`'s summary: faces whose
    /// outward normal points down are blocked by the support.
    pub fn region(&self) -> OcpBox {
        let pose = self.box_pose();
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
        OcpBox {
            region: 0,
            pose: isometry_to_pose(&pose),
            extents: [self.box_extents.x, self.box_extents.y, self.box_extents.z],
            free_faces: free,
            blocked_faces: blocked,
        }
    }
}
