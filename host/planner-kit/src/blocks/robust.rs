//! Robust to the object's pose: the hold test repeated with the object moved.
//!
//! What: [`pose_robustness`] moves the object by each of the request's
//! sampled pose errors ([`pose_errors`]: a shift of the centre of mass of up
//! to `position` and a turn about it of up to `rotation_deg`), re-closes the
//! fingers that carried contacts on the moved object, and repeats the one
//! hold rule ([`crate::blocks::hold::holds_under`]); it counts the errors
//! under which the grasp still holds.
//!
//! Why: vision puts the object a few millimetres and degrees from where it
//! is. A grasp that holds only at the nominal pose is dropped by the robot
//! that executes it; the physics benchmark's pose-noise variant measures
//! exactly this.
//!
//! How: the errors come from a ChaCha8 generator seeded by the plan's seed, so
//! every candidate of one plan, and every machine, sees the same errors. The
//! hand's palm stays where it was planned (the arm does not know the error).
//! Each finger with a contact is opened by [`OPEN`] on its flexing joints (less
//! when a joint's limit is nearer: one opening for all, so closing them
//! together retraces the path) and closed again ([`crate::blocks::closing::close_finger`]); fingers without a
//! contact stay. For a grasp type with palm contact, the fingers pull the
//! object onto the palm: the moved object first slides along the approach
//! until it touches the palm, and the palm is a contact again.
//!
//! ```
//! use tsukami_msgs::planner::PoseError;
//! use tsukami_planner_kit::blocks::robust::pose_errors;
//! let e = PoseError::default();
//! let errs = pose_errors(&e, 7);
//! assert_eq!(errs.len(), 8);
//! assert_eq!(errs, pose_errors(&e, 7)); // the same seed, the same errors
//! assert!(errs.iter().all(|x| x.shift.norm() <= 0.003 && x.turn.angle() <= 3f64.to_radians()));
//! ```

use nalgebra::{Isometry3, Point3, Translation3, Unit, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tsukami_body::collision::CollisionObject;
use tsukami_body::kinematics::FkState;
use tsukami_msgs::planner::{HoldRequest, PoseError, PoseRobustness};

use crate::blocks::closing::close_finger;
use crate::blocks::hold::{holds_under, HoldContact, HoldProblem};
use crate::grasp::FingerContact;
use crate::object::Object;
use crate::robot::{Finger, Hand, Robot};
use tsukami_body::model::{JointId, LinkId, RobotModel};

/// How far (rad) each contact finger's flexing joints open before it closes
/// again on the moved object.
pub const OPEN: f64 = 0.2;

/// Farthest (m) the object may lie from the palm for the fingers to pull it
/// onto it.
pub const PALM_REACH: f64 = 0.03;

/// One sampled pose error: the centre of mass shifted by `shift` (world) and
/// the object turned by `turn` about it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseErrorSample {
    /// Shift of the centre of mass, m (world frame).
    pub shift: Vector3<f64>,
    /// Turn about the centre of mass (world frame).
    pub turn: UnitQuaternion<f64>,
}

impl PoseErrorSample {
    /// The rigid motion of the world this error applies to the object whose
    /// centre of mass is at `com`: `p ↦ com + shift + turn (p − com)`.
    pub fn motion(&self, com: &Point3<f64>) -> Isometry3<f64> {
        let t = com.coords + self.shift - self.turn * com.coords;
        Isometry3::from_parts(Translation3::from(t), self.turn)
    }
}

/// A direction uniform on the sphere (rejection from the cube).
fn unit(rng: &mut ChaCha8Rng) -> Unit<Vector3<f64>> {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..=1.0),
            rng.random_range(-1.0..=1.0),
            rng.random_range(-1.0..=1.0),
        );
        let n = v.norm();
        if n > 1e-3 && n <= 1.0 {
            return Unit::new_unchecked(v / n);
        }
    }
}

/// The request's errors, drawn from `seed`: each a shift of uniform length
/// up to `position` in a uniform direction and a turn of uniform angle up to
/// `rotation_deg` about a uniform axis.
pub fn pose_errors(err: &PoseError, seed: u64) -> Vec<PoseErrorSample> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x7053_655f_4572_7273);
    (0..err.samples)
        .map(|_| {
            let shift = unit(&mut rng).into_inner() * rng.random_range(0.0..=err.position);
            let axis = unit(&mut rng);
            let angle = rng.random_range(0.0..=err.rotation_deg.to_radians());
            PoseErrorSample {
                shift,
                turn: UnitQuaternion::from_axis_angle(&axis, angle),
            }
        })
        .collect()
}

/// Threads the re-check uses at most (the caller's and three more).
const MAX_WORKERS: usize = 4;

/// What the re-check needs besides the grasp.
pub struct RobustProblem<'a> {
    /// The robot.
    pub robot: &'a Robot,
    /// The grasping hand.
    pub hand: &'a Hand,
    /// The object at its planned pose.
    pub object: &'a Object,
    /// Torque scale length, m.
    pub length: f64,
    /// For a grasp type with palm contact, the approach direction (world,
    /// palm toward object) along which the fingers pull the object onto the
    /// palm; `None` otherwise.
    pub palm_approach: Option<Vector3<f64>>,
    /// The grasp type's closing joints (its contacts' `joint`s, in order),
    /// closed again one by one as the planner closed them; when empty, every
    /// finger with a contact closes by all its flexing joints.
    pub closing: Vec<JointId>,
}

/// How many of the request's pose errors (`req.pose_error`, drawn from
/// `seed`) the grasp of posture `q` and `contacts` still holds under.
pub fn pose_robustness(
    p: &RobustProblem<'_>,
    q: &[f64],
    contacts: &[FingerContact],
    req: &HoldRequest,
    seed: u64,
) -> PoseRobustness {
    let errors = pose_errors(&req.pose_error, seed);
    let count = |errs: &[PoseErrorSample]| {
        errs.iter()
            .filter(|e| holds_moved(p, q, contacts, e, req))
            .count()
    };
    // The errors are independent: split over the machine's cores (a count,
    // so the answer does not depend on how they are split).
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, MAX_WORKERS)
        .min(errors.len().max(1));
    let chunk = errors.len().div_ceil(workers).max(1);
    let held: usize = std::thread::scope(|s| {
        let mut parts = errors.chunks(chunk);
        let first = parts.next().unwrap_or(&[]);
        let others: Vec<_> = parts.map(|c| s.spawn(move || count(c))).collect();
        let mine = count(first);
        mine + others
            .into_iter()
            .map(|h| h.join().unwrap_or(0))
            .sum::<usize>()
    });
    PoseRobustness {
        samples: errors.len() as u32,
        held: held as u32,
    }
}

/// The object moved by `err`, slid onto the palm when the type asks for
/// palm contact; the moved collision body and centre of mass.
fn moved_object(
    p: &RobustProblem<'_>,
    fk: &FkState,
    err: &PoseErrorSample,
) -> Option<(CollisionObject, Point3<f64>)> {
    let com = p.object.center_of_mass;
    let m = err.motion(&com);
    let mut body = p.object.collision.clone();
    body.set_pose(m * body.pose());
    let mut com = m * com;
    if let Some(a) = p.palm_approach {
        let near = p
            .hand
            .collision
            .link_object_proximity(fk, p.hand.palm, &body, PALM_REACH)?;
        // The object slides against the approach; the gap closes by the part
        // of the slide along the separating normal.
        let along = near.normal.dot(&-a).max(0.3);
        let slide = Translation3::from(-a * (near.distance / along));
        body.set_pose(slide * body.pose());
        com = slide * com;
    }
    Some((body, com))
}

/// Whether the grasp still holds with the object moved by `err`.
fn holds_moved(
    p: &RobustProblem<'_>,
    q: &[f64],
    contacts: &[FingerContact],
    err: &PoseErrorSample,
    req: &HoldRequest,
) -> bool {
    let (model, hand) = (&p.robot.model, p.hand);
    let mut fk = FkState::new(model);
    model.forward_kinematics(q, &mut fk);
    let Some((body, com)) = moved_object(p, &fk, err) else {
        return false;
    };
    let closers = closers(p, contacts);
    let mut q = q.to_vec();
    for c in &closers {
        // One opening for all of a closer's joints (as far as the nearest
        // limit allows), so closing them together retraces the same path.
        let open = c
            .flex
            .iter()
            .map(|&j| q[j] - model.joints[j].limits.lower)
            .fold(OPEN, f64::min)
            .max(0.0);
        for &j in &c.flex {
            q[j] -= open;
        }
    }
    model.apply_mimics(&mut q);
    let mut moved = Vec::with_capacity(contacts.len());
    for c in &closers {
        match close_finger(p.robot, hand, c, &mut q, &mut fk, &body) {
            Some(c) => moved.push((c.link, c.position, c.normal)),
            None => return false,
        }
    }
    model.forward_kinematics(&q, &mut fk);
    if p.palm_approach.is_some() {
        match palm_contact(hand, &fk, &body) {
            Some(c) => moved.push(c),
            None => return false,
        }
    }
    let problem = HoldProblem {
        model,
        fk: &fk,
        joints: &hand.joints,
        cap: hand.max_finger_force,
        mass: p.object.mass,
        mu: p.object.mu,
        com,
        length: p.length,
        servo_saturation: hand.servo_saturation,
    };
    holds_under(&problem, &moved, req).is_ok()
}

/// What closes again, in order, each as a [`Finger`] whose `flex` joints
/// close together and whose `links` are what they move: each closing joint
/// of the grasp type that lies on a finger (the links below it and below
/// the joints that mimic it), as the planner closed it; without such joints,
/// every finger that carries a contact, by all its flexing joints.
fn closers(p: &RobustProblem<'_>, contacts: &[FingerContact]) -> Vec<Finger> {
    let (model, hand) = (&p.robot.model, p.hand);
    let by_joint: Vec<Finger> = p
        .closing
        .iter()
        .filter_map(|&j| {
            let on = |f: &&Finger| f.joints.contains(&j) || f.flex.contains(&j);
            let f = hand.fingers.iter().find(on)?;
            let links = f
                .links
                .iter()
                .copied()
                .filter(|&l| moved_by(model, j, l))
                .collect();
            Some(Finger {
                flex: vec![j],
                links,
                ..f.clone()
            })
        })
        .collect();
    if !by_joint.is_empty() {
        return by_joint;
    }
    hand.fingers
        .iter()
        .filter(|f| contacts.iter().any(|c| f.links.contains(&c.link)))
        .cloned()
        .collect()
}

/// Whether joint `j` (or a joint mimicking it) lies between link `l` and the root.
fn moved_by(model: &RobotModel, j: JointId, l: LinkId) -> bool {
    let mut at = model.links[l].parent_joint;
    while let Some(k) = at {
        let joint = &model.joints[k];
        if k == j || joint.mimic.as_ref().is_some_and(|m| m.master == j) {
            return true;
        }
        at = model.links[joint.parent].parent_joint;
    }
    false
}

/// The palm as a contact when it touches `body` (within the contact distance,
/// at most 1 mm inside): the nearest point, the palm's push as the normal.
fn palm_contact(hand: &Hand, fk: &FkState, body: &CollisionObject) -> Option<HoldContact> {
    let near = hand
        .collision
        .link_object_proximity(fk, hand.palm, body, hand.contact_distance)?;
    (near.distance > -1e-3 && near.distance < hand.contact_distance)
        .then(|| (hand.palm, near.point_on_object, -near.normal.into_inner()))
}
