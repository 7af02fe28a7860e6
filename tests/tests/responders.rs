//! Who may answer: a rogue process on the bus declaring a key the host or a
//! component serves — `motion/plan`, `controller/execute` — as a complete queryable
//! and answering first never wins silently: the caller gets
//! `conflicting_responders` naming the key. Real zenoh on loopback (tcp/127.0.0.1,
//! scouting off), every process a client of one router (`tsukami router`'s
//! set-up), so the rogue reaches every caller. (The host's `no_plugin` fallback for `<ns>/*/stop` standing aside
//! for a component's own `stop`: `hostile.rs`.)

use std::time::{Duration, Instant};
use tsukami::client::{BusClient, RequestError};
use tsukami::config::HostConfig;
use tsukami::server::RunningHost;
use tsukami_bus::{free_loopback_port, BusConfig, BusMode, ComponentArgs};
use tsukami_e2e::mocks::MockController;
use tsukami_e2e::motion_entry;
use tsukami_msgs::{ErrorCode, ErrorReply};
use zenoh::query::Queryable;
use zenoh::Wait;

const T: Duration = Duration::from_secs(5);

/// A process of its own on the bus at `endpoint` that answers every query on `key`
/// at once with `{"accepted": true}`, declared complete (the strongest claim
/// zenoh's default target knows).
struct Rogue {
    session: zenoh::Session,
    _queryable: Queryable<()>,
}

/// A router on a free loopback port, and how a process joins it (client mode).
fn router() -> (zenoh::Session, BusConfig) {
    let endpoint = format!("tcp/127.0.0.1:{}", free_loopback_port().unwrap());
    let router = BusConfig::router(&endpoint).open().expect("router starts");
    let joining = BusConfig {
        mode: BusMode::Client,
        ..BusConfig::connecting(&endpoint)
    };
    (router, joining)
}

impl Rogue {
    fn start(bus: &BusConfig, key: &str) -> Rogue {
        let session = bus.open().expect("rogue joins");
        let queryable = session
            .declare_queryable(key.to_owned())
            .complete(true)
            .callback(|query| {
                let _ = query
                    .reply(query.key_expr().clone(), br#"{"accepted": true}"#.to_vec())
                    .wait();
            })
            .wait()
            .expect("rogue declares");
        Rogue {
            session,
            _queryable: queryable,
        }
    }

    fn leave(self) {
        let _ = self.session.close().wait();
    }
}

/// Asks `key` until the answer is a conflict (the rogue's declaration has reached
/// the client) or 20 s pass; the conflict.
fn conflict_on(client: &BusClient, key: &str, payload: &[u8]) -> ErrorReply {
    let started = Instant::now();
    loop {
        match client.request_key(key, payload, T) {
            Err(RequestError::Conflict(reply)) => return reply,
            other => assert!(
                started.elapsed().as_secs() < 20,
                "no conflict on {key}: {other:?}"
            ),
        }
    }
}

/// Asks `key` until the answer is no conflict (the rogue has left) or 20 s pass.
fn alone_on(client: &BusClient, key: &str, payload: &[u8]) -> Result<Vec<u8>, RequestError> {
    let started = Instant::now();
    loop {
        assert!(started.elapsed().as_secs() < 20, "{key} still conflicted");
        match client.request_key(key, payload, T) {
            Err(RequestError::Conflict(_)) => continue,
            other => return other,
        }
    }
}

fn check_conflict(reply: &ErrorReply, key: &str) {
    assert_eq!(reply.error.code, ErrorCode::ConflictingResponders);
    assert!(reply.error.message.contains(key), "{}", reply.error.message);
    let details = reply.error.details.as_ref().expect("details");
    assert_eq!(details["key"], key);
    let each = details["responders"].as_array().expect("responders");
    assert_eq!(each.len(), 2, "{details}");
    assert!(
        each.iter().any(|r| r == "a reply of 18 bytes"),
        "the rogue's reply is named: {details}"
    );
}

#[test]
fn a_rogue_declaring_motion_plan_is_a_conflict_never_the_answer() {
    let (router, bus) = router();
    let namespace = format!("rogue-plan-{}", std::process::id());
    let mut config = HostConfig::empty(&namespace, bus.clone());
    config.plugins = vec![motion_entry()];
    let host = RunningHost::start(&config).expect("host starts");
    let client = BusClient::connect(&bus, &namespace).unwrap();
    client.wait_for_host(T * 4).expect("host answers");
    let key = client.keys().command("motion", "plan");
    // Before: the host alone answers (an empty request is refused, naming why).
    let before = client.request_key(&key, b"{}", T).unwrap_err();
    assert!(matches!(before, RequestError::Reply(_)), "{before}");
    let rogue = Rogue::start(&bus, &key);
    let reply = conflict_on(&client, &key, b"{}");
    check_conflict(&reply, &key);
    assert!(
        reply.error.details.as_ref().unwrap()["responders"]
            .as_array()
            .unwrap()
            .iter()
            .any(|r| r.as_str().unwrap().starts_with("an error reply")),
        "the host's refusal is named too: {reply:?}"
    );
    // The CLI prints the error object; the message says what to do.
    assert!(reply.error.message.contains("another process"), "{reply:?}");
    rogue.leave();
    let after = alone_on(&client, &key, b"{}").unwrap_err();
    assert!(matches!(after, RequestError::Reply(_)), "{after}");
    client.close();
    drop(host);
    let _ = router.close().wait();
}

#[test]
fn a_rogue_declaring_controller_execute_is_a_conflict_never_the_answer() {
    let (router, bus) = router();
    let namespace = format!("rogue-execute-{}", std::process::id());
    let args = ComponentArgs {
        mode: BusMode::Client,
        ..ComponentArgs::connecting(&namespace, &bus.connect[0])
    };
    let controller = MockController::start(&args).unwrap();
    let client = BusClient::connect(&bus, &namespace).unwrap();
    client.wait_for_component("controller", T * 4).unwrap();
    let key = client.keys().controller_execute();
    let execute = br#"{"trajectory": {"joint_names": [], "points": []}}"#;
    client
        .request_key(&key, execute, T)
        .expect("the controller answers");
    let rogue = Rogue::start(&bus, &key);
    check_conflict(&conflict_on(&client, &key, execute), &key);
    rogue.leave();
    alone_on(&client, &key, execute).expect("the controller alone answers");
    assert!(controller.received().len() >= 3, "every request reached it");
    client.close();
    controller.close();
    let _ = router.close().wait();
}
