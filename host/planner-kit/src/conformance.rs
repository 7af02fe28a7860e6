//! A conformance suite any grasp-planner plugin runs in its own tests.
//!
//! What: [`run`] drives a planner through a [`Transport`] — the real bus in
//! `tests/tests/conformance.rs`, or in-process — and checks the protocol: the
//! order of commands (`not_ready`), bad input of every kind with its error
//! code and the field it names, state kept after every refused request (the
//! same seed then plans the same grasp), the world version in every reply,
//! finite numbers everywhere, `stop`, and `unknown_command`. It returns every
//! failure found, not just the first.
//!
//! Why: a planner built on the kit passes by construction of the kit; the
//! suite proves it over the real boundary, and tells the author of any other
//! planner what the protocol expects.
//!
//! How: the transport must start from a planner with nothing set. The suite
//! uses the `tsukami_humanoid` robot and the `can_350ml` object of the
//! project's `models/`.

use serde_json::{json, Value};

/// An error reply as the suite sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct WireError {
    /// The error code.
    pub code: String,
    /// The message.
    pub message: String,
    /// The details (or `null`).
    pub details: Value,
}

/// How the suite reaches the planner: one command at a time, or `stop` from
/// another thread while a call runs.
pub trait Transport: Sync {
    /// Sends `command` with a JSON payload; the reply's JSON or the error.
    fn call(&self, command: &str, payload: &[u8]) -> Result<Value, WireError>;
}

/// What the suite found.
#[derive(Debug, Default)]
pub struct Report {
    /// Checks run.
    pub checks: usize,
    /// Failures, each naming the check.
    pub failures: Vec<String>,
}

impl Report {
    fn check(&mut self, ok: bool, what: impl FnOnce() -> String) {
        self.checks += 1;
        if !ok {
            self.failures.push(what());
        }
    }

    fn expect_error(
        &mut self,
        t: &dyn Transport,
        name: &str,
        cmd: &str,
        payload: &str,
        code: &str,
        field: Option<&str>,
    ) {
        match t.call(cmd, payload.as_bytes()) {
            Ok(v) => self.check(false, || format!("{name}: `{cmd}` accepted {payload}: {v}")),
            Err(e) => {
                self.check(e.code == code, || {
                    format!("{name}: code {} (want {code}): {}", e.code, e.message)
                });
                if let Some(f) = field {
                    let named = e.details["field"]
                        .as_str()
                        .is_some_and(|d| d.starts_with(f))
                        || e.message.contains(f);
                    self.check(named, || {
                        format!(
                            "{name}: error does not name `{f}`: {} {}",
                            e.message, e.details
                        )
                    });
                }
            }
        }
    }

    fn expect_ok(
        &mut self,
        t: &dyn Transport,
        name: &str,
        cmd: &str,
        payload: &str,
    ) -> Option<Value> {
        match t.call(cmd, payload.as_bytes()) {
            Ok(v) => {
                self.check(all_finite(&v), || {
                    format!("{name}: reply has a non-number where a number belongs")
                });
                Some(v)
            }
            Err(e) => {
                self.check(false, || {
                    format!("{name}: `{cmd}` failed: {} {}", e.code, e.message)
                });
                None
            }
        }
    }
}

fn all_finite(v: &Value) -> bool {
    match v {
        Value::Number(n) => n.as_f64().is_some_and(f64::is_finite),
        Value::Array(a) => a.iter().all(all_finite),
        Value::Object(o) => o.values().all(all_finite),
        _ => true,
    }
}

/// The object the suite places (the paper's can at breast height).
pub const CAN: &str = r#"{"shape": {"model": {"name": "can_350ml"}}, "mass": 0.15, "pose": {"position": [0.45, -0.25, 1.05]}}"#;

fn with(base: &str, key: &str, value: Value) -> String {
    let mut v: Value = serde_json::from_str(base).unwrap_or_default();
    v[key] = value;
    v.to_string()
}

/// The grasp-relevant part of a plan reply (timing left out).
fn grasp_of(v: &Value) -> Value {
    json!([
        v["grasp_type"],
        v["palm_pose"],
        v["joint_positions"],
        v["contacts"],
        v["samples"]
    ])
}

fn bad_objects() -> Vec<(&'static str, String, &'static str, Option<&'static str>)> {
    vec![
        (
            "position far away",
            with(CAN, "pose", json!({"position": [1e308, 0, 0]})),
            "invalid_value",
            Some("pose.position"),
        ),
        (
            "zero quaternion",
            with(
                CAN,
                "pose",
                json!({"position": [0.4, -0.2, 1.0], "quaternion": [0, 0, 0, 0]}),
            ),
            "invalid_value",
            Some("pose.quaternion"),
        ),
        (
            "negative mass",
            with(CAN, "mass", json!(-1.0)),
            "invalid_value",
            Some("mass"),
        ),
        (
            "friction out of range",
            with(CAN, "friction", json!(50.0)),
            "invalid_value",
            Some("friction"),
        ),
        (
            "centre of mass outside",
            with(CAN, "center_of_mass", json!([10.0, 0, 0])),
            "invalid_value",
            Some("center_of_mass"),
        ),
        (
            "unknown model",
            with(CAN, "shape", json!({"model": {"name": "teapot"}})),
            "model_error",
            Some("shape"),
        ),
        (
            "mesh outside the roots",
            with(CAN, "shape", json!({"mesh": {"path": "/etc/passwd"}})),
            "model_error",
            Some("shape"),
        ),
        (
            "inline mesh not base64",
            with(
                CAN,
                "shape",
                json!({"inline": {"format": "stl", "data_base64": "%%%%"}}),
            ),
            "invalid_value",
            Some("shape.inline.data_base64"),
        ),
        (
            "inline mesh that is no mesh",
            with(
                CAN,
                "shape",
                json!({"inline": {"format": "stl", "data_base64": "AAAAAAAAAAAAAAAA"}}),
            ),
            "model_error",
            Some("shape.inline"),
        ),
        (
            "misspelt field",
            with(CAN, "mas", json!(1.0)),
            "invalid_request",
            Some("mas"),
        ),
        ("a list for an object", "[]".into(), "invalid_request", None),
    ]
}

/// Runs the whole suite on a planner with nothing set; `robot` is the robot name.
pub fn run(t: &dyn Transport, robot: &str) -> Report {
    let mut r = Report::default();
    let set_robot = json!({ "robot": robot }).to_string();
    r.expect_error(t, "plan before set_robot", "plan", "{}", "not_ready", None);
    r.expect_error(
        t,
        "unknown robot",
        "set_robot",
        r#"{"robot": "no_such_robot"}"#,
        "model_error",
        Some("robot"),
    );
    r.expect_error(
        t,
        "robot outside the roots",
        "set_robot",
        r#"{"robot": "/etc/passwd.urdf"}"#,
        "model_error",
        Some("robot"),
    );
    r.expect_error(
        t,
        "misspelt robot field",
        "set_robot",
        r#"{"robt": "x"}"#,
        "invalid_request",
        Some("robt"),
    );
    let robot_reply = r.expect_ok(t, "set_robot", "set_robot", &set_robot);
    let v0 = robot_reply
        .as_ref()
        .and_then(|v| v["world_version"].as_u64())
        .unwrap_or(0);
    r.check(v0 > 0, || "set_robot reply names no world version".into());
    r.expect_error(t, "plan before set_object", "plan", "{}", "not_ready", None);
    for (name, payload, code, field) in bad_objects() {
        r.expect_error(t, name, "set_object", &payload, code, field);
    }
    let object = r.expect_ok(t, "set_object", "set_object", CAN);
    let v1 = object
        .as_ref()
        .and_then(|v| v["world_version"].as_u64())
        .unwrap_or(0);
    r.check(v1 > v0, || {
        format!("set_object's world version {v1} does not follow {v0}")
    });
    let table = r#"{"name": "table", "shape": {"box": {"size": [0.6, 1.0, 0.7]}}, "pose": {"position": [0.8, 0, 0.35]}}"#;
    let flat = r#"{"name": "flat", "shape": {"box": {"size": [0.6, 0.0, 0.7]}}, "pose": {"position": [0.8, 0, 0.35]}}"#;
    r.expect_error(
        t,
        "bad obstacle",
        "set_env",
        &format!(r#"{{"obstacles": [{table}, {flat}]}}"#),
        "invalid_value",
        Some("obstacles[1]"),
    );
    r.expect_error(
        t,
        "set_env all or nothing",
        "remove_env",
        r#"{"names": ["table"]}"#,
        "invalid_value",
        Some("names[0]"),
    );
    let first = r.expect_ok(t, "plan", "plan", r#"{"seed": 3}"#);
    if let Some(p) = &first {
        r.check(p["world_version"].as_u64() == Some(v1), || {
            format!("plan names world version {} not {v1}", p["world_version"])
        });
        r.check(
            p["force_closure"]["exact_resists_weight"] == json!(true),
            || "plan reply is not force closure".into(),
        );
        r.check(
            p["contacts"].as_array().is_some_and(|c| !c.is_empty()),
            || "plan reply has no contacts".into(),
        );
    }
    for (name, opts, field) in [
        ("zero samples", r#"{"max_samples": 0}"#, "max_samples"),
        (
            "zero time budget",
            r#"{"time_budget_ms": 0}"#,
            "time_budget_ms",
        ),
        (
            "unknown grasp type",
            r#"{"grasp_types": ["no_such_type"]}"#,
            "grasp_types",
        ),
    ] {
        r.expect_error(t, name, "plan", opts, "invalid_value", Some(field));
    }
    r.expect_error(
        t,
        "misspelt option",
        "plan",
        r#"{"sed": 1}"#,
        "invalid_request",
        Some("sed"),
    );
    r.expect_error(
        t,
        "unknown command",
        "frobnicate",
        "{}",
        "unknown_command",
        None,
    );
    let idle = r.expect_ok(t, "stop when idle", "stop", "{}");
    r.check(idle.is_some_and(|v| v["stopped"] == json!(false)), || {
        "stop on an idle planner says it stopped something".into()
    });
    let again = r.expect_ok(t, "plan after errors", "plan", r#"{"seed": 3}"#);
    if let (Some(a), Some(b)) = (&first, &again) {
        r.check(grasp_of(a) == grasp_of(b), || {
            "the same seed planned another grasp after refused requests: state changed".into()
        });
    }
    r
}

/// A [`Transport`] calling a [`crate::Session`] directly (no bus), for a
/// planner's own unit tests; the bus test is the one that counts.
pub struct InProcess<P: crate::GraspPlanner>(pub crate::Session<P>);

impl<P: crate::GraspPlanner> Transport for InProcess<P> {
    fn call(&self, command: &str, payload: &[u8]) -> Result<Value, WireError> {
        let cancel = std::sync::atomic::AtomicBool::new(false);
        match self.0.handle(command, payload, &cancel, &mut |_| {}) {
            Ok(bytes) => serde_json::from_slice(&bytes).map_err(|e| WireError {
                code: "internal".into(),
                message: format!("reply is not JSON: {e}"),
                details: Value::Null,
            }),
            Err(e) => Err(WireError {
                code: e.code,
                message: e.message,
                details: serde_json::from_str(&e.details_json).unwrap_or(Value::Null),
            }),
        }
    }
}

/// A planner that never finds a grasp: for tests of the kit's own behaviour
/// (world, validation, errors) without a planning algorithm.
pub struct Null;

impl crate::GraspPlanner for Null {
    type RobotData = ();
    type ObjectData = ();
    fn info() -> crate::PlannerInfo {
        crate::PlannerInfo {
            name: "tsukami-null-planner",
            version: env!("CARGO_PKG_VERSION"),
            description: "finds no grasp (kit tests)",
        }
    }
    fn new(_: &crate::PlannerConfig) -> Result<Self, String> {
        Ok(Null)
    }
    fn robot_data(&self, _: &crate::Robot) -> Result<(), crate::KitError> {
        Ok(())
    }
    fn object_data(&self, _: &crate::Object) -> Result<(), crate::KitError> {
        Ok(())
    }
    fn plan(
        &self,
        _: &crate::World<'_, Self>,
        _: &tsukami_msgs::planner::PlanOptions,
        run: &mut crate::Run,
    ) -> Result<crate::Grasp, crate::NoGrasp> {
        run.sample()?;
        run.reject("null planner");
        Err(crate::NoGrasp::Exhausted)
    }
}
