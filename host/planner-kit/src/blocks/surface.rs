//! Sampling and ray casting on an object's surface (mesh frame).
//!
//! What: [`cumulative_areas`] (the table for area-weighted sampling),
//! [`sample_point`] (a uniformly random surface point and its triangle) and
//! [`ray_cast`] (the first triangle a ray hits, Möller–Trumbore, brute force:
//! fine for the few thousand triangles of a household object).
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_body::mesh::TriangleMesh;
//! use tsukami_planner_kit::blocks::surface::ray_cast;
//! let cube = TriangleMesh::cuboid(Vector3::new(0.1, 0.1, 0.1));
//! let (t, _) = ray_cast(&cube, &Point3::new(0.0, 0.0, -1.0), &Vector3::z(), None).unwrap();
//! assert!((t - 0.95).abs() < 1e-9);
//! ```

use nalgebra::{Point3, Vector3};
use tsukami_body::mesh::TriangleMesh;

/// Running sums of the triangle areas.
pub fn cumulative_areas(mesh: &TriangleMesh) -> Vec<f64> {
    let mut acc = 0.0;
    (0..mesh.indices.len())
        .map(|k| {
            acc += mesh.triangle_area(k);
            acc
        })
        .collect()
}

/// A uniformly random surface point (area-weighted over `cumulative`, the
/// table of [`cumulative_areas`]) from two uniform numbers in [0, 1) and a
/// third for the triangle: `(point, triangle)`.
pub fn sample_point(
    mesh: &TriangleMesh,
    cumulative: &[f64],
    r: [f64; 3],
) -> Option<(Point3<f64>, usize)> {
    let total = *cumulative.last()?;
    let k = cumulative
        .partition_point(|&c| c < r[0] * total)
        .min(cumulative.len() - 1);
    let [p0, p1, p2] = mesh.triangle(k);
    let (u, v) = if r[1] + r[2] > 1.0 {
        (1.0 - r[1], 1.0 - r[2])
    } else {
        (r[1], r[2])
    };
    Some((p0 + (p1 - p0) * u + (p2 - p0) * v, k))
}

fn ray_triangle(
    mesh: &TriangleMesh,
    k: usize,
    origin: &Point3<f64>,
    dir: &Vector3<f64>,
) -> Option<f64> {
    let [p0, p1, p2] = mesh.triangle(k);
    let (e1, e2) = (p1 - p0, p2 - p0);
    let h = dir.cross(&e2);
    let det = e1.dot(&h);
    if det.abs() < 1e-14 {
        return None;
    }
    let s = origin - p0;
    let u = s.dot(&h) / det;
    let q = s.cross(&e1);
    let v = dir.dot(&q) / det;
    if !(0.0..=1.0).contains(&u) || v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(&q) / det;
    (t > 1e-6).then_some(t)
}

/// The nearest hit of the ray `origin + t·dir` (t > 0), skipping triangle
/// `skip`: `(t, triangle)`.
pub fn ray_cast(
    mesh: &TriangleMesh,
    origin: &Point3<f64>,
    dir: &Vector3<f64>,
    skip: Option<usize>,
) -> Option<(f64, usize)> {
    (0..mesh.indices.len())
        .filter(|&k| Some(k) != skip)
        .filter_map(|k| ray_triangle(mesh, k, origin, dir).map(|t| (t, k)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
}
