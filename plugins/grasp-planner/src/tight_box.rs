//! The tightest box about a fixed axis: a smaller OCP than the principal axes give.
//!
//! What: [`tightest_rotation`] tries each candidate axis (the principal axes
//! and the world vertical), finds the minimum-area rectangle of the points
//! projected on the plane across it, and returns the box axes of the smallest
//! volume found with that volume.
//!
//! Why: principal axes follow the surface's mass, not its outline. A mug's
//! handle tilts them, so the OCP of section 3.1 comes out tilted and 30 %
//! larger than the mug, its faces are not the mug's sides and the splitting
//! axis misses the handle. The box aligned with the mug's outline is both
//! smaller and the one a person would draw.
//!
//! How: the minimum-area rectangle around a convex polygon has a side on one of
//! its edges (Freeman and Shapira, 1975), so the 2-D convex hull (Andrew's
//! monotone chain) and one pass over its edges find it. Pure over nalgebra.
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_grasp_planner::tight_box::tightest_rotation;
//! // A 2 × 1 × 1 box turned 30° about z: the vertical candidate finds it.
//! let r = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), 0.5236);
//! let pts: Vec<Point3<f64>> = (0..8)
//!     .map(|i| r * Point3::new((i & 1) as f64 * 2.0, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
//!     .collect();
//! let (_, volume) = tightest_rotation(&pts, &[Vector3::x(), Vector3::z()]).unwrap();
//! assert!((volume - 2.0).abs() < 1e-9);
//! ```

use nalgebra::{Matrix3, Point3, Rotation3, Vector2, Vector3};

/// One chain of Andrew's monotone chain over points in sorted order.
fn half_hull<'a>(points: impl Iterator<Item = &'a Vector2<f64>>) -> Vec<Vector2<f64>> {
    let cross = |o: &Vector2<f64>, a: &Vector2<f64>, b: &Vector2<f64>| {
        (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
    };
    let mut h: Vec<Vector2<f64>> = Vec::new();
    for q in points {
        while h.len() >= 2 && cross(&h[h.len() - 2], &h[h.len() - 1], q) <= 0.0 {
            h.pop();
        }
        h.push(*q);
    }
    h.pop(); // the last point starts the other chain
    h
}

/// Convex hull of 2-D points, counter-clockwise, without collinear points.
fn hull_2d(mut p: Vec<Vector2<f64>>) -> Vec<Vector2<f64>> {
    p.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let mut h = half_hull(p.iter());
    h.extend(half_hull(p.iter().rev()));
    h
}

/// Areas or volumes within this fraction of each other count as equal. Which
/// of two nearly equal boxes is the smaller is decided by the smallest change
/// of the object, and the two can point far apart: the two mirror-image
/// rectangles of a mug with its handle swap under a tilt of 0.01°. Of equal
/// ones a fixed rule picks, so a box turns only when the object turns.
const TIE: f64 = 0.01;

/// A fixed direction, off the world's axes and diagonals, that decides between
/// equally small rectangles: the one with a side nearest it.
const TIE_BREAK: [f64; 3] = [0.93, 0.34, 0.13];

/// Minimum-area rectangle of a convex polygon: `(unit side direction, area)`.
/// Of rectangles equal within [`TIE`], the one with a side nearest `prefer`.
fn min_area_rect(hull: &[Vector2<f64>], prefer: &Vector2<f64>) -> Option<(Vector2<f64>, f64)> {
    let rects: Vec<(Vector2<f64>, f64)> = (0..hull.len())
        .filter_map(|i| {
            let d = (hull[(i + 1) % hull.len()] - hull[i]).try_normalize(1e-15)?;
            let n = Vector2::new(-d.y, d.x);
            let (mut lo, mut hi) = (
                Vector2::repeat(f64::INFINITY),
                Vector2::repeat(f64::NEG_INFINITY),
            );
            for p in hull {
                let l = Vector2::new(d.dot(p), n.dot(p));
                lo = lo.inf(&l);
                hi = hi.sup(&l);
            }
            Some((d, (hi.x - lo.x) * (hi.y - lo.y)))
        })
        .collect();
    let least = rects.iter().map(|r| r.1).fold(f64::INFINITY, f64::min);
    let alignment = |d: &Vector2<f64>| d.dot(prefer).abs().max(d.perp(prefer).abs());
    rects
        .into_iter()
        .filter(|r| r.1 <= least * (1.0 + TIE))
        .max_by(|a, b| alignment(&a.0).total_cmp(&alignment(&b.0)))
}

/// The box axes (columns of a right-handed rotation) of the smallest box about
/// one of `axes`, and its volume; `None` without points or axes.
pub fn tightest_rotation(
    points: &[Point3<f64>],
    axes: &[Vector3<f64>],
) -> Option<(Rotation3<f64>, f64)> {
    let mut best: Option<(Rotation3<f64>, f64)> = None;
    for axis in axes {
        let Some(k) = axis.try_normalize(1e-12) else {
            continue;
        };
        // An orthonormal basis (u, w) of the plane across k.
        let seed = if k.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let u = k.cross(&seed).normalize();
        let w = k.cross(&u);
        let projected = points
            .iter()
            .map(|p| Vector2::new(u.dot(&p.coords), w.dot(&p.coords)))
            .collect();
        let g = Vector3::from(TIE_BREAK).normalize();
        let prefer = Vector2::new(u.dot(&g), w.dot(&g));
        let prefer = prefer.try_normalize(1e-6).unwrap_or_else(Vector2::x);
        let Some((d, area)) = min_area_rect(&hull_2d(projected), &prefer) else {
            continue;
        };
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                let t = k.dot(&p.coords);
                (lo.min(t), hi.max(t))
            });
        let volume = area * (hi - lo);
        if best.as_ref().is_none_or(|(_, v)| volume < *v * (1.0 - TIE)) {
            let a0 = (u * d.x + w * d.y).normalize();
            let a1 = k.cross(&a0);
            let rot = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[a0, a1, k]));
            best = Some((rot, volume));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_drops_inner_and_collinear_points() {
        let pts = vec![
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(2.0, 0.0),
            Vector2::new(2.0, 2.0),
            Vector2::new(0.0, 2.0),
            Vector2::new(1.0, 1.0),
        ];
        assert_eq!(hull_2d(pts).len(), 4);
    }

    #[test]
    fn rectangle_of_a_turned_square_is_the_square() {
        let r = nalgebra::Rotation2::new(0.3);
        let hull: Vec<_> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .iter()
            .map(|&(x, y)| r * Vector2::new(x, y))
            .collect();
        let (d, area) = min_area_rect(&hull, &Vector2::x()).unwrap();
        assert!((area - 1.0).abs() < 1e-12);
        assert!((d.x.abs() - 0.3f64.cos()).abs() < 1e-9 || (d.y.abs() - 0.3f64.cos()).abs() < 1e-9);
    }

    #[test]
    fn no_points_no_box() {
        assert!(tightest_rotation(&[], &[Vector3::z()]).is_none());
    }
}
