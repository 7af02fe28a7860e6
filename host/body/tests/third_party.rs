//! Public robots the project did not design, from two collections on PyPI
//! (`example-robot-data`, BSD-2-Clause; `pybullet`'s pybullet_data, zlib),
//! committed under `tests/data/urdf/third_party` with their licences:
//! a Collada arm (UR5), a package path (the same URDF outside its package),
//! an arm with zero-area triangles in its meshes (KUKA iiwa) and a humanoid
//! with a mimic on a fixed joint (TALOS, meshes not committed).

use std::path::{Path, PathBuf};

use tsukami_body::model::Geometry;
use tsukami_body::packages::PackagePath;
use tsukami_body::urdf::{load_urdf_with, LoadOptions};
use tsukami_body::{BodyError, WarningKind};

fn third_party() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/urdf/third_party")
}

/// Strict reading: every quirk and every cleaned mesh is an error.
fn strict() -> LoadOptions {
    LoadOptions {
        strict: true,
        ..LoadOptions::default()
    }
}

#[test]
fn collada_arm_outside_its_package_loads_with_a_package_dir() {
    let src = third_party().join("example-robot-data/robots/ur_description/urdf/ur5_robot.urdf");
    let tmp = std::env::temp_dir().join(format!("tsukami-ur5-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let copy = tmp.join("ur5_robot.urdf");
    std::fs::copy(&src, &copy).unwrap();
    // Outside its package and with no package path, the error names the
    // package and where it looked.
    let e = load_urdf_with(&copy, &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, BodyError::UnresolvedPackage { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(
        msg.contains("package 'example-robot-data' not found")
            && msg.contains(tmp.to_str().unwrap()),
        "{msg}"
    );
    // With the folder holding the package: complete, and the only warnings
    // are meshes cleaned (the Collada shoulder has 4 zero-area triangles).
    let options = LoadOptions {
        packages: PackagePath::default().with_dirs([third_party()]),
        ..LoadOptions::default()
    };
    let ur5 = load_urdf_with(&copy, &options).unwrap();
    assert!(
        ur5.warnings
            .iter()
            .all(|w| w.kind == WarningKind::MeshCleaned),
        "{:?}",
        ur5.warnings
    );
    std::fs::remove_dir_all(&tmp).ok();
    // Every link's Collada visual (placed by node transforms, in metres)
    // lies where its STL collision mesh lies, within 2 cm.
    let mut dae = 0;
    for link in &ur5.model.links {
        let (Some(v), Some(c)) = (link.visuals.first(), link.collisions.first()) else {
            continue;
        };
        let (
            Geometry::Mesh {
                path: vp, mesh: vm, ..
            },
            Geometry::Mesh { mesh: cm, .. },
        ) = (&v.geometry, &c.geometry)
        else {
            continue;
        };
        assert!(vp.extension().unwrap() == "dae", "{vp:?}");
        let (vl, vh) = vm.aabb();
        let (cl, ch) = cm.aabb();
        let off = (vl - cl).abs().max().max((vh - ch).abs().max());
        assert!(
            off < 0.02,
            "link '{}': visual box {vl}..{vh} vs collision {cl}..{ch}",
            link.name
        );
        assert!(vm.indices.len() > 100);
        dae += 1;
    }
    assert_eq!(dae, 7);
}

#[test]
fn arm_with_zero_area_triangles_is_cleaned_not_refused() {
    let path = third_party().join("pybullet_data/kuka_iiwa/model.urdf");
    let kuka = load_urdf_with(&path, &LoadOptions::default()).unwrap();
    assert_eq!(
        kuka.model.joints.iter().filter(|j| j.is_movable()).count(),
        7
    );
    let cleaned: Vec<String> = kuka
        .warnings
        .iter()
        .filter(|w| w.kind == WarningKind::MeshCleaned)
        .map(|w| w.to_string())
        .collect();
    assert!(!cleaned.is_empty(), "{:?}", kuka.warnings);
    assert!(
        cleaned
            .iter()
            .all(|w| w.contains("zero-area") && w.contains("first: triangle")),
        "{cleaned:?}"
    );
    let e = load_urdf_with(&path, &strict()).unwrap_err().to_string();
    assert!(e.contains("zero-area"), "{e}");
}

#[test]
fn humanoid_with_a_mimic_on_a_fixed_joint_loads_leniently() {
    let path = third_party().join("example-robot-data/robots/talos_data/robots/talos_reduced.urdf");
    let talos = load_urdf_with(&path, &LoadOptions::kinematics_only()).unwrap();
    assert!(talos.model.links.len() > 50);
    assert!(
        talos.warnings.iter().any(|w| w.kind == WarningKind::Quirk
            && w.to_string().contains(
                "joint 'gripper_left_inner_double_joint' mimic: a fixed joint cannot mimic"
            )),
        "{:?}",
        talos
            .warnings
            .iter()
            .filter(|w| w.kind == WarningKind::Quirk)
            .collect::<Vec<_>>()
    );
    // Its meshes are not committed: kinematics skip them by name; a load
    // that needs collision meshes refuses, naming the package.
    assert!(talos
        .warnings
        .iter()
        .any(|w| w.kind == WarningKind::CollisionSkipped));
    let e = load_urdf_with(&path, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("talos_reduced.urdf") && e.contains("not found"),
        "{e}"
    );
    let options = LoadOptions {
        strict: true,
        ..LoadOptions::kinematics_only()
    };
    let e = load_urdf_with(&path, &options).unwrap_err();
    assert!(
        matches!(
            e,
            BodyError::Mimic { .. }
                | BodyError::UnresolvedPackage { .. }
                | BodyError::MissingMesh { .. }
        ),
        "{e:?}"
    );
}
