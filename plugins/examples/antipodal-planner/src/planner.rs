//! The planner: state set by the `set_*` requests, and the antipodal search.
//!
//! What: [`AntipodalPlanner`] owns the robot, the object and the obstacles;
//! [`AntipodalPlanner::plan`] searches for a three-finger pinch (thumb
//! against index + middle) and answers a [`PlanReply`] with every contract
//! field filled.
//!
//! Why this shape (the template for a planner): the state is plain owned data
//! changed only through `&mut self`, one method per command, so the FFI
//! adapter is a thin dispatcher and tests drive the planner directly. Each
//! `set_*` builds everything it needs *before* touching `self`, so a bad
//! request leaves the previous state intact. `plan` does no I/O: it reports
//! through a progress callback and polls a cancel flag (`&AtomicBool`).
//!
//! # The search
//! For each whole-body stage (arm; arm + waist; arm + waist + squat, as far
//! as `whole_body` allows), up to `max_samples` times:
//! 1. **pair** — draw an antipodal pair on the object ([`crate::antipodal`]),
//!    friction half-angle `½·atan μ`;
//! 2. **palm pose** — pick the pre-shape whose thumb–finger gap is the pair's
//!    width plus a clearance ([`crate::hand`]); rotate the palm so the
//!    thumb-pad → finger-pad line lies on the pair, about that line so the
//!    palm faces the object from the shoulder's side; place it so the pads'
//!    midpoint is the pair's midpoint;
//! 3. **IK** — solve the stage's joints for that palm pose (`tsukami_body::ik`);
//! 4. **collisions** — arm and hand clear of the obstacles, hand clear of the
//!    object before closing;
//! 5. **closing** — flex the thumb, index and middle fingers until each
//!    touches the object (distance query); check the obstacles and
//!    self-collision again;
//! 6. **force closure** — the contacts with per-finger force limits: the
//!    ellipsoid margin `n − f` of eq. (10) is reported, and the grasp is
//!    accepted when the exact friction-cone test (`tsukami_grasp::exact`)
//!    resists the object's weight.
//!
//! `PlanOptions::palm_criterion`, `delta_f` and `max_candidates` belong to
//! the paper's planner and are accepted but not used here (`delta_f` is
//! still checked to be finite).

use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tsukami_body::collision::CollisionObject;
use tsukami_body::ik::{IkOptions, IkSolver};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::model::JointId;
use tsukami_body::object::ObjectModel;
use tsukami_grasp::contact::Contact;
use tsukami_grasp::ellipsoid::{ellipsoid_test, EllipsoidModel};
use tsukami_grasp::exact::{exact_test, ConeModel};
use tsukami_grasp::grasp::Grasp;
use tsukami_msgs::planner::{
    ContactReply, EnvSummary, ForceClosureReply, GraspSize, GraspStyle, GraspTypeRef, ObjectMass,
    ObjectShape, ObjectSummary, PhaseTiming, PlanOptions, PlanPhase, PlanReply, ProgressEvent,
    RemoveEnv, RobotSummary, SetEnv, SetObject, SetRobot, WholeBody,
};

use crate::antipodal::sample_pair;
use crate::env::build_obstacle;
use crate::error::PlanError;
use crate::hand::{close_finger, Closing, FingerContact};
use crate::object::{isometry_to_pose, pose_to_isometry, PlanObject};
use crate::robot::PlanRobot;

/// Gravity in the world frame (z up).
const GRAVITY: Vector3<f64> = Vector3::new(0.0, 0.0, -9.81);
/// Free space left on each side of the object when the hand opens (m).
const CLEARANCE: f64 = 0.008;
/// Palm rotations about the pinch line considered per pair.
const ROLLS: usize = 12;
/// A progress event every this many samples.
const PROGRESS_EVERY: u32 = 16;

/// Tunable settings of the search.
#[derive(Debug, Clone)]
pub struct PlannerParams {
    /// Finger closing.
    pub closing: Closing,
    /// Fraction of the friction angle `atan μ` a pair's line may deviate
    /// from the surface normals.
    pub cone_fraction: f64,
    /// IK attempts per palm pose (the first from the rest posture).
    pub ik_attempts: usize,
}

impl Default for PlannerParams {
    fn default() -> Self {
        Self {
            closing: Closing::default(),
            cone_fraction: 0.5,
            ik_attempts: 2,
        }
    }
}

/// The planner's state.
#[derive(Debug)]
pub struct AntipodalPlanner {
    models_dir: PathBuf,
    params: PlannerParams,
    robot: Option<PlanRobot>,
    object: Option<PlanObject>,
    env: BTreeMap<String, CollisionObject>,
}

/// A model name: no path separators, not empty, not `.`/`..`.
fn plain_name(s: &str) -> bool {
    !s.is_empty() && s != "." && s != ".." && !s.contains(['/', '\\'])
}

/// Size class from the object's middle box extent (its usual pinch width).
fn size_class(extents: &Vector3<f64>) -> GraspSize {
    let mut e = [extents.x, extents.y, extents.z];
    e.sort_by(f64::total_cmp);
    match e[1] {
        w if w < 0.045 => GraspSize::Small,
        w if w < 0.085 => GraspSize::Mid,
        _ => GraspSize::Large,
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// A palm pose found for one sample, with its hand pre-shape.
struct Candidate {
    palm: Isometry3<f64>,
    hand_q: Vec<(JointId, f64)>,
}

impl AntipodalPlanner {
    /// A planner resolving model names under `models_dir` (`robots/`, `objects/`).
    pub fn new(models_dir: impl Into<PathBuf>) -> Self {
        Self::with_params(models_dir, PlannerParams::default())
    }

    /// A planner with explicit search settings.
    pub fn with_params(models_dir: impl Into<PathBuf>, params: PlannerParams) -> Self {
        Self {
            models_dir: models_dir.into(),
            params,
            robot: None,
            object: None,
            env: BTreeMap::new(),
        }
    }

    /// The loaded robot, if any.
    pub fn robot(&self) -> Option<&PlanRobot> {
        self.robot.as_ref()
    }

    /// The loaded object, if any.
    pub fn object(&self) -> Option<&PlanObject> {
        self.object.as_ref()
    }

    /// `set_robot`: a `.urdf` path or a robot name under `models_dir/robots/`.
    /// `grasp_types` is the paper planner's file and is not read here.
    pub fn set_robot(&mut self, req: &SetRobot) -> Result<RobotSummary, PlanError> {
        let urdf = if req.robot.ends_with(".urdf") {
            PathBuf::from(&req.robot)
        } else if plain_name(&req.robot) {
            self.models_dir
                .join("robots")
                .join(&req.robot)
                .join(format!("{}.urdf", req.robot))
        } else {
            return Err(PlanError::invalid(
                "robot",
                format!("`{}` is neither a .urdf path nor a robot name", req.robot),
            ));
        };
        if !urdf.is_file() {
            return Err(PlanError::UnknownModel {
                kind: "robot",
                name: req.robot.clone(),
                path: urdf.display().to_string(),
            });
        }
        let robot = PlanRobot::load(&urdf)?;
        let mut body = robot.waist.clone();
        body.push(robot.squat);
        let summary = RobotSummary {
            name: robot.model.name.clone(),
            arm_joints: robot.names(&robot.arm),
            body_joints: robot.names(&body),
            hand_joints: robot.names(&robot.hand.joints()),
            grasp_types: [GraspSize::Small, GraspSize::Mid, GraspSize::Large]
                .iter()
                .map(|s| format!("fingertip3_{}", s.as_str()))
                .collect(),
        };
        self.robot = Some(robot);
        Ok(summary)
    }

    /// `set_object`: a model under `models_dir/objects/NAME/object.toml` or a
    /// mesh file.
    pub fn set_object(&mut self, req: &SetObject) -> Result<ObjectSummary, PlanError> {
        let pose = pose_to_isometry(&req.pose, "pose")?;
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
                let m = ObjectModel::load(&path).map_err(|e| PlanError::Model {
                    field: "shape.model.name".into(),
                    message: e.to_string(),
                })?;
                (m.name.clone(), m.mesh, m.friction)
            }
            ObjectShape::Mesh { path, scale } => {
                let scale = scale.unwrap_or(1.0);
                if !(scale.is_finite() && scale > 0.0) {
                    return Err(PlanError::invalid(
                        "shape.mesh.scale",
                        format!("{scale} must be finite and > 0"),
                    ));
                }
                let p = Path::new(path);
                let mesh = TriangleMesh::load(p, Vector3::repeat(scale)).map_err(|e| {
                    PlanError::Model {
                        field: "shape.mesh.path".into(),
                        message: e.to_string(),
                    }
                })?;
                let stem = p
                    .file_stem()
                    .map_or_else(|| "object".into(), |s| s.to_string_lossy().into_owned());
                (stem, mesh, 0.5)
            }
        };
        let name = req.name.clone().unwrap_or(name);
        let object = PlanObject::new(
            &name,
            mesh,
            pose,
            req.mass,
            req.friction.unwrap_or(default_mu),
            req.center_of_mass,
        )?;
        let summary = ObjectSummary {
            name: object.name.clone(),
            mass: object.mass,
            center_of_mass: object.center_of_mass.coords.into(),
            triangles: object.mesh.indices.len(),
            regions: vec![object.region()],
        };
        self.object = Some(object);
        Ok(summary)
    }

    /// `set_env`: adds or replaces obstacles, all or nothing.
    pub fn set_env(&mut self, req: &SetEnv) -> Result<EnvSummary, PlanError> {
        let built = req
            .obstacles
            .iter()
            .enumerate()
            .map(|(i, o)| build_obstacle(i, o).map(|b| (o.name.clone(), b)))
            .collect::<Result<Vec<_>, _>>()?;
        if req.replace {
            self.env.clear();
        }
        self.env.extend(built);
        Ok(self.env_summary())
    }

    /// `remove_env`: removes obstacles by name (an unknown name removes
    /// nothing) or all of them.
    pub fn remove_env(&mut self, req: &RemoveEnv) -> Result<EnvSummary, PlanError> {
        if req.all {
            self.env.clear();
        } else {
            if let Some((i, n)) = req
                .names
                .iter()
                .enumerate()
                .find(|(_, n)| !self.env.contains_key(*n))
            {
                return Err(PlanError::invalid(
                    format!("names[{i}]"),
                    format!("no obstacle named `{n}`"),
                ));
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

    /// `plan`: searches for a pinch grasp (see the module docs). Polls
    /// `cancel` once per sample and reports through `progress`.
    pub fn plan(
        &self,
        opts: &PlanOptions,
        cancel: &AtomicBool,
        progress: &mut dyn FnMut(&ProgressEvent),
    ) -> Result<PlanReply, PlanError> {
        let start = Instant::now();
        if opts.max_samples == 0 {
            return Err(PlanError::invalid("max_samples", "must be > 0"));
        }
        if opts.time_budget_ms == 0 {
            return Err(PlanError::invalid("time_budget_ms", "must be > 0"));
        }
        if opts.delta_f.is_some_and(|d| !d.is_finite()) {
            return Err(PlanError::invalid("delta_f", "must be finite"));
        }
        let robot = self.robot.as_ref().ok_or(PlanError::NoRobot)?;
        let object = self.object.as_ref().ok_or(PlanError::NoObject)?;
        let size = size_class(&object.box_extents);
        let type_name = format!("fingertip3_{}", size.as_str());
        if let Some(allowed) = &opts.grasp_types {
            if !allowed.contains(&type_name) {
                return Err(PlanError::Infeasible {
                    samples: 0,
                    reason: format!("grasp_types excludes `{type_name}`, the only type this planner uses for this object"),
                });
            }
        }
        let mut timing = PhaseTiming::default();
        let mut stages = vec![robot.arm.clone()];
        if opts.whole_body != WholeBody::ArmOnly {
            stages.push(robot.waist.iter().chain(&robot.arm).copied().collect());
        }
        if opts.whole_body == WholeBody::Squat {
            stages.push(
                std::iter::once(robot.squat)
                    .chain(robot.waist.iter().copied())
                    .chain(robot.arm.iter().copied())
                    .collect(),
            );
        }
        let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
        let mut samples = 0u32;
        let mut rejected: BTreeMap<&'static str, u32> = BTreeMap::new();
        let mut candidates_tried = Vec::new();
        let mut fk = FkState::new(&robot.model);
        let rest = robot.model.rest_positions();
        let env: Vec<&CollisionObject> = self.env.values().collect();
        let half_angle = self.params.cone_fraction * object.mu.atan();
        let shoulder = robot.model.joints[robot.arm[0]].child;
        robot.model.forward_kinematics(&rest, &mut fk);
        let shoulder_pos = fk.pose(shoulder).translation.vector;

        for (stage_index, joints) in stages.iter().enumerate() {
            let extra: Vec<JointId> = joints
                .iter()
                .copied()
                .filter(|j| !robot.arm.contains(j))
                .collect();
            let joints_used = robot.names(&extra);
            candidates_tried.push(type_name.clone());
            let selection =
                JointSelection::new(&robot.model, joints).map_err(|e| PlanError::Model {
                    field: "robot".into(),
                    message: e.to_string(),
                })?;
            let ik_opts = IkOptions {
                max_attempts: self.params.ik_attempts,
                position_tolerance: 5e-4,
                orientation_tolerance: 5e-3,
                seed: opts.seed.wrapping_add(stage_index as u64),
                ..IkOptions::default()
            };
            let mut solver =
                IkSolver::new(&robot.model, robot.palm, selection, ik_opts).map_err(|e| {
                    PlanError::Model {
                        field: "robot".into(),
                        message: e.to_string(),
                    }
                })?;
            let event = |phase, samples, elapsed| ProgressEvent {
                phase,
                grasp_type: Some(type_name.clone()),
                joints_used: joints_used.clone(),
                samples,
                best_margin: None,
                elapsed_ms: elapsed,
            };
            progress(&event(PlanPhase::NominalPose, samples, ms(start)));
            for k in 0..opts.max_samples {
                if cancel.load(Ordering::Relaxed) {
                    return Err(PlanError::Cancelled);
                }
                if ms(start) > opts.time_budget_ms as f64 {
                    return Err(PlanError::Infeasible {
                        samples,
                        reason: format!("time budget of {} ms spent", opts.time_budget_ms),
                    });
                }
                samples += 1;
                if k % PROGRESS_EVERY == PROGRESS_EVERY - 1 {
                    progress(&event(PlanPhase::Search, samples, ms(start)));
                }
                // 1–2: antipodal pair and palm pose ("selection" phase).
                let t = Instant::now();
                let candidate = self.candidate(robot, object, half_angle, &shoulder_pos, &mut rng);
                timing.selection += ms(t);
                let candidate = match candidate {
                    Ok(c) => c,
                    Err(why) => {
                        *rejected.entry(why).or_default() += 1;
                        continue;
                    }
                };
                // 3: inverse kinematics.
                let t = Instant::now();
                let mut q_init = rest.clone();
                for &(j, v) in &candidate.hand_q {
                    q_init[j] = v;
                }
                let sol = solver.solve(&candidate.palm, true, &q_init, Some(&rest));
                timing.nominal_pose += ms(t);
                if !sol.ok {
                    *rejected.entry("palm pose out of reach").or_default() += 1;
                    continue;
                }
                // 4–5: collisions and finger closing.
                let t = Instant::now();
                let closed = self.close_hand(robot, object, &env, sol.q, &mut fk);
                timing.search += ms(t);
                let (q, contacts) = match closed {
                    Ok(c) => c,
                    Err(why) => {
                        *rejected.entry(why).or_default() += 1;
                        continue;
                    }
                };
                // 6: force closure with the weight.
                let t = Instant::now();
                let verdict = force_closure(object, &contacts);
                timing.verification += ms(t);
                let Some((margin, exact_ok)) = verdict else {
                    *rejected.entry("degenerate contacts").or_default() += 1;
                    continue;
                };
                if !exact_ok {
                    *rejected
                        .entry("contacts cannot resist the weight")
                        .or_default() += 1;
                    continue;
                }
                // Accept: fill the reply.
                let palm_pose = {
                    robot.model.forward_kinematics(&q, &mut fk);
                    *fk.pose(robot.palm)
                };
                let approach = palm_pose.rotation * Vector3::z();
                let mut joint_positions = BTreeMap::new();
                for &j in joints.iter().chain(&robot.hand.joints()) {
                    joint_positions.insert(robot.model.joints[j].name.clone(), q[j]);
                }
                timing.total = ms(start);
                progress(&ProgressEvent {
                    best_margin: Some(margin),
                    ..event(PlanPhase::Done, samples, timing.total)
                });
                return Ok(PlanReply {
                    grasp_type: GraspTypeRef {
                        name: type_name.clone(),
                        style: GraspStyle::Fingertip3,
                        size,
                    },
                    ocp_region: 0,
                    face: object.face_toward(&approach),
                    palm_pose: isometry_to_pose(&palm_pose),
                    joint_positions,
                    joints_used,
                    contacts: contacts
                        .iter()
                        .map(|c| ContactReply {
                            link: robot.model.links[c.link].name.clone(),
                            position: c.position.coords.into(),
                            normal: c.normal.into(),
                            f_max: c.f_max,
                        })
                        .collect(),
                    mu: object.mu,
                    object: ObjectMass {
                        mass: object.mass,
                        center_of_mass: object.center_of_mass.coords.into(),
                    },
                    characteristic_length: object.characteristic_length(),
                    force_closure: ForceClosureReply {
                        margin,
                        exact_resists_weight: exact_ok,
                        force_limit: force_limit(&contacts),
                    },
                    samples,
                    timing_ms: timing,
                    candidates_tried,
                });
            }
        }
        progress(&ProgressEvent {
            phase: PlanPhase::Done,
            grasp_type: Some(type_name),
            joints_used: vec![],
            samples,
            best_margin: None,
            elapsed_ms: ms(start),
        });
        let reason = rejected.iter().max_by_key(|(_, n)| **n).map_or_else(
            || "no sample drawn".to_owned(),
            |(why, n)| format!("most samples rejected because: {why} ({n})"),
        );
        Err(PlanError::Infeasible { samples, reason })
    }

    /// Steps 1–2: an antipodal pair and the palm pose that pinches it.
    fn candidate(
        &self,
        robot: &PlanRobot,
        object: &PlanObject,
        half_angle: f64,
        shoulder: &Vector3<f64>,
        rng: &mut ChaCha8Rng,
    ) -> Result<Candidate, &'static str> {
        let pair = sample_pair(&object.mesh, &object.cumulative_area, half_angle, rng)
            .ok_or("no antipodal partner")?;
        let pre = robot
            .hand
            .preshape_for(pair.width() + 2.0 * CLEARANCE)
            .ok_or("wider than the hand opens")?;
        let (a, b) = (object.pose * pair.a, object.pose * pair.b);
        // The thumb takes either point.
        let (thumb_at, fingers_at) = if rng.random::<bool>() { (a, b) } else { (b, a) };
        let axis = Unit::new_normalize(fingers_at - thumb_at);
        let axis_palm = pre.finger_tip - pre.thumb_tip;
        let align = UnitQuaternion::rotation_between(&axis_palm, &axis).unwrap_or_else(|| {
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
        });
        let centre = nalgebra::center(&thumb_at, &fingers_at);
        let reach = (centre.coords - shoulder).normalize();
        // Rolls about the pinch line, scored by how well the palm faces the
        // object from the shoulder's side and not from below.
        let mut rolls: Vec<(f64, UnitQuaternion<f64>)> = (0..ROLLS)
            .map(|k| {
                let r =
                    UnitQuaternion::from_axis_angle(&axis, k as f64 * TAU / ROLLS as f64) * align;
                let approach = r * Vector3::z();
                (approach.dot(&reach) - approach.z.max(0.0), r)
            })
            .collect();
        rolls.sort_by(|x, y| y.0.total_cmp(&x.0));
        let (score, rotation) = rolls[rng.random_range(0..3)];
        if score < 0.0 {
            return Err("palm would face away from the shoulder");
        }
        let pad_centre = nalgebra::center(&pre.thumb_tip, &pre.finger_tip);
        let translation = centre.coords - rotation * pad_centre.coords;
        Ok(Candidate {
            palm: Isometry3::from_parts(Translation3::from(translation), rotation),
            hand_q: pre.q.clone(),
        })
    }

    /// Steps 4–5: collision checks around closing the three fingers.
    fn close_hand(
        &self,
        robot: &PlanRobot,
        object: &PlanObject,
        env: &[&CollisionObject],
        mut q: Vec<f64>,
        fk: &mut FkState,
    ) -> Result<(Vec<f64>, Vec<FingerContact>), &'static str> {
        robot.model.forward_kinematics(&q, fk);
        let hand_links: Vec<_> = std::iter::once(robot.palm)
            .chain(
                robot
                    .hand
                    .pinching()
                    .chain([&robot.hand.idle])
                    .flat_map(|f| f.links.iter().copied()),
            )
            .collect();
        let arm_and_hand: Vec<_> = robot
            .arm_links
            .iter()
            .copied()
            .chain(hand_links.iter().copied())
            .collect();
        if robot
            .collision
            .first_collision(fk, &arm_and_hand, env, 0.0)
            .is_some()
        {
            return Err("arm or hand hits an obstacle");
        }
        if robot
            .collision
            .first_collision(fk, &arm_and_hand, &[&object.collision], 0.0)
            .is_some()
        {
            return Err("hand hits the object before closing");
        }
        let mut contacts = Vec::new();
        for finger in robot.hand.pinching() {
            let c = close_finger(
                &robot.model,
                &robot.collision,
                finger,
                &mut q,
                fk,
                &object.collision,
                &self.params.closing,
            )
            .ok_or("a finger closes without touching")?;
            contacts.push(c);
        }
        robot.model.forward_kinematics(&q, fk);
        if robot
            .collision
            .first_collision(fk, &hand_links, env, 0.0)
            .is_some()
        {
            return Err("closed fingers hit an obstacle");
        }
        if robot.collision.first_self_collision(fk, 0.0).is_some() {
            return Err("self-collision");
        }
        Ok((q, contacts))
    }
}

/// The one normal-force bound applied to every contact: the weakest finger's
/// `f_max` (N), stated in the reply (`ForceClosureReply::force_limit`).
pub fn force_limit(contacts: &[FingerContact]) -> f64 {
    contacts
        .iter()
        .map(|c| c.f_max)
        .fold(f64::INFINITY, f64::min)
}

/// The ellipsoid margin of eq. (10) and the exact test's verdict for the
/// object's weight; `None` when the contacts do not make a valid grasp.
pub fn force_closure(object: &PlanObject, contacts: &[FingerContact]) -> Option<(f64, bool)> {
    let cs = contacts
        .iter()
        .map(|c| Contact::new(c.position, c.normal).ok())
        .collect::<Option<Vec<_>>>()?;
    let limits = vec![force_limit(contacts); contacts.len()];
    let grasp = Grasp::with_force_limits(
        cs,
        limits,
        object.mu,
        object.characteristic_length(),
        object.center_of_mass,
    )
    .ok()?;
    let weight = grasp.weight_wrench(object.mass, &GRAVITY, &object.center_of_mass);
    let margin = ellipsoid_test(&grasp, &EllipsoidModel::default(), &weight).margin();
    let exact = exact_test(&grasp, ConeModel::Circular, &weight).ok()?;
    Some((margin, exact.resists_weight()))
}
