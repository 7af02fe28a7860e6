//! The project's humanoid model: structure, naming contract, frames.

mod common;

use nalgebra::{Point3, Vector3};
use tsukami_body::collision::RobotCollision;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::JointKind;

#[test]
fn naming_contract_and_dimensions() {
    let m = common::humanoid();
    assert_eq!(m.links[0].name, "base_link");
    let names = [
        "squat_z",
        "waist_yaw",
        "waist_pitch",
        "head_yaw",
        "head_pitch",
        "camera_joint",
        "r_shoulder_pitch",
        "r_shoulder_roll",
        "r_shoulder_yaw",
        "r_elbow",
        "r_wrist_yaw",
        "r_wrist_pitch",
        "r_wrist_roll",
    ];
    for n in names {
        m.joint_id(n).unwrap_or_else(|_| panic!("joint {n}"));
    }
    for l in [
        "pelvis",
        "waist_link",
        "chest",
        "camera_link",
        "r_palm",
        "r_shoulder_link",
    ] {
        m.link_id(l).unwrap_or_else(|_| panic!("link {l}"));
    }
    let squat = &m.joints[m.joint_id("squat_z").unwrap()];
    assert_eq!(squat.kind, JointKind::Prismatic);
    assert_eq!(m.links[squat.parent].name, "base_link");
    assert_eq!(m.links[squat.child].name, "pelvis");
    assert!((squat.limits.lower + 0.40).abs() < 1e-12 && squat.limits.upper == 0.0);
    // Fingers: thumb 5 joints, others 4; distal joints mimic the previous one.
    for f in ["index", "middle", "ring"] {
        for k in 1..=4 {
            m.joint_id(&format!("r_{f}_j{k}")).unwrap();
            m.link_id(&format!("r_{f}_l{k}")).unwrap();
        }
        let j4 = &m.joints[m.joint_id(&format!("r_{f}_j4")).unwrap()];
        let mimic = j4.mimic.as_ref().expect("j4 mimics j3");
        assert_eq!(mimic.joint_name, format!("r_{f}_j3"));
        assert_eq!(mimic.multiplier, 1.0);
    }
    for k in 1..=5 {
        m.joint_id(&format!("r_thumb_j{k}")).unwrap();
        let l = m.link_id(&format!("r_thumb_l{k}")).unwrap();
        assert!(!m.links[l].collisions.is_empty());
    }
    let j5 = &m.joints[m.joint_id("r_thumb_j5").unwrap()];
    assert_eq!(j5.mimic.as_ref().unwrap().joint_name, "r_thumb_j4");
    // Every finger link has a collision shape, every finger joint an effort limit.
    for (j, joint) in m.joints.iter().enumerate() {
        if ["r_thumb_j", "r_index_j", "r_middle_j", "r_ring_j"]
            .iter()
            .any(|p| joint.name.starts_with(p))
        {
            assert!(
                !m.links[j + 1].collisions.is_empty(),
                "{}",
                m.links[j + 1].name
            );
            assert!(
                joint.limits.effort > 0.0 && joint.limits.effort <= 5.0,
                "{}",
                joint.name
            );
        }
    }

    let mut fk = FkState::new(&m);
    m.forward_kinematics(&m.rest_positions(), &mut fk);
    let z = |fk: &FkState, l: &str| fk.pose(m.link_id(l).unwrap()).translation.vector.z;
    assert!((z(&fk, "pelvis") - 0.85).abs() < 1e-12);
    let shoulder = z(&fk, "r_shoulder_link");
    assert!(
        (1.35..=1.40).contains(&shoulder),
        "shoulder height {shoulder}"
    );
    // Squatting lowers the shoulder by the joint value.
    let q = m.positions_from_named([("squat_z", -0.4)]).unwrap();
    m.forward_kinematics(&q, &mut fk);
    assert!((z(&fk, "r_shoulder_link") - (shoulder - 0.4)).abs() < 1e-12);
    // Total height about 1.6 m and mass about HRP-3P's 65 kg.
    assert!(
        (55.0..=75.0).contains(&m.total_mass()),
        "{}",
        m.total_mass()
    );
}

#[test]
fn palm_frame_convention() {
    let m = common::humanoid();
    let mut fk = FkState::new(&m);
    m.forward_kinematics(&m.rest_positions(), &mut fk);
    let palm = fk.pose(m.link_id("r_palm").unwrap());
    // Arm hanging: fingers point down (+x palm = -z world), the palm faces the
    // body (+z palm = +y world), the thumb side is -y palm = +x world.
    let r = palm.rotation;
    assert!((r * Vector3::x() - (-Vector3::z())).norm() < 1e-7);
    assert!((r * Vector3::z() - Vector3::y()).norm() < 1e-7);
    assert!((r * Vector3::y() - (-Vector3::x())).norm() < 1e-7);
    // The thumb base is on the palm's -y side; fingertips are along +x.
    let palm_inv = palm.inverse();
    let thumb = palm_inv * fk.pose(m.link_id("r_thumb_l2").unwrap()).translation.vector;
    assert!(thumb.y < -0.04, "{thumb:?}");
    let tip = palm_inv
        * Point3::from(
            fk.pose(m.link_id("r_middle_l4").unwrap())
                .translation
                .vector,
        );
    assert!(tip.x > 0.1, "{tip:?}");
    // Flexing j2 moves the finger toward +z of the palm.
    let q = m.positions_from_named([("r_index_j2", 0.8)]).unwrap();
    m.forward_kinematics(&q, &mut fk);
    let palm_inv = fk.pose(m.link_id("r_palm").unwrap()).inverse();
    let tip = palm_inv * Point3::from(fk.pose(m.link_id("r_index_l3").unwrap()).translation.vector);
    assert!(tip.z > 0.015, "{tip:?}");
    // Camera optical frame: z forward (+x world), y down.
    m.forward_kinematics(&m.rest_positions(), &mut fk);
    let cam = fk.pose(m.link_id("camera_link").unwrap()).rotation;
    assert!((cam * Vector3::z() - Vector3::x()).norm() < 1e-7);
    assert!((cam * Vector3::y() - (-Vector3::z())).norm() < 1e-7);
}

#[test]
fn rest_pose_is_free_of_self_collision() {
    let m = common::humanoid();
    let c = RobotCollision::new(&m).unwrap();
    let mut fk = FkState::new(&m);
    m.forward_kinematics(&m.rest_positions(), &mut fk);
    let hits: Vec<(String, String)> = c
        .self_collisions(&fk, 0.0)
        .into_iter()
        .map(|(a, b)| (m.links[a].name.clone(), m.links[b].name.clone()))
        .collect();
    assert!(hits.is_empty(), "{hits:?}");
    // An arm swung into the chest is detected.
    let q = m
        .positions_from_named([
            ("r_shoulder_roll", 0.25),
            ("r_shoulder_pitch", -1.3),
            ("r_elbow", -2.3),
            ("r_shoulder_yaw", 1.5),
        ])
        .unwrap();
    m.forward_kinematics(&q, &mut fk);
    assert!(c.first_self_collision(&fk, 0.0).is_some());
}

/// The torso's own links never meet over the whole waist and squat range: the
/// chest clears the pelvis at full forward pitch (no pair among them is left
/// unchecked in the robot description, so the model itself must keep them apart).
#[test]
fn the_torso_clears_the_pelvis_over_the_waist_and_squat_range() {
    let m = common::humanoid();
    let c = RobotCollision::new(&m).unwrap();
    let mut fk = FkState::new(&m);
    let torso = [
        "base_link",
        "pelvis",
        "waist_link",
        "chest",
        "neck_link",
        "head_link",
        "l_arm_stub",
    ];
    let torso: Vec<usize> = torso.iter().map(|n| m.link_id(n).unwrap()).collect();
    let steps = |lo: f64, hi: f64| (0..=8).map(move |i| lo + (hi - lo) * f64::from(i) / 8.0);
    for yaw in steps(-0.8, 0.8) {
        for pitch in steps(-0.1, 0.75) {
            for squat in [-0.4, -0.2, 0.0] {
                for head in [-0.5, 0.9] {
                    let q = m
                        .positions_from_named([
                            ("waist_yaw", yaw),
                            ("waist_pitch", pitch),
                            ("squat_z", squat),
                            ("head_pitch", head),
                        ])
                        .unwrap();
                    m.forward_kinematics(&q, &mut fk);
                    let hits: Vec<(&str, &str)> = c
                        .self_collisions(&fk, 0.0)
                        .into_iter()
                        .filter(|(a, b)| torso.contains(a) && torso.contains(b))
                        .map(|(a, b)| (m.links[a].name.as_str(), m.links[b].name.as_str()))
                        .collect();
                    assert!(
                        hits.is_empty(),
                        "yaw {yaw}, pitch {pitch}, squat {squat}: {hits:?}"
                    );
                }
            }
        }
    }
}
