//! Per-test time of every force-closure method for 3, 4, 5 and 10 contacts,
//! and the ratios exact / ellipsoid and Ferrari–Canny / ellipsoid.
//!
//! `cargo bench -p tsukami-grasp --bench force_closure -- --warm-up-time 1 --measurement-time 3`
//! Target: the ellipsoid test under 1 µs for 4 contacts (the paper: < 1 ms).

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tsukami_grasp::ellipsoid::{ellipsoid_test, multi_ellipsoid_test, EllipsoidModel};
use tsukami_grasp::exact::{exact_force_closure, exact_test, ConeModel};
use tsukami_grasp::ferrari_canny::{epsilon_l1, epsilon_linf, FerrariCannyOptions};
use tsukami_grasp::grasp::Grasp;
use tsukami_grasp::grasp_matrix::Wrench;

#[path = "../tests/common/mod.rs"]
mod common;

const COUNTS: [usize; 4] = [3, 4, 5, 10];
/// L∞ grows fast with the contacts (≈0.5 s for three): criterion times it
/// for three, the summary table up to four.
const LINF_CRITERION_UP_TO: usize = 3;
const LINF_TABLE_UP_TO: usize = 4;

/// A force-closure grasp of `n` random contacts on the can (fixed seed).
fn closed_grasp(n: usize) -> (Grasp, Wrench) {
    let mut rng = ChaCha8Rng::seed_from_u64(0x6b61_6e00 + n as u64);
    loop {
        let g = common::random_grasp(common::Shape::Can, n, &mut rng);
        if exact_force_closure(&g, ConeModel::Circular).is_ok_and(|c| c.force_closure) {
            let w = common::weight(&g, common::Shape::Can);
            return (g, w);
        }
    }
}

/// Mean time of `f` over about `budget`.
fn mean_time(budget: Duration, mut f: impl FnMut()) -> Duration {
    f();
    let start = Instant::now();
    let mut runs = 0_u32;
    while start.elapsed() < budget || runs < 3 {
        f();
        runs += 1;
    }
    start.elapsed() / runs
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    let model = EllipsoidModel::default();
    let two = [model, model.scaled(0.5)];
    let fc = FerrariCannyOptions::default();
    let grasps: Vec<(usize, Grasp, Wrench)> = COUNTS
        .iter()
        .map(|&n| {
            let (g, w) = closed_grasp(n);
            (n, g, w)
        })
        .collect();

    let mut group = c.benchmark_group("force_closure");
    for (n, g, w) in &grasps {
        group.bench_with_input(BenchmarkId::new("ellipsoid", n), n, |b, _| {
            b.iter(|| ellipsoid_test(black_box(g), black_box(&model), black_box(w)))
        });
        group.bench_with_input(BenchmarkId::new("ellipsoid_x2", n), n, |b, _| {
            b.iter(|| multi_ellipsoid_test(black_box(g), &two, black_box(w), 1 << 20))
        });
        group.bench_with_input(BenchmarkId::new("exact", n), n, |b, _| {
            b.iter(|| exact_test(black_box(g), ConeModel::Circular, black_box(w)))
        });
        group.bench_with_input(BenchmarkId::new("exact_closure_only", n), n, |b, _| {
            b.iter(|| exact_force_closure(black_box(g), ConeModel::Circular))
        });
        group.bench_with_input(BenchmarkId::new("ferrari_canny_l1", n), n, |b, _| {
            b.iter(|| epsilon_l1(black_box(g), fc.sides))
        });
    }
    group.finish();
    let mut slow = c.benchmark_group("force_closure_linf");
    slow.sample_size(10);
    for (n, g, _) in grasps.iter().filter(|(n, _, _)| *n <= LINF_CRITERION_UP_TO) {
        slow.bench_with_input(BenchmarkId::new("ferrari_canny_linf", n), n, |b, _| {
            b.iter(|| epsilon_linf(black_box(g), &fc))
        });
    }
    slow.finish();
    c.final_summary();

    // One table with the ratios, from a plain timing loop on the same grasps.
    let budget = Duration::from_millis(300);
    println!();
    println!("contacts | ellipsoid | ellipsoid x2 | exact (closure + weight) | F-C L1 | F-C Linf | exact/ellipsoid | F-C L1/ellipsoid | F-C Linf/ellipsoid");
    for (n, g, w) in &grasps {
        let te = mean_time(budget, || {
            black_box(ellipsoid_test(black_box(g), &model, black_box(w)));
        });
        let te2 = mean_time(budget, || {
            black_box(multi_ellipsoid_test(black_box(g), &two, black_box(w), 1 << 20).ok());
        });
        let tx = mean_time(budget, || {
            black_box(exact_test(black_box(g), ConeModel::Circular, black_box(w)).ok());
        });
        let tl1 = mean_time(budget, || {
            black_box(epsilon_l1(black_box(g), fc.sides).ok());
        });
        let tli = (*n <= LINF_TABLE_UP_TO).then(|| {
            mean_time(budget, || {
                black_box(epsilon_linf(black_box(g), &fc).ok());
            })
        });
        let r = |t: Duration| t.as_secs_f64() / te.as_secs_f64();
        println!(
            "{n:>8} | {te:>9.2?} | {te2:>12.2?} | {tx:>24.2?} | {tl1:>6.2?} | {:>8} | {:>15.0} | {:>16.0} | {:>18}",
            tli.map_or("-".to_string(), |t| format!("{t:.2?}")),
            r(tx),
            r(tl1),
            tli.map_or("-".to_string(), |t| format!("{:.0}", r(t))),
        );
    }
}
