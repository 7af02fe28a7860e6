//! The joints a controller drives, with their limits, read from the robot model.
//!
//! What: [`JointTable`] — every independent joint of the URDF (movable, not a
//! mimic) with its position and velocity limits, and the names of the mimic joints
//! (which follow their masters and cannot be commanded).
//!
//! Why: a trajectory is checked against the same model the planner used; a joint the
//! robot does not have, or a position or speed it cannot reach, is refused before
//! anything moves.
//!
//! How: from `tsukami_body::RobotModel` (the project's URDF loader). Continuous
//! joints have infinite position limits; a URDF velocity limit that is not positive
//! means "not given" and is taken as infinite.
//!
//! ```
//! use tsukami_controller::joints::JointTable;
//! let urdf = r#"<robot name="r"><link name="a"/><link name="b"/>
//!   <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
//!   <limit lower="-1" upper="2" effort="1" velocity="3"/></joint></robot>"#;
//! let model = tsukami_body::RobotModel::from_urdf_str(urdf, ".".as_ref()).unwrap();
//! let table = JointTable::from_model(&model);
//! assert_eq!(table.names(), ["j"]);
//! assert_eq!((table.joint(0).lower, table.joint(0).upper, table.joint(0).velocity), (-1.0, 2.0, 3.0));
//! ```

use std::collections::HashMap;
use tsukami_body::model::JointKind;
use tsukami_body::RobotModel;

/// One commandable joint.
#[derive(Debug, Clone, PartialEq)]
pub struct JointSpec {
    /// Joint name.
    pub name: String,
    /// Lower position limit (rad or m; `-inf` for continuous joints).
    pub lower: f64,
    /// Upper position limit (rad or m; `+inf` for continuous joints).
    pub upper: f64,
    /// Speed limit (rad/s or m/s; `+inf` when the model gives none).
    pub velocity: f64,
}

/// What a name in a trajectory refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointLookup<'t> {
    /// A commandable joint, by its index in the table.
    Commandable(usize),
    /// A mimic joint, with the joint it follows.
    Mimic(&'t str),
    /// A fixed joint.
    Fixed,
    /// No joint of that name.
    Unknown,
}

/// The robot's commandable joints, in model order.
#[derive(Debug, Clone)]
pub struct JointTable {
    robot: String,
    joints: Vec<JointSpec>,
    index: HashMap<String, usize>,
    mimics: HashMap<String, String>,
    fixed: Vec<String>,
}

impl JointTable {
    /// The independent joints of `model`.
    pub fn from_model(model: &RobotModel) -> JointTable {
        let mut table = JointTable {
            robot: model.name.clone(),
            joints: Vec::new(),
            index: HashMap::new(),
            mimics: HashMap::new(),
            fixed: Vec::new(),
        };
        for joint in &model.joints {
            if let Some(mimic) = &joint.mimic {
                table
                    .mimics
                    .insert(joint.name.clone(), mimic.joint_name.clone());
                continue;
            }
            if joint.kind == JointKind::Fixed {
                table.fixed.push(joint.name.clone());
                continue;
            }
            let (lower, upper) = match joint.kind {
                JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
                _ => (joint.limits.lower, joint.limits.upper),
            };
            let velocity = if joint.limits.velocity > 0.0 {
                joint.limits.velocity
            } else {
                f64::INFINITY
            };
            table.index.insert(joint.name.clone(), table.joints.len());
            table.joints.push(JointSpec {
                name: joint.name.clone(),
                lower,
                upper,
                velocity,
            });
        }
        table
    }

    /// The robot's name.
    pub fn robot(&self) -> &str {
        &self.robot
    }

    /// Number of commandable joints.
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// True when the robot has no commandable joint.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Joint `i`.
    pub fn joint(&self, i: usize) -> &JointSpec {
        &self.joints[i]
    }

    /// The commandable joints' names, in table order.
    pub fn names(&self) -> Vec<String> {
        self.joints.iter().map(|j| j.name.clone()).collect()
    }

    /// What `name` is on this robot.
    pub fn lookup(&self, name: &str) -> JointLookup<'_> {
        if let Some(&i) = self.index.get(name) {
            JointLookup::Commandable(i)
        } else if let Some(master) = self.mimics.get(name) {
            JointLookup::Mimic(master)
        } else if self.fixed.iter().any(|f| f == name) {
            JointLookup::Fixed
        } else {
            JointLookup::Unknown
        }
    }

    /// The rest pose: 0 clamped into each joint's limits.
    pub fn rest_positions(&self) -> Vec<f64> {
        self.joints
            .iter()
            .map(|j| 0.0f64.clamp(j.lower, j.upper))
            .collect()
    }

    /// Whether `value` is within joint `i`'s position limits (to `1e-9`).
    pub fn within_position_limits(&self, i: usize, value: f64) -> bool {
        let j = &self.joints[i];
        value >= j.lower - LIMIT_SLACK && value <= j.upper + LIMIT_SLACK
    }
}

/// Rounding slack on limit checks, so a waypoint exactly at a limit (after a
/// decimal round trip) is accepted.
pub const LIMIT_SLACK: f64 = 1e-9;

impl JointTable {
    /// Loads the robot `robot`: a URDF file path (ends in `.urdf`), or a model name
    /// looked up as `<models_dir>/robots/<name>/<name>.urdf`.
    pub fn load(robot: &str, models_dir: &std::path::Path) -> anyhow::Result<JointTable> {
        let path = if robot.ends_with(".urdf") {
            std::path::PathBuf::from(robot)
        } else {
            anyhow::ensure!(
                !robot.is_empty()
                    && robot
                        .chars()
                        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-'),
                "robot name `{robot}` must be letters, digits, `_` or `-` (or give a .urdf file)"
            );
            models_dir
                .join("robots")
                .join(robot)
                .join(format!("{robot}.urdf"))
        };
        let model = tsukami_body::urdf::load_urdf(&path)
            .map_err(|e| anyhow::anyhow!("loading robot {}: {e}", path.display()))?;
        Ok(JointTable::from_model(&model))
    }

    /// Positions in table order from a `{"joint": value}` map: named joints take
    /// their value, the others their rest value.
    pub fn positions_from_map(
        &self,
        map: &tsukami_msgs::common::JointMap,
    ) -> Result<Vec<f64>, String> {
        let mut q = self.rest_positions();
        for (name, &value) in map {
            match self.lookup(name) {
                JointLookup::Commandable(i) => q[i] = value,
                _ => {
                    return Err(format!(
                        "`{name}` is not a commandable joint of robot `{}`",
                        self.robot
                    ))
                }
            }
        }
        Ok(q)
    }
}
