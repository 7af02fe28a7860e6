//! Antipodal point pairs on the object's surface.
//!
//! What: [`sample_pair`] draws a point on the surface (area-weighted), casts a
//! ray from it straight into the object and returns the pair it makes with
//! the exit point when the line between them lies inside both friction cones
//! (an *antipodal* pair: two fingers pressing along that line hold the object
//! by friction alone).
//!
//! Why: antipodal pairs are the classic cheap candidate set for pinch grasps
//! (Nguyen 1988; the GPD / Dex-Net samplers): most random palm poses touch
//! nothing useful, while almost every antipodal pair can be pinched.
//!
//! How: everything is in the mesh frame; the caller transforms to the world.
//! The ray cast is a brute-force Möller–Trumbore pass over the triangles,
//! fine for the few thousand triangles of a household object.

use nalgebra::{Point3, Vector3};
use rand::Rng;
use tsukami_body::mesh::TriangleMesh;

/// An antipodal pair in the mesh frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AntipodalPair {
    /// First point (where the ray started).
    pub a: Point3<f64>,
    /// Second point (where the ray left the object).
    pub b: Point3<f64>,
    /// Outward surface normal at `a`.
    pub normal_a: Vector3<f64>,
    /// Outward surface normal at `b`.
    pub normal_b: Vector3<f64>,
}

impl AntipodalPair {
    /// Distance between the points (the width the hand must open to).
    pub fn width(&self) -> f64 {
        (self.b - self.a).norm()
    }
}

/// Distance along `dir` from `origin` to triangle `k`, if the ray hits it
/// (Möller–Trumbore).
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
    let inv = 1.0 / det;
    let s = origin - p0;
    let u = inv * s.dot(&h);
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = s.cross(&e1);
    let v = inv * dir.dot(&qv);
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = inv * e2.dot(&qv);
    (t > 1e-6).then_some(t)
}

/// A uniformly random point on triangle `k`.
fn point_on_triangle(mesh: &TriangleMesh, k: usize, rng: &mut impl Rng) -> Point3<f64> {
    let [p0, p1, p2] = mesh.triangle(k);
    let (mut u, mut v): (f64, f64) = (rng.random(), rng.random());
    if u + v > 1.0 {
        (u, v) = (1.0 - u, 1.0 - v);
    }
    p0 + (p1 - p0) * u + (p2 - p0) * v
}

/// Draws one candidate pair; `None` when the draw is not antipodal within
/// `half_angle` (rad, the cone the line must lie in at both points) or the
/// ray leaves the mesh nowhere (an open mesh).
///
/// `cumulative_area` is the running sum of triangle areas (for area-weighted
/// sampling).
pub fn sample_pair(
    mesh: &TriangleMesh,
    cumulative_area: &[f64],
    half_angle: f64,
    rng: &mut impl Rng,
) -> Option<AntipodalPair> {
    let total = *cumulative_area.last()?;
    let pick: f64 = rng.random::<f64>() * total;
    let k = cumulative_area
        .partition_point(|&c| c < pick)
        .min(cumulative_area.len() - 1);
    let a = point_on_triangle(mesh, k, rng);
    let normal_a = mesh.triangle_normal(k);
    let dir = -normal_a;
    let (t, kb) = (0..mesh.indices.len())
        .filter(|&j| j != k)
        .filter_map(|j| ray_triangle(mesh, j, &a, &dir).map(|t| (t, j)))
        .min_by(|x, y| x.0.total_cmp(&y.0))?;
    let normal_b = mesh.triangle_normal(kb);
    // The line a→b is along −n_a (inside a's cone by construction); at b the
    // finger pushes along +n_a, which must be within `half_angle` of −n_b.
    if normal_a.dot(&-normal_b) < half_angle.cos() {
        return None;
    }
    Some(AntipodalPair {
        a,
        b: a + dir * t,
        normal_a,
        normal_b,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn box_pairs_are_opposite_faces() {
        let mesh = TriangleMesh::cuboid(Vector3::new(0.06, 0.04, 0.1));
        let mut acc = 0.0;
        let cum: Vec<f64> = (0..mesh.indices.len())
            .map(|k| {
                acc += mesh.triangle_area(k);
                acc
            })
            .collect();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut found = 0;
        for _ in 0..50 {
            if let Some(p) = sample_pair(&mesh, &cum, 0.2, &mut rng) {
                found += 1;
                let w = p.width();
                assert!(
                    [0.06, 0.04, 0.1].iter().any(|e| (w - e).abs() < 1e-9),
                    "width {w}"
                );
                assert!((p.normal_a + p.normal_b).norm() < 1e-9);
            }
        }
        assert!(found > 40, "{found} of 50");
    }
}
