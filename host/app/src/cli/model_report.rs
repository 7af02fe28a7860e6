//! The functions behind `tsukami model inspect | fk | ik`: they take parsed
//! arguments and return serde structs whose JSON is the CLI's contract
//! (issue #3). Field names here must not change; fields may be added.
//!
//! * [`inspect`] → `{"links": [{"name", "mass"}], "joints": [{"name", "type",
//!   "parent", "child", "lower", "upper", "effort", "velocity", "mimic"}]}`
//! * [`fk`] / [`fk_batch`] → `{"links": {NAME: {"position": [x,y,z],
//!   "quaternion": [x,y,z,w]}}}` in the model's root frame
//! * [`ik`] / [`ik_batch`] → `{"ok", "joint_positions", "position_error",
//!   "orientation_error", "iterations"}`
//!
//! They live in the CLI, not in `tsukami-body`: the body crate keeps the
//! kinematics (pure functions on a loaded model), and the JSON contract of the
//! command is the command's. No I/O here; `model.rs` reads files and prints.

use std::collections::BTreeMap;

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use serde::{Deserialize, Serialize};

use tsukami_body::error::{BodyError, Result};
use tsukami_body::ik::{IkOptions, IkSolver};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::model::{JointKind, RobotModel};

/// A link in [`InspectReport`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinkInfo {
    /// Link name.
    pub name: String,
    /// Mass (kg).
    pub mass: f64,
}

/// A mimic coupling in [`JointInfo`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MimicInfo {
    /// Master joint.
    pub joint: String,
    /// Multiplier.
    pub multiplier: f64,
    /// Offset.
    pub offset: f64,
}

/// A joint in [`InspectReport`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointInfo {
    /// Joint name.
    pub name: String,
    /// `revolute`, `continuous`, `prismatic` or `fixed`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Parent link.
    pub parent: String,
    /// Child link.
    pub child: String,
    /// Lower limit (`null` for continuous and fixed joints).
    pub lower: Option<f64>,
    /// Upper limit (`null` for continuous and fixed joints).
    pub upper: Option<f64>,
    /// Effort limit (N·m or N).
    pub effort: f64,
    /// Velocity limit (rad/s or m/s).
    pub velocity: f64,
    /// Mimic coupling or `null`.
    pub mimic: Option<MimicInfo>,
}

/// Output of `tsukami model inspect`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InspectReport {
    /// Robot name.
    pub robot: String,
    /// Root link.
    pub root: String,
    /// Total mass (kg).
    pub total_mass: f64,
    /// Links, root first.
    pub links: Vec<LinkInfo>,
    /// Joints, in the order of their child links.
    pub joints: Vec<JointInfo>,
}

/// Describes a loaded model.
pub fn inspect(model: &RobotModel) -> InspectReport {
    let limit = |kind: JointKind, v: f64| match kind {
        JointKind::Revolute | JointKind::Prismatic => Some(v),
        _ => None,
    };
    InspectReport {
        robot: model.name.clone(),
        root: model.links[0].name.clone(),
        total_mass: model.total_mass(),
        links: model
            .links
            .iter()
            .map(|l| LinkInfo {
                name: l.name.clone(),
                mass: l.inertial.mass,
            })
            .collect(),
        joints: model
            .joints
            .iter()
            .map(|j| JointInfo {
                name: j.name.clone(),
                kind: j.kind.as_str().to_string(),
                parent: model.links[j.parent].name.clone(),
                child: model.links[j.child].name.clone(),
                lower: limit(j.kind, j.limits.lower),
                upper: limit(j.kind, j.limits.upper),
                effort: j.limits.effort,
                velocity: j.limits.velocity,
                mimic: j.mimic.as_ref().map(|m| MimicInfo {
                    joint: m.joint_name.clone(),
                    multiplier: m.multiplier,
                    offset: m.offset,
                }),
            })
            .collect(),
    }
}

/// A link pose in [`FkReport`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LinkPose {
    /// Position `[x, y, z]` (m).
    pub position: [f64; 3],
    /// Orientation as a unit quaternion `[x, y, z, w]`.
    pub quaternion: [f64; 4],
}

impl LinkPose {
    /// From an isometry.
    pub fn from_isometry(iso: &Isometry3<f64>) -> Self {
        let t = &iso.translation.vector;
        let q = iso.rotation.quaternion();
        Self {
            position: [t.x, t.y, t.z],
            quaternion: [q.i, q.j, q.k, q.w],
        }
    }
}

/// Output of `tsukami model fk`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FkReport {
    /// Every link's pose in the model's root frame.
    pub links: BTreeMap<String, LinkPose>,
}

/// Forward kinematics for named joint values (others 0; mimic joints
/// follow their masters; setting a mimic, fixed or unknown joint is an error).
pub fn fk<'a>(
    model: &RobotModel,
    joints: impl IntoIterator<Item = (&'a str, f64)>,
) -> Result<FkReport> {
    let q = model.positions_from_named(joints)?;
    let mut state = FkState::new(model);
    model.forward_kinematics(&q, &mut state);
    Ok(FkReport {
        links: model
            .links
            .iter()
            .zip(&state.poses)
            .map(|(l, p)| (l.name.clone(), LinkPose::from_isometry(p)))
            .collect(),
    })
}

/// [`fk`] for many configurations; an error names the failing item.
pub fn fk_batch(
    model: &RobotModel,
    configurations: &[BTreeMap<String, f64>],
) -> Result<Vec<FkReport>> {
    configurations
        .iter()
        .enumerate()
        .map(|(i, c)| {
            fk(model, c.iter().map(|(k, v)| (k.as_str(), *v)))
                .map_err(|e| BodyError::Request(format!("batch item {i}: {e}")))
        })
        .collect()
}

/// An IK request (the CLI's arguments, or one item of `--batch`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IkRequest {
    /// The link to place (`--link`).
    #[serde(default)]
    pub link: Option<String>,
    /// `[x, y, z]` or `[x, y, z, qx, qy, qz, qw]` in the root frame.
    pub target: Vec<f64>,
    /// Joints that may move (`--joints`); default: every independent joint
    /// between the root and the link.
    #[serde(default)]
    pub joints: Option<Vec<String>>,
    /// Restart seed (`--seed`, default 0).
    #[serde(default)]
    pub seed: Option<u64>,
}

/// Output of `tsukami model ik`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IkReport {
    /// True when the target was reached within tolerance.
    pub ok: bool,
    /// Values of the solved joints (the best found when `ok` is false).
    pub joint_positions: BTreeMap<String, f64>,
    /// Position error (m).
    pub position_error: f64,
    /// Orientation error (rad; 0 for position-only targets).
    pub orientation_error: f64,
    /// Solver iterations.
    pub iterations: usize,
    /// Attempts (random restarts + 1).
    pub attempts: usize,
    /// The link.
    pub link: String,
    /// Why it failed, when `ok` is false.
    pub message: Option<String>,
}

/// Parses `x,y,z[,qx,qy,qz,qw]`.
pub fn parse_target(text: &str) -> Result<Vec<f64>> {
    let values = text
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| BodyError::Request(format!("target '{text}': '{s}' is not a number")))
        })
        .collect::<Result<Vec<_>>>()?;
    check_target(&values)?;
    Ok(values)
}

/// Parses `NAME=VALUE`.
pub fn parse_joint_assignment(text: &str) -> Result<(String, f64)> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| BodyError::Request(format!("joint '{text}': expected NAME=VALUE")))?;
    let v = value
        .trim()
        .parse::<f64>()
        .map_err(|_| BodyError::Request(format!("joint '{text}': '{value}' is not a number")))?;
    Ok((name.trim().to_string(), v))
}

fn check_target(t: &[f64]) -> Result<()> {
    if t.len() != 3 && t.len() != 7 {
        return Err(BodyError::Request(format!(
            "target has {} values; expected x,y,z or x,y,z,qx,qy,qz,qw",
            t.len()
        )));
    }
    if !t.iter().all(|v| v.is_finite()) {
        return Err(BodyError::Request(format!(
            "target {t:?} has a non-finite value"
        )));
    }
    Ok(())
}

fn target_pose(t: &[f64]) -> Result<(Isometry3<f64>, bool)> {
    check_target(t)?;
    let tr = Translation3::new(t[0], t[1], t[2]);
    if t.len() == 3 {
        return Ok((Isometry3::from_parts(tr, UnitQuaternion::identity()), false));
    }
    let q = Quaternion::new(t[6], t[3], t[4], t[5]);
    if q.norm() < 1e-9 {
        return Err(BodyError::Request("target quaternion is zero".into()));
    }
    Ok((
        Isometry3::from_parts(tr, UnitQuaternion::from_quaternion(q)),
        true,
    ))
}

/// Solves one IK request from the model's rest pose.
pub fn ik(model: &RobotModel, request: &IkRequest) -> Result<IkReport> {
    ik_batch(model, std::slice::from_ref(request)).map(|mut v| v.remove(0))
}

/// Solves many requests; solvers are reused between items with the same
/// link and joints. An invalid item (unknown link or joint, bad target) is
/// an error naming the item; an unreachable target is `ok: false`.
pub fn ik_batch(model: &RobotModel, requests: &[IkRequest]) -> Result<Vec<IkReport>> {
    let rest = model.rest_positions();
    let mut solvers: Vec<((usize, Vec<usize>), IkSolver<'_>)> = Vec::new();
    let mut out = Vec::with_capacity(requests.len());
    for (i, req) in requests.iter().enumerate() {
        let item = |e: BodyError| {
            if requests.len() == 1 {
                e
            } else {
                BodyError::Request(format!("batch item {i}: {e}"))
            }
        };
        let link_name = req
            .link
            .as_deref()
            .ok_or_else(|| item(BodyError::Request("no link given".into())))?;
        let link = model.link_id(link_name).map_err(item)?;
        let joints = match &req.joints {
            Some(names) => names
                .iter()
                .map(|n| model.joint_id(n))
                .collect::<Result<Vec<_>>>()
                .map_err(item)?,
            None => model.independent_chain(link),
        };
        let (target, orientation) = target_pose(&req.target).map_err(item)?;
        let key = (link, joints.clone());
        let idx = match solvers.iter().position(|(k, _)| *k == key) {
            Some(p) => p,
            None => {
                let sel = JointSelection::new(model, &joints).map_err(item)?;
                let solver = IkSolver::new(model, link, sel, IkOptions::default()).map_err(item)?;
                solvers.push((key, solver));
                solvers.len() - 1
            }
        };
        let solver = &mut solvers[idx].1;
        solver.options_mut().seed = req.seed.unwrap_or(0);
        let sol = solver.solve(&target, orientation, &rest, None);
        out.push(IkReport {
            ok: sol.ok,
            joint_positions: joints
                .iter()
                .map(|&j| (model.joints[j].name.clone(), sol.q[j]))
                .collect(),
            position_error: sol.position_error,
            orientation_error: sol.orientation_error,
            iterations: sol.iterations,
            attempts: sol.attempts,
            link: link_name.to_string(),
            message: (!sol.ok).then(|| match sol.attempts {
                0 => format!(
                    "the target is {:.3} m beyond the reach of the selected joints (no attempt made)",
                    sol.beyond_reach
                ),
                n => format!(
                    "no solution within tolerance after {n} attempts (best position error {:.3e} m, orientation error {:.3e} rad)",
                    sol.position_error, sol.orientation_error
                ),
            }),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn humanoid() -> RobotModel {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../models/robots/tsukami_humanoid/tsukami_humanoid.urdf");
        tsukami_body::urdf::load_urdf(&p).unwrap()
    }

    #[test]
    fn inspect_json_contract() {
        let m = humanoid();
        let v = serde_json::to_value(inspect(&m)).unwrap();
        let links = v["links"].as_array().unwrap();
        assert_eq!(links[0]["name"], "base_link");
        assert!(links[0]["mass"].as_f64().unwrap() > 0.0);
        let joints = v["joints"].as_array().unwrap();
        let find = |n: &str| joints.iter().find(|j| j["name"] == n).unwrap().clone();
        let squat = find("squat_z");
        assert_eq!(squat["type"], "prismatic");
        assert_eq!(squat["parent"], "base_link");
        assert_eq!(squat["child"], "pelvis");
        assert_eq!(squat["lower"].as_f64(), Some(-0.4));
        assert_eq!(squat["upper"].as_f64(), Some(0.0));
        assert!(
            squat["effort"].as_f64().unwrap() > 0.0 && squat["velocity"].as_f64().unwrap() > 0.0
        );
        assert!(squat["mimic"].is_null());
        let j4 = find("r_index_j4");
        assert_eq!(j4["mimic"]["joint"], "r_index_j3");
        assert_eq!(j4["mimic"]["multiplier"], 1.0);
        assert_eq!(j4["mimic"]["offset"], 0.0);
        let cam = find("camera_joint");
        assert_eq!(cam["type"], "fixed");
        assert!(cam["lower"].is_null() && cam["upper"].is_null());
    }

    #[test]
    fn fk_json_contract_and_errors() {
        let m = humanoid();
        let r = fk(&m, [("squat_z", -0.2), ("r_index_j3", 0.5)]).unwrap();
        let v = serde_json::to_value(&r).unwrap();
        let pelvis = &v["links"]["pelvis"];
        assert!((pelvis["position"][2].as_f64().unwrap() - 0.65).abs() < 1e-12);
        assert_eq!(pelvis["quaternion"].as_array().unwrap().len(), 4);
        assert_eq!(pelvis["quaternion"][3].as_f64(), Some(1.0)); // [x, y, z, w]
                                                                 // The mimic joint followed its master: l4 is rotated further than l3.
        let q3 = r.links["r_index_l3"].quaternion;
        let q4 = r.links["r_index_l4"].quaternion;
        assert_ne!(q3, q4);
        // Errors: a mimic joint, an unknown joint, a fixed joint.
        let e = fk(&m, [("r_index_j4", 0.1)]).unwrap_err().to_string();
        assert!(e.contains("r_index_j4") && e.contains("mimic"), "{e}");
        assert!(fk(&m, [("nope", 0.1)])
            .unwrap_err()
            .to_string()
            .contains("nope"));
        assert!(fk(&m, [("camera_joint", 0.1)]).is_err());
        assert!(fk(&m, [("r_elbow", f64::NAN)]).is_err());
        // Batch: one report per configuration; an error names the item.
        let batch: Vec<BTreeMap<String, f64>> =
            serde_json::from_str(r#"[{"r_elbow": -1.0}, {}]"#).unwrap();
        assert_eq!(fk_batch(&m, &batch).unwrap().len(), 2);
        let bad: Vec<BTreeMap<String, f64>> =
            serde_json::from_str(r#"[{}, {"r_ring_j4": 1.0}]"#).unwrap();
        assert!(fk_batch(&m, &bad)
            .unwrap_err()
            .to_string()
            .contains("batch item 1"));
    }

    #[test]
    fn ik_json_contract_and_errors() {
        let m = humanoid();
        // A target made by FK, so it is reachable.
        let target = fk(
            &m,
            [
                ("r_elbow", -1.2),
                ("r_shoulder_pitch", -0.5),
                ("r_wrist_pitch", 0.3),
            ],
        )
        .unwrap();
        let p = target.links["r_palm"];
        let mut t = p.position.to_vec();
        t.extend(p.quaternion);
        // The arm's joints, as the robot's description lists them.
        let description: toml::Table = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../models/robots/tsukami_humanoid/description.toml"),
        )
        .unwrap()
        .parse()
        .unwrap();
        let arm: Vec<String> = description["hand"][0]["arm"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap().to_string())
            .collect();
        let req = IkRequest {
            link: Some("r_palm".into()),
            target: t.clone(),
            joints: Some(arm.clone()),
            seed: Some(3),
        };
        let r = ik(&m, &req).unwrap();
        assert!(r.ok, "{r:?}");
        let v = serde_json::to_value(&r).unwrap();
        for key in [
            "ok",
            "joint_positions",
            "position_error",
            "orientation_error",
            "iterations",
        ] {
            assert!(v.get(key).is_some(), "{key}");
        }
        assert_eq!(v["joint_positions"].as_object().unwrap().len(), 7);
        // Default joint list: the whole chain (squat, waist, arm).
        let r = ik(
            &m,
            &IkRequest {
                joints: None,
                ..req.clone()
            },
        )
        .unwrap();
        assert!(r.ok && r.joint_positions.contains_key("squat_z"));
        // Position only.
        let r = ik(
            &m,
            &IkRequest {
                target: t[..3].to_vec(),
                ..req.clone()
            },
        )
        .unwrap();
        assert!(r.ok && r.orientation_error == 0.0);
        // Unreachable: ok false with a message, not an error.
        let r = ik(
            &m,
            &IkRequest {
                target: vec![3.0, 0.0, 1.0],
                ..req.clone()
            },
        )
        .unwrap();
        assert!(!r.ok && r.message.is_some());
        // Errors.
        assert!(ik(
            &m,
            &IkRequest {
                link: Some("nope".into()),
                ..req.clone()
            }
        )
        .is_err());
        assert!(ik(
            &m,
            &IkRequest {
                joints: Some(vec!["r_index_j4".into()]),
                ..req.clone()
            }
        )
        .is_err());
        assert!(ik(
            &m,
            &IkRequest {
                target: vec![1.0, 2.0],
                ..req.clone()
            }
        )
        .is_err());
        assert!(ik(
            &m,
            &IkRequest {
                target: vec![0.3, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
                ..req.clone()
            }
        )
        .is_err());
        // Batch from JSON, with per-item overrides; deterministic.
        let items: Vec<IkRequest> = serde_json::from_str(&format!(
            r#"[{{"link": "r_palm", "target": {t:?}}}, {{"link": "r_palm", "target": [0.35, -0.3, 1.05], "joints": {arm:?}, "seed": 9}}]"#
        ))
        .unwrap();
        let a = ik_batch(&m, &items).unwrap();
        let b = ik_batch(&m, &items).unwrap();
        assert_eq!(a, b);
        assert!(a.iter().all(|r| r.ok));
        let bad: Result<Vec<IkRequest>, _> =
            serde_json::from_str(r#"[{"target": [0,0,1], "colour": 1}]"#);
        assert!(bad.is_err());
    }

    #[test]
    fn parsers() {
        assert_eq!(parse_target("0.1, 0.2,0.3").unwrap(), vec![0.1, 0.2, 0.3]);
        assert!(parse_target("0.1,0.2").is_err());
        assert!(parse_target("0.1,x,0.3").is_err());
        assert_eq!(
            parse_joint_assignment("r_elbow=-1.5").unwrap(),
            ("r_elbow".to_string(), -1.5)
        );
        assert!(parse_joint_assignment("r_elbow").is_err());
        assert!(parse_joint_assignment("r_elbow=abc").is_err());
    }
}
