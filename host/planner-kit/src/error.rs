//! Every way a planner request fails, and its one mapping to the wire.
//!
//! What: [`KitError`] — the errors of the world commands, of option checks and
//! of a plan ([`NoGrasp`]) — and [`KitError::to_call_error`], the only place a
//! planner's failure becomes a bus error code.
//!
//! Why: two planners with their own mappings disagreed (a spent time budget was
//! `infeasible` in one and `timeout` in the other; details carried `field` in one
//! and `reason` in the other). With one mapping every planner answers alike. A
//! request's own wall-clock limit running out is `time_limit`, never `timeout`
//! (which means a component did not answer).
//!
//! How: `code` is a `tsukami_msgs::ErrorCode`; `details` always holds `reason` (a
//! stable machine-readable word) and, when a request field was wrong, `field`. A
//! failed plan's details add `samples`, `world_version` and the run's bounded
//! tables (`crate::run`): `rejections` (per reason, `verification` counting the
//! samples the final check refused), `blockers` (per `"<link> vs <obstacle>"`)
//! and `blocked_by` (per obstacle, support or `the object`).
//!
//! ```
//! use tsukami_planner_kit::KitError;
//! let e = KitError::invalid("pose.position", "is 1e308 m from the origin; the workspace is 100 m");
//! let wire = e.to_call_error();
//! assert_eq!(wire.code, "invalid_value");
//! assert!(wire.details_json.contains(r#""field":"pose.position""#));
//! ```

use std::collections::BTreeMap;

use tsukami_msgs::ErrorCode;
use tsukami_plugin_api::CallError;

/// Why a plan found no grasp (the planner's answer; the kit adds the counts).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NoGrasp {
    /// No grasp type fits the object (eqs. (1)–(5) for the paper's planner).
    #[error("no grasp type fits the object: {0}")]
    NoGraspType(String),
    /// No palm pose is reachable with the joints allowed.
    #[error("object unreachable with {0}: no palm pose has an IK solution")]
    Unreachable(String),
    /// Reachable, but every sample was rejected.
    #[error("no grasp passed every check")]
    Exhausted,
    /// The run was stopped: by `stop` or by the request's own time budget.
    #[error(transparent)]
    Stopped(#[from] Stop),
}

/// Why a [`crate::Run`] stopped early.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum Stop {
    /// A `stop` request raised the cancel flag.
    #[error("plan cancelled by stop")]
    Cancelled,
    /// The request's `time_budget_ms` ran out (`time_limit`).
    #[error("the request's time limit (time_budget_ms = {0}) ran out before a grasp was found")]
    OutOfTime(u64),
}

/// The rejection tables of a failed plan (see [`crate::Run`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RejectionTables {
    /// Rejected samples per reason.
    pub rejections: BTreeMap<String, u32>,
    /// Blocked samples per `"<link> vs <obstacle>"`.
    pub blockers: BTreeMap<String, u32>,
    /// Blocked samples per obstacle.
    pub blocked_by: BTreeMap<String, u32>,
}

impl RejectionTables {
    /// The tables of a run.
    pub fn of(run: &crate::Run) -> Box<Self> {
        Box::new(RejectionTables {
            rejections: run.rejections().clone(),
            blockers: run.blockers().clone(),
            blocked_by: run.blocked_by(),
        })
    }
}

/// A failed request, as every kit planner reports it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KitError {
    /// The request needs state that is not set yet.
    #[error("no {missing} set: send {command} first")]
    NotReady {
        /// `robot` or `object`.
        missing: &'static str,
        /// The command that sets it.
        command: &'static str,
    },
    /// A request value is out of range.
    #[error("invalid `{field}`: {message}")]
    InvalidValue {
        /// Path of the field (`pose.position`, `obstacles[1].shape`, `max_samples`).
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// A model, mesh or description could not be found, read or used.
    #[error("{field}: {message}")]
    Model {
        /// The request field that named it (`robot`, `shape.mesh.path`, …).
        field: String,
        /// What is wrong (paths relative to a model root, no file contents).
        message: String,
    },
    /// A world change was refused because another plugin refused it, or a
    /// commit named a version that was never prepared.
    #[error("world change {version}: {message}")]
    World {
        /// The version the change would have had.
        version: u64,
        /// What happened.
        message: String,
    },
    /// The plan found no grasp.
    #[error("{no_grasp}{summary}")]
    NoGrasp {
        /// The planner's reason.
        no_grasp: NoGrasp,
        /// Samples drawn.
        samples: u32,
        /// Counts, best margin and rejection reasons, as text (`; …`), or empty.
        summary: String,
        /// The world version the plan ran on.
        world_version: u64,
        /// Rejections per reason, blockers per link and obstacle, blocked
        /// samples per obstacle (bounded tables of [`crate::Run`]).
        tables: Box<RejectionTables>,
    },
    /// A returned grasp failed the kit's verification (a planner bug).
    #[error("the planner returned a grasp that fails verification: {0}")]
    Unverified(String),
}

impl KitError {
    /// A value error on `field`.
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        KitError::InvalidValue {
            field: field.into(),
            message: message.into(),
        }
    }

    /// A model error on `field`.
    pub fn model(field: impl Into<String>, message: impl Into<String>) -> Self {
        KitError::Model {
            field: field.into(),
            message: message.into(),
        }
    }

    /// Prefixes the field with `prefix.` (for errors of nested values).
    pub fn within(self, prefix: &str) -> Self {
        match self {
            KitError::InvalidValue { field, message } => KitError::InvalidValue {
                field: format!("{prefix}.{field}"),
                message,
            },
            KitError::Model { field, message } => KitError::Model {
                field: format!("{prefix}.{field}"),
                message,
            },
            other => other,
        }
    }

    /// The bus error code.
    pub fn code(&self) -> ErrorCode {
        match self {
            KitError::NotReady { .. } => ErrorCode::NotReady,
            KitError::InvalidValue { .. } => ErrorCode::InvalidValue,
            KitError::Model { .. } => ErrorCode::ModelError,
            KitError::World { .. } | KitError::Unverified(_) => ErrorCode::Internal,
            KitError::NoGrasp { no_grasp, .. } => match no_grasp {
                NoGrasp::Stopped(Stop::Cancelled) => ErrorCode::Cancelled,
                NoGrasp::Stopped(Stop::OutOfTime(_)) => ErrorCode::TimeLimit,
                _ => ErrorCode::Infeasible,
            },
        }
    }

    /// A stable machine-readable word for `details.reason`.
    pub fn reason(&self) -> &'static str {
        match self {
            KitError::NotReady {
                missing: "robot", ..
            } => "no_robot",
            KitError::NotReady { .. } => "no_object",
            KitError::InvalidValue { .. } => "bad_value",
            KitError::Model { .. } => "bad_model",
            KitError::World { .. } => "world_conflict",
            KitError::Unverified(_) => "unverified",
            KitError::NoGrasp { no_grasp, .. } => match no_grasp {
                NoGrasp::NoGraspType(_) => "no_grasp_type",
                NoGrasp::Unreachable(_) => "unreachable",
                NoGrasp::Exhausted => "no_force_closure",
                NoGrasp::Stopped(Stop::Cancelled) => "cancelled",
                NoGrasp::Stopped(Stop::OutOfTime(_)) => "out_of_time",
            },
        }
    }

    /// `details` of the error reply: `reason`, and `field` / `samples` when known.
    pub fn details(&self) -> serde_json::Value {
        let mut d = serde_json::json!({ "reason": self.reason() });
        match self {
            KitError::InvalidValue { field, .. } | KitError::Model { field, .. } => {
                d["field"] = field.as_str().into();
            }
            KitError::NoGrasp {
                samples,
                world_version,
                tables,
                ..
            } => {
                d["samples"] = (*samples).into();
                d["world_version"] = (*world_version).into();
                let t = tables.as_ref();
                for (key, table) in [
                    ("rejections", &t.rejections),
                    ("blockers", &t.blockers),
                    ("blocked_by", &t.blocked_by),
                ] {
                    if !table.is_empty() {
                        d[key] = serde_json::json!(table);
                    }
                }
            }
            KitError::NotReady { command, .. } => d["missing"] = (*command).into(),
            _ => {}
        }
        d
    }

    /// The error as it crosses the plugin boundary.
    pub fn to_call_error(&self) -> CallError {
        let mut e = CallError::new(self.code().as_str(), self.to_string());
        e.details_json = self.details().to_string();
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_stop_has_its_own_code() {
        let e = |s| KitError::NoGrasp {
            no_grasp: NoGrasp::Stopped(s),
            samples: 3,
            summary: String::new(),
            world_version: 1,
            tables: Box::new(RejectionTables {
                rejections: [("verification".to_string(), 2)].into(),
                ..RejectionTables::default()
            }),
        };
        assert_eq!(e(Stop::Cancelled).code(), ErrorCode::Cancelled);
        assert_eq!(e(Stop::OutOfTime(5)).code(), ErrorCode::TimeLimit);
        assert_eq!(
            e(Stop::OutOfTime(5)).details()["rejections"]["verification"],
            2
        );
        assert!(e(Stop::OutOfTime(5)).details().get("blockers").is_none());
        assert_eq!(e(Stop::OutOfTime(5)).details()["samples"], 3);
        let m = KitError::model("path", "x").within("shape.mesh");
        assert_eq!(m.details()["field"], "shape.mesh.path");
        assert_eq!(m.code(), ErrorCode::ModelError);
    }
}
