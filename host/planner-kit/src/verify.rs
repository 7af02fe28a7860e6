//! Verification of every grasp before it leaves the kit.
//!
//! What: [`verify`] checks a returned [`Grasp`] on the world it was planned on:
//! a configuration of the model's size with finite values, at least one
//! contact, every contact finite with a unit normal and a positive force
//! limit, on a hand link; then the exact friction-cone test
//! (`tsukami_grasp::exact`, a second-order cone program) must find contact
//! forces, each within its cone and the hand's single force bound (the weakest
//! finger's `f_max`, stated in the reply as `force_limit`), that resist the object's
//! weight; and last the hold test of the request ([`crate::blocks::hold`]:
//! exact force closure and every disturbance of the set balanced by forces
//! the joints' torques can make, inside friction cones with a reserve), whose
//! squeeze the reply carries. [`force_closure`] is the paper's step alone,
//! which planners call inside their loops (the ellipsoid margin of eq. (10)
//! and the exact weight verdict).
//!
//! Why: a planner may be new and wrong; the protocol promises that every grasp
//! sent was verified. The checks here are the kit's, not the planner's.
//!
//! How: checks run in order and the first failure is the reason: the shapes,
//! then [`geometric_checks`] (no link moved by the grasp more than 1 mm inside
//! the object or an obstacle, no two links overlapping but adjacent and
//! allowed pairs, contacts on the surface with agreeing normals:
//! [`crate::blocks::grasp_check`], the same rules the paper's planner applies
//! to its candidates), then the force-closure step. The session then checks
//! the grasp's approach, closing and lift ([`motion_phases`], the trajectory
//! planner's own checks, `crate::motion_check::phases`).

use nalgebra::Vector3;
use tsukami_grasp::contact::Contact;
use tsukami_grasp::ellipsoid::{ellipsoid_test, EllipsoidModel};
use tsukami_grasp::exact::{exact_test, ConeModel};
use tsukami_grasp::grasp::Grasp as GraspMatrix;

use tsukami_body::kinematics::FkState;
use tsukami_body::model::LinkId;

use crate::blocks::grasp_check::check_in;
use crate::blocks::hold::{
    compliance, holds_exactly, holds_under, holds_up_to, passive_response, squeeze, HoldContact,
    HoldProblem, PassiveResponse,
};
use crate::blocks::robust::{pose_robustness, RobustProblem};
use crate::blocks::wrap::{style_check, StyleRule};
use crate::grasp::{FingerContact, Grasp};
use crate::motion_check::goal::Goal;
use crate::motion_check::phases::{check_phases, Blocked, PhaseParams, PhaseScene};
use crate::object::Object;
use crate::planner::{GraspPlanner, World};
use tsukami_msgs::planner::{DisturbanceSet, HoldRequest, JointSqueeze, PoseRobustness};

/// Gravity in the world frame (z up), m/s².
pub const GRAVITY: Vector3<f64> = Vector3::new(0.0, 0.0, -9.81);

/// The force-closure verdicts of a contact set for the object's weight.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// Ellipsoid margin `n − f(p1..pn)` of eq. (10).
    pub margin: f64,
    /// The exact friction-cone test resists the weight.
    pub exact_resists_weight: bool,
    /// The characteristic length used (γ = 1 / length in eq. (6)).
    pub characteristic_length: f64,
    /// The one normal-force bound applied to every contact, N: the weakest
    /// finger's `f_max` (the paper's single maximum finger force).
    pub force_limit: f64,
    /// Exact force closure.
    pub force_closure: bool,
    /// The hold margin (`tsukami_grasp::hold`): the smallest multiple of any
    /// disturbance of the set the joints can balance.
    pub hold_margin: f64,
    /// The set checked.
    pub disturbances: DisturbanceSet,
    /// The squeeze per independent hand joint.
    pub squeeze: Vec<JointSqueeze>,
    /// The hold test under the request's object pose errors ([`robustness`]).
    pub robustness: PoseRobustness,
    /// The worst turn (rad) and shift (m) under the six pulls
    /// ([`crate::blocks::hold::compliance`]).
    pub compliance: Option<(f64, f64)>,
    /// The compliant hand's use of friction and effort under the six pulls
    /// ([`crate::blocks::hold::passive_response`]).
    pub passive: Option<PassiveResponse>,
}

/// The paper's single maximum finger force of a contact set: the weakest `f_max`.
pub fn force_limit(contacts: &[FingerContact]) -> f64 {
    contacts
        .iter()
        .map(|c| c.f_max)
        .fold(f64::INFINITY, f64::min)
        .max(1e-6)
}

/// The ellipsoid margin and the exact verdict of `contacts` on `object` for its
/// weight; `None` when the contacts make no valid grasp (degenerate).
pub fn force_closure(object: &Object, contacts: &[FingerContact], length: f64) -> Option<Verdict> {
    let cs = contacts
        .iter()
        .map(|c| Contact::new(c.position, c.normal).ok())
        .collect::<Option<Vec<_>>>()?;
    let limit = force_limit(contacts);
    let limits = vec![limit; contacts.len()];
    let com = object.center_of_mass;
    let grasp = GraspMatrix::with_force_limits(cs, limits, object.mu, length, com).ok()?;
    let weight = grasp.weight_wrench(object.mass, &GRAVITY, &com);
    let margin = ellipsoid_test(&grasp, &EllipsoidModel::default(), &weight).margin();
    let exact = exact_test(&grasp, ConeModel::Circular, &weight).ok()?;
    Some(Verdict {
        margin,
        exact_resists_weight: exact.resists_weight(),
        characteristic_length: length,
        force_limit: limit,
        force_closure: exact.closure.force_closure,
        hold_margin: 0.0,
        disturbances: DisturbanceSet::Gravity,
        squeeze: Vec::new(),
        robustness: PoseRobustness::default(),
        compliance: None,
        passive: None,
    })
}

fn shape_checks<P: GraspPlanner>(world: &World<'_, P>, grasp: &Grasp) -> Result<(), String> {
    let model = &world.robot.model;
    if grasp.q.len() != model.joints.len() || !grasp.q.iter().all(|v| v.is_finite()) {
        return Err("the configuration is not one finite value per joint".into());
    }
    if grasp
        .joints
        .iter()
        .chain(&grasp.extra)
        .any(|&j| j >= model.joints.len())
    {
        return Err("a joint id is out of range".into());
    }
    if grasp.contacts.is_empty() {
        return Err("no contacts".into());
    }
    let hand = world.hand();
    for (i, c) in grasp.contacts.iter().enumerate() {
        let finite = c
            .position
            .iter()
            .chain(c.normal.iter())
            .all(|v| v.is_finite());
        if !finite
            || (c.normal.norm() - 1.0).abs() > 1e-6
            || !(c.f_max.is_finite() && c.f_max > 0.0)
        {
            return Err(format!(
                "contact {i} has a non-finite value, a non-unit normal or no force"
            ));
        }
        if !hand.links.contains(&c.link) {
            return Err(format!("contact {i} is not on a hand link"));
        }
    }
    Ok(())
}

/// Geometric checks of the grasp on the world
/// ([`crate::blocks::grasp_check`]): the links the grasp moves — the hand, the
/// arm and everything below the extra (waist, whole-body) joints — no more
/// than 1 mm into the object or an obstacle, the robot free of
/// self-collision, and every contact on the object's surface with its normal
/// agreeing.
pub fn geometric_checks<P: GraspPlanner>(
    world: &World<'_, P>,
    grasp: &Grasp,
) -> Result<(), String> {
    let (model, hand) = (&world.robot.model, world.hand());
    let mut fk = FkState::new(model);
    model.forward_kinematics(&grasp.q, &mut fk);
    let mut links: Vec<LinkId> = hand.links.iter().chain(&hand.arm_links).copied().collect();
    let mut below: Vec<LinkId> = grasp.extra.iter().map(|&j| model.joints[j].child).collect();
    while let Some(l) = below.pop() {
        if !links.contains(&l) {
            links.push(l);
        }
        below.extend(model.links[l].children.iter().copied());
    }
    links.retain(|&l| !hand.collision.link_parts(l).is_empty());
    check_in(world, &fk, &links, &grasp.contacts).map_err(|r| r.describe(model))
}

/// Verifies `grasp` on `world` against the hold request `req` (see the
/// module docs); the verdict or why not.
pub fn verify<P: GraspPlanner>(
    world: &World<'_, P>,
    grasp: &Grasp,
    req: &HoldRequest,
) -> Result<Verdict, String> {
    shape_checks(world, grasp)?;
    geometric_checks(world, grasp)?;
    let length = grasp_length(world, grasp);
    let mut verdict = force_closure(world.object, &grasp.contacts, length)
        .ok_or("the contacts make no valid grasp matrix")?;
    if !verdict.exact_resists_weight || !verdict.margin.is_finite() {
        return Err("the exact friction-cone test finds no forces that resist the weight".into());
    }
    hold_checks(world, grasp, length, req, &mut verdict)?;
    Ok(verdict)
}

/// The kit's hold problem for the hand of `world` at posture `fk`.
fn hold_problem<'a, P: GraspPlanner>(
    world: &'a World<'_, P>,
    fk: &'a FkState,
    length: f64,
) -> HoldProblem<'a> {
    let (hand, object) = (world.hand(), world.object);
    HoldProblem {
        model: &world.robot.model,
        fk,
        joints: &hand.joints,
        cap: hand.max_finger_force,
        mass: object.mass,
        mu: object.mu,
        com: object.center_of_mass,
        length,
        servo_saturation: hand.servo_saturation,
    }
}

fn hold_contacts(contacts: &[FingerContact]) -> Vec<HoldContact> {
    contacts
        .iter()
        .map(|c| (c.link, c.position, c.normal))
        .collect()
}

/// Whether the closed hand at `fk` holds the object with `contacts` under the
/// request `req` (closure when the set requires it, every disturbance within
/// the joints' torques): the verdict, or why not. Planners call it in their
/// loops; the verification of every reply calls it too.
pub fn holds<P: GraspPlanner>(
    world: &World<'_, P>,
    fk: &FkState,
    contacts: &[FingerContact],
    length: f64,
    req: &HoldRequest,
) -> Result<tsukami_grasp::hold::HoldVerdict, String> {
    holds_under(
        &hold_problem(world, fk, length),
        &hold_contacts(contacts),
        req,
    )
}

/// How many of the request's object pose errors (drawn from the plan's
/// `seed`) `grasp` still holds under ([`crate::blocks::robust`]): the hand
/// re-closed on the moved object, the rule of [`holds`]. Planners that
/// prefer robust grasps call it through [`crate::Run::pose_robustness`],
/// which keeps the answer for the verification of the same grasp.
pub fn robustness<P: GraspPlanner>(
    world: &World<'_, P>,
    grasp: &Grasp,
    req: &HoldRequest,
    seed: u64,
) -> PoseRobustness {
    let model = &world.robot.model;
    let mut fk = FkState::new(model);
    model.forward_kinematics(&grasp.q, &mut fk);
    let rule = style_rule(world, grasp, &fk);
    let problem = RobustProblem {
        robot: world.robot,
        hand: world.hand(),
        object: world.object,
        length: grasp_length(world, grasp),
        palm_approach: rule.palm_contact.then_some(rule.approach),
        closing: world.robot.closing_joints(&grasp.grasp_type.name),
    };
    pose_robustness(&problem, &grasp.q, &grasp.contacts, req, seed)
}

/// The exact hold margin of `grasp` under `req` (the reply's `hold_margin`:
/// the multiple of every disturbance it resists), `None` when it does not
/// hold. Planners rank their accepted grasps by it
/// (`HoldRequest::preferred_margin`).
pub fn hold_margin<P: GraspPlanner>(
    world: &World<'_, P>,
    grasp: &Grasp,
    req: &HoldRequest,
) -> Option<f64> {
    hold_margin_with(world, grasp, req, None)
}

/// [`hold_margin`] clipped at `cap` (`blocks::hold::holds_up_to`): the same
/// `None`, and `min(hold_margin, cap)` within the solver's rounding, for a
/// fraction of the programs. Planners that only compare the margin with a
/// preferred one call this.
pub fn hold_margin_up_to<P: GraspPlanner>(
    world: &World<'_, P>,
    grasp: &Grasp,
    req: &HoldRequest,
    cap: f64,
) -> Option<f64> {
    hold_margin_with(world, grasp, req, Some(cap))
}

fn hold_margin_with<P: GraspPlanner>(
    world: &World<'_, P>,
    grasp: &Grasp,
    req: &HoldRequest,
    cap: Option<f64>,
) -> Option<f64> {
    let model = &world.robot.model;
    let mut fk = FkState::new(model);
    model.forward_kinematics(&grasp.q, &mut fk);
    let problem = hold_problem(world, &fk, grasp_length(world, grasp));
    let contacts = hold_contacts(&grasp.contacts);
    match cap {
        Some(c) => holds_up_to(&problem, &contacts, req, c),
        None => holds_exactly(&problem, &contacts, req),
    }
    .ok()
    .map(|v| v.margin)
}

/// The characteristic length of `grasp`: its own when valid, else the object's.
fn grasp_length<P: GraspPlanner>(world: &World<'_, P>, grasp: &Grasp) -> f64 {
    grasp
        .characteristic_length
        .filter(|l| l.is_finite() && *l > 0.0)
        .unwrap_or_else(|| world.object.characteristic_length())
}

/// The rule of the grasp's style ([`crate::blocks::wrap`]): the approach and
/// palm requirement of its type in the hand's grasp-type file, or — for a
/// type that file does not list (another planner's) — the palm normal and
/// no palm requirement.
fn style_rule<P: GraspPlanner>(world: &World<'_, P>, grasp: &Grasp, fk: &FkState) -> StyleRule {
    let hand = world.hand();
    let listed = hand
        .grasp_types
        .grasp_types
        .iter()
        .find(|g| g.name == grasp.grasp_type.name);
    let approach = listed.map_or(Vector3::z(), |g| g.approach());
    StyleRule {
        style: grasp.grasp_type.style,
        palm_contact: listed.is_some_and(|g| g.palm_contact),
        palm: hand.palm,
        approach: fk.pose(hand.palm).rotation * approach,
    }
}

/// The hold test of the request and the squeeze, into `verdict`.
fn hold_checks<P: GraspPlanner>(
    world: &World<'_, P>,
    grasp: &Grasp,
    length: f64,
    req: &HoldRequest,
    verdict: &mut Verdict,
) -> Result<(), String> {
    let (model, hand, object) = (&world.robot.model, world.hand(), world.object);
    let mut fk = FkState::new(model);
    model.forward_kinematics(&grasp.q, &mut fk);
    let problem = hold_problem(world, &fk, length);
    let contacts = hold_contacts(&grasp.contacts);
    style_check(&style_rule(world, grasp, &fk), &contacts)?;
    let v = holds_exactly(&problem, &contacts, req)?;
    verdict.compliance = compliance(&problem, &contacts);
    verdict.passive = passive_response(&problem, &contacts, req);
    verdict.force_closure = v.force_closure;
    verdict.hold_margin = v.margin;
    verdict.disturbances = req.disturbances;
    let gaps: Vec<f64> = grasp
        .contacts
        .iter()
        .map(|c| {
            hand.collision
                .link_object_proximity(&fk, c.link, &object.collision, 0.01)
                .map_or(0.0, |p| p.distance.max(0.0))
        })
        .collect();
    let s = squeeze(
        &problem,
        &contacts,
        &gaps,
        &grasp.q,
        hand.servo_saturation,
        req,
    );
    verdict.squeeze = s.ok_or("no squeeze the joints can make balances the contacts")?;
    Ok(())
}

/// The approach, closing and lift `grasp` implies, checked as the trajectory
/// planner will plan them ([`crate::motion_check::phases`], default settings:
/// the motion request's default pre-grasp distance and lift height, the
/// robot description's clearances or else the default ones): the reach moves the grasp's extra joints and the arm,
/// the palm comes in along the grasp type's approach. Planners call it
/// through [`crate::Run::motion_phases`]; the session calls it on every grasp
/// a planner returns.
pub fn motion_phases<P: GraspPlanner>(world: &World<'_, P>, grasp: &Grasp) -> Result<(), Blocked> {
    let robot = world.robot;
    let name = &grasp.grasp_type.name;
    let approach = Goal::type_approach(robot, name, &grasp.q).ok_or_else(|| Blocked {
        reason: "unknown_grasp_type",
        message: format!("the hand has no grasp type `{name}`, so the grasp has no approach"),
    })?;
    let mut reach = grasp.extra.clone();
    reach.extend(robot.hand().arm.iter().filter(|j| !grasp.extra.contains(j)));
    let goal = Goal::new(robot, grasp.q.clone(), reach, name, approach);
    let mut params = PhaseParams::default();
    params.clearance = params.clearance.for_robot(robot);
    let mut scene = PhaseScene::new(robot, world.object, world.obstacles.clone(), goal, params);
    check_phases(&mut scene).map(|_| ())
}
