//! Property test: random contact sets on the 350 ml can and a box, every
//! method against the exact reference (seeded, deterministic).
//!
//! The larger sweep whose figures are in `docs/force-closure.md` is the
//! example `cargo run --release --example fc_agreement -p tsukami-grasp`.

mod common;

#[test]
fn exact_agrees_with_ferrari_canny_and_the_inner_ellipsoid_never_lies() {
    // 2 × 400 grasps of 3–6 contacts; ε_L∞ for 2 × 8 grasps of 3 contacts.
    let s = common::sweep(400, 0x75_6b_61_6d_69, &[3, 4, 5, 6], 8, 8);
    println!("exact(8-pyramid) vs eps_L1 > 0: {}", s.exact_vs_l1);
    println!("exact(8-pyramid) vs eps_Linf > 0: {}", s.exact_vs_linf);
    println!("ellipsoid closure, delta_f = 0: {}", s.ellipsoid_closure);
    println!(
        "ellipsoid closure, delta_f = n-1: {}",
        s.ellipsoid_closure_inner
    );
    println!("ellipsoid weight, delta_f = 0: {}", s.ellipsoid_weight);
    println!(
        "ellipsoid weight, delta_f = n-1: {}",
        s.ellipsoid_weight_inner
    );
    println!(
        "zero-FP delta_f (closure): {}",
        common::Sweep::zero_fp_delta(&s.closure_margins, None)
    );
    println!(
        "zero-FP delta_f (weight): {}",
        common::Sweep::zero_fp_delta(&s.weight_margins, None)
    );

    // Same cone model, same answer (up to boundary cases of measure zero).
    assert!(s.exact_vs_l1.agreement() >= 0.999, "{}", s.exact_vs_l1);
    assert_eq!(s.exact_vs_linf.total(), 16);
    assert!(s.exact_vs_linf.agreement() >= 0.999, "{}", s.exact_vs_linf);
    // The set must exercise both answers.
    assert!(
        s.exact_vs_l1.true_pos > 80 && s.exact_vs_l1.true_neg > 80,
        "{}",
        s.exact_vs_l1
    );
    // The inscribed pyramid is inside the cone: it can only lose closure.
    assert_eq!(s.poly_vs_circular.false_pos, 0, "{}", s.poly_vs_circular);
    // With threshold 1 (δf = n − 1) eq. (10) is an inner approximation of the
    // Minkowski sum of ellipsoids that lie inside the bounded cones: a theorem,
    // so not one false positive.
    assert_eq!(
        s.ellipsoid_closure_inner.false_pos, 0,
        "{}",
        s.ellipsoid_closure_inner
    );
    assert_eq!(
        s.ellipsoid_weight_inner.false_pos, 0,
        "{}",
        s.ellipsoid_weight_inner
    );
}

#[test]
fn the_weight_programs_certificate_bounds_every_grasp_and_is_tight_on_its_own() {
    use rand::{Rng, SeedableRng};
    use tsukami_grasp::exact::{exact_weight_scale, weight_scale_bound, ConeModel};
    // Weak duality, checked: the certificate of one grasp's weight program
    // bounds that grasp's scale exactly and every other grasp's from above,
    // as does any direction at all.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x64_75_61_6c);
    let (mut tight, mut pruned, mut others) = (0, 0, 0);
    for shape in [common::Shape::Can, common::Shape::Box] {
        let mut previous: Option<tsukami_grasp::grasp_matrix::Wrench> = None;
        for i in 0..300 {
            let g = common::random_grasp(shape, 3 + i % 4, &mut rng);
            let w = common::weight(&g, shape);
            let x = exact_weight_scale(&g, ConeModel::Circular, &w).expect("solver");
            let own = weight_scale_bound(&g, &w, &x.certificate);
            assert!(
                (own - x.weight_scale).abs() <= 1e-6 * (1.0 + x.weight_scale),
                "own certificate {own} vs s* {}",
                x.weight_scale
            );
            tight += 1;
            let random =
                tsukami_grasp::grasp_matrix::Wrench::from_fn(|_, _| rng.random_range(-1.0..1.0));
            for y in previous.iter().chain([&random]) {
                let b = weight_scale_bound(&g, &w, y);
                assert!(
                    b >= x.weight_scale * (1.0 - 1e-9) - 1e-9,
                    "bound {b} < s* {}",
                    x.weight_scale
                );
                others += 1;
                pruned += usize::from(b < 1.0);
            }
            previous = Some(x.certificate);
        }
    }
    println!("{tight} tight own bounds; {pruned} of {others} other bounds below 1");
    assert!(pruned > 0);
}
