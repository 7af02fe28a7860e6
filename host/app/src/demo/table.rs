//! The demo's table: one row per scene, as printed and as written to the report.
//!
//! What: [`plan_cells`] (grasp type, region and face, whole-body joints, margin,
//! the independent check's verdict), [`step_cells`] (vision error, motion
//! planning time, motion duration, executed), [`header`] and [`row`] (the
//! printed lines), and [`notes`] (the lines under a row saying what failed).
//!
//! Why: the terminal table and the Markdown report show the same cells.

use super::outcome::DemoScene;
use super::step::{Step, StepStatus};
use crate::scenes::SceneOutcome;

/// One scene's planning cells: grasp type, OCP region and face, whole-body
/// joints, margin, and the independent check's verdict with the weight.
pub fn plan_cells(o: &SceneOutcome) -> [String; 5] {
    let Some(r) = &o.result else {
        return ["-", "-", "-", "-", "-"].map(str::to_owned);
    };
    let face = serde_json::to_value(r.face)
        .ok()
        .and_then(|v| v.as_str().map(str::to_owned))
        .unwrap_or_default();
    let joints = if r.joints_used.is_empty() {
        "arm only".to_owned()
    } else {
        r.joints_used.join(",")
    };
    // Recomputed by the independent check, never the planner's flag.
    let exact = match o.weight_scale {
        Some(s) if s >= 1.0 => "holds",
        Some(_) => "FAILS",
        None => "-",
    };
    [
        r.grasp_type.name.clone(),
        format!("{}:{face}", r.ocp_region),
        joints,
        format!("{:.3}", r.force_closure.margin),
        exact.to_owned(),
    ]
}

/// The cell of a step that did not give a value: `not run`, or `failed`.
fn unfinished<T>(step: &Step<T>) -> Option<String> {
    match step.status {
        StepStatus::Ok => None,
        StepStatus::NotRun => Some("not run".to_owned()),
        StepStatus::Failed => Some("failed".to_owned()),
    }
}

/// One scene's step cells: vision pose error, motion planning time (ms),
/// motion duration (s), executed.
pub fn step_cells(s: &DemoScene) -> [String; 4] {
    let vision = match (&s.vision.data, s.vision.status) {
        (Some(v), StepStatus::Ok) => format!(
            "{:.2}mm {:.2}°{}",
            v.position_error_mm,
            v.orientation_error_deg,
            if v.within_tolerance { "" } else { " off" }
        ),
        _ if is_not_found(&s.vision) => "not found".to_owned(),
        _ => unfinished(&s.vision).unwrap_or_default(),
    };
    let (motion_ms, motion_s) = match (&s.motion.data, s.motion.status) {
        (Some(m), StepStatus::Ok) => (
            format!("{:.1}", m.planning_ms),
            format!("{:.2}", m.duration_s),
        ),
        _ => (unfinished(&s.motion).unwrap_or_default(), "-".to_owned()),
    };
    let executed = match s.execution.status {
        StepStatus::Ok => "ok".to_owned(),
        StepStatus::Failed => "FAILED".to_owned(),
        StepStatus::NotRun => "not run".to_owned(),
    };
    [vision, motion_ms, motion_s, executed]
}

/// Whether a failed vision step is the component's "not found" answer.
fn is_not_found<T>(step: &Step<T>) -> bool {
    step.status == StepStatus::Failed
        && step
            .message
            .as_deref()
            .is_some_and(|m| m.contains("not found"))
}

/// The table's header line.
pub fn header() -> String {
    format!(
        "{:<11} {:<16} {:<5} {:<29} {:>6} {:>5}  {:<16} {:>7} {:>9} {:>8}  {:<8}  paper",
        "scene",
        "grasp type",
        "face",
        "whole-body joints",
        "margin",
        "exact",
        "vision error",
        "plan ms",
        "motion ms",
        "motion s",
        "executed"
    )
}

/// The scene's line in the table.
pub fn row(s: &DemoScene) -> String {
    let [grasp, face, joints, margin, exact] = plan_cells(&s.plan);
    let [vision, motion_ms, motion_s, executed] = step_cells(s);
    let verdict = if s.plan.ok { "ok" } else { "DIFFERS" };
    format!(
        "{:<11} {grasp:<16} {face:<5} {joints:<29} {margin:>6} {exact:>5}  {vision:<16} {:>7.1} {motion_ms:>9} {motion_s:>8}  {executed:<8}  {verdict}: {}",
        s.plan.scene, s.plan.plan_ms, s.plan.expected
    )
}

/// The lines under a scene's row: the arm-only attempt, and what went wrong.
pub fn notes(s: &DemoScene) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(arm_only) = &s.plan.arm_only {
        out.push(format!("arm alone: {arm_only}"));
    }
    if let Some(problem) = &s.plan.problem {
        out.push(format!("problem: {problem}"));
    }
    let failed = [
        ("vision", &s.vision.status, &s.vision.message),
        ("motion", &s.motion.status, &s.motion.message),
        ("execution", &s.execution.status, &s.execution.message),
    ];
    for (step, status, message) in failed {
        if let (StepStatus::Failed, Some(message)) = (status, message) {
            out.push(format!("{step}: {message}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::demo::outcome::PlanOn;

    fn scene() -> DemoScene {
        DemoScene {
            plan: SceneOutcome {
                scene: "can_breast".into(),
                expected: "4-finger fingertip".into(),
                ok: true,
                problem: None,
                result: None,
                regions: 1,
                arm_only: None,
                plan_ms: 1.0,
                weight_scale: None,
            },
            planned_on: PlanOn::Scene,
            vision: Step::failed("infeasible: 'can_350ml' not found: no cluster", None),
            motion: Step::not_run("no grasp"),
            execution: Step::not_run("tsukami-controller not found in /x"),
        }
    }

    #[test]
    fn cells_say_not_found_not_run_and_failed() {
        let mut s = scene();
        assert_eq!(step_cells(&s), ["not found", "not run", "-", "not run"]);
        s.vision = Step::failed("bus error", None);
        s.execution = Step::failed("the grasp part ended `fault`", None);
        assert_eq!(step_cells(&s), ["failed", "not run", "-", "FAILED"]);
        assert!(!s.passed());
        // Only failures get a note; "not run" is said once, in the header.
        assert_eq!(
            notes(&s),
            [
                "vision: bus error",
                "execution: the grasp part ended `fault`"
            ]
        );
        assert!(row(&s).starts_with("can_breast "));
    }
}
