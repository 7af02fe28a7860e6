//! Where a point lies on a triangle mesh, and which outward normals the surface
//! has there.
//!
//! What: [`surface_point`] returns the distance from a point to a closed mesh's
//! surface and the outward normals of every triangle that holds the closest
//! point (one for a face, two along an edge, the whole fan at a vertex);
//! [`surface_point_within`] those of every triangle within a radius of it;
//! [`angle_to_normal_cone`] measures how far a direction is from the cone those
//! normals span.
//!
//! Why: a grasp checker must confirm that each reported contact lies on the
//! object and presses along the surface normal there, without trusting the
//! planner's own distance queries. At an edge or a vertex every direction of the
//! normal cone is a valid contact normal, so the test is "inside the cone", not
//! "equal to one face normal".
//!
//! How: brute force over the triangles (Ericson's closest point,
//! `tsukami_body::capsule_mesh::closest_point_on_triangle`); a checker runs it on a
//! handful of contacts. The cone test is exact: a direction is inside the cone of
//! `k` generators when it is a non-negative combination of at most three of them
//! (Carathéodory); otherwise the nearest direction of the cone lies on a ray or on
//! the plane sector between two generators.
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_body::mesh::TriangleMesh;
//! use tsukami_scenes::surface::{angle_to_normal_cone, surface_point};
//!
//! let cube = TriangleMesh::cuboid(Vector3::new(0.1, 0.1, 0.1));
//! let on_top = surface_point(&cube, &Point3::new(0.01, 0.0, 0.05)).unwrap();
//! assert!(on_top.distance < 1e-12);
//! assert!(angle_to_normal_cone(&Vector3::z(), &on_top.normals) < 1e-9);
//! // On the top edge, any direction between +z and +x is a surface normal.
//! let edge = surface_point(&cube, &Point3::new(0.05, 0.0, 0.05)).unwrap();
//! let diagonal = Vector3::new(1.0, 0.0, 1.0).normalize();
//! assert!(angle_to_normal_cone(&diagonal, &edge.normals) < 1e-9);
//! assert!(angle_to_normal_cone(&-Vector3::z(), &edge.normals) > 1.5);
//! ```

use nalgebra::{Matrix3, Point3, Vector3};
use tsukami_body::capsule_mesh::closest_point_on_triangle;
use tsukami_body::convert::{to_point, to_vec};
use tsukami_body::mesh::TriangleMesh;

/// Triangles within this distance (m) of the overall closest point are taken
/// to hold it (they share the closest edge or vertex).
pub const SAME_POINT: f64 = 1e-7;

/// The closest point of a mesh's surface to a query point.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfacePoint {
    /// Distance from the query point to the surface (m).
    pub distance: f64,
    /// The closest point on the surface.
    pub point: Point3<f64>,
    /// Outward unit normals of the triangles holding the closest point.
    pub normals: Vec<Vector3<f64>>,
}

/// The closest surface point of `mesh` to `p` (both in the mesh's frame);
/// `None` for a mesh without triangles or a non-finite point.
pub fn surface_point(mesh: &TriangleMesh, p: &Point3<f64>) -> Option<SurfacePoint> {
    surface_point_within(mesh, p, SAME_POINT)
}

/// [`surface_point`], with `normals` the outward normals of every triangle
/// within `radius` (m) of the closest point: those holding it and, for a
/// radius above [`SAME_POINT`], the surface around it (an edge that close).
pub fn surface_point_within(
    mesh: &TriangleMesh,
    p: &Point3<f64>,
    radius: f64,
) -> Option<SurfacePoint> {
    if !p.coords.iter().all(|x| x.is_finite()) {
        return None;
    }
    let closest_on = |k: usize, to: &Point3<f64>| {
        let [a, b, c] = mesh.triangle(k);
        let q = to_point(closest_point_on_triangle(
            to_vec(to),
            to_vec(&a),
            to_vec(&b),
            to_vec(&c),
        ));
        ((q - to).norm(), q)
    };
    let (best, point) = (0..mesh.indices.len())
        .map(|k| closest_on(k, p))
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    let radius = radius.max(SAME_POINT);
    let normals = (0..mesh.indices.len())
        .filter(|&k| closest_on(k, &point).0 <= radius)
        .map(|k| mesh.triangle_normal(k))
        .filter(|n| n.iter().all(|x| x.is_finite()))
        .collect();
    Some(SurfacePoint {
        distance: best,
        point,
        normals,
    })
}

/// The angle (rad) between the unit direction `v` and the convex cone spanned by
/// `generators` (unit vectors): 0 inside the cone, π when there are none.
pub fn angle_to_normal_cone(v: &Vector3<f64>, generators: &[Vector3<f64>]) -> f64 {
    let v = v.normalize();
    if !v.iter().all(|x| x.is_finite()) || generators.is_empty() {
        return std::f64::consts::PI;
    }
    if inside_cone(&v, generators) {
        return 0.0;
    }
    let mut best = std::f64::consts::PI;
    for (i, a) in generators.iter().enumerate() {
        best = best.min(angle(&v, a));
        for b in &generators[i + 1..] {
            if let Some(t) = angle_to_sector(&v, a, b) {
                best = best.min(t);
            }
        }
    }
    best
}

fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.normalize().dot(&b.normalize()).clamp(-1.0, 1.0).acos()
}

/// Whether `v` is a non-negative combination of some three (or fewer) generators.
fn inside_cone(v: &Vector3<f64>, g: &[Vector3<f64>]) -> bool {
    const EPS: f64 = 1e-9;
    if g.iter().any(|a| angle(v, a) <= EPS) {
        return true;
    }
    for i in 0..g.len() {
        for j in i + 1..g.len() {
            if angle_to_sector(v, &g[i], &g[j]).is_some_and(|t| t <= EPS) {
                return true;
            }
            for k in j + 1..g.len() {
                let m = Matrix3::from_columns(&[g[i], g[j], g[k]]);
                if let Some(inv) = m.try_inverse() {
                    let l = inv * v;
                    if l.iter().all(|x| *x >= -EPS) {
                        return true;
                    }
                }
            }
        }
    }
    false
}

/// The angle between `v` and the planar sector between `a` and `b`, when the
/// nearest direction of the sector lies strictly between them.
fn angle_to_sector(v: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> Option<f64> {
    let n = a.cross(b);
    if n.norm() < 1e-12 {
        return None;
    }
    let n = n.normalize();
    let in_plane = v - n * v.dot(&n);
    if in_plane.norm() < 1e-12 {
        return None;
    }
    // In the sector: on a's side toward b and on b's side toward a.
    let between = a.cross(&in_plane).dot(&n) >= 0.0 && in_plane.cross(b).dot(&n) >= 0.0;
    between.then(|| angle(v, &in_plane))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_and_normals_of_a_cube() {
        let cube = TriangleMesh::cuboid(Vector3::new(0.2, 0.2, 0.2));
        let above = surface_point(&cube, &Point3::new(0.0, 0.02, 0.105)).unwrap();
        assert!((above.distance - 0.005).abs() < 1e-12);
        assert!(above
            .normals
            .iter()
            .all(|n| (n - Vector3::z()).norm() < 1e-12));
        let corner = surface_point(&cube, &Point3::new(0.2, 0.2, 0.2)).unwrap();
        assert!((corner.distance - 0.1 * 3f64.sqrt()).abs() < 1e-12);
        let diag = Vector3::new(1.0, 1.0, 1.0).normalize();
        assert!(angle_to_normal_cone(&diag, &corner.normals) < 1e-9);
        // A direction 10 degrees outside the +z face normal's cone (a face: one ray).
        let tilted = Vector3::new(10f64.to_radians().sin(), 0.0, 10f64.to_radians().cos());
        let t = angle_to_normal_cone(&tilted, &above.normals);
        assert!((t - 10f64.to_radians()).abs() < 1e-9, "{t}");
    }

    #[test]
    fn a_radius_takes_in_an_edge_that_close() {
        let cube = TriangleMesh::cuboid(Vector3::new(0.2, 0.2, 0.2));
        // On the top face, 0.5 mm from its +x edge.
        let beside = Point3::new(0.0995, 0.0, 0.1);
        let exact = surface_point(&cube, &beside).unwrap();
        let x = Vector3::x();
        assert!(angle_to_normal_cone(&x, &exact.normals) > 1.5);
        let within = surface_point_within(&cube, &beside, 1e-3).unwrap();
        assert_eq!(within.point, exact.point);
        assert!(angle_to_normal_cone(&x, &within.normals) < 1e-9);
        // The -x side is 0.2 m away: never taken in.
        assert!(angle_to_normal_cone(&-x, &within.normals) > 1.5);
    }

    #[test]
    fn nothing_to_measure() {
        let empty = TriangleMesh {
            vertices: vec![],
            indices: vec![],
        };
        assert!(surface_point(&empty, &Point3::origin()).is_none());
        assert_eq!(
            angle_to_normal_cone(&Vector3::x(), &[]),
            std::f64::consts::PI
        );
    }
}
