//! Forward kinematics against implementations this crate did not write:
//! the `k` crate (openrr; its own URDF parser, urdf-rs 0.9, and nalgebra
//! 0.30) on random configurations of the humanoid, and hand-derived closed
//! forms on a 3-joint chain. Jacobians are checked against finite
//! differences of FK, including mimic joints folded into their masters.

mod common;

use nalgebra::{Point3, Vector3};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::RobotModel;

#[test]
fn humanoid_fk_matches_k_crate() {
    let m = common::humanoid();
    let chain = k::Chain::<f64>::from_urdf_file(common::humanoid_path()).expect("k loads the URDF");
    let mut fk = FkState::new(&m);
    let mut rng = common::rng(42);
    let mut worst = 0.0f64;
    let palm = m.link_id("r_palm").unwrap();
    let mut palm_spread = 0.0f64;
    for _ in 0..200 {
        let q = common::random_q(&m, &mut rng);
        // k: set every movable joint, mimic ones with their coupled value.
        for node in chain.iter() {
            let name = node.joint().name.clone();
            if let Ok(j) = m.joint_id(&name) {
                if m.joints[j].is_movable() {
                    node.set_joint_position_unchecked(q[j]);
                }
            }
        }
        chain.update_transforms();
        m.forward_kinematics(&q, &mut fk);
        // Guard against a vacuous comparison: configurations really differ.
        palm_spread = palm_spread.max((fk.pose(palm).translation.vector.z - 0.8).abs());
        for (l, link) in m.links.iter().enumerate().skip(1) {
            let node = chain.find_link(&link.name).expect("k knows the link");
            let theirs = node.world_transform().expect("updated");
            let ours = fk.pose(l);
            let dt = (Vector3::new(
                theirs.translation.vector.x,
                theirs.translation.vector.y,
                theirs.translation.vector.z,
            ) - ours.translation.vector)
                .norm();
            let tq = theirs.rotation.quaternion().coords;
            let oq = ours.rotation.quaternion().coords;
            let dot = (tq.x * oq.x + tq.y * oq.y + tq.z * oq.z + tq.w * oq.w)
                .abs()
                .min(1.0);
            let angle = 2.0 * dot.acos();
            worst = worst.max(dt);
            assert!(dt < 1e-9, "link {} position differs by {dt:e}", link.name);
            assert!(
                angle < 1e-7,
                "link {} rotation differs by {angle:e}",
                link.name
            );
        }
    }
    assert!(palm_spread > 0.3, "configurations did not move the palm");
    eprintln!("worst FK position difference vs k: {worst:e} m");
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
