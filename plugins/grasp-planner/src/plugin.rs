//! The FFI adapter: the [`Planner`] as a `grasp-planner` plugin.
//!
//! What: [`GraspPlannerPlugin`] implements `tsukami_plugin_api::Plugin` and is
//! exported with `export_plugin!`; it answers `set_robot`, `set_object`,
//! `set_env`, `remove_env`, `plan` and `stop` (keys in `tsukami_msgs::keys`).
//!
//! Why: the algorithm stays free of FFI and I/O; this file only parses JSON
//! requests, calls the planner, serialises replies and maps [`PlanError`] to
//! the bus's error codes (the planner's own finer code travels in
//! `details.reason`).
//!
//! How: plugin config (TOML) — `models_dir = "path"` (default: the
//! `TSUKAMI_MODELS` environment variable, else `models`). Progress events are
//! published through the host while a plan runs; the host's `stop` sets the
//! call's cancel flag, which the planner polls between samples.

use serde::Deserialize;
use tsukami_msgs::error::{parse_request, ErrorCode, ErrorReply};
use tsukami_msgs::keys::planner as cmd;
use tsukami_msgs::keys::{ROLE_GRASP_PLANNER, STOP};
use tsukami_msgs::planner::{PlanOptions, RemoveEnv, SetEnv, SetObject, SetRobot};
use tsukami_plugin_api::{export_plugin, CallContext, CallError, Host, Plugin, PluginInfo};

use crate::planner::{PlanError, Planner};

/// Plugin configuration (the plugin's table in the host config).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Config {
    /// Folder holding `robots/`, `objects/` and `scenes/`.
    #[serde(default)]
    models_dir: Option<String>,
}

/// The paper's grasp planner behind the plugin interface.
pub struct GraspPlannerPlugin {
    planner: Planner,
}

/// The bus error for a planner error.
pub fn to_error_reply(e: &PlanError) -> ErrorReply {
    let code = match e {
        PlanError::NoRobot | PlanError::NoObject => ErrorCode::NotReady,
        PlanError::Robot(_) | PlanError::Object(_) | PlanError::UnknownModel { .. } => {
            ErrorCode::ModelError
        }
        PlanError::Env { .. } | PlanError::Options { .. } | PlanError::ObjectValue(_) => {
            ErrorCode::InvalidValue
        }
        PlanError::NoGraspType(_)
        | PlanError::Unreachable(_)
        | PlanError::NoForceClosure { .. } => ErrorCode::Infeasible,
        PlanError::OutOfTime(_) => ErrorCode::Timeout,
        PlanError::Cancelled => ErrorCode::Cancelled,
    };
    ErrorReply::new(code, e.to_string()).with_details(serde_json::json!({ "reason": e.code() }))
}

fn call_error(r: ErrorReply) -> CallError {
    let mut e = CallError::new(r.error.code.as_str(), r.error.message.clone());
    if let Some(d) = &r.error.details {
        e.details_json = d.to_string();
    }
    e
}

fn reply<T: serde::Serialize>(r: Result<T, PlanError>) -> Result<Vec<u8>, CallError> {
    match r {
        Ok(v) => serde_json::to_vec(&v)
            .map_err(|e| CallError::new(ErrorCode::Internal.as_str(), e.to_string())),
        Err(e) => Err(call_error(to_error_reply(&e))),
    }
}

impl GraspPlannerPlugin {
    /// Runs one command on `planner` (shared by the plugin and in-process tests).
    pub fn handle(
        &mut self,
        command: &str,
        payload: &[u8],
        ctx: &CallContext<'_>,
    ) -> Result<Vec<u8>, CallError> {
        let parse_err = |e: ErrorReply| call_error(e);
        match command {
            cmd::SET_ROBOT => {
                let r: SetRobot = parse_request(payload).map_err(parse_err)?;
                reply(self.planner.set_robot(&r))
            }
            cmd::SET_OBJECT => {
                let r: SetObject = parse_request(payload).map_err(parse_err)?;
                reply(self.planner.set_object(&r))
            }
            cmd::SET_ENV => {
                let r: SetEnv = parse_request(payload).map_err(parse_err)?;
                reply(self.planner.set_env(&r))
            }
            cmd::REMOVE_ENV => {
                let r: RemoveEnv = parse_request(payload).map_err(parse_err)?;
                reply(self.planner.remove_env(&r))
            }
            cmd::PLAN => {
                // An empty payload means default options.
                let opts: PlanOptions = if payload.iter().all(u8::is_ascii_whitespace) {
                    PlanOptions::default()
                } else {
                    parse_request(payload).map_err(parse_err)?
                };
                let host = ctx.host();
                let mut progress = |e: &tsukami_msgs::planner::ProgressEvent| {
                    if let Ok(bytes) = serde_json::to_vec(e) {
                        host.progress(&bytes);
                    }
                };
                reply(self.planner.plan(&opts, ctx.cancel_flag(), &mut progress))
            }
            // The host answers `stop` itself (it must work while a plan runs);
            // a host that forwarded it anyway gets the same answer for an idle role.
            STOP => reply(Ok::<_, PlanError>(tsukami_msgs::host::StopReply {
                stopped: false,
                command: None,
            })),
            other => Err(CallError::unknown_command(other)),
        }
    }
}

impl Plugin for GraspPlannerPlugin {
    fn info() -> PluginInfo {
        PluginInfo::new(
            "tsukami-grasp-planner",
            env!("CARGO_PKG_VERSION"),
            &[ROLE_GRASP_PLANNER],
            "the paper's grasp planner: grasp types, nominal palm pose, random posture search, whole-body fallback",
        )
    }

    fn new(_host: Host, config: &str) -> Result<Self, String> {
        let cfg: Config =
            toml::from_str(config).map_err(|e| format!("grasp-planner config: {e}"))?;
        let models = cfg
            .models_dir
            .or_else(|| std::env::var("TSUKAMI_MODELS").ok())
            .unwrap_or_else(|| "models".into());
        Ok(Self {
            planner: Planner::new(models),
        })
    }

    fn call(
        &mut self,
        command: &str,
        payload: &[u8],
        ctx: &CallContext<'_>,
    ) -> Result<Vec<u8>, CallError> {
        self.handle(command, payload, ctx)
    }
}

export_plugin!(GraspPlannerPlugin);
