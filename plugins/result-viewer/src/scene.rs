//! What the web page draws, as JSON: the bodies once per world, the postures
//! and the panel on every change.
//!
//! What: [`geometry`] — every robot link's collision shapes in the link's own
//! frame, the object in its frame with its pose, the obstacles in the world —
//! and [`state`] — the link poses at the planned posture (else at rest), the
//! contacts with μ, the controller's posture, and the panel (grasp type,
//! margin, timings, motion, vision) — and [`trajectory`]: link poses along
//! the last planned motion, for the time slider.
//!
//! Why: the page fetches the bodies when the world version changes and moves
//! them with a few hundred numbers per update, so live updates stay small.
//!
//! How: the same tessellation as the picture ([`Drawing`]), flattened to
//! `f32` arrays; poses are `[x, y, z, qx, qy, qz, qw]` in the world frame
//! (z up, the robot's `base_link`), from forward kinematics.

use crate::latest::{Latest, Outcome};
use crate::world::ViewerWorld;
use nalgebra::Isometry3;
use serde::Serialize;
use serde_json::{json, Value};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::RobotModel;
use tsukami_msgs::motion::JointTrajectory;
use tsukami_msgs::planner::PlanReply;
use tsukami_planner_kit::snapshot::Snapshot;
use tsukami_planner_kit::Robot;
use tsukami_render::drawing::{Drawing, Rgba};
use tsukami_render::grasp_view::posture;

/// Most frames of a trajectory sent to the page.
pub const MAX_FRAMES: usize = 120;

/// One single-coloured triangle set.
#[derive(Debug, Serialize)]
pub struct Solid {
    /// What it is.
    pub name: String,
    /// Linear RGBA.
    pub color: [f32; 4],
    /// Vertex positions, `x y z` after each other.
    pub positions: Vec<f32>,
    /// Triangles, three indices each.
    pub indices: Vec<u32>,
}

fn solids(d: Drawing) -> Vec<Solid> {
    d.groups
        .into_iter()
        .map(|g| Solid {
            name: g.name,
            color: g.color.0,
            positions: g
                .positions
                .iter()
                .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
                .collect(),
            indices: g.triangles.into_iter().flatten().collect(),
        })
        .collect()
}

/// A pose as `[x, y, z, qx, qy, qz, qw]`.
pub fn pose7(p: &Isometry3<f64>) -> [f32; 7] {
    let (t, q) = (p.translation.vector, p.rotation.coords);
    [t.x, t.y, t.z, q.x, q.y, q.z, q.w].map(|v| v as f32)
}

/// The bodies of `world`: `{world_version, links: [{name, hand, solids}],
/// object: {name, pose, solids} | null, obstacles: [solid]}`.
pub fn geometry(world: &Snapshot<ViewerWorld>) -> Value {
    let links: Vec<Value> = world.robot.as_deref().map_or_else(Vec::new, |(robot, ())| {
        let hand = robot.hand();
        let origin = Isometry3::identity();
        robot
            .model
            .links
            .iter()
            .enumerate()
            .map(|(id, link)| {
                let in_hand = hand.links.contains(&id);
                let color = if in_hand { Rgba::HAND } else { Rgba::ROBOT };
                let mut d = Drawing::default();
                for part in hand.collision.link_parts(id) {
                    d.part(&link.name, color, &origin, part);
                }
                json!({"name": link.name, "hand": in_hand, "solids": solids(d)})
            })
            .collect()
    });
    let object = world.object.as_deref().map(|(o, ())| {
        let mut d = Drawing::default();
        d.mesh(&o.name, Rgba::OBJECT, &Isometry3::identity(), &o.mesh);
        json!({"name": o.name, "pose": pose7(&o.pose), "solids": solids(d)})
    });
    let mut d = Drawing::default();
    for o in world.env.values() {
        for part in o.parts() {
            d.part(&o.name, Rgba::OBSTACLE, o.pose(), part);
        }
    }
    json!({
        "world_version": world.version,
        "links": links,
        "object": object,
        "obstacles": solids(d),
    })
}

/// Link poses at `q`.
fn link_poses(model: &RobotModel, q: &[f64]) -> Vec<[f32; 7]> {
    let mut fk = FkState::new(model);
    model.forward_kinematics(q, &mut fk);
    fk.poses.iter().map(pose7).collect()
}

/// The rest posture with `names` set to `values` (unknown joints skipped,
/// values clamped to the limits, mimics applied).
fn posture_of(model: &RobotModel, names: &[String], values: &[f64]) -> Vec<f64> {
    let mut q = model.rest_positions();
    for (name, &v) in names.iter().zip(values) {
        if let Ok(j) = model.joint_id(name) {
            let lim = model.joints[j].limits;
            if model.joints[j].is_independent() && v.is_finite() {
                q[j] = v.clamp(lim.lower, lim.upper);
            }
        }
    }
    model.apply_mimics(&mut q);
    q
}

fn plan_panel(reply: &PlanReply) -> Value {
    json!({
        "grasp_type": reply.grasp_type.name,
        "face": reply.face,
        "ocp_region": reply.ocp_region,
        "margin": reply.force_closure.margin,
        "exact_resists_weight": reply.force_closure.exact_resists_weight,
        "joints_used": reply.joints_used,
        "samples": reply.samples,
        "timing_ms": reply.timing_ms,
        "world_version": reply.world_version,
    })
}

/// The plan's part of the state: `(posture, contacts, panel)`; no posture
/// without a plan that fits this robot.
fn planned(robot: &Robot, latest: &Latest) -> (Option<Vec<f64>>, Value, Value) {
    match latest.plan.as_deref() {
        Some(Outcome::Done(reply)) => {
            let contacts: Vec<Value> = reply
                .contacts
                .iter()
                .map(|c| json!({"link": c.link, "position": c.position, "normal": c.normal, "mu": reply.mu}))
                .collect();
            match posture(&robot.model, reply) {
                Ok(q) => (Some(q), json!(contacts), plan_panel(reply)),
                Err(e) => (None, json!(contacts), json!({"error": e})),
            }
        }
        Some(Outcome::Failed(e)) => (None, json!([]), json!({"error": e})),
        None => (None, json!([]), Value::Null),
    }
}

/// What changes with every result: `{generation, ocp, world_version, posture:
/// {source, links} | null, contacts, plan, motion, controller, vision,
/// counts}`.
pub fn state(world: &Snapshot<ViewerWorld>, latest: &Latest, generation: u64) -> Value {
    let robot = world.robot.as_deref().map(|(r, ())| r);
    let (mut posture, mut contacts, mut plan) = (Value::Null, json!([]), Value::Null);
    let mut controller = Value::Null;
    if let Some(robot) = robot {
        let (q, c, p) = planned(robot, latest);
        let (q, source) = match q {
            Some(q) => (q, "plan"),
            None => (robot.model.rest_positions(), "rest"),
        };
        posture = json!({"source": source, "links": link_poses(&robot.model, &q)});
        (contacts, plan) = (c, p);
        if let Some(s) = latest.controller.as_deref() {
            let q = posture_of(&robot.model, &s.joint_names, &s.positions);
            controller =
                json!({"status": s.status, "time": s.time, "links": link_poses(&robot.model, &q)});
        }
    } else if let Some(Outcome::Failed(e)) = latest.plan.as_deref() {
        plan = json!({"error": e});
    }
    let motion = match latest.motion.as_deref() {
        Some(Outcome::Done(m)) => json!({
            "duration": m.trajectory.points.last().map_or(0.0, |p| p.time),
            "points": m.trajectory.points.len(),
            "planning_ms": m.planning_ms,
            "samples": m.samples,
            "world_version": m.world_version,
        }),
        Some(Outcome::Failed(e)) => json!({"error": e}),
        None => Value::Null,
    };
    let vision = latest.vision.as_deref().map_or(Value::Null, |v| {
        json!({"object": v.object, "position": v.pose.position, "fit_error": v.fit_error, "confidence": v.confidence})
    });
    json!({
        "generation": generation,
        "ocp": ocp_boxes(latest),
        "world_version": world.version,
        "posture": posture,
        "contacts": contacts,
        "plan": plan,
        "motion": motion,
        "controller": controller,
        "vision": vision,
        "counts": {"plans": latest.plans, "motions": latest.motions, "unreadable": latest.unreadable},
    })
}

/// The object's OCP boxes (`{region, pose, extents, chosen}`, world frame),
/// `chosen` for the region the last plan grasped.
fn ocp_boxes(latest: &Latest) -> Value {
    let chosen = match latest.plan.as_deref() {
        Some(Outcome::Done(r)) => Some(r.ocp_region),
        _ => None,
    };
    let boxes = latest.object.as_deref().map_or(&[][..], |o| &o.regions[..]);
    boxes
        .iter()
        .map(|b| {
            let (p, q) = (b.pose.position, b.pose.quaternion);
            let pose = [p[0], p[1], p[2], q[0], q[1], q[2], q[3]];
            json!({"region": b.region, "pose": pose, "extents": b.extents, "chosen": Some(b.region) == chosen})
        })
        .collect()
}

/// Link poses along `trajectory` (at most [`MAX_FRAMES`], evenly by point):
/// `{times, phases, frames: [[pose per link]]}`.
pub fn trajectory(model: &RobotModel, trajectory: &JointTrajectory) -> Value {
    let points = &trajectory.points;
    let n = points.len().min(MAX_FRAMES);
    let picked: Vec<_> = (0..n)
        .map(|k| {
            &points[if n > 1 {
                k * (points.len() - 1) / (n - 1)
            } else {
                0
            }]
        })
        .collect();
    let frames: Vec<Vec<[f32; 7]>> = picked
        .iter()
        .map(|p| {
            link_poses(
                model,
                &posture_of(model, &trajectory.joint_names, &p.positions),
            )
        })
        .collect();
    json!({
        "times": picked.iter().map(|p| p.time).collect::<Vec<_>>(),
        "phases": picked.iter().map(|p| p.phase.as_str()).collect::<Vec<_>>(),
        "frames": frames,
    })
}
