//! A paper scene drawn with the robot at rest and two contacts put by hand on
//! the can: every part of the scene becomes its own group, the contacts are
//! drawn where they project, and the `.glb` has a node per group. (The
//! planned grasp, which needs a planner, is drawn in
//! `tests/tests/picture_can.rs`.)

use std::path::Path;

use nalgebra::{Point3, Vector3};
use tsukami_render::glb::to_glb;
use tsukami_render::grasp_view::{look_at, ContactMark, GraspView, DEFAULT_EYE};
use tsukami_render::render::{render, Camera};
use tsukami_scenes::{scene_requests, World};

#[test]
fn a_scene_at_rest_with_two_contacts() {
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let req = scene_requests(&models.join("scenes/can_breast.toml")).unwrap();
    let world = World::from_requests(&models, &req.robot, &req.object, &req.env).unwrap();
    let centre = Point3::from(world.object.pose.translation.vector);
    // On the can's side facing the camera (−y), a little apart in height.
    let contacts: Vec<ContactMark> = [0.02, -0.02]
        .map(|dz| ContactMark {
            position: centre + Vector3::new(0.0, -0.033, dz),
            normal: Vector3::y(),
            mu: 0.5,
        })
        .to_vec();
    let q = world.robot.model.rest_positions();
    let drawing = GraspView {
        model: &world.robot.model,
        collision: &world.robot.collision,
        q: &q,
        hand_links: &world.robot.hand_links,
        object: Some((&world.object.mesh, world.object.pose)),
        obstacles: &world.obstacles,
        contacts: &contacts,
    }
    .drawing();
    let names: Vec<&str> = drawing.groups.iter().map(|g| g.name.as_str()).collect();
    for name in ["object", "contact 0", "contact 1", "friction cone 1"] {
        assert!(names.contains(&name), "{name} not in {names:?}");
    }
    assert!(names.iter().any(|n| n.starts_with("link ")));
    assert!(names.iter().any(|n| n.starts_with("obstacle ")));

    let target = look_at(&world.object.mesh, &world.object.pose, &contacts);
    let camera = Camera::offset_from(target, Vector3::from(DEFAULT_EYE));
    let picture = render(&drawing, &camera, 320, 240);
    for c in &contacts {
        let [x, y] = camera.project(&c.position, 320, 240).expect("in front");
        let [r, g, b] = picture.pixel(x as u32, y as u32).map(i32::from);
        assert!(
            r > 100 && r > 3 * g && r > 3 * b,
            "({x:.0}, {y:.0}) is not red: {r} {g} {b}"
        );
    }

    let glb = to_glb(&drawing);
    let word = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!((&glb[0..4], word(4), word(8)), (&b"glTF"[..], 2, glb.len()));
    let json: serde_json::Value = serde_json::from_slice(&glb[20..20 + word(12)]).unwrap();
    assert_eq!(
        json["nodes"].as_array().unwrap().len(),
        drawing.groups.len() + 1
    );
}
