//! Finger closing (section 3.5): turn each contacting link's joint by a fixed
//! step until the link is within a distance threshold of the object.
//!
//! What: [`close_fingers`] closes the contacts of one grasp type in turn and
//! returns, per contact, the contact point on the object, the inward normal
//! and the largest force the finger can press with there.
//!
//! Why: this is the paper's way of finding the finger posture — cheap, and
//! good enough because the reference posture already shapes the hand; PQP's
//! distance, witness points and normals are parry's here (`tsukami-body`).
//!
//! How: the assigned joint moves toward its upper limit by the closing step;
//! when the distance falls under the threshold (or the link overshoots into
//! the object) the last step is bisected so the link ends just touching. A
//! finger that reaches its joint limit without touching, or starts inside the
//! object, fails the whole closing. The force limit is `min_j τ_max,j / |Jᵀn|`
//! over the finger's joints (`tsukami-grasp`).

use nalgebra::{DVector, Matrix3xX, Point3, Vector3};
use tsukami_body::collision::CollisionObject;
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::model::LinkId;
use tsukami_grasp::finger_force::max_finger_force;

use crate::hand::{HandModel, ResolvedContact};

/// Cap on a finger's force when no joint limits it (N).
pub const MAX_FINGER_FORCE: f64 = 100.0;

/// One finger contact, world frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FingerContact {
    /// The contacting link.
    pub link: LinkId,
    /// Contact point on the object's surface.
    pub position: Point3<f64>,
    /// Unit normal pointing into the object.
    pub normal: Vector3<f64>,
    /// Largest normal force the finger can apply (N).
    pub f_max: f64,
    /// Link–object distance at the end of closing (m).
    pub distance: f64,
}

/// Closes the fingers of grasp type `t` from the hand posture in `q` (updated
/// in place). `fk` holds scratch poses; on return it matches `q`.
pub fn close_fingers(
    hand: &HandModel,
    t: usize,
    q: &mut [f64],
    fk: &mut FkState,
    object: &CollisionObject,
    threshold: f64,
    step: f64,
) -> Option<Vec<FingerContact>> {
    let spec = &hand.types[t];
    let mut out = Vec::with_capacity(spec.contacts.len());
    for c in &spec.contacts {
        out.push(close_one(hand, c, q, fk, object, threshold, step)?);
    }
    hand.robot.forward_kinematics(q, fk);
    Some(out)
}

fn distance_at(
    hand: &HandModel,
    c: &ResolvedContact,
    q: &mut [f64],
    fk: &mut FkState,
    object: &CollisionObject,
    angle: f64,
) -> Option<tsukami_body::collision::Proximity> {
    q[c.joint] = angle;
    hand.robot.apply_mimics(q);
    hand.robot.forward_kinematics(q, fk);
    hand.collision
        .link_object_proximity(fk, c.link, object, 0.2)
}

fn close_one(
    hand: &HandModel,
    c: &ResolvedContact,
    q: &mut [f64],
    fk: &mut FkState,
    object: &CollisionObject,
    threshold: f64,
    step: f64,
) -> Option<FingerContact> {
    let upper = hand.robot.joints[c.joint].limits.upper;
    let mut prev = q[c.joint];
    let first = distance_at(hand, c, q, fk, object, prev)?;
    if first.distance < 0.0 {
        return None; // starts inside the object
    }
    let mut prox = first;
    let mut angle = prev;
    // At most one turn, even for a joint without an upper limit.
    let upper = upper.min(prev + std::f64::consts::TAU);
    while prox.distance >= threshold {
        if angle >= upper {
            return None; // closed fully without touching
        }
        prev = angle;
        angle = (angle + step).min(upper);
        prox = distance_at(hand, c, q, fk, object, angle)?;
    }
    // Overshot into the object: bisect the last step.
    if prox.distance < 0.0 {
        let (mut lo, mut hi) = (prev, angle);
        let mut best = None;
        for _ in 0..12 {
            let mid = 0.5 * (lo + hi);
            let p = distance_at(hand, c, q, fk, object, mid)?;
            if p.distance < 0.0 {
                hi = mid;
            } else {
                best = Some((mid, p));
                if p.distance < threshold {
                    break;
                }
                lo = mid;
            }
        }
        let (a, p) = best?;
        if p.distance >= threshold {
            return None;
        }
        prox = distance_at(hand, c, q, fk, object, a)?;
    }
    let normal = -prox.normal.into_inner();
    let f_max = finger_force(hand, c, fk, &prox.point_on_object, &normal);
    Some(FingerContact {
        link: c.link,
        position: prox.point_on_object,
        normal,
        f_max,
        distance: prox.distance,
    })
}

/// Largest normal force the finger of `c` can press with at `point` along `normal`.
fn finger_force(
    hand: &HandModel,
    c: &ResolvedContact,
    fk: &FkState,
    point: &Point3<f64>,
    normal: &Vector3<f64>,
) -> f64 {
    let Ok(sel) = JointSelection::new(&hand.robot, &c.finger_joints) else {
        return MAX_FINGER_FORCE;
    };
    let local = fk.pose(c.link).inverse() * point;
    let j6 = hand.robot.jacobian(fk, c.link, &local, &sel);
    let j = Matrix3xX::from_fn(sel.len(), |r, k| j6[(r, k)]);
    let efforts = DVector::from_iterator(
        sel.len(),
        sel.joints
            .iter()
            .map(|&jid| hand.robot.joints[jid].limits.effort),
    );
    match max_finger_force(&j, &efforts, normal) {
        Ok(f) => f.force.min(MAX_FINGER_FORCE),
        Err(_) => 0.0,
    }
}
