//! The segment resolution cannot skip a 1 cm obstacle, and RRT-Connect finds a way
//! around it on the real humanoid model.

use std::path::PathBuf;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use tsukami_body::collision::{CollisionObject, Part, RobotCollision};
use tsukami_body::model::{Geometry, RobotModel};
use tsukami_body::urdf::load_urdf;
use tsukami_trajectory_planner::checker::RobotWorld;
use tsukami_trajectory_planner::rrt_connect::{
    plan, segment_valid, Problem, RrtParams, SegmentSteps, Validity,
};
use tsukami_trajectory_planner::shortcut::shortcut;

const ARM: [&str; 7] = [
    "r_shoulder_pitch",
    "r_shoulder_roll",
    "r_shoulder_yaw",
    "r_elbow",
    "r_wrist_yaw",
    "r_wrist_pitch",
    "r_wrist_roll",
];

fn humanoid() -> RobotModel {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    load_urdf(&root.join("models/robots/tsukami_humanoid/tsukami_humanoid.urdf")).unwrap()
}

/// A 1 cm thick board, 30 × 30 cm, centred at `at`, its thin axis along `normal`.
fn board(at: Vector3<f64>, normal: Vector3<f64>) -> CollisionObject {
    let rot = UnitQuaternion::rotation_between(&Vector3::z(), &normal)
        .unwrap_or_else(UnitQuaternion::identity);
    let pose = Isometry3::from_parts(Translation3::from(at), rot);
    let geometry = Geometry::Box {
        size: Vector3::new(0.3, 0.3, 0.01),
    };
    let part = Part::from_geometry(&Isometry3::identity(), &geometry).unwrap();
    CollisionObject::new("board", pose, vec![part])
}

#[test]
fn a_thin_board_across_the_hands_sweep_is_seen_and_avoided() {
    let model = humanoid();
    let collision = RobotCollision::new(&model).unwrap();
    let joints: Vec<_> = ARM.iter().map(|n| model.joint_id(n).unwrap()).collect();
    let rest = model.rest_positions();
    let start = vec![0.0; 7];
    let goal = vec![-1.3, -0.2, 0.0, -0.6, 0.0, 0.0, 0.0];
    let palm = model.link_id("r_palm").unwrap();

    // Where the palm passes half-way, and which way it moves there.
    let mut free = RobotWorld::new(
        &model,
        &collision,
        vec![],
        joints.clone(),
        rest.clone(),
        0.0,
    );
    let mid: Vec<f64> = start
        .iter()
        .zip(&goal)
        .map(|(a, b)| (a + b) / 2.0)
        .collect();
    let ahead: Vec<f64> = start
        .iter()
        .zip(&goal)
        .map(|(a, b)| a + 0.51 * (b - a))
        .collect();
    let p_mid = free.link_pose(&mid, palm).translation.vector;
    let p_ahead = free.link_pose(&ahead, palm).translation.vector;
    let obstacle = board(p_mid, (p_ahead - p_mid).normalize());

    let mut world = RobotWorld::new(&model, &collision, vec![&obstacle], joints, rest, 0.0);
    assert!(world.is_valid(&start) && world.is_valid(&goal));
    // The straight segment crosses the board: the checks at the stated
    // resolution (no link point moves more than 5 mm between two) find it.
    let res = world.resolution();
    assert!(!segment_valid(&mut world, &res, &start, &goal));
    let n = world.resolution().steps(&start, &goal);
    assert!(n > 50, "the sweep bound asks for {n} checks");

    let (lower, upper) = world.bounds();
    let problem = Problem {
        lower: &lower,
        upper: &upper,
        start: &start,
        goal: &goal,
    };
    let params = RrtParams {
        max_samples: 4000,
        seed: 1,
        ..RrtParams::default()
    };
    let path =
        plan(&problem, &params, &mut world, &res, &|| false).expect("a way around a 30 cm board");
    let path = shortcut(path, 100, 1, &mut world, &res);
    assert_eq!(path.first(), Some(&start));
    assert_eq!(path.last(), Some(&goal));
    // Independent re-check at 1 mm of travel between checks.
    let mut fine = RobotWorld::new(
        &model,
        &collision,
        vec![&obstacle],
        ARM.iter().map(|n| model.joint_id(n).unwrap()).collect(),
        model.rest_positions(),
        0.0,
    )
    .with_max_travel(0.001);
    for w in path.windows(2) {
        let steps = fine.resolution();
        assert!(segment_valid(&mut fine, &steps, &w[0], &w[1]));
    }
}
