//! How fast a closing joint can move a finger's surface: the bound behind
//! conservative advancement in finger closing.
//!
//! What: [`closing_speed`] returns `R` such that turning the closing joint by
//! `Δθ` moves no point of any link it moves (its subtree and the subtrees of
//! the joints mimicking it) by more than `R·|Δθ|`.
//!
//! Why: finger closing ([`crate::finger_closing`]) steps a joint by a fixed
//! angle and measures the distance after each step. A step of `Δθ` moves the
//! fingers by at most `R·Δθ`, so a query need only look that far (plus the
//! contact threshold) to see every link that could have reached, or gone
//! through, the surface: the far steps cost a pruned query instead of an
//! exact distance, with the same result.
//!
//! How: a point `p` moved by joints `j` at rates `m_j` (1 for the closing
//! joint, the mimic multiplier for a follower) has speed
//! `|Σ m_j ω_j × (p − o_j)| ≤ Σ |m_j| |p − o_j|` for revolute joints and
//! `|m_j|` for prismatic ones. `|p − o_j|` is bounded, whatever the other
//! joints' angles, by the link's [`reach`]: the farthest corner of its
//! collision parts' boxes, or a child joint's offset (plus its travel when
//! prismatic) plus that child's reach, by the triangle inequality.
//!
//! ```
//! use std::path::Path;
//! use tsukami_body::{collision::RobotCollision, urdf::load_urdf};
//! use tsukami_grasp_planner::closing_speed::closing_speed;
//!
//! let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/robots/tsukami_humanoid");
//! let model = load_urdf(&root.join("tsukami_humanoid.urdf")).unwrap();
//! let collision = RobotCollision::new(&model).unwrap();
//! let j = model.joint_id("r_index_j2").unwrap();
//! let r = closing_speed(&model, &collision, j);
//! // An index finger is a few centimetres long: its tip moves a few cm per rad.
//! assert!(r > 0.02 && r < 0.2, "{r}");
//! ```

use tsukami_body::collision::RobotCollision;
use tsukami_body::convert::to_vector;
use tsukami_body::model::{JointId, JointKind, LinkId, RobotModel};

/// Upper bound of `|p − o|` over every collision point `p` of `link` and of
/// the links below it, `o` being `link`'s frame origin, for any joint angles.
pub fn reach(model: &RobotModel, collision: &RobotCollision, link: LinkId) -> f64 {
    let own = collision
        .link_parts(link)
        .iter()
        .map(|part| {
            let aabb = part.shape.compute_aabb(&part.origin);
            let (lo, hi) = (to_vector(aabb.mins), to_vector(aabb.maxs));
            lo.abs().sup(&hi.abs()).norm()
        })
        .fold(0.0, f64::max);
    model.links[link]
        .children
        .iter()
        .filter_map(|&child| {
            let j = model.links[child].parent_joint?;
            let joint = &model.joints[j];
            let travel = match joint.kind {
                JointKind::Prismatic => joint.limits.lower.abs().max(joint.limits.upper.abs()),
                _ => 0.0,
            };
            let travel = if travel.is_finite() {
                travel
            } else {
                f64::INFINITY
            };
            Some(joint.origin.translation.vector.norm() + travel + reach(model, collision, child))
        })
        .fold(own, f64::max)
}

/// The speed bound `R` (m per rad, or per m for a prismatic closing joint) of
/// every point moved by `joint` and its mimics. Infinite when a moved link is
/// unbounded (e.g. an unlimited prismatic joint below it).
pub fn closing_speed(model: &RobotModel, collision: &RobotCollision, joint: JointId) -> f64 {
    model
        .joints
        .iter()
        .enumerate()
        .filter_map(|(j, jt)| {
            if j == joint {
                return Some((jt, 1.0));
            }
            let m = jt.mimic.as_ref().filter(|m| m.master == joint)?;
            Some((jt, m.master_multiplier.abs()))
        })
        .map(|(jt, rate)| match jt.kind {
            JointKind::Prismatic => rate,
            JointKind::Fixed => 0.0,
            _ => rate * reach(model, collision, jt.child),
        })
        .sum()
}
