//! The paper's scenes: they load, objects rest on their supports, and the
//! arm-only / whole-body reachability matches the paper's story.

mod common;

use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use tsukami_body::ik::{IkOptions, IkSolver};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::scene::Scene;

fn scene(name: &str) -> Scene {
    Scene::load(
        &common::models_dir()
            .join("scenes")
            .join(format!("{name}.toml")),
    )
    .expect("scene loads")
}

/// Palm pose with this normal (approach direction) and finger direction.
fn palm_pose(at: Point3<f64>, normal: Vector3<f64>, fingers: Vector3<f64>) -> Isometry3<f64> {
    let z = normal.normalize();
    let x = fingers.normalize();
    let r = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, z.cross(&x), z]));
    Isometry3::from_parts(
        Translation3::from(at.coords),
        UnitQuaternion::from_rotation_matrix(&r),
    )
}

/// Side approaches around an upright object: palm facing the axis from
/// directions within ±60° of the robot's line of sight, fingers horizontal
/// (thumb up or down), palm `gap` from the surface at mid-height.
fn side_poses(s: &Scene, object: &str, radius: f64, height: f64, gap: f64) -> Vec<Isometry3<f64>> {
    let o = s.object(object).unwrap();
    let c = o.pose.translation.vector;
    let mut out = Vec::new();
    for k in -4..=4 {
        let phi = (c.y.atan2(c.x)) + k as f64 * 15f64.to_radians();
        let d = Vector3::new(phi.cos(), phi.sin(), 0.0);
        let at = Point3::new(c.x, c.y, c.z + height / 2.0) - d * (radius + gap);
        for sign in [-1.0, 1.0] {
            let fingers = Vector3::z().cross(&d) * sign;
            out.push(s.to_robot_frame(&palm_pose(at, d, fingers)));
        }
    }
    out
}

/// Top approaches: palm facing down above the object, 8 rotations.
fn top_poses(s: &Scene, object: &str, height: f64, gap: f64) -> Vec<Isometry3<f64>> {
    let c = s.object(object).unwrap().pose.translation.vector;
    let at = Point3::new(c.x, c.y, c.z + height + gap);
    (0..8)
        .map(|k| {
            let a = k as f64 * std::f64::consts::FRAC_PI_4;
            s.to_robot_frame(&palm_pose(
                at,
                -Vector3::z(),
                Vector3::new(a.cos(), a.sin(), 0.0),
            ))
        })
        .collect()
}

fn reachable(s: &Scene, poses: &[Isometry3<f64>], extra: &[&str]) -> usize {
    let m = &s.robot;
    let mut names: Vec<&str> = extra.to_vec();
    names.extend(common::humanoid_groups().arm);
    let sel = JointSelection::from_names(m, &names).unwrap();
    let mut solver =
        IkSolver::new(m, m.link_id("r_palm").unwrap(), sel, IkOptions::default()).unwrap();
    let rest = m.rest_positions();
    poses
        .iter()
        .filter(|p| solver.solve(p, true, &rest, None).ok)
        .count()
}

#[test]
fn every_scene_loads_and_objects_rest_on_supports() {
    for name in [
        "can_breast",
        "can_waist",
        "heavy_low",
        "fridge_pet",
        "vase_table",
    ] {
        let s = scene(name);
        assert_eq!(s.name, name);
        assert!(!s.objects.is_empty() && !s.obstacles.is_empty(), "{name}");
        let m = &s.robot;
        let collision = tsukami_body::collision::RobotCollision::new(m).unwrap();
        let mut fk = FkState::new(m);
        fk.base = s.robot_base;
        m.forward_kinematics(&m.rest_positions(), &mut fk);
        let links: Vec<usize> = (0..m.links.len()).collect();
        // The standing robot touches nothing.
        let mut all: Vec<&tsukami_body::collision::CollisionObject> = s.obstacle_refs();
        all.extend(s.objects.iter().map(|o| &o.collision));
        assert!(
            collision.first_collision(&fk, &links, &all, 0.0).is_none(),
            "{name}"
        );
        for o in &s.objects {
            assert!(o.model.is_closed(), "{name}: {}", o.name);
            // The object rests on a support: its bottom is within 1 mm of an
            // obstacle, and nothing penetrates it deeper than 1 mm.
            let mut lowest = f64::INFINITY;
            for ob in &s.obstacles {
                for part in ob.parts() {
                    let pose = tsukami_body::convert::to_pose(ob.pose());
                    let w = pose * part.origin;
                    let op = tsukami_body::convert::to_pose(&o.pose);
                    let d = o.collision.parts()[0].shape.clone();
                    if let Ok(Some(c)) =
                        parry3d_f64::query::contact(&op, &*d, &w, &*part.shape, 0.01)
                    {
                        assert!(c.dist > -1e-3, "{name}: {} penetrates {}", o.name, ob.name);
                        lowest = lowest.min(c.dist);
                    }
                }
            }
            assert!(lowest.abs() < 1e-3, "{name}: {} floats {lowest}", o.name);
        }
    }
}

#[test]
fn cans_at_breast_and_waist_height_are_reachable_with_the_arm() {
    let s = scene("can_breast");
    let side = side_poses(&s, "can", 0.033, 0.122, 0.02);
    assert!(
        reachable(&s, &side, &[]) > 0,
        "can_breast: no side grasp reachable by the arm"
    );
    let s = scene("can_waist");
    let top = top_poses(&s, "can", 0.122, 0.02);
    assert!(
        reachable(&s, &top, &[]) > 0,
        "can_waist: no top grasp reachable by the arm"
    );
}

#[test]
fn low_objects_need_squatting() {
    let groups = common::humanoid_groups();
    let mut whole = vec![groups.squat];
    whole.extend(groups.waist);
    for (name, object, r, h) in [
        ("heavy_low", "can", 0.033, 0.122),
        ("fridge_pet", "pet", 0.0325, 0.205),
    ] {
        let s = scene(name);
        let side = side_poses(&s, object, r, h, 0.02);
        assert_eq!(
            reachable(&s, &side, &[]),
            0,
            "{name}: the arm alone should not reach"
        );
        assert!(
            reachable(&s, &side, &whole) > 0,
            "{name}: squat + waist should reach"
        );
    }
}

#[test]
fn scene_errors_name_the_file_and_field() {
    let dir = std::env::temp_dir().join(format!("tsukami-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let robot = common::humanoid_path();
    let cases = [
        ("unknown_key.toml", format!("[robot]\nmodel = {robot:?}\ncolour = 1\n"), "colour"),
        (
            "bad_mass.toml",
            format!("[robot]\nmodel = {robot:?}\n[[objects]]\nname = \"o\"\nshape = {{ sphere = {{ radius = 0.05 }} }}\nmass = -1.0\nfriction = 0.5\npose = {{ xyz = [0, 0, 0] }}\n"),
            "mass",
        ),
        (
            "no_model.toml",
            format!("[robot]\nmodel = {robot:?}\n[[objects]]\nname = \"o\"\nmodel = \"nope\"\npose = {{}}\n"),
            "objects[0]",
        ),
        (
            "nan_pose.toml",
            format!("[robot]\nmodel = {robot:?}\n[[obstacles]]\nname = \"t\"\npose = {{ xyz = [nan, 0, 0] }}\nparts = [ {{ shape = {{ box = {{ size = [1, 1, 1] }} }} }} ]\n"),
            "obstacles[0]",
        ),
    ];
    for (file, text, needle) in cases {
        let p = dir.join(file);
        std::fs::write(&p, text).unwrap();
        let msg = Scene::load(&p).unwrap_err().to_string();
        assert!(msg.contains(file) && msg.contains(needle), "{msg}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
