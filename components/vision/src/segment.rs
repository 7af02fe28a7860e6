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
//! bound within a few per cent of the true one for compact sets). The size
//! filter comes before the count: a cluster counts towards `max_clusters`
//! (largest first) only when it or one of its pieces is object-sized, so a
//! wall, table legs or large distractors, however many, cannot push the
//! target out; the oversize clusters are skipped, the one nearest the
//! object's size remembered for the "not found" message ([`Cut::nearest`]).
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
    /// Most object-sized clusters kept (largest first; a cluster with no
    /// object-sized piece is skipped and does not count).
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

/// A cluster too wide to be the object, described for a "not found" message.
#[derive(Debug, Clone, PartialEq)]
pub struct Oversize {
    /// Its diameter (m).
    pub width: f64,
    /// Its points (strided cloud).
    pub points: usize,
    /// Its centroid (base frame).
    pub centroid: Point3<f64>,
}

/// What [`segments`] cut the image into.
#[derive(Debug, Clone, Default)]
pub struct Cut {
    /// The clusters kept (largest first), then the unions of two.
    pub clusters: Vec<Vec<Point3<f64>>>,
    /// The object-sized segments, each naming its cluster.
    pub segments: Vec<Segment>,
    /// Clusters skipped: no piece of them is object-sized.
    pub oversize: usize,
    /// Of those, the one nearest the object's size.
    pub nearest: Option<Oversize>,
}

/// The object-sized segments of `cloud` (points off the `planes`) for an
/// object of diameter `size`, and the clusters they belong to.
pub fn segments(
    cloud: &PointCloud,
    planes: &[FoundPlane],
    grid: Grid,
    size: f64,
    params: &SegmentParams,
) -> Cut {
    let limit = size + params.margin;
    let mut cut = split(cloud, planes, grid, limit, params);
    if params.merge_pairs {
        add_unions(&mut cut.clusters, &mut cut.segments, limit);
    }
    cut.segments.retain(|s| diameter(&s.points) <= limit);
    cut
}

/// The off-plane points of `cloud` on the strided pixel grid (`None`: no
/// point, or a plane's), its width in cells.
fn off_plane_grid(
    cloud: &PointCloud,
    planes: &[FoundPlane],
    Grid { width, stride }: Grid,
) -> (Vec<Option<Point3<f64>>>, usize) {
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
    (grid, gw)
}

/// The off-plane points of the strided cloud, clustered (largest first); of
/// each cluster, it and its pieces at smaller gaps; kept while fewer than
/// `max_clusters` are, when it or a piece is no wider than `limit`.
fn split(
    cloud: &PointCloud,
    planes: &[FoundPlane],
    grid_of: Grid,
    limit: f64,
    params: &SegmentParams,
) -> Cut {
    let (grid, gw) = off_plane_grid(cloud, planes, grid_of);
    let points = |c: &[usize]| -> Vec<Point3<f64>> { c.iter().filter_map(|&i| grid[i]).collect() };
    let mut cut = Cut::default();
    for parent in cluster::clusters(&grid, gw, params.cluster_gap, params.min_points) {
        if cut.clusters.len() >= params.max_clusters {
            break;
        }
        let whole = points(&parent);
        let width = diameter(&whole);
        let pieces: Vec<Vec<Point3<f64>>> = pieces(&grid, gw, &parent, params)
            .iter()
            .map(|c| points(c))
            .collect();
        if width > limit && pieces.iter().all(|p| diameter(p) > limit) {
            cut.oversize += 1;
            if cut.nearest.as_ref().is_none_or(|n| width < n.width) {
                cut.nearest = Some(Oversize {
                    width,
                    points: whole.len(),
                    centroid: Moments::of(&whole).map_or(Point3::origin(), |m| m.centroid),
                });
            }
            continue;
        }
        let pi = cut.clusters.len();
        cut.segments.push(Segment {
            points: whole.clone(),
            parent: pi,
        });
        cut.segments.extend(
            pieces
                .into_iter()
                .map(|points| Segment { points, parent: pi }),
        );
        cut.clusters.push(whole);
    }
    cut
}

/// The pieces of the cluster `parent` (grid indices) at each of the smaller
/// gaps that split it (an occluder standing close in front of the target
/// joins it at first). Works on the cluster's bounding box of the grid only.
fn pieces(
    grid: &[Option<Point3<f64>>],
    gw: usize,
    parent: &[usize],
    params: &SegmentParams,
) -> Vec<Vec<usize>> {
    let (mut u0, mut v0, mut u1, mut v1) = (usize::MAX, usize::MAX, 0, 0);
    for &i in parent {
        let (u, v) = (i % gw, i / gw);
        (u0, v0, u1, v1) = (u0.min(u), v0.min(v), u1.max(u), v1.max(v));
    }
    if parent.is_empty() {
        return Vec::new();
    }
    let bw = u1 - u0 + 1;
    let mut sub = vec![None; bw * (v1 - v0 + 1)];
    for &i in parent {
        sub[(i / gw - v0) * bw + (i % gw - u0)] = grid[i];
    }
    let mut out = Vec::new();
    for factor in &params.split_gaps {
        let gap = params.cluster_gap * factor;
        let children = cluster::clusters(&sub, bw, gap, params.min_points);
        if children.len() > 1 {
            out.extend(children.into_iter().map(|c| {
                c.into_iter()
                    .map(|j| (j / bw + v0) * gw + j % bw + u0)
                    .collect()
            }));
        }
    }
    out
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A `w` × `h` patch of points 5 mm apart at pixel column `u0` of a
    /// grid `width` wide (stride 1), at height `z`.
    fn patch(cloud: &mut PointCloud, width: u32, u0: u32, (w, h): (u32, u32), z: f64) {
        for v in 0..h {
            for u in u0..u0 + w {
                cloud.points.push(Point3::new(
                    u as f64 * 0.005,
                    v as f64 * 0.005,
                    z + 0.001 * (u % 2) as f64,
                ));
                cloud.pixels.push(v * width + u);
            }
        }
    }

    fn params() -> SegmentParams {
        SegmentParams {
            cluster_gap: 0.012,
            split_gaps: vec![0.6],
            min_points: 25,
            max_clusters: 6,
            merge_pairs: true,
            margin: 0.01,
        }
    }

    #[test]
    fn seven_wall_blocks_do_not_push_the_object_out() {
        let width = 8 * 70;
        let mut cloud = PointCloud::default();
        // Seven 30 cm blocks (3600 points each), then one 5 cm object (100).
        for k in 0..7 {
            patch(&mut cloud, width, k * 70, (60, 60), 1.0);
        }
        patch(&mut cloud, width, 7 * 70, (10, 10), 0.9);
        let grid = Grid { width, stride: 1 };
        let cut = segments(&cloud, &[], grid, 0.07, &params());
        assert_eq!(cut.oversize, 7, "the blocks are skipped");
        assert_eq!(cut.clusters.len(), 1);
        assert_eq!(cut.segments.len(), 1, "{:?}", cut.segments.len());
        assert_eq!(cut.segments[0].points.len(), 100);
        let nearest = cut.nearest.expect("the blocks are described");
        assert!(
            (nearest.width - 0.295 * 2f64.sqrt()).abs() < 0.01,
            "{nearest:?}"
        );
    }

    #[test]
    fn only_oversize_clusters_leave_no_segment_and_name_the_nearest() {
        let width = 3 * 70;
        let mut cloud = PointCloud::default();
        patch(&mut cloud, width, 0, (60, 60), 1.0);
        patch(&mut cloud, width, 70, (30, 20), 1.0);
        let grid = Grid { width, stride: 1 };
        let cut = segments(&cloud, &[], grid, 0.07, &params());
        assert!(cut.segments.is_empty());
        assert_eq!(cut.oversize, 2);
        let nearest = cut.nearest.unwrap();
        assert_eq!(nearest.points, 600, "the smaller block is nearest in size");
    }

    #[test]
    fn the_count_bound_counts_object_sized_clusters_only() {
        let width = 12 * 20;
        let mut cloud = PointCloud::default();
        for k in 0..12 {
            patch(&mut cloud, width, k * 20, (10, 10 + k), 1.0);
        }
        let grid = Grid { width, stride: 1 };
        let p = SegmentParams {
            merge_pairs: false,
            ..params()
        };
        let cut = segments(&cloud, &[], grid, 0.2, &p);
        assert_eq!(cut.clusters.len(), 6);
        assert_eq!(cut.oversize, 0);
    }
}
