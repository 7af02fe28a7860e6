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
//! whose optical axis points closest to the target, bending the waist forward
//! when the head alone cannot look down far enough.

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
    /// The waist's forward bend, if the model has one (used when the head alone
    /// cannot look down far enough).
    pub waist: Option<JointId>,
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
        let waist = robot.joint_id("waist_pitch").ok();
        Ok(HeadCamera {
            robot,
            link,
            yaw,
            pitch,
            waist,
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
    /// (base frame), within the head joints' limits; when the head alone
    /// leaves the target more than 5° off the optical axis, the waist bends
    /// forward (the least that brings it within 5°, else the best).
    pub fn look_at(&self, target: &Point3<f64>) -> Vec<f64> {
        let mut q = self.robot.rest_positions();
        let mut best = self.aim(&mut q, target);
        if let Some(w) = self.waist {
            let l = self.robot.joints[w].limits;
            let rest = q[w];
            for i in 1..=8 {
                if best.0 < 1.0 - 5f64.to_radians().cos() {
                    break;
                }
                let mut qw = self.robot.rest_positions();
                qw[w] = (rest + (l.upper.min(1.0) - rest) * i as f64 / 8.0).min(l.upper);
                let c = self.aim(&mut qw, target);
                if c.0 < best.0 {
                    best = c;
                    q = qw;
                }
            }
        }
        q[self.yaw] = best.1;
        q[self.pitch] = best.2;
        q
    }

    /// The head angles (cost, yaw, pitch) pointing the optical axis closest
    /// to `target` with the other joints as in `q`; cost is 1 − cos(angle off axis).
    fn aim(&self, q: &mut [f64], target: &Point3<f64>) -> (f64, f64, f64) {
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
        best
    }
}
