//! The planner state machine: robot, object and environment in, grasps out.
//!
//! What: [`Planner`] holds what `set_robot`, `set_object` and `set_env` gave it
//! and answers [`Planner::plan`] with a [`PlanReply`] or a [`PlanError`] that
//! says why no grasp was found. It takes and returns the `tsukami-msgs` types,
//! so the plugin adapter only (de)serialises.
//!
//! Why: one owned value with `&mut self` methods — no hidden shared state —
//! is easy to test in-process and to put behind the plugin boundary; a failed
//! request never changes the state already set.
//!
//! How: `plan` runs grasp-type selection (eqs. (1)–(5)), then for each
//! whole-body stage (arm; arm + waist; arm + waist + squat) solves the IK of
//! every nominal palm pose, ranks them by the palm criterion plus the weighted
//! eq. (3) score, and runs Algorithm 1 on the best few until one gives a
//! force-closure grasp that the exact test confirms. Cancellation is an
//! `&AtomicBool` checked between samples and IK solves; progress goes to a
//! callback.
//!
//! ```no_run
//! use std::sync::atomic::AtomicBool;
//! use tsukami_grasp_planner::planner::Planner;
//! use tsukami_msgs::planner::*;
//! let mut p = Planner::new("models");
//! p.set_robot(&SetRobot { robot: "tsukami_humanoid".into(), grasp_types: None })?;
//! p.set_object(&SetObject {
//!     name: None,
//!     shape: ObjectShape::Model { name: "can_350ml".into() },
//!     mass: 0.15, friction: None, center_of_mass: None,
//!     pose: pose_at([0.45, -0.25, 1.0]),
//! })?;
//! let reply = p.plan(&PlanOptions::default(), &AtomicBool::new(false), &mut |_| {})?;
//! println!("{} on face {}", reply.grasp_type.name, reply.face.as_str());
//! # Ok::<(), tsukami_grasp_planner::planner::PlanError>(())
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use tsukami_scenes::geometry::{build_obstacle, pose_to_isometry};

use nalgebra::{Isometry3, Point3, Vector3};
use tsukami_body::collision::CollisionObject;
use tsukami_body::ik::{IkOptions, IkSolver};
use tsukami_body::kinematics::JointSelection;
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::object::ObjectModel;
use tsukami_msgs::planner::{
    ContactReply, EnvSummary, ForceClosureReply, ObjectMass, ObjectShape, ObjectSummary,
    PhaseTiming, PlanOptions, PlanPhase, PlanReply, Pose, ProgressEvent, RemoveEnv, RobotSummary,
    SetEnv, SetObject, SetRobot,
};

use crate::hand::HandModel;
use crate::object::{PlanObject, MAX_TRIANGLES};
use crate::ocp::OcpParams;
use crate::palm_pose::{criterion_value, palm_targets};
use crate::search::{
    hand_force_limit, search, to_array, Counters, Outcome, SearchContext, SearchParams,
};
use crate::selection::select;
use crate::whole_body::stages;

/// Largest mesh file accepted before parsing (bytes).
pub const MAX_MESH_FILE_BYTES: u64 = 64 << 20;

/// Why a request failed. [`PlanError::code`] gives a stable machine-readable code.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// `plan` before `set_robot`.
    #[error("no robot set: send set_robot first")]
    NoRobot,
    /// `plan` before `set_object`.
    #[error("no object set: send set_object first")]
    NoObject,
    /// The robot or its grasp types could not be loaded.
    #[error("set_robot: {0}")]
    Robot(String),
    /// The object's model or mesh could not be loaded or is unusable (open, degenerate, huge).
    #[error("set_object: {0}")]
    Object(String),
    /// A value of the object request is out of range (mass, pose, scale).
    #[error("set_object: {0}")]
    ObjectValue(String),
    /// A model name that is not under `models/`.
    #[error("unknown {kind} `{name}`: not found at {path}")]
    UnknownModel {
        /// `robot` or `object`.
        kind: &'static str,
        /// The name given.
        name: String,
        /// Where it was looked for.
        path: String,
    },
    /// An obstacle was refused.
    #[error("set_env: obstacle `{name}`: {message}")]
    Env {
        /// Obstacle name.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// Bad plan options.
    #[error("plan: option `{field}`: {message}")]
    Options {
        /// Field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// Eqs. (1)–(5) keep no grasp type.
    #[error("no grasp type fits the object's size and mass: {0}")]
    NoGraspType(String),
    /// No nominal palm pose has an IK solution, even with the whole body.
    #[error("object unreachable with {0}: no nominal palm pose has an IK solution")]
    Unreachable(String),
    /// Reachable, but Algorithm 1 found no collision-free force-closure grasp.
    #[error("no force-closure grasp within the budget ({samples} samples, best margin {best_margin}; rejections: {rejections})")]
    NoForceClosure {
        /// Samples drawn.
        samples: u32,
        /// Best ellipsoid margin seen (`none` if no closing succeeded).
        best_margin: String,
        /// Rejection counts per reason.
        rejections: String,
    },
    /// The time budget ran out.
    #[error("time budget of {0} ms exhausted before a grasp was found")]
    OutOfTime(u64),
    /// Stopped by a `stop` request.
    #[error("plan cancelled by stop")]
    Cancelled,
}

impl PlanError {
    /// A stable machine-readable code.
    pub fn code(&self) -> &'static str {
        match self {
            PlanError::NoRobot => "no_robot",
            PlanError::NoObject => "no_object",
            PlanError::Robot(_) => "bad_robot",
            PlanError::Object(_) => "bad_object",
            PlanError::ObjectValue(_) => "bad_object_value",
            PlanError::UnknownModel { .. } => "unknown_model",
            PlanError::Env { .. } => "bad_env",
            PlanError::Options { .. } => "bad_options",
            PlanError::NoGraspType(_) => "no_grasp_type",
            PlanError::Unreachable(_) => "unreachable",
            PlanError::NoForceClosure { .. } => "no_force_closure",
            PlanError::OutOfTime(_) => "out_of_time",
            PlanError::Cancelled => "cancelled",
        }
    }
}

/// Tunable parameters of the planner (defaults follow the paper).
#[derive(Debug, Clone)]
pub struct PlannerParams {
    /// OCP computation.
    pub ocp: OcpParams,
    /// Algorithm 1 ranges.
    pub search: SearchParams,
    /// Weight (rad per m) of the eq. (3) score against the palm criterion when
    /// ranking nominal poses of different grasp types.
    pub score_weight: f64,
    /// Random restarts of the nominal-pose IK.
    pub nominal_ik_attempts: usize,
}

impl Default for PlannerParams {
    fn default() -> Self {
        Self {
            ocp: OcpParams::default(),
            search: SearchParams::default(),
            score_weight: 4.0,
            nominal_ik_attempts: 4,
        }
    }
}

/// The grasp planner's state.
#[derive(Debug)]
pub struct Planner {
    models_dir: PathBuf,
    params: PlannerParams,
    hand: Option<HandModel>,
    object: Option<PlanObject>,
    env: BTreeMap<String, CollisionObject>,
}

/// A nominal palm pose with its IK solution.
struct Nominal {
    candidate: crate::selection::Candidate,
    palm: Isometry3<f64>,
    q: Vec<f64>,
    cost: f64,
}

fn pose_to_iso(p: &Pose, field: &str) -> Result<Isometry3<f64>, String> {
    pose_to_isometry(p).map_err(|m| format!("{field}.{m}"))
}

fn iso_to_pose(i: &Isometry3<f64>) -> Pose {
    let q = i.rotation;
    Pose {
        position: [i.translation.x, i.translation.y, i.translation.z],
        quaternion: [q.i, q.j, q.k, q.w],
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The triangle count of a binary STL file, read from its header (`None` if
/// the file is not a binary STL).
fn binary_stl_triangles(path: &Path) -> Option<u64> {
    use std::io::Read;
    let is_stl = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("stl"));
    if !is_stl {
        return None;
    }
    let mut head = [0u8; 84];
    let mut f = std::fs::File::open(path).ok()?;
    f.read_exact(&mut head).ok()?;
    let n = u32::from_le_bytes([head[80], head[81], head[82], head[83]]) as u64;
    let len = f.metadata().ok()?.len();
    (len == 84 + 50 * n).then_some(n)
}

/// A model name must be a plain folder name.
fn plain_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.')
        && !name.contains("..")
}

impl Planner {
    /// A planner that resolves model names under `models_dir` (the repository's `models/`).
    pub fn new(models_dir: impl Into<PathBuf>) -> Self {
        Self::with_params(models_dir, PlannerParams::default())
    }

    /// A planner with explicit parameters.
    pub fn with_params(models_dir: impl Into<PathBuf>, params: PlannerParams) -> Self {
        Self {
            models_dir: models_dir.into(),
            params,
            hand: None,
            object: None,
            env: BTreeMap::new(),
        }
    }

    /// The loaded robot, if any.
    pub fn hand(&self) -> Option<&HandModel> {
        self.hand.as_ref()
    }

    /// The current object, if any.
    pub fn object(&self) -> Option<&PlanObject> {
        self.object.as_ref()
    }

    /// `set_robot`: loads the URDF and the grasp types (state kept on error).
    pub fn set_robot(&mut self, req: &SetRobot) -> Result<RobotSummary, PlanError> {
        let urdf = if req.robot.ends_with(".urdf") {
            PathBuf::from(&req.robot)
        } else if plain_name(&req.robot) {
            let p = self
                .models_dir
                .join("robots")
                .join(&req.robot)
                .join(format!("{}.urdf", req.robot));
            if !p.is_file() {
                return Err(PlanError::UnknownModel {
                    kind: "robot",
                    name: req.robot.clone(),
                    path: p.display().to_string(),
                });
            }
            p
        } else {
            return Err(PlanError::Robot(format!(
                "`{}` is neither a .urdf path nor a robot name",
                req.robot
            )));
        };
        let hand = HandModel::load(&urdf, req.grasp_types.as_deref().map(Path::new))
            .map_err(|e| PlanError::Robot(e.to_string()))?;
        let stage_joints = stages(&hand, tsukami_msgs::planner::WholeBody::Squat)
            .last()
            .map(|s| hand.names(&s.extra))
            .unwrap_or_default();
        let summary = RobotSummary {
            name: hand.robot.name.clone(),
            arm_joints: hand.names(&hand.arm),
            body_joints: stage_joints,
            hand_joints: hand.names(&hand.hand_joints),
            grasp_types: hand
                .config
                .grasp_types
                .iter()
                .map(|g| g.name.clone())
                .collect(),
        };
        self.hand = Some(hand);
        Ok(summary)
    }

    /// `set_object`: loads and checks the mesh, computes OCPs (state kept on error).
    pub fn set_object(&mut self, req: &SetObject) -> Result<ObjectSummary, PlanError> {
        let pose = pose_to_iso(&req.pose, "pose").map_err(PlanError::ObjectValue)?;
        if !(req.mass.is_finite() && req.mass > 0.0) {
            return Err(PlanError::ObjectValue(format!(
                "field `mass`: {} kg must be finite and > 0",
                req.mass
            )));
        }
        let (name, mesh, default_mu) = match &req.shape {
            ObjectShape::Model { name } => {
                let path = self
                    .models_dir
                    .join("objects")
                    .join(name)
                    .join("object.toml");
                if !plain_name(name) || !path.is_file() {
                    return Err(PlanError::UnknownModel {
                        kind: "object",
                        name: name.clone(),
                        path: path.display().to_string(),
                    });
                }
                let m = ObjectModel::load(&path).map_err(|e| PlanError::Object(e.to_string()))?;
                (m.name.clone(), m.mesh, m.friction)
            }
            ObjectShape::Mesh { path, scale } => {
                let scale = scale.unwrap_or(1.0);
                if !(scale.is_finite() && scale > 0.0) {
                    return Err(PlanError::ObjectValue(format!(
                        "shape.mesh.scale: {scale} must be > 0"
                    )));
                }
                let p = Path::new(path);
                let meta = std::fs::metadata(p)
                    .map_err(|e| PlanError::Object(format!("shape.mesh.path `{path}`: {e}")))?;
                if meta.len() > MAX_MESH_FILE_BYTES {
                    return Err(PlanError::Object(format!(
                        "shape.mesh.path `{path}`: file is {} MB, more than {} MB; the mesh is huge (at most {MAX_TRIANGLES} triangles are accepted)",
                        meta.len() >> 20,
                        MAX_MESH_FILE_BYTES >> 20
                    )));
                }
                if let Some(n) = binary_stl_triangles(p) {
                    if n > MAX_TRIANGLES as u64 {
                        return Err(PlanError::Object(format!(
                            "shape.mesh.path `{path}`: mesh is huge: {n} triangles, at most {MAX_TRIANGLES} are accepted; decimate it"
                        )));
                    }
                }
                let mesh = TriangleMesh::load(p, Vector3::repeat(scale))
                    .map_err(|e| PlanError::Object(e.to_string()))?;
                let stem = p
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_else(|| "object".into());
                (stem, mesh, 0.5)
            }
        };
        let name = req.name.clone().unwrap_or(name);
        let mu = req.friction.unwrap_or(default_mu);
        let com = req.center_of_mass.map(Point3::from);
        let obj = PlanObject::new(&name, &mesh, pose, req.mass, mu, com, &self.params.ocp)
            .map_err(|e| PlanError::Object(e.to_string()))?;
        let summary = ObjectSummary {
            name: obj.name.clone(),
            mass: obj.mass,
            center_of_mass: to_array(&obj.center_of_mass),
            triangles: obj.triangles.len(),
            regions: obj.ocps.iter().map(|o| o.to_msg()).collect(),
        };
        self.object = Some(obj);
        Ok(summary)
    }

    /// `set_env`: adds or replaces obstacles; all or nothing.
    pub fn set_env(&mut self, req: &SetEnv) -> Result<EnvSummary, PlanError> {
        let mut built = Vec::new();
        for o in &req.obstacles {
            let object = build_obstacle(o).map_err(|e| PlanError::Env {
                name: o.name.clone(),
                message: e.to_string(),
            })?;
            built.push((o.name.clone(), object));
        }
        if req.replace {
            self.env.clear();
        }
        self.env.extend(built);
        Ok(self.env_summary())
    }

    /// `remove_env`: removes obstacles by name (all or nothing) or all of them.
    pub fn remove_env(&mut self, req: &RemoveEnv) -> Result<EnvSummary, PlanError> {
        if req.all {
            self.env.clear();
        } else {
            if let Some(n) = req.names.iter().find(|n| !self.env.contains_key(*n)) {
                return Err(PlanError::Env {
                    name: n.clone(),
                    message: "no such obstacle".into(),
                });
            }
            for n in &req.names {
                self.env.remove(n);
            }
        }
        Ok(self.env_summary())
    }

    fn env_summary(&self) -> EnvSummary {
        EnvSummary {
            obstacles: self.env.keys().cloned().collect(),
        }
    }

    /// `plan`: finds a grasp (see the module docs).
    pub fn plan(
        &mut self,
        opts: &PlanOptions,
        cancel: &AtomicBool,
        progress: &mut dyn FnMut(&ProgressEvent),
    ) -> Result<PlanReply, PlanError> {
        let start = Instant::now();
        let hand = self.hand.as_ref().ok_or(PlanError::NoRobot)?;
        let object = self.object.as_ref().ok_or(PlanError::NoObject)?;
        let opt_err = |f: &str, m: &str| PlanError::Options {
            field: f.into(),
            message: m.into(),
        };
        if opts.max_samples == 0 {
            return Err(opt_err("max_samples", "must be > 0"));
        }
        if opts.time_budget_ms == 0 {
            return Err(opt_err("time_budget_ms", "must be > 0"));
        }
        let delta_f = opts.delta_f.unwrap_or(self.params.search.delta_f);
        if !delta_f.is_finite() {
            return Err(opt_err("delta_f", "must be finite"));
        }
        // Restrict grasp types by name.
        let all = &hand.config.grasp_types;
        let enabled: Vec<usize> = match &opts.grasp_types {
            None => (0..all.len()).collect(),
            Some(names) => {
                if let Some(n) = names.iter().find(|n| !all.iter().any(|g| &g.name == *n)) {
                    return Err(opt_err("grasp_types", &format!("unknown grasp type `{n}`")));
                }
                (0..all.len())
                    .filter(|&i| names.contains(&all[i].name))
                    .collect()
            }
        };
        let deadline = start + Duration::from_millis(opts.time_budget_ms);
        let mut timing = PhaseTiming::default();
        let event = |phase, gt: Option<String>, ju: Vec<String>, c: &Counters| ProgressEvent {
            phase,
            grasp_type: gt,
            joints_used: ju,
            samples: c.samples,
            best_margin: c.best_margin,
            elapsed_ms: ms(start.elapsed()),
        };
        let mut counters = Counters::default();
        progress(&event(PlanPhase::Selection, None, vec![], &counters));

        // Eqs. (1)–(5), score (3).
        let t0 = Instant::now();
        let types: Vec<_> = enabled.iter().map(|&i| all[i].clone()).collect();
        let mut selection = select(&types, &object.ocps, object.mass);
        for c in &mut selection.candidates {
            c.grasp_type = enabled[c.grasp_type];
        }
        timing.selection = ms(t0.elapsed());
        if selection.candidates.is_empty() {
            return Err(PlanError::NoGraspType(selection.explain(&types)));
        }

        let params = SearchParams {
            max_samples: opts.max_samples,
            delta_f,
            contact_distance: hand.config.hand.contact_distance,
            ..self.params.search.clone()
        };
        let env: Vec<&CollisionObject> = self.env.values().collect();
        let ctx = SearchContext {
            hand,
            object,
            env: &env,
            cancel,
            deadline,
            params: &params,
        };
        let mut any_reachable = false;
        let mut tried: Vec<String> = Vec::new();
        let mut last_stage = String::from("the arm");
        let mut q_init = hand.robot.rest_positions();
        // A natural start: elbow bent (seeds the IK away from the straight-arm singularity).
        if let Some(&elbow) = hand.arm.get(3) {
            let l = &hand.robot.joints[elbow].limits;
            q_init[elbow] = (-1.0f64).clamp(l.lower, l.upper);
        }
        for (si, stage) in stages(hand, opts.whole_body).into_iter().enumerate() {
            let extra_names = hand.names(&stage.extra);
            last_stage = if extra_names.is_empty() {
                "the arm".into()
            } else {
                format!("the arm and {}", extra_names.join(", "))
            };
            progress(&event(
                PlanPhase::NominalPose,
                None,
                extra_names.clone(),
                &counters,
            ));
            let t1 = Instant::now();
            let Ok(sel) = JointSelection::new(&hand.robot, &stage.joints) else {
                continue;
            };
            let ik_opts = IkOptions {
                max_attempts: self.params.nominal_ik_attempts,
                position_tolerance: 1e-4,
                orientation_tolerance: 1e-3,
                seed: opts.seed ^ (si as u64) << 32,
                ..IkOptions::default()
            };
            let Ok(mut ik) = IkSolver::new(&hand.robot, hand.palm, sel, ik_opts) else {
                continue;
            };
            let mut nominals: Vec<Nominal> = Vec::new();
            for cand in &selection.candidates {
                let g = &all[cand.grasp_type];
                let ocp = &object.ocps[cand.region];
                for target in palm_targets(g, ocp, cand.face) {
                    if cancel.load(Ordering::Relaxed) {
                        return Err(PlanError::Cancelled);
                    }
                    if Instant::now() >= deadline {
                        return Err(PlanError::OutOfTime(opts.time_budget_ms));
                    }
                    let mut q0 = q_init.clone();
                    hand.set_posture(cand.grasp_type, &mut q0);
                    let sol = ik.solve(&target.palm, true, &q0, Some(&q_init));
                    if !sol.ok {
                        continue;
                    }
                    let cost = criterion_value(hand, &sol.q, opts.palm_criterion, &stage.joints)
                        + self.params.score_weight * cand.score;
                    nominals.push(Nominal {
                        candidate: cand.clone(),
                        palm: target.palm,
                        q: sol.q,
                        cost,
                    });
                }
            }
            timing.nominal_pose += ms(t1.elapsed());
            if nominals.is_empty() {
                continue;
            }
            any_reachable = true;
            nominals.sort_by(|a, b| a.cost.total_cmp(&b.cost));
            let t2 = Instant::now();
            for (k, nom) in nominals
                .iter()
                .take(opts.max_candidates.max(1) as usize)
                .enumerate()
            {
                let g = &all[nom.candidate.grasp_type];
                tried.push(g.name.clone());
                progress(&event(
                    PlanPhase::Search,
                    Some(g.name.clone()),
                    extra_names.clone(),
                    &counters,
                ));
                let seed = opts
                    .seed
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    .wrapping_add(((si as u64) << 16) | k as u64);
                let outcome = search(
                    &ctx,
                    nom.candidate.grasp_type,
                    &stage,
                    &nom.palm,
                    &nom.q,
                    seed,
                    &mut counters,
                    &mut |c| {
                        progress(&event(
                            PlanPhase::Search,
                            Some(g.name.clone()),
                            extra_names.clone(),
                            c,
                        ))
                    },
                );
                match outcome {
                    Outcome::Found(found) => {
                        // The exact verification runs inside the search; report it apart.
                        timing.search += ms(t2.elapsed()) - found.exact_ms;
                        timing.verification = found.exact_ms;
                        let t3 = Instant::now();
                        progress(&event(
                            PlanPhase::Verification,
                            Some(g.name.clone()),
                            extra_names.clone(),
                            &counters,
                        ));
                        let mut joint_positions = BTreeMap::new();
                        for &j in stage.joints.iter() {
                            joint_positions.insert(hand.robot.joints[j].name.clone(), found.q[j]);
                        }
                        for (j, joint) in hand.robot.joints.iter().enumerate() {
                            if joint.is_movable() && hand.hand_links.contains(&joint.child) {
                                joint_positions.insert(joint.name.clone(), found.q[j]);
                            }
                        }
                        let contacts = found
                            .contacts
                            .iter()
                            .map(|c| ContactReply {
                                link: hand.robot.links[c.link].name.clone(),
                                position: to_array(&c.position),
                                normal: [c.normal.x, c.normal.y, c.normal.z],
                                f_max: c.f_max,
                            })
                            .collect();
                        timing.verification += ms(t3.elapsed());
                        timing.total = ms(start.elapsed());
                        progress(&event(
                            PlanPhase::Done,
                            Some(g.name.clone()),
                            extra_names.clone(),
                            &counters,
                        ));
                        return Ok(PlanReply {
                            grasp_type: g.to_ref(),
                            ocp_region: nom.candidate.region,
                            face: nom.candidate.face,
                            palm_pose: iso_to_pose(&found.palm),
                            joint_positions,
                            joints_used: extra_names,
                            contacts,
                            mu: object.mu,
                            object: ObjectMass {
                                mass: object.mass,
                                center_of_mass: to_array(&object.center_of_mass),
                            },
                            characteristic_length: object.characteristic_length,
                            force_closure: ForceClosureReply {
                                margin: found.margin,
                                exact_resists_weight: found.exact_resists_weight,
                                force_limit: hand_force_limit(&found.contacts),
                            },
                            samples: counters.samples,
                            timing_ms: timing,
                            candidates_tried: tried,
                        });
                    }
                    Outcome::Cancelled => return Err(PlanError::Cancelled),
                    Outcome::OutOfTime => return Err(PlanError::OutOfTime(opts.time_budget_ms)),
                    Outcome::Exhausted => {}
                }
            }
            timing.search += ms(t2.elapsed());
        }
        progress(&event(PlanPhase::Done, None, vec![], &counters));
        if !any_reachable {
            return Err(PlanError::Unreachable(last_stage));
        }
        let r = counters.rejections;
        Err(PlanError::NoForceClosure {
            samples: counters.samples,
            best_margin: counters
                .best_margin
                .map_or("none".into(), |m| format!("{m:.3}")),
            rejections: format!(
                "ik {}, collision before closing {}, finger closing {}, collision after closing {}, force closure {}",
                r[0], r[1], r[2], r[3], r[4]
            ),
        })
    }
}
