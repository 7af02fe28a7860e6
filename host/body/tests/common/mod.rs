//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

use nalgebra::Vector3;

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

/// Closest point of triangle `abc` to `p` (Ericson §5.1.5), written here
/// independently of `tsukami_body::capsule_mesh`, as the brute-force reference.
pub fn closest_on_triangle(p: Vector3<f64>, t: &[Vector3<f64>; 3]) -> Vector3<f64> {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// The humanoid's joint groups, read from its robot description (the names
/// are data in `description.toml`, not constants in the body crate).
pub struct Groups {
    /// The right arm, shoulder to wrist.
    pub arm: Vec<&'static str>,
    /// The waist joints the whole-body fallback adds first.
    pub waist: Vec<&'static str>,
    /// The virtual squat joint (the description's `whole_body` group).
    pub squat: &'static str,
}

/// Reads the humanoid's joint groups from its `description.toml`.
pub fn humanoid_groups() -> Groups {
    let path = models_dir().join("robots/tsukami_humanoid/description.toml");
    let text = std::fs::read_to_string(&path).expect("description reads");
    let doc: toml::Table = text.parse().expect("description parses");
    let names = |v: &toml::Value| -> Vec<&'static str> {
        v.as_array()
            .expect("a list of joint names")
            .iter()
            .map(|n| &*String::from(n.as_str().expect("a joint name")).leak())
            .collect()
    };
    let hand = &doc["hand"].as_array().expect("[[hand]]")[0];
    let whole_body = names(&doc["whole_body"]);
    Groups {
        arm: names(&hand["arm"]),
        waist: names(&doc["waist"]),
        squat: whole_body[0],
    }
}
