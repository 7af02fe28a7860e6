//! An independent check of a Plan reply: does the robot, posed as the reply says,
//! really hold the object?
//!
//! What: [`verify`] judges a [`PlanReply`] against the [`World`] the client asked
//! for and returns a [`Verdict`] listing every [`Violation`]:
//! - **force closure with the weight**, recomputed by the exact friction-cone test
//!   (`tsukami-grasp`, circular cones) from the reply's contact points and normals,
//!   the world's μ, mass and centre of mass, and the one normal-force bound the
//!   reply states it used (`force_closure.force_limit`). That bound must be
//!   positive and no larger than what each finger can press with, computed here
//!   from the robot's Jacobian and joint effort limits at the reply's posture
//!   (`tsukami_grasp::finger_force`). The planner's `exact_resists_weight` flag and
//!   its per-contact `f_max` are never read for the verdict; a missing bound is a
//!   violation, never replaced by a default;
//! - **force closure and the disturbances** (unless the reply says it was
//!   checked against gravity alone): exact force closure of the reply's
//!   contacts, and the weight pulling along ±x, ±y, ±z plus the torques of a
//!   [`Tolerances::com_error`] centre-of-mass error, each balanced by forces
//!   inside the friction cones that the hand's joints can make — the torques
//!   `τ = Σ Jᵢᵀ fᵢ` within the URDF efforts, with this module's own Jacobians
//!   (`tsukami_grasp::hold`; no friction reserve, no force cap: the physics
//!   alone);
//! - **contacts on the object**: each contact within [`Tolerances::surface`] of the
//!   object's surface, its normal within [`Tolerances::normal_angle`] of the
//!   (inward) normal cone of the surface there — within
//!   [`Tolerances::normal_radius`] of the contact's closest surface point —
//!   and its link within
//!   [`Tolerances::contact_gap`] of the point;
//! - **no link sunk into anything**: forward kinematics at the reply's joint
//!   positions, then every robot link against the object and every obstacle:
//!   penetration deeper than [`Tolerances::penetration`] is a violation (touching
//!   is allowed; it is how a hand holds);
//! - **no self-collision**: no two links overlap but adjacent ones and the robot
//!   description's `allowed_collisions`;
//! - **the palm where the reply says**, within [`Tolerances::palm_position`] and
//!   [`Tolerances::palm_angle`];
//! - **joint limits**, and **`joints_used`** naming every joint beyond the arm and
//!   the hand whose position differs from the model's rest position (a squat left
//!   out of the list is found);
//! - the reply's **mass, centre of mass and μ** agree with the world's.
//!
//! Why: the planners verify their own grasps before replying, so their flags are
//! always true on a successful reply; a check that reads them cannot fail. This
//! one uses only `tsukami-body` and `tsukami-grasp`, never a planner's code, so the
//! paper tests, the bus tests, the demo and the object benchmark judge every
//! planner, the built-in one and third-party ones, the same way.
//!
//! How: the world frame is the robot's base frame (every message's). Joints the
//! reply does not mention stay at the model's rest position. Checks that need a
//! posture are skipped when the joint positions cannot be used (the violation
//! saying why is reported instead).
//!
//! ```no_run
//! use std::path::Path;
//! use tsukami_scenes::verify::{verify, Tolerances};
//! use tsukami_scenes::world::World;
//! use tsukami_scenes::scene_requests;
//! # fn reply() -> tsukami_msgs::planner::PlanReply { panic!("a Plan reply, e.g. from `tsukami plan`") }
//! let models = Path::new("models");
//! let req = scene_requests(&models.join("scenes/can_breast.toml")).unwrap();
//! let world = World::from_requests(models, &req.robot, &req.object, &req.env).unwrap();
//! let verdict = verify(&world, &reply(), &Tolerances::default());
//! assert!(verdict.is_ok(), "{verdict}");
//! ```

use std::fmt;

use nalgebra::{DVector, Matrix3xX, Point3, Vector3};
use tsukami_body::collision::{CollisionObject, Part};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::model::{Geometry, LinkId};
use tsukami_grasp::contact::Contact;
use tsukami_grasp::exact::{exact_weight_scale, ConeModel};
use tsukami_grasp::finger_force::max_finger_force;
use tsukami_grasp::grasp::Grasp;
use tsukami_grasp::hold::{hold_test, Disturbances, HoldOptions};
use tsukami_grasp::joint_torques::JointTorques;
use tsukami_msgs::planner::DisturbanceSet;
use tsukami_msgs::planner::{ContactReply, PlanReply};

use crate::geometry::pose_to_isometry;
use crate::surface::{angle_to_normal_cone, surface_point_within};
use crate::world::World;

/// Largest disagreement (rad or m) between a reported mimic joint and the value
/// its master gives it.
const MIMIC_SLACK: f64 = 1e-6;

/// Gravity in the world frame (m/s²).
pub const GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// The stated tolerances of [`verify`]. The defaults are physical: a millimetre
/// of position, a few degrees of direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Largest distance (m) of a contact point from the object's surface. 1 mm.
    pub surface: f64,
    /// Largest angle (rad) between a contact normal and the surface's inward
    /// normal cone at the contact. 5°.
    pub normal_angle: f64,
    /// How much surface around a contact's closest surface point spans that
    /// normal cone (m). 1 mm, as `surface`: a contact is placed to within a
    /// millimetre, and so is the surface it presses on — an edge that close
    /// is where it touches, and any direction of the edge's cone is its
    /// normal. (With an exact point only, a grasp planned on an estimated pose
    /// a fraction of a millimetre off fails wherever a fingertip was planned
    /// on an edge: the point falls beside it, on one face.)
    pub normal_radius: f64,
    /// Largest distance (m) from a contact's link to its contact point. 3 mm
    /// (the planners close fingers to within 2 mm).
    pub contact_gap: f64,
    /// Deepest penetration (m) of a link into the object or an obstacle. 1 mm.
    pub penetration: f64,
    /// Palm position error (m) against forward kinematics. 1 mm.
    pub palm_position: f64,
    /// Palm orientation error (rad) against forward kinematics. 0.01 rad.
    pub palm_angle: f64,
    /// Slack (rad or m) on joint limits and on "differs from rest". 1e-9.
    pub joint: f64,
    /// Relative slack on the stated force limit against the fingers' capability,
    /// and on the reply's mass and μ against the world's. 1e-6.
    pub relative: f64,
    /// Largest centre-of-mass disagreement (m). 1 mm.
    pub center_of_mass: f64,
    /// Centre-of-mass error (m) whose torque the grasp must resist. 2 cm.
    pub com_error: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            surface: 1e-3,
            normal_angle: 5f64.to_radians(),
            normal_radius: 1e-3,
            contact_gap: 3e-3,
            penetration: 1e-3,
            palm_position: 1e-3,
            palm_angle: 0.01,
            joint: 1e-9,
            relative: 1e-6,
            center_of_mass: 1e-3,
            com_error: 0.02,
        }
    }
}

/// One way a reply is wrong.
#[derive(Debug, Clone, PartialEq)]
pub enum Violation {
    /// The recomputed exact test: the contacts cannot hold the weight.
    NotHeld {
        /// Largest multiple of the weight the contacts can balance (< 1).
        weight_scale: f64,
    },
    /// The contacts are not in exact force closure.
    NotForceClosure,
    /// A disturbance the joints' torques cannot balance.
    NotHeldUnder {
        /// The disturbance (`"force +x"`, `"torque -z"`, …).
        disturbance: String,
        /// Largest multiple of it the contacts balance (< 1).
        scale: f64,
    },
    /// The contacts do not make a grasp the exact test accepts (fewer than two,
    /// a zero normal, a bad μ or force limit).
    BadGrasp(String),
    /// The stated force limit is missing, not positive, or above what a finger
    /// can press with.
    ForceLimit {
        /// The limit the reply states (N).
        stated: f64,
        /// What the weakest finger can do at the reply's posture (N), if known.
        capability: Option<f64>,
        /// That finger's contact link.
        link: Option<String>,
    },
    /// The reply's mass, μ or centre of mass differs from the world's.
    ObjectMismatch {
        /// `mass`, `mu` or `center_of_mass`.
        field: &'static str,
        /// The reply's value (the distance for the centre of mass).
        reply: f64,
        /// The world's value (0 for the centre of mass).
        world: f64,
    },
    /// A contact is not on the object's surface.
    OffSurface {
        /// Contact link.
        link: String,
        /// Distance from the surface (m).
        distance: f64,
    },
    /// A contact normal disagrees with the surface normal there.
    NormalMismatch {
        /// Contact link.
        link: String,
        /// Angle to the inward normal cone (rad).
        angle: f64,
    },
    /// A contact's link is not at its contact point (or is not a hand link).
    LinkNotAtContact {
        /// Contact link.
        link: String,
        /// Distance from the link to the point (m); infinite for an unknown link.
        distance: f64,
    },
    /// A link sinks into the object or an obstacle.
    Penetration {
        /// Robot link.
        link: String,
        /// The object's or obstacle's name.
        body: String,
        /// Depth (m).
        depth: f64,
    },
    /// Two links of the robot overlap (neither adjacent nor allowed).
    SelfCollision {
        /// One link.
        link: String,
        /// The other.
        other: String,
    },
    /// The palm is not where the reply says.
    PalmPose {
        /// Position error (m).
        position: f64,
        /// Orientation error (rad).
        angle: f64,
    },
    /// A joint is outside its limits.
    JointLimit {
        /// Joint.
        joint: String,
        /// Value.
        value: f64,
        /// Lower limit.
        lower: f64,
        /// Upper limit.
        upper: f64,
    },
    /// A joint beyond the arm and hand moved from rest but is not in `joints_used`.
    HiddenJoint {
        /// Joint.
        joint: String,
        /// Its position.
        value: f64,
        /// Its rest position.
        rest: f64,
    },
    /// A joint position or name the model cannot take (unknown, fixed, mimic,
    /// not finite), or a malformed pose; the posture checks were skipped.
    BadJoints(String),
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use Violation::*;
        match self {
            NotHeld { weight_scale } => write!(
                f,
                "exact test: the contacts hold only {weight_scale:.3} x the weight"
            ),
            BadGrasp(m) => write!(f, "contacts are not a valid grasp: {m}"),
            NotForceClosure => write!(f, "the contacts are not in exact force closure"),
            NotHeldUnder { disturbance, scale } => write!(
                f,
                "the joints' torques balance only {scale:.3} x the disturbance {disturbance}"
            ),
            ForceLimit {
                stated,
                capability,
                link,
            } => write!(
                f,
                "force_limit {stated} N is not a usable bound (weakest finger {} can press {} N)",
                link.as_deref().unwrap_or("?"),
                capability.map_or("?".to_owned(), |c| format!("{c:.3}"))
            ),
            ObjectMismatch {
                field,
                reply,
                world,
            } => write!(f, "object {field}: reply {reply}, world {world}"),
            OffSurface { link, distance } => write!(
                f,
                "contact of {link} is {:.2} mm off the object's surface",
                distance * 1e3
            ),
            NormalMismatch { link, angle } => write!(
                f,
                "contact normal of {link} is {:.1}° off the surface normal",
                angle.to_degrees()
            ),
            LinkNotAtContact { link, distance } => write!(
                f,
                "link {link} is {:.2} mm from its contact point",
                distance * 1e3
            ),
            Penetration { link, body, depth } => {
                write!(f, "link {link} sinks {:.2} mm into {body}", depth * 1e3)
            }
            SelfCollision { link, other } => write!(f, "link {link} overlaps link {other}"),
            PalmPose { position, angle } => write!(
                f,
                "palm pose is {:.2} mm / {:.4} rad from forward kinematics",
                position * 1e3,
                angle
            ),
            JointLimit {
                joint,
                value,
                lower,
                upper,
            } => write!(f, "joint {joint} = {value} outside [{lower}, {upper}]"),
            HiddenJoint { joint, value, rest } => write!(
                f,
                "joint {joint} moved to {value} (rest {rest}) but is not in joints_used"
            ),
            BadJoints(m) => write!(f, "joint positions: {m}"),
        }
    }
}

/// What [`verify`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// Every violation; empty when the reply holds.
    pub violations: Vec<Violation>,
    /// The recomputed largest multiple of the weight the contacts balance, when
    /// the contacts make a grasp.
    pub weight_scale: Option<f64>,
    /// The weakest finger's force capability at the reply's posture (N).
    pub finger_capability: Option<f64>,
    /// The deepest link penetration found (link, body, depth in m), at any depth.
    pub deepest: Option<(String, String, f64)>,
}

impl Verdict {
    /// True when there is no violation.
    pub fn is_ok(&self) -> bool {
        self.violations.is_empty()
    }
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.violations.is_empty() {
            return write!(f, "ok");
        }
        let all: Vec<String> = self.violations.iter().map(|v| v.to_string()).collect();
        write!(f, "{}", all.join("; "))
    }
}

/// Checks `reply` against `world` with tolerances `tol`; see the module docs.
pub fn verify(world: &World, reply: &PlanReply, tol: &Tolerances) -> Verdict {
    let mut v = Verdict {
        violations: Vec::new(),
        weight_scale: None,
        finger_capability: None,
        deepest: None,
    };
    check_object_data(world, reply, tol, &mut v.violations);
    let mut weakest = None;
    match posture(world, reply, tol, &mut v.violations) {
        Some(fk) => {
            check_palm(world, reply, &fk, tol, &mut v.violations);
            check_contacts(world, reply, &fk, tol, &mut v.violations);
            weakest = weakest_finger(world, reply, &fk, &mut v.violations);
            v.finger_capability = weakest.as_ref().map(|w| w.0);
            check_penetration(world, &fk, tol, &mut v);
            check_hold(world, reply, &fk, tol, &mut v.violations);
            check_self_collision(world, &fk, &mut v.violations);
        }
        None => v.violations.push(Violation::BadJoints(
            "posture checks skipped (collision, contacts' links, palm, finger forces)".into(),
        )),
    }
    check_force_limit(reply, weakest, tol, &mut v.violations);
    match recompute_exact(world, reply) {
        Ok(scale) => {
            v.weight_scale = Some(scale);
            if scale < 1.0 {
                v.violations.push(Violation::NotHeld {
                    weight_scale: scale,
                });
            }
        }
        Err(m) => v.violations.push(Violation::BadGrasp(m)),
    }
    v
}

fn check_object_data(world: &World, reply: &PlanReply, tol: &Tolerances, out: &mut Vec<Violation>) {
    let o = &world.object;
    let differs = |a: f64, b: f64| !((a - b).abs() <= tol.relative * b.abs());
    if differs(reply.object.mass, o.mass) {
        out.push(Violation::ObjectMismatch {
            field: "mass",
            reply: reply.object.mass,
            world: o.mass,
        });
    }
    if differs(reply.mu, o.mu) {
        out.push(Violation::ObjectMismatch {
            field: "mu",
            reply: reply.mu,
            world: o.mu,
        });
    }
    let d = (Point3::from(reply.object.center_of_mass) - o.center_of_mass).norm();
    if !(d <= tol.center_of_mass) {
        out.push(Violation::ObjectMismatch {
            field: "center_of_mass",
            reply: d,
            world: 0.0,
        });
    }
}

/// Joint positions → forward kinematics, checking names, limits and `joints_used`.
fn posture(
    world: &World,
    reply: &PlanReply,
    tol: &Tolerances,
    out: &mut Vec<Violation>,
) -> Option<FkState> {
    let r = &world.robot;
    let model = &r.model;
    let mut q = model.rest_positions();
    let rest = q.clone();
    let mut usable = true;
    let mut mimics = Vec::new();
    for (name, &value) in &reply.joint_positions {
        let Ok(j) = model.joint_id(name) else {
            out.push(Violation::BadJoints(format!("unknown joint {name}")));
            usable = false;
            continue;
        };
        let joint = &model.joints[j];
        if !joint.is_movable() || !value.is_finite() {
            out.push(Violation::BadJoints(format!(
                "{name} = {value}: not a finite value of a movable joint"
            )));
            usable = false;
            continue;
        }
        if joint.mimic.is_some() {
            mimics.push((name, j, value)); // compared with its master's below
            continue;
        }
        let lim = joint.limits;
        if value < lim.lower - tol.joint || value > lim.upper + tol.joint {
            out.push(Violation::JointLimit {
                joint: name.clone(),
                value,
                lower: lim.lower,
                upper: lim.upper,
            });
        }
        let beyond_arm = !r.arm_joints.contains(&j) && !r.hand_links.contains(&joint.child);
        if beyond_arm
            && (value - rest[j]).abs() > tol.joint
            && !reply.joints_used.iter().any(|u| u == name)
        {
            out.push(Violation::HiddenJoint {
                joint: name.clone(),
                value,
                rest: rest[j],
            });
        }
        q[j] = value;
    }
    for name in &reply.joints_used {
        if model.joint_id(name).is_err() {
            out.push(Violation::BadJoints(format!(
                "joints_used names unknown joint {name}"
            )));
        }
    }
    if !usable {
        return None;
    }
    model.apply_mimics(&mut q);
    for (name, j, value) in mimics {
        if (value - q[j]).abs() > MIMIC_SLACK {
            out.push(Violation::BadJoints(format!(
                "{name} = {value} but it mimics its master, which puts it at {}",
                q[j]
            )));
            return None;
        }
    }
    let mut fk = FkState::new(model);
    model.forward_kinematics(&q, &mut fk);
    Some(fk)
}

fn check_palm(
    world: &World,
    reply: &PlanReply,
    fk: &FkState,
    tol: &Tolerances,
    out: &mut Vec<Violation>,
) {
    let Ok(stated) = pose_to_isometry(&reply.palm_pose) else {
        out.push(Violation::BadJoints("palm_pose is not a valid pose".into()));
        return;
    };
    let actual = fk.pose(world.robot.palm);
    let position = (stated.translation.vector - actual.translation.vector).norm();
    let angle = stated.rotation.angle_to(&actual.rotation);
    if !(position <= tol.palm_position && angle <= tol.palm_angle) {
        out.push(Violation::PalmPose { position, angle });
    }
}

/// The hand link a contact names, if it is one.
fn contact_link(world: &World, c: &ContactReply) -> Option<LinkId> {
    let r = &world.robot;
    r.model
        .link_id(&c.link)
        .ok()
        .filter(|l| r.hand_links.contains(l))
}

fn check_contacts(
    world: &World,
    reply: &PlanReply,
    fk: &FkState,
    tol: &Tolerances,
    out: &mut Vec<Violation>,
) {
    let o = &world.object;
    let to_object = o.pose.inverse();
    for c in &reply.contacts {
        let p = Point3::from(c.position);
        let n = Vector3::from(c.normal);
        match surface_point_within(&o.mesh, &(to_object * p), tol.normal_radius) {
            Some(s) if s.distance <= tol.surface => {
                // Inward contact normal → outward, in the object frame.
                let outward = -(to_object.rotation * n);
                let angle = angle_to_normal_cone(&outward, &s.normals);
                if !(angle <= tol.normal_angle) {
                    out.push(Violation::NormalMismatch {
                        link: c.link.clone(),
                        angle,
                    });
                }
            }
            s => out.push(Violation::OffSurface {
                link: c.link.clone(),
                distance: s.map_or(f64::INFINITY, |s| s.distance),
            }),
        }
        let gap = contact_link(world, c).map_or(f64::INFINITY, |l| link_to_point(world, fk, l, &p));
        if !(gap <= tol.contact_gap) {
            out.push(Violation::LinkNotAtContact {
                link: c.link.clone(),
                distance: gap,
            });
        }
    }
}

/// Distance (m) from a link's collision shapes to a point (0 when inside).
fn link_to_point(world: &World, fk: &FkState, link: LinkId, p: &Point3<f64>) -> f64 {
    const R: f64 = 1e-5;
    let Ok(part) = Part::from_geometry(
        &nalgebra::Isometry3::identity(),
        &Geometry::Sphere { radius: R },
    ) else {
        return f64::INFINITY;
    };
    let probe = CollisionObject::new(
        "contact point",
        nalgebra::Isometry3::translation(p.x, p.y, p.z),
        vec![part],
    );
    world
        .robot
        .collision
        .link_object_proximity(fk, link, &probe, 1.0)
        .map_or(f64::INFINITY, |prox| (prox.distance + R).max(0.0))
}

/// The smallest force any contact's finger can press with along its normal at
/// the reply's posture (`τ_max / |Jᵀ n|` over the finger's joints below the
/// palm), and that contact's link.
fn weakest_finger(
    world: &World,
    reply: &PlanReply,
    fk: &FkState,
    out: &mut Vec<Violation>,
) -> Option<(f64, String)> {
    let r = &world.robot;
    let model = &r.model;
    let mut weakest: Option<(f64, String)> = None;
    for c in &reply.contacts {
        let Some(link) = contact_link(world, c) else {
            continue; // reported by check_contacts
        };
        let joints: Vec<_> = model
            .independent_chain(link)
            .into_iter()
            .filter(|j| r.hand_links.contains(&model.joints[*j].child))
            .collect();
        if joints.is_empty() {
            continue; // the palm: the arm carries it, no finger joint limits it
        }
        let Ok(sel) = JointSelection::new(model, &joints) else {
            out.push(Violation::BadGrasp(format!(
                "finger of {}: no joints",
                c.link
            )));
            continue;
        };
        let local = fk.pose(link).inverse() * Point3::from(c.position);
        let j6 = model.jacobian(fk, link, &local, &sel);
        let j = Matrix3xX::from_fn(sel.len(), |row, k| j6[(row, k)]);
        let efforts = DVector::from_iterator(
            sel.len(),
            sel.joints.iter().map(|&k| model.joints[k].limits.effort),
        );
        match max_finger_force(&j, &efforts, &Vector3::from(c.normal)) {
            Ok(f) if weakest.as_ref().is_none_or(|(w, _)| f.force < *w) => {
                weakest = Some((f.force, c.link.clone()));
            }
            Ok(_) => {}
            Err(e) => out.push(Violation::BadGrasp(format!("finger of {}: {e}", c.link))),
        }
    }
    weakest
}

fn check_force_limit(
    reply: &PlanReply,
    weakest: Option<(f64, String)>,
    tol: &Tolerances,
    out: &mut Vec<Violation>,
) {
    let stated = reply.force_closure.force_limit;
    let usable = stated.is_finite() && stated > 0.0;
    let within = weakest
        .as_ref()
        .is_none_or(|(c, _)| stated <= c * (1.0 + tol.relative));
    if !(usable && within) {
        let (capability, link) = weakest.unzip();
        out.push(Violation::ForceLimit {
            stated,
            capability,
            link,
        });
    }
}

/// Closure and the disturbance set with the hand's own torque limits (module
/// docs); skipped, as the reply says, for a grasp checked on gravity alone.
fn check_hold(
    world: &World,
    reply: &PlanReply,
    fk: &FkState,
    tol: &Tolerances,
    out: &mut Vec<Violation>,
) {
    if reply.force_closure.disturbances == DisturbanceSet::Gravity {
        return;
    }
    let (o, model) = (&world.object, &world.robot.model);
    let hand: Vec<_> = (0..model.joints.len())
        .filter(|&j| {
            model.joints[j].is_independent()
                && world.robot.hand_links.contains(&model.joints[j].child)
        })
        .collect();
    let Ok(sel) = JointSelection::new(model, &hand) else {
        return out.push(Violation::BadGrasp("the hand has no joints".into()));
    };
    let mut contacts = Vec::new();
    let mut jacobians = Vec::new();
    for c in &reply.contacts {
        let (Some(link), Ok(contact)) = (
            contact_link(world, c),
            Contact::new(Point3::from(c.position), Vector3::from(c.normal)),
        ) else {
            return; // reported by check_contacts / recompute_exact
        };
        let local = fk.pose(link).inverse() * Point3::from(c.position);
        let j6 = model.jacobian(fk, link, &local, &sel);
        jacobians.push(Matrix3xX::from_fn(sel.len(), |row, k| j6[(row, k)]));
        contacts.push(contact);
    }
    let efforts = sel
        .joints
        .iter()
        .map(|&k| model.joints[k].limits.effort)
        .collect();
    let unlimited = vec![1e6; contacts.len()];
    let length = o.mesh.bounding_diagonal();
    let (Ok(grasp), Ok(torques)) = (
        Grasp::with_force_limits(contacts, unlimited, o.mu, length, o.center_of_mass),
        JointTorques::new(jacobians, efforts),
    ) else {
        return; // reported by recompute_exact
    };
    let g = -GRAVITY[2];
    let set = Disturbances::standard(&grasp, o.mass, g, &o.center_of_mass, tol.com_error);
    let physics = HoldOptions {
        friction_reserve: 0.0,
        require_closure: true,
        decide_up_to: None,
    };
    match hold_test(&grasp, &torques, &set, &physics) {
        Ok(v) if !v.force_closure => out.push(Violation::NotForceClosure),
        Ok(v) => {
            if let Some(i) = v.failed {
                out.push(Violation::NotHeldUnder {
                    disturbance: set.0[i].name.clone(),
                    scale: v.scales[i],
                });
            }
        }
        Err(e) => out.push(Violation::BadGrasp(e.to_string())),
    }
}

/// The exact weight test from the reply's contacts and stated force limit, with
/// the world's mass, μ and centre of mass.
fn recompute_exact(world: &World, reply: &PlanReply) -> Result<f64, String> {
    let o = &world.object;
    let contacts = reply
        .contacts
        .iter()
        .map(|c| Contact::new(Point3::from(c.position), Vector3::from(c.normal)))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    let limits = vec![reply.force_closure.force_limit; contacts.len()];
    let length = o.mesh.bounding_diagonal();
    let grasp = Grasp::with_force_limits(contacts, limits, o.mu, length, o.center_of_mass)
        .map_err(|e| e.to_string())?;
    let weight = grasp.weight_wrench(o.mass, &Vector3::from(GRAVITY), &o.center_of_mass);
    exact_weight_scale(&grasp, ConeModel::Circular, &weight)
        .map(|w| w.weight_scale)
        .map_err(|e| e.to_string())
}

fn check_self_collision(world: &World, fk: &FkState, out: &mut Vec<Violation>) {
    let r = &world.robot;
    let name = |l: LinkId| r.model.links[l].name.clone();
    out.extend(
        r.collision
            .self_collisions(fk, 0.0)
            .into_iter()
            .map(|(a, b)| Violation::SelfCollision {
                link: name(a),
                other: name(b),
            }),
    );
}

fn check_penetration(world: &World, fk: &FkState, tol: &Tolerances, v: &mut Verdict) {
    let r = &world.robot;
    let bodies = std::iter::once(&world.object.collision).chain(&world.obstacles);
    for body in bodies {
        for link in 0..r.model.links.len() {
            if r.collision.link_parts(link).is_empty() {
                continue;
            }
            let Some(prox) = r.collision.link_object_proximity(fk, link, body, 0.0) else {
                continue;
            };
            let depth = -prox.distance;
            let name = &r.model.links[link].name;
            if v.deepest.as_ref().is_none_or(|d| depth > d.2) {
                v.deepest = Some((name.clone(), body.name.clone(), depth));
            }
            if depth > tol.penetration {
                v.violations.push(Violation::Penetration {
                    link: name.clone(),
                    body: body.name.clone(),
                    depth,
                });
            }
        }
    }
}
