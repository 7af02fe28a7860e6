//! Ray casting a [`SimWorld`] into a depth image and a label image.
//!
//! What: [`render`] gives the noisy depth image a camera would deliver;
//! [`trace`] gives the exact first hit (depth, body, incidence) of every pixel
//! of a region.
//!
//! Why: tests and the benchmark need images whose truth is known, and the
//! component needs images when no camera is attached.
//!
//! How: each pixel's ray (see [`crate::camera`]) is cast against every shape
//! whose world box, projected into the image, covers the pixel (parry's
//! `cast_ray_and_get_normal`, through the BVH for meshes); the nearest hit
//! wins. Depth is the hit's optical z. Noise follows [`super::noise`].

use nalgebra::Vector3;
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::Ray;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::noise::NoiseModel;
use super::world::SimWorld;
use crate::camera::Camera;
use crate::depth::DepthImage;
use crate::error::Result;

/// The exact first hit of one pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Optical-frame depth (m).
    pub z: f64,
    /// Cosine of the angle between the ray and the surface normal.
    pub cos_incidence: f64,
    /// Index of the body hit.
    pub body: usize,
}

/// A pixel rectangle `[u0, v0, u1, v1)`.
pub type Region = [u32; 4];

/// The first hit of every pixel of `region` (row-major within the region),
/// considering only the bodies for which `include` is true. `camera.pose` is
/// the optical frame in the world.
pub fn trace(
    world: &SimWorld,
    camera: &Camera,
    region: Region,
    include: &dyn Fn(usize) -> bool,
) -> Vec<Option<Hit>> {
    let k = &camera.intrinsics;
    let [u0, v0, u1, v1] = [
        region[0],
        region[1],
        region[2].min(k.width),
        region[3].min(k.height),
    ];
    // Pixel boxes of the shapes, to skip most ray-shape tests.
    let mut shapes = Vec::new();
    for (b, body) in world.bodies.iter().enumerate() {
        if !include(b) {
            continue;
        }
        for s in &body.shapes {
            shapes.push((b, s, pixel_box(camera, s.aabb.mins, s.aabb.maxs)));
        }
    }
    let origin = camera.pose.translation.vector;
    let o = PVec::new(origin.x, origin.y, origin.z);
    let mut out = Vec::with_capacity(((u1.saturating_sub(u0)) * (v1.saturating_sub(v0))) as usize);
    for v in v0..v1 {
        for u in u0..u1 {
            let ray_cam = k.ray(u as f64, v as f64);
            let dir = (camera.pose.rotation * ray_cam).normalize();
            let scale = 1.0 / ray_cam.norm(); // z per unit of range
            let ray = Ray::new(o, PVec::new(dir.x, dir.y, dir.z));
            let mut best: Option<Hit> = None;
            let mut best_t = f64::INFINITY;
            for (b, s, pb) in &shapes {
                if (u as f64) < pb[0]
                    || (u as f64) > pb[2]
                    || (v as f64) < pb[1]
                    || (v as f64) > pb[3]
                {
                    continue;
                }
                if let Some(hit) = s.shape.cast_ray_and_get_normal(&s.pose, &ray, best_t, true) {
                    if hit.time_of_impact < best_t && hit.time_of_impact > 0.0 {
                        best_t = hit.time_of_impact;
                        let n = Vector3::new(hit.normal.x, hit.normal.y, hit.normal.z);
                        best = Some(Hit {
                            z: hit.time_of_impact * scale,
                            cos_incidence: (-n.dot(&dir)).abs().min(1.0),
                            body: *b,
                        });
                    }
                }
            }
            out.push(best);
        }
    }
    out
}

/// The pixel box `[u_min, v_min, u_max, v_max]` covering a world box; the
/// whole image when any corner is behind the camera.
pub fn pixel_box(camera: &Camera, lo: PVec, hi: PVec) -> [f64; 4] {
    let k = &camera.intrinsics;
    let all = [
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::INFINITY,
    ];
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    let inv = camera.pose.inverse();
    for i in 0..8 {
        let p = nalgebra::Point3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let Some((u, v)) = k.project(&(inv * p)) else {
            return all;
        };
        b = [b[0].min(u), b[1].min(v), b[2].max(u), b[3].max(v)];
    }
    [b[0] - 1.0, b[1] - 1.0, b[2] + 1.0, b[3] + 1.0]
}

/// A rendered frame.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The measured depth image.
    pub image: DepthImage,
    /// Per pixel: the body hit plus one, 0 for nothing (before noise).
    pub labels: Vec<u16>,
}

/// Renders the whole image with `noise`, seeded by `seed`.
pub fn render(
    world: &SimWorld,
    camera: &Camera,
    noise: &NoiseModel,
    seed: u64,
) -> Result<Rendered> {
    camera.validate()?;
    let k = &camera.intrinsics;
    let hits = trace(world, camera, [0, 0, k.width, k.height], &|_| true);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut depth = Vec::with_capacity(hits.len());
    let mut labels = Vec::with_capacity(hits.len());
    for h in &hits {
        match h {
            Some(h) => {
                depth.push(noise.apply(h.z, h.cos_incidence, &mut rng).unwrap_or(0.0) as f32);
                labels.push((h.body + 1).min(u16::MAX as usize) as u16);
            }
            None => {
                depth.push(0.0);
                labels.push(0);
            }
        }
    }
    let image = DepthImage::new(k.width, k.height, depth)?;
    Ok(Rendered { image, labels })
}
