//! The smallest distance a planned motion keeps from the obstacles, and where.
//!
//! What: [`smallest`] measures, at every point of a timed trajectory, the
//! distance from every robot link with geometry to every obstacle, and returns
//! the smallest with its link, obstacle, phase and time
//! (`tsukami_msgs::motion::ClearanceReport`); `None` when the world has no
//! obstacle.
//!
//! Why: the planner keeps the configured safety distances
//! ([`crate::motion::Clearance`]) at every check; the reply states how much room
//! the motion actually left, so a client can tell a motion that brushes past a
//! shelf from one that passes far from everything.
//!
//! How: forward kinematics of each point (the start's values for joints the
//! trajectory does not name, mimics applied), then
//! `RobotCollision::link_object_proximity` capped at the best distance so far.
//! During `close` and `lift` the hand may be as near to what the object rests
//! on as the grasp is; the report says so by naming the phase.

use tsukami_body::kinematics::FkState;
use tsukami_msgs::motion::{ClearanceReport, JointTrajectory};
use tsukami_planner_kit::World;

use crate::world::SharedWorld;

/// Farthest distance measured (m): beyond it, the report says this much.
const FAR: f64 = 1.0;

/// The smallest link–obstacle distance over `trajectory`'s points, whose other
/// joints keep their values in `start` (see the module docs).
pub fn smallest(
    world: &World<'_, SharedWorld>,
    trajectory: &JointTrajectory,
    start: &[f64],
) -> Option<ClearanceReport> {
    let model = &world.robot.model;
    let collision = &world.hand().collision;
    let joints: Vec<usize> = trajectory
        .joint_names
        .iter()
        .map(|n| model.joint_id(n).ok())
        .collect::<Option<_>>()?;
    let links: Vec<usize> = (0..model.links.len())
        .filter(|&l| !collision.link_parts(l).is_empty())
        .collect();
    let (mut fk, mut q) = (FkState::new(model), start.to_vec());
    let mut best: Option<ClearanceReport> = None;
    for point in &trajectory.points {
        for (&j, &v) in joints.iter().zip(&point.positions) {
            q[j] = v;
        }
        model.apply_mimics(&mut q);
        model.forward_kinematics(&q, &mut fk);
        for obstacle in &world.obstacles {
            for &l in &links {
                let cap = best.as_ref().map_or(FAR, |b| b.distance.min(FAR));
                let Some(p) = collision.link_object_proximity(&fk, l, obstacle, cap.max(0.0))
                else {
                    continue;
                };
                if best.as_ref().is_none_or(|b| p.distance < b.distance) {
                    best = Some(ClearanceReport {
                        distance: p.distance,
                        link: model.links[l].name.clone(),
                        obstacle: obstacle.name.clone(),
                        phase: point.phase.clone(),
                        time: point.time,
                    });
                }
            }
        }
    }
    best.or_else(|| {
        (!world.obstacles.is_empty()).then(|| ClearanceReport {
            distance: FAR,
            link: String::new(),
            obstacle: String::new(),
            phase: String::new(),
            time: 0.0,
        })
    })
}
