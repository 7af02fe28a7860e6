//! The environment shapes the grasp: supports and blocked faces from the obstacles.
//!
//! What: [`block_faces`] marks, on the object's OCP boxes, the faces that
//! rest on a support (a downward face with an obstacle just below it) and the
//! faces an approaching hand could not reach because an obstacle fills the
//! space in front of them (a wall behind a box, the table beside a lying
//! bottle). Selection then never samples those faces: low and lying objects
//! are approached from the top or their free side.
//!
//! Why: the paper takes the support as the plane under the object's lowest
//! point; on a real scene that sends most samples into the table or the shelf
//! wall. Looking at the obstacles before sampling costs a few box queries.
//!
//! How: in front of each face a slab the size of the face (shrunk by
//! [`FaceProbe::inset`] so a table the object stands on does not block its
//! sides) and [`FaceProbe::depth`] deep is tested against every obstacle.
//! A downward face (normal within 45° of −z) whose slab meets an obstacle
//! rests on a support; any other face whose slab meets one is blocked by it.
//! With no obstacles, the faces keep what [`crate::ocp`] marked from the
//! object's lowest point (the fallback).

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use tsukami_body::collision::{CollisionObject, Part};
use tsukami_body::model::Geometry;
use tsukami_msgs::planner::{BoxFace, FaceBlock};

use crate::ocp::Ocp;

/// The slab tested in front of a face.
#[derive(Debug, Clone, Copy)]
pub struct FaceProbe {
    /// How far out from the face the slab reaches (m): a finger's thickness.
    pub depth: f64,
    /// Gap between the face and the slab (m), so touching is not blocking.
    pub gap: f64,
    /// How much the slab is shrunk on each side of the face (m).
    pub inset: f64,
}

impl Default for FaceProbe {
    fn default() -> Self {
        Self {
            depth: 0.03,
            gap: 0.002,
            inset: 0.008,
        }
    }
}

/// A face found blocked by an obstacle.
#[derive(Debug, Clone, PartialEq)]
pub struct Blocked {
    /// Region.
    pub region: usize,
    /// Face.
    pub face: BoxFace,
    /// The obstacle's name.
    pub obstacle: String,
    /// Support (below) or obstacle (in front).
    pub support: bool,
}

fn slab(ocp: &Ocp, face: BoxFace, probe: &FaceProbe) -> Option<CollisionObject> {
    let k = face.axis();
    let n = ocp.face_normal(face);
    let mut size = ocp.extents.map(|e| (e - 2.0 * probe.inset).max(0.002));
    size[k] = probe.depth;
    let centre = ocp.face_center(face) + n * (probe.gap + 0.5 * probe.depth);
    let pose = Isometry3::from_parts(
        Translation3::from(centre.coords),
        UnitQuaternion::from_rotation_matrix(&ocp.rotation),
    );
    let part = Part::from_geometry(&Isometry3::identity(), &Geometry::Box { size }).ok()?;
    Some(CollisionObject::new("probe", pose, vec![part]))
}

/// Marks the faces of `ocps` blocked by `env` (see the module docs) and
/// returns what blocked each. Faces already blocked stay blocked.
pub fn block_faces(ocps: &mut [Ocp], env: &[&CollisionObject], probe: &FaceProbe) -> Vec<Blocked> {
    let mut out = Vec::new();
    if env.is_empty() {
        return out;
    }
    for ocp in ocps.iter_mut() {
        // The obstacles decide the support: forget the lowest-point guess.
        for b in ocp.blocked.iter_mut() {
            if *b == Some(FaceBlock::Support) {
                *b = None;
            }
        }
        for (k, face) in BoxFace::ALL.into_iter().enumerate() {
            if ocp.blocked[k].is_some() {
                continue;
            }
            let Some(s) = slab(ocp, face, probe) else {
                continue;
            };
            let Some(o) = env.iter().find(|o| o.intersects(&s, 0.0)) else {
                continue;
            };
            let support =
                ocp.face_normal(face).dot(&-Vector3::z()) > std::f64::consts::FRAC_1_SQRT_2;
            ocp.blocked[k] = Some(match support {
                true => FaceBlock::Support,
                false => FaceBlock::Obstacle,
            });
            out.push(Blocked {
                region: ocp.region,
                face,
                obstacle: o.name.clone(),
                support,
            });
        }
    }
    out
}
