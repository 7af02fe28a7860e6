//! Messages the host answers itself (`<ns>/host/...`).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Reply of `<ns>/host/plugins`: every loaded plugin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PluginsReply {
    /// Version of the plugin interface this host speaks.
    pub interface_version: String,
    /// The bus namespace the host serves.
    pub namespace: String,
    /// Loaded plugins, in the order of the host config.
    pub plugins: Vec<PluginEntry>,
}

/// One loaded plugin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PluginEntry {
    /// The plugin's own name.
    pub name: String,
    /// The plugin's own version.
    pub version: String,
    /// Roles this plugin fills in this host.
    pub roles: Vec<String>,
    /// One-line description.
    pub description: String,
    /// The file it was loaded from.
    pub path: String,
}

/// Reply of a `stop` command.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct StopReply {
    /// True when a running call was asked to stop; false when the role was idle.
    pub stopped: bool,
    /// The command that was running, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub command: Option<String>,
}
