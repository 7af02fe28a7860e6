//! Time scaling of a piecewise-linear joint path within velocity and acceleration
//! limits.
//!
//! What: [`time_path`] gives every segment of a joint-space polyline a trapezoidal
//! (or triangular) velocity profile that starts and ends at rest, the fastest one
//! that keeps every joint within its velocity limit and an acceleration limit, and
//! samples it into timed points with positions and velocities.
//!
//! Why: the controller plays a trajectory back by interpolating between points;
//! points sampled from a profile that respects the limits give a playback that
//! respects them too (between two samples a joint moves at the mean of its
//! profile's velocity, which is within the limit).
//!
//! How: along a segment `q(s) = a + s (b − a)`, `s ∈ [0, 1]`; joint `j` moves at
//! `|Δ_j| ṡ` and accelerates at `|Δ_j| s̈`, so the fastest admissible profile has
//! `ṡ ≤ p = min_j v_j / |Δ_j|` and `|s̈| ≤ α = min_j a_j / |Δ_j|`: a trapezoid of
//! duration `1/p + p/α` when `p²/α ≤ 1`, otherwise a triangle of duration `2/√α`.
//! Stopping at every waypoint is slower than blending, but exact and simple;
//! shortcutting leaves few waypoints.
//!
//! ```
//! use tsukami_trajectory_planner::timing::{time_path, Limits};
//! let limits = Limits { velocity: vec![1.0], acceleration: vec![2.0], sample_dt: 0.05 };
//! let points = time_path(&[vec![0.0], vec![1.0]], &limits);
//! let end = points.last().unwrap();
//! assert!((end.time - 1.5).abs() < 1e-12); // 1/p + p/α = 1 + 0.5
//! assert_eq!(end.positions, vec![1.0]);
//! ```

/// Per-joint limits of a path's joints, and the sampling interval.
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// Velocity limit per joint (rad/s or m/s), > 0.
    pub velocity: Vec<f64>,
    /// Acceleration limit per joint (rad/s² or m/s²), > 0.
    pub acceleration: Vec<f64>,
    /// Longest interval between two samples (s).
    pub sample_dt: f64,
}

/// A sampled point of a timed path.
#[derive(Debug, Clone, PartialEq)]
pub struct TimedPoint {
    /// Time from the start (s).
    pub time: f64,
    /// Joint positions.
    pub positions: Vec<f64>,
    /// Joint velocities.
    pub velocities: Vec<f64>,
}

/// The fastest rest-to-rest profile of one segment: peak rate `p`, acceleration
/// `alpha` of the path parameter, and its duration.
#[derive(Debug, Clone, Copy)]
struct Profile {
    p: f64,
    alpha: f64,
    t_acc: f64,
    duration: f64,
}

impl Profile {
    fn new(a: &[f64], b: &[f64], limits: &Limits) -> Option<Profile> {
        let mut p = f64::INFINITY;
        let mut alpha = f64::INFINITY;
        for j in 0..a.len() {
            let d = (b[j] - a[j]).abs();
            if d > 0.0 {
                p = p.min(limits.velocity[j] / d);
                alpha = alpha.min(limits.acceleration[j] / d);
            }
        }
        if !p.is_finite() {
            return None; // no motion
        }
        if p * p / alpha <= 1.0 {
            let t_acc = p / alpha;
            Some(Profile {
                p,
                alpha,
                t_acc,
                duration: 1.0 / p + t_acc,
            })
        } else {
            let t_acc = (1.0 / alpha).sqrt();
            Some(Profile {
                p: alpha * t_acc,
                alpha,
                t_acc,
                duration: 2.0 * t_acc,
            })
        }
    }

    /// Path parameter and its rate at time `t` into the segment.
    fn at(&self, t: f64) -> (f64, f64) {
        let t = t.clamp(0.0, self.duration);
        let cruise_end = self.duration - self.t_acc;
        if t < self.t_acc {
            (0.5 * self.alpha * t * t, self.alpha * t)
        } else if t <= cruise_end {
            (
                0.5 * self.alpha * self.t_acc * self.t_acc + self.p * (t - self.t_acc),
                self.p,
            )
        } else {
            let r = self.duration - t;
            (1.0 - 0.5 * self.alpha * r * r, self.alpha * r)
        }
    }
}

/// Samples the timed path: the first point at time 0, then for each segment its
/// profile's knots and samples at most `sample_dt` apart, ending at rest at the
/// last waypoint. Segments without motion are skipped.
pub fn time_path(path: &[Vec<f64>], limits: &Limits) -> Vec<TimedPoint> {
    let Some(first) = path.first() else {
        return vec![];
    };
    let zero = vec![0.0; first.len()];
    let mut out = vec![TimedPoint {
        time: 0.0,
        positions: first.clone(),
        velocities: zero.clone(),
    }];
    let mut t0 = 0.0;
    for w in path.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let Some(profile) = Profile::new(a, b, limits) else {
            continue;
        };
        let mut times = sample_times(&profile, limits.sample_dt);
        times.remove(0);
        for t in times {
            let (s, rate) = profile.at(t);
            let positions = a.iter().zip(b).map(|(x, y)| x + s * (y - x)).collect();
            let velocities = a.iter().zip(b).map(|(x, y)| rate * (y - x)).collect();
            out.push(TimedPoint {
                time: t0 + t,
                positions,
                velocities,
            });
        }
        let last = out.last_mut().expect("a segment adds points");
        last.positions = b.clone();
        last.velocities = zero.clone();
        t0 += profile.duration;
    }
    out
}

/// Knots of the profile and uniform samples between them, at most `dt` apart.
fn sample_times(profile: &Profile, dt: f64) -> Vec<f64> {
    let knots = [
        0.0,
        profile.t_acc,
        profile.duration - profile.t_acc,
        profile.duration,
    ];
    let mut times = vec![0.0];
    for w in knots.windows(2) {
        let span = w[1] - w[0];
        if span <= 1e-12 {
            continue;
        }
        let n = (span / dt.max(1e-4)).ceil().max(1.0) as usize;
        times.extend((1..=n).map(|i| w[0] + span * i as f64 / n as f64));
    }
    times
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> Limits {
        Limits {
            velocity: vec![1.0, 0.5],
            acceleration: vec![2.0, 2.0],
            sample_dt: 0.02,
        }
    }

    #[test]
    fn every_joint_stays_within_its_limits_between_samples() {
        let path = vec![
            vec![0.0, 0.0],
            vec![1.2, -0.3],
            vec![1.25, 0.9],
            vec![-0.4, 0.9],
        ];
        let lim = limits();
        let pts = time_path(&path, &lim);
        for w in pts.windows(2) {
            let dt = w[1].time - w[0].time;
            assert!(dt > 0.0 && dt <= lim.sample_dt + 1e-12);
            for j in 0..2 {
                let v = (w[1].positions[j] - w[0].positions[j]).abs() / dt;
                assert!(v <= lim.velocity[j] + 1e-9, "joint {j}: {v}");
                assert!(w[1].velocities[j].abs() <= lim.velocity[j] + 1e-9);
                let a = (w[1].velocities[j] - w[0].velocities[j]).abs() / dt;
                assert!(a <= lim.acceleration[j] + 1e-6, "joint {j}: accel {a}");
            }
        }
        // Every waypoint is reached at rest.
        for q in &path {
            assert!(pts
                .iter()
                .any(|p| &p.positions == q && p.velocities == vec![0.0, 0.0]));
        }
    }

    #[test]
    fn short_moves_are_triangles_and_no_motion_adds_nothing() {
        let lim = limits();
        let pts = time_path(&[vec![0.0, 0.0], vec![0.1, 0.0]], &lim);
        // Triangle: 2·sqrt(Δ/a) = 2·sqrt(0.05).
        assert!((pts.last().unwrap().time - 2.0 * 0.05f64.sqrt()).abs() < 1e-12);
        let still = time_path(&[vec![0.3, 0.3], vec![0.3, 0.3]], &lim);
        assert_eq!(still.len(), 1);
    }
}
