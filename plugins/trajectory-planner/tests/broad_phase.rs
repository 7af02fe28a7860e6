//! The checker's broad phase skips only what cannot collide: after its first
//! check a world tests only the moving bodies' pairs and links whose boxes meet
//! (`tsukami_trajectory_planner::bodies`); a fresh world tests every pair and
//! link. Both must name a collision at exactly the same configurations.

use std::path::PathBuf;

use nalgebra::{Isometry3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tsukami_body::collision::{CollisionObject, Part, RobotCollision};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::Geometry;
use tsukami_body::urdf::load_urdf;
use tsukami_trajectory_planner::checker::RobotWorld;

const JOINTS: [&str; 9] = [
    "waist_yaw",
    "r_shoulder_pitch",
    "r_shoulder_roll",
    "r_shoulder_yaw",
    "r_elbow",
    "r_wrist_yaw",
    "r_wrist_pitch",
    "r_wrist_roll",
    "r_index_j2",
];

#[test]
fn the_broad_phase_agrees_with_testing_every_pair() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let model =
        load_urdf(&root.join("models/robots/tsukami_humanoid/tsukami_humanoid.urdf")).unwrap();
    let mut collision = RobotCollision::new(&model).unwrap();
    // As a hand description does: links touching at rest (neighbouring finger
    // bases) may touch.
    let mut fk = FkState::new(&model);
    model.forward_kinematics(&model.rest_positions(), &mut fk);
    for (a, b) in collision.self_collisions(&fk, 0.01) {
        collision.allow(a, b);
    }
    let joints: Vec<_> = JOINTS.iter().map(|n| model.joint_id(n).unwrap()).collect();
    let table = CollisionObject::new(
        "table",
        Isometry3::translation(0.5, -0.2, 0.45),
        vec![Part::from_geometry(
            &Isometry3::identity(),
            &Geometry::Box {
                size: Vector3::new(0.4, 0.6, 0.9),
            },
        )
        .unwrap()],
    );
    let world = |margin| {
        RobotWorld::new(
            &model,
            &collision,
            vec![&table],
            joints.clone(),
            model.rest_positions(),
            margin,
        )
    };
    let lim: Vec<_> = joints.iter().map(|&j| model.joints[j].limits).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for margin in [0.0, 0.01] {
        let mut pruned = world(margin);
        let rest: Vec<f64> = joints.iter().map(|&j| model.rest_positions()[j]).collect();
        let at_rest = pruned.first_hit(&rest);
        assert!(at_rest.is_none(), "the rest posture: {at_rest:?}");
        let (mut hits, mut self_hits) = (0, 0);
        for _ in 0..400 {
            let q: Vec<f64> = lim
                .iter()
                .map(|l| rng.random_range(l.lower..=l.upper))
                .collect();
            let fast = pruned.first_hit(&q);
            let full = world(margin).first_hit(&q);
            assert_eq!(
                fast.is_some(),
                full.is_some(),
                "at {q:?}: {fast:?} vs {full:?}"
            );
            hits += usize::from(full.is_some());
            self_hits += usize::from(full.is_some_and(|c| c.with.starts_with("link")));
        }
        // Both outcomes, and self-collisions among them, were exercised.
        assert!(hits >= 20 && 400 - hits >= 20, "{hits} of 400 collide");
        assert!(self_hits > 10, "{self_hits} self-collisions");
    }
}
