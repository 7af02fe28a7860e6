//! Benchmarks of the body crate's hot paths (targets from issue #3):
//! FK of the whole humanoid (< 5 µs), IK of the 7-DOF arm (p50 < 100 µs,
//! with p99 and success rate printed), and hand-link distance queries
//! against the 350 ml can mesh (< 5 µs) and a 100k-triangle mesh (< 50 µs).
//!
//! `cargo bench -p tsukami-body -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{Isometry3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tsukami_body::collision::{CollisionObject, RobotCollision};
use tsukami_body::ik::{IkOptions, IkSolver, RIGHT_ARM};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::RobotModel;

fn models() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

fn humanoid() -> RobotModel {
    tsukami_body::urdf::load_urdf(&models().join("robots/tsukami_humanoid/tsukami_humanoid.urdf"))
        .unwrap()
}

/// Palm targets from random in-limit arm configurations.
fn arm_targets(m: &RobotModel, n: usize) -> Vec<Isometry3<f64>> {
    let palm = m.link_id("r_palm").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut fk = FkState::new(m);
    (0..n)
        .map(|_| {
            let mut q = m.rest_positions();
            for name in RIGHT_ARM {
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
    let sel = JointSelection::from_names(&m, &RIGHT_ARM).unwrap();
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

fn bench_distance(c: &mut Criterion) {
    let m = humanoid();
    let coll = RobotCollision::new(&m).unwrap();
    let mut fk = FkState::new(&m);
    m.forward_kinematics(&m.rest_positions(), &mut fk);
    let tip = m.link_id("r_index_l4").unwrap();
    let tip_p = fk.pose(tip).translation.vector;
    let can = TriangleMesh::load(
        &models().join("objects/can_350ml/can_350ml.stl"),
        Vector3::repeat(1.0),
    )
    .unwrap();
    // The can 2 cm beside the fingertip.
    let can_obj = CollisionObject::from_mesh(
        "can",
        Isometry3::translation(tip_p.x, tip_p.y + 0.0085 + 0.02 + 0.033, tip_p.z - 0.061),
        &can,
    )
    .unwrap();
    c.bench_function(
        &format!("distance_fingertip_vs_can_{}_tris", can.indices.len()),
        |b| {
            b.iter(|| {
                black_box(
                    coll.link_object_proximity(&fk, tip, &can_obj, 1.0)
                        .map(|p| p.distance),
                )
            })
        },
    );
    let palm = m.link_id("r_palm").unwrap();
    c.bench_function("distance_palm_vs_can", |b| {
        b.iter(|| {
            black_box(
                coll.link_object_proximity(&fk, palm, &can_obj, 1.0)
                    .map(|p| p.distance),
            )
        })
    });
    // A 100k-triangle closed mesh (a finely tessellated 10 cm sphere).
    let big = TriangleMesh::uv_sphere(0.1, 224, 224);
    let big_obj = CollisionObject::from_mesh(
        "sphere100k",
        Isometry3::translation(tip_p.x, tip_p.y + 0.0085 + 0.02 + 0.1, tip_p.z),
        &big,
    )
    .unwrap();
    c.bench_function(
        &format!("distance_fingertip_vs_{}_tris", big.indices.len()),
        |b| {
            b.iter(|| {
                black_box(
                    coll.link_object_proximity(&fk, tip, &big_obj, 1.0)
                        .map(|p| p.distance),
                )
            })
        },
    );
    // The regime of the finger-closing loop: the link 2 mm from the surface.
    let near_can = CollisionObject::from_mesh(
        "can",
        Isometry3::translation(tip_p.x, tip_p.y + 0.0085 + 0.002 + 0.033, tip_p.z - 0.061),
        &can,
    )
    .unwrap();
    c.bench_function("distance_fingertip_vs_can_at_2mm", |b| {
        b.iter(|| {
            black_box(
                coll.link_object_proximity(&fk, tip, &near_can, 1.0)
                    .map(|p| p.distance),
            )
        })
    });
    let near_big = CollisionObject::from_mesh(
        "sphere100k",
        Isometry3::translation(tip_p.x, tip_p.y + 0.0085 + 0.002 + 0.1, tip_p.z),
        &big,
    )
    .unwrap();
    c.bench_function("distance_fingertip_vs_100k_tris_at_2mm", |b| {
        b.iter(|| {
            black_box(
                coll.link_object_proximity(&fk, tip, &near_big, 1.0)
                    .map(|p| p.distance),
            )
        })
    });
    let hand: Vec<usize> = (palm..m.links.len()).collect();
    c.bench_function(
        &format!("collision_hand_{}_links_vs_can", hand.len()),
        |b| b.iter(|| black_box(coll.first_collision(&fk, &hand, &[&can_obj], 0.005))),
    );
    c.bench_function("self_collision_humanoid", |b| {
        b.iter(|| black_box(coll.first_self_collision(&fk, 0.0)))
    });
}

criterion_group!(benches, bench_fk, bench_ik, bench_distance);
criterion_main!(benches);
