//! Messages the host answers itself (`<ns>/host/...`).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::planner::{Obstacle, RemoveEnv, SetEnv, SetObject, SetRobot};

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
    /// What the plugin declares: `world` (it shares the host's world),
    /// `concurrent` (it may run several calls at once).
    #[serde(default)]
    pub capabilities: Vec<String>,
    /// Calls the host runs at once for it (1 unless `concurrent`; then its
    /// config's `workers`, by default the host machine's cores).
    #[serde(default = "one")]
    pub workers: usize,
}

fn one() -> usize {
    1
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

/// One change of the world: the request of a `set_*` / `remove_env` command.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum WorldChange {
    /// `set_robot`.
    SetRobot(SetRobot),
    /// `set_object`.
    SetObject(SetObject),
    /// `set_env`.
    SetEnv(SetEnv),
    /// `remove_env`.
    RemoveEnv(RemoveEnv),
}

impl WorldChange {
    /// Parses the payload of world command `command`; `None` for other commands.
    pub fn parse(command: &str, payload: &[u8]) -> Option<Result<Self, crate::ErrorReply>> {
        use crate::error::parse_request;
        use crate::keys::planner as cmd;
        Some(match command {
            cmd::SET_ROBOT => parse_request(payload).map(WorldChange::SetRobot),
            cmd::SET_OBJECT => parse_request(payload).map(WorldChange::SetObject),
            cmd::SET_ENV => parse_request(payload).map(WorldChange::SetEnv),
            cmd::REMOVE_ENV => parse_request(payload).map(WorldChange::RemoveEnv),
            _ => return None,
        })
    }
}

/// Host → plugin `world_prepare`: check and build `change` as world `version`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WorldPrepare {
    /// The version the world will have once committed.
    pub version: u64,
    /// The change.
    pub change: WorldChange,
}

/// Host → plugin `world_commit` / `world_abort`, and the plugin's answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WorldVersion {
    /// The version.
    pub version: u64,
}

/// Reply of `<ns>/world/get`: the world as the requests that made it.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct WorldState {
    /// Current version (0: nothing set yet).
    pub version: u64,
    /// The accepted `set_robot`, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot: Option<SetRobot>,
    /// The accepted `set_object`, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object: Option<SetObject>,
    /// The obstacles, sorted by name.
    #[serde(default)]
    pub obstacles: Vec<Obstacle>,
    /// Roles of the plugins that share this world.
    #[serde(default)]
    pub plugins: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn world_changes_parse_by_command() {
        let c = WorldChange::parse("set_env", br#"{"replace": true}"#)
            .unwrap()
            .unwrap();
        assert!(matches!(
            c,
            WorldChange::SetEnv(SetEnv { replace: true, .. })
        ));
        assert!(WorldChange::parse("plan", b"{}").is_none());
        assert!(WorldChange::parse("set_robot", b"{}").unwrap().is_err());
        let p = WorldPrepare {
            version: 4,
            change: c,
        };
        let back: WorldPrepare = serde_json::from_slice(&serde_json::to_vec(&p).unwrap()).unwrap();
        assert_eq!(back, p);
    }
}
