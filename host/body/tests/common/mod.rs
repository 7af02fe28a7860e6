//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tsukami_body::RobotModel;

/// The repository's `models/` folder.
pub fn models_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

/// The humanoid's URDF.
pub fn humanoid_path() -> PathBuf {
    models_dir().join("robots/tsukami_humanoid/tsukami_humanoid.urdf")
}

/// Loads the humanoid.
pub fn humanoid() -> RobotModel {
    tsukami_body::urdf::load_urdf(&humanoid_path()).expect("humanoid loads")
}

/// A random in-limit configuration of every independent joint.
pub fn random_q(model: &RobotModel, rng: &mut ChaCha8Rng) -> Vec<f64> {
    let mut q = vec![0.0; model.joints.len()];
    for (j, joint) in model.joints.iter().enumerate() {
        if joint.is_independent() {
            let (lo, hi) = (
                joint.limits.lower.max(-std::f64::consts::PI),
                joint.limits.upper.min(std::f64::consts::PI),
            );
            q[j] = rng.random_range(lo..=hi);
        }
    }
    model.apply_mimics(&mut q);
    q
}

/// A seeded generator.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}
