//! The trajectory planner over a real zenoh bus: a host with the real grasp-planner
//! and trajectory-planner plugin files; for each of the paper's scenes the grasp is
//! planned, then `motion/plan` runs from the rest posture to it, and the trajectory
//! is re-checked here, independently of the planner's own checks:
//! - the controller's own trajectory check (`tsukami_controller::trajectory::Plan`)
//!   accepts it from the rest posture;
//! - times start at 0 and increase; every position within its joint's limits; every
//!   point's velocity and every step's mean speed within the URDF velocity limit;
//!   the first point is the rest posture;
//! - the last point before the lift is the planned grasp posture;
//! - collision-free at a fine resolution (no joint moves more than 1 mrad / 1 mm
//!   between two checks; the world rebuilt from the scene file by
//!   `tsukami_scenes::World`): no link inside an obstacle or the object (hand links
//!   may touch the object up to 1 mm while approaching and closing, as the grasp
//!   planner's verification allows), no self-collision of the arm and hand;
//! - the lift raises the object (carried at the palm) without it or any non-hand
//!   link entering anything;
//! - the Plan reply's squeeze is commanded from the end of `close` through the
//!   lift, and the controller running the trajectory ends commanding its targets.

use std::time::Duration;

use nalgebra::{Isometry3, Translation3};
use serde_json::json;
use tsukami::scenes::run_scene;
use tsukami_body::collision::CollisionObject;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::LinkId;
use tsukami_bus::client::{BusClient, RequestError};
use tsukami_controller::joints::JointTable;
use tsukami_controller::trajectory::Plan;
use tsukami_controller::Executor;
use tsukami_e2e::{models_dir, motion_entry, planner_entry, test_config, TestBus};

#[allow(dead_code)]
#[path = "../../plugins/grasp-planner/tests/common/objects.rs"]
mod objects;
use tsukami_msgs::common::Pose;
use tsukami_msgs::keys::{planner, ROLE_GRASP_PLANNER, ROLE_TRAJECTORY_PLANNER};
use tsukami_msgs::motion::{JointTrajectory, MotionPlanReply};
use tsukami_msgs::planner::{Obstacle, ObstacleShape, PlanReply, SetEnv};
use tsukami_msgs::ErrorCode;
use tsukami_scenes::paper_scene;
use tsukami_scenes::requests::scene_requests;
use tsukami_scenes::world::World;

const TIMEOUT: Duration = Duration::from_secs(120);
/// Largest joint change between two re-checks (rad or m).
const FINE: f64 = 1e-3;
/// How deep a hand link may be in the object while approaching and closing.
const TOUCH: f64 = 1e-3;
/// The default clearances of a motion (m): every link but the hand's, and the
/// hand's until `close`.
const CLEARANCE_BODY: f64 = 0.010;
const CLEARANCE_HAND: f64 = 0.003;
/// Half the planner's check resolution (5 mm of travel between two checks).
const SLACK: f64 = 0.0025;

fn bus() -> TestBus {
    TestBus::start(test_config(vec![planner_entry(), motion_entry()]))
}

fn motion(
    client: &BusClient,
    request: &serde_json::Value,
) -> Result<MotionPlanReply, RequestError> {
    let payload = serde_json::to_vec(request).unwrap();
    client
        .command(ROLE_TRAJECTORY_PLANNER, "plan", &payload, TIMEOUT)
        .map(|bytes| serde_json::from_slice(&bytes).expect("a MotionPlanReply"))
}

/// Sets the scene up on the bus, plans its grasp; returns the grasp and the
/// independent world.
fn grasp_of(bus: &TestBus, name: &str) -> (PlanReply, World) {
    let scene = paper_scene(name).expect("a paper scene");
    let outcome = run_scene(&bus.client, &models_dir(), scene, 0, TIMEOUT);
    assert!(outcome.ok, "{name}: the grasp: {:?}", outcome.problem);
    let file = models_dir().join("scenes").join(format!("{name}.toml"));
    let r = scene_requests(&file).unwrap();
    let world = World::from_requests(&models_dir(), &r.robot, &r.object, &r.env).unwrap();
    (outcome.result.unwrap(), world)
}

/// The trajectory's joints as full configurations of the model (rest elsewhere).
fn full_configs(world: &World, t: &JointTrajectory) -> Vec<Vec<f64>> {
    let model = &world.robot.model;
    let ids: Vec<usize> = t
        .joint_names
        .iter()
        .map(|n| model.joint_id(n).unwrap())
        .collect();
    t.points
        .iter()
        .map(|p| {
            let mut q = model.rest_positions();
            for (&j, &v) in ids.iter().zip(&p.positions) {
                q[j] = v;
            }
            model.apply_mimics(&mut q);
            q
        })
        .collect()
}

fn check_timing_and_limits(world: &World, t: &JointTrajectory) {
    let model = &world.robot.model;
    let table = JointTable::from_model(model);
    Plan::check(t, &table, &table.rest_positions(), 1e-9)
        .expect("the controller accepts it from rest");
    assert_eq!(t.points[0].time, 0.0);
    for (k, w) in t.points.windows(2).enumerate() {
        let dt = w[1].time - w[0].time;
        assert!(dt > 0.0, "point {k}: times must increase");
        for (i, name) in t.joint_names.iter().enumerate() {
            let joint = &model.joints[model.joint_id(name).unwrap()];
            let (lim, q) = (joint.limits, w[1].positions[i]);
            assert!(
                q >= lim.lower - 1e-9 && q <= lim.upper + 1e-9,
                "point {}: {name} = {q}",
                k + 1
            );
            let mean = (w[1].positions[i] - w[0].positions[i]).abs() / dt;
            assert!(
                mean <= lim.velocity + 1e-9,
                "points {k}-{}: {name} at {mean} > {}",
                k + 1,
                lim.velocity
            );
            assert!(
                w[1].velocities[i].abs() <= lim.velocity + 1e-9,
                "point {}: {name} velocity",
                k + 1
            );
        }
    }
    let rest = model.rest_positions();
    for (name, q) in t.joint_names.iter().zip(&t.points[0].positions) {
        assert!(
            (q - rest[model.joint_id(name).unwrap()]).abs() < 1e-9,
            "starts at rest: {name}"
        );
    }
}

/// The arm's and hand's links (everything the trajectory moves relative to the
/// body) and a collision table checking only pairs involving one of them.
struct Fine<'w> {
    world: &'w World,
    collision: tsukami_body::collision::RobotCollision,
    links: Vec<LinkId>,
    fk: FkState,
    checks: usize,
}

impl<'w> Fine<'w> {
    fn new(world: &'w World) -> Self {
        let model = &world.robot.model;
        // Every link pair but the adjacent ones and the description's
        // `allowed_collisions`: the torso, head and legs included.
        let collision = world.robot.collision.clone();
        let n = model.links.len();
        let links = (0..n)
            .filter(|&l| !collision.link_parts(l).is_empty())
            .collect();
        Fine {
            world,
            collision,
            links,
            fk: FkState::new(model),
            checks: 0,
        }
    }

    /// Problems of configuration `q` in `phase` (empty when clear).
    fn problem(
        &mut self,
        q: &[f64],
        phase: &str,
        carried: Option<(&Isometry3<f64>, &[usize])>,
    ) -> Option<String> {
        self.checks += 1;
        let w = self.world;
        let model = &w.robot.model;
        model.forward_kinematics(q, &mut self.fk);
        let name = |l: LinkId| model.links[l].name.clone();
        let obstacles: Vec<&CollisionObject> = w.obstacles.iter().collect();
        if let Some(p) = self
            .collision
            .first_penetration(&self.fk, &self.links, &obstacles, 0.0)
        {
            return Some(format!(
                "{} {:.2} mm inside {}",
                name(p.link),
                p.depth * 1e3,
                obstacles[p.object].name
            ));
        }
        if let Some((a, b)) = self.collision.first_self_collision(&self.fk, 0.0) {
            return Some(format!("{} hits {}", name(a), name(b)));
        }
        let hand = &w.robot.hand_links;
        // The stated clearances (10 mm for every link but the hand's in every
        // phase, 3 mm for the hand in the reach and the approach), which the
        // planner keeps at each of its checks: between two of them a link
        // point moves at most its 5 mm resolution, so half of that is the slack.
        let (body, hand_links): (Vec<LinkId>, Vec<LinkId>) =
            self.links.iter().partition(|l| !hand.contains(l));
        let mut rules = vec![(body, CLEARANCE_BODY - SLACK)];
        if phase == "reach" || phase == "approach" {
            rules.push((hand_links, CLEARANCE_HAND - SLACK));
        }
        for (links, margin) in rules {
            if let Some(h) = self
                .collision
                .first_collision(&self.fk, &links, &obstacles, margin)
            {
                return Some(format!(
                    "{} within {:.1} mm of {} ({phase})",
                    name(h.link),
                    margin * 1e3,
                    obstacles[h.object].name
                ));
            }
        }
        for &l in &self.links {
            let touch = phase != "reach" && carried.is_none() && hand.contains(&l);
            let depth = self
                .collision
                .link_penetration(&self.fk, l, &w.object.collision);
            let allowed = if touch { TOUCH } else { 0.0 };
            if carried.is_none() && depth > allowed {
                return Some(format!(
                    "{} {:.2} mm inside the object ({phase})",
                    name(l),
                    depth * 1e3
                ));
            }
        }
        let (relative, supports) = carried?;
        let mut body = w.object.collision.clone();
        let pose = self.fk.pose(w.robot.palm) * relative;
        body.set_pose(pose);
        let risen = pose.translation.vector.z - w.object.pose.translation.vector.z;
        for (i, o) in w.obstacles.iter().enumerate() {
            if (risen >= 1e-3 || !supports.contains(&i)) && body.intersects(o, 0.0) {
                return Some(format!(
                    "the carried object hits {} (risen {:.1} mm)",
                    o.name,
                    risen * 1e3
                ));
            }
        }
        let others: Vec<LinkId> = self
            .links
            .iter()
            .copied()
            .filter(|l| !hand.contains(l))
            .collect();
        self.collision
            .first_collision(&self.fk, &others, &[&body], 0.0)
            .map(|h| format!("{} hits the carried object", name(h.link)))
    }
}

/// Re-checks every segment at `FINE`, phase by phase.
fn check_collisions(world: &World, t: &JointTrajectory) -> usize {
    let configs = full_configs(world, t);
    let mut fine = Fine::new(world);
    let palm = world.robot.palm;
    let lift_from = t
        .points
        .iter()
        .position(|p| p.phase == "lift")
        .expect("a lift");
    let mut fk = FkState::new(&world.robot.model);
    world
        .robot
        .model
        .forward_kinematics(&configs[lift_from - 1], &mut fk);
    let relative = fk.pose(palm).inverse() * world.object.pose;
    let supports: Vec<usize> = (0..world.obstacles.len())
        .filter(|&i| world.object.collision.intersects(&world.obstacles[i], 1e-3))
        .collect();
    for k in 1..configs.len() {
        let (a, b) = (&configs[k - 1], &configs[k]);
        let phase = t.points[k].phase.as_str();
        let carried = (phase == "lift").then_some((&relative, supports.as_slice()));
        let span = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        let n = (span / FINE).ceil().max(1.0) as usize;
        for i in 0..=n {
            let s = i as f64 / n as f64;
            let q: Vec<f64> = a.iter().zip(b).map(|(x, y)| x + s * (y - x)).collect();
            if let Some(p) = fine.problem(&q, phase, carried) {
                panic!("points {}-{k} ({phase}), s = {s:.3}: {p}", k - 1);
            }
        }
    }
    // The lift raised the carried object.
    world
        .robot
        .model
        .forward_kinematics(configs.last().unwrap(), &mut fk);
    let lifted =
        (fk.pose(palm) * relative).translation.vector.z - world.object.pose.translation.vector.z;
    assert!(lifted > 0.04, "the object rose {lifted} m");
    fine.checks
}

fn ends_at_the_grasp(world: &World, t: &JointTrajectory, grasp: &PlanReply) {
    let k = t.points.iter().rposition(|p| p.phase != "lift").unwrap();
    assert_eq!(t.points[k].phase, "close");
    let q = &full_configs(world, t)[k];
    let model = &world.robot.model;
    for (name, g) in &grasp.joint_positions {
        let v = q[model.joint_id(name).unwrap()];
        assert!(
            (v - g).abs() < 1e-6,
            "{name}: {v} at the end of close, {g} planned"
        );
    }
}

/// The controller runs the trajectory from rest and ends commanding the Plan
/// reply's squeeze targets to the squeezed joints (the lift held them), the
/// trajectory's last positions everywhere (the physical posture); from the end of
/// `close` on, the points command the targets.
fn squeeze_is_commanded(world: &World, t: &JointTrajectory, grasp: &PlanReply) {
    assert!(!grasp.squeeze.is_empty(), "the Plan reply squeezes");
    let target = |name: &str| grasp.squeeze.iter().find(|s| s.joint == name);
    let from = t.points.iter().rposition(|p| p.phase == "close").unwrap();
    for (k, p) in t.points.iter().enumerate().skip(from) {
        for (i, name) in t.joint_names.iter().enumerate() {
            let want = target(name).map_or(p.positions[i], |s| s.target);
            assert_eq!(p.command.get(i), Some(&want), "point {k}: {name}");
        }
    }
    let table = JointTable::from_model(&world.robot.model);
    let mut ex = Executor::new(table, 100.0, None).unwrap();
    ex.start(t, 1e-9)
        .expect("the controller accepts it from rest");
    while ex.step().is_none() {}
    let state = ex.state();
    assert_eq!(state.status, "done");
    let last = t.points.last().unwrap();
    for (i, name) in t.joint_names.iter().enumerate() {
        let j = state.joint_names.iter().position(|n| n == name).unwrap();
        assert!(
            (state.positions[j] - last.positions[i]).abs() < 1e-9,
            "{name}"
        );
        let want = target(name).map_or(last.positions[i], |s| s.target);
        assert!((state.commanded[j] - want).abs() < 1e-9, "{name} commanded");
    }
}

fn plan_and_recheck(name: &str) {
    let bus = bus();
    let (grasp, world) = grasp_of(&bus, name);
    let reply = motion(&bus.client, &json!({ "grasp": grasp, "seed": 1 }))
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(reply.start_source, "rest", "no controller on this bus");
    let t = &reply.trajectory;
    let phases: Vec<&str> = t.points.iter().map(|p| p.phase.as_str()).collect();
    let order = ["reach", "approach", "close", "lift"];
    let mut seen: Vec<&str> = phases.clone();
    seen.dedup();
    assert_eq!(seen, order, "{name}: phases in order");
    check_timing_and_limits(&world, t);
    ends_at_the_grasp(&world, t, &grasp);
    squeeze_is_commanded(&world, t, &grasp);
    let checks = check_collisions(&world, t);
    eprintln!(
        "{name}: {} points, {:.2} s, {} samples, {} planner checks, {checks} re-checks, {:.1} ms",
        t.points.len(),
        t.points.last().unwrap().time,
        reply.samples,
        reply.checks,
        reply.planning_ms
    );
    assert!(checks > 1000, "{name}: {checks} re-checks");
    let c = reply
        .clearance
        .as_ref()
        .expect("every paper scene has obstacles");
    eprintln!(
        "{name}: nearest an obstacle: {:.1} mm, {} to {} in {} at {:.2} s",
        c.distance * 1e3,
        c.link,
        c.obstacle,
        c.phase,
        c.time
    );
    assert!(c.distance >= 0.0 && !c.link.is_empty(), "{name}: {c:?}");
    let named = world.obstacles.iter().any(|o| o.name == c.obstacle);
    assert!(named, "{name}: {c:?}");
    for used in &grasp.joints_used {
        assert!(t.joint_names.contains(used), "{name}: {used} is moved");
    }
    // Same seed and world: the same trajectory.
    let again = motion(&bus.client, &json!({ "grasp": grasp, "seed": 1 })).unwrap();
    assert_eq!(&again.trajectory, t, "{name}: deterministic");
}

#[test]
fn can_breast_reach_approach_close_lift() {
    plan_and_recheck("can_breast");
}

#[test]
fn can_waist_reach_approach_close_lift() {
    plan_and_recheck("can_waist");
}

#[test]
fn heavy_low_with_squat_reach_approach_close_lift() {
    plan_and_recheck("heavy_low");
}

#[test]
fn fridge_pet_squatting_to_the_shelf() {
    plan_and_recheck("fridge_pet");
}

#[test]
fn vase_table_reach_approach_close_lift() {
    plan_and_recheck("vase_table");
}

fn board(name: &str, at: [f64; 3], size: [f64; 3]) -> Obstacle {
    Obstacle {
        name: name.into(),
        shape: ObstacleShape::Box { size },
        pose: Pose {
            position: at,
            quaternion: [0.0, 0.0, 0.0, 1.0],
        },
    }
}

/// A safety distance the scene cannot give is refused naming the obstacle in
/// the way; one out of range is `invalid_value` naming the field.
#[test]
fn the_requested_clearance_is_kept_or_the_motion_refused() {
    let bus = bus();
    let (grasp, _) = grasp_of(&bus, "can_breast");
    let wide = json!({ "grasp": grasp, "clearance": { "body": 0.1, "hand": 0.1 } });
    let e = refusal(motion(&bus.client, &wide));
    assert_eq!(e.code, ErrorCode::Infeasible, "{}", e.message);
    assert!(e.message.contains("obstacle `"), "{}", e.message);
    let bad = json!({ "grasp": grasp, "clearance": { "hand": 0.5 } });
    let e = refusal(motion(&bus.client, &bad));
    assert_eq!(e.code, ErrorCode::InvalidValue);
    assert_eq!(e.details.unwrap()["field"], "clearance.hand");
    let none = json!({ "grasp": grasp, "clearance": { "body": 0.0, "hand": 0.0 } });
    motion(&bus.client, &none).expect("no clearance: the default motion's room suffices");
}

/// Sets the object over the bus; the new world version.
fn set_object(client: &BusClient, object: &tsukami_msgs::planner::SetObject) -> u64 {
    let reply = client
        .command(
            ROLE_GRASP_PLANNER,
            planner::SET_OBJECT,
            &serde_json::to_vec(object).unwrap(),
            TIMEOUT,
        )
        .expect("set_object");
    serde_json::from_slice::<serde_json::Value>(&reply).unwrap()["world_version"]
        .as_u64()
        .unwrap()
}

fn set_env(client: &BusClient, obstacles: Vec<Obstacle>) {
    let env = SetEnv {
        obstacles,
        replace: false,
    };
    client
        .command(
            ROLE_GRASP_PLANNER,
            planner::SET_ENV,
            &serde_json::to_vec(&env).unwrap(),
            TIMEOUT,
        )
        .expect("set_env");
}

/// A shelf board just above the can: the hand must pass under it. Solved (and then
/// re-checked) or reported unsolved with the budget's reason, never anything else.
#[test]
fn narrow_passage_under_a_shelf_board_is_solved_or_reported() {
    let bus = bus();
    let (_, mut world) = grasp_of(&bus, "can_breast");
    // The can's top is 0.122 m above the counter (1.10 m): the board's underside
    // 8 cm above that, across the whole counter. The grasp is planned with it.
    let shelf = board(
        "shelf",
        [0.70, -0.20, 1.10 + 0.122 + 0.08 + 0.005],
        [0.45, 1.0, 0.01],
    );
    set_env(&bus.client, vec![shelf.clone()]);
    world
        .obstacles
        .push(tsukami_scenes::geometry::build_obstacle(&shelf).unwrap());
    let plan = bus
        .client
        .command(
            ROLE_GRASP_PLANNER,
            planner::PLAN,
            br#"{"seed": 0}"#,
            TIMEOUT,
        )
        .expect("a grasp under the shelf");
    let grasp: PlanReply = serde_json::from_slice(&plan).unwrap();
    let request = json!({ "grasp": grasp, "seed": 3, "max_samples": 3000, "lift_height": 0.05 });
    match motion(&bus.client, &request) {
        Ok(reply) => {
            eprintln!(
                "narrow passage solved: {} samples, {:.1} ms",
                reply.samples, reply.planning_ms
            );
            check_timing_and_limits(&world, &reply.trajectory);
            ends_at_the_grasp(&world, &reply.trajectory, &grasp);
            check_collisions(&world, &reply.trajectory);
        }
        Err(RequestError::Reply(e)) => {
            assert_eq!(e.error.code, ErrorCode::Infeasible, "{}", e.error.message);
            let reason = e.error.details.unwrap()["reason"]
                .as_str()
                .unwrap()
                .to_owned();
            eprintln!(
                "narrow passage reported unsolved: {reason}: {}",
                e.error.message
            );
            assert!(
                [
                    "no_path",
                    "approach_blocked",
                    "lift_blocked",
                    "pregrasp_unreachable"
                ]
                .contains(&reason.as_str()),
                "{reason}: {}",
                e.error.message
            );
        }
        Err(e) => panic!("{e}"),
    }
}

/// The error object of a refused motion request.
fn refusal(r: Result<MotionPlanReply, RequestError>) -> tsukami_msgs::error::ErrorBody {
    match r {
        Err(RequestError::Reply(e)) => e.error,
        Err(other) => panic!("expected a refusal: {other}"),
        Ok(m) => panic!(
            "expected a refusal, got a motion (clearance {:?})",
            m.clearance
        ),
    }
}

/// Plan on one world version, move the object (the next version), send the old
/// grasp: refused, naming both versions. Asked to re-validate it, the motion
/// planner checks the grasp on the current world and refuses it (the hand would
/// close beside the can); with the can back in place (another version) the
/// re-validated grasp holds and the reply names the version it was planned on.
#[test]
fn a_grasp_of_another_world_version_is_refused_naming_both() {
    let bus = bus();
    let (grasp, _) = grasp_of(&bus, "can_breast");
    let v = grasp.world_version;
    let file = models_dir().join("scenes/can_breast.toml");
    let object = scene_requests(&file).unwrap().object;
    let mut moved = object.clone();
    moved.pose.position[1] += 0.03;
    assert_eq!(set_object(&bus.client, &moved), v + 1);
    let e = refusal(motion(&bus.client, &json!({ "grasp": grasp })));
    assert_eq!(e.code, ErrorCode::InvalidValue, "{}", e.message);
    let d = e.details.clone().unwrap();
    assert_eq!(d["reason"], "world_changed");
    assert_eq!(d["field"], "grasp.world_version");
    assert_eq!(
        (
            d["grasp_world_version"].as_u64(),
            d["world_version"].as_u64()
        ),
        (Some(v), Some(v + 1))
    );
    let both = format!(
        "planned on world version {v}, but the world is at version {}",
        v + 1
    );
    assert!(e.message.contains(&both), "{}", e.message);
    let again = json!({ "grasp": grasp, "revalidate": true, "seed": 1 });
    let e = refusal(motion(&bus.client, &again));
    assert_eq!(e.code, ErrorCode::Infeasible, "{}", e.message);
    assert_eq!(e.details.clone().unwrap()["reason"], "grasp_invalid");
    let both = format!(
        "planned on world version {v} does not hold on version {}",
        v + 1
    );
    assert!(e.message.contains(&both), "{}", e.message);
    assert_eq!(set_object(&bus.client, &object), v + 2);
    let r = motion(&bus.client, &again).expect("the grasp holds with the can back");
    assert_eq!(r.world_version, v + 2);
}

/// A box where the elbow is at the grasp, added after the grasp was planned: the
/// re-validated grasp is `infeasible`, naming the link and the box.
#[test]
fn an_obstacle_at_the_elbow_fails_the_revalidation_naming_it() {
    let bus = bus();
    let (grasp, world) = grasp_of(&bus, "can_breast");
    let model = &world.robot.model;
    let mut q = model.rest_positions();
    for (n, v) in &grasp.joint_positions {
        q[model.joint_id(n).unwrap()] = *v;
    }
    model.apply_mimics(&mut q);
    let mut fk = FkState::new(model);
    model.forward_kinematics(&q, &mut fk);
    let elbow = fk.pose(model.link_id("r_forearm_link").unwrap());
    let at = Translation3::from(elbow.translation.vector).vector;
    set_env(
        &bus.client,
        vec![board("post", [at.x, at.y, at.z], [0.06, 0.06, 0.06])],
    );
    let e = refusal(motion(
        &bus.client,
        &json!({ "grasp": grasp, "revalidate": true }),
    ));
    assert_eq!(e.code, ErrorCode::Infeasible);
    assert_eq!(
        e.details.as_ref().unwrap()["reason"],
        "grasp_invalid",
        "{}",
        e.message
    );
    assert!(e.message.contains("`post`"), "{}", e.message);
}

/// Bad grasps: `invalid_value` naming the field; the plugin keeps serving.
#[test]
fn bad_grasps_name_the_field_and_the_plugin_keeps_serving() {
    let bus = bus();
    let (grasp, _) = grasp_of(&bus, "can_waist");
    let mut g = serde_json::to_value(&grasp).unwrap();
    let field = |r: Result<MotionPlanReply, RequestError>| match r {
        Err(RequestError::Reply(e)) => (
            e.error.code,
            e.error.details.unwrap()["field"]
                .as_str()
                .unwrap()
                .to_owned(),
        ),
        other => panic!("{other:?}"),
    };
    g["grasp_type"]["name"] = "no_such_type".into();
    assert_eq!(
        field(motion(&bus.client, &json!({ "grasp": g }))),
        (ErrorCode::InvalidValue, "grasp.grasp_type.name".into())
    );
    let mut g = serde_json::to_value(&grasp).unwrap();
    g["joint_positions"]["no_such_joint"] = 0.1.into();
    assert_eq!(
        field(motion(&bus.client, &json!({ "grasp": g }))),
        (
            ErrorCode::InvalidValue,
            "grasp.joint_positions.no_such_joint".into()
        )
    );
    let mut g = serde_json::to_value(&grasp).unwrap();
    g["palm_pose"]["position"][2] = (grasp.palm_pose.position[2] + 0.2).into();
    assert_eq!(
        field(motion(&bus.client, &json!({ "grasp": g }))),
        (ErrorCode::InvalidValue, "grasp.palm_pose".into())
    );
    for (key, value, at) in [
        ("joint", json!("no_such_joint"), "grasp.squeeze[0].joint"),
        ("target", json!(99.0), "grasp.squeeze[0].target"),
    ] {
        let mut g = serde_json::to_value(&grasp).unwrap();
        g["squeeze"][0][key] = value;
        assert_eq!(
            field(motion(&bus.client, &json!({ "grasp": g }))),
            (ErrorCode::InvalidValue, at.into())
        );
    }
    let mut g = serde_json::to_value(&grasp).unwrap();
    g.as_object_mut().unwrap().remove("joint_positions");
    assert_eq!(
        field(motion(&bus.client, &json!({ "grasp": g }))).0,
        ErrorCode::InvalidRequest
    );
    assert_eq!(
        field(motion(
            &bus.client,
            &json!({ "grasp": grasp, "lift_height": -1.0 })
        )),
        (ErrorCode::InvalidValue, "lift_height".into())
    );
    // Still serving, same world.
    motion(&bus.client, &json!({ "grasp": grasp })).expect("plans after bad requests");
    // The host lists the role.
    let plugins = bus.client.wait_for_host(TIMEOUT).unwrap();
    assert!(plugins
        .plugins
        .iter()
        .any(|p| p.roles.iter().any(|r| r == ROLE_TRAJECTORY_PLANNER)));
}

/// The object benchmark's five placements — a table, a rotated counter, a
/// stool, an object lying on a table, a shelf with a board above and a back
/// wall — and each once more with a wall 12 cm beyond the object's centre (away
/// from the robot), one can
/// and one box on each: the grasp is planned, its motion planned from rest,
/// and the trajectory re-checked here like the paper scenes' (every link
/// pair, the clearances, the grasp reached, the lift). At least 10 of the 20
/// must give a motion; the others must be refused with a reason.
#[test]
fn placements_with_walls_and_shelves_move_clear_of_everything() {
    let dir = std::env::temp_dir().join(format!("tsukami-motion-places-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let root = std::fs::canonicalize(&dir).unwrap();
    let mut config = test_config(vec![planner_entry(), motion_entry()]);
    config.models.roots = vec![models_dir(), root.clone()];
    let bus = TestBus::start(config);
    let c = &bus.client;
    let robot = json!({"robot": "tsukami_humanoid"});
    let send = |command: &str, v: &serde_json::Value| {
        c.command(
            ROLE_GRASP_PLANNER,
            command,
            v.to_string().as_bytes(),
            TIMEOUT,
        )
    };
    send(planner::SET_ROBOT, &robot).expect("set_robot");
    let all = objects::objects();
    let (mut moved, mut tried) = (0, Vec::new());
    for name in ["can_2", "box_0"] {
        let o = all.iter().find(|o| o.name == name).unwrap();
        let path = root.join(format!("{name}.stl"));
        o.mesh.write_stl(&path).unwrap();
        for p in objects::placements() {
            for wall in [false, true] {
                let object = objects::set_object(o, &p, &path.display().to_string());
                let mut env = objects::set_env(&p);
                if wall {
                    let [x, y] = p.xy;
                    let far = [x + 0.13, y, p.top / 2.0 + 0.3];
                    let w =
                        serde_json::to_value(board("wall", far, [0.02, 0.6, p.top + 0.6])).unwrap();
                    env["obstacles"].as_array_mut().unwrap().push(w);
                }
                let case = format!(
                    "{name} on {}{}",
                    p.name,
                    if wall { " by a wall" } else { "" }
                );
                send(planner::SET_OBJECT, &object).expect("set_object");
                send(planner::SET_ENV, &env).expect("set_env");
                let Ok(bytes) = send(planner::PLAN, &json!({"seed": 1})) else {
                    tried.push(format!("{case}: no grasp"));
                    continue;
                };
                let grasp: PlanReply = serde_json::from_slice(&bytes).unwrap();
                let world = World::from_requests(
                    &models_dir(),
                    &serde_json::from_value(robot.clone()).unwrap(),
                    &serde_json::from_value(object.clone()).unwrap(),
                    &serde_json::from_value(env.clone()).unwrap(),
                )
                .unwrap();
                match motion(c, &json!({ "grasp": grasp, "seed": 1 })) {
                    Ok(reply) => {
                        let t = &reply.trajectory;
                        check_timing_and_limits(&world, t);
                        ends_at_the_grasp(&world, t, &grasp);
                        let checks = check_collisions(&world, t);
                        moved += 1;
                        tried.push(format!(
                            "{case}: moved, {:.2} s, {checks} re-checks",
                            t.points.last().unwrap().time
                        ));
                    }
                    Err(RequestError::Reply(e)) => {
                        assert_eq!(
                            e.error.code,
                            ErrorCode::Infeasible,
                            "{case}: {}",
                            e.error.message
                        );
                        let reason = e.error.details.as_ref().unwrap()["reason"].clone();
                        // The grasp planner checked these phases: never blocked here.
                        for blocked in ["approach_blocked", "close_blocked", "lift_blocked"] {
                            assert_ne!(reason, blocked, "{case}: {}", e.error.message);
                        }
                        tried.push(format!("{case}: refused, {reason}"));
                    }
                    Err(e) => panic!("{case}: {e}"),
                }
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!("{tried:#?}");
    assert!(moved >= 10, "{moved} of 20 moved: {tried:#?}");
}
