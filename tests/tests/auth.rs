//! The authenticated multi-machine example (configs/zenoh/secure-*.json5), on
//! loopback: a router with TLS, user/password authentication and access control,
//! the real host connecting to it as `tsukami-host`, the vision and the real
//! controller as `tsukami-vision` and `tsukami-controller`, callers as other users.
//!
//! A throwaway CA and router certificate are made at test time (rcgen) in a temp
//! folder; the example configs are used as committed, with only their
//! `/etc/tsukami/...` file paths, the port and (for the hostile clients) the
//! credentials replaced.

use std::path::{Path, PathBuf};
use std::time::Duration;
use tsukami::bus::{free_loopback_port, BusConfig};
use tsukami::client::{BusClient, RequestError};
use tsukami::config::HostConfig;
use tsukami::server::RunningHost;
use tsukami_bus::ComponentArgs;
use tsukami_e2e::mocks::MockVision;
use tsukami_e2e::{models_dir, planner_entry};
use tsukami_msgs::host::StopReply;
use tsukami_msgs::Pose;
use zenoh::Wait;

const USERS: &str = "tsukami-host:change-me-host\ntsukami-vision:change-me-vision\n\
tsukami-controller:change-me-controller\noperator:change-me-operator\nintruder:intruder-pw\n";

struct TempDir(PathBuf);
impl Drop for TempDir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

/// Writes ca.pem, router.pem, router-key.pem and users.txt into `dir`.
fn make_pki(dir: &Path) {
    use rcgen::{BasicConstraints, CertificateParams, DnType, IsCa, Issuer, KeyPair};
    let ca_key = KeyPair::generate().unwrap();
    let mut ca = CertificateParams::new(Vec::<String>::new()).unwrap();
    ca.is_ca = IsCa::Ca(BasicConstraints::Unconstrained);
    ca.distinguished_name
        .push(DnType::CommonName, "tsukami throwaway test CA");
    let ca_cert = ca.self_signed(&ca_key).unwrap();
    let issuer = Issuer::new(ca, ca_key);
    let router_key = KeyPair::generate().unwrap();
    let mut router = CertificateParams::new(vec!["127.0.0.1".to_owned()]).unwrap();
    router
        .distinguished_name
        .push(DnType::CommonName, "tsukami router");
    let router_cert = router.signed_by(&router_key, &issuer).unwrap();
    std::fs::write(dir.join("ca.pem"), ca_cert.pem()).unwrap();
    std::fs::write(dir.join("router.pem"), router_cert.pem()).unwrap();
    std::fs::write(dir.join("router-key.pem"), router_key.serialize_pem()).unwrap();
    std::fs::write(dir.join("users.txt"), USERS).unwrap();
}

/// The committed example config `name`, pointed at `dir`'s files and `port`.
fn example(name: &str, dir: &Path, port: u16) -> String {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../configs/zenoh")
        .join(name);
    let text = std::fs::read_to_string(&file).unwrap();
    let tls = format!("{}/", dir.display());
    text.replace("/etc/tsukami/tls/", &tls)
        .replace(
            "/etc/tsukami/users.txt",
            &dir.join("users.txt").display().to_string(),
        )
        .replace("127.0.0.1:7448", &format!("127.0.0.1:{port}"))
}

fn open(text: &str) -> zenoh::Result<zenoh::Session> {
    zenoh::open(zenoh::Config::from_json5(text)?).wait()
}

/// Every reply `session` gets for `key` within `timeout`: Ok payloads and error payloads.
fn all_replies(session: &zenoh::Session, key: &str, timeout: Duration) -> Vec<String> {
    let replies = session.get(key).timeout(timeout).wait().unwrap();
    let mut out = vec![];
    while let Ok(reply) = replies.recv() {
        let bytes = match reply.result() {
            Ok(sample) => sample.payload().to_bytes().into_owned(),
            Err(err) => err.payload().to_bytes().into_owned(),
        };
        out.push(String::from_utf8_lossy(&bytes).into_owned());
    }
    out
}

/// A queryable on `key` answering `answer`.
fn fake_server(
    session: &zenoh::Session,
    key: &str,
    answer: &'static str,
) -> zenoh::query::Queryable<()> {
    session
        .declare_queryable(key)
        .callback(move |q| {
            let _ = q.reply(q.key_expr().clone(), answer).wait();
        })
        .wait()
        .unwrap()
}

/// The secure set-up of the examples: a throwaway PKI in a temp folder, the
/// router, and the real host (the grasp planner) as `tsukami-host`.
struct Secure {
    host: RunningHost,
    router: zenoh::Session,
    port: u16,
    dir: TempDir,
}

impl Secure {
    fn start(tag: &str) -> Secure {
        let dir = std::env::temp_dir().join(format!("tsukami-auth-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let dir = TempDir(dir);
        make_pki(&dir.0);
        let port = free_loopback_port().unwrap();
        let router = open(&example("secure-router.json5", &dir.0, port)).expect("router opens");
        let mut config = HostConfig::empty("tsukami", BusConfig::connecting("tcp/127.0.0.1:1"));
        config.bus.zenoh_config = Some(write_example("secure-host.json5", &dir.0, port));
        config.plugins = vec![planner_entry()];
        let host = RunningHost::start(&config).expect("host connects to the secure router");
        Secure {
            host,
            router,
            port,
            dir,
        }
    }

    /// The example config `name` for this set-up.
    fn example(&self, name: &str) -> String {
        example(name, &self.dir.0, self.port)
    }

    /// The same, written to a file of this set-up's folder.
    fn file(&self, name: &str) -> PathBuf {
        write_example(name, &self.dir.0, self.port)
    }

    fn stop(self) {
        drop(self.host);
        let _ = self.router.close().wait();
    }
}

/// [`example`] written to `dir/name`.
fn write_example(name: &str, dir: &Path, port: u16) -> PathBuf {
    let file = dir.join(name);
    std::fs::write(&file, example(name, dir, port)).unwrap();
    file
}

#[test]
fn only_named_users_reach_the_host_and_nobody_impersonates_it() {
    let secure = Secure::start("host");
    // A named caller reaches it.
    let operator_text = secure.example("secure-client.json5");
    let operator = BusClient::on_session(open(&operator_text).expect("operator opens"), "tsukami");
    let listing = operator
        .wait_for_host(Duration::from_secs(20))
        .expect("the operator reaches the host");
    assert_eq!(listing.plugins[0].roles, vec!["grasp-planner".to_owned()]);

    // Unauthenticated, wrong password, or plain TCP: no session, or nothing heard.
    let no_auth = operator_text.replace(
        "usrpwd: { user: \"operator\", password: \"change-me-operator\" },",
        "",
    );
    assert_ne!(
        no_auth, operator_text,
        "the example's credentials line changed"
    );
    let wrong = operator_text.replace("change-me-operator", "guess");
    let plain = operator_text.replace("tls/127.0.0.1", "tcp/127.0.0.1");
    for (what, text) in [
        ("no credentials", &no_auth),
        ("wrong password", &wrong),
        ("plain tcp", &plain),
    ] {
        if let Ok(session) = open(text) {
            let heard = all_replies(&session, "tsukami/host/plugins", Duration::from_secs(2));
            assert!(heard.is_empty(), "{what}: heard {heard:?}");
            let _ = session.close().wait();
        }
    }

    // An authenticated user named in no policy, and the operator itself, try to
    // serve the planner's keys; the host's own user serves a probe key afterwards.
    let intruder_text = operator_text
        .replace("\"operator\"", "\"intruder\"")
        .replace("change-me-operator", "intruder-pw");
    let intruder = open(&intruder_text).expect("the intruder authenticates");
    let _fake1 = fake_server(&intruder, "tsukami/planner/**", "{\"fake\":\"intruder\"}");
    // (A second operator session: a session hears its own queryables locally.)
    let operator2 = open(&operator_text).unwrap();
    let _fake2 = fake_server(&operator2, "tsukami/planner/**", "{\"fake\":\"operator\"}");
    let host_user = open(&secure.example("secure-host.json5")).unwrap();
    let _probe = fake_server(&host_user, "tsukami/planner/probe", "{\"probe\":true}");
    // Queryables of other sessions do reach the operator when the router allows
    // them: wait for the probe, so the fakes (declared before it) had their chance.
    let probe = (0..100)
        .find_map(|_| {
            let r = all_replies(
                operator.session(),
                "tsukami/planner/probe",
                Duration::from_millis(200),
            );
            r.iter().any(|p| p.contains("probe")).then_some(r)
        })
        .expect("the host user's probe queryable is heard");
    assert!(probe.iter().all(|p| !p.contains("fake")), "{probe:?}");

    for _ in 0..3 {
        let replies = all_replies(
            operator.session(),
            "tsukami/planner/plan",
            Duration::from_secs(3),
        );
        assert!(!replies.is_empty(), "the real host answers plan");
        assert!(
            replies.iter().all(|p| !p.contains("fake")),
            "impersonated: {replies:?}"
        );
        assert!(
            replies.iter().any(|p| p.contains("not_ready")),
            "{replies:?}"
        );
    }
    // The intruder hears nothing from the host.
    let heard = all_replies(&intruder, "tsukami/host/plugins", Duration::from_secs(2));
    assert!(heard.is_empty(), "intruder heard {heard:?}");

    secure.stop();
}

/// A session of `who` (a config text) trying to serve `controller/execute` and
/// `controller/stop` with fake answers; `None` when it cannot even open.
fn fake_controller(who: &str) -> Option<(zenoh::Session, Vec<zenoh::query::Queryable<()>>)> {
    let session = open(who).ok()?;
    let fakes = ["tsukami/controller/execute", "tsukami/controller/stop"]
        .iter()
        .filter_map(|key| {
            session
                .declare_queryable(*key)
                .complete(true)
                .callback(|q| {
                    let _ = q.reply(q.key_expr().clone(), "{\"fake\":true}").wait();
                })
                .wait()
                .ok()
        })
        .collect();
    Some((session, fakes))
}

/// The real controller (in this process) as `tsukami-controller`.
fn secure_controller(secure: &Secure) -> tsukami_controller::ControllerNode {
    use tsukami_controller::{Executor, JointTable, NodeOptions};
    let args = ComponentArgs {
        zenoh_config: Some(secure.file("secure-controller.json5")),
        ..ComponentArgs::connecting("tsukami", "tcp/127.0.0.1:1")
    };
    let table = JointTable::load("tsukami_humanoid", &models_dir()).unwrap();
    let executor = Executor::new(table, 100.0, None).unwrap();
    let options = NodeOptions {
        speed: 1.0,
        start_tolerance: 0.01,
    };
    tsukami_controller::start(&args, executor, options).expect("controller joins as its user")
}

/// The vision (the mock, a real component) and the controller join as their own
/// users and serve; a caller lists both and reaches `controller/stop`; nobody else
/// — an authenticated user in no policy, a caller, the vision's user, a client
/// without credentials — can take `controller/execute` or `controller/stop`: their
/// declarations are denied, and the real controller alone answers.
#[test]
fn components_have_their_own_users_and_nobody_else_takes_their_keys() {
    let secure = Secure::start("components");
    let controller = secure_controller(&secure);
    let vision_args = ComponentArgs {
        zenoh_config: Some(secure.file("secure-vision.json5")),
        ..ComponentArgs::connecting("tsukami", "tcp/127.0.0.1:1")
    };
    let origin = Pose {
        position: [0.5, 0.0, 0.8],
        quaternion: [0.0, 0.0, 0.0, 1.0],
    };
    let vision = MockVision::start(&vision_args, "can_350ml", origin).expect("vision joins");
    let operator_text = secure.example("secure-client.json5");
    let operator = BusClient::on_session(open(&operator_text).expect("operator opens"), "tsukami");
    for name in ["controller", "vision"] {
        operator
            .wait_for_component(name, Duration::from_secs(20))
            .unwrap_or_else(|e| panic!("the operator reaches the {name}: {e}"));
    }
    let listed = operator.components(Duration::from_secs(3)).unwrap();
    let names: Vec<&str> = listed.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["controller", "vision"]);
    let stop = || operator.request_key("tsukami/controller/stop", b"", Duration::from_secs(5));
    let first: StopReply = serde_json::from_slice(&stop().expect("a caller stops")).unwrap();
    assert!(!first.stopped, "nothing was running");

    // Rogues: another user, a caller, the vision's user, no credentials.
    let rogues = [
        operator_text
            .replace("\"operator\"", "\"intruder\"")
            .replace("change-me-operator", "intruder-pw"),
        operator_text.clone(),
        secure.example("secure-vision.json5"),
        operator_text.replace(
            "usrpwd: { user: \"operator\", password: \"change-me-operator\" },",
            "",
        ),
    ];
    let _fakes: Vec<_> = rogues.iter().filter_map(|r| fake_controller(r)).collect();
    // The controller's own user serves a probe afterwards; once the host's user
    // hears it, the fakes (declared before) had their chance.
    let probe_user = open(&secure.example("secure-controller.json5")).unwrap();
    let _probe = fake_server(&probe_user, "tsukami/controller/probe", "{\"probe\":true}");
    let host_user = BusClient::on_session(
        open(&secure.example("secure-host.json5")).unwrap(),
        "tsukami",
    );
    host_user
        .wait_for("tsukami/controller/probe", Duration::from_secs(20))
        .expect("the probe is heard");
    for _ in 0..3 {
        let stopped = stop().expect("the real controller alone answers stop");
        assert!(
            serde_json::from_slice::<StopReply>(&stopped).is_ok(),
            "{stopped:?}"
        );
        let execute = host_user.request_key(
            "tsukami/controller/execute",
            br#"{"trajectory": {"joint_names": [], "points": []}}"#,
            Duration::from_secs(5),
        );
        match execute {
            Ok(bytes) => assert!(!String::from_utf8_lossy(&bytes).contains("fake")),
            Err(RequestError::Reply(_)) => {} // the real controller refusing it
            Err(other) => panic!("execute: {other}"),
        }
    }
    vision.close();
    controller.shutdown();
    secure.stop();
}
