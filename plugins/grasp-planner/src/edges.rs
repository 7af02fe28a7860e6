//! Sharp edges of the object: where a fingertip slides off.
//!
//! What: [`SharpEdges::new`] keeps the mesh edges whose two triangles meet at
//! more than [`SHARP_ANGLE_DEG`] (a box's edges, a can's rims) and the rims of
//! holes of an open mesh; [`SharpEdges::distance`] is how far a point is from
//! the nearest of them.
//!
//! Why: a point contact on an edge has no face to press on. Its normal is the
//! direction from the edge to the fingertip, which the smallest slip changes:
//! a fingertip on a box's vertical edge slides round it and the box turns out
//! of a three-finger grasp (issue #22: of the physics benchmark's box and
//! low-box grasps that dropped, nearly all had a contact on an edge). The
//! planner prefers grasps whose contacts keep [`EDGE_CLEARANCE`] from every
//! sharp edge (`search::Found::preferred`).
//!
//! How: the triangles' edges are sorted by their vertex pair (no hash map);
//! an edge of two triangles whose normals differ by more than the angle, or
//! of one triangle, is kept as a segment. Distances are by brute force over
//! the kept segments, at most [`MAX_EDGES`] of them (the longest when there
//! are more: a noisy scan's many small creases count less than its rim).
//!
//! ```
//! use nalgebra::{Isometry3, Point3, Vector3};
//! use tsukami_body::mesh::TriangleMesh;
//! use tsukami_grasp_planner::edges::SharpEdges;
//! let cube = TriangleMesh::cuboid(Vector3::new(0.05, 0.05, 0.05));
//! let e = SharpEdges::new(&cube.vertices, &cube.indices);
//! assert_eq!(e.len(), 12);
//! // The middle of a face is 25 mm from every edge; a point on an edge, 0.
//! assert!((e.distance(&Point3::new(0.025, 0.0, 0.0)) - 0.025).abs() < 1e-12);
//! assert!(e.distance(&Point3::new(0.025, 0.025, 0.0)) < 1e-12);
//! // A fine cylinder's side has no sharp edge, only its two rims.
//! let can = TriangleMesh::cylinder(0.033, 0.12, 48);
//! let e = SharpEdges::new(&can.vertices, &can.indices);
//! assert_eq!(e.len(), 96);
//! ```

use nalgebra::{Point3, Vector3};

/// Two triangles meeting at more than this angle (degrees) make a sharp edge.
pub const SHARP_ANGLE_DEG: f64 = 30.0;

/// The distance (m) a preferred grasp keeps its contacts from sharp edges.
pub const EDGE_CLEARANCE: f64 = 0.003;

/// The most edges kept (the longest).
pub const MAX_EDGES: usize = 4096;

/// The sharp edges of a mesh, as segments.
#[derive(Debug, Clone, Default)]
pub struct SharpEdges {
    segments: Vec<(Point3<f64>, Point3<f64>)>,
}

impl SharpEdges {
    /// The sharp edges and hole rims of the mesh `vertices`/`triangles`.
    pub fn new(vertices: &[Point3<f64>], triangles: &[[u32; 3]]) -> Self {
        let normal = |t: &[u32; 3]| -> Option<Vector3<f64>> {
            let p = |k: usize| vertices.get(t[k] as usize);
            let (a, b, c) = (p(0)?, p(1)?, p(2)?);
            (b - a).cross(&(c - a)).try_normalize(1e-18)
        };
        // (smaller vertex, larger vertex, triangle), sorted by the pair.
        let mut edges: Vec<(u32, u32, usize)> = triangles
            .iter()
            .enumerate()
            .flat_map(|(k, t)| (0..3).map(move |i| (t[i], t[(i + 1) % 3], k)))
            .map(|(a, b, k)| (a.min(b), a.max(b), k))
            .collect();
        edges.sort_unstable();
        let cos = SHARP_ANGLE_DEG.to_radians().cos();
        let mut segments = Vec::new();
        for group in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            let sharp = match group {
                [_] => true,
                [(_, _, k), (_, _, l)] => match (normal(&triangles[*k]), normal(&triangles[*l])) {
                    (Some(n), Some(m)) => n.dot(&m) < cos,
                    _ => false,
                },
                // Non-manifold: a crease where bodies meet.
                _ => true,
            };
            let (a, b) = (group[0].0 as usize, group[0].1 as usize);
            if let (true, Some(a), Some(b)) = (sharp, vertices.get(a), vertices.get(b)) {
                segments.push((*a, *b));
            }
        }
        if segments.len() > MAX_EDGES {
            segments.sort_by(|x, y| {
                (y.1 - y.0)
                    .norm_squared()
                    .total_cmp(&(x.1 - x.0).norm_squared())
            });
            segments.truncate(MAX_EDGES);
        }
        SharpEdges { segments }
    }

    /// The number of sharp edges kept.
    pub fn len(&self) -> usize {
        self.segments.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.segments.is_empty()
    }

    /// The distance (m) from `p` to the nearest sharp edge; infinite when there is none.
    pub fn distance(&self, p: &Point3<f64>) -> f64 {
        self.segments
            .iter()
            .map(|(a, b)| {
                let ab = b - a;
                let t = ((p - a).dot(&ab) / ab.norm_squared().max(1e-30)).clamp(0.0, 1.0);
                (p - (a + ab * t)).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tsukami_body::mesh::TriangleMesh;

    #[test]
    fn a_box_has_twelve_edges_and_a_point_on_a_face_knows_its_distance() {
        let mut cube = TriangleMesh::cuboid(Vector3::new(0.05, 0.05, 0.05));
        cube.clean();
        let e = SharpEdges::new(&cube.vertices, &cube.indices);
        assert_eq!(e.len(), 12);
        // 2 mm in from the vertical edge at (+x, +y), on the +x face.
        let d = e.distance(&Point3::new(0.025, 0.023, 0.0));
        assert!((d - 0.002).abs() < 1e-12, "{d}");
        assert!(d < EDGE_CLEARANCE);
        assert!(e.distance(&Point3::new(0.025, 0.0, 0.0)) >= EDGE_CLEARANCE);
    }

    #[test]
    fn hole_rims_are_edges_and_smooth_surfaces_have_none() {
        let mut open = TriangleMesh::cylinder(0.03, 0.1, 32);
        let top = open.vertices.len() as u32 - 1;
        open.indices.retain(|t| !t.contains(&top));
        let closed = TriangleMesh::cylinder(0.03, 0.1, 32);
        let (o, c) = (
            SharpEdges::new(&open.vertices, &open.indices),
            SharpEdges::new(&closed.vertices, &closed.indices),
        );
        // The open top loses its cap's 32 spokes but its rim stays an edge.
        assert_eq!((o.len(), c.len()), (64, 64));
        let ball = TriangleMesh::uv_sphere(0.04, 24, 32);
        let b = SharpEdges::new(&ball.vertices, &ball.indices);
        assert!(b.is_empty(), "{} edges on a sphere", b.len());
        assert_eq!(b.distance(&Point3::origin()), f64::INFINITY);
    }

    #[test]
    fn bad_indices_are_skipped_not_a_panic() {
        let v = vec![Point3::origin(), Point3::new(1.0, 0.0, 0.0)];
        let e = SharpEdges::new(&v, &[[0, 1, 7]]);
        // The triangle's edge (0, 1) is a rim; the edges to vertex 7 are not kept.
        assert_eq!(e.len(), 1);
    }
}
