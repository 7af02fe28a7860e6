//! The robot's head camera: where it is for a head configuration, and how to
//! point it at something.
//!
//! What: [`HeadCamera`] wraps a robot model with a `camera_link` (an optical
//! frame: z forward, x right, y down) and the two head joints.
//!
//! Why: the simulator renders what the head camera sees, and the detector
//! needs the camera's pose in the robot's base frame.
//!
//! How: forward kinematics of the model; [`HeadCamera::look_at`] searches the
//! head joints' range (a grid, then a local refinement) for the configuration
//! whose optical axis points closest to the target.

use nalgebra::{Isometry3, Point3, Vector3};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{JointId, LinkId, RobotModel};

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
        Ok(HeadCamera {
            robot,
            link,
            yaw,
            pitch,
            intrinsics,
        })
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
    /// (base frame), within the head joints' limits.
    pub fn look_at(&self, target: &Point3<f64>) -> Vec<f64> {
        let mut q = self.robot.rest_positions();
        let limits = |j: JointId| {
            let l = self.robot.joints[j].limits;
            (l.lower.max(-3.0), l.upper.min(3.0))
        };
        let (ylo, yhi) = limits(self.yaw);
        let (plo, phi) = limits(self.pitch);
        let cost = |q: &mut Vec<f64>, y: f64, p: f64| {
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
                let c = cost(&mut q, y, p);
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
                let c = cost(&mut q, y, p);
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
        q
    }
}
