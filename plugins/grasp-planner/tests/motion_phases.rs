//! The grasp planner checks the approach, the closing and the lift a grasp
//! implies before it returns it (issue #23): with a board placed just above
//! the hand of the can-at-breast-height grasp — clear of the grasp posture by
//! more than every clearance, but in the way of the 5 cm lift — the grasp is
//! no longer returned; the samples it and its like give are counted as
//! `motion blocked`, the blocker naming the lift, and the search goes on.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use serde_json::json;
use tsukami_body::collision::RobotCollision;
use tsukami_body::kinematics::FkState;
use tsukami_body::scene::Scene;
use tsukami_grasp_planner::planner::Planner;
use tsukami_msgs::planner::{HoldRequest, Obstacle, PlanOptions, PlanReply, SetEnv};
use tsukami_scenes::geometry::build_obstacle;
use tsukami_scenes::scene_requests;

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

/// Seed 1 without the hold-margin preference: the side grasp of the can,
/// under which the board is placed (with the preference, the planner takes a
/// grasp whose hand is higher).
fn plan(p: &Planner) -> Result<PlanReply, tsukami_grasp_planner::planner::PlanError> {
    let opts = PlanOptions {
        seed: 1,
        hold: HoldRequest {
            preferred_margin: 1.0,
            ..HoldRequest::default()
        },
        ..PlanOptions::default()
    };
    p.plan(&opts, &AtomicBool::new(false), &mut |_| {})
}

/// A 40 × 40 cm board, 1 cm thick, whose underside is at `z`, over (x, y).
fn board(x: f64, y: f64, z: f64) -> Obstacle {
    serde_json::from_value(json!({
        "name": "board",
        "shape": {"box": {"size": [0.4, 0.4, 0.01]}},
        "pose": {"position": [x, y, z + 0.005]}
    }))
    .unwrap()
}

/// The lowest underside (1 mm steps from the can's top) at which the board
/// clears every link of `reply`'s posture by more than 12 mm.
fn lowest_clear_board(reply: &PlanReply, x: f64, y: f64) -> f64 {
    let s = Scene::load(&models().join("scenes/can_breast.toml")).unwrap();
    let q = posture(&s, reply);
    let mut fk = FkState::new(&s.robot);
    fk.base = s.robot_base;
    s.robot.forward_kinematics(&q, &mut fk);
    let col = RobotCollision::new(&s.robot).unwrap();
    let links: Vec<usize> = (0..s.robot.links.len()).collect();
    let can_top = 1.10 + 0.122;
    (0..300)
        .map(|k| can_top + 0.001 * k as f64)
        .find(|&z| {
            let b = build_obstacle(&board(x, y, z)).unwrap();
            col.first_collision(&fk, &links, &[&b], 0.012).is_none()
        })
        .expect("some height clears the hand")
}

#[test]
fn a_grasp_whose_lift_is_blocked_is_not_returned_and_the_search_moves_on() {
    let req = scene_requests(&models().join("scenes/can_breast.toml")).unwrap();
    let p = Planner::new(models());
    p.set_robot(&req.robot).unwrap();
    p.set_object(&req.object).unwrap();
    p.set_env(&req.env).unwrap();
    let free = plan(&p).expect("the can at breast height is grasped");
    let (x, y) = (0.52, -0.25);
    let z = lowest_clear_board(&free, x, y);
    assert!(
        z < 1.10 + 0.122 + 0.04,
        "the board would be {z} m high: too high to block a 5 cm lift"
    );
    p.set_env(&SetEnv {
        obstacles: vec![board(x, y, z)],
        replace: false,
    })
    .unwrap();
    match plan(&p) {
        // Another grasp: its hand and the can, raised 5 cm, clear the board.
        Ok(r) => {
            assert_ne!(
                r.joint_positions, free.joint_positions,
                "the grasp whose lift the board blocks was returned"
            );
            assert!(
                raised_hand_clears(&r, &board(x, y, z)),
                "{:?}",
                r.grasp_type
            );
            assert!(1.10 + 0.122 + 0.05 < z, "the raised can reaches the board");
        }
        // No grasp: the lifts were what the board blocked.
        Err(e) => {
            let d = e.details();
            let n = d["rejections"]["motion blocked"].as_u64().unwrap_or(0);
            assert!(n >= 2, "motion-blocked rejections: {}", d["rejections"]);
            let blockers = d["blockers"].to_string();
            assert!(blockers.contains("lift_blocked"), "{blockers}");
        }
    }
}

/// The hand links of `reply`'s posture, raised 5 cm, clear `board`.
fn raised_hand_clears(reply: &PlanReply, board: &Obstacle) -> bool {
    let s = Scene::load(&models().join("scenes/can_breast.toml")).unwrap();
    let q = posture(&s, reply);
    let mut fk = FkState::new(&s.robot);
    fk.base = nalgebra::Translation3::new(0.0, 0.0, 0.05) * s.robot_base;
    s.robot.forward_kinematics(&q, &mut fk);
    let palm = s.robot.link_id("r_palm").unwrap();
    let mut hand = vec![palm];
    let mut k = 0;
    while k < hand.len() {
        hand.extend(s.robot.links[hand[k]].children.iter().copied());
        k += 1;
    }
    let col = RobotCollision::new(&s.robot).unwrap();
    let b = build_obstacle(board).unwrap();
    col.first_collision(&fk, &hand, &[&b], 0.0).is_none()
}

/// The scene robot's joint vector of `reply` (mimic joints follow).
fn posture(s: &Scene, reply: &PlanReply) -> Vec<f64> {
    s.robot
        .positions_from_named(
            reply
                .joint_positions
                .iter()
                .filter(|(n, _)| {
                    let j = s.robot.joint_id(n).unwrap();
                    s.robot.joints[j].mimic.is_none()
                })
                .map(|(n, v)| (n.as_str(), *v)),
        )
        .unwrap()
}
