//! Value checks every request passes before any state changes.
//!
//! What: [`Limits`] — the workspace radius, the friction range, the mass range
//! and the centre-of-mass margin — and the checks built on them: [`pose`]
//! (finite, inside the workspace, a quaternion that normalises), [`friction`],
//! [`mass`], [`center_of_mass`] and [`hold_request`].
//!
//! Why: a position of 1e308 m, a centre of mass 10 m outside the object or a
//! friction of 50 used to be accepted and broke every later plan (or put NaN in
//! a reply). One set of rules, in the kit, holds for every planner.
//!
//! How: every check returns a [`KitError::InvalidValue`] naming the field. The
//! limits come from the plugin config (`workspace_m`, `com_margin_m`); their
//! defaults are documented in `docs/protocol.md`.
//!
//! ```
//! use tsukami_planner_kit::validate::{pose, Limits};
//! use tsukami_msgs::planner::pose_at;
//! let limits = Limits::default();
//! assert!(pose(&pose_at([0.5, 0.0, 1.0]), "pose", &limits).is_ok());
//! let far = pose(&pose_at([1e308, 0.0, 0.0]), "pose", &limits).unwrap_err();
//! assert!(far.to_string().contains("pose.position"));
//! ```

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;
use tsukami_msgs::Pose;

use crate::KitError;

/// The limits values are checked against (plugin config keys in brackets).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Limits {
    /// Largest distance of any position from the world origin, m (`workspace_m`, 100).
    pub workspace_m: f64,
    /// How far the centre of mass may lie outside the object's bounding box, m
    /// (`com_margin_m`, 0.01).
    pub com_margin_m: f64,
    /// Largest friction coefficient accepted (`max_friction`, 2); the smallest is > 0.
    pub max_friction: f64,
    /// Largest object mass accepted, kg (`max_mass_kg`, 1000).
    pub max_mass_kg: f64,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            workspace_m: 100.0,
            com_margin_m: 0.01,
            max_friction: 2.0,
            max_mass_kg: 1000.0,
        }
    }
}

impl Limits {
    /// Checks the limits themselves (from a config file).
    pub fn check(&self) -> Result<(), String> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if ok(self.workspace_m)
            && ok(self.max_friction)
            && ok(self.max_mass_kg)
            && self.com_margin_m.is_finite()
            && self.com_margin_m >= 0.0
        {
            Ok(())
        } else {
            Err("limits must be finite and positive".into())
        }
    }
}

/// A position: finite and within the workspace.
pub fn position(p: &[f64; 3], field: &str, limits: &Limits) -> Result<Vector3<f64>, KitError> {
    let v = Vector3::from(*p);
    if !v.iter().all(|x| x.is_finite()) {
        return Err(KitError::invalid(field, "must be finite numbers"));
    }
    if v.norm() > limits.workspace_m {
        return Err(KitError::invalid(
            field,
            format!(
                "is {:.3e} m from the origin; the workspace is {} m",
                v.norm(),
                limits.workspace_m
            ),
        ));
    }
    Ok(v)
}

/// A quaternion `[x, y, z, w]` that can be normalised (finite, norm in [0.5, 2]).
pub fn quaternion(q: &[f64; 4], field: &str) -> Result<UnitQuaternion<f64>, KitError> {
    let norm2: f64 = q.iter().map(|v| v * v).sum();
    if !q.iter().all(|v| v.is_finite()) || !(0.25..=4.0).contains(&norm2) {
        return Err(KitError::invalid(
            field,
            "must be finite with a norm between 0.5 and 2 (it is normalised)",
        ));
    }
    Ok(UnitQuaternion::from_quaternion(Quaternion::new(
        q[3], q[0], q[1], q[2],
    )))
}

/// A message pose as an isometry; errors name `field.position` or `field.quaternion`.
pub fn pose(p: &Pose, field: &str, limits: &Limits) -> Result<Isometry3<f64>, KitError> {
    let t = position(&p.position, &format!("{field}.position"), limits)?;
    let r = quaternion(&p.quaternion, &format!("{field}.quaternion"))?;
    Ok(Isometry3::from_parts(Translation3::from(t), r))
}

/// An isometry as a message pose.
pub fn to_pose(iso: &Isometry3<f64>) -> Pose {
    let q = iso.rotation;
    Pose {
        position: [iso.translation.x, iso.translation.y, iso.translation.z],
        quaternion: [q.i, q.j, q.k, q.w],
    }
}

/// A friction coefficient in (0, `max_friction`].
pub fn friction(mu: f64, field: &str, limits: &Limits) -> Result<f64, KitError> {
    if mu.is_finite() && mu > 0.0 && mu <= limits.max_friction {
        Ok(mu)
    } else {
        Err(KitError::invalid(
            field,
            format!("{mu} is outside (0, {}]", limits.max_friction),
        ))
    }
}

/// A mass in (0, `max_mass_kg`] kg.
pub fn mass(m: f64, field: &str, limits: &Limits) -> Result<f64, KitError> {
    if m.is_finite() && m > 0.0 && m <= limits.max_mass_kg {
        Ok(m)
    } else {
        Err(KitError::invalid(
            field,
            format!("{m} kg is outside (0, {}] kg", limits.max_mass_kg),
        ))
    }
}

/// A centre of mass (mesh frame) inside the box `[lo, hi]` grown by the margin.
pub fn center_of_mass(
    c: &[f64; 3],
    lo: &Point3<f64>,
    hi: &Point3<f64>,
    field: &str,
    limits: &Limits,
) -> Result<Point3<f64>, KitError> {
    let p = Point3::from(*c);
    if !p.iter().all(|x| x.is_finite()) {
        return Err(KitError::invalid(field, "must be finite numbers"));
    }
    let m = limits.com_margin_m;
    if (0..3).any(|k| p[k] < lo[k] - m || p[k] > hi[k] + m) {
        return Err(KitError::invalid(
            field,
            format!(
                "[{:.4}, {:.4}, {:.4}] lies outside the object's bounds \
                 [{:.4}, {:.4}, {:.4}]..[{:.4}, {:.4}, {:.4}] (mesh frame) plus {m} m",
                p.x, p.y, p.z, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
            ),
        ));
    }
    Ok(p)
}

/// A scale factor: finite and > 0.
pub fn scale(s: f64, field: &str) -> Result<f64, KitError> {
    if s.is_finite() && s > 0.0 && s <= 1e3 {
        Ok(s)
    } else {
        Err(KitError::invalid(
            field,
            format!("{s} must be in (0, 1000]"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternions_are_normalised_or_refused() {
        let q = quaternion(&[0.0, 0.0, 0.0, 1.2], "q").unwrap();
        assert!((q.w - 1.0).abs() < 1e-12);
        assert!(quaternion(&[0.0; 4], "q").is_err());
        assert!(quaternion(&[f64::NAN, 0.0, 0.0, 1.0], "q").is_err());
    }

    #[test]
    fn values_out_of_range_name_the_field() {
        let l = Limits::default();
        assert_eq!(friction(0.5, "friction", &l), Ok(0.5));
        let e = friction(5.0, "friction", &l).unwrap_err();
        assert_eq!(e.code(), tsukami_msgs::ErrorCode::InvalidValue);
        assert!(mass(0.0, "mass", &l).is_err());
        let (lo, hi) = (Point3::new(-0.1, -0.1, 0.0), Point3::new(0.1, 0.1, 0.2));
        assert!(center_of_mass(&[0.0, 0.0, 0.1], &lo, &hi, "com", &l).is_ok());
        let e = center_of_mass(&[10.0, 0.0, 0.1], &lo, &hi, "com", &l).unwrap_err();
        assert!(e.to_string().contains("outside"), "{e}");
    }
}

/// A plan's hold request (`PlanOptions::hold`): every share and distance in
/// its documented range.
pub fn hold_request(h: &tsukami_msgs::planner::HoldRequest) -> Result<(), KitError> {
    let ranged = |v: f64, field: &str, lo: f64, hi: f64, lo_open: bool| {
        let above = if lo_open { v > lo } else { v >= lo };
        match v.is_finite() && above && v <= hi {
            true => Ok(()),
            false => Err(KitError::invalid(
                format!("hold.{field}"),
                format!(
                    "{v} is outside {}{lo}, {hi}]",
                    if lo_open { "(" } else { "[" }
                ),
            )),
        }
    };
    ranged(h.com_error, "com_error", 0.0, 0.2, false)?;
    ranged(h.friction_reserve, "friction_reserve", 0.0, 0.9, false)?;
    ranged(h.squeeze_share, "squeeze_share", 0.0, 1.0, true)?;
    if let Some(t) = h.max_turn_deg {
        ranged(t, "max_turn_deg", 0.0, 90.0, true)?;
    }
    if let Some(s) = h.max_shift_mm {
        ranged(s, "max_shift_mm", 0.0, 100.0, true)?;
    }
    ranged(h.preferred_margin, "preferred_margin", 1.0, 100.0, false)?;
    let e = &h.pose_error;
    ranged(e.position, "pose_error.position", 0.0, 0.05, false)?;
    ranged(e.rotation_deg, "pose_error.rotation_deg", 0.0, 30.0, false)?;
    match e.samples {
        0..=64 => Ok(()),
        n => Err(KitError::invalid(
            "hold.pose_error.samples",
            format!("{n} is outside [0, 64]"),
        )),
    }
}
