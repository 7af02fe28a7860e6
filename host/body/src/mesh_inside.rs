//! Inside tests on a triangle mesh without precomputed pseudo-normals.
//!
//! What: [`VertexTriangles`] lists the triangles around each vertex, and
//! [`contains_local_point`] answers "is this point inside the mesh?" on a
//! parry `TriMesh` built *without* `TriMeshFlags::ORIENTED`, giving exactly
//! the answer parry gives on the same mesh built with it.
//!
//! Why: parry computes every vertex and edge pseudo-normal when the mesh is
//! built, through two hash maps over all edges: about 28 ms on a
//! 100k-triangle object, a third of `set_object` (issue #10). An inside test
//! needs the pseudo-normal of one feature — the one nearest the point — so
//! computing that one when asked costs a few triangle normals per query, and
//! building the vertex–triangle lists costs about a millisecond.
//!
//! How: the point is projected on the mesh by parry's own BVH query (the same
//! projection parry's inside test makes: the `solid` flag changes nothing for
//! triangles in 3D). The projection's feature gives the pseudo-normal
//! (Bærentzen and Aanæs 2005): the triangle's normal on a face; on an edge
//! the sum of the unit normals of the triangles sharing it; on a vertex their
//! sum weighted by each triangle's angle there. The sums run over the
//! triangles in increasing index, with parry's own `Triangle::normal` and
//! angle, so they are bit for bit the sums parry accumulates in its maps. The
//! point is inside when it lies behind that normal.
//!
//! ```
//! use nalgebra::Vector3;
//! use parry3d_f64::math::Vector;
//! use parry3d_f64::shape::TriMesh;
//! use tsukami_body::mesh::TriangleMesh;
//! use tsukami_body::mesh_inside::{contains_local_point, VertexTriangles};
//! let cube = TriangleMesh::cuboid(Vector3::new(1.0, 1.0, 1.0));
//! let v = cube.vertices.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
//! let mesh = TriMesh::new(v, cube.indices.clone()).unwrap();
//! let around = VertexTriangles::new(mesh.indices(), mesh.vertices().len());
//! assert!(contains_local_point(&mesh, &around, Vector::new(0.1, 0.2, 0.3)));
//! assert!(!contains_local_point(&mesh, &around, Vector::new(0.6, 0.0, 0.0)));
//! ```

use parry3d_f64::math::{Real, Vector, VectorExt};
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::{TriMesh, TrianglePointLocation};

/// The triangles around each vertex, in increasing index (compressed rows).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct VertexTriangles {
    /// `start[v]..start[v + 1]` is vertex `v`'s range in `triangles`.
    start: Vec<u32>,
    triangles: Vec<u32>,
}

impl VertexTriangles {
    /// The lists of a mesh of `vertices` vertices (indices past the end are
    /// ignored; a triangle that repeats a vertex is listed once for it).
    pub fn new(indices: &[[u32; 3]], vertices: usize) -> Self {
        let mut start = vec![0u32; vertices + 1];
        let corners = |t: &[u32; 3]| {
            let [a, b, c] = *t;
            [
                Some(a),
                (b != a).then_some(b),
                (c != a && c != b).then_some(c),
            ]
        };
        for t in indices {
            for v in corners(t).into_iter().flatten() {
                if let Some(s) = start.get_mut(v as usize + 1) {
                    *s += 1;
                }
            }
        }
        for v in 0..vertices {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut triangles = vec![0u32; start[vertices] as usize];
        for (k, t) in indices.iter().enumerate() {
            for v in corners(t).into_iter().flatten() {
                if let Some(f) = fill.get_mut(v as usize).filter(|_| (v as usize) < vertices) {
                    triangles[*f as usize] = k as u32;
                    *f += 1;
                }
            }
        }
        Self { start, triangles }
    }

    /// The triangles using vertex `v`, in increasing index.
    pub fn around(&self, v: u32) -> &[u32] {
        let v = v as usize;
        match (self.start.get(v), self.start.get(v + 1)) {
            (Some(&a), Some(&b)) => &self.triangles[a as usize..b as usize],
            _ => &[],
        }
    }
}

/// Is `point` (mesh frame) inside `mesh`? Exactly parry's answer for the
/// same mesh built with `TriMeshFlags::ORIENTED` (see the module
/// documentation); `around` must be the lists of this mesh.
pub fn contains_local_point(mesh: &TriMesh, around: &VertexTriangles, point: Vector) -> bool {
    let Some((proj, (tri, location))) =
        mesh.project_local_point_and_get_location_with_max_dist(point, false, Real::MAX)
    else {
        return false;
    };
    behind_pseudo_normal(mesh, around, point, proj.point, tri, location)
}

/// [`contains_local_point`] when the triangle nearest `point` is known (a
/// closest-point query just found it): the point is projected on that
/// triangle alone, without the mesh-wide search. The answer is the same
/// for a point off the surface (at a tie between triangles the feature they
/// share has one pseudo-normal).
pub fn contains_local_point_near(
    mesh: &TriMesh,
    around: &VertexTriangles,
    point: Vector,
    nearest: u32,
) -> bool {
    if nearest as usize >= mesh.indices().len() {
        return contains_local_point(mesh, around, point);
    }
    let (proj, location) = mesh
        .triangle(nearest)
        .project_local_point_and_get_location(point, false);
    behind_pseudo_normal(mesh, around, point, proj.point, nearest, location)
}

/// Does `point`, whose projection on triangle `tri` is `proj` at `location`,
/// lie behind the mesh's pseudo-normal there?
fn behind_pseudo_normal(
    mesh: &TriMesh,
    around: &VertexTriangles,
    point: Vector,
    proj: Vector,
    tri: u32,
    location: TrianglePointLocation,
) -> bool {
    let idx = mesh.indices()[tri as usize];
    let normal = match location {
        TrianglePointLocation::OnFace(..) | TrianglePointLocation::OnSolid => {
            mesh.triangle(tri).scaled_normal()
        }
        TrianglePointLocation::OnEdge(i, _) => {
            let (a, b) = (idx[i as usize], idx[(i as usize + 1) % 3]);
            edge_pseudo_normal(mesh, around, a, b)
        }
        TrianglePointLocation::OnVertex(i) => vertex_pseudo_normal(mesh, around, idx[i as usize]),
    };
    (point - proj).dot(normal) <= 0.0
}

/// The sum of the unit normals of the triangles having edge `a`–`b`.
fn edge_pseudo_normal(mesh: &TriMesh, around: &VertexTriangles, a: u32, b: u32) -> Vector {
    let mut sum = Vector::ZERO;
    for &t in around.around(a) {
        let idx = mesh.indices()[t as usize];
        if !idx.contains(&b) || a == b {
            continue;
        }
        if let Some(n) = mesh.triangle(t).normal() {
            sum += n;
        }
    }
    sum
}

/// The sum of the unit normals of the triangles around vertex `v`, each
/// weighted by its angle at `v`.
fn vertex_pseudo_normal(mesh: &TriMesh, around: &VertexTriangles, v: u32) -> Vector {
    let mut sum = Vector::ZERO;
    for &t in around.around(v) {
        let idx = mesh.indices()[t as usize];
        let tri = mesh.triangle(t);
        let Some(n) = tri.normal() else {
            continue;
        };
        // parry's order: the angle at a, then b, then c; a vertex repeated in
        // a triangle (never after cleaning) gets each of its angles.
        let angles = [
            (tri.b - tri.a).angle(tri.c - tri.a),
            (tri.a - tri.b).angle(tri.c - tri.b),
            (tri.b - tri.c).angle(tri.a - tri.c),
        ];
        for (corner, angle) in idx.iter().zip(angles) {
            if *corner == v {
                sum += n * angle;
            }
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TriangleMesh;
    use nalgebra::Vector3;
    use parry3d_f64::query::PointQuery;
    use parry3d_f64::shape::TriMeshFlags;

    fn both(m: &TriangleMesh) -> (TriMesh, TriMesh, VertexTriangles) {
        let v: Vec<Vector> = m.vertices.iter().map(crate::convert::to_vec).collect();
        let plain = TriMesh::new(v.clone(), m.indices.clone()).unwrap();
        let oriented = TriMesh::with_flags(v, m.indices.clone(), TriMeshFlags::ORIENTED).unwrap();
        let around = VertexTriangles::new(m.indices.as_slice(), m.vertices.len());
        (plain, oriented, around)
    }

    /// A deterministic point cloud around and inside the mesh, many of them
    /// nearest an edge or a vertex.
    fn probes(lo: Vector, hi: Vector) -> Vec<Vector> {
        let mut out = Vec::new();
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let span = hi - lo;
        for _ in 0..4000 {
            let t = Vector::new(next(), next(), next()) * 1.4 - Vector::splat(0.2);
            out.push(lo + span * t);
        }
        out
    }

    /// [`contains_local_point_near`] with the nearest triangle found by
    /// brute force, the last of equals (not the BVH's pick at a tie).
    fn near(mesh: &TriMesh, around: &VertexTriangles, p: Vector) -> bool {
        use parry3d_f64::query::PointQuery;
        let d = |t: u32| (mesh.triangle(t).project_local_point(p, false).point - p).length();
        let nearest = (0..mesh.indices().len() as u32)
            .min_by(|&a, &b| d(a).total_cmp(&d(b)).then(b.cmp(&a)))
            .unwrap();
        contains_local_point_near(mesh, around, p, nearest)
    }

    #[test]
    fn answers_match_parrys_oriented_mesh_bit_for_bit() {
        let mut mug = TriangleMesh::cuboid(Vector3::new(0.0625, 0.0625, 0.125));
        let handle = mug.clone();
        let n = mug.vertices.len() as u32;
        mug.vertices.extend(
            handle
                .vertices
                .iter()
                .map(|v| v + Vector3::new(0.0625, 0.0625, 0.0)),
        );
        mug.indices
            .extend(handle.indices.iter().map(|t| t.map(|i| i + n)));
        mug.clean();
        for m in [
            TriangleMesh::cylinder(0.033, 0.122, 24),
            TriangleMesh::uv_sphere(0.05, 9, 14),
            TriangleMesh::cuboid(Vector3::new(0.1, 0.2, 0.3)),
            mug,
        ] {
            let (plain, oriented, around) = both(&m);
            let (lo, hi) = m.aabb();
            let (mut inside, mut outside) = (0, 0);
            for p in probes(crate::convert::to_vec(&lo), crate::convert::to_vec(&hi)) {
                let want = oriented.contains_local_point(p);
                assert_eq!(contains_local_point(&plain, &around, p), want, "{p:?}");
                assert_eq!(near(&plain, &around, p), want, "{p:?}");
                inside += usize::from(want);
                outside += usize::from(!want);
            }
            assert!(inside > 100 && outside > 100, "{inside} {outside}");
            // Vertices and edge midpoints pushed slightly out and in.
            for t in m.indices.iter().take(200) {
                for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[0], t[0])] {
                    let (a, b) = (plain.vertices()[a as usize], plain.vertices()[b as usize]);
                    let mid = (a + b) * 0.5;
                    for s in [1.001, 0.999] {
                        let p = mid * s;
                        let want = oriented.contains_local_point(p);
                        assert_eq!(contains_local_point(&plain, &around, p), want, "{p:?}");
                        assert_eq!(near(&plain, &around, p), want, "{p:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn vertex_lists_are_sorted_and_complete() {
        let m = TriangleMesh::cuboid(Vector3::new(1.0, 1.0, 1.0));
        let around = VertexTriangles::new(&m.indices, m.vertices.len());
        let mut total = 0;
        for v in 0..m.vertices.len() as u32 {
            let ts = around.around(v);
            assert!(ts.windows(2).all(|w| w[0] < w[1]));
            assert!(ts.iter().all(|&t| m.indices[t as usize].contains(&v)));
            total += ts.len();
        }
        assert_eq!(total, 3 * m.indices.len());
        assert!(around.around(99).is_empty());
    }
}
