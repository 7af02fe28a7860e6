//! Initial poses of a model standing on the supporting plane under a cluster.
//!
//! What: [`on_plane`] lists candidate poses that put one of the model's
//! principal axes (either sign) along the plane's normal, turn it about the
//! normal so that a horizontal model axis follows the cluster's horizontal
//! principal direction (four quarter turns), centre the camera-facing samples
//! on the cluster's centroid across the plane, and set the model down on it.
//!
//! Why: the principal axes of a partly hidden cluster ([`crate::hypotheses`])
//! tilt with whatever part of the object is missing, and a coarse ICP does not
//! always recover tens of degrees of tilt from a half-seen object. An object on
//! a table rests on a face or a side: its up axis is one of a few, known from
//! the plane, and only the turn about the normal and the position on the plane
//! are left to the cluster — which a partial view still gives well enough.
//!
//! How: for model axis `mᵢ` (sign `s`) up and model axis `mⱼ` along the
//! cluster's horizontal direction `h` turned by `k·90°`, `R` maps
//! (`s mᵢ`, `mⱼ`, `s mᵢ × mⱼ`) to (`n`, `h'`, `n × h'`); rotations equivalent
//! under the model's symmetry are dropped; the height makes the lowest model
//! vertex touch the plane.
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_vision::resting::horizontal_direction;
//! let pts: Vec<Point3<f64>> = (0..20).map(|i| Point3::new(0.01 * i as f64, 0.001 * (i % 2) as f64, 0.8)).collect();
//! let h = horizontal_direction(&pts, &Vector3::z());
//! assert!(h.x.abs() > 0.99);
//! ```

use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, UnitQuaternion, Vector3};

use crate::hypotheses::{place, push_distinct};
use crate::plane::{in_plane_axes, Plane};
use crate::template::ObjectTemplate;

/// The principal direction of `points` projected on the plane of normal `n`
/// (unit, horizontal; any horizontal direction for fewer than 2 points).
pub fn horizontal_direction(points: &[Point3<f64>], n: &Vector3<f64>) -> Vector3<f64> {
    let n = n.normalize();
    let (e1, e2) = in_plane_axes(&n);
    if points.len() < 2 {
        return e1;
    }
    let count = points.len() as f64;
    let mean = points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / count;
    let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
    for p in points {
        let d = p.coords - mean;
        let (x, y) = (d.dot(&e1), d.dot(&e2));
        a += x * x;
        b += x * y;
        c += y * y;
    }
    // Angle of the major axis of the 2-D covariance [[a, b], [b, c]].
    let theta = 0.5 * (2.0 * b).atan2(a - c);
    e1 * theta.cos() + e2 * theta.sin()
}

/// Candidate poses (object → base) of `template` resting on `plane` under the
/// cluster `points`, seen from `camera` (base frame).
pub fn on_plane(
    template: &ObjectTemplate,
    points: &[Point3<f64>],
    plane: &Plane,
    camera: &Point3<f64>,
) -> Vec<Isometry3<f64>> {
    let Some(centroid) = mean(points) else {
        return Vec::new();
    };
    let n = plane.normal.into_inner();
    let h = horizontal_direction(points, &n);
    let axes = template.moments.axes;
    let mut rotations: Vec<UnitQuaternion<f64>> = Vec::new();
    for i in 0..3 {
        for s in [1.0, -1.0] {
            let up = axes.column(i) * s;
            for j in (0..3).filter(|&j| j != i) {
                let side = axes.column(j).into_owned();
                for k in 0..4 {
                    let angle = k as f64 * std::f64::consts::FRAC_PI_2;
                    let hk = UnitQuaternion::from_scaled_axis(n * angle) * h;
                    let model = Matrix3::from_columns(&[up, side, up.cross(&side)]);
                    let world = Matrix3::from_columns(&[n, hk, n.cross(&hk)]);
                    let r = Rotation3::from_matrix_unchecked(world * model.transpose());
                    push_distinct(
                        template,
                        &mut rotations,
                        UnitQuaternion::from_rotation_matrix(&r),
                    );
                }
            }
        }
    }
    rotations
        .into_iter()
        .map(|q| set_down(template, place(template, q, &centroid, camera), plane))
        .collect()
}

fn mean(points: &[Point3<f64>]) -> Option<Point3<f64>> {
    (!points.is_empty()).then(|| {
        Point3::from(
            points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / points.len() as f64,
        )
    })
}

/// `pose` moved along the plane's normal so that its lowest vertex touches the plane.
fn set_down(template: &ObjectTemplate, mut pose: Isometry3<f64>, plane: &Plane) -> Isometry3<f64> {
    let lowest = template
        .model
        .mesh
        .vertices
        .iter()
        .map(|v| plane.distance(&(pose * v)))
        .fold(f64::INFINITY, f64::min);
    if lowest.is_finite() {
        pose.translation.vector -= plane.normal.into_inner() * lowest;
    }
    pose
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, Unit};
    use tsukami_body::model::Geometry;
    use tsukami_body::object::ObjectModel;

    #[test]
    fn a_hypothesis_matches_a_box_lying_on_its_side() {
        let geometry = Geometry::Box {
            size: Vector3::new(0.06, 0.1, 0.16),
        };
        let model = ObjectModel::new(
            "box".into(),
            String::new(),
            "box.obj".as_ref(),
            geometry,
            0.2,
            0.5,
        )
        .unwrap();
        let t = ObjectTemplate::from_model("box", model, 0.004).unwrap();
        // On its side (object x up), turned 0.3 rad about the table's normal.
        let rotation = UnitQuaternion::from_scaled_axis(Vector3::z() * 0.3)
            * UnitQuaternion::from_scaled_axis(Vector3::y() * -std::f64::consts::FRAC_PI_2);
        let truth = Isometry3::from_parts(Translation3::new(0.5, 0.1, 0.83), rotation);
        let camera = Point3::new(0.0, 0.0, 1.3);
        let cam_obj = truth.inverse() * camera;
        let seen: Vec<Point3<f64>> = t
            .points
            .iter()
            .zip(&t.normals)
            .filter(|(p, n)| n.dot(&(cam_obj - *p)) > 0.0)
            .map(|(p, _)| truth * p)
            .collect();
        let plane = Plane {
            normal: Unit::new_normalize(Vector3::z()),
            offset: 0.8,
        };
        let hypotheses = on_plane(&t, &seen, &plane, &camera);
        assert!(hypotheses.len() <= 24, "{}", hypotheses.len());
        // The nearest start is within ICP's reach (the visible side faces pull
        // the horizontal direction a few degrees), and ICP from it lands on the truth.
        let (start, err) = hypotheses
            .iter()
            .map(|h| (h, t.symmetry.pose_error(h, &truth)))
            .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
            .unwrap();
        assert!(err.1.to_degrees() < 10.0 && err.0 < 0.03, "{err:?}");
        let fit = crate::icp::refine(&t, &seen, Some(camera), *start, &Default::default());
        let (dp, da) = t.symmetry.pose_error(&fit.pose, &truth);
        assert!(dp < 1e-3 && da.to_degrees() < 0.5, "{dp} m, {da} rad");
    }
}
