//! The hand's grasp types (section 3.1 of the paper): reference postures and
//! their grasping rectangular convexes (GRC), read from a TOML file per hand.
//!
//! What: [`GraspTypeConfig`] — one [`GraspType`] per reference posture
//! (3-finger fingertip, 4-finger fingertip, 4-finger envelope × small / mid /
//! large): the finger joint angles, the contacting links and the joint that
//! closes each, the closing step, the GRCmax / GRCmin / GRCdes boxes in the palm
//! frame, the approach vector and the mass range.
//!
//! Why: grasp types belong to a hand, not to a planner: the paper's planner
//! searches from them, the antipodal template takes its pinch from the
//! fingertip type. The robot description (`crate::description`) names the file
//! per hand; the format is documented in `docs/grasp-types.md`.
//!
//! How: [`GraspTypeConfig::from_toml_str`] parses and checks the file (unknown
//! fields are errors; every box must have positive edges, every approach vector
//! must be a unit axis of the palm frame, mass ranges ordered);
//! [`GraspTypeConfig::check_against`] then checks joint and link names against
//! a robot model. The hand's joint groups moved to the robot description: a
//! file that still has a `[hand]` table parses (old files stay readable) but is
//! refused by `set_robot` with a message saying where the table went.
//!
//! ```
//! use tsukami_planner_kit::grasp_types::GraspTypeConfig;
//! let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"),
//!     "/../../models/robots/tsukami_humanoid/grasp_types.toml")).unwrap();
//! let cfg = GraspTypeConfig::from_toml_str(&text).unwrap();
//! assert!(cfg.grasp_types.iter().any(|g| g.name == "fingertip4_mid"));
//! ```

use std::collections::BTreeMap;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use tsukami_msgs::planner::{GraspSize, GraspStyle, GraspTypeRef};

/// Errors reading or checking a grasp-type file.
#[derive(Debug, thiserror::Error)]
pub enum GraspTypeError {
    /// The TOML is malformed or has unknown / missing fields.
    #[error("grasp-type file {path}: {message}")]
    Parse {
        /// File path (or `<string>`).
        path: String,
        /// Parser message (names the line and field).
        message: String,
    },
    /// A value is out of range.
    #[error("grasp type `{grasp_type}`, field `{field}`: {message}")]
    Invalid {
        /// Grasp type name (or `hand`).
        grasp_type: String,
        /// Field name.
        field: String,
        /// What is wrong.
        message: String,
    },
}

/// A box in the palm frame: pose of its centre and full edge lengths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GrcBox {
    /// Centre in the palm frame (m).
    pub position: [f64; 3],
    /// Orientation in the palm frame, roll-pitch-yaw (rad); default identity.
    #[serde(default)]
    pub rpy: [f64; 3],
    /// Full edge lengths along the box axes (m).
    pub size: [f64; 3],
}

impl GrcBox {
    /// Pose of the box in the palm frame.
    pub fn pose(&self) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(self.position[0], self.position[1], self.position[2]),
            UnitQuaternion::from_euler_angles(self.rpy[0], self.rpy[1], self.rpy[2]),
        )
    }

    /// Edge lengths as a vector.
    pub fn edges(&self) -> Vector3<f64> {
        Vector3::from(self.size)
    }
}

/// The box's edge lengths sorted ascending.
pub fn sorted_edges(b: &GrcBox) -> [f64; 3] {
    let mut e = b.size;
    e.sort_by(f64::total_cmp);
    e
}

/// A finger link that must touch the object and the joint that closes it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Link that touches the object (e.g. `r_index_l4`).
    pub link: String,
    /// Joint turned step by step until the link touches (e.g. `r_index_j3`).
    pub joint: String,
    /// Joints perturbed by the fingertip offset Δa of Algorithm 1 (default: none).
    #[serde(default)]
    pub perturb: Vec<String>,
}

/// One reference posture and its GRCs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GraspType {
    /// Unique name, e.g. `fingertip4_mid`.
    pub name: String,
    /// Grasp style.
    pub style: GraspStyle,
    /// Size class.
    pub size: GraspSize,
    /// Mass range `[m_min, m_max]` in kg, eqs. (4)–(5).
    pub mass: [f64; 2],
    /// Approach direction in the palm frame (a unit axis; `[0, 0, 1]` = along the palm normal).
    pub approach: [f64; 3],
    /// Closing step of the contact joints (rad).
    pub closing_step: f64,
    /// Reference finger joint angles (rad); hand joints not listed are 0.
    pub posture: BTreeMap<String, f64>,
    /// Contacting links and the joint closing each.
    pub contacts: Vec<ContactSpec>,
    /// Links that may touch the object without being contacts of the force
    /// analysis (e.g. the middle phalanges wrapping an object in an envelope
    /// grasp); default none.
    #[serde(default)]
    pub touch_allowed: Vec<String>,
    /// The palm presses the object too (a power grasp): the nominal pose lays
    /// the object on the palm, the palm is a contact of the force analysis,
    /// and a grasp without it is refused (default false).
    #[serde(default)]
    pub palm_contact: bool,
    /// GRCmax: largest box that fits without touching the fingers.
    pub grc_max: GrcBox,
    /// GRCmin: smallest object the posture can hold.
    pub grc_min: GrcBox,
    /// GRCdes: the object size the posture is made for.
    pub grc_des: GrcBox,
}

impl GraspType {
    /// The message form of this type's name, style and size.
    pub fn to_ref(&self) -> GraspTypeRef {
        GraspTypeRef {
            name: self.name.clone(),
            style: self.style,
            size: self.size,
        }
    }

    /// Approach vector as a unit vector.
    pub fn approach(&self) -> Vector3<f64> {
        Vector3::from(self.approach).normalize()
    }
}

/// What remains of the former `[hand]` table.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
pub struct HandTable {
    /// Links besides the contacts allowed to touch the object (from the
    /// robot description's hand).
    #[serde(default)]
    pub touch_allowed: Vec<String>,
    /// Any other key of an old file (refused by `set_robot`).
    #[serde(flatten)]
    pub legacy: toml::Table,
}

impl HandTable {
    /// True when the file had a `[hand]` table.
    pub fn is_present(&self) -> bool {
        !self.legacy.is_empty() || !self.touch_allowed.is_empty()
    }
}

/// The whole grasp-type file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GraspTypeConfig {
    /// The former `[hand]` table, now in the robot description: empty in a
    /// current file (`set_robot` refuses a file that has one). The kit fills
    /// `touch_allowed` from the description for planners that read it here.
    #[serde(default, skip_serializing)]
    pub hand: HandTable,
    /// Reference postures.
    #[serde(rename = "grasp_type")]
    pub grasp_types: Vec<GraspType>,
}

impl GraspTypeConfig {
    /// Parses and checks a grasp-type file from a string.
    pub fn from_toml_str(text: &str) -> Result<Self, GraspTypeError> {
        Self::parse(text, "<string>")
    }

    /// Parses and checks the text of the file `name` (named in errors, which
    /// give line and column but never quote the file).
    pub fn parse(text: &str, name: &str) -> Result<Self, GraspTypeError> {
        let cfg: Self = toml::from_str(text).map_err(|e| GraspTypeError::Parse {
            path: name.to_string(),
            message: tsukami_body::files::toml_error(&e, text),
        })?;
        cfg.validate()?;
        Ok(cfg)
    }

    /// Checks values that the format cannot express.
    pub fn validate(&self) -> Result<(), GraspTypeError> {
        let bad = |t: &str, f: &str, m: String| GraspTypeError::Invalid {
            grasp_type: t.to_string(),
            field: f.to_string(),
            message: m,
        };
        if self.grasp_types.is_empty() {
            return Err(bad(
                "-",
                "grasp_type",
                "at least one grasp type is required".into(),
            ));
        }
        let mut names = std::collections::BTreeSet::new();
        for g in &self.grasp_types {
            if !names.insert(g.name.as_str()) {
                return Err(bad(&g.name, "name", "duplicate grasp type name".into()));
            }
            let [lo, hi] = g.mass;
            if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && lo < hi) {
                return Err(bad(
                    &g.name,
                    "mass",
                    format!("need 0 <= m_min < m_max, got [{lo}, {hi}]"),
                ));
            }
            let a = Vector3::from(g.approach);
            let n = a.norm();
            if !(n.is_finite()
                && (n - 1.0).abs() < 1e-6
                && a.iter().filter(|x| x.abs() > 1e-6).count() == 1)
            {
                return Err(bad(
                    &g.name,
                    "approach",
                    "must be a unit axis of the palm frame, e.g. [0, 0, 1]".into(),
                ));
            }
            if !(g.closing_step > 0.0 && g.closing_step < 0.5) {
                return Err(bad(
                    &g.name,
                    "closing_step",
                    "must be in (0, 0.5) rad".into(),
                ));
            }
            if g.contacts.is_empty() {
                return Err(bad(
                    &g.name,
                    "contacts",
                    "at least one contacting link is required".into(),
                ));
            }
            for (field, b) in [
                ("grc_max", &g.grc_max),
                ("grc_min", &g.grc_min),
                ("grc_des", &g.grc_des),
            ] {
                if !b.size.iter().all(|s| s.is_finite() && *s > 0.0)
                    || !b.position.iter().chain(b.rpy.iter()).all(|x| x.is_finite())
                {
                    return Err(bad(
                        &g.name,
                        field,
                        "edges must be positive and values finite".into(),
                    ));
                }
            }
            let sort = |b: &GrcBox| sorted_edges(b);
            let (mx, mn, ds) = (sort(&g.grc_max), sort(&g.grc_min), sort(&g.grc_des));
            if (0..3).any(|k| mn[k] > ds[k] || ds[k] > mx[k]) {
                return Err(bad(
                    &g.name,
                    "grc_des",
                    "sorted edges must satisfy GRCmin <= GRCdes <= GRCmax".into(),
                ));
            }
            for v in g.posture.values() {
                if !v.is_finite() {
                    return Err(bad(&g.name, "posture", "angles must be finite".into()));
                }
            }
        }
        Ok(())
    }

    /// Checks that every joint and link named exists in `robot`.
    pub fn check_against(
        &self,
        robot: &tsukami_body::model::RobotModel,
    ) -> Result<(), GraspTypeError> {
        let missing = |t: &str, f: &str, what: &str, name: &str| GraspTypeError::Invalid {
            grasp_type: t.to_string(),
            field: f.to_string(),
            message: format!("{what} `{name}` is not in robot `{}`", robot.name),
        };
        for g in &self.grasp_types {
            for j in g.posture.keys() {
                robot
                    .joint_id(j)
                    .map_err(|_| missing(&g.name, "posture", "joint", j))?;
            }
            for l in &g.touch_allowed {
                robot
                    .link_id(l)
                    .map_err(|_| missing(&g.name, "touch_allowed", "link", l))?;
            }
            for c in &g.contacts {
                robot
                    .link_id(&c.link)
                    .map_err(|_| missing(&g.name, "contacts.link", "link", &c.link))?;
                let j = robot
                    .joint_id(&c.joint)
                    .map_err(|_| missing(&g.name, "contacts.joint", "joint", &c.joint))?;
                let link = robot
                    .link_id(&c.link)
                    .map_err(|_| missing(&g.name, "contacts.link", "link", &c.link))?;
                if robot.joints[j].mimic.is_some() || !robot.chain(link).contains(&j) {
                    return Err(GraspTypeError::Invalid {
                        grasp_type: g.name.clone(),
                        field: "contacts.joint".into(),
                        message: format!(
                            "joint `{}` must be an independent joint between the palm and link `{}`",
                            c.joint, c.link
                        ),
                    });
                }
                for p in &c.perturb {
                    robot
                        .joint_id(p)
                        .map_err(|_| missing(&g.name, "contacts.perturb", "joint", p))?;
                }
            }
        }
        Ok(())
    }
}

/// A grasp-type file with one type, for planners' unit tests: a three-finger
/// fingertip grasp whose one contact is link `l1`, closed by joint `f1`, with
/// its GRC boxes around (0.05, 0, 0.06) in the palm frame.
pub const ONE_TYPE_EXAMPLE: &str = r#"
[[grasp_type]]
name = "fingertip3_mid"
style = "fingertip3"
size = "mid"
mass = [0.0, 0.3]
approach = [0, 0, 1]
closing_step = 0.02
posture = { f1 = 0.3 }
contacts = [{ link = "l1", joint = "f1" }]
grc_max = { position = [0.05, 0, 0.06], size = [0.10, 0.20, 0.30] }
grc_min = { position = [0.05, 0, 0.06], size = [0.02, 0.02, 0.02] }
grc_des = { position = [0.05, 0, 0.06], size = [0.06, 0.06, 0.10] }
"#;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_minimal_file() {
        let cfg = GraspTypeConfig::from_toml_str(ONE_TYPE_EXAMPLE).unwrap();
        assert_eq!(cfg.grasp_types[0].style, GraspStyle::Fingertip3);
        assert_eq!(cfg.grasp_types[0].approach(), Vector3::z());
    }

    #[test]
    fn unknown_field_is_an_error_naming_it() {
        let text = ONE_TYPE_EXAMPLE.replace(
            "closing_step = 0.02",
            "closing_step = 0.02\nclosing_stp = 1",
        );
        let err = GraspTypeConfig::from_toml_str(&text)
            .unwrap_err()
            .to_string();
        assert!(err.contains("closing_stp"), "{err}");
    }

    #[test]
    fn bad_values_are_errors_naming_the_field() {
        let err = GraspTypeConfig::from_toml_str(
            &ONE_TYPE_EXAMPLE.replace("mass = [0.0, 0.3]", "mass = [0.3, 0.1]"),
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("mass") && err.contains("fingertip3_mid"),
            "{err}"
        );
        let err = GraspTypeConfig::from_toml_str(
            &ONE_TYPE_EXAMPLE.replace("approach = [0, 0, 1]", "approach = [0, 1, 1]"),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("approach"), "{err}");
        let err = GraspTypeConfig::from_toml_str(
            &ONE_TYPE_EXAMPLE.replace("size = [0.02, 0.02, 0.02]", "size = [0.2, 0.02, 0.02]"),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("grc_des"), "{err}");
    }
}
