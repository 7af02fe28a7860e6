//! Shortcut smoothing of a collision-free piecewise-linear path.
//!
//! What: [`shortcut`] repeatedly picks two points on the path at random and, if
//! the straight segment between them is free, replaces the part in between with
//! it; then it drops waypoints that lie on the segment joining their neighbours.
//!
//! Why: RRT paths zig-zag. Random shortcutting (as surveyed by R. Geraerts and
//! M. H. Overmars, "Creating high-quality paths for motion planning", IJRR 2007)
//! removes most of the detour at the cost of a few segment checks, and keeps every
//! segment collision-free because it only ever adds checked segments.
//!
//! How: points are drawn by arc length (uniform along the path, not per
//! waypoint) from a seeded ChaCha stream, so the result is deterministic. The
//! number of attempts is the budget. A pair whose straight segment would be less
//! than [`MIN_GAIN`] shorter than the path between them is skipped unchecked: a
//! segment check costs as much for a tiny gain as for a large one.
//!
//! ```
//! use tsukami_trajectory_planner::rrt_connect::{SegmentSteps, Validity};
//! use tsukami_trajectory_planner::shortcut::{path_length, shortcut};
//! struct Free;
//! impl Validity for Free { fn is_valid(&mut self, _: &[f64]) -> bool { true } }
//! struct One;
//! impl SegmentSteps for One { fn steps(&self, _: &[f64], _: &[f64]) -> usize { 1 } }
//! let zigzag = vec![vec![0.0, 0.0], vec![0.5, 1.0], vec![1.0, 0.0]];
//! let smooth = shortcut(zigzag.clone(), 50, 1, &mut Free, &One);
//! assert!(path_length(&smooth) < 0.8 * path_length(&zigzag));
//! assert_eq!(smooth.first(), zigzag.first());
//! assert_eq!(smooth.last(), zigzag.last());
//! ```

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::rrt_connect::{lerp_into, segment_valid, SegmentSteps, Validity};

/// Smallest fraction of the path between two points a shortcut must save to be
/// checked.
pub const MIN_GAIN: f64 = 0.05;

/// Euclidean length of a path.
pub fn path_length(path: &[Vec<f64>]) -> f64 {
    path.windows(2).map(|w| dist(&w[0], &w[1])).sum()
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// The point at arc length `s` and the index of the segment it lies on.
fn point_at(path: &[Vec<f64>], mut s: f64) -> (usize, Vec<f64>) {
    let mut q = path[0].clone();
    for i in 0..path.len() - 1 {
        let l = dist(&path[i], &path[i + 1]);
        if s <= l || i == path.len() - 2 {
            let t = if l > 0.0 {
                (s / l).clamp(0.0, 1.0)
            } else {
                0.0
            };
            lerp_into(&path[i], &path[i + 1], t, &mut q);
            return (i, q);
        }
        s -= l;
    }
    (0, q)
}

/// Shortens `path` with `attempts` random shortcuts; the ends never move and every
/// new segment is checked with `validity` at the resolution `steps` gives.
pub fn shortcut(
    mut path: Vec<Vec<f64>>,
    attempts: usize,
    seed: u64,
    validity: &mut impl Validity,
    steps: &impl SegmentSteps,
) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for _ in 0..attempts {
        let total = path_length(&path);
        if path.len() < 3 || total <= 0.0 {
            break;
        }
        let (mut s1, mut s2) = (rng.random_range(0.0..total), rng.random_range(0.0..total));
        if s1 > s2 {
            std::mem::swap(&mut s1, &mut s2);
        }
        let (i, a) = point_at(&path, s1);
        let (j, b) = point_at(&path, s2);
        if j <= i {
            continue; // on one segment: nothing to gain
        }
        if dist(&a, &b) > (1.0 - MIN_GAIN) * (s2 - s1) {
            continue; // not worth a segment check
        }
        if !segment_valid(validity, steps, &a, &b) {
            continue;
        }
        let mut next = path[..=i].to_vec();
        next.push(a);
        next.push(b);
        next.extend_from_slice(&path[j + 1..]);
        path = next;
        path.dedup_by(|x, y| dist(x, y) < 1e-12);
    }
    drop_collinear(path)
}

/// Removes waypoints that lie on the segment between their neighbours (to 1e-9).
pub fn drop_collinear(path: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    if path.len() < 3 {
        return path;
    }
    let mut out = vec![path[0].clone()];
    for i in 1..path.len() - 1 {
        let a = out.last().expect("out starts non-empty");
        let (b, c) = (&path[i], &path[i + 1]);
        let straight = (dist(a, b) + dist(b, c) - dist(a, c)).abs() < 1e-9;
        if !straight {
            out.push(b.clone());
        }
    }
    out.push(path[path.len() - 1].clone());
    out
}
