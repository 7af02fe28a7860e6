//! Supporting planes by RANSAC: the table, a shelf, the floor.
//!
//! What: [`find_planes`] returns the large, nearly horizontal planes of a
//! point cloud, biggest first, with the indices of their inliers.
//!
//! Why: an object resting on a table touches it; until the table's points are
//! gone, object and table are one cluster.
//!
//! How: RANSAC (Fischler & Bolles) on a fixed-size subsample: three random
//! points give a plane; planes tilted more than `max_tilt` from the base
//! frame's up axis are skipped; the one with most inliers within `threshold`
//! wins and is refitted by least squares (the normal is the smallest
//! principal axis of its inliers). Its inliers over the whole cloud are then
//! removed and the search repeats, while a plane still holds `min_fraction`
//! of the points. Deterministic: the random stream is seeded.
//!
//! ```
//! use nalgebra::Point3;
//! use tsukami_vision::plane::{find_planes, PlaneParams};
//! let mut pts: Vec<Point3<f64>> = (0..400).map(|i| Point3::new((i % 20) as f64 * 0.01, (i / 20) as f64 * 0.01, 0.75)).collect();
//! pts.extend((0..50).map(|i| Point3::new(0.1, 0.1, 0.8 + i as f64 * 0.002)));
//! let planes = find_planes(&pts, &PlaneParams::default());
//! assert_eq!(planes.len(), 1);
//! assert!((planes[0].plane.offset - 0.75).abs() < 1e-9);
//! assert_eq!(planes[0].inliers.len(), 400);
//! ```

use nalgebra::{Point3, Unit, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::cloud::Moments;

/// A plane `normal · p = offset`, the normal pointing up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Unit normal (base frame, upward).
    pub normal: Unit<Vector3<f64>>,
    /// Signed offset along the normal (m).
    pub offset: f64,
}

impl Plane {
    /// Signed distance of `p` above the plane.
    #[inline]
    pub fn distance(&self, p: &Point3<f64>) -> f64 {
        self.normal.dot(&p.coords) - self.offset
    }
}

/// A plane found in a cloud.
#[derive(Debug, Clone)]
pub struct FoundPlane {
    /// The plane.
    pub plane: Plane,
    /// Indices of its inliers in the cloud.
    pub inliers: Vec<usize>,
}

/// RANSAC settings.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneParams {
    /// Up direction of the base frame.
    pub up: Vector3<f64>,
    /// Largest angle between a plane's normal and `up` (rad).
    pub max_tilt: f64,
    /// Inlier distance (m).
    pub threshold: f64,
    /// RANSAC iterations per plane.
    pub iterations: usize,
    /// Points the hypotheses are scored on.
    pub sample: usize,
    /// A plane must hold at least this fraction of the cloud.
    pub min_fraction: f64,
    /// Most planes removed.
    pub max_planes: usize,
    /// Random seed.
    pub seed: u64,
}

impl Default for PlaneParams {
    fn default() -> Self {
        PlaneParams {
            up: Vector3::z(),
            max_tilt: 20f64.to_radians(),
            threshold: 0.006,
            iterations: 150,
            sample: 3000,
            min_fraction: 0.04,
            max_planes: 3,
            seed: 1,
        }
    }
}

/// The large horizontal planes of `points`, biggest first.
pub fn find_planes(points: &[Point3<f64>], params: &PlaneParams) -> Vec<FoundPlane> {
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let mut remaining: Vec<usize> = (0..points.len()).collect();
    let mut found = Vec::new();
    let min_count = ((points.len() as f64 * params.min_fraction) as usize).max(20);
    while found.len() < params.max_planes && remaining.len() >= min_count {
        let step = (remaining.len() / params.sample.max(3)).max(1);
        let sample: Vec<Point3<f64>> = remaining.iter().step_by(step).map(|&i| points[i]).collect();
        let Some(best) = ransac(&sample, params, &mut rng) else {
            break;
        };
        let (inliers, rest): (Vec<usize>, Vec<usize>) = remaining
            .iter()
            .partition(|&&i| best.distance(&points[i]).abs() <= params.threshold);
        if inliers.len() < min_count {
            break;
        }
        remaining = rest;
        found.push(FoundPlane {
            plane: best,
            inliers,
        });
    }
    found
}

/// The best plane of a sample, refitted by least squares on its inliers.
fn ransac(sample: &[Point3<f64>], params: &PlaneParams, rng: &mut ChaCha8Rng) -> Option<Plane> {
    if sample.len() < 3 {
        return None;
    }
    let up = Unit::new_normalize(params.up);
    let cos_tilt = params.max_tilt.cos();
    let mut best: Option<(usize, Plane)> = None;
    for _ in 0..params.iterations {
        let idx: [usize; 3] = std::array::from_fn(|_| rng.random_range(0..sample.len()));
        let [a, b, c] = idx.map(|i| sample[i]);
        let n = (b - a).cross(&(c - a));
        if n.norm() < 1e-9 {
            continue;
        }
        let mut n = Unit::new_normalize(n);
        if n.dot(&up) < 0.0 {
            n = -n;
        }
        if n.dot(&up) < cos_tilt {
            continue;
        }
        let plane = Plane {
            normal: n,
            offset: n.dot(&a.coords),
        };
        let count = sample
            .iter()
            .filter(|p| plane.distance(p).abs() <= params.threshold)
            .count();
        if best.as_ref().is_none_or(|(c, _)| count > *c) {
            best = Some((count, plane));
        }
    }
    let (_, plane) = best?;
    let inliers: Vec<Point3<f64>> = sample
        .iter()
        .filter(|p| plane.distance(p).abs() <= params.threshold)
        .copied()
        .collect();
    let m = Moments::of(&inliers)?;
    let mut n = Unit::new_normalize(m.axes.column(2).into_owned());
    if n.dot(&up) < 0.0 {
        n = -n;
    }
    Some(Plane {
        normal: n,
        offset: n.dot(&m.centroid.coords),
    })
}
