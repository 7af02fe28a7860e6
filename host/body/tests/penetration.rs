//! Penetration depth of links into objects: touching passes, sinking is
//! measured, a link wholly inside a closed mesh counts as deep.

use nalgebra::{Isometry3, Vector3};
use tsukami_body::collision::{CollisionObject, Part, RobotCollision};
use tsukami_body::kinematics::FkState;
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::model::Geometry;
use tsukami_body::RobotModel;

fn probe(geometry: &str) -> (RobotModel, RobotCollision, FkState) {
    let xml = format!(
        r#"<robot name="probe"><link name="probe"><collision><geometry>{geometry}</geometry></collision></link></robot>"#
    );
    let m = RobotModel::from_urdf_str(&xml, std::path::Path::new("/tmp")).unwrap();
    let c = RobotCollision::new(&m).unwrap();
    let fk = FkState::new(&m);
    (m, c, fk)
}

fn place(m: &RobotModel, fk: &mut FkState, x: f64, y: f64, z: f64) {
    fk.base = Isometry3::translation(x, y, z);
    m.forward_kinematics(&[], fk);
}

#[test]
fn sphere_into_a_box_and_a_closed_mesh() {
    let (m, c, mut fk) = probe(r#"<sphere radius="0.01"/>"#);
    let table = CollisionObject::new(
        "table",
        Isometry3::identity(),
        vec![Part::from_geometry(
            &Isometry3::identity(),
            &Geometry::Box {
                size: Vector3::new(1.0, 1.0, 0.1),
            },
        )
        .unwrap()],
    );
    // Apart, touching, 0.5 mm in, 4 mm in.
    for (z, want) in [(0.08, 0.0), (0.06, 0.0), (0.0595, 0.0005), (0.056, 0.004)] {
        place(&m, &mut fk, 0.0, 0.0, z);
        let d = c.link_penetration(&fk, 0, &table);
        assert!((d - want).abs() < 1e-6, "z {z}: depth {d}, want {want}");
    }
    place(&m, &mut fk, 0.0, 0.0, 0.056);
    assert!(c.first_penetration(&fk, &[0], &[&table], 1e-3).is_some());
    assert!(c.first_penetration(&fk, &[0], &[&table], 5e-3).is_none());

    // A closed cylinder mesh (z from 0 to 0.12): a sphere at its centre is wholly inside.
    let can = CollisionObject::from_mesh(
        "can",
        Isometry3::translation(1.0, 0.0, 0.0),
        &TriangleMesh::cylinder(0.04, 0.12, 32),
    )
    .unwrap();
    place(&m, &mut fk, 1.0, 0.0, 0.06);
    let d = c.link_penetration(&fk, 0, &can);
    assert!(d > 0.02, "inside depth {d}");
    let hit = c
        .first_penetration(&fk, &[0], &[&table, &can], 1e-3)
        .unwrap();
    assert_eq!(hit.object, 1);
    // Just touching the side from outside.
    place(&m, &mut fk, 1.0 + 0.04 + 0.0101, 0.0, 0.06);
    assert!(c.link_penetration(&fk, 0, &can) < 1e-6);
}
