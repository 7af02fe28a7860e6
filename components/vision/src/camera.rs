//! Pinhole cameras: intrinsics, the camera's pose, projection and back-projection.
//!
//! What: [`Intrinsics`] (image size, focal lengths and principal point in
//! pixels) and [`Camera`] (intrinsics plus the pose of the optical frame in the
//! robot's base frame).
//!
//! Why: the depth image is a set of rays; every stage (back-projection, the
//! simulator, the free-space check of a fitted model) must agree on one
//! convention.
//!
//! How: optical frame z forward, x right, y down (the URDF's `camera_link`);
//! pixel `(u, v)` has its centre at `(u, v)`, so the ray of pixel `(u, v)` is
//! `((u - cx) / fx, (v - cy) / fy, 1)`; depth values are the z coordinate in
//! the optical frame (not the range along the ray).
//!
//! ```
//! use tsukami_vision::camera::Intrinsics;
//! let k = Intrinsics::head_camera();
//! let p = k.unproject(100.0, 200.0, 0.8);
//! let (u, v) = k.project(&p).unwrap();
//! assert!((u - 100.0).abs() < 1e-9 && (v - 200.0).abs() < 1e-9);
//! assert!(k.validate().is_ok());
//! ```

use nalgebra::{Isometry3, Point3, Vector3};

use crate::error::{invalid, Result};

/// Largest accepted image side, in pixels (bounds memory on any input).
pub const MAX_SIDE: u32 = 4096;

/// Most pixels in one image (1280 × 1024): bounds a detection's memory and work
/// whatever the image holds (docs/components.md, "Bounds").
pub const MAX_PIXELS: usize = 1280 * 1024;

/// Pinhole intrinsics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Intrinsics {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point x, pixels.
    pub cx: f64,
    /// Principal point y, pixels.
    pub cy: f64,
}

impl Intrinsics {
    /// The robot's head camera: 640 × 480, 525 px focal length (a 62° × 49°
    /// field of view, as a Kinect-class depth camera), centred principal point.
    pub fn head_camera() -> Self {
        Intrinsics {
            width: 640,
            height: 480,
            fx: 525.0,
            fy: 525.0,
            cx: 319.5,
            cy: 239.5,
        }
    }

    /// Checks sizes (1..=[`MAX_SIDE`] a side, at most [`MAX_PIXELS`] in all),
    /// finite positive focal lengths and a finite principal point; the error names
    /// the field.
    pub fn validate(&self) -> Result<()> {
        for (name, side) in [("width", self.width), ("height", self.height)] {
            if side == 0 || side > MAX_SIDE {
                return Err(invalid(
                    format!("intrinsics.{name}"),
                    format!("{side} must be in 1..={MAX_SIDE}"),
                ));
            }
        }
        if self.pixels() > MAX_PIXELS {
            return Err(invalid(
                "intrinsics",
                format!(
                    "{} x {} = {} pixels is over the limit of {MAX_PIXELS} pixels (1280 x 1024)",
                    self.width,
                    self.height,
                    self.pixels()
                ),
            ));
        }
        for (name, f) in [("fx", self.fx), ("fy", self.fy)] {
            if !(f.is_finite() && f > 0.0) {
                return Err(invalid(
                    format!("intrinsics.{name}"),
                    format!("{f} must be finite and > 0"),
                ));
            }
        }
        for (name, c) in [("cx", self.cx), ("cy", self.cy)] {
            if !c.is_finite() {
                return Err(invalid(
                    format!("intrinsics.{name}"),
                    format!("{c} must be finite"),
                ));
            }
        }
        Ok(())
    }

    /// Number of pixels.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The ray of pixel `(u, v)` in the optical frame, with z = 1.
    #[inline]
    pub fn ray(&self, u: f64, v: f64) -> Vector3<f64> {
        Vector3::new((u - self.cx) / self.fx, (v - self.cy) / self.fy, 1.0)
    }

    /// The optical-frame point seen at pixel `(u, v)` with depth `z`.
    #[inline]
    pub fn unproject(&self, u: f64, v: f64, z: f64) -> Point3<f64> {
        Point3::from(self.ray(u, v) * z)
    }

    /// The pixel coordinates of an optical-frame point, if it is in front of
    /// the camera.
    #[inline]
    pub fn project(&self, p: &Point3<f64>) -> Option<(f64, f64)> {
        (p.z > 1e-9).then(|| (self.fx * p.x / p.z + self.cx, self.fy * p.y / p.z + self.cy))
    }

    /// The nearest pixel index of an optical-frame point, if it falls inside
    /// the image.
    #[inline]
    pub fn pixel_of(&self, p: &Point3<f64>) -> Option<(u32, u32)> {
        let (u, v) = self.project(p)?;
        let (u, v) = (u.round(), v.round());
        (u >= 0.0 && v >= 0.0 && u < self.width as f64 && v < self.height as f64)
            .then_some((u as u32, v as u32))
    }
}

/// A camera: intrinsics and the pose of its optical frame in the robot's base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Intrinsics.
    pub intrinsics: Intrinsics,
    /// Optical frame → base frame.
    pub pose: Isometry3<f64>,
}

impl Camera {
    /// Checks the intrinsics and that the pose is finite.
    pub fn validate(&self) -> Result<()> {
        self.intrinsics.validate()?;
        let t = &self.pose.translation.vector;
        let q = self.pose.rotation.quaternion();
        if !t.iter().all(|v| v.is_finite()) {
            return Err(invalid("camera_pose.position", "must be finite"));
        }
        if !q.coords.iter().all(|v| v.is_finite()) || (q.norm() - 1.0).abs() > 1e-6 {
            return Err(invalid(
                "camera_pose.quaternion",
                "must be a finite unit quaternion",
            ));
        }
        Ok(())
    }

    /// The camera centre in the base frame.
    pub fn centre(&self) -> Point3<f64> {
        Point3::from(self.pose.translation.vector)
    }

    /// Projects a base-frame point to a pixel index, if visible in the image.
    pub fn pixel_of(&self, p: &Point3<f64>) -> Option<(u32, u32)> {
        self.intrinsics
            .pixel_of(&self.pose.inverse_transform_point(p))
    }
}
