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

#[test]
fn view_draws_a_scene_headless_and_names_bad_arguments() {
    let dir = std::env::temp_dir().join(format!("tsukami-view-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = tsukami_e2e::models_dir().join("scenes/can_breast.toml");
    let view = |extra: &[&str]| {
        let mut args = vec!["view", "--scene", scene.to_str().unwrap()];
        args.extend(extra);
        std::process::Command::new(tsukami_exe())
            .args(&args)
            .output()
            .unwrap()
    };
    let (png, glb) = (dir.join("scene.png"), dir.join("scene.glb"));
    let out = view(&[
        "--out",
        png.to_str().unwrap(),
        "--glb",
        glb.to_str().unwrap(),
        "--size",
        "320x240",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let picture = std::fs::read(&png).unwrap();
    assert_eq!(&picture[..8], b"\x89PNG\r\n\x1a\n");
    // IHDR: width and height, big-endian, right after the chunk's length and type.
    assert_eq!(&picture[16..24], &[0, 0, 1, 64, 0, 0, 0, 240]);
    assert_eq!(&std::fs::read(&glb).unwrap()[..4], b"glTF");
    for (extra, named) in [
        (&["--out", "x.png", "--size", "0x5"][..], "--size"),
        (&["--out", "x.png", "--eye", "1,2"][..], "--eye"),
        (
            &["--out", "x.png", "--result", "/nonexistent/reply.json"][..],
            "result",
        ),
    ] {
        let out = view(extra);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && stderr.contains(named),
            "{extra:?}: {stderr}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn demo_matches_the_paper_and_writes_its_report() {
    let dir = std::env::temp_dir().join(format!("tsukami-demo-report-{}", std::process::id()));
    let out = std::process::Command::new(tsukami_exe())
        .args(["demo", "--json", "--out", dir.to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let scenes: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let scenes = scenes.as_array().unwrap();
    let names: Vec<&str> = scenes
        .iter()
        .map(|s| s["scene"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "can_breast",
            "can_waist",
            "heavy_low",
            "fridge_pet",
            "vase_table"
        ]
    );
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    for s in scenes {
        let name = s["scene"].as_str().unwrap();
        // `ok` is the paper check's verdict, recomputed from the reply's contacts.
        assert_eq!(s["ok"], true, "{name}: {}", s["problem"]);
        assert!(s["weight_scale"].as_f64().unwrap() >= 1.0, "{name}");
        assert!(report.contains(&format!(
            "| {name} | {} |",
            s["result"]["grasp_type"]["name"].as_str().unwrap()
        )));
        assert_eq!(
            &std::fs::read(dir.join(format!("{name}.png"))).unwrap()[..4],
            b"\x89PNG"
        );
        assert_eq!(
            &std::fs::read(dir.join(format!("{name}.glb"))).unwrap()[..4],
            b"glTF"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
