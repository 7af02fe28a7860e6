//! The plugin adapter: any [`GraspPlanner`] as a `grasp-planner` plugin.
//!
//! What: [`KitPlugin`] implements `tsukami_plugin_api::Plugin` around a
//! [`Session`]; [`crate::export_planner!`] exports it. Its roles are
//! `grasp-planner` and the planner's own name (keys `<ns>/<name>/…`). It declares the `world`
//! capability (the host forwards world changes to it) and `concurrent` (plans
//! run on `&self` and a shared snapshot, so the host may run several at once).
//!
//! How: the plugin config is parsed by [`PlannerConfig::parse`]; progress
//! events go to `ctx.host().progress(json)`; the call's cancel flag goes to
//! the [`crate::Run`].

use tsukami_msgs::keys::ROLE_GRASP_PLANNER;
use tsukami_msgs::planner::ProgressEvent;
use tsukami_plugin_api::{CallContext, CallError, Host, Plugin, PluginInfo};

use crate::config::PlannerConfig;
use crate::planner::GraspPlanner;
use crate::session::Session;

/// A kit planner behind the plugin interface.
pub struct KitPlugin<P: GraspPlanner> {
    session: Session<P>,
}

impl<P: GraspPlanner> KitPlugin<P> {
    /// The session inside (for in-process tests).
    pub fn session(&self) -> &Session<P> {
        &self.session
    }
}

impl<P: GraspPlanner> Plugin for KitPlugin<P> {
    fn info() -> PluginInfo {
        let i = P::info();
        // A kit planner also answers under its own name, so a host can load a
        // second planner beside the `grasp-planner` one on the same world.
        PluginInfo::new(
            i.name,
            i.version,
            &[ROLE_GRASP_PLANNER, i.name],
            i.description,
        )
        .with_capabilities(&[PluginInfo::WORLD, PluginInfo::CONCURRENT])
    }

    fn new(_host: Host, config: &str) -> Result<Self, String> {
        let config = PlannerConfig::parse(config)?;
        Ok(KitPlugin {
            session: Session::from_config(config)?,
        })
    }

    fn call(
        &self,
        command: &str,
        payload: &[u8],
        ctx: &CallContext<'_>,
    ) -> Result<Vec<u8>, CallError> {
        let host = ctx.host();
        let mut progress = |e: &ProgressEvent| {
            if let Ok(bytes) = serde_json::to_vec(e) {
                host.progress(&bytes);
            }
        };
        self.session
            .handle(command, payload, ctx.cancel_flag(), &mut progress)
    }
}

/// Exports a [`GraspPlanner`] as this library's plugin. The crate needs
/// `crate-type = ["cdylib", "rlib"]` and `abi_stable` as a dependency.
#[macro_export]
macro_rules! export_planner {
    ($planner:ty) => {
        $crate::__private::export_plugin!($crate::KitPlugin<$planner>);
    };
}
