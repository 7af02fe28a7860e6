//! The offline subcommands of the `tsukami` binary: `model`, `fc`, `schema`.
//! (The bus subcommands are tested end to end in `tests/`.)

use std::path::PathBuf;
use std::process::{Command, Output};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn humanoid() -> String {
    repo()
        .join("models/robots/tsukami_humanoid/tsukami_humanoid.urdf")
        .display()
        .to_string()
}

fn tsukami(args: &[&str], stdin: Option<&str>) -> Output {
    use std::io::Write;
    let mut child = Command::new(env!("CARGO_BIN_EXE_tsukami"))
        .args(args)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut input = child.stdin.take().unwrap();
    input.write_all(stdin.unwrap_or("").as_bytes()).unwrap();
    drop(input);
    child.wait_with_output().unwrap()
}

fn json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn model_inspect_lists_links_and_joints_with_mimics() {
    let report = json(&tsukami(&["model", "inspect", &humanoid()], None));
    let joints = report["joints"].as_array().unwrap();
    let j4 = joints
        .iter()
        .find(|j| j["name"] == "r_index_j4")
        .expect("r_index_j4");
    assert_eq!(j4["mimic"]["joint"], "r_index_j3");
    for field in [
        "type", "parent", "child", "lower", "upper", "effort", "velocity",
    ] {
        assert!(j4.get(field).is_some(), "joint field {field} missing");
    }
    assert!(report["links"]
        .as_array()
        .unwrap()
        .iter()
        .any(|l| l["name"] == "r_palm" && l["mass"].is_number()));
}

#[test]
fn model_fk_single_and_batch_agree() {
    let single = json(&tsukami(
        &["model", "fk", &humanoid(), "--joint", "r_elbow=-0.8"],
        None,
    ));
    let batch_file = std::env::temp_dir().join(format!("tsukami-fk-{}.json", std::process::id()));
    std::fs::write(&batch_file, r#"[{}, {"r_elbow": -0.8}]"#).unwrap();
    let batch = json(&tsukami(
        &[
            "model",
            "fk",
            &humanoid(),
            "--batch",
            batch_file.to_str().unwrap(),
        ],
        None,
    ));
    assert_eq!(batch.as_array().unwrap().len(), 2);
    assert_eq!(batch[1]["links"]["r_palm"], single["links"]["r_palm"]);
    assert_ne!(batch[0]["links"]["r_palm"], single["links"]["r_palm"]);
}

#[test]
fn model_fk_refuses_a_mimic_joint_and_an_unknown_one() {
    for (joint, needle) in [
        ("r_index_j4=0.1", "mimic"),
        ("elbow_of_nobody=1", "elbow_of_nobody"),
    ] {
        let out = tsukami(&["model", "fk", &humanoid(), "--joint", joint], None);
        assert!(!out.status.success());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(needle), "{stderr}");
    }
}

#[test]
fn model_ik_reaches_a_pose_the_arm_can_reach() {
    let arm = "r_shoulder_pitch,r_shoulder_roll,r_shoulder_yaw,r_elbow,r_wrist_yaw,r_wrist_pitch,r_wrist_roll";
    // A target made from a known configuration is reachable by construction.
    let fk = json(&tsukami(
        &[
            "model",
            "fk",
            &humanoid(),
            "--joint",
            "r_elbow=-1.0",
            "--joint",
            "r_shoulder_pitch=-0.4",
        ],
        None,
    ));
    let palm = &fk["links"]["r_palm"];
    let p: Vec<f64> = palm["position"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let q: Vec<f64> = palm["quaternion"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let target = format!(
        "{},{},{},{},{},{},{}",
        p[0], p[1], p[2], q[0], q[1], q[2], q[3]
    );
    // The arm's IK of the palm to `target` (`x,y,z,qx,qy,qz,qw`), seed 3.
    let palm_ik = |target: &str| {
        let urdf = humanoid();
        let args = [
            "model", "ik", &urdf, "--link", "r_palm", "--target", target, "--joints", arm,
            "--seed", "3",
        ];
        json(&tsukami(&args, None))
    };
    let ik = palm_ik(&target);
    assert_eq!(ik["ok"], true, "{ik}");
    assert!(ik["position_error"].as_f64().unwrap() < 1e-3);
    assert_eq!(ik["joint_positions"].as_object().unwrap().len(), 7);
    // 3 m in front of the robot: refused without an attempt, and said why.
    let far = palm_ik("3,0,1,0,0,0,1");
    assert_eq!(far["ok"], false, "{far}");
    assert_eq!(far["attempts"], 0, "{far}");
    let message = far["message"].as_str().unwrap();
    assert!(message.contains("beyond the reach"), "{message}");
}

#[test]
fn fc_answers_every_problem_and_names_the_bad_one() {
    let problems = r#"[
      {"contacts": [{"position": [0.033, 0, 0], "normal": [-1, 0, 0]},
                    {"position": [-0.0165, 0.02858, 0], "normal": [0.5, -0.866025, 0]},
                    {"position": [-0.0165, -0.02858, 0], "normal": [0.5, 0.866025, 0]}],
       "mu": 0.5, "f_max": 10.0, "mass": 0.15, "center_of_mass": [0, 0, 0],
       "characteristic_length": 0.06, "methods": ["ellipsoid", "exact"]},
      {"contacts": [{"position": [0, 0, 0], "normal": [1, 0, 0]}],
       "mu": 0.5, "f_max": 10.0, "mass": 0.15, "center_of_mass": [0, 0, 0], "characteristic_length": 0.06}
    ]"#;
    let results = json(&tsukami(&["fc"], Some(problems)));
    let results = results.as_array().unwrap();
    assert_eq!(results.len(), 2);
    assert!(
        results[0]["ellipsoid"]["margin"].is_number(),
        "{}",
        results[0]
    );
    assert_eq!(
        results[0]["exact"]["resists_weight"], true,
        "{}",
        results[0]
    );
    assert_eq!(results[1]["error"]["index"], 1, "{}", results[1]);
    assert!(
        results[1]["error"]["field"]
            .as_str()
            .unwrap()
            .contains("contacts"),
        "{}",
        results[1]
    );
}

#[test]
fn schema_command_writes_what_is_committed() {
    let out_dir = std::env::temp_dir().join(format!("tsukami-schema-{}", std::process::id()));
    let out = tsukami(&["schema", "--out", out_dir.to_str().unwrap()], None);
    assert!(out.status.success());
    let committed = repo().join("docs/schema");
    let mut count = 0;
    for entry in std::fs::read_dir(&out_dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap();
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            std::fs::read_to_string(committed.join(name)).unwrap_or_default(),
            "{name:?} differs"
        );
        count += 1;
    }
    assert!(count >= 10);
}

#[test]
fn model_compose_declares_a_palm_frame_above_the_hand() {
    let third = repo().join("tests/data/urdf/third_party");
    let arm = third.join("pybullet_data/kuka_iiwa/model.urdf");
    let hand = third
        .join("example-robot-data/robots/allegro_hand_description/urdf/allegro_right_hand.urdf");
    // `tsukami model compose ARM HAND --at lbr_iiwa_link_7 EXTRA…`.
    let compose = |extra: &[&str]| {
        let (arm, hand) = (arm.display().to_string(), hand.display().to_string());
        let mut args = vec!["model", "compose", &arm, &hand, "--at", "lbr_iiwa_link_7"];
        args.extend_from_slice(extra);
        tsukami(&args, None)
    };
    let out = compose(&[
        "--xyz",
        "0,0,0.14",
        "--palm-frame",
        "palm",
        "--palm-xyz",
        "0.0111,0,-0.0475",
        "--palm-rpy",
        "0,-1.5707963267948966,3.141592653589793",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let urdf = String::from_utf8(out.stdout).unwrap();
    // The arm's flange holds the frame, the frame holds the hand's palm link.
    assert!(urdf.contains("<parent link=\"lbr_iiwa_link_7\"/>\n    <child link=\"palm\"/>"));
    assert!(urdf.contains("<parent link=\"palm\"/>\n    <child link=\"palm_link\"/>"));
    // The same as the committed robot, which was composed this way.
    let committed =
        std::fs::read_to_string(repo().join("models/robots/iiwa_allegro/iiwa_allegro.urdf"))
            .unwrap();
    let joints = |t: &str| t.matches("<joint ").count();
    assert_eq!(joints(&urdf), joints(&committed));
    // A frame name the hand already uses is refused, naming it.
    let clash = compose(&["--palm-frame", "link_0.0"]);
    assert!(!clash.status.success());
    assert!(String::from_utf8_lossy(&clash.stderr).contains("link_0.0"));
}

#[test]
fn model_grasp_types_proposes_a_file_that_loads_or_names_what_is_missing() {
    let robot = repo().join("models/robots/iiwa_allegro");
    let out = tsukami(
        &["model", "grasp-types", &robot.display().to_string()],
        None,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let cfg = tsukami_planner_kit::grasp_types::GraspTypeConfig::parse(&text, "proposal").unwrap();
    assert_eq!(cfg.grasp_types.len(), 9);
    assert!(String::from_utf8_lossy(&out.stderr).contains("9 grasp types for hand `right`"));
    // A folder without a description is named in the error.
    let missing = tsukami(
        &[
            "model",
            "grasp-types",
            &repo().join("docs").display().to_string(),
        ],
        None,
    );
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("description.toml"));
}

#[test]
fn model_allowed_collisions_proposes_pairs_with_reasons_deterministically() {
    let robot = repo()
        .join("models/robots/iiwa_allegro")
        .display()
        .to_string();
    let run = |seed: &str| {
        let out = tsukami(
            &[
                "model",
                "allowed-collisions",
                &robot,
                "--samples",
                "150",
                "--seed",
                seed,
            ],
            None,
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let text = run("4");
    assert_eq!(text, run("4"), "the same seed gives the same proposal");
    let table: toml::Table = toml::from_str(&text).unwrap();
    let pairs = table["allowed_collisions"].as_array().unwrap();
    assert!(!pairs.is_empty(), "{text}");
    // Every proposed pair carries its reason; the description's own pair is
    // not proposed again.
    for line in text.lines().filter(|l| l.trim_start().starts_with('[')) {
        assert!(
            line.contains("# in contact in all 150 postures")
                || line.contains("# never in contact in 150 postures"),
            "{line}"
        );
    }
    assert!(!text.contains("[\"palm_link\", \"link_13.0\"]"), "{text}");
    // The iiwa's base never meets its hand within the joint limits.
    assert!(text.contains("never in contact"), "{text}");
    let zero = tsukami(
        &["model", "allowed-collisions", &robot, "--samples", "0"],
        None,
    );
    assert!(!zero.status.success());
    assert!(String::from_utf8_lossy(&zero.stderr).contains("--samples"));
}

#[test]
fn a_reader_that_closes_early_ends_the_client_without_a_panic() {
    use std::os::unix::process::ExitStatusExt;
    use std::process::Stdio;
    // The reader (`| head`) is gone before the client writes: the client ends
    // as `cat` would, by SIGPIPE, not with "failed printing to stdout". The read
    // end is closed before the child starts, so no write can ever succeed (a
    // piped stdout dropped after spawn would race with a fast child).
    let urdf = humanoid();
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_tsukami"))
        .args(["model", "inspect", &urdf])
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.signal(), Some(libc::SIGPIPE), "{:?}", out.status);
}
