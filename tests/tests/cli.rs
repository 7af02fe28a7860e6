//! The `tsukami` binary: `tsukami run` serving, `tsukami plugins` listing it.

use tsukami::bus::free_loopback_port;
use tsukami_e2e::{cli_plugins_listing, plugin_file, spawn_tsukami, tsukami_exe};

#[test]
fn plugins_lists_what_a_running_host_serves() {
    let port = free_loopback_port().unwrap();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let namespace = format!("cli-{port}");
    let dir = std::env::temp_dir().join(format!("tsukami-cli-{port}"));
    std::fs::create_dir_all(&dir).unwrap();
    let config = dir.join("host.toml");
    std::fs::write(
        &config,
        format!(
            "namespace = \"{namespace}\"\n[bus]\nlisten = [\"{endpoint}\"]\n\n[[plugin]]\nrole = \"test-slow\"\npath = {:?}\n",
            plugin_file("tsukami_test_slow")
        ),
    )
    .unwrap();
    let _host = spawn_tsukami(&[
        "run",
        "--config",
        config.to_str().unwrap(),
        "--namespace",
        &namespace,
    ]);

    let listing = cli_plugins_listing(&endpoint, &namespace);
    assert_eq!(listing["namespace"], namespace.as_str());
    assert_eq!(listing["plugins"][0]["roles"][0], "test-slow");
    assert_eq!(listing["plugins"][0]["name"], "test-slow");
    assert_eq!(listing["plugins"][0]["version"], env!("CARGO_PKG_VERSION"));

    // The planner role is not served by this host: the host answers `no_plugin`.
    let out = std::process::Command::new(tsukami_exe())
        .args([
            "stop",
            "--connect",
            &endpoint,
            "--namespace",
            &namespace,
            "--timeout-ms",
            "300",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("no_plugin"), "{stderr}");
}
