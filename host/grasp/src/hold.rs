//! Whether a hand holds an object: force closure, a set of disturbances, the
//! joints' torques, a friction reserve, and the squeeze that realises it.
//!
//! What: [`hold_test`] decides, for a [`Grasp`] whose contacts are pressed by
//! joints with torque limits ([`JointTorques`]), whether the grasp is in exact
//! force closure and, for **each** disturbance wrench of a set, contact forces
//! exist that balance it while every force stays inside its friction cone
//! shrunk by a reserve (`‖f_t‖ ≤ (1 − r) μ f_n`), under the description's
//! force cap, and every joint torque `τ = Σ Jᵢᵀ fᵢ` within its effort limit.
//! [`squeeze`] finds the internal forces (`G f = 0`) deepest inside the cones
//! that a share of each joint's effort can make, and their joint torques: the
//! torque a torque-controlled hand applies, or — through a servo stiffness —
//! the target beyond contact of a position-controlled one.
//! [`Disturbances::standard`] is the default set: the object's weight `m g`
//! pulling along ±x, ±y, ±z at the centre of mass, and the torques `m g e`
//! about ±x, ±y, ±z that a centre-of-mass error `e` gives.
//!
//! Why: the paper's test (eqs. (9)–(10)) and its exact version resist the
//! weight along −z only, with one force bound per finger. A grasp that rests
//! the object on two fingers below it passes and drops the object as soon as
//! the arm accelerates or tilts; fingertip contacts nearly in a line resist
//! the weight and not a small torque. The physical tests the field uses
//! (DexGraspNet, BODex/DexGraspBench) pull the object along six directions
//! with the hand's real joint torques; this is their static counterpart.
//!
//! How: one conic program per disturbance ([`crate::exact`], with the joint
//! rows of [`crate::joint_torques`]): the largest multiple `s_d` of
//! disturbance `d` the grasp can balance. The grasp holds when it is in force
//! closure and `min_d s_d ≥ 1`; `min_d s_d` is the **hold margin** (how many
//! times the worst disturbance it resists). Disturbances are tried in the
//! order given and the test stops at the first one below 1 (its index is
//! reported), so a search spends one program on most rejected samples. A
//! deciding test ([`HoldOptions::decide_up_to`], what searches use) first
//! tries each disturbance with the cheap sufficient test of
//! [`crate::superposition`] on the squeeze, and solves the program only when
//! that fails: the same verdict, one program instead of thirteen for most
//! grasps that hold. Deciding up to a scale `c` gives the hold margin
//! clipped at `c` the same way (what a planner ranking by a preferred margin
//! needs).
//!
//! ```
//! use nalgebra::{Matrix3xX, Point3, Vector3};
//! use tsukami_grasp::{contact::Contact, grasp::Grasp, joint_torques::JointTorques};
//! use tsukami_grasp::hold::{hold_test, Disturbances, HoldOptions};
//!
//! // Three fingertips at 120° around a 30 mm ball, each on its own 1-joint
//! // finger whose axis makes it press along the normal with 0.03 m lever arm.
//! let mut contacts = Vec::new();
//! let mut jac = Vec::new();
//! for i in 0..3 {
//!     let a = i as f64 * std::f64::consts::TAU / 3.0;
//!     let out = Vector3::new(a.cos(), a.sin(), 0.0);
//!     contacts.push(Contact::new(Point3::from(out * 0.03), -out).unwrap());
//!     let mut j = Matrix3xX::zeros(3);
//!     j.set_column(i, &(-out * 0.03));
//!     jac.push(j);
//! }
//! let grasp = Grasp::new(contacts, 0.8, 100.0, 0.03, Point3::origin()).unwrap();
//! let strong = JointTorques::new(jac.clone(), vec![0.6; 3]).unwrap(); // 20 N each
//! let set = Disturbances::standard(&grasp, 0.05, 9.81, &Point3::origin(), 0.02);
//! let held = hold_test(&grasp, &strong, &set, &HoldOptions::default()).unwrap();
//! assert!(held.holds() && held.margin > 1.0);
//! // Joints one hundred times weaker cannot hold the same ball.
//! let weak = JointTorques::new(jac, vec![0.006; 3]).unwrap();
//! assert!(!hold_test(&grasp, &weak, &set, &HoldOptions::default()).unwrap().holds());
//! ```

use nalgebra::{Point3, Vector3};

use crate::exact::{
    exact_force_closure_with, exact_weight_scale_with, ConeModel, ExactError, SQUEEZE_TOLERANCE,
};
use crate::grasp::Grasp;
use crate::grasp_matrix::Wrench;
use crate::joint_torques::JointTorques;
use crate::superposition::Superposition;

/// Options of the hold test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HoldOptions {
    /// Share of μ kept in reserve: forces must lie in the cone of
    /// `(1 − friction_reserve) μ` (default 0.2).
    pub friction_reserve: f64,
    /// Require exact force closure (default true).
    pub require_closure: bool,
    /// Decide up to a scale (default `None`: every scale exact). With
    /// `Some(c)`, a disturbance that the squeeze plus the least-norm forces
    /// balance at `c` times ([`crate::superposition`]) is passed without its
    /// program and its scale is reported as `c`, a lower bound: the margin is
    /// the exact one clipped at `c`, and for `c ≥ 1` the verdict `holds()` is
    /// the exact one's. Searches decide at [`DECIDE_SAFETY`].
    pub decide_up_to: Option<f64>,
}

/// The multiple of a disturbance the cheap test of a deciding hold test
/// must balance (a 1 % reserve over the solver's rounding, so that the exact
/// program agrees).
pub const DECIDE_SAFETY: f64 = 1.01;

impl Default for HoldOptions {
    fn default() -> Self {
        Self {
            friction_reserve: 0.2,
            require_closure: true,
            decide_up_to: None,
        }
    }
}

/// One disturbance: a wrench `[f; γ τ]` about the grasp's reference point.
#[derive(Debug, Clone, PartialEq)]
pub struct Disturbance {
    /// Its name (`"force -z"`, `"torque +x"`, …).
    pub name: String,
    /// The wrench the contacts must balance.
    pub wrench: Wrench,
}

/// A set of disturbances, tested in order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Disturbances(pub Vec<Disturbance>);

const AXES: [(&str, [f64; 3]); 6] = [
    ("-z", [0.0, 0.0, -1.0]),
    ("+z", [0.0, 0.0, 1.0]),
    ("+x", [1.0, 0.0, 0.0]),
    ("-x", [-1.0, 0.0, 0.0]),
    ("+y", [0.0, 1.0, 0.0]),
    ("-y", [0.0, -1.0, 0.0]),
];

impl Disturbances {
    /// The weight alone, along −z (the paper's test).
    pub fn gravity(grasp: &Grasp, mass: f64, g: f64, com: &Point3<f64>) -> Self {
        Self(vec![Disturbance {
            name: "force -z".into(),
            wrench: grasp.weight_wrench(mass, &Vector3::new(0.0, 0.0, -g), com),
        }])
    }

    /// The default set: `m g` along −z, +z, ±x, ±y at `com`, then the torques
    /// `m g com_error` about the same six axes.
    pub fn standard(grasp: &Grasp, mass: f64, g: f64, com: &Point3<f64>, com_error: f64) -> Self {
        let mut out = Vec::with_capacity(12);
        for (name, a) in AXES {
            let dir = Vector3::from(a);
            out.push(Disturbance {
                name: format!("force {name}"),
                wrench: grasp.weight_wrench(mass, &(dir * g), com),
            });
        }
        if com_error > 0.0 {
            let gamma = grasp.torque_scale();
            for (name, a) in AXES {
                let t = Vector3::from(a) * (mass * g * com_error * gamma);
                out.push(Disturbance {
                    name: format!("torque {name}"),
                    wrench: Wrench::new(0.0, 0.0, 0.0, t.x, t.y, t.z),
                });
            }
        }
        Self(out)
    }
}

/// The hold test's answer.
#[derive(Debug, Clone, PartialEq)]
pub struct HoldVerdict {
    /// Exact force closure (with the unreduced μ, no torque limits).
    pub force_closure: bool,
    /// `min_d s_d` over the disturbances tested (0 when none was).
    pub margin: f64,
    /// The first disturbance below scale 1 (the test stopped there), if any.
    pub failed: Option<usize>,
    /// The scale reached for each disturbance tested, in order.
    pub scales: Vec<f64>,
}

impl HoldVerdict {
    /// Closure (when required) and every disturbance resisted.
    pub fn holds(&self) -> bool {
        self.failed.is_none() && self.margin >= 1.0
    }
}

/// `grasp` with its friction reduced by `reserve` (0 keeps it).
fn with_reserve(grasp: &Grasp, reserve: f64) -> Option<Grasp> {
    if reserve <= 0.0 {
        return None;
    }
    Grasp::with_force_limits(
        grasp.contacts().to_vec(),
        grasp.force_limits().to_vec(),
        grasp.mu() * (1.0 - reserve.min(0.99)),
        1.0 / grasp.torque_scale(),
        *grasp.reference(),
    )
    .ok()
}

/// The hold test (module docs): closure, then each disturbance in order.
pub fn hold_test(
    grasp: &Grasp,
    joints: &JointTorques,
    set: &Disturbances,
    opts: &HoldOptions,
) -> Result<HoldVerdict, ExactError> {
    let reduced = with_reserve(grasp, opts.friction_reserve);
    let g = reduced.as_ref().unwrap_or(grasp);
    let (force_closure, fast) = closure(grasp, g, joints, opts)?;
    let mut out = HoldVerdict {
        force_closure,
        margin: 0.0,
        failed: None,
        scales: Vec::with_capacity(set.0.len()),
    };
    if !force_closure {
        return Ok(out);
    }
    out.margin = f64::INFINITY;
    for (i, d) in set.0.iter().enumerate() {
        let s = match (&fast, opts.decide_up_to) {
            (Some(f), Some(c)) if f.resists(&d.wrench, c) => c,
            _ => {
                exact_weight_scale_with(g, ConeModel::Circular, &d.wrench, Some(joints))?
                    .weight_scale
            }
        };
        out.scales.push(s);
        out.margin = out.margin.min(s);
        if s < 1.0 {
            out.failed = Some(i);
            break;
        }
    }
    if out.scales.is_empty() {
        out.margin = 0.0;
    }
    Ok(out)
}

/// The closure verdict and, for a deciding test, the cheap test built on the
/// squeeze of the reduced cones within the joints' torques. That squeeze, when
/// strictly inside (as [`exact_force_closure_with`] requires) and of rank 6,
/// is force closure of the unreduced grasp too (a smaller cone, fewer forces),
/// so the closure program is solved only when it is not.
fn closure(
    grasp: &Grasp,
    reduced: &Grasp,
    joints: &JointTorques,
    opts: &HoldOptions,
) -> Result<(bool, Option<Superposition>), ExactError> {
    let exact = |g: &Grasp| exact_force_closure_with(g, ConeModel::Circular, None);
    if opts.decide_up_to.is_none() {
        let fc = !opts.require_closure || exact(grasp)?.force_closure;
        return Ok((fc, None));
    }
    let sq = exact_force_closure_with(reduced, ConeModel::Circular, Some(joints))?;
    let f_min = grasp
        .force_limits()
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let strict = sq.grasp_rank == 6 && sq.squeeze_margin > SQUEEZE_TOLERANCE * grasp.mu() * f_min;
    let fc = !opts.require_closure || strict || exact(grasp)?.force_closure;
    let fast = (sq.squeeze_margin > 0.0)
        .then(|| Superposition::new(reduced, &sq.forces, Some(joints)))
        .flatten();
    Ok((fc, fast))
}

/// A squeeze: internal contact forces and the joint torques that make them.
#[derive(Debug, Clone, PartialEq)]
pub struct Squeeze {
    /// How far (N) inside its (reduced) cone every force is.
    pub margin: f64,
    /// World-frame contact forces, balancing each other.
    pub forces: Vec<Vector3<f64>>,
    /// `τ = Σ Jᵢᵀ fᵢ`, one per actuated joint (N·m or N).
    pub torques: Vec<f64>,
}

/// The internal forces deepest inside the cones (friction reduced by
/// `opts.friction_reserve`) that `share` of each joint's effort can make, and
/// their torques. The rest of the effort is left for disturbances.
pub fn squeeze(
    grasp: &Grasp,
    joints: &JointTorques,
    share: f64,
    opts: &HoldOptions,
) -> Result<Squeeze, ExactError> {
    let reduced = with_reserve(grasp, opts.friction_reserve);
    let g = reduced.as_ref().unwrap_or(grasp);
    let limited = joints.scaled(share);
    let c = exact_force_closure_with(g, ConeModel::Circular, Some(&limited))?;
    let torques = joints.torques(&c.forces);
    Ok(Squeeze {
        margin: c.squeeze_margin,
        forces: c.forces,
        torques,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Contact;
    use nalgebra::Matrix3xX;

    /// Contacts at `angles` (rad) around a ball of radius `r` in the xy-plane,
    /// each pressed by its own joint with lever arm `r` and effort `effort`.
    fn ring(angles: &[f64], r: f64, mu: f64, effort: f64) -> (Grasp, JointTorques) {
        let mut contacts = Vec::new();
        let mut jac = Vec::new();
        let m = angles.len();
        for (i, a) in angles.iter().enumerate() {
            let out = Vector3::new(a.cos(), a.sin(), 0.0);
            contacts.push(Contact::new(Point3::from(out * r), -out).unwrap());
            let mut j = Matrix3xX::zeros(m);
            j.set_column(i, &(-out * r));
            jac.push(j);
        }
        let grasp = Grasp::new(contacts, mu, 100.0, r, Point3::origin()).unwrap();
        (grasp, JointTorques::new(jac, vec![effort; m]).unwrap())
    }

    #[test]
    fn two_opposed_fingertips_resist_forces_but_not_the_torque_about_their_line() {
        // Point contacts without torsional friction: a couple about the line
        // through both contacts has no resisting force.
        let (g, j) = ring(&[0.0, std::f64::consts::PI], 0.03, 0.8, 1.0);
        let forces_only = Disturbances::standard(&g, 0.1, 9.81, &Point3::origin(), 0.0);
        let v = hold_test(&g, &j, &forces_only, &HoldOptions::default()).unwrap();
        assert!(!v.force_closure && !v.holds());
        let mut no_closure = HoldOptions::default();
        no_closure.require_closure = false;
        let v = hold_test(&g, &j, &forces_only, &no_closure).unwrap();
        assert!(v.holds(), "{v:?}");
        let all = Disturbances::standard(&g, 0.1, 9.81, &Point3::origin(), 0.02);
        let v = hold_test(&g, &j, &all, &no_closure).unwrap();
        assert_eq!(all.0[v.failed.unwrap()].name, "torque +x", "{v:?}");
    }

    #[test]
    fn the_joint_torques_decide_and_the_margin_scales_with_them() {
        let (g, j) = ring(&[0.0, 2.1, 4.2], 0.03, 0.8, 0.3);
        let set = Disturbances::standard(&g, 0.1, 9.81, &Point3::origin(), 0.02);
        let strong = hold_test(&g, &j, &set, &HoldOptions::default()).unwrap();
        assert!(strong.holds(), "{strong:?}");
        assert_eq!(strong.scales.len(), 12);
        // Scales are linear in the efforts here (no force cap is reached):
        // halved below the worst, the test fails, and stops at the first
        // disturbance under 1.
        let k = 0.5 / strong.margin;
        let weak = hold_test(&g, &j.scaled(k), &set, &HoldOptions::default()).unwrap();
        assert!(!weak.holds() && weak.margin < 1.0, "{weak:?}");
        let i = weak.failed.unwrap();
        assert_eq!(weak.scales.len(), i + 1);
        for (a, b) in weak.scales.iter().zip(&strong.scales) {
            assert!((a - b * k).abs() < 1e-4 * b.max(1.0), "{a} vs {b}·{k}");
        }
    }

    #[test]
    fn a_friction_reserve_refuses_a_grasp_that_needs_all_of_its_friction() {
        // Two contacts 90° apart below a ball's equator cannot lift it on
        // their own; with a third on top the weight rests on friction.
        let (g, j) = ring(&[0.0, 2.1, 4.2], 0.03, 0.25, 50.0);
        let set = Disturbances::standard(&g, 0.1, 9.81, &Point3::origin(), 0.0);
        let full = HoldOptions {
            friction_reserve: 0.0,
            ..HoldOptions::default()
        };
        let a = hold_test(&g, &j, &set, &full).unwrap();
        let b = hold_test(&g, &j, &set, &HoldOptions::default()).unwrap();
        assert!(a.margin > b.margin, "{a:?} {b:?}");
    }

    #[test]
    fn the_squeeze_balances_and_stays_within_its_share() {
        let (g, j) = ring(&[0.0, 2.1, 4.2], 0.03, 0.8, 0.3);
        let s = squeeze(&g, &j, 0.5, &HoldOptions::default()).unwrap();
        let net: Vector3<f64> = s.forces.iter().sum();
        assert!(net.norm() < 1e-6, "{net}");
        assert!(s.margin > 0.0);
        for t in &s.torques {
            assert!(t.abs() <= 0.15 + 1e-6, "{t}");
        }
        // The deepest squeeze uses the share on the limiting joint.
        let most = s.torques.iter().fold(0.0f64, |m, t| m.max(t.abs()));
        assert!((most - 0.15).abs() < 1e-4, "{most}");
    }
}
