//! The phases' timed paths as one timed `JointTrajectory`.
//!
//! What: [`assemble`] joins the phases' timed points ([`crate::timing::time_path`],
//! each phase from rest to rest, within every joint's velocity limit and the
//! acceleration limit) end to end and marks every point with its phase.
//!
//! Why: the controller takes one trajectory; the phase markers let a client (or
//! a viewer) tell the reach from the lift.
//!
//! ```
//! use tsukami_trajectory_planner::assemble::{assemble, Phase};
//! use tsukami_trajectory_planner::timing::{time_path, Limits};
//! let limits = Limits { velocity: vec![1.0], acceleration: vec![2.0], sample_dt: 0.1, jerk: vec![] };
//! let phases = [
//!     Phase { name: "reach", points: time_path(&[vec![0.0], vec![1.0]], &limits, 0.0) },
//!     Phase { name: "lift", points: time_path(&[vec![1.0], vec![1.2]], &limits, 0.0) },
//! ];
//! let t = assemble(vec!["j".into()], &phases);
//! assert_eq!(t.points[0].time, 0.0);
//! assert_eq!(t.points.last().unwrap().positions, vec![1.2]);
//! assert_eq!(t.points.last().unwrap().phase, "lift");
//! assert!(t.points.windows(2).all(|w| w[1].time > w[0].time));
//! ```

use tsukami_msgs::motion::{JointTrajectory, TrajectoryPoint};

use crate::timing::TimedPoint;

/// One phase: its name and its timed points (trajectory joints' values), the
/// first at time 0 and equal to the previous phase's last.
#[derive(Debug, Clone, PartialEq)]
pub struct Phase {
    /// `reach`, `approach`, `close`, `lift`.
    pub name: &'static str,
    /// Timed points from time 0.
    pub points: Vec<TimedPoint>,
}

/// One trajectory from the phases, in order; the first point is the first
/// phase's first point at time 0, marked with that phase.
pub fn assemble(joint_names: Vec<String>, phases: &[Phase]) -> JointTrajectory {
    let mut points: Vec<TrajectoryPoint> = Vec::new();
    let mut t0 = 0.0;
    for phase in phases {
        // A phase's first point repeats the previous phase's last one.
        let skip = usize::from(!points.is_empty());
        for p in phase.points.iter().skip(skip) {
            points.push(TrajectoryPoint {
                time: t0 + p.time,
                positions: p.positions.clone(),
                velocities: p.velocities.clone(),
                phase: phase.name.to_owned(),
                command: Vec::new(),
            });
        }
        t0 = points.last().map_or(0.0, |p| p.time);
    }
    JointTrajectory {
        joint_names,
        points,
    }
}
