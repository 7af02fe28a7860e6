//! The trajectory planner as the `trajectory-planner` plugin (`<ns>/motion/*`).
//!
//! What: [`TrajectoryPlugin`] answers `plan` (a `MotionPlanRequest` → a
//! `MotionPlanReply` whose `trajectory` is what `<ns>/controller/execute`
//! takes) and shares the host's world through the planner kit's session
//! ([`crate::world::SharedWorld`]): `world_prepare` / `world_commit` /
//! `world_abort` and `stop` are the kit's.
//!
//! Why: the motion must be planned among the same robot, object and obstacles as
//! the grasp, at the same world version.
//!
//! How: the request is parsed (`invalid_request` naming the field on a wrong
//! shape), the grasp's world version compared with the snapshot's
//! ([`crate::revalidate`]), its values checked (`invalid_value` naming the field), the start
//! completed (the request's joints over the rest posture; no `start`: the
//! controller's state from `controller/state` if a controller answers within
//! `controller_timeout_ms`, else the rest posture), then
//! [`crate::motion::plan_motion`] runs on the world snapshot taken at the start.
//! Progress events (`MotionProgress`) go to `<ns>/motion/progress`; the call's
//! cancel flag stops the reach planner.
//!
//! Config keys (beside the kit's `model_roots`, `limits`, `max_samples`):
//! `acceleration`, `default_velocity`, `sample_dt`, `max_travel`,
//! `touch_tolerance`, `shortcut_attempts`, `controller_timeout_ms`,
//! `clearance_body`, `clearance_hand` (m; a request's `clearance` overrides them),
//! `blend_deviation` (joint units, 0 to 0.5; 0: stop at every waypoint).

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use tsukami_msgs::controller::{ControllerState, ExecuteReply, ExecuteRequest};
use tsukami_msgs::error::parse_request;
use tsukami_msgs::keys::ROLE_TRAJECTORY_PLANNER;
use tsukami_msgs::motion::{
    MotionExecuteReply, MotionExecuteRequest, MotionPlanReply, MotionPlanRequest, MotionProgress,
};
use tsukami_planner_kit::{PlannerConfig, Session};
use tsukami_plugin_api::{CallContext, CallError, Host, Plugin, PluginInfo};

use crate::error::MotionError;
use crate::motion::{plan_motion, Clearance, MotionConfig, MotionQuery, Variant};
use crate::revalidate::admit;
use crate::world::SharedWorld;

/// The plugin: the kit's world session and the motion settings.
pub struct TrajectoryPlugin {
    session: Session<SharedWorld>,
    config: PlannerConfig,
    motion: MotionConfig,
    host: Host,
    controller_timeout: Duration,
}

fn number(
    table: &mut toml::Table,
    key: &str,
    default: f64,
    range: (f64, f64),
) -> Result<f64, String> {
    let Some(v) = table.remove(key) else {
        return Ok(default);
    };
    let x = v
        .as_float()
        .or_else(|| v.as_integer().map(|i| i as f64))
        .ok_or_else(|| format!("plugin config: `{key}` must be a number"))?;
    if !(range.0..=range.1).contains(&x) {
        return Err(format!(
            "plugin config: `{key}` = {x} is outside [{}, {}]",
            range.0, range.1
        ));
    }
    Ok(x)
}

/// The motion settings from the plugin config's own keys; unknown keys are refused.
pub fn motion_config(table: &toml::Table) -> Result<(MotionConfig, Duration), String> {
    let mut t = table.clone();
    let d = MotionConfig::default();
    let cfg = MotionConfig {
        acceleration: number(&mut t, "acceleration", d.acceleration, (1e-3, 1e3))?,
        default_velocity: number(&mut t, "default_velocity", d.default_velocity, (1e-3, 1e3))?,
        sample_dt: number(&mut t, "sample_dt", d.sample_dt, (1e-3, 1.0))?,
        max_travel: number(&mut t, "max_travel", d.max_travel, (1e-4, 0.005))?,
        touch_tolerance: number(&mut t, "touch_tolerance", d.touch_tolerance, (0.0, 0.005))?,
        blend_deviation: number(&mut t, "blend_deviation", d.blend_deviation, (0.0, 0.5))?,
        clearance: Clearance {
            body: number(&mut t, "clearance_body", d.clearance.body, (0.0, 0.1))?,
            hand: number(&mut t, "clearance_hand", d.clearance.hand, (0.0, 0.1))?,
        },
        shortcut_attempts: number(
            &mut t,
            "shortcut_attempts",
            d.shortcut_attempts as f64,
            (0.0, 1e5),
        )? as usize,
        ..d
    };
    let timeout = number(&mut t, "controller_timeout_ms", 200.0, (0.0, 1e4))?;
    if let Some(k) = t.keys().next() {
        return Err(format!("plugin config: unknown key `{k}`"));
    }
    Ok((cfg, Duration::from_millis(timeout as u64)))
}

/// How long `execute` waits for the controller beyond the trajectory's
/// duration (with `wait`) or for its acceptance (without).
const EXECUTE_MARGIN: Duration = Duration::from_secs(10);

/// A request of type `T` from `payload` (blank: `{}`), or the wire's error.
fn parse<T: serde::de::DeserializeOwned>(payload: &[u8]) -> Result<T, CallError> {
    let payload: &[u8] = if payload.iter().all(u8::is_ascii_whitespace) {
        b"{}"
    } else {
        payload
    };
    parse_request(payload).map_err(|r| {
        let mut e = CallError::new(r.error.code.as_str(), r.error.message);
        if let Some(d) = r.error.details {
            e.details_json = d.to_string();
        }
        e
    })
}

impl TrajectoryPlugin {
    /// The default start and where it came from: the controller's state, else rest.
    fn default_start(
        &self,
        model: &tsukami_body::model::RobotModel,
        ask: bool,
    ) -> (Vec<f64>, &'static str) {
        let mut q = model.rest_positions();
        if !ask || self.controller_timeout.is_zero() {
            return (q, "rest");
        }
        let Ok(bytes) = self
            .host
            .request("controller/state", b"{}", self.controller_timeout)
        else {
            return (q, "rest");
        };
        let Ok(state) = serde_json::from_slice::<ControllerState>(&bytes) else {
            return (q, "rest");
        };
        for (name, &v) in state.joint_names.iter().zip(&state.positions) {
            if let Ok(j) = model.joint_id(name) {
                let lim = model.joints[j].limits;
                if model.joints[j].is_independent() && v.is_finite() {
                    q[j] = v.clamp(lim.lower, lim.upper);
                }
            }
        }
        model.apply_mimics(&mut q);
        (q, "controller")
    }

    fn check_values(&self, req: &MotionPlanRequest) -> Result<Option<f64>, MotionError> {
        let in_range = |x: f64, lo: f64, hi: f64| x.is_finite() && (lo..=hi).contains(&x);
        if !in_range(req.lift_height, 0.0, 0.5) {
            return Err(MotionError::invalid("lift_height", "must be 0 to 0.5 m"));
        }
        if !in_range(req.retreat_distance, 0.0, 0.3) {
            return Err(MotionError::invalid(
                "retreat_distance",
                "must be 0 to 0.3 m",
            ));
        }
        if !in_range(req.pregrasp_distance, 0.005, 0.3) {
            return Err(MotionError::invalid(
                "pregrasp_distance",
                "must be 0.005 to 0.3 m",
            ));
        }
        let most = self.config.max_samples;
        if !(1..=most).contains(&req.max_samples) {
            return Err(MotionError::invalid(
                "max_samples",
                format!("must be 1 to {most}"),
            ));
        }
        match req.max_acceleration {
            Some(a) if !in_range(a, 1e-3, 1e3) => Err(MotionError::invalid(
                "max_acceleration",
                "must be 0.001 to 1000",
            )),
            a => Ok(a),
        }
    }

    /// The request's clearances over the robot description's over the
    /// configured ones, each 0 to 0.1 m.
    fn clearance(
        &self,
        req: &MotionPlanRequest,
        robot: &tsukami_planner_kit::Robot,
    ) -> Result<Clearance, MotionError> {
        let d = self.motion.clearance.for_robot(robot);
        let Some(c) = &req.clearance else {
            return Ok(d);
        };
        let pick = |v: Option<f64>, default: f64, field: &str| match v {
            None => Ok(default),
            Some(x) if x.is_finite() && (0.0..=0.1).contains(&x) => Ok(x),
            Some(_) => Err(MotionError::invalid(field, "must be 0 to 0.1 m")),
        };
        Ok(Clearance {
            body: pick(c.body, d.body, "clearance.body")?,
            hand: pick(c.hand, d.hand, "clearance.hand")?,
        })
    }

    fn plan(&self, payload: &[u8], ctx: &CallContext<'_>) -> Result<Vec<u8>, CallError> {
        let req: MotionPlanRequest = parse(payload)?;
        let reply = self.plan_reply(&req, ctx)?;
        serde_json::to_vec(&reply).map_err(|e| CallError::new("internal", e.to_string()))
    }

    /// `execute`: the motion of `plan`, then the controller's
    /// `controller/execute` with it; the reply carries both answers.
    fn execute(&self, payload: &[u8], ctx: &CallContext<'_>) -> Result<Vec<u8>, CallError> {
        let req: MotionExecuteRequest = parse(payload)?;
        let plan = self.plan_reply(&req.plan, ctx)?;
        let progress = |phase: &str| {
            let event = MotionProgress {
                phase: phase.to_owned(),
                samples: plan.samples,
                elapsed_ms: plan.planning_ms,
            };
            if let Ok(bytes) = serde_json::to_vec(&event) {
                ctx.host().progress(&bytes);
            }
        };
        progress("execute");
        let duration = plan.trajectory.points.last().map_or(0.0, |p| p.time);
        let timeout = match req.wait {
            true => Duration::from_secs_f64(duration.min(3600.0)) + EXECUTE_MARGIN,
            false => EXECUTE_MARGIN,
        };
        let request = ExecuteRequest {
            trajectory: plan.trajectory.clone(),
            wait: req.wait,
        };
        let bytes =
            serde_json::to_vec(&request).map_err(|e| CallError::new("internal", e.to_string()))?;
        let answer = self
            .host
            .request("controller/execute", &bytes, timeout)
            .map_err(|mut e| {
                e.message = format!(
                    "the motion was planned (world version {}), but controller/execute failed: {}",
                    plan.world_version, e.message
                );
                e
            })?;
        let execution: ExecuteReply = serde_json::from_slice(&answer).map_err(|e| {
            CallError::new(
                "internal",
                format!("controller/execute replied something else: {e}"),
            )
        })?;
        progress("executed");
        let reply = MotionExecuteReply { plan, execution };
        serde_json::to_vec(&reply).map_err(|e| CallError::new("internal", e.to_string()))
    }

    fn plan_reply(
        &self,
        req: &MotionPlanRequest,
        ctx: &CallContext<'_>,
    ) -> Result<MotionPlanReply, CallError> {
        let t0 = Instant::now();
        let snapshot = self.session.snapshot();
        let world = snapshot.world().map_err(|e| e.to_call_error())?;
        let version = world.version;
        let fail = |e: MotionError| e.to_call_error(version);
        let recheck = admit(&req.grasp, version, req.revalidate).map_err(fail)?;
        let acceleration = self.check_values(&req).map_err(fail)?;
        let model = &world.robot.model;
        let (default, source) = self.default_start(model, req.start.is_none());
        let start = crate::goal::start_state(model, &default, req.start.as_ref()).map_err(fail)?;
        let query = MotionQuery {
            grasp: &req.grasp,
            start,
            lift_height: req.lift_height,
            pregrasp_distance: req.pregrasp_distance,
            retreat_distance: req.retreat_distance,
            seed: req.seed,
            max_samples: req.max_samples as usize,
            acceleration,
            recheck,
            clearance: self.clearance(&req, world.robot).map_err(fail)?,
        };
        let cancel = ctx.cancel_flag();
        let host = ctx.host();
        let mut progress = |phase: &str, samples: usize| {
            let event = MotionProgress {
                phase: phase.to_owned(),
                samples: samples.min(u32::MAX as usize) as u32,
                elapsed_ms: t0.elapsed().as_secs_f64() * 1e3,
            };
            if let Ok(bytes) = serde_json::to_vec(&event) {
                host.progress(&bytes);
            }
        };
        let cancelled = || cancel.load(Ordering::Relaxed);
        let motion = plan_motion(
            &world,
            &query,
            &self.motion,
            &self.config.limits,
            Variant::default(),
            &cancelled,
            &mut progress,
        )
        .map_err(fail)?;
        let clearance = crate::clearance::smallest(&world, &motion.trajectory, &query.start);
        let reply = MotionPlanReply {
            trajectory: motion.trajectory,
            start_source: if req.start.is_some() {
                "request".into()
            } else {
                source.into()
            },
            samples: motion.samples.min(u32::MAX as usize) as u32,
            checks: motion.checks as u64,
            planning_ms: t0.elapsed().as_secs_f64() * 1e3,
            world_version: version,
            clearance,
        };
        Ok(reply)
    }
}

impl Plugin for TrajectoryPlugin {
    fn info() -> PluginInfo {
        PluginInfo::new(
            "tsukami-trajectory-planner",
            env!("CARGO_PKG_VERSION"),
            &[ROLE_TRAJECTORY_PLANNER],
            "collision-free reach (RRT-Connect + shortcutting), straight approach, close and lift to a planned grasp, time-scaled",
        )
        .with_capabilities(&[PluginInfo::WORLD, PluginInfo::CONCURRENT])
    }

    fn new(host: Host, config: &str) -> Result<Self, String> {
        let config = PlannerConfig::parse(config)?;
        let (motion, controller_timeout) = motion_config(&config.planner)?;
        Ok(TrajectoryPlugin {
            session: SharedWorld::session(&config)?,
            config,
            motion,
            host,
            controller_timeout,
        })
    }

    fn call(
        &self,
        command: &str,
        payload: &[u8],
        ctx: &CallContext<'_>,
    ) -> Result<Vec<u8>, CallError> {
        match command {
            "plan" => self.plan(payload, ctx),
            "execute" => self.execute(payload, ctx),
            // World changes, the host's two-phase world commands and `stop`.
            _ => self
                .session
                .handle(command, payload, ctx.cancel_flag(), &mut |_| {}),
        }
    }
}

tsukami_plugin_api::export_plugin!(TrajectoryPlugin);
