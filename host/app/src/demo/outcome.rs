//! What the demo found for one scene, and which pose it planned on.
//!
//! What: [`DemoScene`] — the grasp judged against the paper, the pose it was
//! asked to be and was planned on ([`PlanOn`]), and the vision, motion and
//! execution steps — as
//! printed (`--json`), tabled (`table.rs`) and reported ([`super::report`]).
//!
//! Why: its own file so the runner (`mod.rs`), the table and the report all
//! import it and none of them imports another's file back: no import cycle
//! between the demo's files.
//!
//! ```
//! use tsukami::demo::outcome::PlanOn;
//! assert_eq!(serde_json::to_value(PlanOn::Vision).unwrap(), "vision");
//! ```

use serde::Serialize;

use super::motion::{ExecutionRun, MotionCheck};
use super::step::Step;
use super::vision::VisionCheck;
use crate::scenes::SceneOutcome;

/// Which object pose a grasp is planned on.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanOn {
    /// The scene file's (the truth).
    Scene,
    /// The vision component's estimate.
    Vision,
}

/// What happened to one scene.
#[derive(Debug, Clone, Serialize)]
pub struct DemoScene {
    /// The grasp, judged against the paper (`scene`, `expected`, `ok`, `result`, …).
    #[serde(flatten)]
    pub plan: SceneOutcome,
    /// The object pose the grasp was asked to be planned on (`--plan-on`).
    pub plan_on: PlanOn,
    /// The object pose the grasp was planned on: the scene file's when the
    /// vision was asked for but did not find the object.
    pub planned_on: PlanOn,
    /// The vision component's pose against the scene's.
    pub vision: Step<VisionCheck>,
    /// The trajectory planner's motion to the grasp and the lift.
    pub motion: Step<MotionCheck>,
    /// The controller's run of that motion.
    pub execution: Step<ExecutionRun>,
}

impl DemoScene {
    /// Whether the grasp was planned on the scene file's pose because the
    /// vision, asked for, did not find the object.
    pub fn fell_back(&self) -> bool {
        self.plan_on == PlanOn::Vision && self.planned_on == PlanOn::Scene
    }

    /// The paper's outcome, and the motion planned and executed (or not run).
    pub fn passed(&self) -> bool {
        self.plan.ok && !self.motion.failed_to_run() && !self.execution.failed_to_run()
    }
}
