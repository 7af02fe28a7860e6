//! Final posture search, the paper's Algorithm 1 (sections 3.4–3.5).
//!
//! What: [`search`] starts from one nominal palm pose and its IK solution and
//! draws random offsets — Δp_p (the OCP's position w.r.t. the GRC, i.e. the
//! palm position), Δp_s (the shoulder height, only in the squat stage) and Δa_i
//! (each finger's pre-shape) — until the fingers close on the object without
//! collision and the ellipsoid margin `n − f(p1..pn)` of eq. (10), for the
//! object's weight and the fingers' maximum forces, reaches δf.
//!
//! Why: random sampling around a good nominal pose is what makes the paper's
//! planner fast; the ellipsoid test costs well under a microsecond, so most
//! time goes to IK and distance queries.
//!
//! How: the first sample is the nominal pose itself. Each sample solves the
//! palm IK over the stage's joint list (warm-started from the nominal
//! solution), sets the reference posture plus Δa, checks the open hand and arm
//! against the environment and the object, closes the fingers
//! ([`crate::finger_closing`]), checks again (contacting links may touch the
//! object, nothing may touch the environment or the robot itself), computes
//! the ellipsoid margin, asks the certificates of earlier samples' weight
//! programs whether this one can still hold the weight ([`WeightHints`]),
//! checks the returned-grasp guarantees ([`crate::verify::check_grasp`]) and
//! last runs the exact programs (`tsukami-grasp`), the costliest tests: the
//! weight program, then the kit's hold test (exact force closure and every
//! disturbance of the request's set balanced by forces the finger joints'
//! torques can make, `tsukami_planner_kit::blocks::hold`). The ellipsoid
//! margin ranks; only with the paper's rule ([`SearchParams::paper_rule`])
//! must it reach δf as well. The
//! generator is ChaCha8 seeded by the caller: the same seed, same result. The
//! cancel flag and the deadline are checked before every sample (a sample
//! takes well under a millisecond). Two rules stop a search before its
//! budget, both counted in samples: a nominal pose none of whose first
//! [`STALL_SAMPLES`] open hands was clear of the object and the obstacles is
//! given up, and a
//! caller that already holds a grasp that is not preferred passes a `limit`
//! of [`ROBUST_EXTRA_SAMPLES`].

use std::cell::Cell;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use nalgebra::{Isometry3, Point3, Translation3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tsukami_body::collision::CollisionObject;
use tsukami_body::ik::{IkOptions, IkSolver};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::model::JointId;
use tsukami_grasp::contact::Contact;
use tsukami_grasp::ellipsoid::{ellipsoid_test, EllipsoidModel};
use tsukami_grasp::exact::{
    exact_force_closure, exact_weight_scale, weight_scale_bound, ConeModel,
};
use tsukami_grasp::grasp::Grasp;
use tsukami_grasp::grasp_matrix::Wrench;

use tsukami_msgs::planner::{HoldRequest, PoseRobustness};
use tsukami_planner_kit::blocks::hold::{holds_under, HoldContact, HoldProblem};
use tsukami_planner_kit::blocks::wrap::{style_check, StyleRule};

use crate::edges::EDGE_CLEARANCE;
use crate::finger_closing::{close_fingers, FingerContact};
use crate::hand::HandModel;
use crate::link_sets::LinkSets;
use crate::object::PlanObject;
use crate::verify::{check_grasp, PENETRATION_TOLERANCE};
use crate::whole_body::{Stage, StageJoints};

/// Gravity (world frame, m/s²).
pub const GRAVITY: Vector3<f64> = Vector3::new(0.0, 0.0, -9.81);

/// Sampling ranges and thresholds of Algorithm 1.
#[derive(Debug, Clone)]
pub struct SearchParams {
    /// Samples per nominal pose.
    pub max_samples: u32,
    /// Required ellipsoid margin δf.
    pub delta_f: f64,
    /// Half-range of Δp_p across the approach (m).
    pub palm_offset: f64,
    /// Half-range of Δp_p along the approach (m).
    pub approach_offset: f64,
    /// Half-range of Δa_i on each perturbed finger joint (rad).
    pub finger_offset: f64,
    /// Range of Δp_s, the squat offset (m), used in the squat stage.
    pub squat_offset: (f64, f64),
    /// Finger-closing distance threshold (m).
    pub contact_distance: f64,
    /// The paper's rule: a sample must reach the ellipsoid margin δf (a
    /// request that sets δf). Otherwise the ellipsoid, an inner
    /// approximation of eq. (10), only ranks: the exact tests decide.
    pub paper_rule: bool,
    /// What an accepted sample must resist (the kit's hold test,
    /// `tsukami_planner_kit::blocks::hold`, the same the verification applies).
    pub hold: HoldRequest,
    /// A nominal pose is given up after this many samples when the open hand
    /// of none of them was clear (every one failed the IK or collided before
    /// closing): [`STALL_SAMPLES`] by default.
    pub stall_samples: u32,
}

/// Samples after which a nominal pose none of whose open hands was clear is
/// given up ([`SearchParams::stall_samples`]). Draws around one nominal pose
/// share its neighbourhood: when a hundred open hands there all collide (or
/// have no IK solution), the free share of that neighbourhood is below 3 % at
/// 95 % confidence (the rule of three), and the other nominal poses are the
/// better use of the budget. (Counting only samples that reach the force
/// tests gave up too early: on low objects the Allegro's fingers close on
/// one sample in two or three hundred.)
pub const STALL_SAMPLES: u32 = 100;

impl Default for SearchParams {
    fn default() -> Self {
        Self {
            max_samples: 300,
            delta_f: 0.05,
            palm_offset: 0.015,
            approach_offset: 0.01,
            finger_offset: 0.12,
            squat_offset: (-0.12, 0.04),
            contact_distance: 0.002,
            paper_rule: false,
            hold: HoldRequest::default(),
            stall_samples: STALL_SAMPLES,
        }
    }
}

/// What the search works on.
pub struct SearchContext<'a> {
    /// The robot.
    pub hand: &'a HandModel,
    /// The object.
    pub object: &'a PlanObject,
    /// Obstacles.
    pub env: &'a [&'a CollisionObject],
    /// Set to stop.
    pub cancel: &'a AtomicBool,
    /// Give up after this instant.
    pub deadline: Instant,
    /// Parameters.
    pub params: &'a SearchParams,
}

/// A grasp found by [`search`].
#[derive(Debug, Clone)]
pub struct Found {
    /// Full joint vector.
    pub q: Vec<f64>,
    /// Palm pose (world).
    pub palm: Isometry3<f64>,
    /// Finger contacts.
    pub contacts: Vec<FingerContact>,
    /// Ellipsoid margin `n − f` for the weight.
    pub margin: f64,
    /// Exact test: the weight is resisted.
    pub exact_resists_weight: bool,
    /// Time spent in exact tests (ms).
    pub exact_ms: f64,
    /// Of the request's object pose errors, how many it still holds under.
    pub robustness: PoseRobustness,
    /// The exact hold margin (the multiple of every disturbance it resists).
    pub hold_margin: f64,
    /// How far its nearest contact is from a sharp edge of the object (m).
    pub edge_distance: f64,
}

impl Found {
    /// Whether it is a grasp the planner prefers: it holds under every pose
    /// error, resists `preferred_margin` times every disturbance and keeps its
    /// contacts off the object's sharp edges ([`Found::off_edges`]).
    pub fn preferred(&self, preferred_margin: f64) -> bool {
        self.robustness.held == self.robustness.samples
            && self.hold_margin >= preferred_margin
            && self.off_edges()
    }

    /// Whether every contact keeps [`EDGE_CLEARANCE`] from the object's sharp edges.
    pub fn off_edges(&self) -> bool {
        self.edge_distance >= EDGE_CLEARANCE
    }

    /// Its rank among grasps that are not preferred (higher is better): the
    /// pose errors it holds under, then whether its contacts are off the
    /// edges, then its margin up to `preferred_margin`.
    pub fn rank(&self, preferred_margin: f64) -> (u32, bool, f64) {
        (
            self.robustness.held,
            self.off_edges(),
            self.hold_margin.min(preferred_margin),
        )
    }
}

/// What the kit says of an accepted grasp ([`Judge`]).
#[derive(Debug, Clone, Copy)]
pub struct Judged {
    /// Of the request's object pose errors, how many it still holds under;
    /// `None` when the judge skipped the re-check because the grasp cannot
    /// beat the kept one ([`Bar::may_beat`]).
    pub robustness: Option<PoseRobustness>,
    /// Its exact hold margin (clipped at the preferred one is enough).
    pub hold_margin: f64,
}

/// The grasp a search keeps while it looks for a preferred one, as a later
/// accepted sample must beat it ([`Found::rank`]).
#[derive(Debug, Clone, Copy)]
pub struct Bar {
    /// Its rank.
    pub rank: (u32, bool, f64),
    /// Whether it held under every pose error.
    pub robust: bool,
}

impl Bar {
    /// Whether a sample whose contacts are `off_edges` and whose hold margin
    /// clipped at the preferred one is `margin` can be preferred or beat the
    /// kept grasp, whatever its robustness. When the kept grasp held under
    /// every error, no sample with an equal or lower `(off_edges, margin)`
    /// can (nor be preferred: the kept one would have been), so the judge
    /// may skip the pose-error re-check, the costliest test.
    pub fn may_beat(bar: Option<Self>, off_edges: bool, margin: f64) -> bool {
        match bar {
            Some(b) if b.robust => (off_edges, margin) > (b.rank.1, b.rank.2),
            _ => true,
        }
    }
}

/// How a search ended.
#[derive(Debug, Clone)]
pub enum Outcome {
    /// A grasp was found.
    Found(Box<Found>),
    /// The samples ran out with accepted grasps none of which is preferred
    /// ([`Found::preferred`]): the best ranked ([`Found::rank`]).
    Partial(Box<Found>),
    /// All samples were used.
    Exhausted,
    /// The cancel flag was set.
    Cancelled,
    /// The deadline passed.
    OutOfTime,
}

/// The reasons a sample is rejected, in the order of [`Counters::rejections`].
pub const REJECTION_REASONS: [&str; 12] = [
    "ik",
    "collision before closing",
    "finger closing",
    "collision after closing",
    "force closure",
    "verification",
    "no wrap",
    "pose error",
    "too compliant",
    "motion blocked",
    "below preferred margin",
    "contact on an edge",
];

/// Samples a search goes on drawing, after its first accepted grasp that is
/// not preferred ([`Found::preferred`]), for one that is.
pub const ROBUST_EXTRA_SAMPLES: u32 = 48;

/// The gap (m) a palm-contact grasp type leaves between palm and object
/// before the fingers close: the palm then touches within the contact distance.
pub const PALM_GAP: f64 = 0.0005;

/// Running counters shared across searches of one plan.
#[derive(Debug, Clone, Default)]
pub struct Counters {
    /// Samples drawn.
    pub samples: u32,
    /// Best ellipsoid margin seen.
    pub best_margin: Option<f64>,
    /// Why samples were rejected, per [`REJECTION_REASONS`].
    pub rejections: [u32; 12],
    /// What blocked the collision-rejected samples: `"<link> vs <obstacle>"`
    /// (or `"… vs <link>"` for self-collision) with counts.
    pub blockers: BTreeMap<String, u32>,
    /// The exact weight program's certificates so far ([`exact_resists`]).
    pub hints: WeightHints,
}

impl Counters {
    fn reject(&mut self, reason: usize, blocker: Option<String>) {
        self.rejections[reason] += 1;
        if let Some(b) = blocker {
            *self.blockers.entry(b).or_default() += 1;
        }
    }

    /// Every non-zero rejection count: the reasons of [`REJECTION_REASONS`],
    /// then the blockers as `"blocked: <link> vs <obstacle>"`, most frequent first.
    pub fn reasons(&self) -> Vec<(String, u32)> {
        let mut out: Vec<(String, u32)> = REJECTION_REASONS
            .iter()
            .zip(self.rejections)
            .filter(|(_, n)| *n > 0)
            .map(|(r, n)| (r.to_string(), n))
            .collect();
        let mut b: Vec<_> = self.blockers.iter().collect();
        b.sort_by(|x, y| y.1.cmp(x.1).then(x.0.cmp(y.0)));
        out.extend(b.into_iter().map(|(k, n)| (format!("blocked: {k}"), *n)));
        out
    }
}

/// What the kit says of an accepted grasp before the search keeps it
/// (`tsukami_planner_kit::Run`): `Err` (why) when the approach, closing or lift
/// it implies is blocked (`Run::motion_phases`, the trajectory planner's
/// checks), else how many of the request's object pose errors it still holds
/// under (`Run::pose_robustness`) and its exact hold margin
/// (`Run::hold_margin`).
pub type Judge<'h> = dyn FnMut(&Found, Option<Bar>) -> Result<Judged, String> + 'h;

/// Algorithm 1 around one nominal pose. `q_nominal` is the nominal IK solution
/// (full vector) for grasp type `t` over `stage`. An accepted grasp whose
/// approach, closing or lift is blocked is a rejection (`motion blocked`). The
/// first preferred grasp ([`Found::preferred`]: it holds under every pose
/// error with the request's `preferred_margin`) is returned; one that is not
/// is kept while the search goes on for at most [`ROBUST_EXTRA_SAMPLES`]
/// samples, and the best kept ([`Found::rank`], the first of equals) is
/// returned then as [`Outcome::Partial`]: the caller tries its other nominal
/// poses before it takes it, each with `limit` samples at most
/// ([`ROBUST_EXTRA_SAMPLES`] once it holds a partial grasp).
#[allow(clippy::too_many_arguments)]
pub fn search(
    ctx: &SearchContext<'_>,
    t: usize,
    stage: &StageJoints,
    (nominal_palm, q_nominal): (&Isometry3<f64>, &[f64]),
    seed: u64,
    limit: u32,
    counters: &mut Counters,
    judge: &mut Judge<'_>,
) -> Outcome {
    let mut best: Option<Box<Found>> = None;
    let stop_at = Cell::new(limit);
    let outcome = sample_loop(
        ctx,
        (t, stage),
        (nominal_palm, q_nominal),
        seed,
        counters,
        &mut |found, at, counters| {
            let preferred = ctx.params.hold.preferred_margin;
            let bar = best.as_ref().map(|b| Bar {
                rank: b.rank(preferred),
                robust: b.robustness.held == b.robustness.samples,
            });
            let j = match judge(&found, bar) {
                Ok(j) => j,
                Err(why) => {
                    counters.reject(9, Some(why));
                    return None;
                }
            };
            let Some(robustness) = j.robustness else {
                // It cannot beat the kept grasp (`Bar::may_beat`).
                counters.reject(if found.off_edges() { 10 } else { 11 }, None);
                return None;
            };
            let found = Box::new(Found {
                robustness,
                hold_margin: j.hold_margin,
                ..found
            });
            if found.preferred(preferred) {
                return Some(Outcome::Found(found));
            }
            let reason = match (
                found.robustness.held == found.robustness.samples,
                found.off_edges(),
            ) {
                (false, _) => 7,
                (true, false) => 11,
                (true, true) => 10,
            };
            counters.reject(reason, None);
            if best.is_none() {
                stop_at.set(stop_at.get().min(at.saturating_add(ROBUST_EXTRA_SAMPLES)));
            }
            if best
                .as_ref()
                .is_none_or(|b| found.rank(preferred) > b.rank(preferred))
            {
                best = Some(found);
            }
            None
        },
        &stop_at,
    );
    match (outcome, best) {
        (Outcome::Exhausted, Some(b)) => Outcome::Partial(b),
        (o, _) => o,
    }
}

/// What [`sample_loop`] does with an accepted grasp (drawn at sample `at`):
/// `Some` ends the loop with that outcome.
type OnFound<'f> = dyn FnMut(Found, u32, &mut Counters) -> Option<Outcome> + 'f;

/// The samples of Algorithm 1 until `on_found` ends them, the sample index
/// reaches `stop_at`, or the budget is spent.
fn sample_loop(
    ctx: &SearchContext<'_>,
    (t, stage): (usize, &StageJoints),
    (nominal_palm, q_nominal): (&Isometry3<f64>, &[f64]),
    seed: u64,
    counters: &mut Counters,
    on_found: &mut OnFound<'_>,
    stop_at: &Cell<u32>,
) -> Outcome {
    let hand = ctx.hand;
    let p = ctx.params;
    let Some(mut sampler) = Sampler::new(ctx, (t, stage), (nominal_palm, q_nominal), seed) else {
        return Outcome::Exhausted;
    };
    let g = &hand.config.grasp_types[t];
    let links = LinkSets::for_type(hand, t, &stage.extra);
    let object = &ctx.object.collision;
    let mut fk = FkState::new(&hand.robot);
    let mut q = q_nominal.to_vec();
    let mut exact_ms = 0.0;
    let mut first_clear: Option<u32> = None;
    for s in 0..p.max_samples {
        if s >= stop_at.get() || (first_clear.is_none() && s >= p.stall_samples) {
            break;
        }
        if ctx.cancel.load(Ordering::Relaxed) {
            return Outcome::Cancelled;
        }
        if Instant::now() >= ctx.deadline {
            return Outcome::OutOfTime;
        }
        counters.samples += 1;
        let Some(palm) = sampler.draw(s, &mut q) else {
            counters.reject(0, None);
            continue;
        };
        hand.robot.forward_kinematics(&q, &mut fk);
        if let Some(why) = links.blocked(hand, &fk, object, ctx.env, false) {
            counters.reject(1, Some(why));
            continue;
        }
        first_clear.get_or_insert(s);
        let Some(mut contacts) = close_fingers(
            hand,
            t,
            &mut q,
            &mut fk,
            object,
            p.contact_distance,
            g.closing_step,
        ) else {
            counters.reject(2, None);
            continue;
        };
        if g.palm_contact {
            contacts.extend(palm_contact(hand, &fk, object, p.contact_distance));
        }
        let rule = StyleRule {
            style: g.style,
            palm_contact: g.palm_contact,
            palm: hand.palm,
            approach: palm.rotation * g.approach(),
        };
        if let Err(why) = style_check(&rule, &hold_contacts(&contacts)) {
            counters.reject(6, Some(why));
            continue;
        }
        if let Some(why) = links.blocked(hand, &fk, object, ctx.env, true) {
            counters.reject(3, Some(why));
            continue;
        }
        let closed = Closed {
            fk: &fk,
            links: &links,
            contacts: &contacts,
        };
        let Some(margin) = accept(ctx, &closed, counters, &mut exact_ms) else {
            continue;
        };
        let found = Found {
            q: q.clone(),
            palm,
            margin,
            exact_resists_weight: true,
            exact_ms,
            robustness: PoseRobustness::default(),
            hold_margin: 0.0,
            edge_distance: contacts
                .iter()
                .map(|c| ctx.object.edges.distance(&c.position))
                .fold(f64::INFINITY, f64::min),
            contacts,
        };
        if let Some(done) = on_found(found, s, counters) {
            return done;
        }
    }
    Outcome::Exhausted
}

/// A sample's closed hand: the posture, the stage's link sets, the contacts.
struct Closed<'a> {
    fk: &'a FkState,
    links: &'a LinkSets,
    contacts: &'a [FingerContact],
}

/// The force tests of a closed hand: its ellipsoid margin (eq. (10)) when
/// it is accepted, `None` (the rejection counted) otherwise. The margin
/// ranks and, with the paper's rule ([`SearchParams::paper_rule`], a
/// request that sets δf), must reach δf; otherwise the ellipsoid, an inner
/// approximation, decides nothing. A certificate of an earlier sample may
/// rule the sample out (cheap: it cannot hold its weight); then the
/// guarantees of a returned grasp, on the final posture; then the exact
/// weight program and the kit's hold test (closure and the disturbance set
/// with the joints' torques), the costliest tests (their time is added to
/// `exact_ms`).
fn accept(
    ctx: &SearchContext<'_>,
    closed: &Closed<'_>,
    counters: &mut Counters,
    exact_ms: &mut f64,
) -> Option<f64> {
    let p = ctx.params;
    let Some((margin, grasp)) = ellipsoid_margin(ctx.object, closed.contacts) else {
        counters.reject(4, None);
        return None;
    };
    if counters.best_margin.is_none_or(|b| margin > b) {
        counters.best_margin = Some(margin);
    }
    if margin < p.delta_f && p.paper_rule {
        counters.reject(4, None);
        return None;
    }
    if counters.hints.rule_out(ctx.object, &grasp, 1.0) {
        counters.reject(4, None);
        return None;
    }
    let (hand, object) = (ctx.hand, &ctx.object.collision);
    if let Err(r) = check_grasp(
        hand,
        closed.fk,
        &closed.links.moving,
        object,
        ctx.env,
        closed.contacts,
    ) {
        counters.reject(5, Some(r.label(&hand.robot)));
        return None;
    }
    let t_exact = Instant::now();
    let exact = match exact_resists(ctx.object, &grasp, 1.0, &mut counters.hints) {
        true => holds(ctx, closed),
        false => Err(String::new()),
    };
    *exact_ms += t_exact.elapsed().as_secs_f64() * 1e3;
    if let Err(why) = exact {
        counters.reject(
            if why.starts_with("too compliant") {
                8
            } else {
                4
            },
            None,
        );
        return None;
    }
    Some(margin)
}

/// The palm as a contact when it is within `threshold` of the object: the
/// nearest point on the object, the palm's push as the inward normal.
fn palm_contact(
    hand: &HandModel,
    fk: &FkState,
    object: &CollisionObject,
    threshold: f64,
) -> Option<FingerContact> {
    let p = hand
        .collision
        .link_object_proximity(fk, hand.palm, object, threshold)?;
    (p.distance >= -PENETRATION_TOLERANCE && p.distance < threshold).then(|| FingerContact {
        link: hand.palm,
        position: p.point_on_object,
        normal: -p.normal.into_inner(),
        f_max: hand.max_finger_force,
        distance: p.distance,
    })
}

/// The contacts as the kit's hold and style rules take them.
fn hold_contacts(contacts: &[FingerContact]) -> Vec<HoldContact> {
    contacts
        .iter()
        .map(|c| (c.link, c.position, c.normal))
        .collect()
}

/// The kit's hold problem of the hand at posture `fk`.
fn hold_problem<'a>(ctx: &'a SearchContext<'_>, fk: &'a FkState) -> HoldProblem<'a> {
    let (hand, object) = (ctx.hand, ctx.object);
    HoldProblem {
        model: &hand.robot,
        fk,
        joints: &hand.hand_joints,
        cap: hand.max_finger_force,
        mass: object.mass,
        mu: object.mu,
        com: object.center_of_mass,
        length: object.characteristic_length,
        servo_saturation: hand.servo_saturation,
    }
}

/// The kit's hold test on a closed hand (the rule the verification applies).
fn holds(ctx: &SearchContext<'_>, closed: &Closed<'_>) -> Result<(), String> {
    let problem = hold_problem(ctx, closed.fk);
    holds_under(&problem, &hold_contacts(closed.contacts), &ctx.params.hold).map(|_| ())
}

/// The samples of Algorithm 1 around one nominal pose: Δp_p (the palm),
/// Δp_s (the shoulder height, in the squat stage) and Δa_i (the fingers'
/// pre-shape), drawn in that order from one ChaCha8 generator.
struct Sampler<'a> {
    ctx: &'a SearchContext<'a>,
    t: usize,
    rng: ChaCha8Rng,
    ik: IkSolver<'a>,
    /// The squat joint and the IK over the stage's other joints.
    squat: Option<(JointId, IkSolver<'a>)>,
    nominal_palm: &'a Isometry3<f64>,
    q_nominal: &'a [f64],
}

impl<'a> Sampler<'a> {
    fn new(
        ctx: &'a SearchContext<'a>,
        (t, stage): (usize, &StageJoints),
        (nominal_palm, q_nominal): (&'a Isometry3<f64>, &'a [f64]),
        seed: u64,
    ) -> Option<Self> {
        let robot = &ctx.hand.robot;
        let palm = ctx.hand.palm;
        let ik_opts = IkOptions {
            max_attempts: 2,
            max_iterations: 40,
            position_tolerance: 1e-4,
            orientation_tolerance: 1e-3,
            seed,
            ..IkOptions::default()
        };
        let sel = JointSelection::new(robot, &stage.joints).ok()?;
        let ik = IkSolver::new(robot, palm, sel, ik_opts.clone()).ok()?;
        // In the squat stage, Δp_s fixes the squat joint and IK uses the rest.
        let squat = (stage.stage == Stage::Squat)
            .then_some(ctx.hand.squat)
            .flatten()
            .and_then(|s| {
                let joints: Vec<_> = stage.joints.iter().copied().filter(|&j| j != s).collect();
                let sel = JointSelection::new(robot, &joints).ok()?;
                Some((s, IkSolver::new(robot, palm, sel, ik_opts).ok()?))
            });
        Some(Self {
            ctx,
            t,
            rng: ChaCha8Rng::seed_from_u64(seed),
            ik,
            squat,
            nominal_palm,
            q_nominal,
        })
    }

    /// Sample `s` (the first is the nominal pose itself): its palm pose,
    /// with its posture in `q`; `None` when the IK has no solution.
    fn draw(&mut self, s: u32, q: &mut [f64]) -> Option<Isometry3<f64>> {
        let (p, robot) = (self.ctx.params, &self.ctx.hand.robot);
        let nominal = self.nominal_palm;
        // Δp_p: the OCP's offset w.r.t. the GRC moves the palm by −Δp_p.
        let palm = if s == 0 {
            *nominal
        } else {
            let rng = &mut self.rng;
            let mut d = Vector3::new(
                rng.random_range(-p.palm_offset..=p.palm_offset),
                rng.random_range(-p.palm_offset..=p.palm_offset),
                rng.random_range(-p.palm_offset..=p.palm_offset),
            );
            let approach = self.ctx.hand.config.grasp_types[self.t].approach();
            let along = d.dot(&approach);
            d += approach * (along.clamp(-p.approach_offset, p.approach_offset) - along);
            Isometry3::from_parts(
                Translation3::from(nominal.translation.vector - nominal.rotation * d),
                nominal.rotation,
            )
        };
        // Δp_s: the shoulder height, only where squatting is allowed.
        q.copy_from_slice(self.q_nominal);
        let sol = match self.squat.as_mut() {
            Some((sj, solver)) if s > 0 => {
                let l = &robot.joints[*sj].limits;
                q[*sj] = (self.q_nominal[*sj]
                    + self.rng.random_range(p.squat_offset.0..=p.squat_offset.1))
                .clamp(l.lower, l.upper);
                solver.solve(&palm, true, q, Some(self.q_nominal))
            }
            _ => self.ik.solve(&palm, true, q, Some(self.q_nominal)),
        };
        if !sol.ok {
            return None;
        }
        let (palm, sol) = match self.lay_on_palm(&palm, &sol.q, q) {
            Some(laid) => laid,
            None => (palm, sol),
        };
        // The nominal's hand posture (the reference posture, or its
        // pre-flexed form, `crate::clearance`) + Δa_i.
        q.copy_from_slice(&sol.q);
        if s > 0 {
            for c in &self.ctx.hand.types[self.t].contacts {
                for &j in &c.perturb {
                    let l = &robot.joints[j].limits;
                    q[j] = (q[j] + self.rng.random_range(-p.finger_offset..=p.finger_offset))
                        .clamp(l.lower, l.upper);
                }
            }
            robot.apply_mimics(q);
        }
        Some(palm)
    }
}

impl Sampler<'_> {
    /// For a palm-contact grasp type: the palm moved along the approach until
    /// it is [`PALM_GAP`] from the object, and the IK solution there (warm
    /// started from `q_sol`); `None` for other types, a palm out of reach of
    /// the object (3 cm), or no IK solution.
    fn lay_on_palm(
        &mut self,
        palm: &Isometry3<f64>,
        q_sol: &[f64],
        q: &mut [f64],
    ) -> Option<(Isometry3<f64>, tsukami_body::ik::IkSolution)> {
        let hand = self.ctx.hand;
        let g = &hand.config.grasp_types[self.t];
        if !g.palm_contact {
            return None;
        }
        let mut fk = FkState::new(&hand.robot);
        hand.robot.forward_kinematics(q_sol, &mut fk);
        let object = &self.ctx.object.collision;
        let p = hand
            .collision
            .link_object_proximity(&fk, hand.palm, object, 0.03)?;
        let a = palm.rotation * g.approach();
        // The palm moves along the approach; the gap closes by the part of
        // the move along the separating normal.
        let along = p.normal.dot(&-a).max(0.3);
        let shift = (p.distance - PALM_GAP) / along;
        let moved = Isometry3::from_parts(
            Translation3::from(palm.translation.vector + a * shift),
            palm.rotation,
        );
        q.copy_from_slice(q_sol);
        let sol = self.ik.solve(&moved, true, q, Some(self.q_nominal));
        sol.ok.then_some((moved, sol))
    }
}

/// The grasp of `contacts` on `object` (torques about the centre of mass).
pub fn make_grasp(object: &PlanObject, contacts: &[FingerContact]) -> Option<Grasp> {
    let cs = contacts
        .iter()
        .map(|c| Contact::new(c.position, c.normal).ok())
        .collect::<Option<Vec<_>>>()?;
    let limits = vec![hand_force_limit(contacts); contacts.len()];
    Grasp::with_force_limits(
        cs,
        limits,
        object.mu,
        object.characteristic_length,
        object.center_of_mass,
    )
    .ok()
}

/// The paper's single "maximum finger force" of the hand, applied to every
/// contact: the weakest finger's `f_max` (N). Replies state it
/// (`ForceClosureReply::force_limit`) so a checker can recompute the tests.
pub fn hand_force_limit(contacts: &[FingerContact]) -> f64 {
    contacts
        .iter()
        .map(|c| c.f_max)
        .fold(f64::INFINITY, f64::min)
        .max(1e-6)
}

/// Eq. (10) margin `n − f(p1..pn)` for the object's weight.
pub fn ellipsoid_margin(object: &PlanObject, contacts: &[FingerContact]) -> Option<(f64, Grasp)> {
    let grasp = make_grasp(object, contacts)?;
    let weight = grasp.weight_wrench(object.mass, &GRAVITY, &object.center_of_mass);
    let test = ellipsoid_test(&grasp, &EllipsoidModel::default(), &weight);
    if test.degenerate || !test.margin().is_finite() {
        return None;
    }
    Some((test.margin(), grasp))
}

/// The exact test: the contacts, within circular friction cones and their
/// force limits, balance `safety` times the weight; with `safety > 1` the
/// grasp must be in force closure as well. A sample that one of `hints`'
/// certificates already bounds below the scale it needs is refused without
/// a program (the bound is exact weak duality: it never refuses one the
/// program would accept); every program solved adds its certificate.
pub fn exact_resists(
    object: &PlanObject,
    grasp: &Grasp,
    safety: f64,
    hints: &mut WeightHints,
) -> bool {
    if hints.rule_out(object, grasp, safety) {
        return false;
    }
    // The weight program first: most samples that fail, fail it, and the
    // closure program is then not solved.
    let weight = grasp.weight_wrench(object.mass, &GRAVITY, &object.center_of_mass);
    let Ok(w) = exact_weight_scale(grasp, ConeModel::Circular, &weight) else {
        return false;
    };
    hints.add(w.certificate);
    w.weight_scale >= safety.max(1.0)
        && (safety <= 1.0
            || exact_force_closure(grasp, ConeModel::Circular).is_ok_and(|c| c.force_closure))
}

/// The weight program's certificates of one plan (the latest
/// [`WeightHints::KEEP`]): nearby samples share their limiting directions.
#[derive(Debug, Clone, Default)]
pub struct WeightHints {
    certificates: Vec<Wrench>,
}

impl WeightHints {
    /// Certificates kept.
    pub const KEEP: usize = 16;

    /// Whether a certificate bounds the weight scale of `grasp` on `object`
    /// below `safety` (at least 1): the weight program would refuse it.
    /// A relative 1e-9 is left for the solver's rounding.
    pub fn rule_out(&self, object: &PlanObject, grasp: &Grasp, safety: f64) -> bool {
        if self.certificates.is_empty() {
            return false;
        }
        let weight = grasp.weight_wrench(object.mass, &GRAVITY, &object.center_of_mass);
        let bound = self
            .certificates
            .iter()
            .map(|y| weight_scale_bound(grasp, &weight, y))
            .fold(f64::INFINITY, f64::min);
        bound * (1.0 + 1e-9) < safety.max(1.0)
    }

    fn add(&mut self, y: Wrench) {
        if self.certificates.len() == Self::KEEP {
            self.certificates.remove(0);
        }
        self.certificates.push(y);
    }
}

/// Contact point helper for replies.
pub fn to_array(p: &Point3<f64>) -> [f64; 3] {
    [p.x, p.y, p.z]
}
