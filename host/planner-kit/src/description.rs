//! The robot description: what a planner must know about a robot beyond its URDF.
//!
//! What: [`Description`], read from `description.toml` beside the URDF (the
//! role SRDF plays for MoveIt): the URDF file, the hand(s) — palm link, arm and
//! wrist joints, fingers, the grasp-type file, contact tolerance, finger force
//! cap — the joint groups the whole-body fallback adds (`waist`, then
//! `whole_body`), and link pairs whose shapes may overlap
//! (`allowed_collisions`).
//!
//! Why: joint and link names used to be constants in the planners and in
//! `tsukami_body::ik`, and a `[hand]` table in the grasp-type file, so each
//! planner served one robot. With the names in a data file, any planner serves
//! any robot that has a description: a new robot is a new folder under
//! `models/robots/`, not a code change.
//!
//! How: [`Description::parse`] checks the format (unknown keys are errors) and
//! the values; [`crate::robot::Robot`] resolves the names against the URDF.
//!
//! ```
//! use tsukami_planner_kit::description::Description;
//! let d = Description::parse(r#"
//!     urdf = "arm.urdf"
//!     [[hand]]
//!     name = "right"
//!     palm_link = "palm"
//!     arm = ["j1", "j2"]
//!     wrist = ["j2"]
//!     grasp_types = "grasp_types.toml"
//!     fingers = [{ name = "thumb", tip = "thumb_tip", flex = ["t2"] }]
//! "#, "description.toml").unwrap();
//! assert_eq!(d.hands[0].contact_distance, 0.002);
//! assert!(d.waist.is_empty());
//! ```

use serde::Deserialize;

use crate::KitError;

/// The file name of a robot's description, beside its URDF.
pub const FILE_NAME: &str = "description.toml";

/// One finger of a hand.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FingerSpec {
    /// Short name (`thumb`, `index`, …).
    pub name: String,
    /// The distal link (the fingertip); the finger's links are the links from
    /// the palm down to it.
    pub tip: String,
    /// The joints that flex the finger toward the palm, base to tip (the
    /// finger-closing block turns these).
    pub flex: Vec<String>,
}

/// One hand.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandSpec {
    /// Name (`right`, `left`).
    pub name: String,
    /// The palm link; its frame is the palm frame of the grasp types.
    pub palm_link: String,
    /// Arm joints, shoulder to wrist.
    pub arm: Vec<String>,
    /// Wrist joints (the paper's palm-pose criterion is their norm).
    pub wrist: Vec<String>,
    /// The hand's grasp-type file, relative to this description.
    pub grasp_types: String,
    /// The fingers.
    pub fingers: Vec<FingerSpec>,
    /// A link this close to the object (m) touches it (default 0.002).
    #[serde(default = "default_contact_distance")]
    pub contact_distance: f64,
    /// Links besides the contacts allowed to touch the object (default none).
    #[serde(default)]
    pub touch_allowed: Vec<String>,
    /// Largest normal force credited to one finger, N (default 100): an
    /// upper bound only; the joints' torques limit the forces first.
    #[serde(default = "default_finger_force")]
    pub max_finger_force: f64,
    /// Position error (rad, or m) at which a finger joint's servo reaches
    /// its full effort: the stiffness a squeeze target assumes is
    /// `effort / servo_saturation` (default 0.2).
    #[serde(default = "default_servo_saturation")]
    pub servo_saturation: f64,
}

fn default_contact_distance() -> f64 {
    0.002
}
fn default_finger_force() -> f64 {
    100.0
}
fn default_servo_saturation() -> f64 {
    0.2
}

/// Joint acceleration (or jerk) limits (rad/s², m/s² for prismatic joints;
/// s³ for jerk), which a URDF cannot state (MoveIt keeps them in
/// `joint_limits.yaml`). Motions are timed within them.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccelerationSpec {
    /// Every joint not named otherwise; none: the trajectory planner's
    /// configured `acceleration`.
    #[serde(default)]
    pub default: Option<f64>,
    /// Every joint of the hands (below the palm).
    #[serde(default)]
    pub hand: Option<f64>,
    /// Joints by name, over the two above.
    #[serde(default)]
    pub joints: std::collections::BTreeMap<String, f64>,
}

/// Safety distances this robot's motions keep from the obstacles (m); a
/// motion request's `clearance` overrides them, and without them the
/// trajectory planner's configured ones apply (10 mm, 3 mm).
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClearanceSpec {
    /// Every link but the hand's, in every phase.
    #[serde(default)]
    pub body: Option<f64>,
    /// The hand's links in the reach and the approach.
    #[serde(default)]
    pub hand: Option<f64>,
}

/// A robot description file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Description {
    /// The URDF, relative to this file.
    pub urdf: String,
    /// The hands; the first is the one planners use unless told otherwise.
    #[serde(rename = "hand")]
    pub hands: Vec<HandSpec>,
    /// Joints the whole-body fallback adds first (e.g. the waist).
    #[serde(default)]
    pub waist: Vec<String>,
    /// Joints it adds last (e.g. the virtual squat joint).
    #[serde(default)]
    pub whole_body: Vec<String>,
    /// Link pairs never checked for self-collision, beyond the adjacent ones
    /// (SRDF's `disable_collisions`): for collision models whose shapes
    /// overlap by construction, e.g. the Allegro hand's thumb base inside its
    /// palm box. Default none.
    #[serde(default)]
    pub allowed_collisions: Vec<[String; 2]>,
    /// Joint acceleration limits (default: none stated).
    #[serde(default)]
    pub acceleration: AccelerationSpec,
    /// Joint jerk limits (rad/s³, m/s³; same keys as `acceleration`; default:
    /// none, the motion's jerk is not limited).
    #[serde(default)]
    pub jerk: AccelerationSpec,
    /// Safety distances of this robot's motions (default: none stated).
    #[serde(default)]
    pub clearance: ClearanceSpec,
}

impl Description {
    /// Parses and checks the text of description file `name`; errors name the
    /// file and the key, and give line and column without quoting the file.
    pub fn parse(text: &str, name: &str) -> Result<Self, KitError> {
        let d: Description = toml::from_str(text).map_err(|e| {
            KitError::model(
                "robot",
                format!("{name}: {}", tsukami_body::files::toml_error(&e, text)),
            )
        })?;
        d.check(name)?;
        Ok(d)
    }

    fn check(&self, name: &str) -> Result<(), KitError> {
        let bad = |key: String, m: &str| KitError::model("robot", format!("{name}: {key} {m}"));
        if self.hands.is_empty() {
            return Err(bad("[[hand]]".into(), "is required (at least one hand)"));
        }
        for (i, h) in self.hands.iter().enumerate() {
            let key = |k: &str| format!("hand[{i}].{k}");
            if h.arm.is_empty() {
                return Err(bad(key("arm"), "must name at least one joint"));
            }
            if let Some(w) = h.wrist.iter().find(|w| !h.arm.contains(w)) {
                return Err(bad(key("wrist"), &format!("`{w}` is not an arm joint")));
            }
            if h.fingers.is_empty() {
                return Err(bad(key("fingers"), "must list at least one finger"));
            }
            if !(h.contact_distance > 0.0 && h.contact_distance < 0.05) {
                return Err(bad(key("contact_distance"), "must be in (0, 0.05) m"));
            }
            if !(h.max_finger_force.is_finite() && h.max_finger_force > 0.0) {
                return Err(bad(key("max_finger_force"), "must be finite and > 0"));
            }
            if !(h.servo_saturation > 0.0 && h.servo_saturation <= 3.0) {
                return Err(bad(key("servo_saturation"), "must be in (0, 3]"));
            }
        }
        for (table, spec, most, unit) in [
            (
                "acceleration",
                &self.acceleration,
                1e4,
                "10000] rad/s² (or m/s²)",
            ),
            ("jerk", &self.jerk, 1e6, "1000000] rad/s³ (or m/s³)"),
        ] {
            let named = spec
                .joints
                .iter()
                .map(|(j, v)| (format!("{table}.joints.{j}"), *v));
            let groups = [("default", spec.default), ("hand", spec.hand)]
                .into_iter()
                .filter_map(|(k, v)| v.map(|v| (format!("{table}.{k}"), v)));
            if let Some((k, _)) = groups
                .chain(named)
                .find(|(_, v)| !(v.is_finite() && *v > 0.0 && *v <= most))
            {
                return Err(bad(k, &format!("must be in (0, {unit}")));
            }
        }
        let c = &self.clearance;
        for (k, v) in [("clearance.body", c.body), ("clearance.hand", c.hand)] {
            if v.is_some_and(|v| !(v.is_finite() && (0.0..=0.1).contains(&v))) {
                return Err(bad(k.into(), "must be 0 to 0.1 m"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_humanoid_description_parses() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../models/robots/tsukami_humanoid/description.toml"
        );
        let d = Description::parse(&std::fs::read_to_string(path).unwrap(), "d").unwrap();
        assert_eq!(d.hands[0].palm_link, "r_palm");
        assert_eq!(d.waist, ["waist_yaw", "waist_pitch"]);
    }

    #[test]
    fn unknown_keys_and_bad_values_are_named() {
        let e = Description::parse("urdf = \"a\"\nhands = []\n", "d.toml").unwrap_err();
        assert!(e.to_string().contains("d.toml"), "{e}");
        let text = r#"
            urdf = "a.urdf"
            [[hand]]
            name = "r"
            palm_link = "p"
            arm = ["a"]
            wrist = ["b"]
            grasp_types = "g.toml"
            fingers = [{ name = "t", tip = "t", flex = [] }]
        "#;
        let e = Description::parse(text, "d.toml").unwrap_err();
        assert!(e.to_string().contains("hand[0].wrist"), "{e}");
        let ok = text.replace("wrist = [\"b\"]", "wrist = [\"a\"]");
        for (extra, key) in [
            ("[acceleration]\nhand = -1.0\n", "acceleration.hand"),
            (
                "[acceleration]\njoints = { a = 0.0 }\n",
                "acceleration.joints.a",
            ),
            ("[clearance]\nbody = 0.5\n", "clearance.body"),
            ("[jerk]\ndefault = 0.0\n", "jerk.default"),
        ] {
            let e = Description::parse(&format!("{ok}\n{extra}"), "d.toml").unwrap_err();
            assert!(e.to_string().contains(key), "{e}");
        }
        let d =
            Description::parse(&format!("{ok}\n[clearance]\nhand = 0.005\n"), "d.toml").unwrap();
        assert_eq!((d.clearance.hand, d.clearance.body), (Some(0.005), None));
    }
}
