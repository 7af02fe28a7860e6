//! The picture and the `.glb` of the paper's can-at-breast-height grasp,
//! planned by the built-in planner: the picture shows the hand, the can and
//! the contact markers where they project; the `.glb` is structurally valid
//! glTF 2.0 (header, chunks, accessors against buffer views, node tree).
//!
//! The drawing is the host library `tsukami-render`; the grasp needs the
//! paper's planner, linked here as a library (the one plugin crate this test
//! links), so the test lives with the end-to-end tests rather than in
//! `host/render`, whose manifest names no plugin crate.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use nalgebra::{Point3, Vector3};
use serde_json::Value;
use tsukami_grasp_planner::planner::Planner;
use tsukami_msgs::planner::{PlanOptions, PlanReply};
use tsukami_render::drawing::Drawing;
use tsukami_render::glb::to_glb;
use tsukami_render::render::{render, Camera, Picture};
use tsukami_scenes::{scene_requests, World};

const W: u32 = 480;
const H: u32 = 360;

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../models")
}

/// The planned can grasp, its world and its drawing.
fn can_breast() -> (PlanReply, World, Drawing) {
    let req = scene_requests(&models().join("scenes/can_breast.toml")).unwrap();
    let p = Planner::new(models());
    p.set_robot(&req.robot).unwrap();
    p.set_object(&req.object).unwrap();
    p.set_env(&req.env).unwrap();
    let reply = p
        .plan(
            &PlanOptions::default(),
            &AtomicBool::new(false),
            &mut |_| {},
        )
        .unwrap();
    let world = World::from_requests(&models(), &req.robot, &req.object, &req.env).unwrap();
    // The drawing `tsukami view` and the demo's report make.
    let drawing = tsukami::picture::scene_drawing(&world, Some(&reply)).unwrap();
    (reply, world, drawing)
}

/// The camera of the test picture: the robot's right side, a little above.
fn camera(world: &World) -> Camera {
    let target = Point3::from(world.object.pose.translation.vector);
    Camera::looking_at(
        target + Vector3::new(0.15, -0.55, 0.25),
        target,
        Vector3::z(),
    )
}

fn is_object(p: [u8; 3]) -> bool {
    let [r, g, b] = p.map(i32::from);
    b > r + 60 && b > g + 30
}
fn is_hand(p: [u8; 3]) -> bool {
    let [r, g, b] = p.map(i32::from);
    r > g + 40 && g > b + 40
}
fn is_contact(p: [u8; 3]) -> bool {
    let [r, g, b] = p.map(i32::from);
    r > 100 && r > 3 * g && r > 3 * b
}

fn count(picture: &Picture, class: fn([u8; 3]) -> bool) -> usize {
    picture.pixels.iter().filter(|&&p| class(p)).count()
}

#[test]
fn the_picture_shows_hand_can_and_contacts_where_they_are() {
    let (reply, world, drawing) = can_breast();
    let camera = camera(&world);
    let picture = render(&drawing, &camera, W, H);
    let (hand, object, contact) = (
        count(&picture, is_hand),
        count(&picture, is_object),
        count(&picture, is_contact),
    );
    assert!(
        hand > 500 && object > 2000 && contact > 20,
        "hand {hand}, object {object}, contact {contact} pixels"
    );
    // Each contact marker is drawn where the contact projects.
    for c in &reply.contacts {
        let [x, y] = camera.project(&Point3::from(c.position), W, H).unwrap();
        assert!(
            x >= 0.0 && y >= 0.0 && x < f64::from(W) && y < f64::from(H),
            "{x} {y}"
        );
        assert!(
            is_contact(picture.pixel(x as u32, y as u32)),
            "contact on {} at ({x:.0}, {y:.0})",
            c.link
        );
    }
    // The can's pixels lie around where its centre projects.
    let [cx, cy] = camera
        .project(&Point3::from(world.object.pose.translation.vector), W, H)
        .unwrap();
    let near_can = (0..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .filter(|&(x, y)| is_object(picture.pixel(x, y)))
        .filter(|&(x, y)| (f64::from(x) - cx).abs() < 120.0 && (f64::from(y) - cy).abs() < 160.0)
        .count();
    assert!(
        near_can > object * 9 / 10,
        "{near_can} of {object} can pixels near its centre"
    );
    // Without the contacts nothing else in the picture has the contact colour.
    let mut bare = drawing.clone();
    bare.groups
        .retain(|g| !g.name.starts_with("contact") && !g.name.starts_with("friction"));
    assert_eq!(count(&render(&bare, &camera, W, H), is_contact), 0);
    let png = picture.to_png().unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n") && png.len() > 1000);
}

/// Reads a `.glb` as the specification lays it out (independently of the writer).
fn parse_glb(bytes: &[u8]) -> (Value, Vec<u8>) {
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(word(4), 2, "version");
    assert_eq!(word(8), bytes.len(), "total length");
    let json_len = word(12);
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let json: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let at = 20 + json_len;
    let bin_len = word(at);
    assert_eq!(&bytes[at + 4..at + 8], b"BIN\0");
    assert_eq!(at + 8 + bin_len, bytes.len());
    (json, bytes[at + 8..].to_vec())
}

#[test]
fn the_glb_is_valid_gltf_with_one_node_per_group() {
    let (_, _, drawing) = can_breast();
    let (json, bin) = parse_glb(&to_glb(&drawing));
    assert_eq!(json["asset"]["version"], "2.0");
    let buffer_len = json["buffers"][0]["byteLength"].as_u64().unwrap() as usize;
    assert!(buffer_len <= bin.len() && bin.len() - buffer_len < 4);
    let views = json["bufferViews"].as_array().unwrap();
    for v in views {
        let (offset, len) = (
            v["byteOffset"].as_u64().unwrap(),
            v["byteLength"].as_u64().unwrap(),
        );
        assert!(
            offset % 4 == 0 && (offset + len) as usize <= buffer_len,
            "{v}"
        );
    }
    let accessors = json["accessors"].as_array().unwrap();
    for a in accessors {
        let view = &views[a["bufferView"].as_u64().unwrap() as usize];
        let (size, components) = match a["type"].as_str().unwrap() {
            "VEC3" => (12, 3),
            "SCALAR" => (4, 1),
            other => panic!("accessor type {other}"),
        };
        let count = a["count"].as_u64().unwrap();
        assert!(count > 0);
        assert_eq!(count * size, view["byteLength"].as_u64().unwrap(), "{a}");
        if components == 3 {
            let (min, max) = (a["min"].as_array().unwrap(), a["max"].as_array().unwrap());
            assert!(min.iter().zip(max).all(|(l, h)| l.as_f64() <= h.as_f64()));
        }
    }
    // Every index is inside its mesh's position accessor.
    for mesh in json["meshes"].as_array().unwrap() {
        let prim = &mesh["primitives"][0];
        let positions = &accessors[prim["attributes"]["POSITION"].as_u64().unwrap() as usize];
        let indices = &accessors[prim["indices"].as_u64().unwrap() as usize];
        let view = &views[indices["bufferView"].as_u64().unwrap() as usize];
        let start = view["byteOffset"].as_u64().unwrap() as usize;
        let n = positions["count"].as_u64().unwrap() as u32;
        for k in 0..indices["count"].as_u64().unwrap() as usize {
            let i = u32::from_le_bytes(bin[start + 4 * k..start + 4 * k + 4].try_into().unwrap());
            assert!(i < n, "{} index {i} of {n}", mesh["name"]);
        }
    }
    // Node tree: one root, whose children are every other node, once each.
    let nodes = json["nodes"].as_array().unwrap();
    assert_eq!(json["scenes"][0]["nodes"], serde_json::json!([0]));
    let children: Vec<u64> = nodes[0]["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_u64().unwrap())
        .collect();
    assert_eq!(children, (1..nodes.len() as u64).collect::<Vec<_>>());
    assert_eq!(nodes.len() - 1, drawing.groups.len());
    assert!(nodes.iter().skip(1).all(|n| n.get("children").is_none()));
    let names: Vec<&str> = nodes.iter().filter_map(|n| n["name"].as_str()).collect();
    for wanted in ["object", "link r_palm", "contact 0", "friction cone 0"] {
        assert!(names.contains(&wanted), "{wanted} not in {names:?}");
    }
}
