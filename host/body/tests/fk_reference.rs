//! Forward kinematics against implementations this crate did not write: a
//! reference FK written here from the URDF specification alone (urdf-rs's
//! parser, plain 4×4 arrays, mimic joints from their `<mimic>` tags) on random
//! configurations of the humanoid, and hand-derived closed forms on a 3-joint
//! chain. Jacobians are checked against finite differences of FK, including
//! mimic joints folded into their masters.
//!
//! (The reference was the `k` crate until it was dropped: it brought a second
//! nalgebra, 0.30, into the build.)

mod common;

use std::collections::HashMap;

use nalgebra::{Point3, Vector3};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::RobotModel;

/// A homogeneous transform, row-major.
type M4 = [[f64; 4]; 4];

fn mul(a: &M4, b: &M4) -> M4 {
    let mut c = [[0.0; 4]; 4];
    for (i, row) in c.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

/// `rotation` (3×3) and `translation` as a transform.
fn transform(rotation: [[f64; 3]; 3], translation: [f64; 3]) -> M4 {
    let mut m = [[0.0, 0.0, 0.0, 1.0]; 4];
    for i in 0..3 {
        m[i] = [
            rotation[i][0],
            rotation[i][1],
            rotation[i][2],
            translation[i],
        ];
    }
    m
}

/// A URDF `<origin>`: `Rz(yaw) Ry(pitch) Rx(roll)`, then the offset.
fn origin(xyz: [f64; 3], [r, p, y]: [f64; 3]) -> M4 {
    let (sr, cr, sp, cp, sy, cy) = (r.sin(), r.cos(), p.sin(), p.cos(), y.sin(), y.cos());
    let rotation = [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ];
    transform(rotation, xyz)
}

/// `axis` scaled to unit length.
fn unit(axis: [f64; 3]) -> [f64; 3] {
    let n = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
    axis.map(|a| a / n)
}

/// Translation by `d` along `axis`.
fn along(axis: [f64; 3], d: f64) -> M4 {
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    transform(identity, unit(axis).map(|a| a * d))
}

/// Rotation by `angle` about `axis` (Rodrigues).
fn about(axis: [f64; 3], angle: f64) -> M4 {
    let [x, y, z] = unit(axis);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    let rotation = [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ];
    transform(rotation, [0.0; 3])
}

/// Every link's world transform at joint values `value` (by joint name;
/// a mimic joint follows its master as its `<mimic>` tag says).
fn reference_fk(robot: &urdf_rs::Robot, value: impl Fn(&str) -> f64) -> HashMap<String, M4> {
    use urdf_rs::JointType::*;
    let identity = origin([0.0; 3], [0.0; 3]);
    let children: Vec<&str> = robot.joints.iter().map(|j| j.child.link.as_str()).collect();
    let root = robot
        .links
        .iter()
        .find(|l| !children.contains(&l.name.as_str()));
    let mut poses = HashMap::from([(root.expect("a root link").name.clone(), identity)]);
    while poses.len() < robot.links.len() {
        let before = poses.len();
        for j in &robot.joints {
            let Some(parent) = poses.get(&j.parent.link).copied() else {
                continue;
            };
            let q = match &j.mimic {
                Some(m) => m.multiplier.unwrap_or(1.0) * value(&m.joint) + m.offset.unwrap_or(0.0),
                None => value(&j.name),
            };
            let axis = *j.axis.xyz;
            let motion = match j.joint_type {
                Revolute | Continuous => about(axis, q),
                Prismatic => along(axis, q),
                _ => identity,
            };
            let pose = mul(
                &mul(&parent, &origin(*j.origin.xyz, *j.origin.rpy)),
                &motion,
            );
            poses.insert(j.child.link.clone(), pose);
        }
        assert!(poses.len() > before, "the URDF's links are not one tree");
    }
    poses
}

#[test]
fn humanoid_fk_matches_a_reference_written_from_the_urdf_spec() {
    let m = common::humanoid();
    let robot = urdf_rs::read_file(common::humanoid_path()).expect("urdf-rs reads the URDF");
    let mut fk = FkState::new(&m);
    let mut rng = common::rng(42);
    let mut worst = 0.0f64;
    let palm = m.link_id("r_palm").unwrap();
    let mut palm_spread = 0.0f64;
    for _ in 0..200 {
        let q = common::random_q(&m, &mut rng);
        let theirs = reference_fk(&robot, |name| q[m.joint_id(name).expect("a joint")]);
        m.forward_kinematics(&q, &mut fk);
        // Guard against a vacuous comparison: configurations really differ.
        palm_spread = palm_spread.max((fk.pose(palm).translation.vector.z - 0.8).abs());
        for (l, link) in m.links.iter().enumerate() {
            let theirs = theirs
                .get(&link.name)
                .expect("the reference knows the link");
            let ours = fk.pose(l).to_homogeneous();
            let dt = (0..3)
                .map(|i| (theirs[i][3] - ours[(i, 3)]).powi(2))
                .sum::<f64>()
                .sqrt();
            let dr = (0..3)
                .flat_map(|i| (0..3).map(move |j| (i, j)))
                .map(|(i, j)| (theirs[i][j] - ours[(i, j)]).powi(2))
                .sum::<f64>()
                .sqrt();
            worst = worst.max(dt);
            assert!(dt < 1e-9, "link {} position differs by {dt:e}", link.name);
            assert!(dr < 1e-9, "link {} rotation differs by {dr:e}", link.name);
        }
    }
    assert!(palm_spread > 0.3, "configurations did not move the palm");
    eprintln!("worst FK position difference vs the reference: {worst:e} m");
}

const CHAIN: &str = r#"<robot name="chain3">
  <link name="base"/><link name="a"/><link name="b"/><link name="tip"/>
  <joint name="q1" type="revolute"><origin xyz="0 0 0.3"/><parent link="base"/><child link="a"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="q2" type="continuous"><origin xyz="0.4 0 0"/><parent link="a"/><child link="b"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="d" type="prismatic"><origin xyz="0.25 0 0" rpy="0 0 0"/><parent link="b"/><child link="tip"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="0.2" effort="10" velocity="1"/></joint>
</robot>"#;

#[test]
fn closed_form_planar_chain() {
    let m = RobotModel::from_urdf_str(CHAIN, std::path::Path::new("/tmp")).unwrap();
    let mut fk = FkState::new(&m);
    let mut rng = common::rng(3);
    for _ in 0..100 {
        let q = common::random_q(&m, &mut rng);
        let (q1, q2, d) = (q[0], q[1], q[2]);
        m.forward_kinematics(&q, &mut fk);
        // tip = (0,0,0.3) + R(q1)(0.4,0,0) + R(q1+q2)(0.25 + d, 0, 0)
        let expect = Vector3::new(
            0.4 * q1.cos() + (0.25 + d) * (q1 + q2).cos(),
            0.4 * q1.sin() + (0.25 + d) * (q1 + q2).sin(),
            0.3,
        );
        let tip = fk.pose(m.link_id("tip").unwrap());
        assert!((tip.translation.vector - expect).norm() < 1e-12);
        let yaw = tip.rotation.euler_angles().2;
        let dyaw = (yaw - (q1 + q2)).sin().abs();
        assert!(dyaw < 1e-12);
        // Analytic Jacobian of the tip position.
        let sel = JointSelection::from_names(&m, &["q1", "q2", "d"]).unwrap();
        let j = m.jacobian(&fk, m.link_id("tip").unwrap(), &Point3::origin(), &sel);
        let s1 = q1.sin();
        let s12 = (q1 + q2).sin();
        let c12 = (q1 + q2).cos();
        let l2 = 0.25 + d;
        assert!((j[(0, 0)] - (-0.4 * s1 - l2 * s12)).abs() < 1e-12);
        assert!((j[(0, 1)] - (-l2 * s12)).abs() < 1e-12);
        assert!((j[(0, 2)] - c12).abs() < 1e-12);
        assert!((j[(1, 2)] - s12).abs() < 1e-12);
        assert!((j[(5, 0)] - 1.0).abs() < 1e-12 && j[(5, 2)].abs() < 1e-12);
    }
}

#[test]
fn jacobian_matches_finite_differences_with_mimics() {
    let m = common::humanoid();
    let tip = m.link_id("r_index_l4").unwrap();
    // r_index_j3 drives the mimic r_index_j4 on the way to the tip.
    let mut names: Vec<&str> = vec!["squat_z", "waist_yaw", "waist_pitch"];
    names.extend(common::humanoid_groups().arm);
    names.extend(["r_index_j1", "r_index_j2", "r_index_j3"]);
    let sel = JointSelection::from_names(&m, &names).unwrap();
    let mut fk = FkState::new(&m);
    let mut rng = common::rng(11);
    let point = Point3::new(0.02, 0.003, -0.004);
    for _ in 0..20 {
        let q = common::random_q(&m, &mut rng);
        m.forward_kinematics(&q, &mut fk);
        let jac = m.jacobian(&fk, tip, &point, &sel);
        let p0 = fk.pose(tip) * point;
        let r0 = fk.pose(tip).rotation;
        let h = 1e-6;
        for (c, &j) in sel.joints.iter().enumerate() {
            let mut qh = q.clone();
            qh[j] += h;
            m.apply_mimics(&mut qh);
            m.forward_kinematics(&qh, &mut fk);
            let dp = (fk.pose(tip) * point - p0) / h;
            let dr = (fk.pose(tip).rotation * r0.inverse()).scaled_axis() / h;
            let lin = jac.fixed_view::<3, 1>(0, c).into_owned();
            let ang = jac.fixed_view::<3, 1>(3, c).into_owned();
            assert!((dp - lin).norm() < 1e-5, "{}: {dp:?} vs {lin:?}", names[c]);
            assert!((dr - ang).norm() < 1e-5, "{}", names[c]);
        }
    }
}
