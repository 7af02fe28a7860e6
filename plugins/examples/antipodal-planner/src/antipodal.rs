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
//! Sampling and ray casting are the kit's (`blocks::surface`).

use nalgebra::{Point3, Vector3};
use rand::Rng;
use tsukami_body::mesh::TriangleMesh;
use tsukami_planner_kit::blocks::surface::{ray_cast, sample_point};

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

/// Draws one candidate pair; `None` when the draw is not antipodal within
/// `half_angle` (rad) or the ray leaves the mesh nowhere (an open mesh).
/// `cumulative` is `blocks::surface::cumulative_areas` of the mesh.
pub fn sample_pair(
    mesh: &TriangleMesh,
    cumulative: &[f64],
    half_angle: f64,
    rng: &mut impl Rng,
) -> Option<AntipodalPair> {
    let (a, k) = sample_point(mesh, cumulative, rng.random())?;
    let normal_a = mesh.triangle_normal(k);
    let (t, kb) = ray_cast(mesh, &a, &-normal_a, Some(k))?;
    let normal_b = mesh.triangle_normal(kb);
    // At b the finger pushes along +n_a, which must be within the cone of −n_b.
    (normal_a.dot(&-normal_b) >= half_angle.cos()).then_some(AntipodalPair {
        a,
        b: a - normal_a * t,
        normal_a,
        normal_b,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use tsukami_planner_kit::blocks::surface::cumulative_areas;

    #[test]
    fn box_pairs_are_opposite_faces() {
        let mesh = TriangleMesh::cuboid(Vector3::new(0.06, 0.04, 0.1));
        let cum = cumulative_areas(&mesh);
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
