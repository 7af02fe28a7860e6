//! A public hand on public arms, composed without editing either file: the
//! Allegro hand (example-robot-data, BSD) on the UR5 (Collada, `package://`
//! meshes) and on the KUKA iiwa (relative mesh paths, pybullet_data), both
//! committed under `tests/data/urdf/third_party`.

use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use tsukami_body::compose::{compose, read_raw, Attach, ComposeError};
use tsukami_body::kinematics::FkState;
use tsukami_body::packages::PackagePath;
use tsukami_body::urdf::{load_urdf_with, LoadOptions};
use tsukami_body::urdf_write::write_urdf;
use tsukami_body::urdf_xml::RawPose;
use tsukami_body::RobotModel;

fn third_party() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/urdf/third_party")
}

fn allegro() -> PathBuf {
    third_party()
        .join("example-robot-data/robots/allegro_hand_description/urdf/allegro_right_hand.urdf")
}

fn ur5() -> PathBuf {
    third_party().join("example-robot-data/robots/ur_description/urdf/ur5_robot.urdf")
}

fn iiwa() -> PathBuf {
    third_party().join("pybullet_data/kuka_iiwa/model.urdf")
}

/// Planner loading: collision meshes required, packages from the committed folder.
fn options() -> LoadOptions {
    LoadOptions {
        packages: PackagePath::default().with_dirs([third_party()]),
        ..LoadOptions::default()
    }
}

fn attach(link: &str, prefix: &str) -> Attach {
    Attach {
        parent_link: link.into(),
        origin: RawPose {
            xyz: [0.0, 0.01, 0.02],
            rpy: [0.3, -0.2, 1.1],
        },
        prefix: prefix.into(),
        name: None,
    }
}

/// Composes `arm` and the Allegro hand into a file in a fresh folder
/// (elsewhere than either input) and loads it as the planner would.
fn compose_to_file(arm: &Path, at: &Attach, tag: &str) -> RobotModel {
    let out = std::env::temp_dir().join(format!("tsukami-compose-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    let folder = |p: &Path| p.parent().unwrap().to_path_buf();
    let robot = compose(
        read_raw(arm, false).unwrap().0,
        read_raw(&allegro(), false).unwrap().0,
        at,
        (&folder(arm), &folder(&allegro()), &out),
    )
    .unwrap();
    let file = out.join("composed.urdf");
    std::fs::write(&file, write_urdf(&robot)).unwrap();
    let model = load_urdf_with(&file, &options()).unwrap().model;
    std::fs::remove_dir_all(&out).ok();
    model
}

/// Every joint at a value inside its limits, from a fixed pattern.
fn some_configuration(model: &RobotModel) -> Vec<f64> {
    let mut q: Vec<f64> = model
        .joints
        .iter()
        .enumerate()
        .map(|(i, j)| {
            let (lo, hi) = (j.limits.lower.max(-2.0), j.limits.upper.min(2.0));
            lo + (hi - lo) * (0.2 + 0.6 * ((i * 37 % 11) as f64 / 10.0))
        })
        .collect();
    model.apply_mimics(&mut q);
    q
}

/// The same joint values, by name, in another model of the same joints.
fn by_name(from: &RobotModel, q: &[f64], to: &RobotModel, prefix: &str) -> Vec<f64> {
    to.joints
        .iter()
        .map(|j| {
            let name = format!("{prefix}{}", j.name);
            from.joints
                .iter()
                .position(|f| f.name == name)
                .map_or(0.0, |i| q[i])
        })
        .collect()
}

fn fk(model: &RobotModel, q: &[f64]) -> FkState {
    let mut state = FkState::new(model);
    model.forward_kinematics(q, &mut state);
    state
}

/// Composed FK equals arm FK · attachment · hand FK for every hand link.
fn check_fk(composed: &RobotModel, arm: &RobotModel, hand: &RobotModel, at: &Attach) {
    let q = some_configuration(composed);
    let (fa, fh, fc) = (
        fk(arm, &by_name(composed, &q, arm, "")),
        fk(hand, &by_name(composed, &q, hand, &at.prefix)),
        fk(composed, &q),
    );
    let o = at.origin;
    let mount = Isometry3::from_parts(
        Translation3::new(o.xyz[0], o.xyz[1], o.xyz[2]),
        UnitQuaternion::from_euler_angles(o.rpy[0], o.rpy[1], o.rpy[2]),
    );
    let flange = fa.pose(arm.link_id(&at.parent_link).unwrap());
    let hand_root = fh.pose(0).inverse();
    for (l, link) in hand.links.iter().enumerate() {
        let expected = flange * mount * hand_root * fh.pose(l);
        let got = fc.pose(
            composed
                .link_id(&format!("{}{}", at.prefix, link.name))
                .unwrap(),
        );
        let err = (expected.to_homogeneous() - got.to_homogeneous())
            .abs()
            .max();
        assert!(err < 1e-9, "link {}: {err}", link.name);
    }
}

#[test]
fn allegro_on_the_ur5_loads_with_its_meshes_and_moves_with_the_flange() {
    let at = attach("tool0", "");
    let composed = compose_to_file(&ur5(), &at, "ur5");
    let (arm, hand) = (
        load_urdf_with(&ur5(), &options()).unwrap().model,
        load_urdf_with(&allegro(), &options()).unwrap().model,
    );
    assert_eq!(composed.links.len(), arm.links.len() + hand.links.len());
    assert_eq!(
        composed.joints.len(),
        arm.joints.len() + hand.joints.len() + 1
    );
    let palm = composed.link_id("palm_link").unwrap();
    assert!(!composed.links[palm].collisions.is_empty());
    check_fk(&composed, &arm, &hand, &at);
}

#[test]
fn relative_mesh_paths_are_rewritten_for_the_composed_file() {
    // The iiwa's meshes are `meshes/...` next to its URDF; the composed file
    // is written elsewhere and still finds them (collision meshes required).
    let at = attach("lbr_iiwa_link_7", "allegro_");
    let composed = compose_to_file(&iiwa(), &at, "iiwa");
    let arm = load_urdf_with(&iiwa(), &options()).unwrap().model;
    let hand = load_urdf_with(&allegro(), &options()).unwrap().model;
    let link1 = composed.link_id("lbr_iiwa_link_1").unwrap();
    assert!(!composed.links[link1].collisions.is_empty());
    check_fk(&composed, &arm, &hand, &at);
}

#[test]
fn clashing_names_missing_links_and_two_roots_are_named() {
    let hand = || read_raw(&allegro(), false).unwrap().0;
    let here = Path::new(".");
    let e = compose(hand(), hand(), &attach("palm_link", ""), (here, here, here)).unwrap_err();
    assert!(
        matches!(&e, ComposeError::Clash { what: "links", names } if names.contains(&"palm_link".to_owned())),
        "{e:?}"
    );
    assert!(e.to_string().contains("prefix"), "{e}");
    // With a prefix the same two hands compose.
    compose(
        hand(),
        hand(),
        &attach("link_3.0_tip", "second_"),
        (here, here, here),
    )
    .unwrap();
    let e = compose(hand(), hand(), &attach("flange", "h_"), (here, here, here)).unwrap_err();
    assert!(e.to_string().contains("no link 'flange'"), "{e}");
    let mut two_roots = hand();
    two_roots.joints.remove(0);
    let e = compose(
        hand(),
        two_roots,
        &attach("palm_link", "h_"),
        (here, here, here),
    )
    .unwrap_err();
    assert!(
        matches!(e, ComposeError::HandRoot { ref roots, .. } if roots.len() == 2),
        "{e:?}"
    );
}
