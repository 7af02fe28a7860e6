//! The demo's motion step: the trajectory planner plans rest → grasp → lift, the
//! controller runs it, and the state the controller publishes is compared with the
//! planned grasp posture.
//!
//! What: [`plan`] asks `<ns>/motion/plan` for a planned grasp ([`MotionCheck`]);
//! [`execute`] runs the trajectory on the controller in two parts — up to the end
//! of `close`, then the `lift` — and reports how each ended ([`ExecutionRun`]).
//!
//! Why: a grasp is only useful if the robot reaches it. Splitting the run at the
//! end of `close` lets the demo read the robot's state exactly at the grasp: the
//! controller's published state then must equal the grasp planner's joint
//! positions, not merely the trajectory's last point.
//!
//! How: the controller holds its state between trajectories, so the lift starts
//! where the grasp part ended. Each part is one `execute` request that waits for
//! the run to end (timeout: the part's duration at the controller's speed plus a
//! margin); the state compared is the first one published on
//! `<ns>/controller/state` at or after the run's last control period.
//!
//! ```
//! use tsukami::demo::motion::split_at_grasp;
//! use tsukami_msgs::motion::{JointTrajectory, TrajectoryPoint};
//! let point = |time: f64, q: f64, phase: &str| TrajectoryPoint {
//!     time, positions: vec![q], velocities: vec![], phase: phase.into(), command: vec![],
//! };
//! let t = JointTrajectory {
//!     joint_names: vec!["j".into()],
//!     points: vec![point(0.0, 0.0, "reach"), point(1.0, 0.5, "close"), point(1.5, 0.6, "lift")],
//! };
//! let (grasp, lift) = split_at_grasp(&t).unwrap();
//! assert_eq!(grasp.points.len(), 2);
//! assert_eq!(lift.unwrap().points[0].time, 0.0);
//! ```

use std::collections::BTreeMap;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use serde::Serialize;
use tsukami_msgs::controller::{ControllerState, ExecuteReply, ExecuteRequest, ExecutionOutcome};
use tsukami_msgs::keys::ROLE_TRAJECTORY_PLANNER;
use tsukami_msgs::motion::{JointTrajectory, MotionPlanReply};
use tsukami_msgs::planner::PlanReply;

use super::step::Step;
use crate::client::BusClient;

/// Largest difference (rad or m) between the controller's final state and the
/// target for a run to count as ending there.
pub const STATE_TOLERANCE: f64 = 1e-6;

/// How long to wait for a published state after a run's reply.
const STATE_WAIT: Duration = Duration::from_secs(5);

/// The planned motion.
#[derive(Debug, Clone, Serialize)]
pub struct MotionCheck {
    /// The planner's own planning time, milliseconds.
    pub planning_ms: f64,
    /// Round trip of the request, milliseconds.
    pub round_trip_ms: f64,
    /// Duration of the trajectory, seconds of robot time.
    pub duration_s: f64,
    /// Waypoints.
    pub points: usize,
    /// The phases in order (`reach`, `approach`, `close`, `lift`).
    pub phases: Vec<String>,
    /// Where the start came from (`controller` when one answered, else `rest`).
    pub start_source: String,
    /// Samples the reach planner drew.
    pub samples: u32,
}

/// Plans the motion from the default start (the controller's state, else rest)
/// to `grasp` and on to the lift.
pub fn plan(
    client: &BusClient,
    grasp: &PlanReply,
    seed: u64,
    timeout: Duration,
) -> Result<(MotionCheck, JointTrajectory), String> {
    let request = serde_json::json!({ "grasp": grasp, "seed": seed });
    let start = Instant::now();
    let bytes = client
        .command(
            ROLE_TRAJECTORY_PLANNER,
            "plan",
            request.to_string().as_bytes(),
            timeout,
        )
        .map_err(|e| format!("motion plan: {e}"))?;
    let round_trip_ms = start.elapsed().as_secs_f64() * 1e3;
    let reply: MotionPlanReply =
        serde_json::from_slice(&bytes).map_err(|e| format!("motion plan reply: {e}"))?;
    let t = reply.trajectory;
    let mut phases: Vec<String> = t.points.iter().map(|p| p.phase.clone()).collect();
    phases.dedup();
    let check = MotionCheck {
        planning_ms: reply.planning_ms,
        round_trip_ms,
        duration_s: t.points.last().map_or(0.0, |p| p.time),
        points: t.points.len(),
        phases,
        start_source: reply.start_source,
        samples: reply.samples,
    };
    Ok((check, t))
}

/// The trajectory up to the end of `close` (the grasp posture), and the `lift`
/// after it as a trajectory of its own starting at time 0 (none when the
/// trajectory has no lift). Fails when no point before the lift is `close`.
pub fn split_at_grasp(
    t: &JointTrajectory,
) -> Result<(JointTrajectory, Option<JointTrajectory>), String> {
    let k = t
        .points
        .iter()
        .rposition(|p| p.phase != "lift")
        .ok_or("the trajectory is all lift")?;
    if t.points[k].phase != "close" {
        return Err(format!(
            "the last point before the lift is `{}`, not `close`",
            t.points[k].phase
        ));
    }
    let grasp = JointTrajectory {
        joint_names: t.joint_names.clone(),
        points: t.points[..=k].to_vec(),
    };
    let lift = (k + 1 < t.points.len()).then(|| {
        let t0 = t.points[k].time;
        let mut points = t.points[k..].to_vec();
        for p in &mut points {
            p.time -= t0;
        }
        JointTrajectory {
            joint_names: t.joint_names.clone(),
            points,
        }
    });
    Ok((grasp, lift))
}

/// How one part of the trajectory ran.
#[derive(Debug, Clone, Serialize)]
pub struct PartRun {
    /// `done`, `cancelled` or `fault`.
    pub outcome: String,
    /// The controller's published state at the end of the run.
    pub final_state: BTreeMap<String, f64>,
    /// Largest difference between that state and the part's target (rad or m).
    pub max_error: f64,
    /// The joint with that difference.
    pub worst_joint: String,
    /// Wall-clock time of the run, milliseconds.
    pub wall_ms: f64,
}

/// The whole run: reach to the grasp, then lift.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ExecutionRun {
    /// From the start to the end of `close`; its target is the Plan reply's
    /// `joint_positions`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grasp: Option<PartRun>,
    /// The lift; its target is the trajectory's last point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lift: Option<PartRun>,
    /// Joints of the grasp posture the controller does not drive (mimic joints,
    /// which follow their master).
    pub joints_not_driven: Vec<String>,
}

/// Runs `trajectory` on the controller (at `speed` times real time) and checks
/// where it ends: `ok` when both parts ran to the end and each ended at its
/// target within [`STATE_TOLERANCE`] — the grasp part at the grasp planner's
/// joint positions.
pub fn execute(
    client: &BusClient,
    trajectory: &JointTrajectory,
    grasp: &PlanReply,
    speed: f64,
) -> Step<ExecutionRun> {
    let mut run = ExecutionRun::default();
    match run_parts(client, trajectory, grasp, speed, &mut run) {
        Ok(()) => Step::ok(run),
        Err(problem) => Step::failed(problem, Some(run)),
    }
}

fn run_parts(
    client: &BusClient,
    trajectory: &JointTrajectory,
    grasp: &PlanReply,
    speed: f64,
    check: &mut ExecutionRun,
) -> Result<(), String> {
    let (to_grasp, lift) = split_at_grasp(trajectory)?;
    let states = StateStream::subscribe(client)?;
    let run = run_part(client, &states, &to_grasp, speed, &grasp.joint_positions)?;
    check.joints_not_driven = grasp
        .joint_positions
        .keys()
        .filter(|name| !run.final_state.contains_key(*name))
        .cloned()
        .collect();
    let reached = run.outcome == "done" && run.max_error <= STATE_TOLERANCE;
    let summary = format!(
        "the grasp part ended `{}`, {:.2e} from the grasp at {}",
        run.outcome, run.max_error, run.worst_joint
    );
    check.grasp = Some(run);
    if !reached {
        return Err(summary);
    }
    let Some(lift) = lift else {
        return Ok(());
    };
    let last = lift.points.last().ok_or("an empty lift")?;
    let target = lift
        .joint_names
        .iter()
        .cloned()
        .zip(last.positions.iter().copied());
    let run = run_part(client, &states, &lift, speed, &target.collect())?;
    let lifted = run.outcome == "done" && run.max_error <= STATE_TOLERANCE;
    let summary = format!(
        "the lift ended `{}`, {:.2e} from its last point at {}",
        run.outcome, run.max_error, run.worst_joint
    );
    check.lift = Some(run);
    if lifted {
        Ok(())
    } else {
        Err(summary)
    }
}

/// Runs one part and compares the published final state with `target` (joints
/// the controller does not drive are left out).
fn run_part(
    client: &BusClient,
    states: &StateStream,
    part: &JointTrajectory,
    speed: f64,
    target: &BTreeMap<String, f64>,
) -> Result<PartRun, String> {
    let duration = part.points.last().map_or(0.0, |p| p.time);
    let timeout = Duration::from_secs_f64(duration / speed.max(1e-3) + 30.0);
    let request = ExecuteRequest {
        trajectory: part.clone(),
        wait: true,
    };
    let payload = serde_json::to_vec(&request).map_err(|e| e.to_string())?;
    let start = Instant::now();
    let bytes = client
        .request_key(&client.keys().controller_execute(), &payload, timeout)
        .map_err(|e| format!("execute: {e}"))?;
    let wall_ms = start.elapsed().as_secs_f64() * 1e3;
    let reply: ExecuteReply =
        serde_json::from_slice(&bytes).map_err(|e| format!("execute reply: {e}"))?;
    if !reply.accepted {
        return Err(format!(
            "the controller refused the trajectory: {}",
            reply.reason.unwrap_or_default()
        ));
    }
    let end = reply
        .state
        .ok_or("the controller's reply has no final state")?;
    let published = states.at_or_after(end.tick)?;
    let final_state: BTreeMap<String, f64> = published
        .joint_names
        .iter()
        .cloned()
        .zip(published.positions.iter().copied())
        .collect();
    let (worst_joint, max_error) = target
        .iter()
        .filter_map(|(name, want)| final_state.get(name).map(|q| (name, (q - want).abs())))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(n, e)| (n.clone(), e))
        .unwrap_or_default();
    Ok(PartRun {
        outcome: outcome_name(reply.outcome),
        final_state,
        max_error,
        worst_joint,
        wall_ms,
    })
}

fn outcome_name(outcome: Option<ExecutionOutcome>) -> String {
    match outcome {
        Some(ExecutionOutcome::Done) => "done",
        Some(ExecutionOutcome::Cancelled) => "cancelled",
        Some(ExecutionOutcome::Fault) => "fault",
        None => "none",
    }
    .to_owned()
}

/// The controller's published states (`<ns>/controller/state`), as they arrive.
pub struct StateStream {
    _subscriber: zenoh::pubsub::Subscriber<()>,
    states: mpsc::Receiver<ControllerState>,
}

impl StateStream {
    /// Subscribes on `client`'s session.
    pub fn subscribe(client: &BusClient) -> Result<StateStream, String> {
        let (tx, states) = mpsc::channel();
        let tx = std::sync::Mutex::new(tx);
        let subscriber = zenoh::Wait::wait(
            client
                .session()
                .declare_subscriber(client.keys().controller_state())
                .callback(move |sample| {
                    if let Ok(state) = serde_json::from_slice(&sample.payload().to_bytes()) {
                        let _ = tx.lock().unwrap_or_else(|e| e.into_inner()).send(state);
                    }
                }),
        )
        .map_err(|e| format!("subscribing to the controller's state: {e}"))?;
        Ok(StateStream {
            _subscriber: subscriber,
            states,
        })
    }

    /// The next published state, or none within `timeout`.
    pub fn next(&self, timeout: Duration) -> Option<ControllerState> {
        self.states.recv_timeout(timeout).ok()
    }

    /// The first published state of control period `tick` or later.
    pub fn at_or_after(&self, tick: u64) -> Result<ControllerState, String> {
        let start = Instant::now();
        loop {
            let left = STATE_WAIT.saturating_sub(start.elapsed());
            match self.next(left) {
                Some(state) if state.tick >= tick => return Ok(state),
                Some(_) => continue,
                None => {
                    return Err(format!(
                        "no state of period {tick} or later published within {STATE_WAIT:?}"
                    ))
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tsukami_msgs::motion::TrajectoryPoint;

    fn point(time: f64, q: f64, phase: &str) -> TrajectoryPoint {
        TrajectoryPoint {
            time,
            positions: vec![q],
            velocities: vec![0.0],
            phase: phase.into(),
            command: vec![],
        }
    }

    fn trajectory(points: Vec<TrajectoryPoint>) -> JointTrajectory {
        JointTrajectory {
            joint_names: vec!["j".into()],
            points,
        }
    }

    #[test]
    fn the_lift_starts_where_the_grasp_ends() {
        let t = trajectory(vec![
            point(0.0, 0.0, "reach"),
            point(1.0, 0.3, "approach"),
            point(2.0, 0.5, "close"),
            point(2.5, 0.6, "lift"),
            point(3.0, 0.7, "lift"),
        ]);
        let (grasp, lift) = split_at_grasp(&t).unwrap();
        assert_eq!(grasp.points, t.points[..3]);
        let lift = lift.unwrap();
        assert_eq!(lift.points[0].positions, grasp.points[2].positions);
        let times: Vec<f64> = lift.points.iter().map(|p| p.time).collect();
        assert_eq!(times, [0.0, 0.5, 1.0]);
    }

    #[test]
    fn no_lift_and_no_close_are_told_apart() {
        let t = trajectory(vec![point(0.0, 0.0, "reach"), point(1.0, 0.5, "close")]);
        assert!(split_at_grasp(&t).unwrap().1.is_none());
        let t = trajectory(vec![point(0.0, 0.0, "reach"), point(1.0, 0.5, "lift")]);
        assert!(split_at_grasp(&t).unwrap_err().contains("`reach`"));
        let t = trajectory(vec![point(0.0, 0.0, "lift")]);
        assert!(split_at_grasp(&t).is_err());
    }
}
