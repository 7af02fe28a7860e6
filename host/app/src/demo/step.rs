//! One step of a demo scene (vision, motion, execution) and how it went.
//!
//! What: [`Step`], a step's status (`ok`, `failed`, `not_run`), a message saying
//! why when it is not `ok`, and whatever the step measured, flattened beside them
//! in the JSON output.
//!
//! Why: a step can fail after measuring something worth reporting (a run that
//! ended away from the grasp still has its final state), and a step that could
//! not run (its component binary is missing) is not a failure.
//!
//! ```
//! use tsukami::demo::step::{Step, StepStatus};
//! let step: Step<u32> = Step::not_run("tsukami-vision not found");
//! assert_eq!(step.status, StepStatus::NotRun);
//! let json = serde_json::to_value(Step::ok(serde_json::json!({"x": 1}))).unwrap();
//! assert_eq!(json, serde_json::json!({"status": "ok", "x": 1}));
//! ```

use serde::Serialize;

/// How a step went.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StepStatus {
    /// It ran and did what it should.
    Ok,
    /// It ran and failed, or could not finish.
    Failed,
    /// It did not run (say why in the message).
    NotRun,
}

/// A step's status, message and measurements.
#[derive(Debug, Clone, Serialize)]
pub struct Step<T> {
    /// How it went.
    pub status: StepStatus,
    /// Why it failed or did not run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
    /// What it measured.
    #[serde(flatten)]
    pub data: Option<T>,
}

impl<T> Step<T> {
    /// A step that did what it should.
    pub fn ok(data: T) -> Self {
        Step {
            status: StepStatus::Ok,
            message: None,
            data: Some(data),
        }
    }

    /// A step that failed, with what it measured if anything.
    pub fn failed(message: impl Into<String>, data: Option<T>) -> Self {
        Step {
            status: StepStatus::Failed,
            message: Some(message.into()),
            data,
        }
    }

    /// A step that did not run, and why.
    pub fn not_run(why: impl Into<String>) -> Self {
        Step {
            status: StepStatus::NotRun,
            message: Some(why.into()),
            data: None,
        }
    }

    /// `Ok(data)` as an ok step, `Err(message)` as a failed one.
    pub fn from_result(result: Result<T, String>) -> Self {
        match result {
            Ok(data) => Step::ok(data),
            Err(message) => Step::failed(message, None),
        }
    }

    /// Whether it failed (not run is not a failure).
    pub fn failed_to_run(&self) -> bool {
        self.status == StepStatus::Failed
    }
}
