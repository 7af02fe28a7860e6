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
//! principal axis of its inliers). A supporting plane is one connected
//! surface: its inliers over the whole cloud are cut into connected pieces
//! (occupied cells of a `cell`-sized grid laid in the plane, cells up to two
//! apart joined: 14 mm always, 3 cm never), and only the pieces holding `min_fraction` of the points and
//! wider than `min_width` are removed as the plane — the tops of several
//! objects at one height are coplanar but no surface anything rests on, and
//! no object's own top is wider than the object. The other inliers stay in
//! the cloud but are no longer sampled, so the next round cannot find the
//! same disconnected plane again. The search repeats while a round finds a
//! plane and the sampled points could still hold one (at most
//! `2 · max_planes + 2` rounds). Deterministic: the random stream is seeded.
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
//! // A 40 cm table and three 4 cm box tops 10 cm apart, 10 cm above it: the
//! // tops hold 11 % of the points together, each less than 4 %.
//! let mut pts: Vec<Point3<f64>> = (0..1600).map(|i| Point3::new((i % 40) as f64 * 0.01, (i / 40) as f64 * 0.01, 0.75)).collect();
//! for k in 0..3 {
//!     pts.extend((0..64).map(|i| Point3::new(0.1 * k as f64 + (i % 8) as f64 * 0.005, 0.2 + (i / 8) as f64 * 0.005, 0.85)));
//! }
//! let planes = find_planes(&pts, &PlaneParams::default());
//! assert_eq!(planes.len(), 1, "the tops are no supporting plane");
//! assert_eq!(planes[0].inliers.len(), 1600);
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
    /// Side of the grid cells, laid in the plane, that connect a plane's
    /// inliers into surfaces: points of cells at most two cells apart in each
    /// direction are joined, so points `2 · cell` apart always are, and
    /// points more than `3 √2 · cell` apart never directly (m).
    pub cell: f64,
    /// A supporting surface is wider than this (m; the detector sets the
    /// object's width: no object's own top is wider than the object).
    pub min_width: f64,
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
            cell: 0.007,
            min_width: 0.0,
            seed: 1,
        }
    }
}

/// Two unit axes spanning the plane of unit normal `n` (`e1`, `e2`, with
/// `e1 × e2 = n`): the world x (or y, when `n` is close to x) projected on
/// it, and the third.
pub fn in_plane_axes(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let any = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = (any - n * n.dot(&any)).normalize();
    (e1, n.cross(&e1))
}

/// The large horizontal planes of `points`, biggest first, each a connected
/// surface (see the module's How).
pub fn find_planes(points: &[Point3<f64>], params: &PlaneParams) -> Vec<FoundPlane> {
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    // Points neither removed as a plane nor refused as one: what RANSAC samples.
    let mut sampled: Vec<usize> = (0..points.len()).collect();
    let mut taken = vec![false; points.len()];
    let mut found = Vec::new();
    let min_count = ((points.len() as f64 * params.min_fraction) as usize).max(20);
    for _ in 0..2 * params.max_planes + 2 {
        if found.len() >= params.max_planes || sampled.len() < min_count {
            break;
        }
        let step = (sampled.len() / params.sample.max(3)).max(1);
        let sample: Vec<Point3<f64>> = sampled.iter().step_by(step).map(|&i| points[i]).collect();
        let Some(best) = ransac(&sample, params, &mut rng) else {
            break;
        };
        // Inliers over the whole cloud (also points refused before: a
        // surface may join pieces refused alone), but none already removed.
        let inliers: Vec<usize> = (0..points.len())
            .filter(|&i| !taken[i] && best.distance(&points[i]).abs() <= params.threshold)
            .collect();
        let surface = surfaces(points, &inliers, &best, params, min_count);
        if surface.is_empty() && inliers.len() < min_count {
            break;
        }
        let refused: std::collections::HashSet<usize> = inliers.iter().copied().collect();
        for &i in &surface {
            taken[i] = true;
        }
        sampled.retain(|i| !refused.contains(i));
        if !surface.is_empty() {
            found.push(FoundPlane {
                plane: best,
                inliers: surface,
            });
        }
    }
    found.sort_by_key(|p| std::cmp::Reverse(p.inliers.len()));
    found
}

/// The `inliers` of `plane` that lie in connected pieces of at least
/// `min_count` points and wider than `min_width` (sorted indices).
fn surfaces(
    points: &[Point3<f64>],
    inliers: &[usize],
    plane: &Plane,
    params: &PlaneParams,
    min_count: usize,
) -> Vec<usize> {
    if inliers.len() < min_count {
        return Vec::new();
    }
    let (e1, e2) = in_plane_axes(&plane.normal);
    let uv: Vec<(f64, f64)> = inliers
        .iter()
        .map(|&i| (points[i].coords.dot(&e1), points[i].coords.dot(&e2)))
        .collect();
    let lo = uv.iter().fold((f64::INFINITY, f64::INFINITY), |m, p| {
        (m.0.min(p.0), m.1.min(p.1))
    });
    let cell = params.cell.max(1e-6);
    let key = |p: &(f64, f64)| -> (u64, u64) {
        (((p.0 - lo.0) / cell) as u64, ((p.1 - lo.1) / cell) as u64)
    };
    let members = pieces_of(&uv.iter().map(key).collect::<Vec<_>>());
    let mut out: Vec<usize> = members
        .iter()
        .filter(|m| m.len() >= min_count)
        .filter(|m| {
            let pts: Vec<Point3<f64>> = m.iter().map(|&j| points[inliers[j]]).collect();
            crate::segment::diameter(&pts) > params.min_width
        })
        .flat_map(|m| m.iter().map(|&j| inliers[j]))
        .collect();
    out.sort_unstable();
    out
}

/// Groups of indices into `cells` whose cells are at most two cells apart
/// in each direction (sparse:
/// union–find over the occupied cells, neighbours by binary search).
fn pieces_of(cells: &[(u64, u64)]) -> Vec<Vec<usize>> {
    let mut occupied: Vec<(u64, u64)> = cells.iter().map(|&(u, v)| (v, u)).collect();
    occupied.sort_unstable();
    occupied.dedup();
    let mut parent: Vec<usize> = (0..occupied.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for (i, &(v, u)) in occupied.iter().enumerate() {
        // The cells ahead within two cells (row-major): a 5 × 5 neighbourhood.
        let row = (1..=2).map(|du| (v, u + du));
        let below = (1..=2).flat_map(|dv| (0..5).map(move |k| (v + dv, (u + k).wrapping_sub(2))));
        for cell in row.chain(below) {
            if let Ok(j) = occupied.binary_search(&cell) {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); occupied.len()];
    for (j, &(u, v)) in cells.iter().enumerate() {
        let Ok(i) = occupied.binary_search(&(v, u)) else {
            continue;
        };
        let r = root(&mut parent, i);
        groups[r].push(j);
    }
    groups.retain(|g| !g.is_empty());
    groups
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A `n` × `m` grid of points `step` apart from `(x, y)` at height `z`.
    fn patch(x: f64, y: f64, (n, m): (usize, usize), step: f64, z: f64) -> Vec<Point3<f64>> {
        (0..n * m)
            .map(|i| Point3::new(x + (i % n) as f64 * step, y + (i / n) as f64 * step, z))
            .collect()
    }

    #[test]
    fn coplanar_box_tops_are_not_a_supporting_plane() {
        // A 1 m × 0.5 m table, five 6 cm box tops 12 cm above it, 4 cm apart:
        // together 6 % of the points, each 1.3 %.
        let mut pts = patch(0.0, 0.0, (100, 50), 0.01, 0.75);
        for k in 0..5 {
            pts.extend(patch(0.1 * k as f64, 0.2, (12, 12), 0.005, 0.87));
        }
        let planes = find_planes(&pts, &PlaneParams::default());
        assert_eq!(
            planes.len(),
            1,
            "{:?}",
            planes.iter().map(|p| p.plane).collect::<Vec<_>>()
        );
        assert!((planes[0].plane.offset - 0.75).abs() < 1e-6);
        assert_eq!(planes[0].inliers.len(), 5000);
    }

    #[test]
    fn a_connected_shelf_is_a_plane_and_an_object_top_is_not() {
        let mut pts = patch(0.0, 0.0, (100, 50), 0.01, 0.75);
        // A 15 cm shelf board, 6 % of the points.
        pts.extend(patch(0.2, 0.1, (18, 18), 0.009, 1.1));
        let planes = find_planes(&pts, &PlaneParams::default());
        assert_eq!(planes.len(), 2);
        // The same board, but the object looked for is wider: no object's top
        // is wider than the object, so the board may be one.
        let wide = PlaneParams {
            min_width: 0.5,
            ..PlaneParams::default()
        };
        let found = find_planes(&pts, &wide);
        let sizes: Vec<usize> = found.iter().map(|p| p.inliers.len()).collect();
        assert_eq!(sizes, [5000]);
    }
}
