//! A third party swaps in their own planner by host config alone: the example
//! antipodal planner (`plugins/examples/antipodal-planner`, built only against the
//! `host/` crates) fills the `grasp-planner` role and plans the can scene over the bus.

use std::time::Duration;
use tsukami_e2e::{grasp_planner_entry, models_dir, test_config, TestBus};
use tsukami_msgs::keys::{planner, ROLE_GRASP_PLANNER};
use tsukami_msgs::planner::PlanReply;
use tsukami_scenes::{scene_requests, verify, Tolerances, World};

const T: Duration = Duration::from_secs(60);

#[test]
fn the_example_planner_fills_the_grasp_planner_role_by_config_alone() {
    let entry = grasp_planner_entry("tsukami_antipodal_planner");
    let bus = TestBus::start(test_config(vec![entry]));
    let c = &bus.client;

    let listing = c.wait_for_host(T).unwrap();
    assert_eq!(listing.plugins[0].name, "tsukami-antipodal-planner");
    assert_eq!(
        listing.plugins[0].roles,
        vec![ROLE_GRASP_PLANNER.to_owned()]
    );

    // The same commands any client sends to the built-in planner.
    let req = scene_requests(&models_dir().join("scenes/can_breast.toml")).unwrap();
    let send =
        |command: &str, body: Vec<u8>| c.command(ROLE_GRASP_PLANNER, command, &body, T).unwrap();
    send(planner::SET_ROBOT, serde_json::to_vec(&req.robot).unwrap());
    send(
        planner::SET_OBJECT,
        serde_json::to_vec(&req.object).unwrap(),
    );
    send(planner::SET_ENV, serde_json::to_vec(&req.env).unwrap());
    let reply: PlanReply =
        serde_json::from_slice(&send(planner::PLAN, br#"{"seed": 2}"#.to_vec())).unwrap();

    assert!(reply.contacts.len() >= 2, "{:?}", reply.contacts);
    assert!(reply.joint_positions.contains_key("r_wrist_roll"));
    // The built-in planner's checker judges the third party's grasp too: force
    // closure with the weight recomputed, contacts on the can, no link in the
    // counter or the can, limits, the reply's mass and μ are the client's.
    let world = World::from_requests(&models_dir(), &req.robot, &req.object, &req.env).unwrap();
    let verdict = verify(&world, &reply, &Tolerances::default());
    assert!(verdict.is_ok(), "{verdict}");
    assert!(verdict.weight_scale.unwrap() >= 1.0);
}
