//! The one hold rule every planner and the kit's verification apply.
//!
//! What: [`hold`] decides whether a closed hand holds the object — exact force
//! closure and every disturbance of the request's set balanced by forces inside
//! the reduced friction cones that the hand's joints can make
//! (`tsukami_grasp::hold`) — and [`squeeze`] gives the joint torques and
//! position targets that make the fingers press with such forces.
//!
//! Why: a planner that searches with one rule and a verification that checks
//! another would return nothing, or return grasps the check was meant to stop.
//! Both call this module with the same [`HoldProblem`].
//!
//! How: the contacts' Jacobians over the hand's independent joints come from
//! [`crate::blocks::force::hand_torques`]; each contact's normal force is
//! capped by the description's `max_finger_force` (an upper bound only: the
//! joint rows limit first). Disturbances are built about the centre of mass
//! with the problem's characteristic length.
//!
//! ```
//! use tsukami_msgs::planner::{DisturbanceSet, HoldRequest};
//! // The default request: closure and the standard set of twelve disturbances.
//! let r = HoldRequest::default();
//! assert_eq!(r.disturbances, DisturbanceSet::Standard);
//! assert_eq!((r.com_error, r.friction_reserve, r.squeeze_share), (0.02, 0.2, 0.9));
//! ```

use nalgebra::{Point3, Vector3};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{JointId, LinkId, RobotModel};
use tsukami_grasp::contact::Contact;
use tsukami_grasp::grasp::Grasp;
use tsukami_grasp::hold::{hold_test, Disturbances, HoldOptions, HoldVerdict, DECIDE_SAFETY};
use tsukami_grasp::joint_torques::JointTorques;
use tsukami_grasp::stiffness::GraspStiffness;
use tsukami_msgs::planner::{DisturbanceSet, HoldRequest, JointSqueeze};

use crate::blocks::force::hand_torques;

/// Gravity's magnitude, m/s² (the direction is the disturbance set's).
pub const G: f64 = 9.81;

/// What the hold test needs besides the contacts.
pub struct HoldProblem<'a> {
    /// The robot.
    pub model: &'a RobotModel,
    /// Its posture (the closed hand).
    pub fk: &'a FkState,
    /// The hand's independent joints.
    pub joints: &'a [JointId],
    /// Normal force cap per contact, N.
    pub cap: f64,
    /// Object mass, kg.
    pub mass: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// Centre of mass, world.
    pub com: Point3<f64>,
    /// Torque scale length, m.
    pub length: f64,
    /// The hand's servo position error at full effort (rad or m): the
    /// joints' stiffness is `effort / servo_saturation` ([`compliance`]).
    pub servo_saturation: f64,
}

/// One contact as the hold test sees it: link, point and inward normal.
pub type HoldContact = (LinkId, Point3<f64>, Vector3<f64>);

/// The grasp and its torque limits, `None` when degenerate.
pub fn setup(p: &HoldProblem<'_>, contacts: &[HoldContact]) -> Option<(Grasp, JointTorques)> {
    let cs = contacts
        .iter()
        .map(|(_, x, n)| Contact::new(*x, *n).ok())
        .collect::<Option<Vec<_>>>()?;
    let limits = vec![p.cap; cs.len()];
    let grasp = Grasp::with_force_limits(cs, limits, p.mu, p.length, p.com).ok()?;
    let points: Vec<(LinkId, Point3<f64>)> = contacts.iter().map(|(l, x, _)| (*l, *x)).collect();
    let torques = hand_torques(p.model, p.fk, p.joints, &points)?;
    Some((grasp, torques))
}

/// The request's options as the grasp crate's (exact margins).
pub fn options(req: &HoldRequest) -> HoldOptions {
    HoldOptions {
        friction_reserve: req.friction_reserve,
        require_closure: req.disturbances == DisturbanceSet::Standard,
        decide_up_to: None,
    }
}

/// The request's disturbance set for `grasp`.
pub fn disturbances(p: &HoldProblem<'_>, grasp: &Grasp, req: &HoldRequest) -> Disturbances {
    match req.disturbances {
        DisturbanceSet::Standard => Disturbances::standard(grasp, p.mass, G, &p.com, req.com_error),
        DisturbanceSet::Gravity => Disturbances::gravity(grasp, p.mass, G, &p.com),
    }
}

/// The hold verdict of `contacts`; `None` when they make no valid grasp or
/// the solver fails (the caller treats both as "does not hold").
pub fn hold(
    p: &HoldProblem<'_>,
    contacts: &[HoldContact],
    req: &HoldRequest,
) -> Option<HoldVerdict> {
    hold_with(p, contacts, req, None)
}

/// [`hold`] deciding up to scale `cap` (`tsukami_grasp::hold::HoldOptions::decide_up_to`):
/// the same verdict, the margin clipped at `cap` (at least [`DECIDE_SAFETY`]),
/// most disturbances without their program.
pub fn hold_up_to(
    p: &HoldProblem<'_>,
    contacts: &[HoldContact],
    req: &HoldRequest,
    cap: f64,
) -> Option<HoldVerdict> {
    hold_with(p, contacts, req, Some(cap.max(DECIDE_SAFETY)))
}

fn hold_with(
    p: &HoldProblem<'_>,
    contacts: &[HoldContact],
    req: &HoldRequest,
    decide_up_to: Option<f64>,
) -> Option<HoldVerdict> {
    let (grasp, torques) = setup(p, contacts)?;
    let set = disturbances(p, &grasp, req);
    let opts = HoldOptions {
        decide_up_to,
        ..options(req)
    };
    hold_test(&grasp, &torques, &set, &opts).ok()
}

/// The squeeze of `contacts` at posture `q`: for every hand joint its torque
/// (`tsukami_grasp::hold::squeeze` with the request's share) and, with the
/// stiffness `effort / servo_saturation`, its target, within its limits. The
/// target also closes each contact's remaining gap (`gaps[i]`, m: a finger
/// stops within the contact distance, not on the surface) and compresses its
/// pad by the squeeze's normal force over [`PAD_STIFFNESS`]: the least-norm
/// joint motion that moves every contact point by gap plus compression along
/// its normal, so the whole servo error presses. Without the compression a
/// stiff servo (the Allegro's 15 N·m over 0.2 rad) would be commanded a few
/// tenths of a millimetre past the surface, which the pad alone takes up.
pub fn squeeze(
    p: &HoldProblem<'_>,
    contacts: &[HoldContact],
    gaps: &[f64],
    q: &[f64],
    servo_saturation: f64,
    req: &HoldRequest,
) -> Option<Vec<JointSqueeze>> {
    let (grasp, torques) = setup(p, contacts)?;
    let s =
        tsukami_grasp::hold::squeeze(&grasp, &torques, req.squeeze_share, &options(req)).ok()?;
    let travel: Vec<f64> = contacts
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let press = s.forces.get(i).map_or(0.0, |f| f.dot(&c.2).max(0.0));
            gaps.get(i).copied().unwrap_or(0.0).max(0.0) + press / PAD_STIFFNESS
        })
        .collect();
    let close = gap_motion(&torques, contacts, &travel);
    let out = p
        .joints
        .iter()
        .zip(&s.torques)
        .zip(close)
        .map(|((&j, &torque), dq)| {
            let joint = &p.model.joints[j];
            let lim = joint.limits;
            let stiffness = lim.effort / servo_saturation;
            let target = match stiffness > 0.0 {
                true => (q[j] + dq + torque / stiffness).clamp(lim.lower, lim.upper),
                false => q[j],
            };
            JointSqueeze {
                joint: joint.name.clone(),
                position: q[j],
                torque,
                stiffness,
                target,
            }
        })
        .collect();
    Some(out)
}

/// The least-norm joint motion `δq` with `nᵢᵀ Jᵢ δq = gapᵢ` for every contact
/// that loads a joint (rows of contacts the structure carries are dropped), in
/// the least-squares sense when the rows are dependent.
fn gap_motion(torques: &JointTorques, contacts: &[HoldContact], gaps: &[f64]) -> Vec<f64> {
    let m = torques.joints();
    let rows: Vec<(nalgebra::RowDVector<f64>, f64)> = contacts
        .iter()
        .enumerate()
        .filter(|(i, _)| torques.loads(*i))
        .map(|(i, c)| {
            let r = torques.rows(i, &nalgebra::Matrix3::identity());
            let row = nalgebra::RowDVector::from_fn(m, |_, j| r.column(j).dot(&c.2));
            (row, gaps.get(i).copied().unwrap_or(0.0).max(0.0))
        })
        .collect();
    if rows.is_empty() {
        return vec![0.0; m];
    }
    let a = nalgebra::DMatrix::from_rows(&rows.iter().map(|r| r.0.clone()).collect::<Vec<_>>());
    let d = nalgebra::DVector::from_iterator(rows.len(), rows.iter().map(|r| r.1));
    // Least-norm least squares: two contacts on one link, or more contacts
    // than joints, make the rows dependent; their mean travel is closed.
    match a.svd(true, true).solve(&d, 1e-12) {
        Ok(dq) => dq.iter().copied().collect(),
        Err(_) => vec![0.0; m],
    }
}

/// The request's rule, decided: closure when the set is the standard one,
/// every disturbance balanced; the verdict (its margins lower bounds:
/// `tsukami_grasp::hold::HoldOptions::decide_up_to`, the same verdict as
/// [`hold`]'s at a fraction of the cost) or why not. Searches call this.
pub fn holds_under(
    p: &HoldProblem<'_>,
    contacts: &[HoldContact],
    req: &HoldRequest,
) -> Result<HoldVerdict, String> {
    holds_up_to(p, contacts, req, DECIDE_SAFETY)
}

/// [`holds_under`] with the margin clipped at `cap` ([`hold_up_to`]): what a
/// planner that ranks by a preferred margin needs, for less than
/// [`holds_exactly`] costs.
pub fn holds_up_to(
    p: &HoldProblem<'_>,
    contacts: &[HoldContact],
    req: &HoldRequest,
    cap: f64,
) -> Result<HoldVerdict, String> {
    let v = rule(hold_up_to(p, contacts, req, cap), req)?;
    within_stiffness(p, contacts, req)?;
    Ok(v)
}

/// [`holds_under`] with the exact margins (the reply's `hold_margin`).
pub fn holds_exactly(
    p: &HoldProblem<'_>,
    contacts: &[HoldContact],
    req: &HoldRequest,
) -> Result<HoldVerdict, String> {
    let v = rule(hold(p, contacts, req), req)?;
    within_stiffness(p, contacts, req)?;
    Ok(v)
}

/// Whether the object moves under the six pulls of its weight at most the
/// request's `max_turn_deg` and `max_shift_mm` by the linear stiffness model
/// ([`compliance`]), when the request sets them; always with the gravity
/// set (the paper's test). Part of [`holds_under`] and [`holds_exactly`].
pub fn within_stiffness(
    p: &HoldProblem<'_>,
    contacts: &[HoldContact],
    req: &HoldRequest,
) -> Result<(), String> {
    let (max_turn, max_shift) = (
        req.max_turn_deg.unwrap_or(f64::INFINITY),
        req.max_shift_mm.unwrap_or(f64::INFINITY),
    );
    if req.disturbances != DisturbanceSet::Standard
        || (max_turn, max_shift) == (f64::INFINITY, f64::INFINITY)
    {
        return Ok(());
    }
    let (turn, shift) = compliance(p, contacts)
        .ok_or("too compliant: some motion of the object is not resisted")?;
    if turn.to_degrees() > max_turn || shift * 1e3 > max_shift {
        return Err(format!(
            "too compliant: the object turns {:.2}° and shifts {:.2} mm under its weight (at most {max_turn}° and {max_shift} mm)",
            turn.to_degrees(),
            shift * 1e3,
        ));
    }
    Ok(())
}

fn rule(v: Option<HoldVerdict>, req: &HoldRequest) -> Result<HoldVerdict, String> {
    let v = v.ok_or("the hold test could not be solved")?;
    if req.disturbances == DisturbanceSet::Standard && !v.force_closure {
        return Err("the contacts are not in force closure".into());
    }
    if !v.holds() {
        return Err(format!(
            "the joints' torques cannot hold the disturbances: the worst is resisted {:.2} times",
            v.margin
        ));
    }
    Ok(v)
}

/// Pad stiffness (N/m) of a contact, for [`compliance`].
pub const PAD_STIFFNESS: f64 = 5000.0;

/// How far the held object moves under the six pulls of its weight
/// (±x, ±y, ±z at the centre of mass) with the finger joints as servos of
/// stiffness `effort / servo_saturation` and pads of [`PAD_STIFFNESS`]
/// (`tsukami_grasp::stiffness`): the largest turn (rad) and shift (m);
/// `None` when some motion is not resisted at all.
pub fn compliance(p: &HoldProblem<'_>, contacts: &[HoldContact]) -> Option<(f64, f64)> {
    let (_, torques) = setup(p, contacts)?;
    let k = stiffness(p, &torques, contacts)?;
    let (mut turn, mut shift) = (0.0f64, 0.0f64);
    for w in weight_pulls(p.mass) {
        let d = k.displacement(&w)?;
        turn = turn.max(d.turn.norm());
        shift = shift.max(d.shift.norm());
    }
    Some((turn, shift))
}

/// The grasp's stiffness about the centre of mass: the hand's joints as
/// servos of `effort / servo_saturation`, pads of [`PAD_STIFFNESS`].
fn stiffness(
    p: &HoldProblem<'_>,
    torques: &JointTorques,
    contacts: &[HoldContact],
) -> Option<GraspStiffness> {
    let points: Vec<Point3<f64>> = contacts.iter().map(|(_, x, _)| *x).collect();
    let jac: Vec<_> = (0..points.len())
        .map(|i| torques.jacobian(i).clone())
        .collect();
    let springs: Vec<f64> = torques
        .efforts()
        .iter()
        .map(|e| (e / p.servo_saturation.max(1e-6)).max(1e-9))
        .collect();
    GraspStiffness::new(&points, &p.com, &jac, &springs, PAD_STIFFNESS)
}

/// The object's weight pulling along −x, +x, −y, +y, −z, +z at the centre
/// of mass.
fn weight_pulls(mass: f64) -> impl Iterator<Item = tsukami_grasp::grasp_matrix::Wrench> {
    (0..6).map(move |k| {
        let mut w = tsukami_grasp::grasp_matrix::Wrench::zeros();
        w[k / 2] = if k % 2 == 0 { -1.0 } else { 1.0 } * mass * G;
        w
    })
}

/// What the compliant hand does under the six pulls of the weight
/// ([`passive_response`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassiveResponse {
    /// The largest `‖f_t‖ / (μ f_n)` of any contact under any pull (the
    /// full friction coefficient; infinite when a contact lets go).
    pub friction_use: f64,
    /// The largest `|τⱼ| / effortⱼ` of any hand joint under any pull.
    pub torque_use: f64,
}

/// The forces the hand really makes, not forces that merely exist: the
/// fingers press with the [`squeeze`]'s forces `f₀`, then each pull of the
/// weight moves the object by the grasp's compliance and changes the contact
/// forces by `δf` (`tsukami_grasp::stiffness::GraspStiffness::force_change`).
/// The object stays put only while every `f₀ + δf` stays inside its friction
/// cone and every joint within its effort; this says how much of both the
/// worst pull uses. `None` when the squeeze or the stiffness cannot be
/// computed.
pub fn passive_response(
    p: &HoldProblem<'_>,
    contacts: &[HoldContact],
    req: &HoldRequest,
) -> Option<PassiveResponse> {
    let (grasp, torques) = setup(p, contacts)?;
    let s =
        tsukami_grasp::hold::squeeze(&grasp, &torques, req.squeeze_share, &options(req)).ok()?;
    let k = stiffness(p, &torques, contacts)?;
    let mut out = PassiveResponse {
        friction_use: 0.0,
        torque_use: 0.0,
    };
    for w in weight_pulls(p.mass) {
        let df = k.force_change(&w)?;
        let f: Vec<Vector3<f64>> = s.forces.iter().zip(&df).map(|(a, b)| a + b).collect();
        for ((_, _, n), fi) in contacts.iter().zip(&f) {
            let normal = n.dot(fi);
            let tangential = (fi - n * normal).norm();
            let used = match normal > 1e-9 {
                true => tangential / (p.mu * normal),
                false => f64::INFINITY,
            };
            out.friction_use = out.friction_use.max(used);
        }
        for (t, e) in torques.torques(&f).iter().zip(torques.efforts()) {
            if *e > 0.0 {
                out.torque_use = out.torque_use.max(t.abs() / e);
            }
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two prismatic fingers closing along x on a 6 cm cube at the origin,
    /// each touching it at two points, `gap` short of the surface.
    fn gripper() -> RobotModel {
        let finger = |name: &str, x: f64, axis: f64| {
            format!(
                r#"<link name="{name}"/>
                <joint name="{name}_slide" type="prismatic"><parent link="base"/><child link="{name}"/>
                  <origin xyz="{x} 0 0"/><axis xyz="{axis} 0 0"/>
                  <limit lower="0" upper="0.05" effort="10" velocity="1"/></joint>"#
            )
        };
        let urdf = format!(
            r#"<robot name="g"><link name="base"/>{}{}</robot>"#,
            finger("left", -0.05, 1.0),
            finger("right", 0.05, -1.0)
        );
        RobotModel::from_urdf_str(&urdf, std::path::Path::new(".")).unwrap()
    }

    #[test]
    fn the_target_closes_the_gap_and_compresses_the_pads_before_the_servo_presses() {
        let model = gripper();
        let q = [0.02, 0.02];
        let mut fk = FkState::new(&model);
        model.forward_kinematics(&q, &mut fk);
        let joints = [
            model.joint_id("left_slide").unwrap(),
            model.joint_id("right_slide").unwrap(),
        ];
        let (left, right) = (
            model.link_id("left").unwrap(),
            model.link_id("right").unwrap(),
        );
        let contacts: Vec<HoldContact> = [(left, -0.03, 1.0), (right, 0.03, -1.0)]
            .iter()
            .flat_map(|&(l, x, n)| {
                [-0.01, 0.01].map(|z| (l, Point3::new(x, 0.0, z), Vector3::new(n, 0.0, 0.0)))
            })
            .collect();
        let p = HoldProblem {
            model: &model,
            fk: &fk,
            joints: &joints,
            cap: 20.0,
            mass: 0.1,
            mu: 0.5,
            com: Point3::origin(),
            length: 0.03,
            servo_saturation: 0.01,
        };
        let gap = 0.0005;
        let s = squeeze(&p, &contacts, &[gap; 4], &q, 0.01, &HoldRequest::default()).unwrap();
        for js in &s {
            // Each finger pushes with `torque` (N) shared by its two contacts,
            // both normal: each pad compresses by torque / 2 / PAD_STIFFNESS.
            assert!(js.torque > 1.0, "{js:?}");
            assert_eq!(js.stiffness, 10.0 / 0.01);
            let expected =
                js.position + gap + js.torque / 2.0 / PAD_STIFFNESS + js.torque / js.stiffness;
            assert!(
                (js.target - expected).abs() < 1e-6,
                "{js:?}: expected {expected}"
            );
        }
    }
}
