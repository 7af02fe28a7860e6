//! The kit's side of every command: world state, dispatch, options, the plan.
//!
//! What: [`Session`] owns a planner, its config and the world
//! ([`crate::snapshot::Snapshot`]s). [`Session::handle`] answers a command's
//! JSON bytes with JSON bytes or a `CallError` — the same for every planner:
//! `set_robot`, `set_object`, `set_env`, `remove_env` (a local change), the
//! host's two-phase `world_prepare` / `world_commit` / `world_abort` (one
//! change for every world-aware plugin), `plan` and `stop`. The typed methods
//! ([`Session::set_object`], [`Session::plan`], …) serve in-process use.
//!
//! Why: one dispatcher, one options check, one error mapping
//! ([`KitError::to_call_error`]) and one reply builder for every planner.
//!
//! How: every method takes `&self`. A change is built beside the current
//! snapshot and swapped in whole (a lock serialises changes, not plans); a plan
//! clones the current `Arc` and keeps it to the end, so plans run in parallel
//! and never see a half-applied change.

use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex, MutexGuard};

use serde::de::DeserializeOwned;
use tsukami_msgs::error::{parse_request, ErrorReply};
use tsukami_msgs::host::{StopReply, WorldChange, WorldPrepare, WorldVersion};
use tsukami_msgs::keys::{planner as cmd, world, STOP};
use tsukami_msgs::planner::{
    EnvSummary, ObjectSummary, PlanOptions, PlanReply, ProgressEvent, RemoveEnv, RobotSummary,
    SetEnv, SetObject, SetRobot,
};
use tsukami_plugin_api::CallError;

use crate::config::PlannerConfig;
use crate::grasp::{reply, RunReport};
use crate::planner::{GraspPlanner, World};
use crate::run::Run;
use crate::snapshot::Snapshot;
use crate::verify::verify;
use crate::KitError;

/// Most samples a request may ask for per candidate.
pub const MAX_SAMPLES: u32 = 1_000_000;

/// A planner with its world.
pub struct Session<P: GraspPlanner> {
    planner: P,
    config: PlannerConfig,
    current: Mutex<Arc<Snapshot<P>>>,
    pending: Mutex<Option<Arc<Snapshot<P>>>>,
    changing: Mutex<()>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

fn request_error(r: ErrorReply) -> CallError {
    let mut e = CallError::new(r.error.code.as_str(), r.error.message);
    if let Some(d) = r.error.details {
        e.details_json = d.to_string();
    }
    e
}

fn parse<T: DeserializeOwned>(payload: &[u8]) -> Result<T, CallError> {
    let payload: &[u8] = if payload.iter().all(u8::is_ascii_whitespace) {
        b"{}"
    } else {
        payload
    };
    parse_request(payload).map_err(request_error)
}

fn typed<T: DeserializeOwned>(bytes: Result<Vec<u8>, KitError>) -> Result<T, KitError> {
    let bytes = bytes?;
    serde_json::from_slice(&bytes).map_err(|e| KitError::Unverified(e.to_string()))
}

impl<P: GraspPlanner> Session<P> {
    /// A session of `planner` with `config`.
    pub fn with_planner(planner: P, config: PlannerConfig) -> Self {
        Session {
            planner,
            config,
            current: Mutex::new(Arc::new(Snapshot::default())),
            pending: Mutex::new(None),
            changing: Mutex::new(()),
        }
    }

    /// Creates the planner from `config`.
    pub fn from_config(config: PlannerConfig) -> Result<Self, String> {
        Ok(Self::with_planner(P::new(&config)?, config))
    }

    /// A session reading models under `models_dir`, default limits, for
    /// in-process use (tests, examples, benchmarks). Panics if the planner
    /// refuses a config without planner keys, which no kit planner does.
    pub fn new(models_dir: impl Into<std::path::PathBuf>) -> Self {
        let config = PlannerConfig::with_roots([models_dir.into()]);
        Self::from_config(config).expect("the planner accepts an empty config")
    }

    /// The planner.
    pub fn planner(&self) -> &P {
        &self.planner
    }

    /// The current world snapshot.
    pub fn snapshot(&self) -> Arc<Snapshot<P>> {
        lock(&self.current).clone()
    }

    /// Applies a change locally (no host world): the next version, at once.
    pub fn change(&self, change: &WorldChange) -> Result<Vec<u8>, KitError> {
        let _one_at_a_time = lock(&self.changing);
        let current = self.snapshot();
        let (next, reply) =
            current.apply(&self.planner, &self.config, change, current.version + 1)?;
        *lock(&self.current) = Arc::new(next);
        Ok(reply)
    }

    /// Host phase 1: builds the change as `version` and keeps it pending.
    pub fn prepare(&self, req: &WorldPrepare) -> Result<Vec<u8>, KitError> {
        let _one_at_a_time = lock(&self.changing);
        let (next, reply) =
            self.snapshot()
                .apply(&self.planner, &self.config, &req.change, req.version)?;
        *lock(&self.pending) = Some(Arc::new(next));
        Ok(reply)
    }

    /// Host phase 2: makes the pending change of `version` current.
    pub fn commit(&self, v: WorldVersion) -> Result<WorldVersion, KitError> {
        let _one_at_a_time = lock(&self.changing);
        let mut pending = lock(&self.pending);
        match pending.take() {
            Some(next) if next.version == v.version => {
                *lock(&self.current) = next;
                Ok(v)
            }
            other => {
                *pending = other;
                Err(KitError::World {
                    version: v.version,
                    message: "no change of this version is pending".into(),
                })
            }
        }
    }

    /// Host phase 2 on refusal: drops the pending change of `version`.
    pub fn abort(&self, v: WorldVersion) -> WorldVersion {
        let mut pending = lock(&self.pending);
        if pending.as_ref().is_some_and(|p| p.version == v.version) {
            *pending = None;
        }
        v
    }

    /// `set_robot` in-process.
    pub fn set_robot(&self, req: &SetRobot) -> Result<RobotSummary, KitError> {
        typed(self.change(&WorldChange::SetRobot(req.clone())))
    }

    /// `set_object` in-process.
    pub fn set_object(&self, req: &SetObject) -> Result<ObjectSummary, KitError> {
        typed(self.change(&WorldChange::SetObject(req.clone())))
    }

    /// `set_env` in-process.
    pub fn set_env(&self, req: &SetEnv) -> Result<EnvSummary, KitError> {
        typed(self.change(&WorldChange::SetEnv(req.clone())))
    }

    /// `remove_env` in-process.
    pub fn remove_env(&self, req: &RemoveEnv) -> Result<EnvSummary, KitError> {
        typed(self.change(&WorldChange::RemoveEnv(req.clone())))
    }

    fn check_options(&self, world: &World<'_, P>, opts: &PlanOptions) -> Result<(), KitError> {
        let most = self.config.max_samples;
        if !(1..=most).contains(&opts.max_samples) {
            return Err(KitError::invalid(
                "max_samples",
                format!("must be 1 to {most}"),
            ));
        }
        if opts.time_budget_ms == Some(0) {
            return Err(KitError::invalid(
                "time_budget_ms",
                "must be > 0 (omit it for no limit)",
            ));
        }
        if opts.delta_f.is_some_and(|d| !d.is_finite()) {
            return Err(KitError::invalid("delta_f", "must be finite"));
        }
        crate::validate::hold_request(&opts.hold)?;
        if let Some(names) = &opts.grasp_types {
            let known = self.planner.grasp_types(world.robot, world.robot_data);
            if let Some((i, n)) = names.iter().enumerate().find(|(_, n)| !known.contains(n)) {
                return Err(KitError::invalid(
                    format!("grasp_types[{i}]"),
                    format!("unknown grasp type `{n}`; this planner offers {known:?}"),
                ));
            }
        }
        Ok(())
    }

    /// `plan` on the current snapshot (kept to the end of the plan).
    pub fn plan(
        &self,
        opts: &PlanOptions,
        cancel: &AtomicBool,
        progress: &mut dyn FnMut(&ProgressEvent),
    ) -> Result<PlanReply, KitError> {
        let snapshot = self.snapshot();
        let world = snapshot.world()?;
        self.check_options(&world, opts)?;
        let mut run = Run::new(cancel, opts.time_budget_ms, progress);
        match self.planner.plan(&world, opts, &mut run) {
            Ok(grasp)
                if opts
                    .grasp_types
                    .as_ref()
                    .is_some_and(|n| !n.contains(&grasp.grasp_type.name)) =>
            {
                let why = format!(
                    "this planner grasps the object only as `{}`, which the request excludes",
                    grasp.grasp_type.name
                );
                let samples = run.samples();
                let tables = crate::error::RejectionTables::of(&run);
                run.finish();
                Err(KitError::NoGrasp {
                    no_grasp: crate::NoGrasp::NoGraspType(why),
                    samples,
                    summary: String::new(),
                    world_version: world.version,
                    tables,
                })
            }
            Ok(grasp) => {
                let mut verdict =
                    verify(&world, &grasp, &opts.hold).map_err(KitError::Unverified)?;
                run.motion_phases(&world, &grasp).map_err(|b| {
                    KitError::Unverified(format!("the grasp cannot be executed: {b}"))
                })?;
                verdict.robustness = run.pose_robustness(&world, &grasp, &opts.hold, opts.seed);
                let (timing, tried, samples) = run.finish();
                let report = RunReport {
                    timing,
                    tried,
                    samples,
                };
                Ok(reply(&world, &grasp, &verdict, report))
            }
            Err(no_grasp) => {
                let summary = format!(" ({})", run.summary());
                let samples = run.samples();
                let tables = crate::error::RejectionTables::of(&run);
                run.finish();
                Err(KitError::NoGrasp {
                    no_grasp,
                    samples,
                    summary,
                    world_version: world.version,
                    tables,
                })
            }
        }
    }

    /// Answers one command (the plugin adapter calls this).
    pub fn handle(
        &self,
        command: &str,
        payload: &[u8],
        cancel: &AtomicBool,
        progress: &mut dyn FnMut(&ProgressEvent),
    ) -> Result<Vec<u8>, CallError> {
        let out = |r: Result<Vec<u8>, KitError>| r.map_err(|e| e.to_call_error());
        let json = |v: &dyn erased::Json| v.bytes();
        if let Some(change) = WorldChange::parse(command, payload) {
            return out(self.change(&change.map_err(request_error)?));
        }
        match command {
            cmd::PLAN => {
                let opts: PlanOptions = parse(payload)?;
                out(self.plan(&opts, cancel, progress).map(|r| json(&r)))
            }
            world::PREPARE => out(self.prepare(&parse(payload)?)),
            world::COMMIT => out(self.commit(parse(payload)?).map(|v| json(&v))),
            world::ABORT => Ok(json(&self.abort(parse(payload)?))),
            // The host answers `stop` itself while a call runs; reaching the
            // plugin means nothing was running.
            STOP => Ok(json(&StopReply {
                stopped: false,
                command: None,
            })),
            other => Err(CallError::unknown_command(other)),
        }
    }
}

mod erased {
    /// Serialisation to JSON bytes behind a trait object.
    pub trait Json {
        fn bytes(&self) -> Vec<u8>;
    }
    impl<T: serde::Serialize> Json for T {
        fn bytes(&self) -> Vec<u8> {
            serde_json::to_vec(self).unwrap_or_default()
        }
    }
}
