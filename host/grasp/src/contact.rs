//! Point contacts with friction and their local frames.
//!
//! A [`Contact`] is a point on the object's surface together with the unit
//! normal pointing **into** the object — the direction a finger pushes. Every
//! force-closure method in this crate works with the contact frame
//! `U_i = [t1 t2 n]` (paper, section 3.3.2): two unit tangents and the inward
//! normal, as the columns of a rotation matrix. A force written in that frame,
//! `f_local = U_iᵀ f`, has its normal component last, which is the layout the
//! Coulomb cone `‖(f_t1, f_t2)‖ ≤ μ f_n` wants.
//!
//! The tangents are chosen with the branch-free construction of Duff et al.
//! ("Building an orthonormal basis, revisited", JCGT 2017): continuous almost
//! everywhere and exact for the coordinate axes. Which tangent pair is chosen
//! does not matter to any method here — the friction cone and the paper's
//! ellipsoid are both symmetric about the normal.
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_grasp::contact::Contact;
//!
//! let c = Contact::new(Point3::new(0.03, 0.0, 0.0), Vector3::new(-1.0, 0.0, 0.0)).unwrap();
//! let u = c.frame();
//! assert!((u.column(2) - c.normal()).norm() < 1e-12);
//! ```

use nalgebra::{Matrix3, Point3, Unit, Vector3};

/// How far a given normal's length may be from 1 and still count as a unit vector.
///
/// Normals from meshes or JSON carry rounding; anything further off is almost
/// certainly a bug (an unnormalised vector or the wrong field) and is rejected.
pub const UNIT_NORMAL_TOLERANCE: f64 = 1e-6;

/// Why a contact could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ContactError {
    /// A coordinate of the position is NaN or infinite.
    #[error("contact position has a non-finite coordinate")]
    NonFinitePosition,
    /// A coordinate of the normal is NaN or infinite.
    #[error("contact normal has a non-finite coordinate")]
    NonFiniteNormal,
    /// The normal is not a unit vector (length given).
    #[error("contact normal has length {0}, expected a unit vector")]
    NonUnitNormal(f64),
}

/// A frictional point contact: a surface point and the inward unit normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    position: Point3<f64>,
    normal: Unit<Vector3<f64>>,
}

impl Contact {
    /// Builds a contact, checking that `normal` is a finite unit vector
    /// (within [`UNIT_NORMAL_TOLERANCE`]; it is then renormalised exactly).
    pub fn new(position: Point3<f64>, normal: Vector3<f64>) -> Result<Self, ContactError> {
        if !position.coords.iter().all(|x| x.is_finite()) {
            return Err(ContactError::NonFinitePosition);
        }
        if !normal.iter().all(|x| x.is_finite()) {
            return Err(ContactError::NonFiniteNormal);
        }
        let len = normal.norm();
        if (len - 1.0).abs() > UNIT_NORMAL_TOLERANCE {
            return Err(ContactError::NonUnitNormal(len));
        }
        Ok(Self {
            position,
            normal: Unit::new_normalize(normal),
        })
    }

    /// Builds a contact from a normal that is already a unit vector.
    pub fn from_unit(position: Point3<f64>, normal: Unit<Vector3<f64>>) -> Self {
        Self { position, normal }
    }

    /// The contact point (world frame, metres).
    pub fn position(&self) -> &Point3<f64> {
        &self.position
    }

    /// The unit normal pointing into the object.
    pub fn normal(&self) -> &Vector3<f64> {
        self.normal.as_ref()
    }

    /// Two unit tangents `(t1, t2)` such that `(t1, t2, n)` is right-handed.
    #[inline]
    pub fn tangents(&self) -> (Vector3<f64>, Vector3<f64>) {
        orthonormal_tangents(self.normal())
    }

    /// The contact frame `U_i = [t1 t2 n]` (columns), a rotation matrix taking
    /// contact-frame coordinates to world coordinates.
    #[inline]
    pub fn frame(&self) -> Matrix3<f64> {
        let (t1, t2) = self.tangents();
        Matrix3::from_columns(&[t1, t2, *self.normal()])
    }
}

/// Branch-free orthonormal tangents for a unit vector `n` (Duff et al. 2017).
#[inline]
pub fn orthonormal_tangents(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let sign = 1.0_f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t1 = Vector3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let t2 = Vector3::new(b, sign + n.y * n.y * a, -n.y);
    (t1, t2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_a_right_handed_rotation_for_many_normals() {
        let normals = [
            Vector3::x(),
            -Vector3::x(),
            Vector3::y(),
            -Vector3::y(),
            Vector3::z(),
            -Vector3::z(),
            Vector3::new(1.0, 2.0, -3.0).normalize(),
            Vector3::new(-0.3, 0.1, -1e-9).normalize(),
        ];
        for n in normals {
            let c = Contact::new(Point3::origin(), n).unwrap();
            let u = c.frame();
            assert!(
                (u.transpose() * u - Matrix3::identity()).norm() < 1e-12,
                "{n}"
            );
            assert!((u.determinant() - 1.0).abs() < 1e-12, "{n}");
            assert!((u.column(2) - n).norm() < 1e-12);
        }
    }

    #[test]
    fn rejects_bad_normals() {
        let p = Point3::origin();
        assert!(matches!(
            Contact::new(p, Vector3::new(0.0, 0.0, 0.0)),
            Err(ContactError::NonUnitNormal(_))
        ));
        assert!(matches!(
            Contact::new(p, Vector3::new(0.0, 0.0, 2.0)),
            Err(ContactError::NonUnitNormal(_))
        ));
        assert_eq!(
            Contact::new(p, Vector3::new(f64::NAN, 0.0, 1.0)),
            Err(ContactError::NonFiniteNormal)
        );
        assert_eq!(
            Contact::new(Point3::new(f64::INFINITY, 0.0, 0.0), Vector3::z()),
            Err(ContactError::NonFinitePosition)
        );
    }
}
