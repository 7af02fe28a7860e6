//! Benchmarks of the body crate's hot paths (targets from issue #3):
//! FK of the whole humanoid (< 5 µs), IK of the 7-DOF arm (p50 < 100 µs,
//! with p99 and success rate printed), and hand-link distance queries
//! against the 350 ml can mesh (< 5 µs) and a 100k-triangle mesh (< 50 µs).
//!
//! The distance benchmarks run twice, with the closed-form capsule-vs-mesh
//! path (`DistanceMethod::Fast`, the default, plain names) and with parry's
//! general path (`parry/…`), and print the ratio measured in the same run.
//!
//! `cargo bench -p tsukami-body -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{Isometry3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tsukami_body::collision::{CollisionObject, DistanceMethod, RobotCollision};
use tsukami_body::ik::{IkOptions, IkSolver};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::RobotModel;

#[path = "../tests/common/mod.rs"]
mod common;
use common::{humanoid, models_dir as models};

/// Palm targets from random in-limit arm configurations.
fn arm_targets(m: &RobotModel, n: usize) -> Vec<Isometry3<f64>> {
    let palm = m.link_id("r_palm").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut fk = FkState::new(m);
    let arm = common::humanoid_groups().arm;
    (0..n)
        .map(|_| {
            let mut q = m.rest_positions();
            for name in &arm {
                let j = m.joint_id(name).unwrap();
                let l = m.joints[j].limits;
                q[j] = rng.random_range(l.lower..=l.upper);
            }
            m.forward_kinematics(&q, &mut fk);
            *fk.pose(palm)
        })
        .collect()
}

fn bench_fk(c: &mut Criterion) {
    let m = humanoid();
    let mut fk = FkState::new(&m);
    let mut q = m.rest_positions();
    q[m.joint_id("r_elbow").unwrap()] = -1.0;
    c.bench_function(&format!("fk_humanoid_{}_links", m.links.len()), |b| {
        b.iter(|| {
            m.forward_kinematics(black_box(&q), &mut fk);
            black_box(fk.poses[5].translation.vector.x)
        })
    });
}

fn bench_ik(c: &mut Criterion) {
    let m = humanoid();
    let sel = JointSelection::from_names(&m, &common::humanoid_groups().arm).unwrap();
    let mut solver =
        IkSolver::new(&m, m.link_id("r_palm").unwrap(), sel, IkOptions::default()).unwrap();
    let rest = m.rest_positions();
    let targets = arm_targets(&m, 1000);
    // Distribution over 1,000 reachable targets (one timed solve each).
    let mut times = Vec::with_capacity(targets.len());
    let mut ok = 0;
    for t in &targets {
        let start = Instant::now();
        let sol = solver.solve(t, true, &rest, None);
        times.push(start.elapsed().as_secs_f64() * 1e6);
        ok += sol.ok as usize;
    }
    times.sort_by(f64::total_cmp);
    println!(
        "ik_arm_7dof over {} targets: success {:.1}%, p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs (target p50 < 100 µs)",
        targets.len(),
        100.0 * ok as f64 / targets.len() as f64,
        times[times.len() / 2],
        times[times.len() * 99 / 100],
        times[times.len() - 1]
    );
    let mut k = 0;
    c.bench_function("ik_arm_7dof_mean", |b| {
        b.iter(|| {
            k = (k + 1) % targets.len();
            black_box(solver.solve(&targets[k], true, &rest, None).ok)
        })
    });
}

/// Mean time of one call (µs) over interleaved batches, the best of 7.
fn mean_us(mut f: impl FnMut()) -> f64 {
    let batch = 2000;
    let mut best = f64::INFINITY;
    for _ in 0..7 {
        let start = Instant::now();
        for _ in 0..batch {
            f();
        }
        best = best.min(start.elapsed().as_secs_f64() * 1e6 / batch as f64);
    }
    best
}

/// Benchmarks `query` with the fast path (`name`) and parry's (`parry/name`)
/// and prints their ratio.
fn both_paths<T>(
    c: &mut Criterion,
    name: &str,
    fast: &RobotCollision,
    parry: &RobotCollision,
    query: impl Fn(&RobotCollision) -> T,
) {
    let t_parry = mean_us(|| {
        black_box(query(black_box(parry)));
    });
    let t_fast = mean_us(|| {
        black_box(query(black_box(fast)));
    });
    println!(
        "{name}: parry {t_parry:.2} µs, fast {t_fast:.2} µs, ratio {:.1}x",
        t_parry / t_fast
    );
    c.bench_function(name, |b| b.iter(|| black_box(query(fast))));
    c.bench_function(&format!("parry/{name}"), |b| {
        b.iter(|| black_box(query(parry)))
    });
}

fn bench_distance(c: &mut Criterion) {
    let m = humanoid();
    let coll = RobotCollision::new(&m).unwrap();
    let mut parry = coll.clone();
    parry.set_distance_method(DistanceMethod::Parry);
    let mut fk = FkState::new(&m);
    m.forward_kinematics(&m.rest_positions(), &mut fk);
    let tip = m.link_id("r_index_l4").unwrap();
    let tip_p = fk.pose(tip).translation.vector;
    let can = TriangleMesh::load(
        &models().join("objects/can_350ml/can_350ml.stl"),
        Vector3::repeat(1.0),
    )
    .unwrap();
    let at = |gap: f64, radius: f64, dz: f64| {
        Isometry3::translation(tip_p.x, tip_p.y + 0.0085 + gap + radius, tip_p.z + dz)
    };
    // The can 2 cm beside the fingertip, and 2 mm (the finger-closing loop).
    let can_obj = CollisionObject::from_mesh("can", at(0.02, 0.033, -0.061), &can).unwrap();
    let near_can = CollisionObject::from_mesh("can", at(0.002, 0.033, -0.061), &can).unwrap();
    // A 100k-triangle closed mesh (a finely tessellated 10 cm sphere).
    let big = TriangleMesh::uv_sphere(0.1, 224, 224);
    let big_obj = CollisionObject::from_mesh("sphere100k", at(0.02, 0.1, 0.0), &big).unwrap();
    let near_big = CollisionObject::from_mesh("sphere100k", at(0.002, 0.1, 0.0), &big).unwrap();
    let palm = m.link_id("r_palm").unwrap();
    let distance = |link: usize, object: &CollisionObject| {
        let fk = &fk;
        let object = object.clone();
        move |c: &RobotCollision| {
            c.link_object_proximity(fk, link, &object, 1.0)
                .map(|p| p.distance)
        }
    };
    let cases: Vec<(String, usize, &CollisionObject)> = vec![
        (
            format!("distance_fingertip_vs_can_{}_tris", can.indices.len()),
            tip,
            &can_obj,
        ),
        ("distance_palm_vs_can".into(), palm, &can_obj),
        (
            format!("distance_fingertip_vs_{}_tris", big.indices.len()),
            tip,
            &big_obj,
        ),
        ("distance_fingertip_vs_can_at_2mm".into(), tip, &near_can),
        (
            "distance_fingertip_vs_100k_tris_at_2mm".into(),
            tip,
            &near_big,
        ),
    ];
    for (name, link, object) in cases {
        both_paths(c, &name, &coll, &parry, distance(link, object));
    }
    let hand: Vec<usize> = (palm..m.links.len()).collect();
    both_paths(
        c,
        &format!("collision_hand_{}_links_vs_can", hand.len()),
        &coll,
        &parry,
        |c| c.first_collision(&fk, &hand, &[&can_obj], 0.005),
    );
    c.bench_function("self_collision_humanoid", |b| {
        b.iter(|| black_box(coll.first_self_collision(&fk, 0.0)))
    });
}

criterion_group!(benches, bench_fk, bench_ik, bench_distance);
criterion_main!(benches);
