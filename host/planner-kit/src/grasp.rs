//! What a planner returns, and the reply the kit builds from it.
//!
//! What: [`Grasp`] — the grasp type, region and face, the full joint
//! configuration, the joints the stage moved, the finger contacts; and
//! [`reply`], which turns a verified grasp into the `PlanReply` of the
//! protocol (palm pose by forward kinematics, joint map, contacts, object,
//! force-closure verdicts, counts, timing, world version).
//!
//! Why: the reply's field contract (issue #5) is kept in one place for every
//! planner; a planner returns plain values in ids and the kit names them.

use std::collections::BTreeMap;

use nalgebra::{Point3, Vector3};
use tsukami_body::kinematics::FkState;
use tsukami_body::model::{JointId, LinkId};
use tsukami_msgs::planner::{
    BoxFace, ContactReply, FaceTilt, ForceClosureReply, GraspTypeRef, HoldCompliance, ObjectMass,
    PhaseTiming, PlanReply,
};

use crate::planner::{GraspPlanner, World};
use crate::validate::to_pose;
use crate::verify::Verdict;

/// One finger contact, world frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FingerContact {
    /// The touching link.
    pub link: LinkId,
    /// Contact point on the object's surface.
    pub position: Point3<f64>,
    /// Unit normal pointing into the object.
    pub normal: Vector3<f64>,
    /// Largest normal force the finger can apply there, N.
    pub f_max: f64,
}

/// A planned grasp, as a planner returns it.
#[derive(Debug, Clone, PartialEq)]
pub struct Grasp {
    /// Grasp type used.
    pub grasp_type: GraspTypeRef,
    /// Region (OCP) grasped.
    pub region: usize,
    /// Face of that region the hand approached.
    pub face: BoxFace,
    /// The approach's turn from the face's normal, if any.
    pub tilt: Option<FaceTilt>,
    /// The whole configuration (every joint of the model).
    pub q: Vec<f64>,
    /// Joints the stage moved (arm and extra joints); hand joints are added.
    pub joints: Vec<JointId>,
    /// Joints beyond the arm.
    pub extra: Vec<JointId>,
    /// Finger contacts.
    pub contacts: Vec<FingerContact>,
    /// The planner's characteristic length for wrenches, if it has its own
    /// (default: the object's largest box edge).
    pub characteristic_length: Option<f64>,
}

impl Grasp {
    /// A grasp of region 0 made on `stage` (its joints; the extra ones as
    /// `joints_used`), with the planner's characteristic length.
    pub fn on_stage(
        grasp_type: GraspTypeRef,
        face: BoxFace,
        stage: &crate::robot::Stage,
        q: Vec<f64>,
        contacts: Vec<FingerContact>,
        characteristic_length: f64,
    ) -> Self {
        Grasp {
            grasp_type,
            region: 0,
            face,
            tilt: None,
            q,
            joints: stage.joints.clone(),
            extra: stage.extra.clone(),
            contacts,
            characteristic_length: Some(characteristic_length),
        }
    }
}

/// Timing, types tried, samples of the run.
pub struct RunReport {
    /// Phase times.
    pub timing: PhaseTiming,
    /// Grasp types tried.
    pub tried: Vec<String>,
    /// Samples drawn.
    pub samples: u32,
}

/// The reply for `grasp`, which passed verification with `verdict`.
pub fn reply<P: GraspPlanner>(
    world: &World<'_, P>,
    grasp: &Grasp,
    verdict: &Verdict,
    run: RunReport,
) -> PlanReply {
    let robot = world.robot;
    let model = &robot.model;
    let hand = world.hand();
    let mut fk = FkState::new(model);
    model.forward_kinematics(&grasp.q, &mut fk);
    let mut joint_positions = BTreeMap::new();
    for &j in &grasp.joints {
        joint_positions.insert(model.joints[j].name.clone(), grasp.q[j]);
    }
    for (j, joint) in model.joints.iter().enumerate() {
        if joint.is_movable() && hand.links.contains(&joint.child) {
            joint_positions.insert(joint.name.clone(), grasp.q[j]);
        }
    }
    let object = world.object;
    PlanReply {
        grasp_type: grasp.grasp_type.clone(),
        ocp_region: grasp.region,
        face: grasp.face,
        tilt: grasp.tilt,
        palm_pose: to_pose(fk.pose(hand.palm)),
        joint_positions,
        joints_used: robot.names(&grasp.extra),
        contacts: grasp
            .contacts
            .iter()
            .map(|c| ContactReply {
                link: model.links[c.link].name.clone(),
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
        characteristic_length: verdict.characteristic_length,
        force_closure: ForceClosureReply {
            margin: verdict.margin,
            exact_resists_weight: verdict.exact_resists_weight,
            force_limit: verdict.force_limit,
            force_closure: verdict.force_closure,
            hold_margin: verdict.hold_margin,
            disturbances: verdict.disturbances,
            robustness: verdict.robustness,
            compliance: verdict.compliance.map(|(t, s)| HoldCompliance {
                turn_deg: t.to_degrees(),
                shift_mm: s * 1e3,
                friction_use: verdict
                    .passive
                    .map(|p| p.friction_use)
                    .filter(|u| u.is_finite()),
                torque_use: verdict.passive.map(|p| p.torque_use),
            }),
        },
        squeeze: verdict.squeeze.clone(),
        samples: run.samples,
        timing_ms: run.timing,
        candidates_tried: run.tried,
        world_version: world.version,
    }
}
