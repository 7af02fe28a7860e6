//! Judging a fitted pose against the image: is this the object, and is it there?
//!
//! What: [`verify`] scores a pose by two independent tests and combines them
//! into a confidence in [0, 1].
//!
//! Why: ICP always returns *a* pose. A wrong model (a bottle fitted to a
//! can) or a pose on clutter must be reported as not found, never as a
//! confident pose; an occluded object must still be found.
//!
//! How:
//! - *explained*: the fraction of the segment's measured points within
//!   `inlier` of the model's surface, or well in front of it (an occluder
//!   the segmentation could not separate). A wrong shape leaves many
//!   unexplained.
//! - *free space*: the model's camera-facing surface samples are projected
//!   into the image (a z-buffer keeps the nearest per pixel); samples seen
//!   more obliquely than `max_incidence` are left out, since a depth camera
//!   rarely measures a surface seen edge-on. Where the camera
//!   measured a depth well *behind* the model's surface, it saw through where
//!   the object would be: a violation. Much nearer measurements are occlusion
//!   and count neither way; measurements within `support` of the model
//!   support the pose; the rest (a surface a little in front of the model,
//!   as when a smaller model is fitted inside a larger object) count against
//!   it.
//! - confidence = explained × agreement, agreement = supported / (supported +
//!   violations + near misses + `unmeasured_weight` × unmeasured),
//!   and 0 when less than `min_visible` of the model's unoccluded surface is
//!   supported, more than `max_seen_through` of it is seen through (a wrong
//!   model sticking out of the object: on the benchmark's images right poses
//!   see through at most 1.7 % of their judged pixels, a bottle fitted to a
//!   lying can 13 % or more), more than `max_occluded` of it is hidden, or
//!   more than `max_outside` of its camera-facing samples fall outside the
//!   image (a model mostly out of the frame cannot be judged: a bottle fitted
//!   to a 2 cm scrap at the image's edge was "confirmed" by the 41 pixels of
//!   it left inside).

use nalgebra::{Isometry3, Point3};

use crate::camera::Camera;
use crate::depth::DepthImage;
use crate::template::ObjectTemplate;

/// Verification settings.
#[derive(Debug, Clone, PartialEq)]
pub struct VerifyParams {
    /// A measured point within this distance of the surface is explained (m).
    pub inlier: f64,
    /// A measurement this close to the model's surface supports it (m).
    pub support: f64,
    /// A measurement this much behind the model's surface is a violation,
    /// this much in front an occlusion (m).
    pub free_space: f64,
    /// Least supported fraction of the model's measured, unoccluded pixels.
    pub min_visible: f64,
    /// Largest hidden fraction of the model's measured pixels.
    pub max_occluded: f64,
    /// Largest fraction of the model's judged pixels where the camera sees
    /// through it.
    pub max_seen_through: f64,
    /// How much a model pixel without a measurement counts against the pose
    /// (relative to a violation): no return can mean the camera saw through
    /// the model to something out of range, or just a dropout.
    pub unmeasured_weight: f64,
    /// Model samples seen at a larger angle between the view ray and their
    /// normal are not judged (rad).
    pub max_incidence: f64,
    /// Largest fraction of the model's camera-facing samples outside the image.
    pub max_outside: f64,
    /// Judge every `sample_step`-th model sample only (1: all; a quick
    /// score for ranking hypotheses uses more).
    pub sample_step: usize,
    /// Find the nearest model sample through the template's lookup grid
    /// (faster, off by up to a cell) instead of exactly.
    pub fast_pairing: bool,
}

impl Default for VerifyParams {
    fn default() -> Self {
        VerifyParams {
            inlier: 0.005,
            support: 0.008,
            free_space: 0.015,
            min_visible: 0.5,
            max_occluded: 0.6,
            max_seen_through: 0.06,
            unmeasured_weight: 0.5,
            max_outside: 0.5,
            max_incidence: 75f64.to_radians(),
            sample_step: 1,
            fast_pairing: false,
        }
    }
}

/// The outcome of verification.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Verdict {
    /// Fraction of the segment's points explained by the model.
    pub explained: f64,
    /// Model pixels whose measurement agrees with the model.
    pub supported: usize,
    /// Model pixels where the camera saw something nearer (occlusion).
    pub occluded: usize,
    /// Model pixels where the camera saw through the model.
    pub violations: usize,
    /// Model pixels with a surface a little in front of the model.
    pub near_misses: usize,
    /// Model pixels without a measurement.
    pub unmeasured: usize,
    /// Fraction of the model's camera-facing samples outside the image.
    pub outside: f64,
    /// The model rests on a plane found in the image (set by the detector).
    pub resting: bool,
    /// The combined confidence in [0, 1].
    pub confidence: f64,
}

impl Verdict {
    /// The fraction of the model's judged pixels whose measurement supports
    /// it, an unmeasured pixel counting `unmeasured_weight`.
    pub fn agreement(&self, unmeasured_weight: f64) -> f64 {
        let judged = self.supported as f64
            + self.violations as f64
            + self.near_misses as f64
            + self.unmeasured as f64 * unmeasured_weight;
        self.supported as f64 / judged.max(1.0)
    }

    /// Fraction of the model's judged pixels where the camera sees through it.
    pub fn seen_through(&self) -> f64 {
        let judged = self.supported + self.violations + self.near_misses + self.unmeasured;
        self.violations as f64 / judged.max(1) as f64
    }

    /// Fraction of the model's visible surface hidden by something in front.
    pub fn occluded_fraction(&self) -> f64 {
        let seen = self.supported + self.occluded + self.violations + self.near_misses;
        self.occluded as f64 / seen.max(1) as f64
    }
}

/// The fraction of `segment` within `inlier` of the model's surface, or in
/// front of it (an occluder merged into the segment: nearer to the camera than
/// the model's surface at its pixel, by more than `free_space`).
fn explained_fraction(
    template: &ObjectTemplate,
    inv: &Isometry3<f64>,
    segment: &[Point3<f64>],
    camera: &Camera,
    splats: &[(u32, f64)],
    params: &VerifyParams,
) -> f64 {
    let gate2 = params.inlier * params.inlier;
    let k = &camera.intrinsics;
    let model_z = |u: u32, v: u32| -> Option<f64> {
        let mut best: Option<f64> = None;
        for dv in -1i64..=1 {
            for du in -1i64..=1 {
                let (uu, vv) = (u as i64 + du, v as i64 + dv);
                if uu < 0 || vv < 0 || uu >= k.width as i64 || vv >= k.height as i64 {
                    continue;
                }
                let key = vv as u32 * k.width + uu as u32;
                if let Ok(i) = splats.binary_search_by_key(&key, |s| s.0) {
                    best = Some(best.map_or(splats[i].1, |b: f64| b.max(splats[i].1)));
                }
            }
        }
        best
    };
    let cam_inv = camera.pose.inverse();
    let count = segment
        .iter()
        .filter(|p| {
            if template.pair(&(inv * *p), params.fast_pairing).1 <= gate2 {
                return true;
            }
            let pc = cam_inv * *p;
            match k.pixel_of(&pc).and_then(|(u, v)| model_z(u, v)) {
                Some(z) => pc.z < z - params.free_space,
                None => false,
            }
        })
        .count();
    count as f64 / segment.len().max(1) as f64
}

/// The camera-facing model samples at `pose` as a z-buffer: (pixel index,
/// optical depth), sorted by pixel, the nearest per pixel; and the fraction
/// of those samples outside the image.
fn splat(
    template: &ObjectTemplate,
    pose: &Isometry3<f64>,
    camera: &Camera,
    params: &VerifyParams,
) -> (Vec<(u32, f64)>, f64) {
    let cam_obj = pose.inverse() * camera.centre();
    let to_cam = camera.pose.inverse() * pose;
    let mut splats: Vec<(u32, f64)> = Vec::new();
    let cos_max = params.max_incidence.cos();
    let step = params.sample_step.max(1);
    let (mut facing, mut outside) = (0usize, 0usize);
    for (p, n) in template.points.iter().zip(&template.normals).step_by(step) {
        let ray = cam_obj - p;
        if n.dot(&ray) <= cos_max * ray.norm() {
            continue;
        }
        let pc = to_cam * p;
        facing += 1;
        match camera.intrinsics.pixel_of(&pc) {
            Some((u, v)) => splats.push((v * camera.intrinsics.width + u, pc.z)),
            None => outside += 1,
        }
    }
    splats.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    splats.dedup_by_key(|s| s.0);
    (splats, outside as f64 / facing.max(1) as f64)
}

/// The model's pixels at `pose` sorted by what the image measured there
/// (the pixel counts of a [`Verdict`]; `explained` and `confidence` stay 0).
pub fn pixel_counts(
    template: &ObjectTemplate,
    pose: &Isometry3<f64>,
    image: &DepthImage,
    camera: &Camera,
    params: &VerifyParams,
) -> Verdict {
    let (splats, outside) = splat(template, pose, camera, params);
    Verdict {
        outside,
        ..count_pixels(&splats, image, camera, params)
    }
}

fn count_pixels(
    splats: &[(u32, f64)],
    image: &DepthImage,
    camera: &Camera,
    params: &VerifyParams,
) -> Verdict {
    let mut verdict = Verdict::default();
    let width = camera.intrinsics.width;
    for &(pixel, z) in splats {
        match image.get(pixel % width, pixel / width) {
            None => verdict.unmeasured += 1,
            Some(d) if d > z + params.free_space => verdict.violations += 1,
            Some(d) if d < z - params.free_space => verdict.occluded += 1,
            Some(d) if (d - z).abs() <= params.support => verdict.supported += 1,
            Some(_) => verdict.near_misses += 1,
        }
    }
    verdict
}

/// Scores `pose` of `template` against the `segment` points (base frame) it
/// was fitted to and the image they came from.
pub fn verify(
    template: &ObjectTemplate,
    pose: &Isometry3<f64>,
    segment: &[Point3<f64>],
    image: &DepthImage,
    camera: &Camera,
    params: &VerifyParams,
) -> Verdict {
    let (splats, outside) = splat(template, pose, camera, params);
    let inv = pose.inverse();
    let mut verdict = count_pixels(&splats, image, camera, params);
    verdict.outside = outside;
    verdict.explained = explained_fraction(template, &inv, segment, camera, &splats, params);
    let explained = verdict.explained;
    let supported = verdict.agreement(params.unmeasured_weight);
    verdict.confidence = if supported >= params.min_visible
        && verdict.seen_through() <= params.max_seen_through
        && verdict.occluded_fraction() <= params.max_occluded
        && verdict.outside <= params.max_outside
    {
        explained * supported
    } else {
        0.0
    };
    verdict
}
