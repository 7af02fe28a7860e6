//! The paper's planner as a `GraspPlanner` of the planner kit.
//!
//! What: [`Paper`] derives a [`HandModel`] from the world's robot and a
//! [`PlanObject`] (OCP boxes) from its object, and plans: grasp-type selection
//! (eqs. (1)–(5)), then for each whole-body stage (arm; arm + waist; arm +
//! waist + squat) the IK of every nominal palm pose, ranked by the palm
//! criterion plus the weighted eq. (3) score, and Algorithm 1 on the best few
//! until one gives a force-closure grasp the exact test confirms.
//!
//! Why: the kit owns the world, validation, dispatch, errors, the reply and
//! the final verification; this file is only the paper's method.
//! [`Planner`] is the kit's session around it, for in-process use.
//!
//! ```no_run
//! use std::sync::atomic::AtomicBool;
//! use tsukami_grasp_planner::planner::Planner;
//! use tsukami_msgs::planner::*;
//! let p = Planner::new("models");
//! p.set_robot(&SetRobot {
//!     robot: "tsukami_humanoid".into(),
//!     grasp_types: None,
//!     package_dirs: Vec::new(),
//! })?;
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

use std::time::{Duration, Instant};

use nalgebra::Isometry3;
use tsukami_body::collision::CollisionObject;
use tsukami_body::ik::{IkOptions, IkSolver};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_msgs::planner::{FaceBlock, OcpBox, PlanOptions, PlanPhase};
use tsukami_planner_kit::{FingerContact, Grasp, GraspPlanner, KitError, NoGrasp, Stop};
use tsukami_planner_kit::{Object, PlannerConfig, PlannerInfo, Robot, Run, World};

use crate::clearance::{clear_nominal, max_lift, Surroundings};
use crate::hand::HandModel;
use crate::link_sets::LinkSets;
use crate::object::PlanObject;
use crate::ocp::{Ocp, OcpParams};
use crate::palm_pose::{criterion_value, palm_targets};
use crate::search::{
    search, Bar, Counters, Found, Judged, Outcome, SearchContext, SearchParams,
    ROBUST_EXTRA_SAMPLES,
};
use crate::selection::{select, Candidate, Selection};
use crate::tilt::tilts;
use crate::whole_body::{stages, StageJoints};

/// The planner with its world (the kit's session), for in-process use.
pub type Planner = tsukami_planner_kit::Session<Paper>;
/// Why a request failed (the kit's error; `reason()` is the stable word).
pub type PlanError = KitError;

/// Tunable parameters of the planner (defaults follow the paper).
#[derive(Debug, Clone)]
pub struct PlannerParams {
    /// OCP computation.
    pub ocp: OcpParams,
    /// Algorithm 1 ranges.
    pub search: SearchParams,
    /// Weight (rad per m) of the eq. (3) score against the palm criterion.
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

/// The paper's planner.
#[derive(Debug, Default)]
pub struct Paper {
    /// Its parameters.
    pub params: PlannerParams,
}

/// A nominal palm pose with its IK solution.
struct Nominal {
    candidate: Candidate,
    palm: Isometry3<f64>,
    q: Vec<f64>,
    cost: f64,
    /// The open hand at the nominal pose already touches an obstacle, the
    /// robot itself or the object where it may not (searched after the rest).
    blocked: bool,
}

impl GraspPlanner for Paper {
    type RobotData = HandModel;
    type ObjectData = PlanObject;

    fn info() -> PlannerInfo {
        PlannerInfo {
            name: "tsukami-grasp-planner",
            version: env!("CARGO_PKG_VERSION"),
            description: "the paper's grasp planner: grasp types, nominal palm pose, random posture search, whole-body fallback",
        }
    }

    fn new(_config: &PlannerConfig) -> Result<Self, String> {
        Ok(Paper::default())
    }

    fn robot_data(&self, robot: &Robot) -> Result<HandModel, KitError> {
        HandModel::from_robot(robot)
    }

    fn object_data(&self, o: &Object) -> Result<PlanObject, KitError> {
        PlanObject::new(o, &self.params.ocp).map_err(|e| KitError::model("shape", e.to_string()))
    }

    fn regions(&self, _object: &Object, data: &PlanObject) -> Vec<OcpBox> {
        data.ocps.iter().map(|o| o.to_msg()).collect()
    }

    fn plan(
        &self,
        w: &World<'_, Self>,
        opts: &PlanOptions,
        run: &mut Run,
    ) -> Result<Grasp, NoGrasp> {
        let (hand, object) = (w.robot_data, w.object_data);
        let all = &hand.config.grasp_types;
        let enabled: Vec<usize> = (0..all.len())
            .filter(|&i| {
                opts.grasp_types
                    .as_ref()
                    .is_none_or(|n| n.contains(&all[i].name))
            })
            .collect();
        run.phase(PlanPhase::Selection, None, &[]);
        // Eqs. (1)–(5), score (3).
        let types: Vec<_> = enabled.iter().map(|&i| all[i].clone()).collect();
        // Faces resting on a support or blocked by an obstacle are not sampled.
        let mut ocps = object.ocps.clone();
        crate::support::block_faces(&mut ocps, &w.obstacles, &Default::default());
        // The support's height, when the object stands on one (its lowest point).
        let floor = ocps
            .iter()
            .any(|o| o.blocked.iter().flatten().any(|b| *b == FaceBlock::Support))
            .then_some(object.lowest);
        let mut selection = select(&types, &ocps, object.mass);
        for c in selection
            .candidates
            .iter_mut()
            .chain(&mut selection.fallback)
        {
            c.grasp_type = enabled[c.grasp_type];
        }
        if selection.candidates.is_empty() && selection.fallback.is_empty() {
            return Err(NoGrasp::NoGraspType(selection.explain(&types)));
        }
        let params = SearchParams {
            max_samples: opts.max_samples,
            delta_f: opts.delta_f.unwrap_or(self.params.search.delta_f),
            // A requested δf is the paper's rule: no acceptance below it.
            paper_rule: opts.delta_f.is_some(),
            hold: opts.hold,
            contact_distance: hand.contact_distance,
            ..self.params.search.clone()
        };
        let ctx = SearchContext {
            hand,
            object,
            env: &w.obstacles,
            cancel: run.cancel_flag(),
            deadline: run.deadline().unwrap_or_else(far_future),
            params: &params,
        };
        let mut tiers = Tiers {
            counters: Counters::default(),
            any_reachable: false,
            last_stage: String::from("the arm"),
            partial: None,
        };
        // The mass range's preferred types on every stage first, then the
        // types that fit in size only (`Selection::fallback`), then both at
        // an angle ([`crate::tilt`]).
        let tilted = tilted(&selection, &ocps);
        for (tier, candidates) in [&selection.candidates, &selection.fallback, &tilted]
            .into_iter()
            .enumerate()
        {
            if let Some(g) =
                self.search_tier(w, opts, run, &ctx, (tier, candidates), floor, &mut tiers)?
            {
                return Ok(g);
            }
        }
        if let Some(p) = tiers.partial {
            run.phase(
                PlanPhase::Verification,
                Some(&p.grasp.grasp_type.name),
                &p.extra,
            );
            return Ok(p.grasp);
        }
        record_rejections(run, &tiers.counters);
        Err(match tiers.any_reachable {
            false => NoGrasp::Unreachable(tiers.last_stage),
            true => NoGrasp::Exhausted,
        })
    }
}

/// What the tiers of one plan share: the search's counts, whether any
/// nominal pose was reachable (and on which stage last), and the best grasp
/// set aside so far.
struct Tiers {
    counters: Counters,
    any_reachable: bool,
    last_stage: String,
    partial: Option<SetAside>,
}

/// The share of the sampled object pose errors below which a set-aside
/// fingertip grasp is *weak*: the planner then looks through the later tiers
/// for a better one ([`SetAside`]). On the physics benchmark (humanoid, 258
/// cases, 2026-12-03) the returned fingertip grasps that held under fewer than
/// six of eight errors held in MuJoCo 6 times of 33, those that held under six
/// or seven 13 of 24.
pub const WEAK_SHARE: f64 = 0.75;

/// The best grasp found so far that is not preferred ([`Found::rank`]); a
/// later candidate's grasp replaces it when it ranks higher.
///
/// When a stage's candidates are spent it is returned, unless it is a weak
/// fingertip grasp (no palm contact, holding under less than [`WEAK_SHARE`]
/// of the pose errors): that one is kept while the later tiers (the types
/// that fit in size only, the tilts) are searched on its whole-body stage or
/// an earlier one (the arm alone is never traded for a squat), and returned
/// at the end if nothing better is found. An envelope is not traded: its type
/// is the one the selection chose for the object's weight.
struct SetAside {
    rank: (u32, bool, f64),
    /// The index of its whole-body stage ([`stages`]).
    stage: usize,
    /// Returned when its stage's candidates are spent (not a weak fingertip grasp).
    settles: bool,
    /// The names of that stage's extra joints (the reply's phase report).
    extra: Vec<String>,
    grasp: Grasp,
}

/// Hands the search's counts to the kit: every reason of
/// [`crate::search::REJECTION_REASONS`] (`verification`: samples the final
/// check refused) and every blocker (`"<link> vs <obstacle>"`).
fn record_rejections(run: &mut Run, counters: &Counters) {
    for (why, n) in crate::search::REJECTION_REASONS
        .iter()
        .zip(counters.rejections)
    {
        run.rejected(why, n);
    }
    for (what, &n) in &counters.blockers {
        run.blocked(what, n);
    }
}

/// Every candidate of `selection` (preferred types, then the fallback) at
/// each of its face's tilts ([`crate::tilt::tilts`]).
fn tilted(selection: &Selection, ocps: &[Ocp]) -> Vec<Candidate> {
    selection
        .candidates
        .iter()
        .chain(&selection.fallback)
        .flat_map(|c| {
            tilts(&ocps[c.region], c.face)
                .into_iter()
                .map(|t| Candidate {
                    tilt: Some(t),
                    ..c.clone()
                })
        })
        .collect()
}

/// A deadline that never comes (no wall-clock limit was asked for).
fn far_future() -> Instant {
    let now = Instant::now();
    now.checked_add(Duration::from_secs(365 * 86_400))
        .unwrap_or(now)
}

fn grasp(
    grasp_type: tsukami_msgs::planner::GraspTypeRef,
    c: &Candidate,
    stage: &StageJoints,
    found: Found,
    object: &PlanObject,
) -> Grasp {
    Grasp {
        grasp_type,
        region: c.region,
        face: c.face,
        tilt: c.tilt,
        q: found.q,
        joints: stage.joints.clone(),
        extra: stage.extra.clone(),
        contacts: found
            .contacts
            .iter()
            .map(|f| FingerContact {
                link: f.link,
                position: f.position,
                normal: f.normal,
                f_max: f.f_max,
            })
            .collect(),
        characteristic_length: Some(object.characteristic_length),
    }
}

impl Paper {
    /// Every whole-body stage in turn for one tier of candidates: the nominal
    /// poses, then Algorithm 1 on the best few. `Some` with the first grasp.
    #[allow(clippy::too_many_arguments)]
    fn search_tier(
        &self,
        w: &World<'_, Self>,
        opts: &PlanOptions,
        run: &mut Run,
        ctx: &SearchContext<'_>,
        (tier, candidates): (usize, &[Candidate]),
        floor: Option<f64>,
        t: &mut Tiers,
    ) -> Result<Option<Grasp>, NoGrasp> {
        let (hand, object) = (w.robot_data, w.object_data);
        if candidates.is_empty() {
            return Ok(None);
        }
        for (si, stage) in stages(hand, opts.whole_body).into_iter().enumerate() {
            // A grasp set aside on this stage bounds the body's motion.
            if t.partial.as_ref().is_some_and(|p| si > p.stage) {
                break;
            }
            let extra = hand.names(&stage.extra);
            t.last_stage = match extra.is_empty() {
                true => "the arm".into(),
                false => format!("the arm and {}", extra.join(", ")),
            };
            run.phase(PlanPhase::NominalPose, None, &extra);
            let mut nominals = self.nominals(
                hand,
                object,
                candidates,
                &stage,
                opts,
                (si, floor, &w.obstacles),
                run,
            )?;
            if nominals.is_empty() {
                continue;
            }
            t.any_reachable = true;
            // Approaches the support or an obstacle blocks go last; then by cost.
            nominals.sort_by(|a, b| a.blocked.cmp(&b.blocked).then(a.cost.total_cmp(&b.cost)));
            for (k, nom) in nominals
                .iter()
                .take(opts.max_candidates.max(1) as usize)
                .enumerate()
            {
                if let Some(g) =
                    self.try_nominal(w, opts, run, ctx, (tier, si, k), (&stage, &extra), nom, t)?
                {
                    return Ok(Some(g));
                }
            }
            if let Some(p) = t.partial.take_if(|p| p.settles) {
                run.phase(
                    PlanPhase::Verification,
                    Some(&p.grasp.grasp_type.name),
                    &p.extra,
                );
                return Ok(Some(p.grasp));
            }
        }
        Ok(None)
    }

    /// Algorithm 1 around one nominal pose (the `k`-th of stage `si` of tier
    /// `tier`): `Some` with a preferred grasp; a grasp that is not preferred
    /// goes to `t.partial` when it ranks above the one set aside.
    #[allow(clippy::too_many_arguments)]
    fn try_nominal(
        &self,
        w: &World<'_, Self>,
        opts: &PlanOptions,
        run: &mut Run,
        ctx: &SearchContext<'_>,
        (tier, si, k): (usize, usize, usize),
        (stage, extra): (&StageJoints, &[String]),
        nom: &Nominal,
        t: &mut Tiers,
    ) -> Result<Option<Grasp>, NoGrasp> {
        let (object, all) = (w.object_data, &w.robot_data.config.grasp_types);
        let pm = opts.hold.preferred_margin;
        let g = &all[nom.candidate.grasp_type];
        run.tried(&g.name);
        run.phase(PlanPhase::Search, Some(&g.name), extra);
        let seed = opts
            .seed
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(((tier as u64) << 32) | ((si as u64) << 16) | k as u64);
        let ti = nom.candidate.grasp_type;
        // Once a grasp is set aside, a later nominal pose only gets
        // the samples the first got after its partial grasp.
        let limit = match t.partial {
            Some(_) => ROBUST_EXTRA_SAMPLES,
            None => u32::MAX,
        };
        let outcome = search(
            ctx,
            ti,
            stage,
            (&nom.palm, &nom.q),
            seed,
            limit,
            &mut t.counters,
            &mut |found, bar| {
                let g = grasp(g.to_ref(), &nom.candidate, stage, found.clone(), object);
                run.motion_phases(w, &g).map_err(|b| b.to_string())?;
                // Only compared with the preferred margin.
                let hold_margin = run.hold_margin_up_to(w, &g, &opts.hold, pm).unwrap_or(0.0);
                let robustness = Bar::may_beat(bar, found.off_edges(), hold_margin.min(pm))
                    .then(|| run.pose_robustness(w, &g, &opts.hold, opts.seed));
                Ok(Judged {
                    robustness,
                    hold_margin,
                })
            },
        );
        run.record(t.counters.samples, t.counters.best_margin);
        match outcome {
            Outcome::Found(found) => {
                run.phase(PlanPhase::Verification, Some(&g.name), extra);
                return Ok(Some(grasp(
                    g.to_ref(),
                    &nom.candidate,
                    stage,
                    *found,
                    object,
                )));
            }
            Outcome::Partial(found) => {
                let rank = found.rank(pm);
                if t.partial.as_ref().is_none_or(|p| rank > p.rank) {
                    let weak = found.robustness.share() < WEAK_SHARE;
                    t.partial = Some(SetAside {
                        rank,
                        stage: si,
                        settles: all[ti].palm_contact || !weak,
                        extra: extra.to_vec(),
                        grasp: grasp(g.to_ref(), &nom.candidate, stage, *found, object),
                    });
                }
            }
            Outcome::Cancelled => return Err(Stop::Cancelled.into()),
            Outcome::OutOfTime => return Err(run.check().err().unwrap_or(Stop::Cancelled).into()),
            Outcome::Exhausted => {}
        }
        Ok(None)
    }

    /// The nominal palm poses of one stage that have an IK solution (section 3.2).
    #[allow(clippy::too_many_arguments)]
    fn nominals(
        &self,
        hand: &HandModel,
        object: &PlanObject,
        candidates: &[Candidate],
        stage: &StageJoints,
        opts: &PlanOptions,
        (si, floor, env): (usize, Option<f64>, &[&CollisionObject]),
        run: &mut Run,
    ) -> Result<Vec<Nominal>, NoGrasp> {
        let mut fk = FkState::new(&hand.robot);
        let mut q_init = hand.robot.rest_positions();
        // A natural start: elbow bent (seeds the IK away from the straight-arm singularity).
        if let Some(&elbow) = hand.arm.get(3) {
            let l = &hand.robot.joints[elbow].limits;
            q_init[elbow] = (-1.0f64).clamp(l.lower, l.upper);
        }
        let (Ok(sel), mut out) = (JointSelection::new(&hand.robot, &stage.joints), Vec::new())
        else {
            return Ok(Vec::new());
        };
        let ik_opts = IkOptions {
            max_attempts: self.params.nominal_ik_attempts,
            position_tolerance: 1e-4,
            orientation_tolerance: 1e-3,
            seed: opts.seed ^ (si as u64) << 32,
            ..IkOptions::default()
        };
        let Ok(mut ik) = IkSolver::new(&hand.robot, hand.palm, sel, ik_opts) else {
            return Ok(out);
        };
        let around = Surroundings {
            object: &object.collision,
            env,
        };
        for cand in candidates {
            let g = &hand.config.grasp_types[cand.grasp_type];
            let links = LinkSets::for_type(hand, cand.grasp_type, &stage.extra);
            let ocp = &object.ocps[cand.region];
            for target in palm_targets(g, ocp, cand.face, cand.tilt, floor) {
                run.check()?;
                let mut q0 = q_init.clone();
                hand.set_posture(cand.grasp_type, &mut q0);
                let Some(c) = clear_nominal(
                    &mut ik,
                    hand,
                    &links,
                    &target.palm,
                    (&q0, &q_init),
                    &around,
                    (cand.grasp_type, max_lift(ocp)),
                    &mut fk,
                ) else {
                    continue;
                };
                let cost = criterion_value(hand, &c.q, opts.palm_criterion, &stage.joints)
                    + self.params.score_weight * cand.score;
                out.push(Nominal {
                    candidate: cand.clone(),
                    palm: c.palm,
                    q: c.q,
                    cost,
                    blocked: c.blocked,
                });
            }
        }
        Ok(out)
    }
}
