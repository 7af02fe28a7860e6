//! The outcomes the paper reports for its scenes, as checks on a Plan reply.
//!
//! One table serves the planner's in-process tests, the end-to-end tests over the
//! bus and `tsukami demo`, so "what the paper says" is written once. Every check
//! also runs the independent grasp check ([`crate::verify`]) with its default
//! tolerances: the paper's outcome counts only for a grasp that really holds.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use tsukami_msgs::planner::{GraspStyle, PlanReply};

use crate::verify::{verify, Tolerances, Verdict};
use crate::world::World;

/// What the paper reports for one scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperScene {
    /// The scene file's stem under `models/scenes/`.
    pub name: &'static str,
    /// The outcome in words (the demo prints it).
    pub expected: &'static str,
    /// The grasp style the paper reports, if it names one.
    pub style: Option<GraspStyle>,
    /// Where the palm approaches from.
    pub approach: Approach,
    /// Whether squatting must be used.
    pub squat: Requirement,
    /// Whether a plan with the arm alone must fail.
    pub arm_alone_fails: bool,
    /// The least number of OCP regions the object splits into.
    pub min_regions: usize,
}

/// Where the palm approaches the object from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Approach {
    /// The palm normal is horizontal (within ~11°).
    Side,
    /// The palm normal points down (within ~25°).
    Top,
    /// Not reported.
    Any,
}

/// Whether a joint group must, must not, or may be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Requirement {
    /// Must be in `joints_used`.
    Required,
    /// Must not be.
    Forbidden,
    /// Either way.
    Any,
}

/// The virtual squat joint's name in the project's humanoid.
pub const SQUAT_JOINT: &str = "squat_z";

/// The paper's scenes (section 4), in the order the demo runs them.
pub const PAPER_SCENES: [PaperScene; 5] = [
    PaperScene {
        name: "can_breast",
        expected: "4-finger fingertip on the side, arm only",
        style: Some(GraspStyle::Fingertip4),
        approach: Approach::Side,
        squat: Requirement::Forbidden,
        arm_alone_fails: false,
        min_regions: 1,
    },
    PaperScene {
        name: "can_waist",
        expected: "3-finger fingertip from the top",
        style: Some(GraspStyle::Fingertip3),
        approach: Approach::Top,
        squat: Requirement::Forbidden,
        arm_alone_fails: false,
        min_regions: 1,
    },
    PaperScene {
        name: "heavy_low",
        expected: "4-finger envelope with squatting",
        style: Some(GraspStyle::Envelope4),
        approach: Approach::Any,
        squat: Requirement::Required,
        arm_alone_fails: false,
        min_regions: 1,
    },
    PaperScene {
        name: "fridge_pet",
        expected: "arm alone fails, squatting succeeds",
        style: None,
        approach: Approach::Any,
        squat: Requirement::Required,
        arm_alone_fails: true,
        min_regions: 1,
    },
    PaperScene {
        name: "vase_table",
        expected: "split into 3 regions (lip, neck, body), a grasp on one",
        style: None,
        approach: Approach::Any,
        squat: Requirement::Any,
        arm_alone_fails: false,
        min_regions: 3,
    },
];

/// The paper scene called `name`.
pub fn paper_scene(name: &str) -> Option<&'static PaperScene> {
    PAPER_SCENES.iter().find(|s| s.name == name)
}

/// The palm's approach direction (its +z axis) in the world.
pub fn approach_direction(reply: &PlanReply) -> Vector3<f64> {
    let [x, y, z, w] = reply.palm_pose.quaternion;
    UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)) * Vector3::z()
}

impl PaperScene {
    /// Checks a Plan reply (and the object's region count) against the paper, and
    /// the reply's grasp against `world` ([`verify`], default tolerances: force
    /// closure recomputed, contacts on the surface, no link more than 1 mm deep in
    /// anything, joint limits, `joints_used`); the error says what differs.
    pub fn check(&self, world: &World, reply: &PlanReply, regions: usize) -> Result<(), String> {
        self.judge(
            reply,
            regions,
            &verify(world, reply, &Tolerances::default()),
        )
    }

    /// [`PaperScene::check`] with the grasp check already run (`verdict`).
    pub fn judge(
        &self,
        reply: &PlanReply,
        regions: usize,
        verdict: &Verdict,
    ) -> Result<(), String> {
        self.check_outcome(reply, regions)?;
        if !verdict.is_ok() {
            return Err(format!("the grasp does not hold up: {verdict}"));
        }
        Ok(())
    }

    /// The paper's outcome alone: grasp style, approach, squat and region count.
    pub fn check_outcome(&self, reply: &PlanReply, regions: usize) -> Result<(), String> {
        if let Some(style) = self.style {
            if reply.grasp_type.style != style {
                return Err(format!(
                    "grasp style {:?}, the paper reports {:?}",
                    reply.grasp_type.style, style
                ));
            }
        }
        let approach = approach_direction(reply);
        match self.approach {
            Approach::Side if approach.z.abs() > 0.2 => {
                return Err(format!("approach {approach:?} is not from the side"));
            }
            Approach::Top if approach.z > -0.9 => {
                return Err(format!("approach {approach:?} is not from the top"));
            }
            _ => {}
        }
        let squats = reply.joints_used.iter().any(|j| j == SQUAT_JOINT);
        match self.squat {
            Requirement::Required if !squats => {
                return Err(format!("no squat; joints used {:?}", reply.joints_used))
            }
            Requirement::Forbidden if !reply.joints_used.is_empty() => {
                return Err(format!(
                    "arm only expected; joints used {:?}",
                    reply.joints_used
                ));
            }
            _ => {}
        }
        if regions < self.min_regions {
            return Err(format!(
                "{regions} OCP region(s); the paper splits it into >= {}",
                self.min_regions
            ));
        }
        Ok(())
    }
}
