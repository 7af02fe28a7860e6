//! Distance queries: analytic cases (sphere–box, capsule–cylinder), a mesh
//! against brute force, closed meshes as solids, obstacle checks.

mod common;

use nalgebra::{Isometry3, Point3, Vector3};
use tsukami_body::collision::{CollisionObject, Part, RobotCollision};
use tsukami_body::kinematics::FkState;
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::model::Geometry;
use tsukami_body::RobotModel;

/// A one-link robot whose link carries `geometry` (URDF snippet).
fn probe(geometry: &str) -> (RobotModel, RobotCollision, FkState) {
    let xml = format!(
        r#"<robot name="probe"><link name="probe"><collision><geometry>{geometry}</geometry></collision></link></robot>"#
    );
    let m = RobotModel::from_urdf_str(&xml, std::path::Path::new("/tmp")).unwrap();
    let c = RobotCollision::new(&m).unwrap();
    let fk = FkState::new(&m);
    (m, c, fk)
}

fn place(m: &RobotModel, fk: &mut FkState, pose: Isometry3<f64>) {
    fk.base = pose;
    m.forward_kinematics(&[], fk);
}

fn object(geometry: Geometry, pose: Isometry3<f64>) -> CollisionObject {
    CollisionObject::new(
        "o",
        pose,
        vec![Part::from_geometry(&Isometry3::identity(), &geometry).unwrap()],
    )
}

#[test]
fn sphere_box() {
    let (m, c, mut fk) = probe(r#"<sphere radius="0.1"/>"#);
    let boxed = object(
        Geometry::Box {
            size: Vector3::new(0.4, 0.6, 0.2),
        },
        Isometry3::identity(),
    );
    place(&m, &mut fk, Isometry3::translation(0.5, 0.2, 0.05));
    let p = c.link_object_proximity(&fk, 0, &boxed, 10.0).unwrap();
    assert!((p.distance - 0.2).abs() < 1e-9, "{p:?}");
    assert!((p.point_on_object - Point3::new(0.2, 0.2, 0.05)).norm() < 1e-9);
    assert!((p.point_on_link - Point3::new(0.4, 0.2, 0.05)).norm() < 1e-9);
    assert!((p.normal.into_inner() - Vector3::x()).norm() < 1e-9);
    // Beyond max_distance: nothing.
    assert!(c.link_object_proximity(&fk, 0, &boxed, 0.1).is_none());
    // Overlapping by 0.03: negative distance, normal still out of the box.
    place(&m, &mut fk, Isometry3::translation(0.27, 0.0, 0.0));
    let p = c.link_object_proximity(&fk, 0, &boxed, 10.0).unwrap();
    assert!((p.distance + 0.03).abs() < 1e-9, "{p:?}");
    assert!((p.normal.into_inner() - Vector3::x()).norm() < 1e-9);
    // A rotated box: the box frame is turned 90° about z.
    let turned = object(
        Geometry::Box {
            size: Vector3::new(0.4, 0.6, 0.2),
        },
        Isometry3::new(Vector3::zeros(), Vector3::z() * std::f64::consts::FRAC_PI_2),
    );
    place(&m, &mut fk, Isometry3::translation(0.5, 0.0, 0.0));
    let p = c.link_object_proximity(&fk, 0, &turned, 10.0).unwrap();
    assert!((p.distance - 0.1).abs() < 1e-9, "{p:?}");
}

#[test]
fn capsule_cylinder() {
    // URDF capsule and cylinder are both along z.
    let (m, c, mut fk) = probe(r#"<capsule radius="0.02" length="0.1"/>"#);
    let cyl = object(
        Geometry::Cylinder {
            radius: 0.05,
            length: 0.2,
        },
        Isometry3::identity(),
    );
    // Side by side, parallel: distance 0.3 - 0.05 - 0.02.
    place(&m, &mut fk, Isometry3::translation(0.0, 0.3, 0.0));
    let p = c.link_object_proximity(&fk, 0, &cyl, 10.0).unwrap();
    assert!((p.distance - 0.23).abs() < 1e-6, "{p:?}");
    assert!((p.point_on_object.y - 0.05).abs() < 1e-6 && p.point_on_object.z.abs() <= 0.05 + 1e-6);
    assert!((p.point_on_link.y - 0.28).abs() < 1e-6);
    assert!((p.normal.into_inner() - Vector3::y()).norm() < 1e-6);
    // Lying across the top: capsule along x, 0.2 above the centre.
    place(
        &m,
        &mut fk,
        Isometry3::new(
            Vector3::new(0.0, 0.0, 0.2),
            Vector3::y() * std::f64::consts::FRAC_PI_2,
        ),
    );
    let p = c.link_object_proximity(&fk, 0, &cyl, 10.0).unwrap();
    assert!((p.distance - 0.08).abs() < 1e-6, "{p:?}");
    assert!((p.point_on_object.z - 0.1).abs() < 1e-6);
    assert!((p.normal.into_inner() - Vector3::z()).norm() < 1e-6);
    // Off the rim, diagonally: the closest point is on the rim circle.
    place(
        &m,
        &mut fk,
        Isometry3::new(
            Vector3::new(0.15, 0.0, 0.25),
            Vector3::y() * std::f64::consts::FRAC_PI_2,
        ),
    );
    let p = c.link_object_proximity(&fk, 0, &cyl, 10.0).unwrap();
    // Capsule segment x in [0.1, 0.2] at z 0.25; rim point (0.05, 0, 0.1).
    let expect = ((0.1f64 - 0.05).powi(2) + 0.15f64.powi(2)).sqrt() - 0.02;
    assert!((p.distance - expect).abs() < 1e-7, "{p:?} vs {expect}");
    assert!((p.point_on_object - Point3::new(0.05, 0.0, 0.1)).norm() < 1e-6);
}

/// Closest point on triangle `abc` to `p` (the shared brute-force reference).
fn closest_on_triangle(
    p: Point3<f64>,
    a: Point3<f64>,
    b: Point3<f64>,
    c: Point3<f64>,
) -> Point3<f64> {
    Point3::from(common::closest_on_triangle(
        p.coords,
        &[a.coords, b.coords, c.coords],
    ))
}

#[test]
fn mesh_distance_matches_brute_force() {
    let (m, c, mut fk) = probe(r#"<sphere radius="0.015"/>"#);
    let can = TriangleMesh::load(
        &common::models_dir().join("objects/can_350ml/can_350ml.stl"),
        Vector3::repeat(1.0),
    )
    .unwrap();
    let obj_pose = Isometry3::new(Vector3::new(0.4, -0.2, 0.8), Vector3::new(0.2, -0.1, 0.7));
    let object = CollisionObject::from_mesh("can", obj_pose, &can).unwrap();
    assert!(object.is_solid());
    let mut rng = common::rng(5);
    use rand::Rng;
    let mut checked = 0;
    for _ in 0..300 {
        let local = Point3::new(
            rng.random_range(-0.12..0.12),
            rng.random_range(-0.12..0.12),
            rng.random_range(-0.08..0.2),
        );
        let centre = obj_pose * local;
        place(
            &m,
            &mut fk,
            Isometry3::translation(centre.x, centre.y, centre.z),
        );
        // Brute force over every triangle, in the object frame.
        let (mut best, mut best_pt) = (f64::INFINITY, Point3::origin());
        for k in 0..can.indices.len() {
            let [a, b, cc] = can.triangle(k);
            let q = closest_on_triangle(local, a, b, cc);
            let d = (q - local).norm();
            if d < best {
                best = d;
                best_pt = q;
            }
        }
        let inside = can.volume() > 0.0 && {
            // Inside iff the vector to the closest point faces the same way as the outward normal there.
            let k = (0..can.indices.len())
                .min_by(|&i, &j| {
                    let [a, b, cc] = can.triangle(i);
                    let [d, e, f] = can.triangle(j);
                    (closest_on_triangle(local, a, b, cc) - local)
                        .norm()
                        .total_cmp(&(closest_on_triangle(local, d, e, f) - local).norm())
                })
                .unwrap();
            (best_pt - local).dot(&can.triangle_normal(k)) > 0.0
        };
        let Some(p) = c.link_object_proximity(&fk, 0, &object, 1.0) else {
            panic!("no result")
        };
        if best > 0.02 {
            // Inside: our distance is minus the distance from the ball's surface to
            // the mesh surface.
            let expect = if inside {
                -(best - 0.015)
            } else {
                best - 0.015
            };
            let ours = p.distance;
            if inside {
                assert!(ours < 0.0, "inside point reported at {ours}");
                assert!((ours - expect).abs() < 1e-6, "{ours} vs {expect}");
            } else {
                assert!((ours - expect).abs() < 1e-6, "{ours} vs {expect}");
                assert!((p.point_on_object - obj_pose * best_pt).norm() < 1e-6);
                // The normal points from the object toward the link.
                assert!(
                    (p.normal.into_inner() - (centre - p.point_on_object).normalize()).norm()
                        < 1e-6
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked}");
}

#[test]
fn closed_meshes_are_solids_open_ones_are_not() {
    let (m, c, mut fk) = probe(r#"<sphere radius="0.01"/>"#);
    let can = TriangleMesh::cylinder(0.033, 0.122, 32);
    let solid = CollisionObject::from_mesh("can", Isometry3::identity(), &can).unwrap();
    place(&m, &mut fk, Isometry3::translation(0.0, 0.0, 0.06));
    let p = c.link_object_proximity(&fk, 0, &solid, 1.0).unwrap();
    assert!(p.distance < 0.0, "{p:?}");
    assert!(c.first_collision(&fk, &[0], &[&solid], 0.0).is_some());
    // The same mesh without its caps is open: a surface only.
    let mut open = can.clone();
    open.indices.truncate(64);
    assert!(!open.is_closed());
    let surface = CollisionObject::from_mesh("tube", Isometry3::identity(), &open).unwrap();
    assert!(!surface.is_solid());
    assert!(c.first_collision(&fk, &[0], &[&surface], 0.0).is_none());
    // Margins: 5 mm from the side is clear at margin 0 but not at 1 cm.
    place(&m, &mut fk, Isometry3::translation(0.048, 0.0, 0.06));
    assert!(c.first_collision(&fk, &[0], &[&solid], 0.0).is_none());
    assert!(c.first_collision(&fk, &[0], &[&solid], 0.01).is_some());
}

#[test]
fn hand_links_against_a_can() {
    let m = common::humanoid();
    let c = RobotCollision::new(&m).unwrap();
    let mut fk = FkState::new(&m);
    m.forward_kinematics(&m.rest_positions(), &mut fk);
    let tip = m.link_id("r_index_l4").unwrap();
    let can = TriangleMesh::load(
        &common::models_dir().join("objects/can_350ml/can_350ml.stl"),
        Vector3::repeat(1.0),
    )
    .unwrap();
    // Put the can 2 cm in front of the fingertip along the palm normal.
    let palm = fk.pose(m.link_id("r_palm").unwrap());
    let tip_pose = fk.pose(tip);
    let centre =
        tip_pose.translation.vector + palm.rotation * Vector3::z() * (0.0085 + 0.02 + 0.033);
    let pose = Isometry3::translation(centre.x, centre.y, centre.z - 0.061);
    let obj = CollisionObject::from_mesh("can", pose, &can).unwrap();
    let p = c.link_object_proximity(&fk, tip, &obj, 1.0).unwrap();
    assert!((p.distance - 0.02).abs() < 2e-3, "{p:?}");
    // Normal on the can's side points back toward the finger (-palm z).
    assert!(p.normal.dot(&(palm.rotation * -Vector3::z())) > 0.95);
}

/// The AABB broad phase of the pair queries (link boxes, then part boxes,
/// placed once per configuration) skips only pairs that cannot collide: the
/// same pairs come out as from each pair's distance, which uses no box.
#[test]
fn broad_phase_drops_no_colliding_pair() {
    let m = common::humanoid();
    let c = RobotCollision::new(&m).unwrap();
    let mut fk = FkState::new(&m);
    let mut rng = common::rng(11);
    let margin = 0.005;
    let links: Vec<usize> = (0..m.links.len())
        .filter(|&l| !c.link_parts(l).is_empty())
        .collect();
    let table = object(
        Geometry::Box {
            size: Vector3::new(0.4, 0.6, 0.9),
        },
        Isometry3::translation(0.45, -0.2, 0.45),
    );
    let (mut pairs, mut hits) = (0, 0);
    for _ in 0..60 {
        m.forward_kinematics(&common::random_q(&m, &mut rng), &mut fk);
        let mut expected = Vec::new();
        for (i, &a) in links.iter().enumerate() {
            let body = CollisionObject::new("a", *fk.pose(a), c.link_parts(a).to_vec());
            for &b in &links[i + 1..] {
                if !c.is_allowed(a, b) && c.link_object_proximity(&fk, b, &body, margin).is_some() {
                    expected.push((a, b));
                }
            }
        }
        assert_eq!(c.self_collisions(&fk, margin), expected);
        pairs += expected.len();
        for &l in &links {
            let near = c.link_object_proximity(&fk, l, &table, margin).is_some();
            assert_eq!(
                c.first_collision(&fk, &[l], &[&table], margin).is_some(),
                near
            );
            hits += usize::from(near);
        }
    }
    assert!(
        pairs > 10 && hits > 10,
        "{pairs} self pairs, {hits} table hits"
    );
}

#[test]
fn a_point_on_a_faceted_cylinders_edge_has_both_faces_normals() {
    // A contact computed on a vertical edge of a 24-sided can lands a
    // rounding error inside one face as often as not; the surface's normal
    // cone there is still both faces' (as the independent checker finds it),
    // not the one face's, 7.5° off the contact normal.
    let (r, h, n) = (0.033, 0.122, 24);
    let can = TriangleMesh::cylinder(r, h, n);
    let object =
        CollisionObject::from_mesh("can", Isometry3::translation(0.4, -0.2, 0.7), &can).unwrap();
    let pose = *object.pose();
    let half = std::f64::consts::PI / n as f64;
    let mut edges = 0;
    for v in can.vertices.iter().filter(|v| v.z.abs() < 1e-12) {
        let theta = v.y.atan2(v.x);
        if (v.coords.xy().norm() - r).abs() > 1e-9 {
            continue; // a cap's centre
        }
        edges += 1;
        let tangent = Vector3::new(-theta.sin(), theta.cos(), 0.0);
        for (z, nudge) in [(0.3, 1e-9), (0.5, -1e-9), (0.7, 0.0)] {
            let p = pose * (Point3::new(v.x, v.y, z * h) + tangent * nudge);
            let s = object.surface_point(&p).unwrap();
            assert!(s.distance < 1e-8, "{}", s.distance);
            for side in [-half, half] {
                let face =
                    pose.rotation * Vector3::new((theta + side).cos(), (theta + side).sin(), 0.0);
                assert!(
                    s.normals.iter().any(|m| m.angle(&face) < 1e-6),
                    "edge at {:.1}°, z {z}: normals {:?} miss the face at {:.1}°",
                    theta.to_degrees(),
                    s.normals,
                    (theta + side).to_degrees()
                );
            }
            assert!(!s.on_face);
        }
        // Inside a face, away from its edges: that face's normal alone.
        let mid = Vector3::new((theta + half).cos(), (theta + half).sin(), 0.0) * r * half.cos();
        let s = object
            .surface_point(&(pose * Point3::new(mid.x, mid.y, 0.5 * h)))
            .unwrap();
        assert!(s.on_face && s.normals.len() == 1, "{:?}", s.normals);
    }
    assert_eq!(edges, n);
}
