//! Ferrari–Canny ε against reference values recorded with the previous
//! implementation (the `qhull` crate, bindgen bindings), on 1,000 seeded random
//! grasps: the build without libclang must give the same ε.
//!
//! The reference file `tests/data/hull_reference.tsv` holds, per grasp, the
//! contact count, ε_L1 and (for 20 three-contact grasps) ε_L∞, written with 17
//! significant digits. The grasps are regenerated from the seed here.

mod common;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tsukami_grasp::ferrari_canny::{epsilon_l1, epsilon_linf, FerrariCannyOptions};

/// Seed, grasps per shape and contact counts of the reference set.
const SEED: u64 = 0x4846_435f_6875_6c6c;
const PER_SHAPE: usize = 500;
const CONTACTS: [usize; 4] = [3, 4, 5, 6];
/// ε_L∞ for the first this many three-contact grasps of each shape.
const LINF_PER_SHAPE: usize = 10;
const SIDES: usize = 8;

/// One row: shape index, grasp index, contacts, ε_L1, ε_L∞ (if computed).
type Row = (usize, usize, usize, f64, Option<f64>);

fn compute() -> Vec<Row> {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let options = FerrariCannyOptions {
        sides: SIDES,
        ..FerrariCannyOptions::default()
    };
    let mut rows = Vec::new();
    for (s, shape) in [common::Shape::Can, common::Shape::Box]
        .into_iter()
        .enumerate()
    {
        let mut linf_done = 0;
        for i in 0..PER_SHAPE {
            let n = CONTACTS[i % CONTACTS.len()];
            let g = common::random_grasp(shape, n, &mut rng);
            let l1 = epsilon_l1(&g, SIDES).expect("hull");
            let linf = (n == 3 && linf_done < LINF_PER_SHAPE).then(|| {
                linf_done += 1;
                epsilon_linf(&g, &options).expect("hull")
            });
            rows.push((s, i, n, l1, linf));
        }
    }
    rows
}

fn reference_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/hull_reference.tsv")
}

/// Parses the reference file into rows.
fn reference() -> Vec<Row> {
    let text = std::fs::read_to_string(reference_path()).expect("reference file");
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let f: Vec<&str> = l.split('\t').collect();
            let linf = (f[4] != "-").then(|| f[4].parse().expect("eps_linf"));
            (
                f[0].parse().expect("shape"),
                f[1].parse().expect("grasp"),
                f[2].parse().expect("contacts"),
                f[3].parse().expect("eps_l1"),
                linf,
            )
        })
        .collect()
}

/// Largest `|a − b| / max(1, |b|)` of the pairs, and the count of pairs on
/// opposite sides of zero.
fn compare(pairs: &[(f64, f64)]) -> (f64, usize) {
    let worst = pairs
        .iter()
        .map(|(a, b)| (a - b).abs() / b.abs().max(1.0))
        .fold(0.0, f64::max);
    let flipped = pairs
        .iter()
        .filter(|(a, b)| (*a > 0.0) != (*b > 0.0))
        .count();
    (worst, flipped)
}

/// Tolerance on ε (N, relative above 1 N): ε values are 0.1–10 N here.
const TOLERANCE: f64 = 1e-9;

#[test]
fn epsilon_matches_the_recorded_qhull_crate_values() {
    let expected = reference();
    let got = compute();
    assert_eq!(got.len(), expected.len());
    let mut l1 = Vec::new();
    let mut linf = Vec::new();
    for (g, e) in got.iter().zip(&expected) {
        assert_eq!((g.0, g.1, g.2), (e.0, e.1, e.2), "same grasp sequence");
        l1.push((g.3, e.3));
        if let (Some(a), Some(b)) = (g.4, e.4) {
            linf.push((a, b));
        }
    }
    assert_eq!(linf.len(), 2 * LINF_PER_SHAPE);
    let (l1_worst, l1_flipped) = compare(&l1);
    let (linf_worst, linf_flipped) = compare(&linf);
    let positive = l1.iter().filter(|(_, b)| *b > 0.0).count();
    println!(
        "eps_L1: {} grasps ({positive} with eps > 0), largest difference {l1_worst:.3e}, {l1_flipped} closure verdicts differ",
        l1.len()
    );
    println!(
        "eps_Linf: {} grasps, largest difference {linf_worst:.3e}, {linf_flipped} closure verdicts differ",
        linf.len()
    );
    // The set exercises both verdicts.
    assert!(positive > 300 && positive < 700, "{positive}");
    assert_eq!((l1_flipped, linf_flipped), (0, 0));
    assert!(l1_worst <= TOLERANCE, "{l1_worst}");
    assert!(linf_worst <= TOLERANCE, "{linf_worst}");
}
