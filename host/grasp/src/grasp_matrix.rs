//! Wrenches and the grasp matrix `G` (paper, eq. (6)).
//!
//! A contact force `f_i` applied at `p_i` exerts on the object the wrench
//!
//! ```text
//! w_i = [ f_i ; γ (p_i − r) × f_i ] = G_i f_i,      G_i = [ I ; γ [p_i − r]× ]      (eq. (6))
//! ```
//!
//! where `r` is the reference point torques are taken about and `γ` the torque
//! scale. The paper takes moments about the origin; this crate takes them about
//! a chosen reference point, normally the object's **centre of mass**: then the
//! object's weight is a pure force (no torque term), and `γ`-scaled torques stay
//! of the order of forces whatever the object's position in the world. Changing
//! `r` or `γ` maps every wrench by the same invertible linear transform, so the
//! force-closure decisions of every method here do not depend on them; only the
//! Ferrari–Canny ε, which measures a Euclidean distance in wrench space, does.
//!
//! `γ = 1 / characteristic_length` (1/m), so `γ (p × f)` is in newtons like the
//! force part: the torque a force makes at one characteristic length counts as
//! much as the force itself. Use a length of the order of the object's radius.
//!
//! `G = [G_1 … G_n]` is 6×3n; methods that need speed never build it and sum
//! the 6×6 or 6×1 contributions of each `G_i` instead.

use nalgebra::{Dyn, Matrix3, Matrix6x3, OMatrix, Point3, Vector3, Vector6, U6};

use crate::contact::Contact;

/// A wrench `[force; γ·torque]`, both parts in newtons.
pub type Wrench = Vector6<f64>;

/// The skew-symmetric matrix `[v]×` with `[v]× x = v × x`.
#[inline]
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// `γ [p − r]×`: the map from a force at `p` to its scaled torque about `r`.
#[inline]
pub fn torque_map(point: &Point3<f64>, reference: &Point3<f64>, torque_scale: f64) -> Matrix3<f64> {
    skew(&((point - reference) * torque_scale))
}

/// The wrench of force `force` applied at `point`, torque about `reference`
/// scaled by `torque_scale` (eq. (6)).
#[inline]
pub fn wrench(
    force: &Vector3<f64>,
    point: &Point3<f64>,
    reference: &Point3<f64>,
    torque_scale: f64,
) -> Wrench {
    let torque = (point - reference).cross(force) * torque_scale;
    Wrench::new(force.x, force.y, force.z, torque.x, torque.y, torque.z)
}

/// `G_i = [I; γ [p_i − r]×]`, the 6×3 block of contact `i` (world-frame force in).
#[inline]
pub fn contact_block(
    contact: &Contact,
    reference: &Point3<f64>,
    torque_scale: f64,
) -> Matrix6x3<f64> {
    let mut g = Matrix6x3::zeros();
    g.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&Matrix3::identity());
    g.fixed_view_mut::<3, 3>(3, 0).copy_from(&torque_map(
        contact.position(),
        reference,
        torque_scale,
    ));
    g
}

/// The full grasp matrix `G = [G_1 … G_n]` (6×3n, world-frame forces).
pub fn grasp_matrix(
    contacts: &[Contact],
    reference: &Point3<f64>,
    torque_scale: f64,
) -> OMatrix<f64, U6, Dyn> {
    let mut g = OMatrix::<f64, U6, Dyn>::zeros(3 * contacts.len());
    for (i, c) in contacts.iter().enumerate() {
        g.fixed_view_mut::<6, 3>(0, 3 * i)
            .copy_from(&contact_block(c, reference, torque_scale));
    }
    g
}

/// The wrench of the object's weight `mass · gravity` acting at `center_of_mass`,
/// torque about `reference` (zero torque when the reference is the centre of mass).
pub fn weight_wrench(
    mass: f64,
    gravity: &Vector3<f64>,
    center_of_mass: &Point3<f64>,
    reference: &Point3<f64>,
    torque_scale: f64,
) -> Wrench {
    wrench(&(gravity * mass), center_of_mass, reference, torque_scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_times_force_is_the_wrench() {
        let c = Contact::new(Point3::new(0.1, -0.2, 0.3), Vector3::new(0.0, 0.6, 0.8)).unwrap();
        let r = Point3::new(0.01, 0.02, 0.03);
        let f = Vector3::new(1.0, 2.0, -0.5);
        let g = contact_block(&c, &r, 16.0);
        assert!((g * f - wrench(&f, c.position(), &r, 16.0)).norm() < 1e-12);
        let big = grasp_matrix(&[c, c], &r, 16.0);
        assert_eq!(big.ncols(), 6);
        assert!((big.fixed_view::<6, 3>(0, 3) - g).norm() == 0.0);
    }

    #[test]
    fn weight_about_the_centre_of_mass_is_a_pure_force() {
        let com = Point3::new(0.3, 0.1, 0.9);
        let w = weight_wrench(0.5, &Vector3::new(0.0, 0.0, -9.81), &com, &com, 10.0);
        assert_eq!(w, Wrench::new(0.0, 0.0, -4.905, 0.0, 0.0, 0.0));
        let w2 = weight_wrench(
            0.5,
            &Vector3::new(0.0, 0.0, -9.81),
            &com,
            &Point3::origin(),
            10.0,
        );
        assert!((w2[3] - 10.0 * 0.1 * -4.905).abs() < 1e-12);
    }
}
