//! Plans the can scenes in-process, calling the planner directly, and checks
//! the grasps with the project's independent checker (`tsukami_scenes::verify`):
//! the exact force-closure test with the weight recomputed from the reply,
//! contacts on the can, no link inside the can or the furniture, joint limits.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use nalgebra::Vector3;
use tsukami_antipodal_planner::AntipodalPlanner;
use tsukami_msgs::planner::{PlanOptions, PlanReply};
use tsukami_scenes::{verify, Tolerances, Verdict, World};

fn models() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../models")
}

fn planner_for(scene: &str) -> AntipodalPlanner {
    let req = tsukami_scenes::scene_requests(&models().join("scenes").join(scene)).unwrap();
    let p = AntipodalPlanner::new(models());
    p.set_robot(&req.robot).unwrap();
    p.set_object(&req.object).unwrap();
    p.set_env(&req.env).unwrap();
    p
}

/// The independent check of the reply in the scene's world.
fn verdict(scene: &str, r: &PlanReply) -> Verdict {
    let req = tsukami_scenes::scene_requests(&models().join("scenes").join(scene)).unwrap();
    let world = World::from_requests(&models(), &req.robot, &req.object, &req.env).unwrap();
    verify(&world, r, &Tolerances::default())
}

fn check_scene(scene: &str) {
    let planner = planner_for(scene);
    let cancel = AtomicBool::new(false);
    let mut events = 0;
    let reply = planner
        .plan(&PlanOptions::default(), &cancel, &mut |_| events += 1)
        .unwrap_or_else(|e| panic!("{scene}: {e}"));
    assert!(events >= 2, "progress events: {events}");
    assert_eq!(reply.contacts.len(), 3);
    assert!(reply.contacts[0].link.starts_with("r_thumb"));
    let v = verdict(scene, &reply);
    assert!(v.is_ok(), "{scene}: {v}");
    assert!(v.weight_scale.unwrap() >= 1.0);
    assert_eq!(reply.grasp_type.name, "fingertip3_mid");
    assert!(reply.joint_positions.contains_key("r_elbow"));
    assert!(reply.joint_positions.contains_key("r_index_j2"));
    assert!((reply.object.mass - 0.15).abs() < 1e-12);
    assert!(reply.characteristic_length > 0.1 && reply.characteristic_length < 0.13);
    assert!(reply.timing_ms.total > 0.0);
    // Contacts lie on the can's surface: 33 mm from its vertical axis (or on
    // a cap), between its bottom and its top (122 mm).
    let req = tsukami_scenes::scene_requests(&models().join("scenes").join(scene)).unwrap();
    let base = Vector3::from(req.object.pose.position);
    for c in &reply.contacts {
        assert!(c.f_max > 0.0);
        assert!((Vector3::from(c.normal).norm() - 1.0).abs() < 1e-9);
        let p = Vector3::from(c.position) - base;
        let radial = p.xy().norm();
        assert!(
            radial < 0.0335 && p.z > -1e-3 && p.z < 0.123,
            "{scene}: contact {p:?} not on the can"
        );
        assert!(
            radial > 0.032 || p.z < 1e-3 || p.z > 0.121,
            "{scene}: contact {p:?} inside the can"
        );
    }
    eprintln!(
        "{scene}: {} samples, {:.1} ms, face {:?}, margin {:.3}, joints_used {:?}",
        reply.samples,
        reply.timing_ms.total,
        reply.face,
        reply.force_closure.margin,
        reply.joints_used
    );
}

#[test]
fn can_breast() {
    check_scene("can_breast.toml");
}

#[test]
fn can_waist() {
    check_scene("can_waist.toml");
}
