//! The antipodal search, as a `GraspPlanner` of the planner kit.
//!
//! For each whole-body stage the request allows, up to `max_samples` times:
//! 1. **pair** — an antipodal pair on the object ([`crate::antipodal`]),
//!    friction half-angle `½·atan μ`;
//! 2. **palm pose** — the pre-shape whose gap fits the pair ([`crate::pinch`]),
//!    the palm turned so the thumb-pad → finger-pad line lies on the pair and
//!    the palm faces the object from the shoulder's side;
//! 3. **IK** of the stage's joints (kit block `stages`);
//! 4. **collisions** — arm and hand clear of the obstacles and, before closing,
//!    of the object (kit block `collision`);
//! 5. **closing** — each pinching finger flexes until it touches (kit block
//!    `closing`), then obstacles and self-collision again;
//! 6. **holding** — accepted when the kit's hold test passes (kit
//!    `verify::holds`: exact force closure and the request's disturbances
//!    within the joints' torques, `PlanOptions::hold`);
//! 7. **motion** — the approach, closing and lift the grasp implies are free
//!    (kit `Run::motion_phases`, the trajectory planner's own checks).
//!
//! Each failed step names its reason (`run.reject`), which the kit reports.
//! `palm_criterion`, `delta_f` and `max_candidates` belong to the paper's
//! planner and are not used here.

use std::f64::consts::TAU;

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::JointId;
use tsukami_msgs::planner::{GraspSize, GraspStyle, GraspTypeRef, PlanOptions, PlanPhase};
use tsukami_planner_kit::blocks::collision::{arm_and_hand, first_failure, Pass};
use tsukami_planner_kit::blocks::stages::{palm_ik, stage_solver, StageSolver};
use tsukami_planner_kit::blocks::{closing, grasp_check, surface};
use tsukami_planner_kit::{verify, FingerContact, Grasp, GraspPlanner, KitError, NoGrasp, Object};
use tsukami_planner_kit::{PlannerConfig, PlannerInfo, Robot, Run, World};

use crate::antipodal::sample_pair;
use crate::pinch::Pinch;

/// Free space left on each side of the object when the hand opens, m.
const CLEARANCE: f64 = 0.008;
/// Palm rotations about the pinch line considered per pair.
const ROLLS: usize = 12;

/// The antipodal pinch planner.
pub struct Antipodal;

/// What one sample works with.
struct Sample<'a, 'w> {
    w: &'a World<'w, Antipodal>,
    fk: FkState,
    rest: Vec<f64>,
    shoulder: Vector3<f64>,
    rng: ChaCha8Rng,
    hold: tsukami_msgs::planner::HoldRequest,
}

/// Size class from the object's middle box extent (its usual pinch width).
fn size_class(object: &Object) -> GraspSize {
    let mut e: Vec<f64> = object.extents().iter().copied().collect();
    e.sort_by(f64::total_cmp);
    match e[1] {
        w if w < 0.045 => GraspSize::Small,
        w if w < 0.085 => GraspSize::Mid,
        _ => GraspSize::Large,
    }
}

/// What `tsukami plugins` shows for this planner.
const INFO: PlannerInfo = PlannerInfo {
    name: "tsukami-antipodal-planner",
    version: env!("CARGO_PKG_VERSION"),
    description: "example planner: antipodal fingertip pinch, whole-body IK",
};

impl GraspPlanner for Antipodal {
    type RobotData = Pinch;
    type ObjectData = Vec<f64>;

    fn info() -> PlannerInfo {
        INFO
    }

    fn new(_config: &PlannerConfig) -> Result<Self, String> {
        Ok(Antipodal)
    }

    fn robot_data(&self, robot: &Robot) -> Result<Pinch, KitError> {
        Pinch::new(robot)
    }

    fn object_data(&self, object: &Object) -> Result<Vec<f64>, KitError> {
        Ok(surface::cumulative_areas(&object.mesh))
    }

    fn plan(&self, w: &World<'_, Self>, o: &PlanOptions, run: &mut Run) -> Result<Grasp, NoGrasp> {
        let size = size_class(w.object);
        let gt = GraspTypeRef {
            name: format!("fingertip3_{}", size.as_str()),
            style: GraspStyle::Fingertip3,
            size,
        };
        let (robot, hand) = (w.robot, w.hand());
        let rest = robot.model.rest_positions();
        let mut fk = FkState::new(&robot.model);
        robot.model.forward_kinematics(&rest, &mut fk);
        let shoulder = fk
            .pose(robot.model.joints[hand.arm[0]].child)
            .translation
            .vector;
        let rng = ChaCha8Rng::seed_from_u64(o.seed);
        let mut s = Sample {
            w,
            fk,
            rest,
            shoulder,
            rng,
            hold: o.hold,
        };
        let stages = robot.stages(hand, o.whole_body);
        for (si, stage) in stages.iter().enumerate() {
            run.tried(&gt.name);
            run.phase(
                PlanPhase::Search,
                Some(&gt.name),
                &robot.names(&stage.extra),
            );
            let Some(mut ik) = stage_solver(
                robot,
                hand,
                stage,
                palm_ik(2, o.seed.wrapping_add(si as u64)),
            ) else {
                continue;
            };
            for k in 0..o.max_samples {
                run.sample()?;
                if k % 16 == 15 {
                    run.report();
                }
                match s.attempt(&mut ik) {
                    Ok((q, contacts, length, approach)) => {
                        let face = w.object.face_toward(&approach);
                        let g = Grasp::on_stage(gt.clone(), face, stage, q, contacts, length);
                        // Step 7: the approach, closing and lift it implies
                        // are free (the kit's, the trajectory planner's checks).
                        match run.motion_phases(w, &g) {
                            Ok(()) => return Ok(g),
                            Err(_) => run.reject("approach, closing or lift blocked"),
                        }
                    }
                    Err(why) => run.reject(why),
                }
            }
        }
        Err(NoGrasp::Exhausted)
    }
}

/// Steps 3–6 give the grasp: configuration, contacts, the characteristic
/// length used, the palm's approach direction.
type Found = (Vec<f64>, Vec<FingerContact>, f64, Vector3<f64>);

impl Sample<'_, '_> {
    /// One sample, steps 1–6; the reason it failed otherwise.
    fn attempt(&mut self, ik: &mut StageSolver<'_>) -> Result<Found, &'static str> {
        let (w, hand) = (self.w, self.w.hand());
        let (palm, hand_q) = self.palm_pose()?;
        let mut start = self.rest.clone();
        hand_q.iter().for_each(|&(j, v)| start[j] = v);
        let mut q = ik
            .reach(&palm, &start, &self.rest)
            .ok_or("palm pose out of reach")?;
        let (links, object) = (arm_and_hand(hand), [&w.object.collision]);
        w.robot.model.forward_kinematics(&q, &mut self.fk);
        let before = [
            Pass::clear(&links, &w.obstacles, "arm or hand hits an obstacle"),
            Pass::clear(&links, &object, "hand hits the object before closing"),
        ];
        first_failure(hand, &self.fk, &before).map_or(Ok(()), Err)?;
        let fingers = &w.robot_data.fingers;
        let contacts =
            closing::close_fingers(w.robot, hand, fingers, &mut q, &mut self.fk, object[0])
                .ok_or("a finger closes without touching")?;
        w.robot.model.forward_kinematics(&q, &mut self.fk);
        let after = [
            Pass::clear(&hand.links, &w.obstacles, "closed fingers hit an obstacle"),
            Pass::SelfCollision,
        ];
        first_failure(hand, &self.fk, &after).map_or(Ok(()), Err)?;
        // The kit's guarantees (no link 1 mm in, contacts on the surface with
        // agreeing normals): a sample that fails them is not returned.
        grasp_check::check_in(w, &self.fk, &links, &contacts)
            .map_err(|_| "fails the grasp check")?;
        let length = w.object.characteristic_length();
        let v = verify::force_closure(w.object, &contacts, length).ok_or("degenerate contacts")?;
        if !v.exact_resists_weight {
            return Err("contacts cannot resist the weight");
        }
        verify::holds(w, &self.fk, &contacts, length, &self.hold)
            .map_err(|_| "contacts cannot hold the disturbances")?;
        Ok((
            q,
            contacts,
            length,
            self.fk.pose(hand.palm).rotation * Vector3::z(),
        ))
    }

    /// Steps 1–2: an antipodal pair and the palm pose (with its pre-shape) that pinches it.
    fn palm_pose(&mut self) -> Result<(Isometry3<f64>, Vec<(JointId, f64)>), &'static str> {
        let (object, rng) = (self.w.object, &mut self.rng);
        let half_angle = 0.5 * object.mu.atan();
        let pair = sample_pair(&object.mesh, self.w.object_data, half_angle, rng)
            .ok_or("no antipodal partner")?;
        let pre = (self
            .w
            .robot_data
            .preshape_for(pair.width() + 2.0 * CLEARANCE))
        .ok_or("wider than the hand opens")?;
        let (a, b) = (object.pose * pair.a, object.pose * pair.b);
        let (thumb_at, fingers_at) = if rng.random::<bool>() { (a, b) } else { (b, a) };
        let axis = Unit::new_normalize(fingers_at - thumb_at);
        let align = UnitQuaternion::rotation_between(&(pre.fingers - pre.thumb), &axis)
            .unwrap_or_else(|| {
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
            });
        let centre = nalgebra::center(&thumb_at, &fingers_at);
        let reach = (centre.coords - self.shoulder).normalize();
        // Rolls about the pinch line, scored by how well the palm faces the
        // object from the shoulder's side and not from below.
        let mut rolls: Vec<(f64, UnitQuaternion<f64>)> = (0..ROLLS)
            .map(|k| UnitQuaternion::from_axis_angle(&axis, k as f64 * TAU / ROLLS as f64) * align)
            .map(|r| {
                (
                    (r * Vector3::z()).dot(&reach) - (r * Vector3::z()).z.max(0.0),
                    r,
                )
            })
            .collect();
        rolls.sort_by(|x, y| y.0.total_cmp(&x.0));
        let (score, rotation) = rolls[rng.random_range(0..3)];
        if score < 0.0 {
            return Err("palm would face away from the shoulder");
        }
        let pads = nalgebra::center(&pre.thumb, &pre.fingers);
        let palm = Isometry3::from_parts(
            Translation3::from(centre.coords - rotation * pads.coords),
            rotation,
        );
        Ok((palm, pre.q.clone()))
    }
}
