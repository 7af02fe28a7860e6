#[path = "../tests/common/mod.rs"]
mod common;
use rand::SeedableRng;
use tsukami_grasp::exact::*;
use tsukami_grasp::ferrari_canny::*;
use tsukami_grasp::ellipsoid::*;
use std::time::Instant;
fn main() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x75_6b_61_6d_69);
    let mut t_li = [0.0f64; 7];
    let (mut t_poly, mut t_circ, mut t_l1, mut t_w, mut t_e) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for shape in [common::Shape::Can, common::Shape::Box] {
        for i in 0..300 {
            let n = [3, 4, 5, 6][i % 4];
            let g = common::random_grasp(shape, n, &mut rng);
            let w = common::weight(&g, shape);
            let t = Instant::now();
            let poly = exact_force_closure(&g, ConeModel::Polyhedral { sides: 8 }).unwrap();
            t_poly += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let circ = exact_force_closure(&g, ConeModel::Circular).unwrap();
            t_circ += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let l1 = epsilon_l1(&g, 8).unwrap();
            t_l1 += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let _ = exact_weight_scale(&g, ConeModel::Circular, &w).unwrap();
            t_w += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let _ = ellipsoid_test(&g, &EllipsoidModel::default(), &w);
            t_e += t.elapsed().as_secs_f64();
            let t = Instant::now();
            if n <= 4 { let li = epsilon_linf(&g, &FerrariCannyOptions::default()).unwrap(); if (li > 0.0) != poly.force_closure { println!("LINF {li:e} {}", poly.squeeze_margin); } }
            t_li[n] += t.elapsed().as_secs_f64();
            if (l1 > 0.0) != poly.force_closure {
                println!("{shape:?} n={n} mu={:.3} l1={l1:e} poly tau={:e} rank={} circ tau={:e}", g.mu(), poly.squeeze_margin, poly.grasp_rank, circ.squeeze_margin);
            }
        }
    }
    println!("poly {t_poly:.3}s circ {t_circ:.3}s l1 {t_l1:.3}s weight {t_w:.3}s ell {t_e:.6}s linf {t_li:?}");
}
