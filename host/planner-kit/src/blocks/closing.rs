//! Closing a finger onto the object (the paper's section 3.5 closes fingers
//! the same way).
//!
//! What: [`close_finger`] flexes a finger's `flex` joints together, in steps,
//! until one of its links is within the hand's contact distance of the object
//! (bisecting back when a step goes into it), and returns the contact with the
//! finger's force limit.
//!
//! Why: every planner that places a palm needs to know where the fingers
//! really touch; the answer depends only on the hand and the object.

use tsukami_body::collision::{CollisionObject, Proximity};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::LinkId;

use crate::blocks::force::finger_force;
use crate::grasp::FingerContact;
use crate::robot::{Finger, Hand, Robot};

/// Joint step while closing, rad.
pub const STEP: f64 = 0.04;

fn nearest(
    hand: &Hand,
    fk: &FkState,
    finger: &Finger,
    object: &CollisionObject,
) -> Option<(LinkId, Proximity)> {
    finger
        .links
        .iter()
        .filter_map(|&l| {
            hand.collision
                .link_object_proximity(fk, l, object, 0.1)
                .map(|p| (l, p))
        })
        .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance))
}

/// Flexes `finger` from `q` (changed in place; `fk` holds the link poses
/// afterwards) until it touches `object`; `None` when it reaches its limits
/// without touching, starts inside the object, or can press with no force.
pub fn close_finger(
    robot: &Robot,
    hand: &Hand,
    finger: &Finger,
    q: &mut [f64],
    fk: &mut FkState,
    object: &CollisionObject,
) -> Option<FingerContact> {
    let model = &robot.model;
    let start: Vec<f64> = finger.flex.iter().map(|&j| q[j]).collect();
    let span = finger
        .flex
        .iter()
        .zip(&start)
        .map(|(&j, &q0)| model.joints[j].limits.upper - q0)
        .fold(0.0, f64::max);
    let at = |q: &mut [f64], fk: &mut FkState, delta: f64| {
        for (&j, &q0) in finger.flex.iter().zip(&start) {
            let lim = model.joints[j].limits;
            q[j] = (q0 + delta).clamp(lim.lower, lim.upper);
        }
        model.apply_mimics(q);
        model.forward_kinematics(q, fk);
        nearest(hand, fk, finger, object)
    };
    let touching = |p: &Proximity| p.distance < hand.contact_distance;
    let first = at(q, fk, 0.0)?;
    if first.1.distance < 0.0 {
        return None;
    }
    let (mut lo, mut delta, mut inside) = (0.0, 0.0, None);
    let mut touch = touching(&first.1).then_some(first);
    while touch.is_none() && delta < span {
        delta = (delta + STEP).min(span);
        let (l, p) = at(q, fk, delta)?;
        if p.distance < 0.0 {
            inside = Some(delta);
            break;
        }
        if touching(&p) {
            touch = Some((l, p));
        } else {
            lo = delta;
        }
    }
    if let Some(mut hi) = inside {
        for _ in 0..12 {
            let mid = 0.5 * (lo + hi);
            let (l, p) = at(q, fk, mid)?;
            if p.distance < 0.0 {
                hi = mid;
            } else if touching(&p) {
                touch = Some((l, p));
                break;
            } else {
                lo = mid;
            }
        }
    }
    let (link, prox) = touch?;
    let normal = -prox.normal.into_inner();
    let point = prox.point_on_object;
    let f_max = finger_force(
        model,
        fk,
        &finger.joints,
        link,
        &point,
        &normal,
        hand.max_finger_force,
    );
    (f_max > 0.0).then_some(FingerContact {
        link,
        position: point,
        normal,
        f_max,
    })
}

/// Closes `fingers` (indices into the hand's fingers) one after the other from
/// `q`; the contacts, or `None` when one closes without touching.
pub fn close_fingers(
    robot: &Robot,
    hand: &Hand,
    fingers: &[usize],
    q: &mut [f64],
    fk: &mut FkState,
    object: &CollisionObject,
) -> Option<Vec<FingerContact>> {
    fingers
        .iter()
        .map(|&f| close_finger(robot, hand, &hand.fingers[f], q, fk, object))
        .collect()
}
