//! The depth noise model of the simulated camera.
//!
//! What: [`NoiseModel`] turns a true depth into a measured one, or into "no
//! measurement".
//!
//! Why: the pipeline must be tested on data as imperfect as a real depth
//! camera's, and the imperfections must be stated so a figure measured on
//! simulated images says what it was measured on.
//!
//! How — for a pixel whose ray hits a surface at depth `z` (optical z, m) with
//! angle `θ` between the ray and the surface normal:
//! 1. *Range*: outside `[min_range, max_range]` → no measurement.
//! 2. *Grazing*: `θ > max_incidence` → no measurement (structured-light and
//!    time-of-flight cameras lose returns on surfaces seen edge-on).
//! 3. *Dropout*: with probability `dropout`, independently per pixel → no
//!    measurement.
//! 4. *Gaussian depth noise*: `z + N(0, σ(z)²)` with
//!    `σ(z) = sigma + sigma_quadratic · z²` (Kinect-style axial noise grows with
//!    the square of the distance; the benchmark uses a constant 1 mm).
//! 5. *Quantisation*: rounded to `quantum` (1 mm, the unit of a 16-bit PNG),
//!    when `quantum > 0`.
//!
//! Every draw comes from one ChaCha8 stream seeded by the caller and consumed
//! in pixel order, so an image is a function of the scene and the seed.
//!
//! ```
//! use rand::SeedableRng;
//! use tsukami_vision::sim::noise::NoiseModel;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
//! let none = NoiseModel::none();
//! assert_eq!(none.apply(0.8, 1.0, &mut rng), Some(0.8));
//! assert_eq!(NoiseModel::default().apply(0.8, 0.05, &mut rng), None); // 87° incidence
//! ```

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// The simulated camera's imperfections.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseModel {
    /// Constant part of the depth noise's standard deviation (m).
    pub sigma: f64,
    /// Quadratic part: `σ(z) = sigma + sigma_quadratic · z²` (1/m).
    pub sigma_quadratic: f64,
    /// Largest angle between ray and surface normal that still returns (rad).
    pub max_incidence: f64,
    /// Probability that a pixel returns nothing.
    pub dropout: f64,
    /// Nearest measurable depth (m).
    pub min_range: f64,
    /// Farthest measurable depth (m).
    pub max_range: f64,
    /// Depth quantum (m); 0 for none.
    pub quantum: f64,
}

impl Default for NoiseModel {
    /// 1 mm Gaussian noise, returns up to 80° incidence, 0.5 % dropout,
    /// 0.3–4 m range, 1 mm quantisation.
    fn default() -> Self {
        NoiseModel {
            sigma: 0.001,
            sigma_quadratic: 0.0,
            max_incidence: 80f64.to_radians(),
            dropout: 0.005,
            min_range: 0.3,
            max_range: 4.0,
            quantum: 0.001,
        }
    }
}

impl NoiseModel {
    /// A perfect camera (no noise, no dropout, no quantisation, any range).
    pub fn none() -> Self {
        NoiseModel {
            sigma: 0.0,
            sigma_quadratic: 0.0,
            max_incidence: std::f64::consts::FRAC_PI_2,
            dropout: 0.0,
            min_range: 0.0,
            max_range: f64::INFINITY,
            quantum: 0.0,
        }
    }

    /// The measured depth of a surface at depth `z` whose normal makes
    /// `cos_incidence` with the ray, or `None`.
    pub fn apply(&self, z: f64, cos_incidence: f64, rng: &mut ChaCha8Rng) -> Option<f64> {
        // Draw both numbers always, so one pixel's outcome never shifts the
        // stream of the next.
        let u: f64 = rng.random();
        let g: f64 = StandardNormal.sample(rng);
        if !(self.min_range..=self.max_range).contains(&z) {
            return None;
        }
        if cos_incidence < self.max_incidence.cos() || u < self.dropout {
            return None;
        }
        let sigma = self.sigma + self.sigma_quadratic * z * z;
        let mut d = z + sigma * g;
        if self.quantum > 0.0 {
            d = (d / self.quantum).round() * self.quantum;
        }
        (d > 0.0).then_some(d)
    }
}
