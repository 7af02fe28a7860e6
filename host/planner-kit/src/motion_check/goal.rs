//! The grasp a motion ends in: the posture closed and open, the palm, the
//! approach, and the joints each phase moves.
//!
//! What: a [`Goal`] is what the phase checks ([`super::phases`]) and the
//! trajectory planner need of a grasp: the joints the reach, approach and lift
//! move, the hand's joints, the grasp posture with the hand closed and open,
//! the palm pose, the approach direction and the grasp type's closing order.
//! [`Goal::new`] builds one from a full joint vector, a grasp type and an
//! approach direction ([`Goal::type_approach`]: the type's).
//!
//! Why: the grasp planner checks the approach, closing and lift of a grasp
//! before it returns it, and the trajectory planner plans them; both start from
//! the same [`Goal`], so they open the hand the same way and check the same
//! postures.
//!
//! How: the open hand has every finger's flex joints at 0 (clamped into their
//! limits) and the grasp type's other closing joints (e.g. the thumb's
//! opposition) at the type's reference posture, where the grasp planner started
//! closing them, or part way there ([`Goal::open_by`]); the remaining hand
//! joints are at their grasp values.

use nalgebra::{Isometry3, Vector3};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{JointId, RobotModel};

use crate::Robot;

/// The grasp a motion ends in, resolved against the robot.
#[derive(Debug, Clone)]
pub struct Goal {
    /// Joints the reach, approach and lift move: body joints, then the arm.
    pub reach: Vec<JointId>,
    /// The hand's independent joints.
    pub hand: Vec<JointId>,
    /// The grasp posture, hand closed (full joint vector).
    pub closed: Vec<f64>,
    /// The grasp posture, hand open (see [`Goal::open_by`]).
    pub open: Vec<f64>,
    /// The joints that open the hand and their fully open values: the
    /// fingers' flex joints (straight: 0, clamped into the limits) and the
    /// grasp type's closing joints that are not flex joints (e.g. a thumb's
    /// opposition), at the type's reference posture, where the grasp
    /// planner's closing started.
    pub flex: Vec<(JointId, f64)>,
    /// The palm pose at the grasp (forward kinematics of `closed`).
    pub palm: Isometry3<f64>,
    /// Unit direction the palm moves in along the approach (world frame).
    pub approach: Vector3<f64>,
    /// The grasp type's closing joints (its contacts' `joint`s, in the
    /// type's order: the order the grasp planner closed them); empty for a
    /// type the robot does not know.
    pub closing: Vec<JointId>,
    /// The grasp's squeeze: each squeezed hand joint and its target beyond
    /// contact; empty when the grasp has none (the phase checks ignore it).
    pub squeeze: Vec<(JointId, f64)>,
}

impl Goal {
    /// The goal of the grasp posture `closed` (full joint vector, mimics
    /// applied) of grasp type `grasp_type`, the reach moving `reach`, the palm
    /// moving along `approach` (world; normalised here) to the grasp.
    pub fn new(
        robot: &Robot,
        closed: Vec<f64>,
        reach: Vec<JointId>,
        grasp_type: &str,
        approach: Vector3<f64>,
    ) -> Goal {
        let model = &robot.model;
        let mut goal = Goal {
            reach,
            hand: robot.hand().joints.clone(),
            open: closed.clone(),
            flex: opening_joints(robot, grasp_type),
            closing: robot.closing_joints(grasp_type),
            squeeze: Vec::new(),
            palm: palm_pose(robot, &closed),
            closed,
            approach: approach.normalize(),
        };
        goal.open_by(model, 1.0);
        goal
    }

    /// The approach of grasp type `grasp_type` at the palm pose of the full
    /// configuration `q`: the type's `approach` (palm frame) in the world;
    /// `None` for a type the hand does not list.
    pub fn type_approach(robot: &Robot, grasp_type: &str, q: &[f64]) -> Option<Vector3<f64>> {
        let types = &robot.hand().grasp_types.grasp_types;
        let g = types.iter().find(|g| g.name == grasp_type)?;
        Some(palm_pose(robot, q).rotation * g.approach())
    }

    /// The closing in the grasp planner's order, from the current opening:
    /// first every opened joint but the type's closing joints back at the
    /// grasp's angles (the pre-shape), then each closing joint in turn; the
    /// postures after each step (the last is `closed`).
    pub fn sequential_close(&self, model: &RobotModel) -> Vec<Vec<f64>> {
        let mut q = self.open.clone();
        for &(j, _) in &self.flex {
            if !self.closing.contains(&j) {
                q[j] = self.closed[j];
            }
        }
        model.apply_mimics(&mut q);
        let mut out = vec![q.clone()];
        for &j in &self.closing {
            q[j] = self.closed[j];
            model.apply_mimics(&mut q);
            out.push(q.clone());
        }
        out.push(self.closed.clone());
        out
    }

    /// Opens the hand by `opening` (1: every flex joint at 0, clamped into its
    /// limits; 0: the grasp's angles; linear between).
    pub fn open_by(&mut self, model: &RobotModel, opening: f64) {
        self.open.clone_from(&self.closed);
        for &(j, open) in &self.flex {
            self.open[j] = self.closed[j] + opening * (open - self.closed[j]);
        }
        model.apply_mimics(&mut self.open);
    }
}

/// The palm pose (world) of the full configuration `q`.
fn palm_pose(robot: &Robot, q: &[f64]) -> Isometry3<f64> {
    let mut fk = FkState::new(&robot.model);
    robot.model.forward_kinematics(q, &mut fk);
    *fk.pose(robot.hand().palm)
}

/// [`Goal::flex`]: the flex joints straight, then the grasp type's other
/// closing joints at its reference posture (a type the robot does not know
/// adds none).
fn opening_joints(robot: &Robot, grasp_type: &str) -> Vec<(JointId, f64)> {
    let (model, hand) = (&robot.model, robot.hand());
    let mut out: Vec<(JointId, f64)> = hand
        .fingers
        .iter()
        .flat_map(|f| f.flex.iter().copied())
        .map(|j| {
            let lim = model.joints[j].limits;
            (j, 0.0f64.clamp(lim.lower, lim.upper))
        })
        .collect();
    let types = &hand.grasp_types.grasp_types;
    let Some(g) = types.iter().find(|g| g.name == grasp_type) else {
        return out;
    };
    for c in &g.contacts {
        let (Ok(j), Some(&v)) = (model.joint_id(&c.joint), g.posture.get(&c.joint)) else {
            continue;
        };
        if !out.iter().any(|&(k, _)| k == j) {
            let lim = model.joints[j].limits;
            out.push((j, v.clamp(lim.lower, lim.upper)));
        }
    }
    out
}
