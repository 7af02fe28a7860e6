//! JSON Schema of every bus payload, generated from the types.
//!
//! `tsukami schema --out docs/schema` writes one `<name>.schema.json` per entry of
//! [`all`]; a test checks that the committed files match the types, so the published
//! schema can never drift from the code.

use schemars::{schema_for, JsonSchema};

/// One payload type's schema, with the file stem it is published under.
pub struct NamedSchema {
    /// File stem, e.g. `plan_request`.
    pub name: &'static str,
    /// The schema as pretty JSON (with a trailing newline).
    pub json: String,
}

fn named<T: JsonSchema>(name: &'static str) -> NamedSchema {
    let schema = schema_for!(T);
    let mut json = serde_json::to_string_pretty(&schema).unwrap_or_default();
    json.push('\n');
    NamedSchema { name, json }
}

/// Every payload of the key table, in a fixed order.
pub fn all() -> Vec<NamedSchema> {
    vec![
        named::<crate::error::ErrorReply>("error_reply"),
        named::<crate::host::PluginsReply>("host_plugins_reply"),
        named::<crate::host::StopReply>("stop_reply"),
        named::<crate::motion::MotionPlanRequest>("motion_plan_request"),
        named::<crate::motion::MotionPlanReply>("motion_plan_reply"),
        named::<crate::motion::MotionExecuteRequest>("motion_execute_request"),
        named::<crate::motion::MotionExecuteReply>("motion_execute_reply"),
        named::<crate::motion::MotionProgress>("motion_progress"),
        named::<crate::motion::JointTrajectory>("joint_trajectory"),
        named::<crate::controller::ExecuteRequest>("controller_execute_request"),
        named::<crate::controller::ExecuteReply>("controller_execute_reply"),
        named::<crate::controller::ControllerState>("controller_state"),
        named::<crate::component::ComponentInfo>("component_info"),
        named::<crate::vision::DetectRequest>("vision_detect_request"),
        named::<crate::vision::ObjectPose>("vision_object_pose"),
        named::<crate::vision::LookRequest>("vision_look_request"),
        named::<crate::vision::LookReply>("vision_look_reply"),
        named::<crate::planner::SetRobot>("planner_set_robot_request"),
        named::<crate::planner::RobotSummary>("planner_set_robot_reply"),
        named::<crate::planner::SetObject>("planner_set_object_request"),
        named::<crate::planner::ObjectSummary>("planner_set_object_reply"),
        named::<crate::planner::SetEnv>("planner_set_env_request"),
        named::<crate::planner::RemoveEnv>("planner_remove_env_request"),
        named::<crate::planner::EnvSummary>("planner_env_reply"),
        named::<crate::planner::PlanOptions>("planner_plan_request"),
        named::<crate::planner::PlanReply>("planner_plan_reply"),
        named::<crate::planner::ProgressEvent>("planner_progress"),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// The committed `docs/schema/` must match the types; regenerate with
    /// `cargo run -- schema --out docs/schema` after changing a message.
    #[test]
    fn committed_schema_matches_the_types() {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/schema");
        let mut stale = Vec::new();
        for schema in all() {
            let path = dir.join(format!("{}.schema.json", schema.name));
            match std::fs::read_to_string(&path) {
                Ok(text) if text == schema.json => {}
                _ => stale.push(schema.name),
            }
        }
        assert!(
            stale.is_empty(),
            "docs/schema is out of date for {stale:?}: run `cargo run -- schema --out docs/schema`"
        );
    }

    #[test]
    fn names_are_unique() {
        let mut names: Vec<_> = all().into_iter().map(|s| s.name).collect();
        names.sort();
        let before = names.len();
        names.dedup();
        assert_eq!(before, names.len());
    }
}
