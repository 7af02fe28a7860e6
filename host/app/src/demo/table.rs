//! The demo's table: one row per scene, as printed and as written to the report.
//!
//! What: [`plan_cells`] (grasp type, region and face, whole-body joints, margin,
//! the independent check's verdict), [`step_cells`] (vision error and the view
//! it was found in, motion planning time, motion duration, executed),
//! [`header`] and [`row`] (the printed lines), and [`notes`] (the lines under
//! a row: the views of a look that took several, a plan on the scene file's
//! pose for want of the vision's, what failed).
//!
//! Why: the terminal table and the Markdown report show the same cells.

use tsukami_msgs::vision::LookView;

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

/// One scene's step cells: vision pose error and the view it was found in,
/// motion planning time (ms), motion duration (s), executed.
pub fn step_cells(s: &DemoScene) -> [String; 4] {
    let vision = match (&s.vision.data, s.vision.status) {
        (Some(v), StepStatus::Ok) => format!(
            "{:.2}mm {:.2}°{} {}",
            v.position_error_mm,
            v.orientation_error_deg,
            if v.within_tolerance { "" } else { " off" },
            v.view
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

/// The views of a look, in words: `aim: not found (0.00); crouch: found (0.99)`.
pub fn views(views: &[LookView]) -> String {
    let view = |v: &LookView| {
        let what = if v.found { "found" } else { "not found" };
        match v.confidence {
            Some(c) => format!("{}: {what} ({c:.2})", v.name),
            None => format!("{}: {what}", v.name),
        }
    };
    views.iter().map(view).collect::<Vec<_>>().join("; ")
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
        "{:<11} {:<16} {:<5} {:<29} {:>6} {:>5}  {:<24} {:>7} {:>9} {:>8}  {:<8}  paper",
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
        "{:<11} {grasp:<16} {face:<5} {joints:<29} {margin:>6} {exact:>5}  {vision:<24} {:>7.1} {motion_ms:>9} {motion_s:>8}  {executed:<8}  {verdict}: {}",
        s.plan.scene, s.plan.plan_ms, s.plan.expected
    )
}

/// The lines under a scene's row: the views of a look that took more than
/// one, a plan on the scene file's pose for want of the vision's, the
/// arm-only attempt, and what went wrong.
pub fn notes(s: &DemoScene) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(v) = s.vision.data.as_ref().filter(|v| v.views.len() > 1) {
        out.push(format!("look: {}", views(&v.views)));
    }
    if s.fell_back() {
        out.push("planned on the scene file's pose: the vision did not find the object".into());
    }
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
    use crate::demo::vision::VisionCheck;
    use tsukami_msgs::Pose;

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
            plan_on: PlanOn::Vision,
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
                "planned on the scene file's pose: the vision did not find the object",
                "vision: bus error",
                "execution: the grasp part ended `fault`"
            ]
        );
        assert!(row(&s).starts_with("can_breast "));
        s.plan_on = PlanOn::Scene;
        assert_eq!(
            notes(&s).len(),
            2,
            "asked for the scene file's pose: no fallback"
        );
    }

    fn view(name: &str, confidence: Option<f64>, found: bool) -> LookView {
        LookView {
            name: name.into(),
            joints: Default::default(),
            camera_pose: Pose {
                position: [0.0; 3],
                quaternion: [0.0, 0.0, 0.0, 1.0],
            },
            self_hidden: 0.0,
            found,
            confidence,
            occluded: None,
            reason: None,
        }
    }

    #[test]
    fn a_look_of_several_views_is_noted_and_the_view_named() {
        let mut s = scene();
        let pose = Pose {
            position: [0.5, 0.0, 1.0],
            quaternion: [0.0, 0.0, 0.0, 1.0],
        };
        s.planned_on = PlanOn::Vision;
        s.vision = Step::ok(VisionCheck {
            object: "pet_500ml".into(),
            position_error_mm: 0.41,
            orientation_error_deg: 0.2,
            within_tolerance: true,
            confidence: 0.99,
            fit_error_mm: 0.7,
            detect_ms: 800.0,
            pose,
            plan_pose: pose,
            view: "crouch".into(),
            views: vec![view("aim", None, false), view("crouch", Some(0.99), true)],
        });
        assert_eq!(step_cells(&s)[0], "0.41mm 0.20° crouch");
        assert_eq!(notes(&s), ["look: aim: not found; crouch: found (0.99)"]);
    }
}
