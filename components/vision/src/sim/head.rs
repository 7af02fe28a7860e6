//! The robot's head camera: where it is for a head configuration, and how to
//! point it at something.
//!
//! What: [`HeadCamera`] wraps a robot model with a `camera_link` (an optical
//! frame: z forward, x right, y down), the two head joints, and the joints
//! below the head that carry the camera: one that bends the upper body
//! forward (`waist`), one that turns it (`turn`), one that lowers it
//! (`lift`), each if the model has it.
//!
//! Why: the simulator renders what the head camera sees, the detector needs
//! the camera's pose in the robot's base frame, and a look
//! ([`crate::look`]) moves the camera with the body as well as the head.
//!
//! How: forward kinematics of the model; [`HeadCamera::aim`] searches the
//! head joints' range (a grid, then a local refinement) for the angles whose
//! optical axis points closest to the target; [`HeadCamera::look_at`] bends
//! the waist forward when the head alone cannot look down far enough. The
//! body joints are told apart by how they move at rest, not by name: of the
//! movable joints between the root and the camera (the head's left out), a
//! revolute one about a horizontal axis bends, about a vertical axis turns, a
//! prismatic one along the vertical lifts — the first of each.
//!
//! ```
//! use std::path::Path;
//! use tsukami_body::urdf::load_urdf;
//! use tsukami_vision::camera::Intrinsics;
//! use tsukami_vision::sim::head::HeadCamera;
//! let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/../../models/robots/tsukami_humanoid/tsukami_humanoid.urdf");
//! let head = HeadCamera::new(load_urdf(Path::new(urdf)).unwrap(), Intrinsics::head_camera()).unwrap();
//! let name = |j: Option<usize>| head.robot.joints[j.unwrap()].name.clone();
//! assert_eq!((name(head.waist), name(head.turn), name(head.lift)),
//!            ("waist_pitch".into(), "waist_yaw".into(), "squat_z".into()));
//! ```

use nalgebra::{Isometry3, Point3, Vector3};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{JointId, JointKind, LinkId, RobotModel};

use crate::camera::{Camera, Intrinsics};
use crate::error::{invalid, Result};

/// The head camera of a robot model.
#[derive(Debug, Clone)]
pub struct HeadCamera {
    /// The robot model.
    pub robot: RobotModel,
    /// The optical frame's link.
    pub link: LinkId,
    /// Pan joint.
    pub yaw: JointId,
    /// Tilt joint.
    pub pitch: JointId,
    /// The joint bending the upper body forward (the waist's pitch), if the
    /// model has one (used when the head alone cannot look down far enough).
    pub waist: Option<JointId>,
    /// The joint turning the upper body about the vertical (the waist's yaw).
    pub turn: Option<JointId>,
    /// The joint lowering the upper body (a squat).
    pub lift: Option<JointId>,
    /// Intrinsics of the camera.
    pub intrinsics: Intrinsics,
}

impl HeadCamera {
    /// The camera `camera_link` moved by `head_yaw` and `head_pitch`.
    pub fn new(robot: RobotModel, intrinsics: Intrinsics) -> Result<Self> {
        let find = |what: &str, r: std::result::Result<usize, _>| {
            r.map_err(|e: tsukami_body::BodyError| invalid(format!("robot.{what}"), e.to_string()))
        };
        let link = find("camera_link", robot.link_id("camera_link"))?;
        let yaw = find("head_yaw", robot.joint_id("head_yaw"))?;
        let pitch = find("head_pitch", robot.joint_id("head_pitch"))?;
        intrinsics.validate()?;
        let [waist, turn, lift] = body_joints(&robot, link, [yaw, pitch]);
        Ok(HeadCamera {
            robot,
            link,
            yaw,
            pitch,
            waist,
            turn,
            lift,
            intrinsics,
        })
    }

    /// Whether joint `j` moves the camera.
    pub fn carries_camera(&self, j: JointId) -> bool {
        self.robot.chain(self.link).contains(&j)
    }

    /// The optical frame in the robot's base frame for configuration `q`.
    pub fn pose(&self, q: &[f64]) -> Isometry3<f64> {
        let mut fk = FkState::new(&self.robot);
        self.robot.forward_kinematics(q, &mut fk);
        *fk.pose(self.link)
    }

    /// The camera (pose in the base frame) for configuration `q`.
    pub fn camera(&self, q: &[f64]) -> Camera {
        Camera {
            intrinsics: self.intrinsics,
            pose: self.pose(q),
        }
    }

    /// The rest configuration with the head turned to look at `target`
    /// (base frame), within the head joints' limits; when the head alone
    /// leaves the target more than 5° off the optical axis, the waist bends
    /// forward (the least that brings it within 5°, else the best).
    pub fn look_at(&self, target: &Point3<f64>) -> Vec<f64> {
        let mut q = self.robot.rest_positions();
        let mut best = self.aim(&mut q, target);
        if let Some(w) = self.waist {
            for i in 1..=BEND_STEPS {
                if best < AIMED {
                    break;
                }
                let mut qw = self.robot.rest_positions();
                qw[w] = self.bend(i);
                let off = self.aim(&mut qw, target);
                if off < best {
                    best = off;
                    q = qw;
                }
            }
        }
        q
    }

    /// The waist's bend at step `i` of [`BEND_STEPS`] from rest to its forward
    /// limit (at most 1 rad); rest without a waist.
    pub fn bend(&self, i: usize) -> f64 {
        let rest = self.robot.rest_positions();
        let Some(w) = self.waist else { return 0.0 };
        let l = self.robot.joints[w].limits;
        (rest[w] + (l.upper.min(1.0) - rest[w]) * i as f64 / BEND_STEPS as f64).min(l.upper)
    }

    /// Turns the head in `q` (the other joints as they are) so that its
    /// optical axis points closest to `target`; returns the angle (rad) left
    /// between the axis and the target.
    pub fn aim(&self, q: &mut [f64], target: &Point3<f64>) -> f64 {
        let limits = |j: JointId| {
            let l = self.robot.joints[j].limits;
            (l.lower.max(-3.0), l.upper.min(3.0))
        };
        let (ylo, yhi) = limits(self.yaw);
        let (plo, phi) = limits(self.pitch);
        let mut cost = |y: f64, p: f64| {
            q[self.yaw] = y;
            q[self.pitch] = p;
            let pose = self.pose(q);
            let axis = pose.rotation * Vector3::z();
            let to = (target - Point3::from(pose.translation.vector)).normalize();
            1.0 - axis.dot(&to)
        };
        let mut best = (f64::INFINITY, 0.0, 0.0);
        for i in 0..=24 {
            for j in 0..=24 {
                let y = ylo + (yhi - ylo) * i as f64 / 24.0;
                let p = plo + (phi - plo) * j as f64 / 24.0;
                let c = cost(y, p);
                if c < best.0 {
                    best = (c, y, p);
                }
            }
        }
        let mut step = ((yhi - ylo) / 24.0).max((phi - plo) / 24.0);
        while step > 1e-5 {
            let mut improved = false;
            for (dy, dp) in [(step, 0.0), (-step, 0.0), (0.0, step), (0.0, -step)] {
                let (y, p) = ((best.1 + dy).clamp(ylo, yhi), (best.2 + dp).clamp(plo, phi));
                let c = cost(y, p);
                if c < best.0 {
                    best = (c, y, p);
                    improved = true;
                }
            }
            if !improved {
                step *= 0.5;
            }
        }
        q[self.yaw] = best.1;
        q[self.pitch] = best.2;
        (1.0 - best.0).clamp(-1.0, 1.0).acos()
    }
}

/// Steps of the waist's bend from rest to its forward limit.
pub const BEND_STEPS: usize = 8;

/// A target this close to the optical axis (rad) is looked at: 5°.
pub const AIMED: f64 = 5.0 * std::f64::consts::PI / 180.0;

/// The first joint below the head (not `head`) of each kind that carries
/// `camera`: bending (revolute, horizontal axis), turning (revolute, vertical
/// axis), lifting (prismatic, vertical axis), judged at rest.
fn body_joints(robot: &RobotModel, camera: LinkId, head: [JointId; 2]) -> [Option<JointId>; 3] {
    let mut fk = FkState::new(robot);
    robot.forward_kinematics(&robot.rest_positions(), &mut fk);
    let mut found = [None; 3];
    for &j in robot.chain(camera) {
        let joint = &robot.joints[j];
        if head.contains(&j) || !joint.is_independent() {
            continue;
        }
        let up = (fk.pose(joint.child).rotation * joint.axis.into_inner())
            .z
            .abs();
        let kind = match joint.kind {
            JointKind::Revolute | JointKind::Continuous if up < 0.3 => 0,
            JointKind::Revolute | JointKind::Continuous if up > 0.9 => 1,
            JointKind::Prismatic if up > 0.9 => 2,
            _ => continue,
        };
        found[kind] = found[kind].or(Some(j));
    }
    found
}
