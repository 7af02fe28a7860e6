//! Finger closing (section 3.5): turn each contacting link's joint by a fixed
//! step until the finger is within a distance threshold of the object.
//!
//! What: [`close_fingers`] closes the contacts of one grasp type in turn and
//! returns, per contact, the touching link, the contact point on the object,
//! the inward normal and the largest force the finger can press with there.
//!
//! Why: this is the paper's way of finding the finger posture — cheap, and
//! good enough because the reference posture already shapes the hand; PQP's
//! distance, witness points and normals are parry's here (`tsukami-body`).
//! Every link the closing joint moves stops at contact, not only the named
//! contact link: a middle phalanx that meets the object before the fingertip
//! stops the finger there (and is the contact), it never sinks in.
//!
//! How: the assigned joint moves toward its upper limit by the closing step;
//! after each step the nearest of the links it moves ([`moved_links`]: the
//! joint's subtree and the subtrees of joints mimicking it) is measured; when
//! that distance falls under the threshold (or a link overshoots into the
//! object) the last step is bisected so the finger ends just touching. A
//! finger that reaches its joint limit without touching, or starts inside the
//! object, fails the whole closing. The force limit is `min_j τ_max,j / |Jᵀn|`
//! over the finger's joints, capped by the description's `max_finger_force`
//! (the kit's `blocks::force`, the rule every planner shares).

use nalgebra::{Point3, Vector3};
use tsukami_body::collision::CollisionObject;
use tsukami_body::collision::Proximity;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{JointId, LinkId, RobotModel};
use tsukami_planner_kit::blocks::force::finger_force;

use crate::hand::{HandModel, ResolvedContact};

/// One finger contact, world frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FingerContact {
    /// The touching link (the contact's link, or another link of the same
    /// finger that met the object first).
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

/// The links, with collision geometry, that `joint` moves: its child's
/// subtree and the subtrees of the joints that mimic it. `first` comes first.
pub fn moved_links(hand: &HandModel, joint: JointId, first: LinkId) -> Vec<LinkId> {
    let robot: &RobotModel = &hand.robot;
    let mut stack: Vec<LinkId> = vec![robot.joints[joint].child];
    for j in &robot.joints {
        if j.mimic.as_ref().is_some_and(|m| m.master == joint) {
            stack.push(j.child);
        }
    }
    let mut out = vec![first];
    while let Some(l) = stack.pop() {
        if !out.contains(&l) && !hand.collision.link_parts(l).is_empty() {
            out.push(l);
        }
        stack.extend(robot.links[l].children.iter().copied());
    }
    out.retain(|&l| !hand.collision.link_parts(l).is_empty());
    out
}

/// The nearest of `links` to the object with the joint of `c` at `angle`.
fn distance_at(
    hand: &HandModel,
    c: &ResolvedContact,
    links: &[LinkId],
    q: &mut [f64],
    fk: &mut FkState,
    object: &CollisionObject,
    angle: f64,
) -> Option<(LinkId, Proximity)> {
    q[c.joint] = angle;
    hand.robot.apply_mimics(q);
    hand.robot.forward_kinematics(q, fk);
    links
        .iter()
        .filter_map(|&l| {
            hand.collision
                .link_object_proximity(fk, l, object, 0.2)
                .map(|p| (l, p))
        })
        .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance))
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
    let links = moved_links(hand, c.joint, c.link);
    let upper = hand.robot.joints[c.joint].limits.upper;
    let mut prev = q[c.joint];
    let first = distance_at(hand, c, &links, q, fk, object, prev)?;
    if first.1.distance < 0.0 {
        return None; // starts inside the object
    }
    let mut near = first;
    let mut angle = prev;
    // At most one turn, even for a joint without an upper limit.
    let upper = upper.min(prev + std::f64::consts::TAU);
    while near.1.distance >= threshold {
        if angle >= upper {
            return None; // closed fully without touching
        }
        prev = angle;
        angle = (angle + step).min(upper);
        near = distance_at(hand, c, &links, q, fk, object, angle)?;
    }
    // Overshot into the object: bisect the last step.
    if near.1.distance < 0.0 {
        let (mut lo, mut hi) = (prev, angle);
        let mut best = None;
        for _ in 0..16 {
            let mid = 0.5 * (lo + hi);
            let p = distance_at(hand, c, &links, q, fk, object, mid)?;
            if p.1.distance < 0.0 {
                hi = mid;
            } else {
                best = Some((mid, p.1.distance));
                if p.1.distance < threshold {
                    break;
                }
                lo = mid;
            }
        }
        let (a, d) = best?;
        if d >= threshold {
            return None;
        }
        near = distance_at(hand, c, &links, q, fk, object, a)?;
    }
    let (link, prox) = near;
    let normal = -prox.normal.into_inner();
    // The kit's one rule: the effort limit through the finger's Jacobian,
    // capped by the description's `max_finger_force`, 0 N if not computable.
    let f_max = finger_force(
        &hand.robot,
        fk,
        &c.finger_joints,
        link,
        &prox.point_on_object,
        &normal,
        hand.max_finger_force,
    );
    Some(FingerContact {
        link,
        position: prox.point_on_object,
        normal,
        f_max,
        distance: prox.distance,
    })
}
