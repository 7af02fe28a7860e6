//! The grasp checker the paper tests, the bus tests and the demo use
//! (`tsukami_scenes::verify` through `PaperScene::check`) rejects replies that are
//! wrong in one way each: a real reply of the planner passes, then one field is
//! corrupted and the checker must refuse it, for the right reason.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use nalgebra::Vector3;
use tsukami_grasp_planner::planner::Planner;
use tsukami_msgs::planner::{PlanOptions, PlanReply};
use tsukami_scenes::{paper_scene, scene_requests, verify, Tolerances, Verdict, Violation, World};

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

/// A real reply for `scene` (seed 0), the checker's world and the region count.
fn planned(scene: &str) -> (PlanReply, World, usize) {
    let req = scene_requests(&models().join("scenes").join(format!("{scene}.toml"))).unwrap();
    let p = Planner::new(models());
    p.set_robot(&req.robot).unwrap();
    let regions = p.set_object(&req.object).unwrap().regions.len();
    p.set_env(&req.env).unwrap();
    let reply = p
        .plan(
            &PlanOptions::default(),
            &AtomicBool::new(false),
            &mut |_| {},
        )
        .unwrap();
    let world = World::from_requests(&models(), &req.robot, &req.object, &req.env).unwrap();
    (reply, world, regions)
}

/// Asserts the paper check refuses `corrupted`, and the checker finds in it a
/// violation `expected` accepts that it does not find in the `original` reply:
/// the rejection is the corruption's doing. Returns the corrupted verdict.
fn rejected(
    scene: &str,
    world: &World,
    original: &PlanReply,
    corrupted: &PlanReply,
    regions: usize,
    what: &str,
    expected: impl Fn(&Violation) -> bool,
) -> Verdict {
    let paper = paper_scene(scene).unwrap();
    let e = paper
        .check(world, corrupted, regions)
        .expect_err(&format!("{scene}: {what} must be rejected"));
    let before = verify(world, original, &Tolerances::default());
    assert!(
        !before.violations.iter().any(&expected),
        "{scene}: {what}: the original reply already shows it: {before}"
    );
    let verdict = verify(world, corrupted, &Tolerances::default());
    assert!(
        verdict.violations.iter().any(&expected),
        "{scene}: {what}: rejected, but not for the expected reason: {e}"
    );
    verdict
}

/// The untouched reply passes.
fn accepted(scene: &str, world: &World, reply: &PlanReply, regions: usize) {
    let paper = paper_scene(scene).unwrap();
    if let Err(e) = paper.check(world, reply, regions) {
        panic!("{scene}: the planner's own reply is rejected: {e}");
    }
}

#[test]
fn flipped_normal_and_contact_off_the_surface() {
    let (reply, world, regions) = planned("can_breast");
    accepted("can_breast", &world, &reply, regions);

    let mut flipped = reply.clone();
    flipped.contacts[1].normal = (-Vector3::from(flipped.contacts[1].normal)).into();
    rejected(
        "can_breast",
        &world,
        &reply,
        &flipped,
        regions,
        "a flipped normal",
        |v| matches!(v, Violation::NormalMismatch { angle, .. } if *angle > 3.0),
    );

    // 5 mm outward, along the contact's own (inward) normal.
    let mut off = reply.clone();
    let c = &mut off.contacts[0];
    c.position = (Vector3::from(c.position) - Vector3::from(c.normal) * 0.005).into();
    rejected(
        "can_breast",
        &world,
        &reply,
        &off,
        regions,
        "a contact 5 mm off",
        |v| matches!(v, Violation::OffSurface { distance, .. } if (distance - 0.005).abs() < 5e-4),
    );
}

#[test]
fn elbow_moved_and_hand_lowered_into_the_counter() {
    let (reply, world, regions) = planned("can_breast");
    accepted("can_breast", &world, &reply, regions);

    let mut elbow = reply.clone();
    let q = elbow.joint_positions.get_mut("r_elbow").unwrap();
    let lim = world.robot.model.joints[world.robot.model.joint_id("r_elbow").unwrap()].limits;
    *q += if *q + 0.1 <= lim.upper { 0.1 } else { -0.1 };
    rejected(
        "can_breast",
        &world,
        &reply,
        &elbow,
        regions,
        "the elbow moved 0.1 rad",
        |v| matches!(v, Violation::PalmPose { position, .. } if *position > 0.01),
    );

    // The whole robot 5 cm lower (squat, declared, palm pose updated to match):
    // the hand sinks into the counter the can stands on.
    let mut lowered = reply.clone();
    lowered.joint_positions.insert("squat_z".into(), -0.05);
    lowered.joints_used.push("squat_z".into());
    lowered.palm_pose.position[2] -= 0.05;
    for c in &mut lowered.contacts {
        c.position[2] -= 0.05;
    }
    let v = rejected(
        "can_breast",
        &world,
        &reply,
        &lowered,
        regions,
        "the hand lowered",
        |v| {
            matches!(v, Violation::Penetration { body, depth, .. }
            if body.starts_with("counter") && *depth > 0.01)
        },
    );
    assert!(!v
        .violations
        .iter()
        .any(|x| matches!(x, Violation::PalmPose { .. })));
}

#[test]
fn twenty_times_the_mass_is_not_held() {
    let (reply, world, regions) = planned("can_waist");
    accepted("can_waist", &world, &reply, regions);
    let held = verify(&world, &reply, &Tolerances::default())
        .weight_scale
        .unwrap();
    assert!(
        (1.0..20.0).contains(&held),
        "the can's 3-finger grasp holds {held} x its weight"
    );

    // The reply reports 20 times the mass the client set.
    let mut claims = reply.clone();
    claims.object.mass *= 20.0;
    rejected(
        "can_waist",
        &world,
        &reply,
        &claims,
        regions,
        "reported mass x 20",
        |v| matches!(v, Violation::ObjectMismatch { field: "mass", .. }),
    );

    // The client's object is 20 times heavier: the same grasp cannot hold it.
    let heavy = world.clone().with_mass_scaled(20.0);
    let paper = paper_scene("can_waist").unwrap();
    let e = paper.check(&heavy, &claims, regions).unwrap_err();
    let verdict = verify(&heavy, &claims, &Tolerances::default());
    assert!(
        verdict.violations.iter().any(|v| matches!(v,
            Violation::NotHeld { weight_scale } if (weight_scale * 20.0 - held).abs() < 1e-3 * held)),
        "mass x 20: {e}"
    );
    assert!(!verdict
        .violations
        .iter()
        .any(|v| matches!(v, Violation::ObjectMismatch { .. })));
}

#[test]
fn hidden_squat_and_untrue_force_limit() {
    // A reply that squats 2 cm and declares it (built from the fingertip grasp, so
    // the test does not depend on the envelope search of issue 10); hiding the
    // squat must add a HiddenJoint violation to whatever else that posture has.
    let (planned_reply, world, regions) = planned("can_breast");
    let mut reply = planned_reply.clone();
    reply.joint_positions.insert("squat_z".into(), -0.02);
    reply.joints_used.push("squat_z".into());
    let mut hidden = reply.clone();
    hidden.joints_used.retain(|j| j != "squat_z");
    rejected(
        "can_breast",
        &world,
        &reply,
        &hidden,
        regions,
        "a hidden squat",
        |v| matches!(v, Violation::HiddenJoint { joint, .. } if joint == "squat_z"),
    );

    // A limit above what the weakest finger can press with (e.g. a silent default).
    let capability = verify(&world, &planned_reply, &Tolerances::default())
        .finger_capability
        .unwrap();
    let mut strong = planned_reply.clone();
    strong.force_closure.force_limit = capability * 1.5;
    rejected(
        "can_breast",
        &world,
        &planned_reply,
        &strong,
        regions,
        "an overstated force limit",
        |v| matches!(v, Violation::ForceLimit { capability: Some(c), .. } if *c == capability),
    );
    let mut missing = planned_reply.clone();
    missing.force_closure.force_limit = 0.0;
    rejected(
        "can_breast",
        &world,
        &planned_reply,
        &missing,
        regions,
        "no force limit",
        |v| matches!(v, Violation::ForceLimit { stated, .. } if *stated == 0.0),
    );
}

#[test]
fn joint_outside_its_limits() {
    let (reply, world, regions) = planned("can_waist");
    accepted("can_waist", &world, &reply, regions);
    let model = &world.robot.model;
    let wrist = model.joint_id("r_wrist_pitch").unwrap();
    let mut beyond = reply.clone();
    beyond.joint_positions.insert(
        "r_wrist_pitch".into(),
        model.joints[wrist].limits.upper + 0.05,
    );
    rejected(
        "can_waist",
        &world,
        &reply,
        &beyond,
        regions,
        "a joint past its limit",
        |v| matches!(v, Violation::JointLimit { joint, .. } if joint == "r_wrist_pitch"),
    );
}

#[test]
fn an_arm_folded_into_the_chest_is_a_self_collision() {
    let (reply, world, regions) = planned("fridge_pet");
    accepted("fridge_pet", &world, &reply, regions);
    let mut folded = reply.clone();
    for (joint, value) in [
        ("r_shoulder_roll", 0.25),
        ("r_shoulder_pitch", -1.3),
        ("r_elbow", -2.3),
        ("r_shoulder_yaw", 1.5),
    ] {
        folded.joint_positions.insert(joint.into(), value);
    }
    rejected(
        "fridge_pet",
        &world,
        &reply,
        &folded,
        regions,
        "an arm folded into the chest",
        |v| matches!(v, Violation::SelfCollision { .. }),
    );
}
