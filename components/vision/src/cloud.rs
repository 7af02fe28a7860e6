//! Point clouds from depth images, and their first and second moments.
//!
//! What: [`PointCloud`] is a set of base-frame points, each remembering the
//! pixel it came from; [`Moments`] gives a set's centroid and principal axes.
//!
//! Why: plane removal, clustering and ICP work on 3-D points; the pixel index
//! lets a later stage go back to the full-resolution image around a cluster.
//!
//! How: back-projection through the pinhole model of [`crate::camera`], every
//! `stride`-th pixel in each direction; principal axes are the eigenvectors of
//! the covariance (nalgebra's symmetric eigen-decomposition), sorted by
//! decreasing variance and made right-handed.
//!
//! ```
//! use nalgebra::Point3;
//! use tsukami_vision::cloud::Moments;
//! let pts: Vec<Point3<f64>> = (0..100).map(|i| Point3::new(i as f64 * 0.01, 0.0, (i % 2) as f64 * 0.001)).collect();
//! let m = Moments::of(&pts).unwrap();
//! assert!(m.axes.column(0).x.abs() > 0.99); // the long axis is x
//! ```

use nalgebra::{Matrix3, Point3, SymmetricEigen, Vector3};

use crate::camera::Camera;
use crate::depth::DepthImage;

/// Base-frame points with their source pixels.
#[derive(Debug, Clone, Default)]
pub struct PointCloud {
    /// Points in the robot's base frame.
    pub points: Vec<Point3<f64>>,
    /// The pixel index `v * width + u` of each point.
    pub pixels: Vec<u32>,
}

impl PointCloud {
    /// Back-projects every `stride`-th pixel (in u and v) with a measurement.
    pub fn from_depth(image: &DepthImage, camera: &Camera, stride: u32) -> Self {
        let stride = stride.max(1);
        let k = &camera.intrinsics;
        let mut cloud = PointCloud::default();
        for v in (0..image.height()).step_by(stride as usize) {
            for u in (0..image.width()).step_by(stride as usize) {
                if let Some(z) = image.get(u, v) {
                    let p = k.unproject(u as f64, v as f64, z);
                    cloud.points.push(camera.pose * p);
                    cloud.pixels.push(v * image.width() + u);
                }
            }
        }
        cloud
    }

    /// Back-projects the pixels of a rectangle `[u0, u1) × [v0, v1)`.
    pub fn from_region(image: &DepthImage, camera: &Camera, region: [u32; 4]) -> Self {
        let [u0, v0, u1, v1] = region;
        let k = &camera.intrinsics;
        let mut cloud = PointCloud::default();
        for v in v0..v1.min(image.height()) {
            for u in u0..u1.min(image.width()) {
                if let Some(z) = image.get(u, v) {
                    cloud
                        .points
                        .push(camera.pose * k.unproject(u as f64, v as f64, z));
                    cloud.pixels.push(v * image.width() + u);
                }
            }
        }
        cloud
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The points at `indices`, as a new cloud.
    pub fn select(&self, indices: &[usize]) -> Self {
        PointCloud {
            points: indices.iter().map(|&i| self.points[i]).collect(),
            pixels: indices.iter().map(|&i| self.pixels[i]).collect(),
        }
    }
}

/// Centroid and principal axes of a point set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moments {
    /// Mean of the points.
    pub centroid: Point3<f64>,
    /// Unit principal axes as columns, by decreasing variance, right-handed.
    pub axes: Matrix3<f64>,
    /// Variances along the axes, decreasing.
    pub variances: Vector3<f64>,
}

impl Moments {
    /// Moments of a point set (`None` for fewer than 3 points or non-finite values).
    pub fn of(points: &[Point3<f64>]) -> Option<Self> {
        Self::weighted(points.iter().map(|p| (*p, 1.0)))
    }

    /// Moments of weighted points.
    pub fn weighted(points: impl Iterator<Item = (Point3<f64>, f64)> + Clone) -> Option<Self> {
        let (mut sum, mut wsum, mut n) = (Vector3::zeros(), 0.0, 0usize);
        for (p, w) in points.clone() {
            sum += p.coords * w;
            wsum += w;
            n += 1;
        }
        if n < 3 || wsum <= 0.0 {
            return None;
        }
        let c = sum / wsum;
        let mut cov = Matrix3::zeros();
        for (p, w) in points {
            let d = p.coords - c;
            cov += d * d.transpose() * w;
        }
        cov /= wsum;
        Self::from_covariance(Point3::from(c), &cov)
    }

    /// Moments from a centroid and a covariance matrix (`None` if not finite).
    pub fn from_covariance(centroid: Point3<f64>, cov: &Matrix3<f64>) -> Option<Self> {
        if !cov.iter().all(|v| v.is_finite()) {
            return None;
        }
        let eig = SymmetricEigen::new(*cov);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
        let mut axes = Matrix3::from_columns(&[
            eig.eigenvectors.column(order[0]).into_owned(),
            eig.eigenvectors.column(order[1]).into_owned(),
            eig.eigenvectors.column(order[2]).into_owned(),
        ]);
        if axes.determinant() < 0.0 {
            axes.set_column(2, &(-axes.column(2)));
        }
        Some(Moments {
            centroid,
            axes,
            variances: Vector3::new(
                eig.eigenvalues[order[0]],
                eig.eigenvalues[order[1]],
                eig.eigenvalues[order[2]],
            ),
        })
    }

    /// Exact area-weighted moments of a triangle surface:
    /// `∫x dA = A(a+b+c)/3` and `∫x xᵀ dA = A/12 (aaᵀ + bbᵀ + ccᵀ + ssᵀ)`, `s = a+b+c`.
    pub fn of_surface(triangles: impl Iterator<Item = [Point3<f64>; 3]>) -> Option<Self> {
        let (mut area, mut first, mut second) = (0.0, Vector3::zeros(), Matrix3::zeros());
        for [a, b, c] in triangles {
            let w = (b - a).cross(&(c - a)).norm() * 0.5;
            let s = a.coords + b.coords + c.coords;
            area += w;
            first += s * (w / 3.0);
            second += (a.coords * a.coords.transpose()
                + b.coords * b.coords.transpose()
                + c.coords * c.coords.transpose()
                + s * s.transpose())
                * (w / 12.0);
        }
        if area.is_nan() || area <= 0.0 {
            return None;
        }
        let c = first / area;
        Self::from_covariance(Point3::from(c), &(second / area - c * c.transpose()))
    }
}
