//! The plugin config a kit planner is created with.
//!
//! What: [`PlannerConfig`] — the model roots (`model_roots`, which the host
//! passes; `models_dir` is the older single-folder key), the host's limits it
//! passes too (`max_samples`, `max_urdf_bytes`, `max_toml_bytes`,
//! `max_mesh_bytes`), the value limits (`[limits]`, see
//! `crate::validate::Limits`) and the planner's own keys (everything else, for
//! `GraspPlanner::new`).
//!
//! ```
//! use tsukami_planner_kit::PlannerConfig;
//! let c = PlannerConfig::parse("model_roots = [\"models\"]\nlimits = { workspace_m = 5.0 }\nrolls = 12\n").unwrap();
//! assert_eq!(c.limits.workspace_m, 5.0);
//! assert_eq!(c.planner["rolls"].as_integer(), Some(12));
//! ```

use std::path::PathBuf;

use crate::models::Models;
use crate::validate::Limits;

/// A planner's configuration.
#[derive(Debug, Clone)]
pub struct PlannerConfig {
    /// Where model names resolve; nothing outside is read.
    pub models: Models,
    /// Value limits.
    pub limits: Limits,
    /// The largest `max_samples` a plan may ask for (host key `max_samples`).
    pub max_samples: u32,
    /// The planner's own keys.
    pub planner: toml::Table,
}

impl PlannerConfig {
    /// A config reading models under `roots`, default limits, no planner keys.
    pub fn with_roots(roots: impl IntoIterator<Item = PathBuf>) -> Self {
        PlannerConfig {
            models: Models::new(roots),
            limits: Limits::default(),
            max_samples: crate::session::MAX_SAMPLES,
            planner: toml::Table::new(),
        }
    }

    /// Parses the plugin's config table (TOML text, may be empty). Without
    /// `model_roots` or `models_dir`: `$TSUKAMI_MODELS`, else `models`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut table: toml::Table =
            toml::from_str(text).map_err(|e| format!("plugin config: {e}"))?;
        let strings = |v: toml::Value, key: &str| -> Result<Vec<PathBuf>, String> {
            match v {
                toml::Value::String(s) => Ok(vec![PathBuf::from(s)]),
                toml::Value::Array(a) => a
                    .into_iter()
                    .map(|x| {
                        x.as_str()
                            .map(PathBuf::from)
                            .ok_or(format!("{key}: expected strings"))
                    })
                    .collect(),
                _ => Err(format!("{key}: expected a string or a list of strings")),
            }
        };
        let mut roots = Vec::new();
        for key in ["model_roots", "models_dir"] {
            if let Some(v) = table.remove(key) {
                roots.extend(strings(v, key)?);
            }
        }
        if roots.is_empty() {
            roots.push(
                std::env::var("TSUKAMI_MODELS")
                    .map_or_else(|_| PathBuf::from("models"), PathBuf::from),
            );
        }
        let limits: Limits = match table.remove("limits") {
            Some(v) => v
                .try_into()
                .map_err(|e| format!("plugin config: limits: {e}"))?,
            None => Limits::default(),
        };
        limits.check().map_err(|e| format!("plugin config: {e}"))?;
        let mut number = |key: &str| {
            table
                .remove(key)
                .and_then(|v| v.as_integer())
                .and_then(|v| u64::try_from(v).ok())
        };
        let max_samples = number("max_samples").map_or(crate::session::MAX_SAMPLES, |n| {
            n.min(u32::MAX as u64) as u32
        });
        let defaults = tsukami_body::files::SizeLimits::default();
        let sizes = tsukami_body::files::SizeLimits {
            urdf: number("max_urdf_bytes").unwrap_or(defaults.urdf),
            toml: number("max_toml_bytes").unwrap_or(defaults.toml),
            mesh: number("max_mesh_bytes").unwrap_or(defaults.mesh),
        };
        Ok(PlannerConfig {
            models: Models::with_limits(roots, sizes),
            limits,
            max_samples,
            planner: table,
        })
    }
}
