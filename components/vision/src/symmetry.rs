//! Symmetries of an object model, pose errors modulo symmetry, and a canonical
//! representative of a symmetric pose.
//!
//! What: [`Symmetry`] is the set of object-frame motions that map the model's
//! surface onto itself: an optional continuous rotation axis (a can, a
//! bottle) and a finite group of discrete motions (the 180° turns of a box,
//! the top-bottom flip of a plain cylinder).
//!
//! Why: a depth image cannot tell a can's rotation about its own axis, nor
//! which of a box's equal faces is which. The detector reports one pose of
//! the equivalence class and says which motions leave it unchanged; accuracy
//! is measured modulo them.
//!
//! How: candidate axes are the model's principal axes through its centroid.
//! A candidate motion is accepted when every transformed surface sample lies
//! within a tolerance of the model's surface (parry's point projection on the
//! mesh). The discrete set is closed under composition. Errors take the best
//! group element; for a continuous axis the best angle is closed-form
//! (maximising the trace of the residual rotation).
//!
//! ```
//! use nalgebra::{Isometry3, Point3, Unit, Vector3};
//! use tsukami_vision::symmetry::Symmetry;
//! let can = Symmetry {
//!     axis: Some((Point3::origin(), Vector3::z_axis())),
//!     discrete: vec![Isometry3::identity()],
//! };
//! let truth = Isometry3::new(Vector3::new(0.5, 0.0, 0.8), Vector3::zeros());
//! let spun = truth * Isometry3::rotation(Vector3::new(0.0, 0.0, 1.1));
//! let (dp, da) = can.pose_error(&spun, &truth);
//! assert!(dp < 1e-12 && da < 1e-9);
//! ```

use nalgebra::{Isometry3, Matrix3, Point3, Translation3, Unit, UnitQuaternion, Vector3};

/// The self-motions of a model (object frame).
#[derive(Debug, Clone, PartialEq)]
pub struct Symmetry {
    /// A continuous rotation axis: a point on it and its direction.
    pub axis: Option<(Point3<f64>, Unit<Vector3<f64>>)>,
    /// The discrete motions, identity first (just the identity when there are none).
    pub discrete: Vec<Isometry3<f64>>,
}

impl Default for Symmetry {
    fn default() -> Self {
        Symmetry {
            axis: None,
            discrete: vec![Isometry3::identity()],
        }
    }
}

/// Rotation by `angle` about the axis through `point` along `dir`.
pub fn rotation_about(point: &Point3<f64>, dir: &Unit<Vector3<f64>>, angle: f64) -> Isometry3<f64> {
    let r = UnitQuaternion::from_axis_angle(dir, angle);
    let t = point.coords - r * point.coords;
    Isometry3::from_parts(Translation3::from(t), r)
}

impl Symmetry {
    /// True when the model has no symmetry.
    pub fn is_none(&self) -> bool {
        self.axis.is_none() && self.discrete.len() <= 1
    }

    /// Finds the symmetries of a surface: `on_surface(motion)` must say whether
    /// the model's surface mapped by `motion` stays on the surface. Candidate
    /// axes are `axes` (unit columns) through `centre`.
    pub fn detect(
        centre: &Point3<f64>,
        axes: &Matrix3<f64>,
        on_surface: impl Fn(&Isometry3<f64>) -> bool,
    ) -> Self {
        let dirs: Vec<Unit<Vector3<f64>>> = (0..3)
            .map(|i| Unit::new_normalize(axes.column(i).into_owned()))
            .collect();
        let continuous = dirs.iter().position(|d| {
            [0.41, 1.37, 2.29]
                .iter()
                .all(|&a| on_surface(&rotation_about(centre, d, a)))
        });
        let mut generators = Vec::new();
        match continuous {
            Some(i) => {
                // Any half turn about a perpendicular axis: the rest follow by
                // the continuous rotation.
                let flip = rotation_about(centre, &dirs[(i + 1) % 3], std::f64::consts::PI);
                if on_surface(&flip) {
                    generators.push(flip);
                }
            }
            None => {
                for d in &dirs {
                    for n in [4u32, 3, 2] {
                        let g = rotation_about(centre, d, 2.0 * std::f64::consts::PI / n as f64);
                        if on_surface(&g) {
                            generators.push(g);
                            break;
                        }
                    }
                }
            }
        }
        Symmetry {
            axis: continuous.map(|i| (*centre, dirs[i])),
            discrete: close_group(&generators),
        }
    }

    /// Position error (m, of the object frame's origin) and orientation error
    /// (rad) between an estimate and the truth, minimised over the symmetry.
    pub fn pose_error(&self, estimate: &Isometry3<f64>, truth: &Isometry3<f64>) -> (f64, f64) {
        let mut best = (f64::INFINITY, f64::INFINITY);
        for g in &self.discrete {
            let mut t = truth * g;
            if let Some((c, a)) = &self.axis {
                let m = (estimate.rotation.inverse() * t.rotation).to_rotation_matrix();
                let theta = best_trace_angle(m.matrix(), a);
                t *= rotation_about(c, a, theta);
            }
            let angle = estimate.rotation.angle_to(&t.rotation);
            let dist = (estimate.translation.vector - t.translation.vector).norm();
            if angle < best.1 - 1e-12 || (angle <= best.1 + 1e-12 && dist < best.0) {
                best = (dist, angle);
            }
        }
        best
    }

    /// The representative of `pose`'s class that a client sees: the discrete
    /// element whose object z axis points most upward (base +z), then, about a
    /// continuous axis, the angle whose object x axis points most along
    /// `preferred_x` (a base-frame direction).
    pub fn canonical(&self, pose: &Isometry3<f64>, preferred_x: &Vector3<f64>) -> Isometry3<f64> {
        let score = |p: &Isometry3<f64>| {
            let z = p.rotation * Vector3::z();
            let x = p.rotation * Vector3::x();
            (z.z * 1e3).round() * 1e3 + x.dot(preferred_x)
        };
        let mut best = *pose;
        let mut best_score = f64::NEG_INFINITY;
        for g in &self.discrete {
            let p = pose * g;
            let s = score(&p);
            if s > best_score + 1e-9 {
                best = p;
                best_score = s;
            }
        }
        if let Some((c, a)) = &self.axis {
            // Maximise preferred·R·Rot_a(θ)·x over θ (Rodrigues' formula).
            let w = best.rotation.inverse() * preferred_x;
            let x = Vector3::x();
            let ax = a.cross(&x);
            let cos_term = w.dot(&x) - w.dot(a) * a.dot(&x);
            let theta = w.dot(&ax).atan2(cos_term);
            if cos_term.abs() + w.dot(&ax).abs() > 1e-9 {
                best *= rotation_about(c, a, theta);
            }
        }
        best
    }
}

/// The angle θ maximising `trace(M · Rot_a(θ))`.
fn best_trace_angle(m: &Matrix3<f64>, a: &Unit<Vector3<f64>>) -> f64 {
    let k = a.cross_matrix();
    let k2 = k * k;
    // trace(M R) = trace(M) + sinθ·trace(MK) + (1 − cosθ)·trace(MK²)
    let (s, c) = ((m * k).trace(), (m * k2).trace());
    let theta = (-s).atan2(c) + std::f64::consts::PI;
    let f = |t: f64| s * t.sin() - c * t.cos();
    let alt = theta + std::f64::consts::PI;
    if f(alt) > f(theta) {
        alt
    } else {
        theta
    }
}

/// The group generated by `generators` (with the identity), up to 24 elements.
fn close_group(generators: &[Isometry3<f64>]) -> Vec<Isometry3<f64>> {
    let same = |a: &Isometry3<f64>, b: &Isometry3<f64>| {
        a.rotation.angle_to(&b.rotation) < 1e-6
            && (a.translation.vector - b.translation.vector).norm() < 1e-7
    };
    let mut group = vec![Isometry3::identity()];
    let mut i = 0;
    while i < group.len() && group.len() < 24 {
        for g in generators {
            let p = group[i] * g;
            if !group.iter().any(|q| same(q, &p)) {
                group.push(p);
            }
        }
        i += 1;
    }
    group
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    #[test]
    fn best_angle_undoes_a_spin() {
        let a = Vector3::z_axis();
        for spin in [0.3, -2.0, 3.0] {
            let m = Rotation3::from_axis_angle(&a, spin);
            let t = best_trace_angle(m.matrix(), &a);
            let r = m * Rotation3::from_axis_angle(&a, t);
            assert!(r.angle() < 1e-9, "spin {spin}: left {}", r.angle());
        }
    }

    #[test]
    fn box_group_has_four_elements() {
        let c = Point3::new(0.0, 0.0, 0.08);
        let gens: Vec<_> = [Vector3::x_axis(), Vector3::y_axis(), Vector3::z_axis()]
            .iter()
            .map(|d| rotation_about(&c, d, std::f64::consts::PI))
            .collect();
        assert_eq!(close_group(&gens).len(), 4);
        let sym = Symmetry {
            axis: None,
            discrete: close_group(&gens),
        };
        let truth = Isometry3::new(Vector3::new(0.4, -0.2, 0.8), Vector3::new(0.0, 0.0, 0.7));
        let flipped = truth * sym.discrete[1];
        let (dp, da) = sym.pose_error(&flipped, &truth);
        assert!(dp < 1e-12 && da < 1e-9);
        // The canonical pose of an upside-down box is upright.
        let up = sym.canonical(
            &(truth * rotation_about(&c, &Vector3::x_axis(), std::f64::consts::PI)),
            &Vector3::x(),
        );
        assert!((up.rotation * Vector3::z()).z > 0.999);
    }
}
