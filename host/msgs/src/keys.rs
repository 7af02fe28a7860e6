//! Key expressions of the bus, built from a namespace.
//!
//! Everything lives under one namespace (default [`DEFAULT_NAMESPACE`]) so several
//! robots can share a bus. A role's commands live under the role's key prefix:
//! `<ns>/planner/<command>` for the grasp planner, `<ns>/motion/<command>` for the
//! trajectory planner, `<ns>/viewer/<command>` for the result viewer.

/// The namespace used when none is configured.
pub const DEFAULT_NAMESPACE: &str = "tsukami";

/// Role filled by a grasp-planner plugin.
pub const ROLE_GRASP_PLANNER: &str = "grasp-planner";
/// Role filled by a trajectory-planner plugin.
pub const ROLE_TRAJECTORY_PLANNER: &str = "trajectory-planner";
/// Role filled by a result-viewer plugin.
pub const ROLE_RESULT_VIEWER: &str = "result-viewer";

/// Planner commands (`<ns>/planner/<command>`).
pub mod planner {
    /// Set the robot model and grasp-type config.
    pub const SET_ROBOT: &str = "set_robot";
    /// Set the object to grasp.
    pub const SET_OBJECT: &str = "set_object";
    /// Add or replace environment obstacles.
    pub const SET_ENV: &str = "set_env";
    /// Remove environment obstacles.
    pub const REMOVE_ENV: &str = "remove_env";
    /// Plan a grasp.
    pub const PLAN: &str = "plan";
}

/// World commands (`<ns>/world/<command>`), answered by the host for every
/// world-aware plugin at once (see `docs/protocol.md`, "World"). `set_robot`,
/// `set_object`, `set_env` and `remove_env` take the planner's payloads;
/// `<ns>/planner/set_*` stay as aliases of the same world.
pub mod world {
    /// The key prefix.
    pub const PREFIX: &str = "world";
    /// The world as the host holds it: version, robot, object, obstacles.
    pub const GET: &str = "get";
    /// Host → plugin: check and build a change, keep it pending.
    pub const PREPARE: &str = "world_prepare";
    /// Host → plugin: make the pending change of a version current.
    pub const COMMIT: &str = "world_commit";
    /// Host → plugin: drop the pending change of a version.
    pub const ABORT: &str = "world_abort";
    /// The host's own commands to its plugins. No bus key reaches them: a query
    /// `<ns>/<role>/world_prepare` (or `world_commit`, `world_abort`) is refused
    /// by the host, so no client can change a plugin's world behind the host's.
    pub const HOST_ONLY: [&str; 3] = [PREPARE, COMMIT, ABORT];
    /// The commands that change the world.
    pub const CHANGES: [&str; 4] = [
        super::planner::SET_ROBOT,
        super::planner::SET_OBJECT,
        super::planner::SET_ENV,
        super::planner::REMOVE_ENV,
    ];
}

/// The command every role understands: cancel the call the role's plugin is running.
/// The host answers it itself, so it works while the plugin is busy.
pub const STOP: &str = "stop";
/// The publication suffix of a role's progress events.
pub const PROGRESS: &str = "progress";

/// The bus key prefix of a role: `planner`, `motion`, `viewer`, or the role name
/// itself for roles this version does not know (third-party roles).
pub fn role_prefix(role: &str) -> &str {
    match role {
        ROLE_GRASP_PLANNER => "planner",
        ROLE_TRAJECTORY_PLANNER => "motion",
        ROLE_RESULT_VIEWER => "viewer",
        other => other,
    }
}

/// Builds key expressions under one namespace.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeySpace {
    namespace: String,
}

impl Default for KeySpace {
    fn default() -> Self {
        KeySpace::new(DEFAULT_NAMESPACE)
    }
}

impl KeySpace {
    /// A key space under `namespace` (trailing slashes are dropped).
    pub fn new(namespace: &str) -> Self {
        KeySpace {
            namespace: namespace.trim_end_matches('/').to_owned(),
        }
    }

    /// The namespace.
    pub fn namespace(&self) -> &str {
        &self.namespace
    }

    /// `<ns>/<suffix>`.
    pub fn key(&self, suffix: &str) -> String {
        format!("{}/{}", self.namespace, suffix.trim_start_matches('/'))
    }

    /// `<ns>/<role prefix>/<command>`: where a role's command is queried.
    pub fn command(&self, role: &str, command: &str) -> String {
        self.key(&format!("{}/{}", role_prefix(role), command))
    }

    /// `<ns>/<role prefix>/**`: everything a role's plugin answers.
    pub fn role_wildcard(&self, role: &str) -> String {
        self.key(&format!("{}/**", role_prefix(role)))
    }

    /// `<ns>/<role prefix>/progress`: where a role's progress events are published.
    pub fn progress(&self, role: &str) -> String {
        self.command(role, PROGRESS)
    }

    /// `<ns>/host/plugins`: the loaded plugins, their versions and roles.
    pub fn host_plugins(&self) -> String {
        self.key("host/plugins")
    }

    /// `<ns>/world/<command>`: the world every world-aware plugin shares.
    pub fn world(&self, command: &str) -> String {
        self.key(&format!("{}/{command}", world::PREFIX))
    }

    /// `<ns>/vision/detect`: ask the vision component for an object's pose.
    pub fn vision_detect(&self) -> String {
        self.key("vision/detect")
    }

    /// `<ns>/vision/look`: ask the vision component to look for an object with
    /// the robot's head camera.
    pub fn vision_look(&self) -> String {
        self.key("vision/look")
    }

    /// `<ns>/vision/pose/<object>`: the vision component's pose stream of an object.
    pub fn vision_pose(&self, object: &str) -> String {
        self.key(&format!("vision/pose/{object}"))
    }

    /// `<ns>/controller/execute`: hand a joint trajectory to the controller.
    pub fn controller_execute(&self) -> String {
        self.key("controller/execute")
    }

    /// `<ns>/controller/state`: the controller's joint state stream.
    pub fn controller_state(&self) -> String {
        self.key("controller/state")
    }

    /// `<ns>/controller/stop`: cancel the trajectory the controller is executing.
    pub fn controller_stop(&self) -> String {
        self.key(&format!("controller/{STOP}"))
    }

    /// `<ns>/<component>/info`: a component's name, version and keys.
    pub fn component_info(&self, component: &str) -> String {
        self.key(&format!("{component}/info"))
    }

    /// `<ns>/*/info`: every component's info (query it to see what is on the bus).
    pub fn component_info_all(&self) -> String {
        self.key("*/info")
    }

    /// Splits a key under a role's prefix into its command: `tsukami/planner/plan` → `plan`.
    pub fn command_of<'k>(&self, role: &str, key: &'k str) -> Option<&'k str> {
        let prefix = self.key(&format!("{}/", role_prefix(role)));
        key.strip_prefix(prefix.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_follow_the_design_table() {
        let ks = KeySpace::default();
        assert_eq!(
            ks.command(ROLE_GRASP_PLANNER, planner::PLAN),
            "tsukami/planner/plan"
        );
        assert_eq!(ks.progress(ROLE_GRASP_PLANNER), "tsukami/planner/progress");
        assert_eq!(
            ks.command(ROLE_TRAJECTORY_PLANNER, "plan"),
            "tsukami/motion/plan"
        );
        assert_eq!(ks.host_plugins(), "tsukami/host/plugins");
        assert_eq!(ks.world(planner::SET_OBJECT), "tsukami/world/set_object");
        assert_eq!(ks.vision_pose("can"), "tsukami/vision/pose/can");
        assert_eq!(ks.vision_look(), "tsukami/vision/look");
        assert_eq!(ks.controller_stop(), "tsukami/controller/stop");
        assert_eq!(ks.component_info("vision"), "tsukami/vision/info");
        assert_eq!(ks.component_info_all(), "tsukami/*/info");
        assert_eq!(
            KeySpace::new("robot2/").role_wildcard("grasp-planner"),
            "robot2/planner/**"
        );
    }

    #[test]
    fn command_of_strips_the_role_prefix() {
        let ks = KeySpace::new("ns");
        assert_eq!(
            ks.command_of(ROLE_GRASP_PLANNER, "ns/planner/set_robot"),
            Some("set_robot")
        );
        assert_eq!(ks.command_of(ROLE_GRASP_PLANNER, "ns/motion/plan"), None);
        assert_eq!(
            ks.command_of("test-slow", "ns/test-slow/echo"),
            Some("echo")
        );
    }
}
