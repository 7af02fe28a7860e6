//! The JSON contract of `tsukami fc`: force-closure problems in, one result per
//! problem out, malformed problems answered with an error object.
//!
//! [`solve_json`] takes the text of one problem or of an array of problems and
//! returns the text of one result (or an array of results in the same order).
//! It does no I/O; the CLI reads the input and prints the answer.
//!
//! # Problem
//!
//! ```json
//! {"contacts": [{"position": [x,y,z], "normal": [nx,ny,nz]}, …],
//!  "mu": 0.5, "f_max": 10.0, "mass": 0.15, "center_of_mass": [x,y,z],
//!  "gravity": [0,0,-9.81], "characteristic_length": 0.06,
//!  "methods": ["ellipsoid","exact","ferrari_canny"]}
//! ```
//!
//! World frame, metres, newtons, kilograms. `normal` is the unit normal pointing
//! **into** the object. Torques are taken about `center_of_mass` with scale
//! `γ = 1 / characteristic_length`, so the weight is a pure force. `gravity`
//! defaults to `[0, 0, -9.81]`, `methods` to all three. Optional fields (added
//! to the contract; ignored fields are allowed):
//!
//! | field | default | meaning |
//! | --- | --- | --- |
//! | `contacts[i].f_max` | `f_max` | this contact's force limit |
//! | `contacts[i].finger` | — | `{"jacobian": [[…k],[…k],[…k]], "effort_limits": […k]}`: limit from [`crate::finger_force`] (used when finite) |
//! | `alpha` | `1/√2` | ellipsoid normal semi-axis ratio |
//! | `ellipsoid_centre` | `"inscribed"` | `"inscribed"` (centre `f_max/(1+α)`) or `"paper"` (centre `f_max`) |
//! | `ellipsoid_scales` | `[1.0]` | several ellipsoids per cone, e.g. `[1.0, 0.5]` (every combination must pass) |
//! | `delta_f` | `0` | ellipsoid acceptance threshold `δf` |
//! | `exact_cone` | `"circular"` | `"circular"` or `"polyhedral"` (with `cone_sides`) |
//! | `cone_sides` | `8` | pyramid sides for Ferrari–Canny (and a polyhedral exact cone) |
//!
//! # Result
//!
//! ```json
//! {"ellipsoid": {"force_closure": bool, "resists_weight": bool, "margin": f64, "time_ns": u64, …},
//!  "exact": {"force_closure": bool, "resists_weight": bool, "weight_scale": f64,
//!            "forces": [[fx,fy,fz], …], "time_ns": u64, …},
//!  "ferrari_canny": {"epsilon_l1": f64, "epsilon_linf": f64, "time_ns": u64, …}}
//! ```
//!
//! Only the requested methods appear. `margin` is the paper's `n − f` at the
//! weight (the posture is accepted when `margin ≥ δf`); `closure_margin` is
//! `n − f(0)`. A degenerate (flat) ellipsoid gives an infinite `f`; JSON has
//! no infinities, so infinite values are written as `±1.7976931348623157e308`
//! (`±f64::MAX`). `epsilon_linf` is `null`, with `linf_error` saying why, when
//! the L∞ Minkowski sum exceeds the point limit. `time_ns` is measured around
//! that method's call alone.
//!
//! # Errors
//!
//! A problem that cannot be evaluated is answered, in its place, with
//! `{"error": {"code", "message", "index", "field"}}`; the others are still
//! answered. `field` is a path such as `contacts[1].normal` (or `null`), `index`
//! the problem's position (0 for a single problem; `null` when the document
//! itself does not parse, which is answered with that one error). JSON has no
//! NaN: a non-number where a number belongs is an `invalid_type`.

use std::time::Instant;

use nalgebra::{DVector, Matrix3xX, Point3, Vector3};
use serde::{Deserialize, Serialize, Serializer};
use serde_json::{Map, Value};

use crate::contact::{Contact, ContactError};
use crate::ellipsoid::{ellipsoid_test, multi_ellipsoid_test, EllipsoidModel, DEFAULT_ALPHA};
use crate::exact::{exact_test, ConeModel};
use crate::ferrari_canny::{epsilon_l1, epsilon_linf, FerrariCannyOptions};
use crate::finger_force::max_finger_force;
use crate::grasp::{Grasp, GraspError};

/// Gravity when a problem gives none (m/s²).
pub const DEFAULT_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// Most ellipsoid combinations (`k^n`) one problem may ask for.
pub const MAX_ELLIPSOID_COMBINATIONS: u64 = 1 << 20;

/// A force-closure method of the contract.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// The paper's ellipsoid test ([`crate::ellipsoid`]).
    Ellipsoid,
    /// The conic reference ([`crate::exact`]).
    Exact,
    /// Ferrari–Canny ε ([`crate::ferrari_canny`]).
    FerrariCanny,
}

impl Method {
    /// All methods, in contract order.
    pub const ALL: [Method; 3] = [Method::Ellipsoid, Method::Exact, Method::FerrariCanny];

    /// The contract name.
    pub fn name(self) -> &'static str {
        match self {
            Method::Ellipsoid => "ellipsoid",
            Method::Exact => "exact",
            Method::FerrariCanny => "ferrari_canny",
        }
    }

    fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == s)
    }
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
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FingerSpec {
    /// 3×k translational Jacobian, as three rows of k entries.
    pub jacobian: [Vec<f64>; 3],
    /// k joint effort limits.
    pub effort_limits: Vec<f64>,
}

/// One contact of a problem.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactSpec {
    /// Contact point (m).
    pub position: [f64; 3],
    /// Unit normal into the object.
    pub normal: [f64; 3],
    /// This contact's force limit (N), overriding the problem's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub f_max: Option<f64>,
    /// Finger model giving this contact's force limit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finger: Option<FingerSpec>,
}

/// One force-closure problem (see the module docs for the JSON form).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Value")]
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
    pub gravity: [f64; 3],
    /// Characteristic length (m); `γ = 1 / characteristic_length`.
    pub characteristic_length: f64,
    /// Methods to run.
    pub methods: Vec<Method>,
    /// Ellipsoid normal semi-axis ratio `α`.
    pub alpha: f64,
    /// Ellipsoid placement.
    pub ellipsoid_centre: EllipsoidCentre,
    /// Scales of the ellipsoids per cone (one entry: the single-ellipsoid test).
    pub ellipsoid_scales: Vec<f64>,
    /// Ellipsoid acceptance threshold `δf`.
    pub delta_f: f64,
    /// Cone of the exact method.
    pub exact_cone: ExactCone,
    /// Pyramid sides for Ferrari–Canny and the polyhedral exact cone.
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
    #[error("{field} must be {expected}")]
    InvalidType {
        /// Path of the field.
        field: String,
        /// What was expected.
        expected: &'static str,
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
    #[error("{field}: unknown method {name:?} (expected ellipsoid, exact or ferrari_canny)")]
    UnknownMethod {
        /// Path of the entry.
        field: String,
        /// The name given.
        name: String,
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
}

// ---- parsing (one parser: `Deserialize` for `Problem` goes through it) ----

fn get<'a>(obj: &'a Map<String, Value>, key: &str, path: &str) -> Result<&'a Value, ProblemError> {
    obj.get(key).ok_or_else(|| ProblemError::MissingField {
        field: join(path, key),
    })
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

fn number(v: &Value, field: &str) -> Result<f64, ProblemError> {
    let x = v.as_f64().ok_or_else(|| ProblemError::InvalidType {
        field: field.to_string(),
        expected: "a number",
    })?;
    finite(x, field)
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

fn numbers(v: &Value, field: &str) -> Result<Vec<f64>, ProblemError> {
    let arr = v.as_array().ok_or_else(|| ProblemError::InvalidType {
        field: field.to_string(),
        expected: "an array of numbers",
    })?;
    arr.iter()
        .enumerate()
        .map(|(i, x)| number(x, &format!("{field}[{i}]")))
        .collect()
}

fn vec3(v: &Value, field: &str) -> Result<[f64; 3], ProblemError> {
    let xs = numbers(v, field)?;
    <[f64; 3]>::try_from(xs).map_err(|_| ProblemError::InvalidType {
        field: field.to_string(),
        expected: "an array of 3 numbers",
    })
}

fn object<'a>(v: &'a Value, field: &str) -> Result<&'a Map<String, Value>, ProblemError> {
    v.as_object().ok_or_else(|| ProblemError::NotAnObject {
        field: if field.is_empty() {
            "problem".into()
        } else {
            field.to_string()
        },
    })
}

fn string<'a>(v: &'a Value, field: &str) -> Result<&'a str, ProblemError> {
    v.as_str().ok_or_else(|| ProblemError::InvalidType {
        field: field.to_string(),
        expected: "a string",
    })
}

fn parse_finger(v: &Value, field: &str) -> Result<FingerSpec, ProblemError> {
    let obj = object(v, field)?;
    let jf = join(field, "jacobian");
    let rows = get(obj, "jacobian", field)?
        .as_array()
        .filter(|r| r.len() == 3)
        .ok_or_else(|| ProblemError::InvalidType {
            field: jf.clone(),
            expected: "an array of 3 rows",
        })?;
    let r: Vec<Vec<f64>> = rows
        .iter()
        .enumerate()
        .map(|(i, row)| numbers(row, &format!("{jf}[{i}]")))
        .collect::<Result<_, _>>()?;
    let effort_limits = numbers(
        get(obj, "effort_limits", field)?,
        &join(field, "effort_limits"),
    )?;
    let k = effort_limits.len();
    if r.iter().any(|row| row.len() != k) {
        return Err(ProblemError::InvalidValue {
            field: jf,
            message: format!("every row must have {k} entries, one per effort limit"),
        });
    }
    let [a, b, c]: [Vec<f64>; 3] = r.try_into().map_err(|_| ProblemError::InvalidType {
        field: join(field, "jacobian"),
        expected: "an array of 3 rows",
    })?;
    Ok(FingerSpec {
        jacobian: [a, b, c],
        effort_limits,
    })
}

impl Problem {
    /// Parses one problem from a JSON value, naming the first bad field.
    pub fn from_value(v: &Value) -> Result<Self, ProblemError> {
        let obj = object(v, "")?;
        let contacts_v =
            get(obj, "contacts", "")?
                .as_array()
                .ok_or_else(|| ProblemError::InvalidType {
                    field: "contacts".into(),
                    expected: "an array of contacts",
                })?;
        let mut contacts = Vec::with_capacity(contacts_v.len());
        for (i, c) in contacts_v.iter().enumerate() {
            let path = format!("contacts[{i}]");
            let co = object(c, &path)?;
            contacts.push(ContactSpec {
                position: vec3(get(co, "position", &path)?, &join(&path, "position"))?,
                normal: vec3(get(co, "normal", &path)?, &join(&path, "normal"))?,
                f_max: co
                    .get("f_max")
                    .map(|x| number(x, &join(&path, "f_max")))
                    .transpose()?,
                finger: co
                    .get("finger")
                    .map(|x| parse_finger(x, &join(&path, "finger")))
                    .transpose()?,
            });
        }
        let opt_num = |key: &str| obj.get(key).map(|x| number(x, key)).transpose();
        let methods = match obj.get("methods") {
            None => Method::ALL.to_vec(),
            Some(m) => {
                let arr = m.as_array().ok_or_else(|| ProblemError::InvalidType {
                    field: "methods".into(),
                    expected: "an array of method names",
                })?;
                let mut out = Vec::new();
                for (i, s) in arr.iter().enumerate() {
                    let field = format!("methods[{i}]");
                    let name = string(s, &field)?;
                    let m = Method::parse(name).ok_or_else(|| ProblemError::UnknownMethod {
                        field,
                        name: name.to_string(),
                    })?;
                    if !out.contains(&m) {
                        out.push(m);
                    }
                }
                out
            }
        };
        let ellipsoid_centre = match obj.get("ellipsoid_centre") {
            None => EllipsoidCentre::Inscribed,
            Some(v) => match string(v, "ellipsoid_centre")? {
                "inscribed" => EllipsoidCentre::Inscribed,
                "paper" => EllipsoidCentre::Paper,
                other => {
                    return Err(ProblemError::InvalidValue {
                        field: "ellipsoid_centre".into(),
                        message: format!("expected \"inscribed\" or \"paper\", got {other:?}"),
                    })
                }
            },
        };
        let exact_cone = match obj.get("exact_cone") {
            None => ExactCone::Circular,
            Some(v) => match string(v, "exact_cone")? {
                "circular" => ExactCone::Circular,
                "polyhedral" => ExactCone::Polyhedral,
                other => {
                    return Err(ProblemError::InvalidValue {
                        field: "exact_cone".into(),
                        message: format!("expected \"circular\" or \"polyhedral\", got {other:?}"),
                    })
                }
            },
        };
        let cone_sides = match obj.get("cone_sides") {
            None => FerrariCannyOptions::default().sides,
            Some(v) => v
                .as_u64()
                .filter(|&k| (3..=64).contains(&k))
                .ok_or_else(|| ProblemError::InvalidValue {
                    field: "cone_sides".into(),
                    message: "must be an integer from 3 to 64".into(),
                })? as usize,
        };
        let problem = Problem {
            contacts,
            mu: number(get(obj, "mu", "")?, "mu")?,
            f_max: number(get(obj, "f_max", "")?, "f_max")?,
            mass: number(get(obj, "mass", "")?, "mass")?,
            center_of_mass: vec3(get(obj, "center_of_mass", "")?, "center_of_mass")?,
            gravity: obj
                .get("gravity")
                .map(|g| vec3(g, "gravity"))
                .transpose()?
                .unwrap_or(DEFAULT_GRAVITY),
            characteristic_length: number(
                get(obj, "characteristic_length", "")?,
                "characteristic_length",
            )?,
            methods,
            alpha: opt_num("alpha")?.unwrap_or(DEFAULT_ALPHA),
            ellipsoid_centre,
            ellipsoid_scales: obj
                .get("ellipsoid_scales")
                .map(|v| numbers(v, "ellipsoid_scales"))
                .transpose()?
                .unwrap_or_else(|| vec![1.0]),
            delta_f: opt_num("delta_f")?.unwrap_or(0.0),
            exact_cone,
            cone_sides,
        };
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
            return Err(ProblemError::InvalidValue {
                field: "gravity".into(),
                message: "must be non-zero (the weight test needs a weight)".into(),
            });
        }
        if self.methods.is_empty() {
            return Err(ProblemError::InvalidValue {
                field: "methods".into(),
                message: "at least one method is needed".into(),
            });
        }
        positive(self.alpha, "alpha")?;
        finite(self.delta_f, "delta_f")?;
        if self.ellipsoid_scales.is_empty() {
            return Err(ProblemError::InvalidValue {
                field: "ellipsoid_scales".into(),
                message: "at least one scale is needed".into(),
            });
        }
        for (k, s) in self.ellipsoid_scales.iter().enumerate() {
            positive(*s, &format!("ellipsoid_scales[{k}]"))?;
        }
        if !(3..=64).contains(&self.cone_sides) {
            return Err(ProblemError::InvalidValue {
                field: "cone_sides".into(),
                message: "must be an integer from 3 to 64".into(),
            });
        }
        Ok(())
    }

    /// The validated [`Grasp`] (reference point: the centre of mass) and its
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
            other => ProblemError::InvalidValue {
                field: "contacts".into(),
                message: other.to_string(),
            },
        })
    }

    fn ellipsoid_models(&self) -> Vec<EllipsoidModel> {
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

impl TryFrom<Value> for Problem {
    type Error = ProblemError;
    fn try_from(v: Value) -> Result<Self, Self::Error> {
        Problem::from_value(&v)
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
        return Err(ProblemError::InvalidValue {
            field: join(path, "jacobian"),
            message: format!("must be 3 rows of {k} entries, with at least one joint"),
        });
    }
    let j = Matrix3xX::from_fn(k, |r, c| finger.jacobian[r][c]);
    let n = Vector3::from(*normal);
    max_finger_force(
        &j,
        &DVector::from_vec(finger.effort_limits.clone()),
        &n.normalize(),
    )
    .map(|f| f.force)
    .map_err(|e| ProblemError::InvalidValue {
        field: path.to_string(),
        message: e.to_string(),
    })
}

// ---- results ----

/// Writes non-finite numbers as `±f64::MAX` (JSON has no infinities).
fn finite_f64<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    let y = if x.is_nan() {
        f64::MIN
    } else {
        x.clamp(f64::MIN, f64::MAX)
    };
    s.serialize_f64(y)
}

/// Ellipsoid test result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EllipsoidResult {
    /// `n − f(0) > δf` with a non-degenerate wrench set.
    pub force_closure: bool,
    /// `n − f(−w_weight) ≥ δf`.
    pub resists_weight: bool,
    /// `n − f(−w_weight)`, the paper's margin (worst combination with several ellipsoids).
    #[serde(serialize_with = "finite_f64")]
    pub margin: f64,
    /// `n − f(0)`.
    #[serde(serialize_with = "finite_f64")]
    pub closure_margin: f64,
    /// With several ellipsoids per cone: the best combination's weight margin.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub best_margin: Option<f64>,
    /// Number of ellipsoid combinations evaluated (`k^n`).
    pub combinations: u64,
    /// `G U⁻¹ Gᵀ` was singular for some combination.
    pub degenerate: bool,
    /// Time of this method's call (ns).
    pub time_ns: u64,
}

/// Exact method result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExactResult {
    /// Exact force closure.
    pub force_closure: bool,
    /// `weight_scale ≥ 1`.
    pub resists_weight: bool,
    /// Largest multiple of the weight the grasp balances.
    pub weight_scale: f64,
    /// Contact forces (world, N) balancing `weight_scale` × the weight.
    pub forces: Vec<[f64; 3]>,
    /// Internal squeeze margin `τ*` (N).
    pub squeeze_margin: f64,
    /// Numerical rank of `G`.
    pub grasp_rank: usize,
    /// Time of this method's call (ns).
    pub time_ns: u64,
}

/// Ferrari–Canny result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FerrariCannyResult {
    /// ε of the L1 wrench space (N).
    pub epsilon_l1: f64,
    /// ε of the L∞ wrench space (N); `null` when over the size limit.
    pub epsilon_linf: Option<f64>,
    /// Why `epsilon_linf` is missing.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub linf_error: Option<String>,
    /// Pyramid sides used.
    pub cone_sides: usize,
    /// Time of this method's call (ns).
    pub time_ns: u64,
}

/// One problem's answer: one entry per requested method.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ProblemResult {
    /// Ellipsoid test, if requested.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub ellipsoid: Option<EllipsoidResult>,
    /// Exact method, if requested.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub exact: Option<ExactResult>,
    /// Ferrari–Canny ε, if requested.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub ferrari_canny: Option<FerrariCannyResult>,
}

fn elapsed_ns(t: Instant) -> u64 {
    u64::try_from(t.elapsed().as_nanos()).unwrap_or(u64::MAX)
}

/// Runs the requested methods on one problem.
pub fn solve_problem(problem: &Problem) -> Result<ProblemResult, ProblemError> {
    let grasp = problem.grasp()?;
    let weight = grasp.weight_wrench(
        problem.mass,
        &Vector3::from(problem.gravity),
        &Point3::from(problem.center_of_mass),
    );
    let mut out = ProblemResult::default();
    for method in &problem.methods {
        match method {
            Method::Ellipsoid => {
                let models = problem.ellipsoid_models();
                let delta_f = problem.delta_f;
                let result = if let [model] = models.as_slice() {
                    let t0 = Instant::now();
                    let t = ellipsoid_test(&grasp, model, &weight);
                    let time_ns = elapsed_ns(t0);
                    EllipsoidResult {
                        force_closure: t.force_closure(delta_f),
                        resists_weight: t.resists(delta_f),
                        margin: t.margin(),
                        closure_margin: t.closure_margin(),
                        best_margin: None,
                        combinations: 1,
                        degenerate: t.degenerate,
                        time_ns,
                    }
                } else {
                    let t0 = Instant::now();
                    let t =
                        multi_ellipsoid_test(&grasp, &models, &weight, MAX_ELLIPSOID_COMBINATIONS)
                            .map_err(|e| ProblemError::MethodFailed {
                                method: "ellipsoid",
                                message: e.to_string(),
                            })?;
                    let time_ns = elapsed_ns(t0);
                    EllipsoidResult {
                        force_closure: t.worst.force_closure(delta_f),
                        resists_weight: t.worst.resists(delta_f),
                        margin: t.worst.margin(),
                        closure_margin: t.worst.closure_margin(),
                        best_margin: Some(t.best.margin()).filter(|m| m.is_finite()),
                        combinations: t.combinations,
                        degenerate: t.worst.degenerate,
                        time_ns,
                    }
                };
                out.ellipsoid = Some(result);
            }
            Method::Exact => {
                let cone = match problem.exact_cone {
                    ExactCone::Circular => ConeModel::Circular,
                    ExactCone::Polyhedral => ConeModel::Polyhedral {
                        sides: problem.cone_sides,
                    },
                };
                let t0 = Instant::now();
                let t =
                    exact_test(&grasp, cone, &weight).map_err(|e| ProblemError::MethodFailed {
                        method: "exact",
                        message: e.to_string(),
                    })?;
                let time_ns = elapsed_ns(t0);
                out.exact = Some(ExactResult {
                    force_closure: t.closure.force_closure,
                    resists_weight: t.resists_weight(),
                    weight_scale: t.weight.weight_scale,
                    forces: t.weight.forces.iter().map(|f| [f.x, f.y, f.z]).collect(),
                    squeeze_margin: t.closure.squeeze_margin,
                    grasp_rank: t.closure.grasp_rank,
                    time_ns,
                });
            }
            Method::FerrariCanny => {
                let options = FerrariCannyOptions {
                    sides: problem.cone_sides,
                    ..FerrariCannyOptions::default()
                };
                let t0 = Instant::now();
                let l1 = epsilon_l1(&grasp, options.sides);
                let linf = epsilon_linf(&grasp, &options);
                let time_ns = elapsed_ns(t0);
                let epsilon_l1 = l1.map_err(|e| ProblemError::MethodFailed {
                    method: "ferrari_canny",
                    message: e.to_string(),
                })?;
                let (epsilon_linf, linf_error) = match linf {
                    Ok(e) => (Some(e), None),
                    Err(e) => (None, Some(e.to_string())),
                };
                out.ferrari_canny = Some(FerrariCannyResult {
                    epsilon_l1,
                    epsilon_linf,
                    linf_error,
                    cone_sides: options.sides,
                    time_ns,
                });
            }
        }
    }
    Ok(out)
}

/// Answers one problem given as a JSON value: a result object or an error object.
pub fn solve_value(v: &Value, index: usize) -> Value {
    match Problem::from_value(v).and_then(|p| solve_problem(&p)) {
        Ok(r) => serde_json::to_value(r).unwrap_or_else(|e| {
            ProblemError::MethodFailed {
                method: "serialize",
                message: e.to_string(),
            }
            .to_json(Some(index))
        }),
        Err(e) => e.to_json(Some(index)),
    }
}

/// Answers a JSON document holding one problem or an array of problems: one
/// result (or error object) per problem, in the same order, as JSON text.
/// A document that is not JSON is answered with a single error object.
pub fn solve_json(input: &str) -> String {
    let answer = match serde_json::from_str::<Value>(input) {
        Err(e) => ProblemError::Parse(e.to_string()).to_json(None),
        Ok(Value::Array(problems)) => Value::Array(
            problems
                .iter()
                .enumerate()
                .map(|(i, p)| solve_value(p, i))
                .collect(),
        ),
        Ok(one) => solve_value(&one, 0),
    };
    answer.to_string()
}
