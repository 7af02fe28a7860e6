//! The FFI adapter: [`AntipodalPlugin`] exports the [`AntipodalPlanner`] as a
//! `grasp-planner` plugin.
//!
//! This file is the only one that knows about plugins. It
//! - reads the plugin config (TOML text handed to `new`): `models_dir`, else
//!   the `TSUKAMI_MODELS` environment variable, else `models`;
//! - parses each request with `tsukami_msgs::error::parse_request` (wrong
//!   shapes become `invalid_request` naming the field, before the planner sees
//!   anything);
//! - calls one planner method per command and serialises the reply;
//! - maps [`PlanError`] to `CallError { code, message, details_json }` with the
//!   `tsukami_msgs::ErrorCode` wire names;
//! - forwards progress events to `ctx.host().progress(json)` and hands the
//!   call's cancel flag (`ctx.cancel_flag()`) to the planner, which polls it.

use serde::{Deserialize, Serialize};
use tsukami_msgs::error::{parse_request, ErrorCode, ErrorReply};
use tsukami_msgs::host::StopReply;
use tsukami_msgs::keys::planner as cmd;
use tsukami_msgs::keys::{ROLE_GRASP_PLANNER, STOP};
use tsukami_msgs::planner::{PlanOptions, ProgressEvent, RemoveEnv, SetEnv, SetObject, SetRobot};
use tsukami_plugin_api::{export_plugin, CallContext, CallError, Host, Plugin, PluginInfo};

use crate::error::PlanError;
use crate::planner::AntipodalPlanner;

/// The plugin's config table.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Config {
    /// Folder holding `robots/` and `objects/`.
    #[serde(default)]
    models_dir: Option<String>,
}

/// The antipodal planner behind the plugin interface.
pub struct AntipodalPlugin {
    planner: AntipodalPlanner,
}

impl AntipodalPlugin {
    /// A plugin around an existing planner (for in-process use and tests).
    pub fn from_planner(planner: AntipodalPlanner) -> Self {
        Self { planner }
    }

    /// The planner inside.
    pub fn planner(&self) -> &AntipodalPlanner {
        &self.planner
    }
}

/// The `CallError` for a planner error.
pub fn call_error(e: &PlanError) -> CallError {
    let mut err = CallError::new(e.code().as_str(), e.to_string());
    err.details_json = e.details().to_string();
    err
}

fn request_error(r: ErrorReply) -> CallError {
    let mut e = CallError::new(r.error.code.as_str(), r.error.message);
    if let Some(d) = r.error.details {
        e.details_json = d.to_string();
    }
    e
}

fn reply<T: Serialize>(r: Result<T, PlanError>) -> Result<Vec<u8>, CallError> {
    let v = r.map_err(|e| call_error(&e))?;
    serde_json::to_vec(&v).map_err(|e| CallError::new(ErrorCode::Internal.as_str(), e.to_string()))
}

/// An empty payload stands for `{}`.
fn parse<T: serde::de::DeserializeOwned>(payload: &[u8]) -> Result<T, CallError> {
    let payload: &[u8] = if payload.iter().all(u8::is_ascii_whitespace) {
        b"{}"
    } else {
        payload
    };
    parse_request(payload).map_err(request_error)
}

impl Plugin for AntipodalPlugin {
    fn info() -> PluginInfo {
        PluginInfo::new(
            "tsukami-antipodal-planner",
            env!("CARGO_PKG_VERSION"),
            &[ROLE_GRASP_PLANNER],
            "example third-party planner: antipodal thumb/index/middle pinch, whole-body IK, exact force closure",
        )
    }

    fn new(_host: Host, config: &str) -> Result<Self, String> {
        let cfg: Config =
            toml::from_str(config).map_err(|e| format!("antipodal-planner config: {e}"))?;
        let models = cfg
            .models_dir
            .or_else(|| std::env::var("TSUKAMI_MODELS").ok())
            .unwrap_or_else(|| "models".into());
        Ok(Self {
            planner: AntipodalPlanner::new(models),
        })
    }

    fn call(
        &mut self,
        command: &str,
        payload: &[u8],
        ctx: &CallContext<'_>,
    ) -> Result<Vec<u8>, CallError> {
        match command {
            cmd::SET_ROBOT => reply(self.planner.set_robot(&parse::<SetRobot>(payload)?)),
            cmd::SET_OBJECT => reply(self.planner.set_object(&parse::<SetObject>(payload)?)),
            cmd::SET_ENV => reply(self.planner.set_env(&parse::<SetEnv>(payload)?)),
            cmd::REMOVE_ENV => reply(self.planner.remove_env(&parse::<RemoveEnv>(payload)?)),
            cmd::PLAN => {
                let opts: PlanOptions = parse(payload)?;
                let host = ctx.host();
                let mut progress = |e: &ProgressEvent| {
                    if let Ok(bytes) = serde_json::to_vec(e) {
                        host.progress(&bytes);
                    }
                };
                reply(self.planner.plan(&opts, ctx.cancel_flag(), &mut progress))
            }
            // The host answers `stop` itself while a call runs; reaching the
            // plugin means nothing was running.
            STOP => reply(Ok::<_, PlanError>(StopReply {
                stopped: false,
                command: None,
            })),
            other => Err(CallError::unknown_command(other)),
        }
    }
}

export_plugin!(AntipodalPlugin);
