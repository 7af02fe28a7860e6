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
//! object) the last step is bisected so the finger ends just touching. Each
//! step's query looks only as far as a step can move the links
//! ([`crate::closing_speed`]) plus the threshold: beyond that nothing can
//! touch, so far steps cost a pruned query (a 2–3× faster closing with the
//! same contacts). A finger that reaches its joint limit without touching,
//! starts inside the object or starts farther than 0.2 m from it fails the
//! whole closing. The force limit is `min_j τ_max,j / |Jᵀn|`
//! over the finger's joints, capped by the description's `max_finger_force`
//! (the kit's `blocks::force`, the rule every planner shares).

use nalgebra::{Point3, Vector3};
use tsukami_body::collision::CollisionObject;
use tsukami_body::collision::Proximity;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{JointId, LinkId, RobotModel};
use tsukami_planner_kit::blocks::force::finger_force;

use crate::closing_speed::closing_speed;
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

/// How many steps, each moving the links by at most `per_step`, certainly
/// leave links now `distance` away farther than `range` (0 when none).
fn far_steps(distance: f64, range: f64, per_step: f64) -> usize {
    let k = ((distance - range) / per_step * (1.0 - 1e-9)).floor();
    match k.is_finite() && k > 0.0 && per_step > 0.0 {
        true => k.min(1e6) as usize,
        false => 0,
    }
}

/// Farthest a link–object query looks (m): a finger whose links are all
/// farther than this when closing starts fails, as it cannot be near a grasp.
const MAX_QUERY: f64 = 0.2;

/// One finger's closing: the contact, the links its joint moves, and how far
/// a query must look during a step.
struct Closing<'a> {
    hand: &'a HandModel,
    c: &'a ResolvedContact,
    links: Vec<LinkId>,
    object: &'a CollisionObject,
    /// The first joint whose pose a step changes: the closing joint or a
    /// joint mimicking it (forward kinematics restarts there).
    first_joint: JointId,
    /// Farthest a step moves a point of `links` ([`closing_speed`] · step).
    per_step: f64,
    /// Query range during steps: a step moves no point of `links` by more
    /// than `speed · step` ([`closing_speed`]), so a link that was outside by
    /// at least the threshold is, after the step, either farther than this
    /// from the surface (outside: nothing found, "far") or found — also when
    /// it went wholly inside a closed mesh, whose surface is then within
    /// `speed · step` of it. Far steps thus cost a pruned query, not an
    /// exact distance, with the same outcome as measuring every step.
    reach: f64,
}

impl<'a> Closing<'a> {
    /// The closing of contact `c` in steps of `step` (rad) down to `threshold`.
    fn new(
        hand: &'a HandModel,
        c: &'a ResolvedContact,
        object: &'a CollisionObject,
        threshold: f64,
        step: f64,
    ) -> Self {
        let robot = &hand.robot;
        let speed = closing_speed(robot, &hand.collision, c.joint);
        let moves = |j: usize| {
            j == c.joint
                || robot.joints[j]
                    .mimic
                    .as_ref()
                    .is_some_and(|m| m.master == c.joint)
        };
        Closing {
            hand,
            c,
            links: moved_links(hand, c.joint, c.link),
            object,
            first_joint: (0..robot.joints.len())
                .find(|&j| moves(j))
                .unwrap_or(c.joint),
            per_step: speed * step,
            reach: (speed * step + threshold).min(MAX_QUERY),
        }
    }

    /// Turns the joint from its value in `q` until a link is within
    /// `threshold` of the object (bisecting a step that went in): that link
    /// and its proximity, with `q` and `fk` at that angle. `None` when the
    /// finger starts inside the object, farther than [`MAX_QUERY`], or
    /// reaches its limit (or a full turn) without touching.
    fn touch(
        &self,
        q: &mut [f64],
        fk: &mut FkState,
        threshold: f64,
        step: f64,
    ) -> Option<(LinkId, Proximity)> {
        let mut prev = q[self.c.joint];
        let first = self.at(q, fk, prev, MAX_QUERY)?;
        if first.1.distance < 0.0 {
            return None; // starts inside the object
        }
        // Steps that cannot bring any link within the query range of the
        // first distance (each moves a point by at most `per_step`): their
        // queries would find nothing, so they are not made.
        let mut skip = far_steps(first.1.distance, self.reach, self.per_step);
        let mut near = Some(first);
        let mut angle = prev;
        // At most one turn, even for a joint without an upper limit.
        let upper = self.hand.robot.joints[self.c.joint]
            .limits
            .upper
            .min(prev + std::f64::consts::TAU);
        let near = loop {
            match near {
                Some(n) if n.1.distance < threshold => break n,
                _ if angle >= upper => return None, // closed fully without touching
                _ => {}
            }
            prev = angle;
            angle = (angle + step).min(upper);
            if skip > 0 {
                skip -= 1;
                near = None;
                continue;
            }
            near = self.at(q, fk, angle, self.reach);
        };
        // Overshot into the object: bisect the last step.
        match near.1.distance < 0.0 {
            true => self.bisect(q, fk, (prev, angle), threshold),
            false => Some(near),
        }
    }

    /// The nearest of the links to the object with the joint at `angle`,
    /// within `limit` (`None`: all farther).
    fn at(
        &self,
        q: &mut [f64],
        fk: &mut FkState,
        angle: f64,
        limit: f64,
    ) -> Option<(LinkId, Proximity)> {
        q[self.c.joint] = angle;
        self.hand.robot.apply_mimics(q);
        self.hand
            .robot
            .forward_kinematics_from(q, fk, self.first_joint);
        self.links
            .iter()
            .filter_map(|&l| {
                self.hand
                    .collision
                    .link_object_proximity(fk, l, self.object, limit)
                    .map(|p| (l, p))
            })
            .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance))
    }

    /// Bisects the step `(lo, hi)` whose end went into the object: the angle
    /// and proximity where the finger is within `threshold` and outside.
    fn bisect(
        &self,
        q: &mut [f64],
        fk: &mut FkState,
        (mut lo, mut hi): (f64, f64),
        threshold: f64,
    ) -> Option<(LinkId, Proximity)> {
        let mut best = None;
        for _ in 0..16 {
            let mid = 0.5 * (lo + hi);
            let d = self
                .at(q, fk, mid, self.reach)
                .map_or(f64::INFINITY, |p| p.1.distance);
            if d < 0.0 {
                hi = mid;
            } else {
                best = Some((mid, d));
                if d < threshold {
                    break;
                }
                lo = mid;
            }
        }
        let (a, d) = best?;
        if d >= threshold {
            return None;
        }
        self.at(q, fk, a, self.reach)
    }
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
    let closing = Closing::new(hand, c, object, threshold, step);
    // `fk` matches `q` from here on, but for the joints a step moves.
    hand.robot.forward_kinematics(q, fk);
    let (link, prox) = closing.touch(q, fk, threshold, step)?;
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

#[cfg(test)]
mod tests {
    use super::far_steps;

    #[test]
    fn far_steps_are_exactly_those_that_stay_out_of_range() {
        // The first finger of the fridge scene: 30.3 mm away, a query range
        // of 7.8 mm, 5.8 mm a step at most: steps 1–3 cannot come in range.
        assert_eq!(far_steps(0.0303, 0.0078, 0.0058), 3);
        for (d, r, m) in [(0.05, 0.004, 0.001), (0.01, 0.002, 0.003), (0.2, 0.2, 0.01)] {
            let k = far_steps(d, r, m) as f64;
            assert!(d - k * m > r || k == 0.0, "{d} {r} {m}: {k}");
            // The next step might come in range: it is queried.
            assert!(d - (k + 1.0) * m <= r + 1e-12, "{d} {r} {m}: {k}");
        }
        assert_eq!(far_steps(0.001, 0.002, 0.001), 0);
        assert_eq!(far_steps(0.05, 0.002, 0.0), 0);
        assert_eq!(far_steps(f64::NAN, 0.002, 0.001), 0);
        assert_eq!(far_steps(f64::INFINITY, 0.002, 0.001), 0);
    }
}
