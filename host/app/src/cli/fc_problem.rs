//! The input side of `tsukami fc`: one force-closure problem, read with serde
//! derive, checked, and turned into a [`tsukami_grasp::grasp::Grasp`].
//!
//! **What.** [`Problem`] is the JSON problem; [`Problem::from_value`] reads one
//! and names the first bad field in a [`ProblemError`] (code, message, path).
//! **Why here.** The grasp crate keeps pure functions (contacts, grasp matrix,
//! the three methods); the JSON contract and its error codes belong to the CLI.
//! **How.** `serde_path_to_error` gives the path of a field serde rejects; the
//! serde message's kind (missing field, invalid type or length, unknown
//! variant) picks the contract's code. Value checks (unit normals, positive
//! quantities) run after, in [`Problem::validate`].
//!
//! # Problem
//!
//! ```json
//! {"contacts": [{"position": [x,y,z], "normal": [nx,ny,nz]}, …],
//!  "mu": 0.5, "f_max": 10.0, "mass": 0.15, "center_of_mass": [x,y,z],
//!  "gravity": [0,0,-9.81], "characteristic_length": 0.06,
//!  "methods": ["ellipsoid","exact"]}
//! ```
//!
//! World frame, metres, newtons, kilograms. `normal` is the unit normal pointing
//! **into** the object. Torques are taken about `center_of_mass` with scale
//! `γ = 1 / characteristic_length`, so the weight is a pure force. `gravity`
//! defaults to `[0, 0, -9.81]`; `methods` to the fast two, `["ellipsoid",
//! "exact"]` — Ferrari–Canny (`"ferrari_canny"`, milliseconds for ε_L1 and
//! up to seconds for ε_L∞) runs only when named. Optional fields (unknown
//! fields are ignored):
//!
//! | field | default | meaning |
//! | --- | --- | --- |
//! | `contacts[i].f_max` | `f_max` | this contact's force limit |
//! | `contacts[i].finger` | — | `{"jacobian": [[…k],[…k],[…k]], "effort_limits": […k]}`: limit from `tsukami_grasp::finger_force` (used when finite) |
//! | `alpha` | `1/√2` | ellipsoid normal semi-axis ratio |
//! | `ellipsoid_centre` | `"inscribed"` | `"inscribed"` (centre `f_max/(1+α)`) or `"paper"` (centre `f_max`) |
//! | `ellipsoid_scales` | `[1.0]` | several ellipsoids per cone, e.g. `[1.0, 0.5]` (every combination must pass) |
//! | `delta_f` | `0` | ellipsoid acceptance threshold `δf` |
//! | `exact_cone` | `"circular"` | `"circular"` or `"polyhedral"` (with `cone_sides`) |
//! | `cone_sides` | `8` | pyramid sides for Ferrari–Canny (and a polyhedral exact cone) |

use nalgebra::{DVector, Matrix3xX, Point3, Vector3};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use tsukami_grasp::contact::{Contact, ContactError};
use tsukami_grasp::ellipsoid::{EllipsoidModel, DEFAULT_ALPHA};
use tsukami_grasp::ferrari_canny::FerrariCannyOptions;
use tsukami_grasp::finger_force::max_finger_force;
use tsukami_grasp::grasp::{Grasp, GraspError};

/// Gravity when a problem gives none (m/s²).
pub const DEFAULT_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// A force-closure method of the contract.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// The paper's ellipsoid test (`tsukami_grasp::ellipsoid`).
    Ellipsoid,
    /// The conic reference (`tsukami_grasp::exact`).
    Exact,
    /// Ferrari–Canny ε (`tsukami_grasp::ferrari_canny`).
    FerrariCanny,
}

impl Method {
    /// The methods run when a problem names none: the fast ones.
    pub const DEFAULT: [Method; 2] = [Method::Ellipsoid, Method::Exact];
}

/// Where the ellipsoid of eq. (9) sits on the normal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EllipsoidCentre {
    /// Centre at `f_max/(1+α)`: inside the force bound.
    #[default]
    Inscribed,
    /// Centre at `f_max`, as the paper writes it.
    Paper,
}

/// The cone the exact method uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ExactCone {
    /// Exact Coulomb cone.
    #[default]
    Circular,
    /// `cone_sides`-sided inscribed pyramid.
    Polyhedral,
}

/// A finger's Jacobian and joint effort limits at a contact.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FingerSpec {
    /// 3×k translational Jacobian, as three rows of k entries.
    pub jacobian: [Vec<f64>; 3],
    /// k joint effort limits.
    pub effort_limits: Vec<f64>,
}

/// One contact of a problem.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactSpec {
    /// Contact point (m).
    pub position: [f64; 3],
    /// Unit normal into the object.
    pub normal: [f64; 3],
    /// This contact's force limit (N), overriding the problem's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub f_max: Option<f64>,
    /// Finger model giving this contact's force limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub finger: Option<FingerSpec>,
}

fn default_gravity() -> [f64; 3] {
    DEFAULT_GRAVITY
}
fn default_methods() -> Vec<Method> {
    Method::DEFAULT.to_vec()
}
fn default_alpha() -> f64 {
    DEFAULT_ALPHA
}
fn default_scales() -> Vec<f64> {
    vec![1.0]
}
fn default_sides() -> usize {
    FerrariCannyOptions::default().sides
}

/// One force-closure problem (see the module docs for the JSON form).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Problem {
    /// The contacts.
    pub contacts: Vec<ContactSpec>,
    /// Friction coefficient.
    pub mu: f64,
    /// Normal force limit per contact (N).
    pub f_max: f64,
    /// Object mass (kg).
    pub mass: f64,
    /// Centre of mass; also the point torques are taken about.
    pub center_of_mass: [f64; 3],
    /// Gravity (m/s²).
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    /// Characteristic length (m); `γ = 1 / characteristic_length`.
    pub characteristic_length: f64,
    /// Methods to run (duplicates are run once).
    #[serde(default = "default_methods")]
    pub methods: Vec<Method>,
    /// Ellipsoid normal semi-axis ratio `α`.
    #[serde(default = "default_alpha")]
    pub alpha: f64,
    /// Ellipsoid placement.
    #[serde(default)]
    pub ellipsoid_centre: EllipsoidCentre,
    /// Scales of the ellipsoids per cone (one entry: the single-ellipsoid test).
    #[serde(default = "default_scales")]
    pub ellipsoid_scales: Vec<f64>,
    /// Ellipsoid acceptance threshold `δf`.
    #[serde(default)]
    pub delta_f: f64,
    /// Cone of the exact method.
    #[serde(default)]
    pub exact_cone: ExactCone,
    /// Pyramid sides for Ferrari–Canny and the polyhedral exact cone.
    #[serde(default = "default_sides")]
    pub cone_sides: usize,
}

/// Why a problem could not be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProblemError {
    /// The document is not JSON.
    #[error("input is not valid JSON: {0}")]
    Parse(String),
    /// A problem (or nested element) is not a JSON object.
    #[error("{field} must be an object")]
    NotAnObject {
        /// Path of the element.
        field: String,
    },
    /// A required field is absent.
    #[error("missing field {field}")]
    MissingField {
        /// Path of the field.
        field: String,
    },
    /// A field has the wrong JSON type or length.
    #[error("{field}: {message}")]
    InvalidType {
        /// Path of the field.
        field: String,
        /// What serde expected.
        message: String,
    },
    /// Fewer than two contacts.
    #[error("a problem needs at least 2 contacts, got {count}")]
    TooFewContacts {
        /// Number given.
        count: usize,
    },
    /// A normal that is zero or not of unit length.
    #[error("{field} must be a unit vector, its length is {length}")]
    InvalidNormal {
        /// Path of the normal.
        field: String,
        /// Its length.
        length: f64,
    },
    /// A NaN or infinite number.
    #[error("{field} must be finite")]
    NotFinite {
        /// Path of the field.
        field: String,
    },
    /// A quantity that must be positive is not.
    #[error("{field} must be positive, got {value}")]
    NotPositive {
        /// Path of the field.
        field: String,
        /// The value.
        value: f64,
    },
    /// An unknown method name.
    #[error("{field}: {message} (methods: ellipsoid, exact, ferrari_canny)")]
    UnknownMethod {
        /// Path of the entry.
        field: String,
        /// serde's message, naming the value.
        message: String,
    },
    /// Any other unusable value.
    #[error("{field}: {message}")]
    InvalidValue {
        /// Path of the field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A method failed on a well-formed problem (solver failure, size limit).
    #[error("method {method} failed: {message}")]
    MethodFailed {
        /// The method.
        method: &'static str,
        /// Why.
        message: String,
    },
}

impl ProblemError {
    /// Short machine-readable code of the error object.
    pub fn code(&self) -> &'static str {
        match self {
            ProblemError::Parse(_) => "parse_error",
            ProblemError::NotAnObject { .. } => "not_an_object",
            ProblemError::MissingField { .. } => "missing_field",
            ProblemError::InvalidType { .. } => "invalid_type",
            ProblemError::TooFewContacts { .. } => "too_few_contacts",
            ProblemError::InvalidNormal { .. } => "invalid_normal",
            ProblemError::NotFinite { .. } => "not_finite",
            ProblemError::NotPositive { .. } => "not_positive",
            ProblemError::UnknownMethod { .. } => "unknown_method",
            ProblemError::InvalidValue { .. } => "invalid_value",
            ProblemError::MethodFailed { .. } => "method_failed",
        }
    }

    /// The offending field's path, if one field is to blame.
    pub fn field(&self) -> Option<String> {
        match self {
            ProblemError::Parse(_) => None,
            ProblemError::TooFewContacts { .. } => Some("contacts".into()),
            ProblemError::MethodFailed { method, .. } => Some(format!("methods.{method}")),
            ProblemError::NotAnObject { field }
            | ProblemError::MissingField { field }
            | ProblemError::InvalidType { field, .. }
            | ProblemError::InvalidNormal { field, .. }
            | ProblemError::NotFinite { field }
            | ProblemError::NotPositive { field, .. }
            | ProblemError::UnknownMethod { field, .. }
            | ProblemError::InvalidValue { field, .. } => Some(field.clone()),
        }
    }

    /// The contract's error object, `{"error": {"code", "message", "index", "field"}}`.
    pub fn to_json(&self, index: Option<usize>) -> Value {
        serde_json::json!({"error": {
            "code": self.code(),
            "message": self.to_string(),
            "index": index,
            "field": self.field(),
        }})
    }

    /// Maps a serde error at `path` to the contract's codes. serde's messages
    /// have a fixed form (`missing field `x``, `invalid type: …`, `invalid
    /// length …`, `unknown variant …`); their kind picks the code.
    fn from_serde(path: &serde_path_to_error::Path, message: String) -> Self {
        let at = if path.iter().next().is_none() {
            String::new()
        } else {
            path.to_string()
        };
        if let Some(name) = message
            .strip_prefix("missing field `")
            .and_then(|s| s.split('`').next())
        {
            return ProblemError::MissingField {
                field: join(&at, name),
            };
        }
        if message.starts_with("invalid type") && message.contains("expected struct") {
            return ProblemError::NotAnObject {
                field: if at.is_empty() { "problem".into() } else { at },
            };
        }
        if message.starts_with("unknown variant") {
            return if at.starts_with("methods") {
                ProblemError::UnknownMethod { field: at, message }
            } else {
                ProblemError::InvalidValue { field: at, message }
            };
        }
        if message.starts_with("invalid type") || message.starts_with("invalid length") {
            return ProblemError::InvalidType { field: at, message };
        }
        ProblemError::InvalidValue {
            field: if at.is_empty() { "problem".into() } else { at },
            message,
        }
    }
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

fn finite(x: f64, field: &str) -> Result<f64, ProblemError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(ProblemError::NotFinite {
            field: field.to_string(),
        })
    }
}

fn positive(x: f64, field: &str) -> Result<f64, ProblemError> {
    finite(x, field)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(ProblemError::NotPositive {
            field: field.to_string(),
            value: x,
        })
    }
}

fn invalid(field: &str, message: &str) -> ProblemError {
    ProblemError::InvalidValue {
        field: field.into(),
        message: message.into(),
    }
}

impl Problem {
    /// Reads one problem from a JSON value and checks it, naming the first bad field.
    pub fn from_value(v: &Value) -> Result<Self, ProblemError> {
        let mut problem: Problem = serde_path_to_error::deserialize(v)
            .map_err(|e| ProblemError::from_serde(e.path(), e.inner().to_string()))?;
        let mut seen = Vec::with_capacity(problem.methods.len());
        problem.methods.retain(|m| {
            let new = !seen.contains(m);
            seen.push(*m);
            new
        });
        problem.validate()?;
        Ok(problem)
    }

    /// Checks the values (also for problems built in Rust): at least two
    /// contacts, finite numbers, unit normals, positive `μ`, `f_max`, mass,
    /// length, gravity and ellipsoid parameters.
    pub fn validate(&self) -> Result<(), ProblemError> {
        if self.contacts.len() < 2 {
            return Err(ProblemError::TooFewContacts {
                count: self.contacts.len(),
            });
        }
        for (i, c) in self.contacts.iter().enumerate() {
            let path = format!("contacts[{i}]");
            contact(c, &path)?;
            if let Some(f) = c.f_max {
                positive(f, &join(&path, "f_max"))?;
            }
            if let Some(finger) = &c.finger {
                finger_limit(finger, &c.normal, &join(&path, "finger"))?;
            }
        }
        positive(self.mu, "mu")?;
        positive(self.f_max, "f_max")?;
        positive(self.mass, "mass")?;
        positive(self.characteristic_length, "characteristic_length")?;
        for (k, x) in self.center_of_mass.iter().enumerate() {
            finite(*x, &format!("center_of_mass[{k}]"))?;
        }
        for (k, x) in self.gravity.iter().enumerate() {
            finite(*x, &format!("gravity[{k}]"))?;
        }
        if Vector3::from(self.gravity).norm() == 0.0 {
            return Err(invalid(
                "gravity",
                "must be non-zero (the weight test needs a weight)",
            ));
        }
        if self.methods.is_empty() {
            return Err(invalid("methods", "at least one method is needed"));
        }
        positive(self.alpha, "alpha")?;
        finite(self.delta_f, "delta_f")?;
        if self.ellipsoid_scales.is_empty() {
            return Err(invalid("ellipsoid_scales", "at least one scale is needed"));
        }
        for (k, s) in self.ellipsoid_scales.iter().enumerate() {
            positive(*s, &format!("ellipsoid_scales[{k}]"))?;
        }
        if !(3..=64).contains(&self.cone_sides) {
            return Err(invalid("cone_sides", "must be an integer from 3 to 64"));
        }
        Ok(())
    }

    /// The validated [`Grasp`] (reference point: the centre of mass) with
    /// per-contact force limits.
    pub fn grasp(&self) -> Result<Grasp, ProblemError> {
        self.validate()?;
        let mut contacts = Vec::with_capacity(self.contacts.len());
        let mut limits = Vec::with_capacity(self.contacts.len());
        for (i, c) in self.contacts.iter().enumerate() {
            let path = format!("contacts[{i}]");
            contacts.push(contact(c, &path)?);
            let mut limit = c.f_max.unwrap_or(self.f_max);
            if let Some(finger) = &c.finger {
                let f = finger_limit(finger, &c.normal, &join(&path, "finger"))?;
                if f.is_finite() {
                    limit = f;
                }
            }
            limits.push(limit);
        }
        Grasp::with_force_limits(
            contacts,
            limits,
            self.mu,
            self.characteristic_length,
            Point3::from(self.center_of_mass),
        )
        .map_err(|e| match e {
            GraspError::BadForceLimit { index, value } => ProblemError::NotPositive {
                field: format!("contacts[{index}].finger"),
                value,
            },
            other => invalid("contacts", &other.to_string()),
        })
    }

    /// The ellipsoid models of eq. (9), one per scale.
    pub fn ellipsoid_models(&self) -> Vec<EllipsoidModel> {
        let base = match self.ellipsoid_centre {
            EllipsoidCentre::Inscribed => EllipsoidModel::inscribed(self.alpha),
            EllipsoidCentre::Paper => EllipsoidModel::paper(self.alpha),
        };
        self.ellipsoid_scales
            .iter()
            .map(|&s| base.scaled(s))
            .collect()
    }
}

fn contact(c: &ContactSpec, path: &str) -> Result<Contact, ProblemError> {
    Contact::new(Point3::from(c.position), Vector3::from(c.normal)).map_err(|e| match e {
        ContactError::NonFinitePosition => ProblemError::NotFinite {
            field: join(path, "position"),
        },
        ContactError::NonFiniteNormal => ProblemError::NotFinite {
            field: join(path, "normal"),
        },
        ContactError::NonUnitNormal(length) => ProblemError::InvalidNormal {
            field: join(path, "normal"),
            length,
        },
    })
}

fn finger_limit(finger: &FingerSpec, normal: &[f64; 3], path: &str) -> Result<f64, ProblemError> {
    let k = finger.effort_limits.len();
    if k == 0 || finger.jacobian.iter().any(|r| r.len() != k) {
        return Err(invalid(
            &join(path, "jacobian"),
            &format!("must be 3 rows of {k} entries, with at least one joint"),
        ));
    }
    let j = Matrix3xX::from_fn(k, |r, c| finger.jacobian[r][c]);
    let n = Vector3::from(*normal);
    max_finger_force(
        &j,
        &DVector::from_vec(finger.effort_limits.clone()),
        &n.normalize(),
    )
    .map(|f| f.force)
    .map_err(|e| invalid(path, &e.to_string()))
}
