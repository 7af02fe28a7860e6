//! The host config (TOML): namespace, bus, limits, and which plugin fills which role.
//!
//! ```toml
//! namespace = "tsukami"
//!
//! [bus]
//! listen = ["tcp/127.0.0.1:17447"]
//!
//! [[plugin]]
//! role = "grasp-planner"
//! library = "tsukami_grasp_planner"   # platform prefix/extension added; or `path = "…/libx.so"`
//! [plugin.config]                     # handed to the plugin as TOML text
//! models_dir = "../models"
//! ```
//!
//! Relative paths are relative to the config file. A plugin given by `library`
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
    /// The plugins, one entry per role.
    #[serde(default, rename = "plugin")]
    pub plugins: Vec<PluginEntryConfig>,
    /// The folder relative paths resolve against (the config file's folder).
    #[serde(skip)]
    pub base_dir: PathBuf,
}

/// Request limits.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// Largest request payload the host passes to a plugin, bytes.
    #[serde(default = "default_max_payload")]
    pub max_payload_bytes: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_payload_bytes: default_max_payload(),
        }
    }
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
}

fn default_namespace() -> String {
    DEFAULT_NAMESPACE.to_owned()
}

fn default_bus() -> BusConfig {
    BusConfig::listening(&default_endpoint())
}

fn default_max_payload() -> usize {
    16 * 1024 * 1024
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
            plugins: vec![],
            base_dir: PathBuf::from("."),
        }
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
