//! Initial poses of a model on a cluster, from principal axes.
//!
//! What: [`from_principal_axes`] lists candidate poses that put the model's
//! principal axes on the cluster's, one per signed permutation.
//!
//! Why: ICP converges only from a pose a few tens of degrees off; the
//! principal axes of a cluster give the object's orientation up to the
//! ambiguities a partial view leaves (which axis is which, and their signs).
//!
//! How: with cluster axes `A` and model axes `M` (columns, right-handed),
//! each of the 24 proper signed permutation matrices `P` gives `R = A P Mᵀ`.
//! Rotations equivalent under the model's symmetry are dropped. The
//! translation puts the centroid of the model's camera-facing samples (what
//! the camera can see of it) on the cluster's centroid, since a partial view's
//! centroid lies on the near side of the object.
//!
//! ```
//! use tsukami_vision::hypotheses::signed_permutations;
//! assert_eq!(signed_permutations().len(), 24);
//! ```

use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

use crate::cloud::Moments;
use crate::template::ObjectTemplate;

/// The 24 signed permutation matrices with determinant +1.
pub fn signed_permutations() -> Vec<Matrix3<f64>> {
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut out = Vec::with_capacity(24);
    for p in perms {
        for signs in 0..8u32 {
            let mut m = Matrix3::zeros();
            for (row, &col) in p.iter().enumerate() {
                m[(row, col)] = if signs & (1 << row) != 0 { -1.0 } else { 1.0 };
            }
            if m.determinant() > 0.0 {
                out.push(m);
            }
        }
    }
    out
}

/// Candidate poses (object → base) of `template` on a cluster with moments
/// `cluster`, seen from `camera` (base frame).
pub fn from_principal_axes(
    template: &ObjectTemplate,
    cluster: &Moments,
    camera: &Point3<f64>,
) -> Vec<Isometry3<f64>> {
    let model = &template.moments;
    let mut rotations: Vec<UnitQuaternion<f64>> = Vec::new();
    for p in signed_permutations() {
        let r = cluster.axes * p * model.axes.transpose();
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
        push_distinct(template, &mut rotations, q);
    }
    rotations
        .into_iter()
        .map(|q| place(template, q, &cluster.centroid, camera))
        .collect()
}

/// Adds `q` to `rotations` unless one equivalent under the model's symmetry
/// (within 5°) is there already.
pub fn push_distinct(
    template: &ObjectTemplate,
    rotations: &mut Vec<UnitQuaternion<f64>>,
    q: UnitQuaternion<f64>,
) {
    let probe = Isometry3::from_parts(Translation3::identity(), q);
    let duplicate = rotations.iter().any(|o| {
        let other = Isometry3::from_parts(Translation3::identity(), *o);
        template.symmetry.pose_error(&probe, &other).1 < 5f64.to_radians()
    });
    if !duplicate {
        rotations.push(q);
    }
}

/// The pose with rotation `q` whose camera-facing samples are centred on
/// `centroid`.
pub fn place(
    template: &ObjectTemplate,
    q: UnitQuaternion<f64>,
    centroid: &Point3<f64>,
    camera: &Point3<f64>,
) -> Isometry3<f64> {
    let mut pose = Isometry3::from_parts(
        Translation3::from(centroid.coords - q * template.moments.centroid.coords),
        q,
    );
    // Twice: which side faces the camera depends (weakly) on the position.
    for _ in 0..2 {
        let cam = pose.inverse() * camera;
        let (mut sum, mut n) = (Vector3::zeros(), 0usize);
        // Every 8th sample: a rough centroid is enough for a start.
        for (p, nrm) in template.points.iter().zip(&template.normals).step_by(8) {
            if nrm.dot(&(cam - p)) > 0.0 {
                sum += p.coords;
                n += 1;
            }
        }
        if n == 0 {
            break;
        }
        let visible = sum / n as f64;
        pose.translation = Translation3::from(centroid.coords - q * visible);
    }
    pose
}
