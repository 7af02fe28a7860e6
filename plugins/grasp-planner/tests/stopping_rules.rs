//! The search's two stopping rules (issue #24, item 6: a fast, honest "no"),
//! on the paper's scenes, counted in samples:
//! - a nominal pose none of whose first `STALL_SAMPLES` open hands is clear is
//!   given up (the vase's small envelope: every open hand collides with the
//!   vase or the table);
//! - once the plan holds a grasp that is not preferred, each later nominal pose
//!   of the stage gets `ROBUST_EXTRA_SAMPLES` samples (the heavy can low down:
//!   its first nominal pose gives a grasp some pose error drops, the others
//!   give nothing better), and the reply is the same grasp.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use tsukami_grasp_planner::planner::{PlanError, Planner};
use tsukami_grasp_planner::search::{ROBUST_EXTRA_SAMPLES, STALL_SAMPLES};
use tsukami_msgs::planner::{PlanOptions, PlanReply, WholeBody};
use tsukami_scenes::scene_requests;

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

fn setup(scene: &str) -> Planner {
    let path = models().join("scenes").join(format!("{scene}.toml"));
    let req = scene_requests(&path).unwrap();
    let p = Planner::new(models());
    p.set_robot(&req.robot).unwrap();
    p.set_object(&req.object).unwrap();
    p.set_env(&req.env).unwrap();
    p
}

fn plan(p: &Planner, opts: &PlanOptions) -> Result<PlanReply, PlanError> {
    p.plan(opts, &AtomicBool::new(false), &mut |_| {})
}

#[test]
fn a_stalled_nominal_pose_is_given_up() {
    let p = setup("vase_table");
    let opts = PlanOptions {
        grasp_types: Some(vec!["envelope4_small".into()]),
        whole_body: WholeBody::ArmOnly,
        max_candidates: 1,
        ..PlanOptions::default()
    };
    let e = plan(&p, &opts).expect_err("no small envelope fits around the vase");
    let d = e.details();
    assert_eq!(d["reason"], "no_force_closure", "{d}");
    let samples = d["samples"].as_u64().unwrap();
    // One nominal pose per tier at most (preferred, fallback, tilted), each
    // given up after its stall samples, far below its 1000-sample budget.
    assert!(
        samples > 0 && samples <= 3 * u64::from(STALL_SAMPLES),
        "{d}"
    );
    assert_eq!(samples % u64::from(STALL_SAMPLES), 0, "{d}");
    // Given up for that reason only: no open hand was clear.
    let rejections = d["rejections"].as_object().unwrap();
    assert!(
        rejections
            .keys()
            .all(|k| k == "ik" || k == "collision before closing"),
        "{d}"
    );
}

#[test]
fn after_a_partial_grasp_later_nominal_poses_are_short() {
    let p = setup("heavy_low");
    let first_only = PlanOptions {
        max_candidates: 1,
        ..PlanOptions::default()
    };
    let a = plan(&p, &first_only).unwrap();
    let b = plan(&p, &PlanOptions::default()).unwrap();
    assert_eq!(a.joint_positions, b.joint_positions);
    assert_eq!(a.contacts, b.contacts);
    let later = b.samples - a.samples;
    assert!(later > 0, "the other nominal poses were searched");
    assert!(
        later <= 7 * ROBUST_EXTRA_SAMPLES,
        "{} then {}",
        a.samples,
        b.samples
    );
}
