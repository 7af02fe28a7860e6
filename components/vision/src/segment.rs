//! Object-sized pieces of the image: what is left above the supporting planes,
//! clustered, split and joined.
//!
//! What: [`segments`] turns the strided cloud and its planes into candidate
//! [`Segment`]s, each a set of base-frame points that could all belong to one
//! object of a given size, and the whole clusters they came from.
//!
//! Why: ICP fits the model to one segment at a time. A segment must hold (most
//! of) the visible part of the target and little else; an occluder standing
//! close in front of the target can join it into one cluster, or cut what is
//! seen of it in two.
//!
//! How: the off-plane points are clustered on the pixel grid
//! ([`crate::cluster`]); each cluster is split again with smaller gaps
//! (`split_gaps`), each piece a segment of its own; the union of two clusters
//! is a segment too. A segment is kept when its diameter is at most the
//! model's (twice its radius about the centroid) plus a margin: a partial
//! view of the object is never wider than the object, whatever part of it is
//! hidden. The diameter is estimated by two farthest-point sweeps (a lower
//! bound within a few per cent of the true one for compact sets).
//!
//! ```
//! use nalgebra::Point3;
//! use tsukami_vision::segment::diameter;
//! let pts = [Point3::new(0.0, 0.0, 0.0), Point3::new(0.1, 0.0, 0.0), Point3::new(0.05, 0.01, 0.0)];
//! assert!((diameter(&pts) - 0.1).abs() < 1e-12);
//! ```

use nalgebra::Point3;

use crate::cloud::{Moments, PointCloud};
use crate::cluster;
use crate::plane::FoundPlane;

/// How the image is cut into segments.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentParams {
    /// Largest 3-D gap inside a cluster (m).
    pub cluster_gap: f64,
    /// Each cluster is split again with these fractions of `cluster_gap`.
    pub split_gaps: Vec<f64>,
    /// Smallest cluster (points of the strided cloud).
    pub min_points: usize,
    /// Most clusters examined (largest first).
    pub max_clusters: usize,
    /// Also the union of two clusters no larger than the object together.
    pub merge_pairs: bool,
    /// A segment may be this much wider than the model (m): noise, and points
    /// of the table's edge left by plane removal.
    pub margin: f64,
}

/// How the cloud was taken from the image: the image's width and the pixel
/// stride (to map a point's pixel to a cell of the strided grid).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grid {
    /// Image width (pixels).
    pub width: u32,
    /// Pixel stride of the cloud.
    pub stride: u32,
}

/// A cluster, or a piece or union of clusters, and the index of the whole
/// cluster it belongs to.
#[derive(Debug, Clone)]
pub struct Segment {
    /// Base-frame points.
    pub points: Vec<Point3<f64>>,
    /// Index into the clusters returned alongside.
    pub parent: usize,
}

/// The object-sized segments of `cloud` (points off the `planes`) for an
/// object of diameter `size`, and the whole clusters (largest first).
pub fn segments(
    cloud: &PointCloud,
    planes: &[FoundPlane],
    grid: Grid,
    size: f64,
    params: &SegmentParams,
) -> (Vec<Vec<Point3<f64>>>, Vec<Segment>) {
    let (mut clusters, mut pieces) = split(cloud, planes, grid, params);
    let limit = size + params.margin;
    if params.merge_pairs {
        add_unions(&mut clusters, &mut pieces, limit);
    }
    pieces.retain(|s| diameter(&s.points) <= limit);
    (clusters, pieces)
}

/// The off-plane points of the strided cloud, clustered (largest first), and
/// each cluster with its pieces when a smaller gap splits it.
fn split(
    cloud: &PointCloud,
    planes: &[FoundPlane],
    Grid { width, stride }: Grid,
    params: &SegmentParams,
) -> (Vec<Vec<Point3<f64>>>, Vec<Segment>) {
    let s = stride.max(1);
    let gw = width.div_ceil(s) as usize;
    let gh = cloud
        .pixels
        .iter()
        .map(|p| p / width / s)
        .max()
        .map_or(0, |v| v as usize + 1);
    let mut in_plane = vec![false; cloud.len()];
    for p in planes {
        for &i in &p.inliers {
            in_plane[i] = true;
        }
    }
    let mut grid = vec![None; gw * gh];
    for (i, (p, px)) in cloud.points.iter().zip(&cloud.pixels).enumerate() {
        if !in_plane[i] {
            let (u, v) = (px % width / s, px / width / s);
            grid[v as usize * gw + u as usize] = Some(*p);
        }
    }
    let points = |c: &[usize]| -> Vec<Point3<f64>> { c.iter().filter_map(|&i| grid[i]).collect() };
    let (mut parents, mut out) = (Vec::new(), Vec::new());
    let found = cluster::clusters(&grid, gw, params.cluster_gap, params.min_points);
    for (pi, parent) in found.into_iter().take(params.max_clusters).enumerate() {
        parents.push(points(&parent));
        out.push(Segment {
            points: points(&parent),
            parent: pi,
        });
        // Split again with smaller gaps: an occluder standing close in front
        // of the target joins it at first.
        let mut sub = vec![None; grid.len()];
        for &i in &parent {
            sub[i] = grid[i];
        }
        for factor in &params.split_gaps {
            let gap = params.cluster_gap * factor;
            let children = cluster::clusters(&sub, gw, gap, params.min_points);
            if children.len() > 1 {
                out.extend(children.iter().map(|c| Segment {
                    points: points(c),
                    parent: pi,
                }));
            }
        }
    }
    (parents, out)
}

/// Adds, as a cluster and a segment of its own, the union of every two
/// clusters that together are no wider than `limit`: an occluder standing in
/// front of the target can cut what is seen of it in two.
fn add_unions(clusters: &mut Vec<Vec<Point3<f64>>>, pieces: &mut Vec<Segment>, limit: f64) {
    let n = clusters.len();
    let centroids: Vec<Option<Point3<f64>>> = clusters
        .iter()
        .map(|c| Moments::of(c).map(|m| m.centroid))
        .collect();
    for a in 0..n {
        for b in a + 1..n {
            let (Some(ca), Some(cb)) = (centroids[a], centroids[b]) else {
                continue;
            };
            if (ca - cb).norm() > limit {
                continue;
            }
            let union: Vec<Point3<f64>> = clusters[a].iter().chain(&clusters[b]).copied().collect();
            if diameter(&union) <= limit {
                pieces.push(Segment {
                    points: union.clone(),
                    parent: clusters.len(),
                });
                clusters.push(union);
            }
        }
    }
}

/// The largest distance between two of `points`, estimated by two
/// farthest-point sweeps (exact for two points; never above the truth).
pub fn diameter(points: &[Point3<f64>]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let mean = points
        .iter()
        .fold(nalgebra::Vector3::zeros(), |s, p| s + p.coords)
        / points.len() as f64;
    let farthest = |from: &Point3<f64>| {
        points
            .iter()
            .max_by(|a, b| {
                (*a - from)
                    .norm_squared()
                    .total_cmp(&(*b - from).norm_squared())
            })
            .copied()
            .unwrap_or(*from)
    };
    let a = farthest(&Point3::from(mean));
    let b = farthest(&a);
    (a - b).norm()
}
