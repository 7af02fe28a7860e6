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
    for (s, shape) in [common::Shape::Can, common::Shape::Box].into_iter().enumerate() {
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

/// Writes the reference file (run once with the old implementation).
#[test]
#[ignore = "records the reference file"]
fn record_reference() {
    use std::fmt::Write;
    let mut out = String::from(
        "# Ferrari-Canny reference: qhull crate 0.4.1 (Qhull 2020.2 via bindgen), 8-sided pyramids\n\
         # shape(0 can, 1 box)\tgrasp\tcontacts\teps_l1\teps_linf\n",
    );
    for (s, i, n, l1, linf) in compute() {
        let linf = linf.map_or("-".to_string(), |e| format!("{e:.16e}"));
        writeln!(out, "{s}\t{i}\t{n}\t{l1:.16e}\t{linf}").unwrap();
    }
    std::fs::write(reference_path(), out).unwrap();
}
