//! The host config (TOML): namespace, bus, limits, and which plugin fills which role.
//!
//! ```toml
//! namespace = "tsukami"
//!
//! [bus]
//! listen = ["tcp/127.0.0.1:17447"]
//!
//! [models]                            # the only folders bus requests may read models from
//! roots = ["../models", "~/.local/share/tsukami/models"]
//!
//! [limits]                            # all optional; defaults shown
//! max_payload_bytes = 16777216        # largest request payload
//! max_queue = 8                       # queued requests per plugin; more get `busy`
//! max_call_ms = 120000                # the host cancels a call running longer
//! max_samples = 10000                 # largest `max_samples` a plan may ask for
//! max_urdf_bytes = 4194304            # model file size limits, checked before reading
//! max_toml_bytes = 1048576
//! max_mesh_bytes = 67108864
//!
//! [[plugin]]
//! role = "grasp-planner"
//! library = "tsukami_grasp_planner"   # platform prefix/extension added; or `path = "…/libx.so"`
//! # workers = 2                       # calls at once (`concurrent` plugins); default: the cores
//! [plugin.config]                     # handed to the plugin as TOML text
//! models_dir = "../models"
//! ```
//!
//! Every plugin's config table gets the host's `model_roots` (absolute, existing
//! roots only), `max_samples`, `max_urdf_bytes`, `max_toml_bytes` and
//! `max_mesh_bytes` inserted, so every planner applies the same limits.
//!
//! Relative paths are relative to the config file; a root may start with `~/`.
//! A plugin given by `library`
//! name alone (no directory) is looked for beside the `tsukami` executable and in
//! its `deps/` folder, which is where cargo puts the workspace's plugin libraries.
//! Swapping in a third-party planner is a config change: name its library for the
//! `grasp-planner` role.

use crate::bus::{default_endpoint, BusConfig};
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use tsukami_msgs::keys::DEFAULT_NAMESPACE;
use tsukami_plugin_api::loader::library_file_name;

/// The whole host config.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct HostConfig {
    /// Key-expression namespace, so several robots can share a bus.
    #[serde(default = "default_namespace")]
    pub namespace: String,
    /// How to join the bus.
    #[serde(default = "default_bus")]
    pub bus: BusConfig,
    /// Request limits.
    #[serde(default)]
    pub limits: Limits,
    /// Where bus requests may read model files from.
    #[serde(default)]
    pub models: ModelsConfig,
    /// The plugins, one entry per role.
    #[serde(default, rename = "plugin")]
    pub plugins: Vec<PluginEntryConfig>,
    /// The folder relative paths resolve against (the config file's folder).
    #[serde(skip)]
    pub base_dir: PathBuf,
}

/// Request limits (see `docs/protocol.md`, "Limits", for the memory bound they give).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Limits {
    /// Largest request payload the host passes to a plugin, bytes.
    pub max_payload_bytes: usize,
    /// Requests queued per plugin behind the running one; more are answered `busy`.
    pub max_queue: usize,
    /// The host raises a call's cancel flag after this many milliseconds.
    pub max_call_ms: u64,
    /// The largest per-candidate sample budget (`max_samples`) a plan may ask for.
    pub max_samples: u32,
    /// Largest URDF file a request may name, bytes.
    pub max_urdf_bytes: u64,
    /// Largest TOML file (grasp types, object, description), bytes.
    pub max_toml_bytes: u64,
    /// Largest mesh file, bytes.
    pub max_mesh_bytes: u64,
}

impl Default for Limits {
    fn default() -> Self {
        let files = tsukami_body::files::SizeLimits::default();
        Limits {
            max_payload_bytes: default_max_payload(),
            max_queue: 8,
            max_call_ms: 120_000,
            max_samples: 10_000,
            max_urdf_bytes: files.urdf,
            max_toml_bytes: files.toml,
            max_mesh_bytes: files.mesh,
        }
    }
}

impl Limits {
    /// The file size limits, as the model readers take them.
    pub fn file_sizes(&self) -> tsukami_body::files::SizeLimits {
        tsukami_body::files::SizeLimits {
            urdf: self.max_urdf_bytes,
            toml: self.max_toml_bytes,
            mesh: self.max_mesh_bytes,
        }
    }
}

/// The `[models]` table: the folders bus requests may name model files in.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ModelsConfig {
    /// Root folders, searched in order (relative to the config file; `~/` allowed).
    /// Default: the project's `models/` ([`default_models_dir`]) and the user data
    /// folder ([`user_models_dir`]).
    #[serde(default = "default_roots")]
    pub roots: Vec<PathBuf>,
}

impl Default for ModelsConfig {
    fn default() -> Self {
        ModelsConfig {
            roots: default_roots(),
        }
    }
}

fn default_roots() -> Vec<PathBuf> {
    let mut roots = vec![default_models_dir()];
    roots.extend(user_models_dir());
    roots
}

/// The user's own model folder: `$XDG_DATA_HOME/tsukami/models`, else
/// `~/.local/share/tsukami/models`.
pub fn user_models_dir() -> Option<PathBuf> {
    let data = std::env::var_os("XDG_DATA_HOME")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".local/share")))?;
    Some(data.join("tsukami").join("models"))
}

/// One plugin and the role it fills.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PluginEntryConfig {
    /// The role: `grasp-planner`, `trajectory-planner`, `result-viewer`, or a
    /// third-party role (its bus prefix is then the role name).
    pub role: String,
    /// Library name without platform prefix and extension (`tsukami_grasp_planner`).
    #[serde(default)]
    pub library: Option<String>,
    /// Exact path of the library file.
    #[serde(default)]
    pub path: Option<PathBuf>,
    /// The plugin's own config, handed to it as TOML text.
    #[serde(default)]
    pub config: Option<toml::Table>,
    /// Calls the host runs at once for this plugin (its worker pool; default:
    /// the machine's cores, `std::thread::available_parallelism`, at most 64).
    /// Used only if the plugin declares the `concurrent` capability; others get
    /// one worker.
    #[serde(default)]
    pub workers: Option<usize>,
}

fn default_namespace() -> String {
    DEFAULT_NAMESPACE.to_owned()
}

fn default_bus() -> BusConfig {
    BusConfig::listening(&default_endpoint())
}

fn default_max_payload() -> usize {
    tsukami_bus::MAX_PAYLOAD_BYTES
}

/// The config used when `tsukami run` gets no `--config`: the default port and the
/// workspace's own plugins, found beside the executable.
pub const DEFAULT_CONFIG: &str = r#"
namespace = "tsukami"

[bus]
listen = ["tcp/127.0.0.1:17447"]

[[plugin]]
role = "grasp-planner"
library = "tsukami_grasp_planner"

[[plugin]]
role = "trajectory-planner"
library = "tsukami_trajectory_planner"

[[plugin]]
role = "result-viewer"
library = "tsukami_result_viewer"
[plugin.config]
web = "127.0.0.1:17448"     # the live view: http://127.0.0.1:17448/ (a free port if taken; the log says)
"#;

impl HostConfig {
    /// Parses config text; relative paths will resolve against `base_dir`.
    pub fn parse(text: &str, base_dir: &Path, origin: &str) -> Result<HostConfig> {
        let mut config: HostConfig =
            toml::from_str(text).with_context(|| format!("parsing host config {origin}"))?;
        config.base_dir = base_dir.to_owned();
        for entry in &config.plugins {
            if entry.library.is_some() == entry.path.is_some() {
                bail!("host config {origin}: plugin for role `{}` needs exactly one of `library` or `path`", entry.role);
            }
        }
        Ok(config)
    }

    /// Reads a config file.
    pub fn from_file(path: &Path) -> Result<HostConfig> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("reading host config {}", path.display()))?;
        let base = path.parent().unwrap_or(Path::new("."));
        HostConfig::parse(&text, base, &path.display().to_string())
    }

    /// The embedded default config, with plugins resolved beside the executable and
    /// the planner pointed at the project's `models/` ([`default_models_dir`]).
    pub fn default_config() -> Result<HostConfig> {
        let mut config = HostConfig::parse(DEFAULT_CONFIG, Path::new("."), "(built-in default)")?;
        let models = default_models_dir();
        for entry in &mut config.plugins {
            let table = entry.config.get_or_insert_with(toml::Table::new);
            table.insert(
                "models_dir".into(),
                toml::Value::String(models.display().to_string()),
            );
        }
        Ok(config)
    }

    /// A config with no plugins (tests add their own).
    pub fn empty(namespace: &str, bus: BusConfig) -> HostConfig {
        HostConfig {
            namespace: namespace.to_owned(),
            bus,
            limits: Limits::default(),
            models: ModelsConfig::default(),
            plugins: vec![],
            base_dir: PathBuf::from("."),
        }
    }

    /// The model roots as absolute, canonical folders (missing ones skipped).
    pub fn model_roots(&self) -> Vec<PathBuf> {
        let home = std::env::var_os("HOME").map(PathBuf::from);
        self.models
            .roots
            .iter()
            .filter_map(|root| match root.strip_prefix("~") {
                Ok(rest) => home.as_ref().map(|h| h.join(rest)),
                Err(_) => Some(self.base_dir.join(root)),
            })
            .filter_map(|root| std::fs::canonicalize(root).ok())
            .filter(|root| root.is_dir())
            .collect()
    }

    /// The TOML text handed to a plugin: its own table plus the host's
    /// `model_roots`, `max_samples` and file size limits.
    pub fn plugin_config_text(&self, entry: &PluginEntryConfig) -> String {
        let mut table = entry.config.clone().unwrap_or_default();
        let roots = self
            .model_roots()
            .iter()
            .map(|r| toml::Value::String(r.display().to_string()))
            .collect();
        table.insert("model_roots".into(), toml::Value::Array(roots));
        let limits = &self.limits;
        let int = |v: u64| toml::Value::Integer(v.min(i64::MAX as u64) as i64);
        table.insert("max_samples".into(), int(limits.max_samples.into()));
        table.insert("max_urdf_bytes".into(), int(limits.max_urdf_bytes));
        table.insert("max_toml_bytes".into(), int(limits.max_toml_bytes));
        table.insert("max_mesh_bytes".into(), int(limits.max_mesh_bytes));
        table.to_string()
    }

    /// Resolves the plugin file of an entry.
    pub fn plugin_file(&self, entry: &PluginEntryConfig) -> Result<PathBuf> {
        if let Some(path) = &entry.path {
            return Ok(self.base_dir.join(path));
        }
        let name = entry.library.as_deref().unwrap_or_default();
        let given = Path::new(name);
        let file_name =
            library_file_name(given.file_name().and_then(|n| n.to_str()).unwrap_or(name));
        if given.parent().is_some_and(|p| !p.as_os_str().is_empty()) {
            return Ok(self.base_dir.join(given.with_file_name(file_name)));
        }
        let tried: Vec<PathBuf> = plugin_search_dirs()
            .into_iter()
            .map(|dir| dir.join(&file_name))
            .collect();
        // Cargo leaves a copy in the profile folder (`cargo build -p plugin`) and one in
        // `deps/` (when it is built as a dependency); the newer one is the current build.
        let modified = |p: &&PathBuf| std::fs::metadata(p).and_then(|m| m.modified()).ok();
        tried
            .iter()
            .filter(|p| p.is_file())
            .max_by_key(modified)
            .cloned()
            .with_context(|| format!("plugin library `{file_name}` for role `{}` not found; looked in {tried:?} (build it with `cargo build --workspace`)", entry.role))
    }
}

/// The model library the built-in config hands the planner: `$TSUKAMI_MODELS`, else
/// the first `models/` folder (holding `robots/`) found walking up from the executable
/// (`target/release/tsukami` → the repository), else `./models`.
pub fn default_models_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("TSUKAMI_MODELS") {
        return PathBuf::from(dir);
    }
    let exe = std::env::current_exe().ok();
    exe.iter()
        .flat_map(|e| e.ancestors().skip(1))
        .map(|dir| dir.join("models"))
        .find(|models| models.join("robots").is_dir())
        .unwrap_or_else(|| PathBuf::from("models"))
}

/// Where plugins named without a folder are looked for: the executable's folder,
/// its `deps/` and (for test binaries, which live in `deps/`) the folder above.
pub fn plugin_search_dirs() -> Vec<PathBuf> {
    let Ok(exe) = std::env::current_exe() else {
        return vec![];
    };
    let Some(dir) = exe.parent() else {
        return vec![];
    };
    let mut dirs = vec![dir.to_owned(), dir.join("deps")];
    if dir.ends_with("deps") {
        if let Some(up) = dir.parent() {
            dirs.push(up.to_owned());
        }
    }
    dirs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_config_parses() {
        let config = HostConfig::default_config().unwrap();
        // It listens on loopback only: every endpoint is a 127.0.0.0/8 socket address.
        assert!(!config.bus.listen.is_empty());
        for endpoint in &config.bus.listen {
            let addr: std::net::SocketAddr = endpoint
                .strip_prefix("tcp/")
                .and_then(|a| a.parse().ok())
                .unwrap_or_else(|| panic!("{endpoint} is not a tcp socket address"));
            assert!(addr.ip().is_loopback(), "{endpoint} is not loopback");
        }
        // The planner gets a models folder that really holds the project's robot
        // (resolved from the executable's location, not written in the config).
        let planner = config
            .plugins
            .iter()
            .find(|p| p.role == "grasp-planner")
            .expect("a grasp-planner entry");
        let models = planner.config.as_ref().unwrap()["models_dir"]
            .as_str()
            .unwrap();
        let urdf = Path::new(models).join("robots/tsukami_humanoid/tsukami_humanoid.urdf");
        assert!(urdf.is_file(), "{} does not exist", urdf.display());
    }

    #[test]
    fn unknown_fields_and_ambiguous_plugins_are_refused() {
        assert!(HostConfig::parse("namespaec = \"x\"", Path::new("."), "t").is_err());
        let both = "[[plugin]]\nrole = \"a\"\nlibrary = \"x\"\npath = \"y\"\n";
        let err = HostConfig::parse(both, Path::new("."), "t").unwrap_err();
        assert!(format!("{err:#}").contains("exactly one"), "{err:#}");
    }

    #[test]
    fn relative_paths_resolve_against_the_config_folder() {
        let text = "[[plugin]]\nrole = \"a\"\nlibrary = \"plugins/my_planner\"\n";
        let config = HostConfig::parse(text, Path::new("/etc/tsukami"), "t").unwrap();
        let file = config.plugin_file(&config.plugins[0]).unwrap();
        assert_eq!(
            file,
            Path::new("/etc/tsukami/plugins").join(library_file_name("my_planner"))
        );
    }
}
