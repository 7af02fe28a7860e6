//! The authenticated multi-machine example (configs/zenoh/secure-*.json5), on
//! loopback: a router with TLS, user/password authentication and access control,
//! the real host connecting to it as `tsukami-host`, callers as other users.
//!
//! A throwaway CA and router certificate are made at test time (rcgen) in a temp
//! folder; the example configs are used as committed, with only their
//! `/etc/tsukami/...` file paths, the port and (for the hostile clients) the
//! credentials replaced.

use std::path::{Path, PathBuf};
use std::time::Duration;
use tsukami::bus::{free_loopback_port, BusConfig};
use tsukami::client::BusClient;
use tsukami::config::HostConfig;
use tsukami::server::RunningHost;
use tsukami_e2e::planner_entry;
use zenoh::Wait;

const USERS: &str =
    "tsukami-host:change-me-host\noperator:change-me-operator\nintruder:intruder-pw\n";

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

#[test]
fn only_named_users_reach_the_host_and_nobody_impersonates_it() {
    let dir = TempDir(std::env::temp_dir().join(format!("tsukami-auth-{}", std::process::id())));
    std::fs::create_dir_all(&dir.0).unwrap();
    make_pki(&dir.0);
    let port = free_loopback_port().unwrap();
    let router = open(&example("secure-router.json5", &dir.0, port)).expect("router opens");

    // The real host, as user `tsukami-host`, with the real grasp planner.
    let host_file = dir.0.join("host.json5");
    std::fs::write(&host_file, example("secure-host.json5", &dir.0, port)).unwrap();
    let mut config = HostConfig::empty("tsukami", BusConfig::connecting("tcp/127.0.0.1:1"));
    config.bus.zenoh_config = Some(host_file);
    config.plugins = vec![planner_entry()];
    let host = RunningHost::start(&config).expect("host connects to the secure router");

    // A named caller reaches it.
    let operator_text = example("secure-client.json5", &dir.0, port);
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
    let host_user = open(&example("secure-host.json5", &dir.0, port)).unwrap();
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

    drop(host);
    let _ = router.close().wait();
}
