//! The component as a separate process on a real zenoh bus (loopback): info,
//! detect with its simulated camera, the published pose, set_object sent on to
//! the world, error replies (oversized payloads too), and a clean exit on
//! SIGTERM; a look in the fridge scene, its views in the reply.

use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use tsukami_bus::serve::reply_json;
use tsukami_bus::{free_loopback_port, BusClient, BusConfig, RequestError};
use tsukami_msgs::planner::SetObject;
use tsukami_msgs::vision::{LookReply, ObjectPose};
use tsukami_msgs::ErrorCode;
use zenoh::Wait;

struct Process(Child);

impl Drop for Process {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The component serving `extra` arguments on a free loopback port under a
/// namespace named after `name`, and a client connected to it.
fn start(name: &str, extra: &[&str]) -> (Process, BusClient, String) {
    let port = free_loopback_port().unwrap();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let ns = format!("test-{name}-{}", std::process::id());
    let child = Process(
        Command::new(env!("CARGO_BIN_EXE_tsukami-vision"))
            .args(["serve", "--listen", &endpoint, "--namespace", &ns])
            .args(extra)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    let client = BusClient::connect(&BusConfig::connecting(&endpoint), &ns).unwrap();
    (child, client, ns)
}

#[test]
fn a_look_over_the_bus_answers_its_views() {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../models/scenes/fridge_pet.toml"
    );
    let (_child, client, ns) = start("vision-look", &["--scene", scene]);
    let info = client
        .wait_for_component("vision", Duration::from_secs(60))
        .unwrap();
    assert!(
        info.keys.contains(&format!("{ns}/vision/look")),
        "{:?}",
        info.keys
    );
    let poses = client
        .session()
        .declare_subscriber(format!("{ns}/vision/pose/pet_500ml"))
        .wait()
        .unwrap();
    let reply = client
        .request_key(
            &format!("{ns}/vision/look"),
            br#"{"object": "pet_500ml", "seed": 0}"#,
            Duration::from_secs(120),
        )
        .unwrap();
    let look: LookReply = serde_json::from_slice(&reply).unwrap();
    // The bottle on the lower shelf at (0.58, -0.25, 0.33), seen crouched.
    let p = look.pose.pose.position;
    assert!(
        (p[0] - 0.58).abs() < 0.005 && (p[1] + 0.25).abs() < 0.005 && (p[2] - 0.33).abs() < 0.005,
        "{p:?}"
    );
    assert!(
        look.views.len() > 1 && !look.views[0].found,
        "{:?}",
        look.views
    );
    let seen = &look.views[look.view as usize];
    assert!(
        seen.found && seen.joints.contains_key("squat_z"),
        "{seen:?}"
    );
    let published = poses
        .recv_timeout(Duration::from_secs(10))
        .unwrap()
        .expect("a published pose");
    let published: ObjectPose = serde_json::from_slice(&published.payload().to_bytes()).unwrap();
    assert_eq!(published, look.pose);
    client.close();
}

#[test]
fn vision_component_over_the_bus() {
    let (mut child, client, ns) = start("vision", &[]);
    let info = client
        .wait_for_component("vision", Duration::from_secs(60))
        .unwrap();
    assert_eq!(info.name, "vision");
    assert!(
        info.keys.contains(&format!("{ns}/vision/detect")),
        "{:?}",
        info.keys
    );

    // A mock world that records what it is sent.
    let received: Arc<Mutex<Vec<SetObject>>> = Arc::default();
    let sink = received.clone();
    let _world = client
        .session()
        .declare_queryable(format!("{ns}/world/set_object"))
        .callback(move |q| {
            let bytes = q
                .payload()
                .map(|p| p.to_bytes().into_owned())
                .unwrap_or_default();
            if let Ok(set) = serde_json::from_slice::<SetObject>(&bytes) {
                sink.lock().unwrap().push(set);
            }
            reply_json(&q, &serde_json::json!({}));
        })
        .wait()
        .unwrap();
    let poses = client
        .session()
        .declare_subscriber(format!("{ns}/vision/pose/can_350ml"))
        .wait()
        .unwrap();

    assert!(
        info.keys.contains(&format!("{ns}/vision/look")),
        "{:?}",
        info.keys
    );

    // The can of models/scenes/can_breast.toml (the default scene) stands at (0.52, -0.25, 1.10).
    let key = format!("{ns}/vision/detect");
    let ask = |body: &str| client.request_key(&key, body.as_bytes(), Duration::from_secs(60));
    let reply: ObjectPose = serde_json::from_slice(
        &ask(r#"{"object": "can_350ml", "seed": 1, "set_object": true}"#).unwrap(),
    )
    .unwrap();
    let p = reply.pose.position;
    let err = ((p[0] - 0.52).powi(2) + (p[1] + 0.25).powi(2) + (p[2] - 1.10).powi(2)).sqrt();
    assert!(err < 0.005, "pose {p:?} is {:.1} mm off", err * 1e3);
    assert!(
        reply.confidence >= 0.8 && reply.symmetry.is_some(),
        "{reply:?}"
    );
    assert_eq!(
        reply.sent_to.as_deref(),
        Some(format!("{ns}/world/set_object").as_str())
    );
    let sent = received.lock().unwrap().clone();
    assert_eq!(sent.len(), 1);
    assert_eq!(sent[0].pose, reply.pose);
    assert!((sent[0].mass - 0.15).abs() < 1e-12);
    let published = poses
        .recv_timeout(Duration::from_secs(10))
        .unwrap()
        .expect("a published pose");
    let published: ObjectPose = serde_json::from_slice(&published.payload().to_bytes()).unwrap();
    assert_eq!(published.pose, reply.pose);

    // Same seed, same reply.
    let again: ObjectPose =
        serde_json::from_slice(&ask(r#"{"object": "can_350ml", "seed": 1}"#).unwrap()).unwrap();
    assert_eq!(again.pose, reply.pose);

    // Errors: an absent object, malformed JSON, an unknown field; still serving after.
    let code = |r: Result<Vec<u8>, RequestError>| r.unwrap_err().code();
    let absent = ask(r#"{"object": "box", "seed": 2}"#).unwrap_err();
    match &absent {
        RequestError::Reply(e) => {
            assert_eq!(e.error.code, ErrorCode::Infeasible);
            assert_eq!(e.error.details.as_ref().unwrap()["reason"], "not_found");
        }
        other => panic!("{other}"),
    }
    assert_eq!(code(ask("{not json")), Some(ErrorCode::MalformedJson));
    assert_eq!(
        code(ask(r#"{"object": "can_350ml", "colour": 1}"#)),
        Some(ErrorCode::InvalidRequest)
    );
    // Over the payload limit: refused naming it (before it is queued), a message
    // over zenoh's reassembly cap dropped (no reply); still serving.
    let over = vec![b' '; tsukami_bus::MAX_PAYLOAD_BYTES + 1024];
    let refused = client
        .request_key(&key, &over, Duration::from_secs(60))
        .unwrap_err();
    assert_eq!(
        refused.code(),
        Some(ErrorCode::PayloadTooLarge),
        "{refused}"
    );
    assert!(refused.to_string().contains("16777216"), "{refused}");
    let huge = vec![b' '; 64 << 20];
    let dropped = client.request_key(&key, &huge, Duration::from_secs(10));
    assert!(
        matches!(dropped, Err(RequestError::Timeout { .. })),
        "{dropped:?}"
    );
    assert!(ask(r#"{"object": "can_350ml", "seed": 3}"#).is_ok());

    // SIGTERM: a clean exit.
    // SAFETY: kill(2) on our own child's pid; no memory is shared.
    let sent = unsafe { libc::kill(child.0.id() as libc::pid_t, libc::SIGTERM) };
    assert_eq!(sent, 0, "kill: {}", std::io::Error::last_os_error());
    let start = Instant::now();
    loop {
        if let Some(s) = child.0.try_wait().unwrap() {
            assert!(s.success(), "exit status {s}");
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "still running 10 s after SIGTERM"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    client.close();
}
