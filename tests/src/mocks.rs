//! Mock components for headless tests: a vision that answers with a given pose and
//! a controller that records what it is sent.
//!
//! What: [`MockVision`] answers `<ns>/vision/detect` for its one object with the
//! pose it was given (and `infeasible` / `not_found` for any other object, as the
//! real component does) and publishes it on `<ns>/vision/pose/<object>`;
//! [`MockController`] answers `<ns>/controller/execute` as if every trajectory ran
//! to its end and keeps every request.
//!
//! Why: planner tests need no rendering and no robot: they check what the planner
//! does with a detected pose and what it would send to the controller.
//!
//! How: each is a real component on the bus ([`tsukami_bus::Component`]: it
//! answers `<ns>/<name>/info` too), in the test's process, on its own zenoh session.

use anyhow::Result;
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};
use tsukami_bus::{Component, ComponentArgs};
use tsukami_msgs::controller::{ControllerState, ExecuteReply, ExecuteRequest, ExecutionOutcome};
use tsukami_msgs::vision::ObjectPose;
use tsukami_msgs::{ErrorCode, ErrorReply, Pose};
use zenoh::query::Queryable;
use zenoh::Wait;

/// A vision component that "sees" one object at a fixed pose.
pub struct MockVision {
    component: Component,
    _detect: Queryable<()>,
    pose: ObjectPose,
}

impl MockVision {
    /// Joins the bus as `bus` says and answers for `object` at `pose`.
    pub fn start(bus: &ComponentArgs, object: &str, pose: Pose) -> Result<MockVision> {
        let component = Component::start(
            "vision",
            "mock",
            "mock vision: one object at a given pose",
            bus,
        )?;
        // Built from JSON so the fields the real component adds keep their defaults.
        let pose: ObjectPose = serde_json::from_value(serde_json::json!({
            "object": object, "pose": pose, "fit_error": 0.0,
        }))?;
        let answer = pose.clone();
        let detect = component.serve(
            &component.keys().vision_detect(),
            move |request: serde_json::Value| {
                let wanted = request.get("object").and_then(|o| o.as_str()).unwrap_or("");
                if wanted == answer.object {
                    Ok(answer.clone())
                } else {
                    Err(ErrorReply::new(
                        ErrorCode::Infeasible,
                        format!("object `{wanted}` not found"),
                    )
                    .with_details(serde_json::json!({"reason": "not_found"})))
                }
            },
        )?;
        Ok(MockVision {
            component,
            _detect: detect,
            pose,
        })
    }

    /// Publishes the pose once on `<ns>/vision/pose/<object>`.
    pub fn publish(&self) -> Result<()> {
        let key = self.component.keys().vision_pose(&self.pose.object);
        self.component
            .session()
            .put(key, serde_json::to_vec(&self.pose)?)
            .wait()
            .map_err(|e| anyhow::anyhow!("publishing the pose: {e}"))
    }

    /// Leaves the bus.
    pub fn close(self) {
        self.component.close();
    }
}

/// The requests a [`MockController`] received.
#[derive(Default)]
struct Received {
    requests: Mutex<Vec<ExecuteRequest>>,
    arrived: Condvar,
}

/// A controller that accepts every trajectory, reports it done at its last point,
/// and records it.
pub struct MockController {
    component: Component,
    _execute: Queryable<()>,
    received: Arc<Received>,
}

impl MockController {
    /// Joins the bus as `bus` says.
    pub fn start(bus: &ComponentArgs) -> Result<MockController> {
        let component = Component::start(
            "controller",
            "mock",
            "mock controller: records trajectories",
            bus,
        )?;
        let received = Arc::new(Received::default());
        let log = received.clone();
        let execute = component.serve(
            &component.keys().controller_execute(),
            move |request: ExecuteRequest| {
                let reply = done_at_the_end(&request);
                log.requests
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(request);
                log.arrived.notify_all();
                Ok(reply)
            },
        )?;
        Ok(MockController {
            component,
            _execute: execute,
            received,
        })
    }

    /// Every request so far, in arrival order.
    pub fn received(&self) -> Vec<ExecuteRequest> {
        self.received
            .requests
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    /// Waits until `n` requests have arrived (or `timeout` passes) and returns them.
    pub fn wait_for(&self, n: usize, timeout: Duration) -> Vec<ExecuteRequest> {
        let deadline = Instant::now() + timeout;
        let mut requests = self
            .received
            .requests
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        while requests.len() < n {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                break;
            }
            requests = self
                .received
                .arrived
                .wait_timeout(requests, left)
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
        requests.clone()
    }

    /// Leaves the bus.
    pub fn close(self) {
        self.component.close();
    }
}

/// The reply of a run that reached the trajectory's last point.
fn done_at_the_end(request: &ExecuteRequest) -> ExecuteReply {
    let trajectory = &request.trajectory;
    let last = trajectory.points.last();
    let time = last.map_or(0.0, |p| p.time);
    let state = ControllerState {
        joint_names: trajectory.joint_names.clone(),
        positions: last.map(|p| p.positions.clone()).unwrap_or_default(),
        commanded: last
            .map(|p| {
                if p.command.is_empty() {
                    p.positions.clone()
                } else {
                    p.command.clone()
                }
            })
            .unwrap_or_default(),
        status: "done".into(),
        time,
        velocities: vec![0.0; trajectory.joint_names.len()],
        tick: 0,
        trajectory_time: Some(time),
    };
    ExecuteReply {
        accepted: true,
        reason: None,
        outcome: request.wait.then_some(ExecutionOutcome::Done),
        state: request.wait.then_some(state),
        stop_requested_at: None,
    }
}
