//! Runs the paper's scenes against a planner over the bus, exactly as an external
//! client would: SetRobot, SetObject, SetEnv, Plan — and judges each reply against
//! what the paper reports and with the independent grasp check, in the world the
//! requests describe (`tsukami-scenes`: force closure recomputed, contacts on the
//! surface, no link sunk into the object or an obstacle, joint limits). Used by
//! `tsukami demo` and the end-to-end tests.

use crate::client::{BusClient, RequestError};
use serde::Serialize;
use std::path::Path;
use std::time::{Duration, Instant};
use tsukami_msgs::keys::{planner, ROLE_GRASP_PLANNER};
use tsukami_msgs::planner::{ObjectSummary, PlanOptions, PlanReply, WholeBody};
use tsukami_msgs::{ErrorCode, Pose};
use tsukami_scenes::{scene_requests, verify, PaperScene, Tolerances, World};

/// The `details.reason` of the planner's error when no palm pose is reachable.
pub const UNREACHABLE_REASON: &str = "unreachable";

/// What happened to one scene.
#[derive(Debug, Clone, Serialize)]
pub struct SceneOutcome {
    /// Scene name.
    pub scene: String,
    /// The paper's outcome, in words.
    pub expected: String,
    /// Whether the outcome matches the paper.
    pub ok: bool,
    /// Why not, when it does not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub problem: Option<String>,
    /// The Plan reply (absent when planning failed).
    pub result: Option<PlanReply>,
    /// Number of OCP regions the object split into.
    pub regions: usize,
    /// The error of the arm-only plan, for scenes where the paper says it fails.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub arm_only: Option<String>,
    /// Round trip of the Plan request, milliseconds.
    pub plan_ms: f64,
    /// The largest multiple of the object's weight the reply's contacts hold,
    /// recomputed by the independent check (`tsukami_scenes::verify`), not read
    /// from the reply.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weight_scale: Option<f64>,
}

fn send<T: Serialize>(
    client: &BusClient,
    command: &str,
    request: &T,
    timeout: Duration,
) -> Result<Vec<u8>, String> {
    send_raw(client, command, request, timeout).map_err(|e| format!("{command}: {e}"))
}

fn send_raw<T: Serialize>(
    client: &BusClient,
    command: &str,
    request: &T,
    timeout: Duration,
) -> Result<Vec<u8>, RequestError> {
    let payload = serde_json::to_vec(request).map_err(|e| RequestError::Bus {
        key: command.to_owned(),
        message: format!("cannot serialize the request: {e}"),
    })?;
    client.command(ROLE_GRASP_PLANNER, command, &payload, timeout)
}

/// `Ok` when a plan with the arm alone failed the way the paper says: `infeasible`
/// because the object is unreachable (not a timeout, not a refused request).
pub fn arm_alone_failed(result: &Result<Vec<u8>, RequestError>) -> Result<(), String> {
    let e = match result {
        Ok(_) => return Err("the arm alone found a grasp; the paper says it cannot".to_owned()),
        Err(e) => e,
    };
    let reason = match e {
        RequestError::Reply(r) => r.error.details.as_ref().and_then(|d| d["reason"].as_str()),
        _ => None,
    };
    if e.code() == Some(ErrorCode::Infeasible) && reason == Some(UNREACHABLE_REASON) {
        Ok(())
    } else {
        Err(format!(
            "the arm-only plan must fail as infeasible/{UNREACHABLE_REASON}, it failed with: {e} (reason {reason:?})"
        ))
    }
}

/// Sets the planner up for `scene` and plans it with `seed`.
pub fn run_scene(
    client: &BusClient,
    models_dir: &Path,
    scene: &PaperScene,
    seed: u64,
    timeout: Duration,
) -> SceneOutcome {
    run_scene_at(client, models_dir, scene, seed, timeout, None)
}

/// [`run_scene`], with the object at `object_pose` (e.g. where the vision saw it)
/// instead of the scene file's pose. The reply is still judged in the scene
/// file's world: the grasp must hold the object where it really is.
pub fn run_scene_at(
    client: &BusClient,
    models_dir: &Path,
    scene: &PaperScene,
    seed: u64,
    timeout: Duration,
    object_pose: Option<Pose>,
) -> SceneOutcome {
    let mut outcome = SceneOutcome {
        scene: scene.name.to_owned(),
        expected: scene.expected.to_owned(),
        ok: false,
        problem: None,
        result: None,
        regions: 0,
        arm_only: None,
        plan_ms: 0.0,
        weight_scale: None,
    };
    let setup = Setup {
        seed,
        timeout,
        object_pose,
    };
    if let Err(problem) = plan_scene(client, models_dir, scene, &setup, &mut outcome) {
        outcome.problem = Some(problem);
    }
    outcome
}

/// How a scene is planned.
struct Setup {
    seed: u64,
    timeout: Duration,
    /// The object's pose sent to the planner, when not the scene file's.
    object_pose: Option<Pose>,
}

fn plan_scene(
    client: &BusClient,
    models_dir: &Path,
    scene: &PaperScene,
    setup: &Setup,
    outcome: &mut SceneOutcome,
) -> Result<(), String> {
    let Setup {
        seed,
        timeout,
        object_pose,
    } = *setup;
    let file = models_dir
        .join("scenes")
        .join(format!("{}.toml", scene.name));
    let requests = scene_requests(&file).map_err(|e| e.to_string())?;
    let world = World::from_requests(models_dir, &requests.robot, &requests.object, &requests.env)
        .map_err(|e| format!("the checker's world: {e}"))?;
    send(client, planner::SET_ROBOT, &requests.robot, timeout)?;
    let mut set_object = requests.object.clone();
    if let Some(pose) = object_pose {
        set_object.pose = pose;
    }
    let object: ObjectSummary =
        serde_json::from_slice(&send(client, planner::SET_OBJECT, &set_object, timeout)?)
            .map_err(|e| format!("set_object reply: {e}"))?;
    outcome.regions = object.regions.len();
    send(client, planner::SET_ENV, &requests.env, timeout)?;

    if scene.arm_alone_fails {
        let arm_only = PlanOptions {
            seed,
            whole_body: WholeBody::ArmOnly,
            ..PlanOptions::default()
        };
        let result = send_raw(client, planner::PLAN, &arm_only, timeout);
        arm_alone_failed(&result)?;
        outcome.arm_only = result.err().map(|e| format!("plan: {e}"));
    }

    let options = PlanOptions {
        seed,
        ..PlanOptions::default()
    };
    let start = Instant::now();
    let reply = send(client, planner::PLAN, &options, timeout);
    outcome.plan_ms = start.elapsed().as_secs_f64() * 1e3;
    let reply: PlanReply =
        serde_json::from_slice(&reply?).map_err(|e| format!("plan reply: {e}"))?;
    let verdict = verify(&world, &reply, &Tolerances::default());
    outcome.weight_scale = verdict.weight_scale;
    let verdict = scene.judge(&reply, outcome.regions, &verdict);
    outcome.result = Some(reply);
    verdict?;
    outcome.ok = true;
    Ok(())
}
