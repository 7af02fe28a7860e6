//! Refinement by visible-surface agreement: moving a fitted model so that
//! what the camera would see of it matches what it measured.
//!
//! What: [`settle`] takes a pose from ICP and searches small translations
//! around it for the one whose rendering agrees best with the depth image.
//!
//! Why: ICP pairs each measured point with the nearest model surface; it
//! says nothing about model surface where no point was measured. When the
//! object is partly hidden and its sides are seen edge-on (no returns), the
//! visible points may be a face or two, along which the model can slide a few
//! millimetres without any residual changing. The image constrains that
//! slide: where the model would stick out, the camera sees the table behind
//! it (free space violated); where it falls short, measured object points are
//! left unsupported.
//!
//! How: the objective is, over the model's camera-facing samples projected
//! into the image ([`crate::verify::pixel_counts`] with a tight support
//! distance), supported − violations − near misses − ½·unmeasured pixels;
//! occluded pixels count neither way. A compass (pattern) search moves along
//! ± the model's principal axes (a box's face normals: it slides along its
//! faces) by `step`, takes the best improving move
//! until none improves, then halves the step, down to `min_step`. The first
//! move must gain at least `min_gain` of the judged pixels, so a pose the
//! points already fix is not moved by noise.

use nalgebra::{Isometry3, Translation3, Vector3};

use crate::camera::Camera;
use crate::depth::DepthImage;
use crate::template::ObjectTemplate;
use crate::verify::{pixel_counts, Verdict, VerifyParams};

/// Search settings.
#[derive(Debug, Clone, PartialEq)]
pub struct SettleParams {
    /// How pixels are judged (a tight `support`).
    pub verify: VerifyParams,
    /// First step (m).
    pub step: f64,
    /// Last step (m).
    pub min_step: f64,
    /// Most moves per step size.
    pub max_moves: usize,
    /// Least gain of the first move, as a fraction of the judged pixels.
    pub min_gain: f64,
}

impl Default for SettleParams {
    fn default() -> Self {
        SettleParams {
            verify: VerifyParams {
                support: 0.003,
                sample_step: 1,
                ..VerifyParams::default()
            },
            step: 0.002,
            min_step: 0.0005,
            max_moves: 8,
            min_gain: 0.01,
        }
    }
}

/// The objective: supported − violations − near misses − ½·unmeasured.
fn objective(v: &Verdict) -> f64 {
    v.supported as f64 - v.violations as f64 - v.near_misses as f64 - 0.5 * v.unmeasured as f64
}

/// The translation of `pose` (object → base) that best agrees with the image.
pub fn settle(
    template: &ObjectTemplate,
    pose: &Isometry3<f64>,
    image: &DepthImage,
    camera: &Camera,
    params: &SettleParams,
) -> Isometry3<f64> {
    let score =
        |p: &Isometry3<f64>| objective(&pixel_counts(template, p, image, camera, &params.verify));
    let start = pixel_counts(template, pose, image, camera, &params.verify);
    let judged = (start.supported + start.violations + start.near_misses + start.unmeasured) as f64;
    let mut best = (*pose, objective(&start));
    let threshold = best.1 + params.min_gain * judged;
    let mut moved = false;
    let mut step = params.step;
    // The model's principal axes: a box slides along its faces.
    let axes: Vec<Vector3<f64>> = (0..3)
        .map(|i| pose.rotation * template.moments.axes.column(i).into_owned())
        .collect();
    while step >= params.min_step * 0.999 {
        for _ in 0..params.max_moves {
            let mut next: Option<(Isometry3<f64>, f64)> = None;
            for axis in &axes {
                for sign in [1.0, -1.0] {
                    let p = Translation3::from(*axis * (sign * step)) * best.0;
                    let s = score(&p);
                    if s > next.as_ref().map_or(best.1, |n| n.1) {
                        next = Some((p, s));
                    }
                }
            }
            match next {
                Some(n) if moved || n.1 > threshold => {
                    best = n;
                    moved = true;
                }
                _ => break,
            }
        }
        step *= 0.5;
    }
    if moved {
        best.0
    } else {
        *pose
    }
}
