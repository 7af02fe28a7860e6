//! Tilted approaches: a face approached at an angle, turned toward one of its
//! neighbour faces, when every approach along the OCP's axes has failed.
//!
//! What: a [`Tilt`] (the reply's `FaceTilt`) turns the approach of a face
//! (the face's inward normal, section 3.2) by its `angle` toward the
//! neighbour face `toward`; [`tilts`] lists the tilts of one face that the
//! planner tries: toward every neighbour that neither rests on the support
//! nor faces an obstacle, at each of [`TILT_ANGLES`].
//!
//! Why: the paper's approaches run along the OCP's axes. Some everyday
//! placements leave none of them clear: a 25 mm flat box on a 1 m counter
//! (from the top the fingers and the thumb meet the counter, a side face is
//! lower than the fingers are wide), the same box under a shelf board (the
//! forearm meets the board above), a thin ring lying on a low table (the
//! fingers of every straight approach meet the table). A person takes them
//! with the hand coming at an angle: on the counter from the near side,
//! almost level; on the shelf from the top, leaning to the side; the ring
//! from the top, leaning over its near side. The tilted approaches are tried
//! only after every axis-aligned one has failed on every whole-body stage, so
//! a scene that plans without them plans exactly the same.
//!
//! How: [`rotation`] is the rotation by `angle` about `n × n₂` (`n` the
//! face's outward normal, `n₂` the neighbour's): it takes `n` to
//! `n cos θ + n₂ sin θ`, so the palm, turned by it about the point it holds,
//! comes from between the two faces. [`crate::palm_pose::palm_targets`]
//! applies it and measures the object across the tilted palm by projection.
//!
//! ```
//! use nalgebra::{Matrix3, Point3, Rotation3, Vector3};
//! use tsukami_grasp_planner::{ocp::Ocp, tilt::{rotation, tilts, TILT_ANGLES}};
//! use tsukami_msgs::planner::{BoxFace, FaceBlock};
//! // A flat box on a table: its bottom (−z) rests on the support.
//! let mut blocked = [None; 6];
//! blocked[5] = Some(FaceBlock::Support);
//! let flat = Ocp {
//!     region: 0,
//!     center: Point3::new(0.5, -0.25, 1.0125),
//!     rotation: Rotation3::identity(),
//!     extents: Vector3::new(0.1, 0.07, 0.025),
//!     blocked,
//! };
//! // The top turns toward each of the four sides, never toward the table.
//! let t = tilts(&flat, BoxFace::PosZ);
//! assert_eq!(t.len(), 4 * TILT_ANGLES.len());
//! // Turned toward −x (the robot's side), the approach comes down from there.
//! let toward_robot = t.iter().find(|t| t.toward == BoxFace::NegX).unwrap();
//! let a = rotation(toward_robot, &flat, BoxFace::PosZ) * -Vector3::z();
//! assert!(a.x > 0.0 && a.z < 0.0);
//! // A side face does not turn toward the table.
//! assert!(tilts(&flat, BoxFace::NegX).iter().all(|t| t.toward != BoxFace::NegZ));
//! ```

use nalgebra::{Unit, UnitQuaternion};
pub use tsukami_msgs::planner::FaceTilt as Tilt;
use tsukami_msgs::planner::{BoxFace, FaceBlock};

use crate::ocp::Ocp;

/// The angles (rad) a face's approach is turned by: 30°, 45°, 60° and 75°.
pub const TILT_ANGLES: [f64; 4] = [
    std::f64::consts::FRAC_PI_6,
    std::f64::consts::FRAC_PI_4,
    std::f64::consts::FRAC_PI_3,
    5.0 * std::f64::consts::PI / 12.0,
];

/// The world rotation that turns `face`'s outward normal by `tilt.angle`
/// toward `tilt.toward`'s.
pub fn rotation(tilt: &Tilt, ocp: &Ocp, face: BoxFace) -> UnitQuaternion<f64> {
    let axis = ocp.face_normal(face).cross(&ocp.face_normal(tilt.toward));
    UnitQuaternion::from_axis_angle(&Unit::new_normalize(axis), tilt.angle)
}

/// The tilts of `face` of `ocp` worth trying: toward each neighbour face that
/// does not rest on the support or face an obstacle (a neighbour against
/// another region of the object is fine: the hand reaches over it), at each
/// of [`TILT_ANGLES`], in [`BoxFace::ALL`] order.
pub fn tilts(ocp: &Ocp, face: BoxFace) -> Vec<Tilt> {
    BoxFace::ALL
        .into_iter()
        .zip(ocp.blocked)
        .filter(|(f, b)| {
            f.axis() != face.axis() && !matches!(b, Some(FaceBlock::Support | FaceBlock::Obstacle))
        })
        .flat_map(|(toward, _)| TILT_ANGLES.map(|angle| Tilt { toward, angle }))
        .collect()
}
