//! The planner kit's conformance suite (`tsukami_planner_kit::conformance`)
//! over a real bus, for the built-in planner and the third-party template: each
//! runs in a fresh host on loopback, loaded from its real plugin file.

use std::time::Duration;

use serde_json::Value;
use tsukami::client::{BusClient, RequestError};
use tsukami_e2e::{grasp_planner_entry, test_config, TestBus};
use tsukami_msgs::keys::ROLE_GRASP_PLANNER;
use tsukami_planner_kit::conformance::{run, Transport, WireError};

const T: Duration = Duration::from_secs(60);

struct Bus<'a>(&'a BusClient);

impl Transport for Bus<'_> {
    fn call(&self, command: &str, payload: &[u8]) -> Result<Value, WireError> {
        match self.0.command(ROLE_GRASP_PLANNER, command, payload, T) {
            Ok(bytes) => serde_json::from_slice(&bytes).map_err(|e| WireError {
                code: "internal".into(),
                message: format!("reply is not JSON: {e}"),
                details: Value::Null,
            }),
            Err(RequestError::Reply(r)) => Err(WireError {
                code: r.error.code.as_str().into(),
                message: r.error.message,
                details: r.error.details.unwrap_or(Value::Null),
            }),
            Err(e) => Err(WireError {
                code: "no_reply".into(),
                message: e.to_string(),
                details: Value::Null,
            }),
        }
    }
}

fn conforms(lib_name: &str) {
    let bus = TestBus::start(test_config(vec![grasp_planner_entry(lib_name)]));
    let report = run(&Bus(&bus.client), "tsukami_humanoid");
    assert!(report.checks > 40, "{} checks", report.checks);
    assert!(
        report.failures.is_empty(),
        "{lib_name}: {} of {} checks failed:\n{}",
        report.failures.len(),
        report.checks,
        report.failures.join("\n")
    );
}

#[test]
fn the_built_in_planner_conforms() {
    conforms("tsukami_grasp_planner");
}

#[test]
fn the_template_planner_conforms() {
    conforms("tsukami_antipodal_planner");
}
