//! Moving the arms out of the camera's view of the object.
//!
//! What: [`Looker::clear_arm`] moves the joints that carry the links hiding
//! the target, but not the camera, until none hides it — and those of links
//! that would collide in the look's posture.
//!
//! Why: the arm hangs beside the body at rest; when the robot bends or
//! turns to look down at something on its own side, the arm comes into the
//! picture in front of the object; when it crouches and leans, the hanging
//! hand meets its own legs.
//!
//! How: a coordinate search, deterministic and bounded: the joint nearest the
//! root among those moving the link that hides the most, else a colliding
//! one (the shoulder before the elbow, the elbow before the fingers), set to the one of
//! [`ARM_STEPS`]` + 1` evenly spaced values across its limits that hides the
//! least — ties to the one nearest rest — among the postures the robot may
//! take ([`Looker::allowed`]: no link into an obstacle, no self-collision
//! beyond the rest posture's); then the next such joint, at most
//! [`ARM_JOINTS`] of them.

use tsukami_body::model::{JointId, LinkId};

use super::sight::Hidden;
use super::{Looker, Target};

/// Most joints one arm clearing moves.
pub const ARM_JOINTS: usize = 3;

/// Steps across a joint's range tried when clearing the arm.
pub const ARM_STEPS: usize = 8;

impl Looker {
    /// Moves arm joints in `q` so that no link hides `target` and the
    /// posture may be taken, as far as [`ARM_JOINTS`] joints can; returns
    /// what is still hidden.
    pub fn clear_arm(&self, q: &mut [f64], target: &Target) -> Hidden {
        let mut hidden = self.hidden(q, target);
        let mut moved: Vec<JointId> = Vec::new();
        while moved.len() < ARM_JOINTS {
            let colliding = self.colliding(q);
            if hidden.hidden == 0 && colliding.is_empty() {
                break;
            }
            let links = hidden
                .by_link
                .iter()
                .map(|&(l, _)| l)
                .chain(colliding.iter().copied());
            let Some(j) = self.arm_joint(links, &moved) else {
                break;
            };
            moved.push(j);
            if let Some((value, h)) = self.best_value(q, j, target) {
                if !colliding.is_empty() || h.hidden < hidden.hidden {
                    q[j] = value;
                    hidden = h;
                }
            }
        }
        hidden
    }

    /// Of [`ARM_STEPS`]` + 1` values of joint `j` across its limits, the
    /// posture may be taken with, the one hiding the least of `target`, ties
    /// to the nearest rest; with what it hides.
    fn best_value(&self, q: &[f64], j: JointId, target: &Target) -> Option<(f64, Hidden)> {
        let rest = self.rest[j];
        let l = self.head.robot.joints[j].limits;
        let pi = std::f64::consts::PI;
        let (lo, hi) = (l.lower.max(-pi), l.upper.min(pi));
        let mut best: Option<((usize, f64), f64, Hidden)> = None;
        for i in 0..=ARM_STEPS {
            let value = lo + (hi - lo) * i as f64 / ARM_STEPS as f64;
            let mut trial = q.to_vec();
            trial[j] = value;
            if !self.allowed(&trial) {
                continue;
            }
            let h = self.hidden(&trial, target);
            let key = (h.hidden, (value - rest).abs());
            if best
                .as_ref()
                .is_none_or(|b| key.0 < b.0 .0 || (key.0 == b.0 .0 && key.1 < b.0 .1))
            {
                best = Some((key, value, h));
            }
        }
        best.map(|(_, value, h)| (value, h))
    }

    /// The joint to move next: the first from the root that moves one of
    /// `links` (in the order given), not the camera, and was not moved yet.
    fn arm_joint(
        &self,
        links: impl IntoIterator<Item = LinkId>,
        moved: &[JointId],
    ) -> Option<JointId> {
        let robot = &self.head.robot;
        links.into_iter().find_map(|link| {
            robot
                .independent_chain(link)
                .into_iter()
                .find(|&j| !self.head.carries_camera(j) && !moved.contains(&j))
        })
    }
}
