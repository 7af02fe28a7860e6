//! Euclidean clusters of an organised point cloud.
//!
//! What: [`clusters`] groups the points left after plane removal into
//! connected pieces.
//!
//! Why: each object (and each leftover obstacle) becomes one candidate.
//!
//! How: the cloud comes from a regular pixel grid, so neighbours are known
//! without a search: two points of adjacent grid cells (8-neighbourhood) are
//! joined when they are closer than `max_gap` in 3-D; union–find collects the
//! components. This is linear in the number of points and splits objects at
//! depth discontinuities (an occluder in front of the target).
//!
//! ```
//! use nalgebra::Point3;
//! use tsukami_vision::cluster::clusters;
//! // Two 3x3 patches in a 6x3 grid, 0.5 m apart in depth.
//! let mut grid = vec![None; 18];
//! for v in 0..3 { for u in 0..6 {
//!     let z = if u < 3 { 1.0 } else { 1.5 };
//!     grid[v * 6 + u] = Some(Point3::new(u as f64 * 0.003, v as f64 * 0.003, z));
//! } }
//! let c = clusters(&grid, 6, 0.01, 1);
//! assert_eq!(c.len(), 2);
//! ```

use nalgebra::Point3;

/// Connected components of a grid of optional points (`width` cells per
/// row), joining 8-neighbours closer than `max_gap`; components smaller than
/// `min_points` are dropped. Returns grid indices, largest cluster first.
pub fn clusters(
    grid: &[Option<Point3<f64>>],
    width: usize,
    max_gap: f64,
    min_points: usize,
) -> Vec<Vec<usize>> {
    let mut parent: Vec<u32> = (0..grid.len() as u32).collect();
    let gap2 = max_gap * max_gap;
    let height = grid.len().checked_div(width).unwrap_or(0);
    for v in 0..height {
        for u in 0..width {
            let i = v * width + u;
            let Some(p) = grid[i] else { continue };
            let mut join = |j: usize| {
                if let Some(q) = grid[j] {
                    if (p - q).norm_squared() <= gap2 {
                        union(&mut parent, i as u32, j as u32);
                    }
                }
            };
            if u + 1 < width {
                join(i + 1);
            }
            if v + 1 < height {
                join(i + width);
                if u + 1 < width {
                    join(i + width + 1);
                }
                if u > 0 {
                    join(i + width - 1);
                }
            }
        }
    }
    let mut groups: std::collections::BTreeMap<u32, Vec<usize>> = Default::default();
    for (i, p) in grid.iter().enumerate() {
        if p.is_some() {
            let r = find(&mut parent, i as u32);
            groups.entry(r).or_default().push(i);
        }
    }
    let mut out: Vec<Vec<usize>> = groups
        .into_values()
        .filter(|g| g.len() >= min_points)
        .collect();
    out.sort_by_key(|g| std::cmp::Reverse(g.len()));
    out
}

fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let p = parent[parent[i as usize] as usize];
        parent[i as usize] = p;
        i = p;
    }
    i
}

fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb) as usize] = ra.min(rb);
    }
}
