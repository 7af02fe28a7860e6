//! SetRobot's `package_dirs`: a robot whose collision mesh is named by
//! `package://` loads only when the request names a folder that holds the
//! package, and that folder must lie inside the model roots.

use std::fs;
use std::path::{Path, PathBuf};

use tsukami_msgs::planner::SetRobot;
use tsukami_msgs::ErrorCode;
use tsukami_planner_kit::models::Models;
use tsukami_planner_kit::Robot;

/// A model root holding the humanoid's grasp types and `tsukami_arm7` with its
/// bracket made a `package://arm7_meshes/bracket.stl` mesh, and the package
/// two folders below `pkgs/` (out of reach of the URDF's own ancestors).
fn root_with_packaged_arm(tag: &str) -> PathBuf {
    let root = std::env::temp_dir().join(format!("tsukami-pkgdirs-{tag}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&root);
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/robots");
    for (robot, files) in [
        ("tsukami_humanoid", &["grasp_types.toml"][..]),
        (
            "tsukami_arm7",
            &["description.toml", "tsukami_arm7.urdf"][..],
        ),
    ] {
        let dir = root.join("robots").join(robot);
        fs::create_dir_all(&dir).unwrap();
        for f in files {
            fs::copy(models.join(robot).join(f), dir.join(f)).unwrap();
        }
    }
    let urdf = root.join("robots/tsukami_arm7/tsukami_arm7.urdf");
    let text = fs::read_to_string(&urdf).unwrap();
    let bracket = r#"<collision name="bracket"><origin xyz="-0.11 -0.21 1.38"/><geometry><box size="0.08 0.06 0.06"/></geometry></collision>"#;
    assert!(text.contains(bracket), "the arm's bracket changed");
    let packaged = r#"<collision name="bracket"><origin xyz="-0.11 -0.21 1.38"/><geometry><mesh filename="package://arm7_meshes/bracket.stl"/></geometry></collision>"#;
    fs::write(&urdf, text.replace(bracket, packaged)).unwrap();
    let package = root.join("pkgs/vendor/arm7_meshes");
    fs::create_dir_all(&package).unwrap();
    fs::write(package.join("bracket.stl"), cube_stl(0.03)).unwrap();
    root
}

/// An ASCII STL of a closed cube of half-size `h`.
fn cube_stl(h: f64) -> String {
    let v = |i: usize| {
        [
            if i & 1 == 0 { -h } else { h },
            if i & 2 == 0 { -h } else { h },
            if i & 4 == 0 { -h } else { h },
        ]
    };
    // Outward-wound faces of the cube as vertex-index triangles.
    let faces = [
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    let mut s = String::from("solid cube\n");
    for f in faces {
        s.push_str(" facet normal 0 0 0\n  outer loop\n");
        for i in f {
            let [x, y, z] = v(i);
            s.push_str(&format!("   vertex {x} {y} {z}\n"));
        }
        s.push_str("  endloop\n endfacet\n");
    }
    s + "endsolid cube\n"
}

fn request(dirs: &[&str]) -> SetRobot {
    SetRobot {
        robot: "tsukami_arm7".into(),
        grasp_types: None,
        package_dirs: dirs.iter().map(|d| d.to_string()).collect(),
    }
}

#[test]
fn package_dirs_find_a_mesh_package_inside_the_roots() {
    let root = root_with_packaged_arm("ok");
    let models = Models::new([root.clone()]);
    // Without the folder the package is not found, and the error names it.
    let e = Robot::load(&models, &request(&[])).map(|_| ()).unwrap_err();
    assert!(e.to_string().contains("arm7_meshes"), "{e}");
    // With it the robot loads, bracket mesh included.
    let robot = Robot::load(&models, &request(&["pkgs"])).unwrap();
    assert!(robot.model.link_id("r_palm").is_ok());
    // An absolute folder inside the root works the same.
    let abs = root.join("pkgs").display().to_string();
    assert!(Robot::load(&models, &request(&[&abs])).is_ok());
    fs::remove_dir_all(&root).unwrap();
}

#[test]
fn package_dirs_outside_the_roots_or_too_many_are_refused() {
    let root = root_with_packaged_arm("bad");
    let models = Models::new([root.clone()]);
    for dir in [
        "/etc",
        "../..",
        "pkgs/vendor/arm7_meshes/bracket.stl",
        "nope",
    ] {
        let e = Robot::load(&models, &request(&["pkgs", dir]))
            .map(|_| ())
            .unwrap_err();
        assert_eq!(e.code(), ErrorCode::ModelError, "{dir}: {e}");
        let text = e.to_string();
        assert!(text.contains("package_dirs[1]"), "{dir}: {text}");
        assert!(!text.contains(&root.display().to_string()), "{text}");
    }
    let many = vec!["pkgs"; SetRobot::MAX_PACKAGE_DIRS + 1];
    let e = Robot::load(&models, &request(&many))
        .map(|_| ())
        .unwrap_err();
    assert_eq!(e.code(), ErrorCode::InvalidValue, "{e}");
    assert!(e.to_string().contains("package_dirs"), "{e}");
    fs::remove_dir_all(&root).unwrap();
}
