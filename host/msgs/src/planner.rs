//! Messages of the grasp planner role (`tsukami/planner/*`).
//!
//! What: the request and reply payloads of the planner's queryables —
//! [`SetRobot`], [`SetObject`], [`SetEnv`], [`RemoveEnv`], [`PlanOptions`] /
//! [`PlanReply`] — and the [`ProgressEvent`] it publishes while
//! planning.
//!
//! Why: the same JSON travels in-process (through the plugin boundary) and over
//! zenoh, so external tools (Python, the C client, the `tsukami demo`) rely on
//! these field names. [`PlanReply`] carries the field contract of issue #5;
//! fields may be added but never renamed.
//!
//! How: every request derives `Deserialize` with `deny_unknown_fields` so a typo
//! in a field name is an error rather than a silently ignored option; every type
//! derives [`schemars::JsonSchema`] so the schema can be published. Units are SI
//! (metres, kilograms, radians, newtons); poses are in the world frame, which is
//! the robot's `base_link` frame (on the floor between the feet, x forward, y
//! left, z up); quaternions are `[x, y, z, w]`.
//!
//! ```
//! use tsukami_msgs::planner::{PlanOptions, SetObject};
//! let req: SetObject = serde_json::from_str(
//!     r#"{"shape": {"model": {"name": "can_350ml"}}, "mass": 0.15,
//!         "pose": {"position": [0.45, -0.2, 1.05], "quaternion": [0, 0, 0, 1]}}"#,
//! ).unwrap();
//! assert_eq!(req.mass, 0.15);
//! let opts: PlanOptions = serde_json::from_str(r#"{"seed": 7}"#).unwrap();
//! assert_eq!(opts.seed, 7);
//! assert!(serde_json::from_str::<PlanOptions>(r#"{"sed": 7}"#).is_err());
//! // A mesh sent inline (a client on another machine): base64 of the file's bytes.
//! let inline: SetObject = serde_json::from_str(
//!     r#"{"shape": {"inline": {"format": "stl", "data_base64": "c29saWQgeAplbmRzb2xpZCB4Cg=="}},
//!         "mass": 0.2, "pose": {"position": [0.5, 0, 1], "quaternion": [0, 0, 0, 1]}}"#,
//! ).unwrap();
//! assert!(matches!(inline.shape, tsukami_msgs::planner::ObjectShape::Inline { .. }));
//! ```

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

pub use crate::common::Pose;

/// A pose at `position` with the identity orientation.
pub fn pose_at(position: [f64; 3]) -> Pose {
    Pose {
        position,
        quaternion: Pose::IDENTITY.quaternion,
    }
}

// ---------------------------------------------------------------------------
// set_robot
// ---------------------------------------------------------------------------

/// `tsukami/planner/set_robot`: load the robot model and its hand's grasp types.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SetRobot {
    /// Robot model: a URDF file path, or a robot name under `models/robots/`
    /// (e.g. `"tsukami_humanoid"`).
    pub robot: String,
    /// Grasp-type configuration file (TOML, see `docs/grasp-types.md`). Default:
    /// `grasp_types.toml` beside the URDF.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grasp_types: Option<String>,
    /// Extra folders where `package://PKG/...` mesh URIs are looked up, in
    /// order (step 4 of the search order in `docs/robots.md`). Each must be a
    /// folder inside the host's model roots; at most
    /// [`SetRobot::MAX_PACKAGE_DIRS`].
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub package_dirs: Vec<String>,
}

impl SetRobot {
    /// Most entries in [`SetRobot::package_dirs`].
    pub const MAX_PACKAGE_DIRS: usize = 16;
}

/// Reply to [`SetRobot`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct RobotSummary {
    /// Robot name from the URDF.
    pub name: String,
    /// Joints of the arm, shoulder to wrist.
    pub arm_joints: Vec<String>,
    /// Joints the whole-body fallback may add (waist, then squat).
    pub body_joints: Vec<String>,
    /// Actuated hand joints.
    pub hand_joints: Vec<String>,
    /// Names of the grasp types loaded from the configuration.
    pub grasp_types: Vec<String>,
    /// The world version this robot belongs to (see `docs/protocol.md`, "World").
    #[serde(default)]
    pub world_version: u64,
}

// ---------------------------------------------------------------------------
// set_object
// ---------------------------------------------------------------------------

/// Where the object's geometry comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ObjectShape {
    /// A triangle mesh file (STL, OBJ, PLY or Collada, by its extension), any
    /// object, seen before or not.
    Mesh {
        /// File path.
        path: String,
        /// Uniform scale applied to the file's coordinates (default 1; use 0.001 for millimetres).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        scale: Option<f64>,
    },
    /// An object model under `models/objects/` by name (e.g. `"can_350ml"`).
    Model {
        /// Model name.
        name: String,
    },
    /// A mesh sent in the request itself, for a client whose files are not on
    /// the host's disk (another machine, the vision PC). The decoded bytes may
    /// be at most the host's `max_mesh_bytes` (default 64 MiB; the request
    /// payload's `max_payload_bytes`, default 16 MiB, usually bounds it first:
    /// base64 is 4/3 of the bytes) and hold at most 2 000 000 triangles.
    Inline {
        /// The file format of the decoded bytes.
        format: MeshFormat,
        /// The mesh file's bytes, base64 (standard alphabet, `=` padding
        /// optional; line breaks are ignored).
        data_base64: String,
        /// Uniform scale applied to the mesh's coordinates (default 1; use 0.001 for millimetres).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        scale: Option<f64>,
    },
}

/// The file format of an inline mesh ([`ObjectShape::Inline`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum MeshFormat {
    /// STL, binary or ASCII.
    Stl,
    /// Wavefront OBJ (positions and faces; material libraries are not read).
    Obj,
    /// PLY (Stanford polygon format), ASCII or binary: vertex positions and
    /// faces (polygons are fan-triangulated); other properties and elements
    /// are skipped.
    Ply,
}

impl MeshFormat {
    /// Every format, in wire order.
    pub const ALL: [MeshFormat; 3] = [MeshFormat::Stl, MeshFormat::Obj, MeshFormat::Ply];

    /// The format's usual file extension (`"stl"`, `"obj"`, `"ply"`), which
    /// is also its name on the wire.
    pub fn extension(self) -> &'static str {
        match self {
            MeshFormat::Stl => "stl",
            MeshFormat::Obj => "obj",
            MeshFormat::Ply => "ply",
        }
    }

    /// The format a file extension names (case-insensitive), if any.
    pub fn from_extension(ext: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|f| ext.eq_ignore_ascii_case(f.extension()))
    }
}

/// `tsukami/planner/set_object`: the object to grasp.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SetObject {
    /// Display name (default: the model name or the file stem).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Geometry source.
    pub shape: ObjectShape,
    /// Mass in kg (must be > 0).
    pub mass: f64,
    /// Coulomb friction coefficient μ between fingers and object (default 0.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// Pose of the object's mesh frame in the world.
    pub pose: Pose,
    /// Centre of mass in the object's mesh frame (default: the centroid of the
    /// enclosed volume).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center_of_mass: Option<[f64; 3]>,
}

/// A face of an OCP box, named by the box-frame axis of its outward normal.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, JsonSchema,
)]
pub enum BoxFace {
    /// Normal +x.
    #[serde(rename = "+x")]
    PosX,
    /// Normal −x.
    #[serde(rename = "-x")]
    NegX,
    /// Normal +y.
    #[serde(rename = "+y")]
    PosY,
    /// Normal −y.
    #[serde(rename = "-y")]
    NegY,
    /// Normal +z.
    #[serde(rename = "+z")]
    PosZ,
    /// Normal −z.
    #[serde(rename = "-z")]
    NegZ,
}

impl BoxFace {
    /// All six faces in a fixed order.
    pub const ALL: [BoxFace; 6] = [
        BoxFace::PosX,
        BoxFace::NegX,
        BoxFace::PosY,
        BoxFace::NegY,
        BoxFace::PosZ,
        BoxFace::NegZ,
    ];

    /// Axis index (0 = x, 1 = y, 2 = z) of the face normal.
    pub fn axis(self) -> usize {
        match self {
            BoxFace::PosX | BoxFace::NegX => 0,
            BoxFace::PosY | BoxFace::NegY => 1,
            BoxFace::PosZ | BoxFace::NegZ => 2,
        }
    }

    /// Sign (+1 or −1) of the face normal along its axis.
    pub fn sign(self) -> f64 {
        match self {
            BoxFace::PosX | BoxFace::PosY | BoxFace::PosZ => 1.0,
            _ => -1.0,
        }
    }

    /// The face from an axis index and a sign.
    pub fn from_axis(axis: usize, positive: bool) -> BoxFace {
        match (axis, positive) {
            (0, true) => BoxFace::PosX,
            (0, false) => BoxFace::NegX,
            (1, true) => BoxFace::PosY,
            (1, false) => BoxFace::NegY,
            (_, true) => BoxFace::PosZ,
            (_, false) => BoxFace::NegZ,
        }
    }

    /// The name used on the wire (`"+x"`, `"-z"`, …).
    pub fn as_str(self) -> &'static str {
        match self {
            BoxFace::PosX => "+x",
            BoxFace::NegX => "-x",
            BoxFace::PosY => "+y",
            BoxFace::NegY => "-y",
            BoxFace::PosZ => "+z",
            BoxFace::NegZ => "-z",
        }
    }
}

/// Why a face of an OCP box cannot be approached.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum FaceBlock {
    /// The face rests on the support (table, shelf, floor) below it.
    Support,
    /// The face lies against another region of the same object.
    Region,
    /// An obstacle fills the space in front of the face (a wall behind a box,
    /// the table beside a lying bottle): no hand fits there.
    Obstacle,
}

/// One object convex polygon (OCP): an oriented box around one region of the object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct OcpBox {
    /// Region index (0-based, along the object's principal axis).
    pub region: usize,
    /// Box centre and orientation in the world frame.
    pub pose: Pose,
    /// Full edge lengths along the box axes, metres.
    pub extents: [f64; 3],
    /// Faces the hand may approach.
    pub free_faces: Vec<BoxFace>,
    /// Faces that are blocked, and why.
    pub blocked_faces: Vec<(BoxFace, FaceBlock)>,
}

/// Reply to [`SetObject`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ObjectSummary {
    /// Object name.
    pub name: String,
    /// Mass in kg.
    pub mass: f64,
    /// Centre of mass in the world frame.
    pub center_of_mass: [f64; 3],
    /// Triangle count of the mesh.
    pub triangles: usize,
    /// OCP boxes, one per region.
    pub regions: Vec<OcpBox>,
    /// The world version this object belongs to.
    #[serde(default)]
    pub world_version: u64,
    /// What was done to the mesh to plan on it, one sentence each: zero-area
    /// triangles dropped, non-manifold edges, triangles re-wound, an open mesh's
    /// fallback (inside test and centre of mass). Empty for a tidy closed mesh.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

// ---------------------------------------------------------------------------
// set_env / remove_env
// ---------------------------------------------------------------------------

/// Geometry of an obstacle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ObstacleShape {
    /// A box with full edge lengths `size`, centred on the obstacle pose.
    Box {
        /// Full edge lengths in metres.
        size: [f64; 3],
    },
    /// A cylinder along its local z, centred on the obstacle pose.
    Cylinder {
        /// Radius in metres.
        radius: f64,
        /// Full height in metres.
        height: f64,
    },
    /// A capsule along its local z, centred on the obstacle pose.
    Capsule {
        /// Radius in metres.
        radius: f64,
        /// Length of the cylindrical part in metres.
        length: f64,
    },
    /// A sphere centred on the obstacle pose.
    Sphere {
        /// Radius in metres.
        radius: f64,
    },
    /// A triangle mesh file (STL, OBJ, PLY or Collada, by its extension).
    Mesh {
        /// File path.
        path: String,
        /// Uniform scale (default 1).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        scale: Option<f64>,
    },
}

/// One named obstacle of the environment (table, fridge shelf, wall, …).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// Unique name; setting an existing name replaces that obstacle.
    pub name: String,
    /// Geometry.
    pub shape: ObstacleShape,
    /// Pose in the world frame.
    pub pose: Pose,
}

/// `tsukami/planner/set_env`: add or replace obstacles.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SetEnv {
    /// Obstacles to add (an existing name is replaced).
    #[serde(default)]
    pub obstacles: Vec<Obstacle>,
    /// Remove every existing obstacle first.
    #[serde(default)]
    pub replace: bool,
}

/// `tsukami/planner/remove_env`: remove obstacles.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RemoveEnv {
    /// Names to remove; an unknown name is an error and removes nothing.
    #[serde(default)]
    pub names: Vec<String>,
    /// Remove all obstacles (then `names` is ignored).
    #[serde(default)]
    pub all: bool,
}

/// Reply to [`SetEnv`] and [`RemoveEnv`]: the obstacles now present.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct EnvSummary {
    /// Obstacle names, sorted.
    pub obstacles: Vec<String>,
    /// The world version these obstacles belong to.
    #[serde(default)]
    pub world_version: u64,
}

// ---------------------------------------------------------------------------
// plan
// ---------------------------------------------------------------------------

/// Criterion choosing among nominal palm poses (section 3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum PalmCriterion {
    /// The paper: minimum norm of the wrist joint angles.
    #[default]
    MinWristNorm,
    /// graspPlugin's public code: minimum distance of all arm joints from the
    /// middle of their ranges (normalised by the range).
    MidRange,
}

/// How much of the body the planner may use (section 3.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum WholeBody {
    /// Arm only.
    ArmOnly,
    /// Arm, then arm + waist.
    Waist,
    /// Arm, then arm + waist, then arm + waist + squat (the default).
    #[default]
    Squat,
}

/// `tsukami/planner/plan`: options of one planning request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlanOptions {
    /// Random seed; the same seed and state give the same result.
    #[serde(default)]
    pub seed: u64,
    /// Maximum number of random samples of Algorithm 1 per candidate (default 1000).
    #[serde(default = "default_max_samples")]
    pub max_samples: u32,
    /// Wall-clock budget for the whole plan in milliseconds. Default: none —
    /// the plan is bounded by its sample budget (`max_samples`,
    /// `max_candidates`) and is deterministic; a budget makes the outcome depend
    /// on the machine's speed (`time_limit` when it runs out).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_budget_ms: Option<u64>,
    /// Joints beyond the arm the planner may add when the arm alone fails.
    #[serde(default)]
    pub whole_body: WholeBody,
    /// Nominal palm pose criterion.
    #[serde(default)]
    pub palm_criterion: PalmCriterion,
    /// Required ellipsoid margin δf: stop when `n − f(p1..pn) ≥ δf`. Absent:
    /// δf = 0.05, and a sample below it is also accepted when the exact test
    /// finds force closure holding twice the object's weight (the ellipsoid is
    /// an inner approximation). Given: the paper's rule alone, the margin is
    /// required.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delta_f: Option<f64>,
    /// Restrict the search to these grasp-type names (default: all).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grasp_types: Option<Vec<String>>,
    /// Maximum number of nominal palm poses (grasp type × OCP face × rotation)
    /// searched per whole-body stage, best first (default 8).
    #[serde(default = "default_max_candidates")]
    pub max_candidates: u32,
    /// What a grasp must resist to be returned (`docs/force-closure.md`,
    /// "Holding"): by default force closure and the weight along ±x, ±y, ±z
    /// plus centre-of-mass torques, with the joints' torques.
    #[serde(default)]
    pub hold: HoldRequest,
}

/// Which disturbances a returned grasp must resist.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DisturbanceSet {
    /// Exact force closure, and the weight `m g` pulling along −z, +z, ±x,
    /// ±y at the centre of mass, and the torques `m g · com_error` about the
    /// same six axes, each balanced by forces the joints can make.
    #[default]
    Standard,
    /// The weight along −z only, without requiring force closure (the paper's
    /// test; a grasp may then rest the object on the fingers).
    Gravity,
}

/// `PlanOptions::hold`: the physical acceptance test of a grasp.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HoldRequest {
    /// The disturbance set (default `standard`).
    #[serde(default)]
    pub disturbances: DisturbanceSet,
    /// Centre-of-mass error (m) whose torque `m g e` the grasp must resist
    /// (default 0.02; 0 to 0.2).
    #[serde(default = "default_com_error")]
    pub com_error: f64,
    /// Share of μ kept in reserve: forces stay inside the cone of
    /// `(1 − friction_reserve) μ` (default 0.2; 0 to 0.9).
    #[serde(default = "default_friction_reserve")]
    pub friction_reserve: f64,
    /// Share of each finger joint's effort the squeeze may use on its most
    /// loaded joint; the rest is headroom (default 0.9; above 0, at most 1).
    /// A firm squeeze is what holds in simulation: 0.5 held 49 % of the
    /// physics benchmark's grasps, 0.9 held 65 % (`docs/benchmarks.md`).
    #[serde(default = "default_squeeze_share")]
    pub squeeze_share: f64,
    /// Largest turn (degrees) of the object under the six pulls of its
    /// weight by the grasp's linear stiffness (servoed finger joints, pads;
    /// `docs/force-closure.md`, "Stiffness"): a grasp beyond it is refused,
    /// with the standard set only. Off by default; above 0, at most 90.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_turn_deg: Option<f64>,
    /// Largest shift (mm) of its centre of mass, likewise (off by default;
    /// above 0, at most 100).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_shift_mm: Option<f64>,
    /// The hold margin the planner prefers (default 3; 1 to 100): a grasp
    /// that resists this multiple of every disturbance wins over one that
    /// resists less (1 is every returned grasp's floor), as a grasp that holds
    /// under every pose error wins over one that some error drops; the
    /// weaker grasp is returned only when the stage has no preferred one. On
    /// the physics benchmark, grasps with a margin above 3 held 91 % of the
    /// time, those at or below 65 % (`docs/force-closure.md`).
    #[serde(default = "default_preferred_margin")]
    pub preferred_margin: f64,
    /// The object pose error the returned grasp is re-checked under
    /// (`docs/force-closure.md`, "Robust to the object's pose").
    #[serde(default)]
    pub pose_error: PoseError,
}

/// `HoldRequest::pose_error`: how far the object may lie from where vision
/// put it. The planner re-closes the hand on the object moved by each of
/// `samples` errors (drawn from the plan's seed: the same seed, the same
/// errors) and repeats the hold test; the reply says how many still hold
/// and the planner prefers grasps that hold under all of them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PoseError {
    /// Largest shift of the centre of mass, m (default 0.003; 0 to 0.05).
    #[serde(default = "default_pose_shift")]
    pub position: f64,
    /// Largest turn about the centre of mass, degrees (default 3; 0 to 30).
    #[serde(default = "default_pose_turn")]
    pub rotation_deg: f64,
    /// Errors sampled (default 8; 0 to 64; 0 turns the check off).
    #[serde(default = "default_pose_samples")]
    pub samples: u32,
}

fn default_pose_shift() -> f64 {
    0.003
}
fn default_pose_turn() -> f64 {
    3.0
}
fn default_pose_samples() -> u32 {
    8
}

impl Default for PoseError {
    fn default() -> Self {
        Self {
            position: default_pose_shift(),
            rotation_deg: default_pose_turn(),
            samples: default_pose_samples(),
        }
    }
}

fn default_com_error() -> f64 {
    0.02
}
fn default_friction_reserve() -> f64 {
    0.2
}
fn default_squeeze_share() -> f64 {
    0.9
}

fn default_preferred_margin() -> f64 {
    3.0
}

impl Default for HoldRequest {
    fn default() -> Self {
        Self {
            disturbances: DisturbanceSet::default(),
            com_error: default_com_error(),
            friction_reserve: default_friction_reserve(),
            squeeze_share: default_squeeze_share(),
            max_turn_deg: None,
            max_shift_mm: None,
            preferred_margin: default_preferred_margin(),
            pose_error: PoseError::default(),
        }
    }
}

fn default_max_samples() -> u32 {
    1000
}
fn default_max_candidates() -> u32 {
    8
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            max_samples: default_max_samples(),
            time_budget_ms: None,
            whole_body: WholeBody::default(),
            palm_criterion: PalmCriterion::default(),
            delta_f: None,
            grasp_types: None,
            max_candidates: default_max_candidates(),
            hold: HoldRequest::default(),
        }
    }
}

/// Grasp style of a reference posture.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum GraspStyle {
    /// 3-finger fingertip grasp (thumb, index, middle).
    Fingertip3,
    /// 4-finger fingertip grasp.
    Fingertip4,
    /// 4-finger enveloping grasp.
    Envelope4,
}

impl GraspStyle {
    /// The name used on the wire.
    pub fn as_str(self) -> &'static str {
        match self {
            GraspStyle::Fingertip3 => "fingertip3",
            GraspStyle::Fingertip4 => "fingertip4",
            GraspStyle::Envelope4 => "envelope4",
        }
    }
}

/// Object size class of a reference posture.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum GraspSize {
    /// Small objects.
    Small,
    /// Mid-sized objects.
    Mid,
    /// Large objects.
    Large,
}

impl GraspSize {
    /// The name used on the wire.
    pub fn as_str(self) -> &'static str {
        match self {
            GraspSize::Small => "small",
            GraspSize::Mid => "mid",
            GraspSize::Large => "large",
        }
    }
}

/// Which grasp type a plan used.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct GraspTypeRef {
    /// Name from the grasp-type configuration (e.g. `"fingertip4_mid"`).
    pub name: String,
    /// Style.
    pub style: GraspStyle,
    /// Size class.
    pub size: GraspSize,
}

/// One finger contact of the planned grasp, in the world frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ContactReply {
    /// Finger link touching the object.
    pub link: String,
    /// Contact point on the object surface (metres, world frame).
    pub position: [f64; 3],
    /// Unit contact normal pointing into the object.
    pub normal: [f64; 3],
    /// Maximum normal force this finger can apply at this posture (N).
    pub f_max: f64,
}

/// Object data the grasp was planned for, in the world frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ObjectMass {
    /// Mass in kg.
    pub mass: f64,
    /// Centre of mass (metres, world frame).
    pub center_of_mass: [f64; 3],
}

/// Force-closure verdicts of the planned grasp.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ForceClosureReply {
    /// Ellipsoid margin `n − f(p1..pn)` of eq. (10) for the object's weight.
    pub margin: f64,
    /// Exact friction-cone test (second-order cone program): the contacts, each
    /// within its friction cone and pressing at most `force_limit`, can resist
    /// the weight.
    pub exact_resists_weight: bool,
    /// The one normal-force bound (N) the planner applied to every contact in
    /// both tests: the weakest contact's `f_max` (the paper's single maximum
    /// finger force). An independent checker recomputes the exact test with it
    /// (`tsukami_scenes::verify`); 0 in replies of planners that predate it.
    #[serde(default)]
    pub force_limit: f64,
    /// Exact force closure (rank 6 and an internal squeeze strictly inside
    /// every cone).
    #[serde(default)]
    pub force_closure: bool,
    /// The hold margin: the smallest multiple of any disturbance of the
    /// request's set (`PlanOptions::hold`) that forces inside the reduced
    /// friction cones, within the joints' torques, can balance. ≥ 1 for
    /// every returned grasp; 2 means it resists twice the worst disturbance.
    #[serde(default)]
    pub hold_margin: f64,
    /// The disturbance set the grasp was checked against.
    #[serde(default)]
    pub disturbances: DisturbanceSet,
    /// The hold test repeated under the request's object pose errors
    /// (`HoldRequest::pose_error`).
    #[serde(default)]
    pub robustness: PoseRobustness,
    /// How far the object moves in the hand under the six pulls of its
    /// weight, the finger joints as servos and the contacts as pads
    /// (`docs/force-closure.md`, "Stiffness"); absent when not computed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compliance: Option<HoldCompliance>,
}

/// The worst motion of the held object under the six pulls of its weight.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct HoldCompliance {
    /// Largest turn, degrees.
    pub turn_deg: f64,
    /// Largest shift of the centre of mass, mm.
    pub shift_mm: f64,
    /// The compliant hand's largest `‖f_t‖ / (μ f_n)` of any contact under
    /// any of the six pulls, squeezing with the reply's squeeze
    /// (docs/force-closure.md); absent when a contact lets go under some pull.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_use: Option<f64>,
    /// Its largest `|τ| / effort` of any hand joint under any pull.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torque_use: Option<f64>,
}

/// How many of the sampled object pose errors the grasp still holds under:
/// the hand re-closed on the moved object, the same hold test.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PoseRobustness {
    /// Errors sampled (0: not checked).
    pub samples: u32,
    /// Errors under which it still holds.
    pub held: u32,
}

impl PoseRobustness {
    /// The share that still hold (1 when none was sampled).
    pub fn share(&self) -> f64 {
        match self.samples {
            0 => 1.0,
            n => f64::from(self.held) / f64::from(n),
        }
    }
}

/// One joint's squeeze: what a hand controller applies after contact so the
/// fingers press with the planned forces (`docs/force-closure.md`, "The
/// squeeze").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct JointSqueeze {
    /// Joint name (an independent hand joint; mimic joints follow theirs).
    pub joint: String,
    /// Position at contact (rad or m): the grasp posture.
    pub position: f64,
    /// Torque (N·m, or N for a prismatic joint) a torque-controlled hand applies,
    /// from the end of the motion's `close` phase through its lift.
    pub torque: f64,
    /// Servo stiffness (N·m/rad) the target assumes: the joint's effort over
    /// the hand's `servo_saturation`.
    pub stiffness: f64,
    /// Target of a position-controlled hand: `position` + the motion that closes the
    /// contacts' gaps and compresses their pads under the squeeze + `torque / stiffness`,
    /// clamped to the joint's limits (what a position-controlled hand commands from
    /// the end of `close` through the lift: the motion's points' `command`).
    pub target: f64,
}

/// Time spent per phase, milliseconds.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct PhaseTiming {
    /// Grasp-type selection, eqs. (1)–(5).
    pub selection: f64,
    /// Nominal palm poses and inverse kinematics (section 3.2, 3.4).
    pub nominal_pose: f64,
    /// Random posture search, Algorithm 1.
    pub search: f64,
    /// Exact force-closure verification of the result.
    pub verification: f64,
    /// Whole request.
    pub total: f64,
}

/// An approach turned from a face's inward normal toward a neighbour face:
/// the hand comes from between the two faces.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct FaceTilt {
    /// The neighbour face the approach turned toward.
    pub toward: BoxFace,
    /// The angle between the approach and the face's inward normal, radians.
    pub angle: f64,
}

/// Reply to [`PlanOptions`]: one planned grasp (the field contract of issue #5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PlanReply {
    /// Grasp type used.
    pub grasp_type: GraspTypeRef,
    /// Index of the OCP region grasped.
    pub ocp_region: usize,
    /// Face of that OCP the hand approached.
    pub face: BoxFace,
    /// How the approach was turned from the face's inward normal toward a
    /// neighbour face; absent when the hand came straight along the normal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tilt: Option<FaceTilt>,
    /// Palm (`r_palm` frame) pose in the world frame.
    pub palm_pose: Pose,
    /// Every joint used (waist, squat, arm, hand): name → position (rad or m).
    pub joint_positions: BTreeMap<String, f64>,
    /// Joints used beyond the arm (waist and squat joints); empty for arm only.
    pub joints_used: Vec<String>,
    /// Finger contacts in the world frame.
    pub contacts: Vec<ContactReply>,
    /// Friction coefficient used.
    pub mu: f64,
    /// Object mass and centre of mass.
    pub object: ObjectMass,
    /// Length (m) scaling torques to forces in wrenches, γ = 1 / length in eq. (6).
    pub characteristic_length: f64,
    /// Force-closure verdicts.
    pub force_closure: ForceClosureReply,
    /// The squeeze beyond contact, per independent hand joint (empty in
    /// replies of planners that predate it).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub squeeze: Vec<JointSqueeze>,
    /// Random samples drawn by Algorithm 1 over all candidates.
    pub samples: u32,
    /// Time per phase.
    pub timing_ms: PhaseTiming,
    /// Grasp types of the nominal palm poses searched, in the order tried
    /// (ranked by the palm criterion plus the weighted eq. (3) score).
    pub candidates_tried: Vec<String>,
    /// The world version (robot, object, obstacles) the grasp was planned on.
    #[serde(default)]
    pub world_version: u64,
}

// ---------------------------------------------------------------------------
// stop / progress
// ---------------------------------------------------------------------------

// `tsukami/planner/stop` is answered by the host for every role (see
// `crate::host::StopReply`): it must work while the plugin is busy planning.

/// Phase a [`ProgressEvent`] reports on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum PlanPhase {
    /// Grasp-type selection.
    Selection,
    /// Nominal palm pose and IK.
    NominalPose,
    /// Random posture search.
    Search,
    /// Exact verification.
    Verification,
    /// Finished (successfully or not).
    Done,
}

/// `tsukami/planner/progress`: published while planning.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ProgressEvent {
    /// Current phase.
    pub phase: PlanPhase,
    /// Grasp type being tried, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grasp_type: Option<String>,
    /// Joints used beyond the arm at this stage.
    #[serde(default)]
    pub joints_used: Vec<String>,
    /// Samples drawn so far.
    pub samples: u32,
    /// Best ellipsoid margin seen so far, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub best_margin: Option<f64>,
    /// Milliseconds since the plan started.
    pub elapsed_ms: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reply with every field set.
    fn sample_reply() -> PlanReply {
        PlanReply {
            grasp_type: GraspTypeRef {
                name: "fingertip4_mid".into(),
                style: GraspStyle::Fingertip4,
                size: GraspSize::Mid,
            },
            ocp_region: 0,
            face: BoxFace::NegX,
            tilt: Some(FaceTilt {
                toward: BoxFace::PosZ,
                angle: 0.5,
            }),
            palm_pose: Pose::IDENTITY,
            joint_positions: BTreeMap::from([("r_elbow".to_string(), -1.0)]),
            joints_used: vec!["squat_z".into()],
            contacts: vec![ContactReply {
                link: "r_index_l4".into(),
                position: [0.0; 3],
                normal: [1.0, 0.0, 0.0],
                f_max: 5.0,
            }],
            mu: 0.5,
            object: ObjectMass {
                mass: 0.15,
                center_of_mass: [0.0; 3],
            },
            characteristic_length: 0.05,
            force_closure: ForceClosureReply {
                margin: 0.3,
                exact_resists_weight: true,
                force_limit: 5.0,
                force_closure: true,
                hold_margin: 1.5,
                disturbances: DisturbanceSet::Standard,
                robustness: PoseRobustness {
                    samples: 8,
                    held: 7,
                },
                compliance: Some(HoldCompliance {
                    turn_deg: 2.5,
                    shift_mm: 1.2,
                    friction_use: Some(0.6),
                    torque_use: Some(0.95),
                }),
            },
            squeeze: vec![JointSqueeze {
                joint: "r_index_j2".into(),
                position: 0.5,
                torque: 0.4,
                stiffness: 15.0,
                target: 0.5 + 0.4 / 15.0,
            }],
            samples: 3,
            timing_ms: PhaseTiming::default(),
            candidates_tried: vec![],
            world_version: 3,
        }
    }

    #[test]
    fn plan_reply_field_contract() {
        let reply = sample_reply();
        let v = serde_json::to_value(&reply).unwrap();
        assert_eq!(v["grasp_type"]["style"], "fingertip4");
        assert_eq!(v["grasp_type"]["size"], "mid");
        assert_eq!(v["face"], "-x");
        assert_eq!(v["palm_pose"]["quaternion"].as_array().unwrap().len(), 4);
        for key in [
            "ocp_region",
            "joint_positions",
            "joints_used",
            "mu",
            "characteristic_length",
            "samples",
            "timing_ms",
        ] {
            assert!(v.get(key).is_some(), "missing {key}");
        }
        assert_eq!(v["contacts"][0]["f_max"], 5.0);
        assert_eq!(v["object"]["mass"], 0.15);
        assert_eq!(v["force_closure"]["exact_resists_weight"], true);
        let back: PlanReply = serde_json::from_value(v).unwrap();
        assert_eq!(back, reply);
    }

    #[test]
    fn requests_reject_unknown_fields() {
        assert!(serde_json::from_str::<SetRobot>(r#"{"robot":"x","urdf":"y"}"#).is_err());
        assert!(serde_json::from_str::<SetEnv>(r#"{"obstacle":[]}"#).is_err());
        let env: SetEnv = serde_json::from_str(
            r#"{"obstacles":[{"name":"table","shape":{"box":{"size":[1,1,0.7]}},
                "pose":{"position":[0.6,0,0.35]}}]}"#,
        )
        .unwrap();
        assert_eq!(env.obstacles[0].pose.quaternion, [0.0, 0.0, 0.0, 1.0]);
    }

    /// Follows `$ref` (and a lone `allOf: [$ref]`) to the definition it names.
    fn resolve<'a>(
        node: &'a serde_json::Value,
        root: &'a serde_json::Value,
    ) -> &'a serde_json::Value {
        let reference = node["$ref"]
            .as_str()
            .or_else(|| node["allOf"][0]["$ref"].as_str());
        match reference {
            Some(r) => {
                let name = r.rsplit('/').next().unwrap();
                let defs = if root["$defs"].is_object() {
                    &root["$defs"]
                } else {
                    &root["definitions"]
                };
                resolve(&defs[name], root)
            }
            None => node,
        }
    }

    /// Every object in `value` has exactly the properties its schema lists, and
    /// all the required ones; recurses into properties and array items.
    fn matches_schema(
        path: &str,
        node: &serde_json::Value,
        value: &serde_json::Value,
        root: &serde_json::Value,
    ) {
        let node = resolve(node, root);
        if let (Some(props), Some(object)) = (node["properties"].as_object(), value.as_object()) {
            let listed: std::collections::BTreeSet<&String> = props.keys().collect();
            let present: std::collections::BTreeSet<&String> = object.keys().collect();
            assert_eq!(
                listed, present,
                "{path}: schema properties vs serialized fields"
            );
            for required in node["required"].as_array().into_iter().flatten() {
                assert!(
                    object.contains_key(required.as_str().unwrap()),
                    "{path}: {required} missing"
                );
            }
            for (key, v) in object {
                matches_schema(&format!("{path}.{key}"), &props[key], v, root);
            }
        }
        if let (Some(items), Some(array)) = (node.get("items"), value.as_array()) {
            for (i, v) in array.iter().enumerate() {
                matches_schema(&format!("{path}[{i}]"), items, v, root);
            }
        }
    }

    #[test]
    fn schema_is_generated() {
        // The published schema describes what a reply really serializes to: the
        // same fields at every level (a renamed, added or skipped field shows up).
        let schema = serde_json::to_value(schemars::schema_for!(PlanReply)).unwrap();
        let reply = serde_json::to_value(sample_reply()).unwrap();
        matches_schema("plan_reply", &schema, &reply, &schema);
        let limit = &resolve(&schema["properties"]["force_closure"], &schema)["properties"];
        assert!(limit["force_limit"].is_object(), "{limit}");
    }

    #[test]
    fn mesh_formats_are_named_by_their_extension_on_the_wire() {
        for format in MeshFormat::ALL {
            let wire = serde_json::to_value(format).unwrap();
            assert_eq!(wire, format.extension());
            assert_eq!(serde_json::from_value::<MeshFormat>(wire).unwrap(), format);
            let upper = format.extension().to_ascii_uppercase();
            assert_eq!(MeshFormat::from_extension(&upper), Some(format));
        }
        assert_eq!(MeshFormat::from_extension("ply"), Some(MeshFormat::Ply));
        assert_eq!(MeshFormat::from_extension("dae"), None);
        let e = serde_json::from_str::<MeshFormat>(r#""off""#).unwrap_err();
        assert!(
            e.to_string()
                .contains("unknown variant `off`, expected one of `stl`, `obj`, `ply`"),
            "{e}"
        );
    }
}
