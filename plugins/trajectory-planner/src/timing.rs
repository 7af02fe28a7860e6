//! Time scaling of a joint path within velocity and acceleration limits,
//! without stopping between its ends.
//!
//! What: [`time_path`] rounds the corners of a joint-space polyline within a
//! deviation ([`crate::blend`]), finds the fastest rest-to-rest speed along it
//! that keeps every joint within its velocity limit and an acceleration limit
//! ([`crate::topp`], TOPP-RA), and samples it into timed points with positions
//! and velocities.
//!
//! Why: the controller plays a trajectory back by interpolating between points;
//! points sampled from a profile that respects the limits give a playback that
//! respects them too (between two samples a joint moves at the mean of its
//! profile's velocity, which is within the limit). Rounded corners let the
//! motion flow through the waypoints instead of stopping at each.
//!
//! How: the samples are at most `sample_dt` apart and include every point where
//! one piece of the rounded path meets the next, so the polyline the
//! controller follows is the rounded path's inscribed one; a caller that
//! checks collisions checks that polyline ([`crate::motion`] does, and rounds
//! less, down to stopping at the waypoints, when it collides). With deviation 0
//! every corner is a stop and the motion between two waypoints is the fastest
//! rest-to-rest one: a trapezoid (or triangle) of the path parameter.
//!
//! ```
//! use tsukami_trajectory_planner::timing::{time_path, Limits};
//! let limits = Limits { velocity: vec![1.0], acceleration: vec![2.0], sample_dt: 0.05, jerk: vec![] };
//! let points = time_path(&[vec![0.0], vec![1.0]], &limits, 0.0);
//! let end = points.last().unwrap();
//! assert!((end.time - 1.5).abs() < 0.01); // 1/v + v/a = 1 + 0.5
//! assert_eq!(end.positions, vec![1.0]);
//! ```

use crate::blend::Blended;
use crate::topp::parameterize;

/// Largest step of the time scaling's grid along the path (joint units).
pub const GRID_STEP: f64 = 0.002;

/// Per-joint limits of a path's joints, and the sampling interval.
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// Velocity limit per joint (rad/s or m/s), > 0.
    pub velocity: Vec<f64>,
    /// Acceleration limit per joint (rad/s² or m/s²), > 0.
    pub acceleration: Vec<f64>,
    /// Longest interval between two samples (s).
    pub sample_dt: f64,
    /// Jerk limit per joint (rad/s³ or m/s³); empty: none.
    pub jerk: Vec<f64>,
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

/// Samples the timed path: the first point at time 0, then samples at most
/// `sample_dt` apart (and at every piece break of the rounded path), ending at
/// rest at the last waypoint. Corners are rounded within `deviation` (0: none,
/// every waypoint a stop). A path without motion gives its first point only.
pub fn time_path(path: &[Vec<f64>], limits: &Limits, deviation: f64) -> Vec<TimedPoint> {
    time_path_with(path, limits, &vec![deviation; path.len()])
}

/// [`time_path`] with a deviation per waypoint (`deviations[i]` rounds the
/// corner at `path[i]`).
pub fn time_path_with(path: &[Vec<f64>], limits: &Limits, deviations: &[f64]) -> Vec<TimedPoint> {
    let Some(first) = path.first() else {
        return vec![];
    };
    let start = TimedPoint {
        time: 0.0,
        positions: first.clone(),
        velocities: vec![0.0; first.len()],
    };
    let blended = Blended::with_deviations(path, deviations);
    let Some(mut profile) =
        parameterize(&blended, &limits.velocity, &limits.acceleration, GRID_STEP)
    else {
        return vec![start];
    };
    // Sampled a little finer than `sample_dt`, so that slowing down by up to
    // `STRETCH` keeps the samples `sample_dt` apart.
    let dt = limits.sample_dt / STRETCH;
    let mut out = sample(&blended, &profile, dt, start.clone(), path);
    // Resampling after a stretch keeps the sample spacing, so a jerk measured
    // across one sample falls only as 1/k²: a few rounds, then in place.
    for round in 0..=RESAMPLES {
        let k = overshoot(&out, limits);
        if k <= 1.0 {
            break;
        }
        if k <= STRETCH || round == RESAMPLES {
            for p in &mut out {
                p.time *= k;
                p.velocities.iter_mut().for_each(|v| *v /= k);
            }
            break;
        }
        profile.stretch(k);
        out = sample(&blended, &profile, dt, start.clone(), path);
    }
    out
}

/// How many times a profile slowed down is sampled again ([`time_path_with`]).
const RESAMPLES: usize = 6;

/// The most the samples are slowed down in place ([`overshoot`]).
const STRETCH: f64 = 1.1;

/// The profile's samples: `start`, then at most `dt` apart and at every
/// piece break and stop, then the last waypoint at rest.
fn sample(
    blended: &Blended,
    profile: &crate::topp::Profile,
    dt: f64,
    start: TimedPoint,
    path: &[Vec<f64>],
) -> Vec<TimedPoint> {
    let total = profile.duration();
    let mut times: Vec<f64> = blended
        .breaks()
        .iter()
        .chain(blended.stops())
        .filter_map(|b| profile.s.iter().position(|s| (s - b).abs() < 1e-9))
        .map(|i| profile.t[i])
        .collect();
    let n = (total / dt.max(1e-4)).ceil().max(1.0) as usize;
    times.extend((1..n).map(|k| total * k as f64 / n as f64));
    times.sort_by(f64::total_cmp);
    times.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    let zero = vec![0.0; start.positions.len()];
    let mut out = vec![start];
    for t in times.into_iter().filter(|&t| t > 1e-9 && t < total - 1e-9) {
        let (s, rate) = profile.at(t);
        let (q, dq, _) = blended.at(s);
        out.push(TimedPoint {
            time: t,
            positions: q,
            velocities: dq.iter().map(|d| d * rate).collect(),
        });
    }
    out.push(TimedPoint {
        time: total,
        positions: path.last().expect("not empty").clone(),
        velocities: zero,
    });
    out
}

/// The least `k ≥ 1` such that `points`, slowed down by `k` (times × k,
/// velocities ÷ k), keep every joint within its velocity limit all along the
/// cubic Hermite curve the controller plays between two points (positions
/// and velocities at both ends), its mean velocity change within its
/// acceleration limit and, when it has one, that curve's jerk within its jerk
/// limit. The grid's limits hold at its points; between them,
/// on a tight arc, a joint may exceed them by a few per cent.
fn overshoot(points: &[TimedPoint], limits: &Limits) -> f64 {
    let mut k: f64 = 1.0;
    for w in points.windows(2) {
        let h = w[1].time - w[0].time;
        if h <= 0.0 {
            continue;
        }
        for j in 0..w[0].positions.len() {
            let (q0, q1) = (w[0].positions[j], w[1].positions[j]);
            let (v0, v1) = (w[0].velocities[j], w[1].velocities[j]);
            let v = hermite_max_speed(q0, q1, v0, v1, h);
            let a = (v1 - v0).abs() / h;
            k = k
                .max(v / limits.velocity[j] * SLACK)
                .max((a / limits.acceleration[j] * SLACK).sqrt());
            if let Some(&jmax) = limits.jerk.get(j) {
                k = k.max((hermite_jerk(q0, q1, v0, v1, h) / jmax * SLACK).cbrt());
            }
        }
    }
    k
}

/// The jerk `|d³q/dt³|` of the cubic Hermite segment from `(q0, v0)` to
/// `(q1, v1)` over `h` seconds, constant along it: `|2 a| / h³` with `a` the
/// `s²` coefficient of `dq/ds`. Scaling time by `k` scales it by `1/k³`.
fn hermite_jerk(q0: f64, q1: f64, v0: f64, v1: f64, h: f64) -> f64 {
    let (a, _, _) = hermite_derivative(q0, q1, v0, v1, h);
    (2.0 * a).abs() / (h * h * h)
}

/// `dq/ds = a s² + b s + c` (`s ∈ [0, 1]`) of the cubic Hermite segment from
/// `(q0, v0)` to `(q1, v1)` over `h` seconds.
fn hermite_derivative(q0: f64, q1: f64, v0: f64, v1: f64, h: f64) -> (f64, f64, f64) {
    let a = 6.0 * q0 + 3.0 * h * v0 - 6.0 * q1 + 3.0 * h * v1;
    let b = -6.0 * q0 - 4.0 * h * v0 + 6.0 * q1 - 2.0 * h * v1;
    (a, b, h * v0)
}

/// The largest `|dq/dt|` of the cubic Hermite segment from `(q0, v0)` to
/// `(q1, v1)` over `h` seconds (the controller's interpolation between two
/// trajectory points). Scaling time by `k` scales it by `1/k`.
fn hermite_max_speed(q0: f64, q1: f64, v0: f64, v1: f64, h: f64) -> f64 {
    let (a, b, c) = hermite_derivative(q0, q1, v0, v1, h);
    let rate = |s: f64| ((a * s + b) * s + c).abs() / h;
    let mut best = rate(0.0).max(rate(1.0));
    if a != 0.0 {
        let vertex = -b / (2.0 * a);
        if (0.0..=1.0).contains(&vertex) {
            best = best.max(rate(vertex));
        }
    }
    best
}

/// Room left below every limit by [`overshoot`] (a fraction).
const SLACK: f64 = 1.0 + 1e-3;

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> Limits {
        Limits {
            velocity: vec![1.0, 0.5],
            acceleration: vec![2.0, 2.0],
            sample_dt: 0.02,
            jerk: vec![],
        }
    }

    /// Three segments with two sharp corners.
    fn zigzag() -> Vec<Vec<f64>> {
        vec![
            vec![0.0, 0.0],
            vec![1.2, -0.3],
            vec![1.25, 0.9],
            vec![-0.4, 0.9],
        ]
    }

    #[test]
    fn every_joint_stays_within_its_limits_between_samples() {
        let path = zigzag();
        let lim = limits();
        let pts = time_path(&path, &lim, 0.0);
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
        // Without rounding, every waypoint is reached at rest.
        let near = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9);
        for q in &path {
            assert!(pts
                .iter()
                .any(|p| near(&p.positions, q) && near(&p.velocities, &[0.0, 0.0])));
        }
    }

    #[test]
    fn a_rounded_path_never_stops_between_its_ends_and_keeps_the_limits() {
        let path = zigzag();
        let lim = limits();
        let sharp = time_path(&path, &lim, 0.0);
        let pts = time_path(&path, &lim, 0.1);
        let inner = &pts[1..pts.len() - 1];
        assert!(inner
            .iter()
            .all(|p| p.velocities.iter().any(|v| v.abs() > 1e-6)));
        assert!(pts.last().unwrap().time < sharp.last().unwrap().time);
        assert_eq!(pts.last().unwrap().positions, path[3]);
        for w in pts.windows(2) {
            let dt = w[1].time - w[0].time;
            assert!(dt > 0.0 && dt <= lim.sample_dt + 1e-12);
            for j in 0..2 {
                let v = (w[1].positions[j] - w[0].positions[j]).abs() / dt;
                assert!(v <= lim.velocity[j] * 1.01, "joint {j}: {v}");
                let a = (w[1].velocities[j] - w[0].velocities[j]).abs() / dt;
                assert!(a <= lim.acceleration[j] * 1.05, "joint {j}: accel {a}");
            }
        }
    }

    #[test]
    fn a_jerk_limit_slows_the_motion_until_every_segment_keeps_it() {
        let path = vec![vec![0.0, 0.0], vec![1.2, -0.3], vec![1.25, 0.9]];
        let free = time_path(&path, &limits(), 0.1);
        let lim = Limits {
            jerk: vec![20.0, 20.0],
            ..limits()
        };
        let pts = time_path(&path, &lim, 0.1);
        assert!(pts.last().unwrap().time > free.last().unwrap().time);
        for w in pts.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            let h = b.time - a.time;
            for j in 0..2 {
                let jerk = hermite_jerk(
                    a.positions[j],
                    b.positions[j],
                    a.velocities[j],
                    b.velocities[j],
                    h,
                );
                assert!(jerk <= 20.0 * 1.0001, "joint {j}: {jerk}");
            }
        }
    }

    #[test]
    fn short_moves_are_triangles_and_no_motion_adds_nothing() {
        let lim = limits();
        let pts = time_path(&[vec![0.0, 0.0], vec![0.1, 0.0]], &lim, 0.0);
        // Triangle: 2·sqrt(Δ/a) = 2·sqrt(0.05).
        assert!((pts.last().unwrap().time - 2.0 * 0.05f64.sqrt()).abs() < 2e-3);
        let still = time_path(&[vec![0.3, 0.3], vec![0.3, 0.3]], &lim, 0.0);
        assert_eq!(still.len(), 1);
    }
}
