//! Textbook grasps, checked with every method that applies.

mod common;

use nalgebra::{Point3, Vector3};
use tsukami_grasp::contact::Contact;
use tsukami_grasp::ellipsoid::{ellipsoid_test, multi_ellipsoid_test, EllipsoidModel};
use tsukami_grasp::exact::{exact_force_closure, exact_test, exact_weight_scale, ConeModel};
use tsukami_grasp::ferrari_canny::{epsilon_l1, epsilon_linf, FerrariCannyOptions};
use tsukami_grasp::grasp::Grasp;
use tsukami_grasp::grasp_matrix::{contact_block, Wrench};

const CONES: [ConeModel; 2] = [ConeModel::Circular, ConeModel::Polyhedral { sides: 8 }];

fn down(grasp: &Grasp, mass: f64) -> Wrench {
    grasp.weight_wrench(mass, &Vector3::new(0.0, 0.0, -9.81), grasp.reference())
}

fn pinch() -> Grasp {
    let contacts = vec![
        Contact::new(Point3::new(0.03, 0.0, 0.0), -Vector3::x()).unwrap(),
        Contact::new(Point3::new(-0.03, 0.0, 0.0), Vector3::x()).unwrap(),
    ];
    Grasp::new(contacts, 0.5, 10.0, 0.03, Point3::origin()).unwrap()
}

#[test]
fn antipodal_pinch_is_not_force_closure_but_holds_its_weight() {
    let g = pinch();
    let w = down(&g, 0.1);
    let e = ellipsoid_test(&g, &EllipsoidModel::default(), &w);
    assert!(
        e.degenerate,
        "nothing resists torque about the contact line"
    );
    assert!(!e.force_closure(0.0));
    for cone in CONES {
        let x = exact_test(&g, cone, &w).unwrap();
        assert!(!x.closure.force_closure);
        assert_eq!(x.closure.grasp_rank, 5);
        // The squeeze exists, only the rank fails.
        assert!(x.closure.squeeze_margin > 1.0);
        // Friction holds up to 2 μ f_max; the inscribed pyramid reaches between
        // cos(π/k) of that (facet) and all of it (edge), depending on its tangents.
        let full = 2.0 * 0.5 * 10.0 / (0.1 * 9.81);
        let s = x.weight.weight_scale;
        match cone {
            ConeModel::Circular => assert!((s - full).abs() < 1e-5 * full, "{s}"),
            ConeModel::Polyhedral { sides } => {
                let facet = full * (std::f64::consts::PI / sides as f64).cos();
                assert!(s > facet * (1.0 - 1e-6) && s < full * (1.0 + 1e-6), "{s}");
            }
        }
        assert!(x.resists_weight());
    }
    assert_eq!(epsilon_l1(&g, 8).unwrap(), 0.0);
    assert_eq!(
        epsilon_linf(&g, &FerrariCannyOptions::default()).unwrap(),
        0.0
    );
    // The ellipsoid's flat wrench set still contains the (torque-free) weight.
    assert!(e.resists(0.0));
}

#[test]
fn three_fingers_at_120_degrees_are_force_closure() {
    let g = common::equator_grasp(3, 0.03, 0.5);
    let w = down(&g, 0.1);
    let e = ellipsoid_test(&g, &EllipsoidModel::default(), &w);
    assert!(!e.degenerate);
    // Symmetric: w0 = 0, so f(0) = 0 and the margin is n.
    assert!((e.closure_margin() - 3.0).abs() < 1e-9);
    assert!(e.force_closure(0.0) && e.resists(0.0));
    let multi = multi_ellipsoid_test(
        &g,
        &[
            EllipsoidModel::default(),
            EllipsoidModel::default().scaled(0.5),
        ],
        &w,
        100,
    )
    .unwrap();
    assert_eq!(multi.combinations, 8);
    assert!(multi.worst.force_closure(0.0));
    for cone in CONES {
        let x = exact_test(&g, cone, &w).unwrap();
        assert!(x.closure.force_closure, "{cone:?}");
        assert_eq!(x.closure.grasp_rank, 6);
        // Vertical friction capacity is at most 3 μ f_max.
        let s = x.weight.weight_scale;
        assert!(
            s > 1.0 && s <= 3.0 * 0.5 * 10.0 / (0.1 * 9.81) * (1.0 + 1e-6),
            "{cone:?}: {s}"
        );
        // The returned forces balance s × the weight and respect the cones.
        let mut total = Wrench::zeros();
        for ((c, f), &f_max) in g
            .contacts()
            .iter()
            .zip(&x.weight.forces)
            .zip(g.force_limits())
        {
            total += contact_block(c, g.reference(), g.torque_scale()) * f;
            let fn_ = f.dot(c.normal());
            assert!(fn_ <= f_max * (1.0 + 1e-6));
            assert!((f - c.normal() * fn_).norm() <= 0.5 * fn_ * (1.0 + 1e-5) + 1e-6);
        }
        assert!((total + w * s).norm() < 1e-5, "{}", (total + w * s).norm());
    }
    let l1 = epsilon_l1(&g, 8).unwrap();
    let linf = epsilon_linf(&g, &FerrariCannyOptions::default()).unwrap();
    assert!(l1 > 0.0);
    assert!(linf >= l1 * (1.0 - 1e-9), "W_L1 ⊆ W_L∞: {l1} vs {linf}");
}

#[test]
fn circular_exact_weight_scale_is_three_mu_f_max() {
    let g = common::equator_grasp(3, 0.03, 0.5);
    let w = down(&g, 0.1);
    let x = exact_weight_scale(&g, ConeModel::Circular, &w).unwrap();
    let expected = 3.0 * 0.5 * 10.0 / 0.981;
    assert!(
        (x.weight_scale - expected).abs() < 1e-5 * expected,
        "{}",
        x.weight_scale
    );
}

#[test]
fn parallel_normals_are_not_force_closure() {
    // Three fingers under a box's bottom face, all pushing up.
    let contacts = [[0.02, 0.01], [-0.02, 0.01], [0.0, -0.015]]
        .iter()
        .map(|[x, y]| Contact::new(Point3::new(*x, *y, -0.05), Vector3::z()).unwrap())
        .collect();
    let g = Grasp::new(contacts, 0.8, 10.0, 0.04, Point3::origin()).unwrap();
    let w = down(&g, 0.2);
    let e = ellipsoid_test(&g, &EllipsoidModel::default(), &w);
    assert!(
        !e.force_closure(0.0),
        "closure margin {}",
        e.closure_margin()
    );
    for cone in CONES {
        let c = exact_force_closure(&g, cone).unwrap();
        assert!(!c.force_closure);
        assert_eq!(
            c.grasp_rank, 6,
            "rank is fine, the cones are all on one side"
        );
        assert!(c.squeeze_margin <= 1e-6);
    }
    assert_eq!(epsilon_l1(&g, 8).unwrap(), 0.0);
    assert_eq!(
        epsilon_linf(&g, &FerrariCannyOptions::default()).unwrap(),
        0.0
    );
    // Resting on three supports, it does hold its weight.
    assert!(
        exact_weight_scale(&g, ConeModel::Circular, &w)
            .unwrap()
            .weight_scale
            > 1.0
    );
}

#[test]
fn contacts_at_one_point_are_not_force_closure() {
    let p = Point3::new(0.0, 0.0, 0.03);
    let contacts = [
        [0.0, 0.3, -1.0],
        [0.26, -0.15, -1.0],
        [-0.26, -0.15, -1.0],
        [0.0, 0.0, -1.0],
    ]
    .iter()
    .map(|n| Contact::new(p, Vector3::from(*n).normalize()).unwrap())
    .collect();
    let g = Grasp::new(contacts, 1.0, 10.0, 0.03, Point3::origin()).unwrap();
    let w = down(&g, 0.1);
    let e = ellipsoid_test(&g, &EllipsoidModel::default(), &w);
    assert!(e.degenerate && !e.force_closure(0.0));
    for cone in CONES {
        let c = exact_force_closure(&g, cone).unwrap();
        assert!(!c.force_closure);
        assert_eq!(c.grasp_rank, 3);
    }
    assert_eq!(epsilon_l1(&g, 8).unwrap(), 0.0);
    assert_eq!(
        epsilon_linf(&g, &FerrariCannyOptions::default()).unwrap(),
        0.0
    );
}

#[test]
fn four_fingers_on_a_can_hold_its_weight() {
    // Four fingertips around the can's side at mid-height, as in the paper's
    // experiments: closed, and the weight (0.35 kg) is well within reach.
    let g = common::equator_grasp(4, common::CAN_RADIUS, 0.5);
    let w = down(&g, 0.35);
    let e = ellipsoid_test(&g, &EllipsoidModel::default(), &w);
    assert!(e.force_closure(0.0) && e.resists(0.0));
    let x = exact_test(&g, ConeModel::Circular, &w).unwrap();
    assert!(x.closure.force_closure && x.resists_weight());
    // f_max = 1 N cannot hold 3.43 N with μ = 0.5 on four fingers (at most 2 N).
    let weak = Grasp::new(
        g.contacts().to_vec(),
        0.5,
        1.0,
        common::CAN_RADIUS,
        Point3::origin(),
    )
    .unwrap();
    let xw = exact_test(&weak, ConeModel::Circular, &w).unwrap();
    assert!(xw.closure.force_closure && !xw.resists_weight());
    assert!((xw.weight.weight_scale - 2.0 / 3.4335).abs() < 1e-5);
    let ew = ellipsoid_test(&weak, &EllipsoidModel::default(), &w);
    assert!(ew.force_closure(0.0) && !ew.resists(0.0));
}

#[test]
fn linf_epsilon_of_a_box_grasp_is_at_least_l1() {
    // Regression: two contacts on one face and one opposite. The L∞ sum of the
    // first two contacts is flat (5-D); the last hull used to be rebuilt from
    // its own vertices, which Qhull rejected, reporting ε_L∞ = 0.
    let contacts = vec![
        Contact::new(Point3::new(-0.0253, 0.02, 0.0222), -Vector3::y()).unwrap(),
        Contact::new(Point3::new(-0.0033, -0.02, 0.0413), Vector3::y()).unwrap(),
        Contact::new(Point3::new(0.0251, 0.02, 0.0433), -Vector3::y()).unwrap(),
    ];
    let g = Grasp::new(contacts, 0.5, 10.0, 0.04, Point3::origin()).unwrap();
    let l1 = epsilon_l1(&g, 8).unwrap();
    let linf = epsilon_linf(&g, &FerrariCannyOptions::default()).unwrap();
    assert!(l1 > 0.1 && linf >= l1, "{l1} {linf}");
    assert!(
        exact_force_closure(&g, ConeModel::Polyhedral { sides: 8 })
            .unwrap()
            .force_closure
    );
}

#[test]
fn linf_refuses_sums_over_the_point_limit() {
    let g = common::equator_grasp(3, 0.03, 0.5);
    let small = FerrariCannyOptions {
        sides: 8,
        max_points: 100,
    };
    assert!(matches!(
        epsilon_linf(&g, &small),
        Err(
            tsukami_grasp::ferrari_canny::FerrariCannyError::TooManyPoints {
                points: 729,
                limit: 100
            }
        )
    ));
}
