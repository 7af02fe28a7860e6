//! Conversions between the nalgebra types of this crate's API and the glam
//! types (`glamx`) that parry3d 0.31 uses internally.
//!
//! The public API of `tsukami-body` speaks nalgebra only; these helpers are the
//! one place where the two meet, so a parry upgrade touches one file.

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Rot3, Vector};

/// nalgebra isometry -> parry pose.
#[inline]
pub fn to_pose(iso: &Isometry3<f64>) -> Pose {
    let q = iso.rotation.quaternion();
    let t = &iso.translation.vector;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rot3::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

/// parry pose -> nalgebra isometry.
#[inline]
pub fn from_pose(pose: &Pose) -> Isometry3<f64> {
    let r = pose.rotation;
    let t = pose.translation;
    Isometry3::from_parts(
        Translation3::new(t.x, t.y, t.z),
        UnitQuaternion::new_unchecked(Quaternion::new(r.w, r.x, r.y, r.z)),
    )
}

/// nalgebra point -> parry vector.
#[inline]
pub fn to_vec(p: &Point3<f64>) -> Vector {
    Vector::new(p.x, p.y, p.z)
}

/// nalgebra vector -> parry vector.
#[inline]
pub fn vec_to_parry(v: &Vector3<f64>) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// parry vector -> nalgebra point.
#[inline]
pub fn to_point(v: Vector) -> Point3<f64> {
    Point3::new(v.x, v.y, v.z)
}

/// parry vector -> nalgebra vector.
#[inline]
pub fn to_vector(v: Vector) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_round_trip() {
        let iso = Isometry3::new(Vector3::new(0.1, -0.2, 0.3), Vector3::new(0.4, 0.5, -0.6));
        let back = from_pose(&to_pose(&iso));
        assert!((back.translation.vector - iso.translation.vector).norm() < 1e-15);
        assert!(back.rotation.angle_to(&iso.rotation) < 1e-12);
        // Same action on a point.
        let p = Point3::new(0.7, -0.1, 0.25);
        let a = iso * p;
        let b = to_pose(&iso) * to_vec(&p);
        assert!((a - to_point(b)).norm() < 1e-14);
    }
}
