//! Time-optimal path parameterization by reachability analysis (TOPP-RA).
//!
//! What: [`parameterize`] finds, along a path `q(s)` ([`crate::blend::Blended`]),
//! the fastest speed profile `ṡ(s)` from rest to rest that keeps every joint
//! within its velocity limit `|q'_j ṡ| ≤ v_j` and its acceleration limit
//! `|q'_j s̈ + q''_j ṡ²| ≤ a_j`, at rest wherever the path has a sharp corner.
//! [`Profile::at`] gives the path position and speed at a time.
//!
//! Why: stopping at every waypoint makes a reach stop-and-go; following a
//! rounded path at the fastest admissible speed is what a robot arm's own
//! controller does. This is the method of H. Pham and Q.-C. Pham, "A New
//! Approach to Time-Optimal Path Parameterization Based on Reachability
//! Analysis", IEEE T-RO 34(3), 2018 (the `toppra` library), with the
//! constraints of a joint-limited arm only.
//!
//! How: on a grid `s_0 < … < s_N` (every piece of the path cut into steps of at
//! most `step`, at least two each), the state is `x_i = ṡ²` and the control
//! `u_i = s̈`, constant on `[s_i, s_{i+1}]`, so `x_{i+1} = x_i + 2 Δ_i u_i`.
//! At each grid point the limits are linear in `(x, u)`: `x ≤ min_j v_j² / q'_j²`
//! and `−a_j ≤ q'_j u + q''_j x ≤ a_j` (both sides' `q''` at a piece break).
//! The backward pass computes the controllable sets `K_i = [lo_i, hi_i]` (the
//! speeds from which rest at `s_N` can still be reached): `K_N = {0}` and
//! `K_i` the `x` for which some admissible `u` leads into `K_{i+1}` — a
//! two-variable linear program, solved exactly by eliminating `u`
//! (Fourier–Motzkin: every pair of an upper and a lower bound on `u` is a
//! bound on `x`). The forward pass starts at rest and takes the largest
//! admissible `u` that stays in `K_{i+1}` (the greedy step of TOPP-RA, which
//! is time-optimal on the grid). The time across an interval is
//! `2 Δ_i / (√x_i + √x_{i+1})`.
//!
//! ```
//! use tsukami_trajectory_planner::blend::Blended;
//! use tsukami_trajectory_planner::topp::parameterize;
//! // 1 rad at 1 rad/s and 2 rad/s²: accelerate 0.5 s, cruise 0.5 s, brake 0.5 s.
//! let path = Blended::new(&[vec![0.0], vec![1.0]], 0.0);
//! let p = parameterize(&path, &[1.0], &[2.0], 0.001).unwrap();
//! assert!((p.duration() - 1.5).abs() < 0.01, "{}", p.duration());
//! ```

use crate::blend::Blended;

/// The speed profile along a path: grid, `ṡ²` at each grid point, and the
/// time each grid point is reached.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// Arc length of each grid point.
    pub s: Vec<f64>,
    /// `ṡ²` at each grid point.
    pub x: Vec<f64>,
    /// Time at each grid point (s).
    pub t: Vec<f64>,
}

/// A linear constraint `ax · x + au · u ≤ c`.
#[derive(Debug, Clone, Copy)]
struct Row {
    ax: f64,
    au: f64,
    c: f64,
}

/// The grid: every piece cut into at least two steps of at most `step`.
fn grid(path: &Blended, step: f64) -> Vec<f64> {
    let mut edges = vec![0.0];
    edges.extend_from_slice(path.breaks());
    edges.push(path.length());
    let mut s = vec![0.0];
    for w in edges.windows(2) {
        let span = w[1] - w[0];
        if span <= 1e-12 {
            continue;
        }
        let n = ((span / step).ceil() as usize).max(2);
        s.extend((1..=n).map(|k| w[0] + span * k as f64 / n as f64));
    }
    s
}

/// The limits at arc length `s` as rows in `(x, u)`, and the largest `x`
/// the velocity limits allow.
fn rows_at(path: &Blended, s: f64, v: &[f64], a: &[f64], out: &mut Vec<Row>) -> f64 {
    out.clear();
    let mut xmax = f64::INFINITY;
    for side in [false, true] {
        let (_, dq, ddq) = path.at_side(s, side);
        for j in 0..dq.len() {
            if dq[j].abs() > 1e-12 {
                xmax = xmax.min((v[j] / dq[j]).powi(2));
            }
            if dq[j].abs() > 1e-12 || ddq[j].abs() > 1e-12 {
                out.push(Row {
                    ax: ddq[j],
                    au: dq[j],
                    c: a[j],
                });
                out.push(Row {
                    ax: -ddq[j],
                    au: -dq[j],
                    c: a[j],
                });
            }
        }
    }
    xmax
}

/// The interval of `x` for which some `u` satisfies every row: `u` eliminated
/// pair by pair. `None` when empty.
fn x_range(rows: &[Row], lo: f64, hi: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (lo, hi);
    let tiny = 1e-12;
    for r in rows.iter().filter(|r| r.au.abs() <= tiny) {
        // ax x ≤ c
        if r.ax > tiny {
            hi = hi.min(r.c / r.ax);
        } else if r.ax < -tiny {
            lo = lo.max(r.c / r.ax);
        } else if r.c < 0.0 {
            return None;
        }
    }
    for up in rows.iter().filter(|r| r.au > tiny) {
        for dn in rows.iter().filter(|r| r.au < -tiny) {
            // (c_dn − ax_dn x)/au_dn ≤ u ≤ (c_up − ax_up x)/au_up
            let k = up.ax / up.au - dn.ax / dn.au;
            let m = up.c / up.au - dn.c / dn.au;
            if k > tiny {
                hi = hi.min(m / k);
            } else if k < -tiny {
                lo = lo.max(m / k);
            } else if m < -1e-9 {
                return None;
            }
        }
    }
    (lo <= hi + 1e-12).then_some((lo, hi.max(lo)))
}

/// The rows of a grid point and those that keep `x + d2 u` (the next state)
/// inside the next point's controllable set `[lo1, hi1]`.
fn into_next(rows: &[Row], d2: f64, (lo1, hi1): (f64, f64)) -> Vec<Row> {
    let mut r = rows.to_vec();
    r.push(Row {
        ax: 1.0,
        au: d2,
        c: hi1,
    });
    r.push(Row {
        ax: -1.0,
        au: -d2,
        c: -lo1,
    });
    r
}

/// The largest `u` every row allows at `x`, or `None`.
fn u_max(rows: &[Row], x: f64) -> Option<f64> {
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for r in rows {
        let rhs = r.c - r.ax * x;
        if r.au > 1e-12 {
            hi = hi.min(rhs / r.au);
        } else if r.au < -1e-12 {
            lo = lo.max(rhs / r.au);
        }
    }
    (lo <= hi + 1e-9 && hi.is_finite()).then_some(hi.max(lo))
}

/// The fastest rest-to-rest profile along `path` within the joints'
/// velocity limits `v` and acceleration limits `a` (all > 0), on a grid of
/// at most `step`; at rest at every [`Blended::stops`]. `None` when the path
/// has no length or the limits admit no motion.
pub fn parameterize(path: &Blended, v: &[f64], a: &[f64], step: f64) -> Option<Profile> {
    let s = grid(path, step.max(1e-6));
    let n = s.len() - 1;
    if n == 0 {
        return None;
    }
    let stops = path.stops();
    let is_stop = |si: f64| stops.iter().any(|&p| (p - si).abs() < 1e-9);
    let mut rows: Vec<Vec<Row>> = Vec::with_capacity(n + 1);
    let mut xmax = Vec::with_capacity(n + 1);
    let mut scratch = Vec::new();
    for &si in &s {
        let m = rows_at(path, si, v, a, &mut scratch);
        xmax.push(if is_stop(si) { 0.0 } else { m });
        rows.push(scratch.clone());
    }
    xmax[0] = 0.0;
    xmax[n] = 0.0;
    // Backward pass: the controllable sets.
    let mut k = vec![(0.0, 0.0); n + 1];
    for i in (0..n).rev() {
        let d2 = 2.0 * (s[i + 1] - s[i]);
        let (lo1, hi1) = k[i + 1];
        let r = into_next(&rows[i], d2, (lo1, hi1));
        k[i] = x_range(&r, 0.0, xmax[i])?;
    }
    // Forward pass: the greedy step.
    let mut x = vec![0.0; n + 1];
    for i in 0..n {
        let d2 = 2.0 * (s[i + 1] - s[i]);
        let (lo1, hi1) = k[i + 1];
        let r = into_next(&rows[i], d2, (lo1, hi1));
        let u = u_max(&r, x[i]).unwrap_or((hi1 - x[i]) / d2);
        x[i + 1] = (x[i] + d2 * u).clamp(lo1.max(0.0), hi1);
    }
    let mut t = vec![0.0; n + 1];
    for i in 0..n {
        let rate = x[i].sqrt() + x[i + 1].sqrt();
        if rate <= 0.0 {
            return None;
        }
        t[i + 1] = t[i] + 2.0 * (s[i + 1] - s[i]) / rate;
    }
    Some(Profile { s, x, t })
}

impl Profile {
    /// The time the profile takes (s).
    pub fn duration(&self) -> f64 {
        self.t.last().copied().unwrap_or(0.0)
    }

    /// The same path `k` times slower (`k > 0`): every time × k, `ṡ²` ÷ k².
    pub fn stretch(&mut self, k: f64) {
        self.t.iter_mut().for_each(|t| *t *= k);
        self.x.iter_mut().for_each(|x| *x /= k * k);
    }

    /// Arc length and speed `ṡ` at time `t` (clamped): constant `s̈` across
    /// each grid interval.
    pub fn at(&self, t: f64) -> (f64, f64) {
        let t = t.clamp(0.0, self.duration());
        let i = self
            .t
            .partition_point(|&ti| ti <= t)
            .clamp(1, self.t.len() - 1)
            - 1;
        let (v0, v1) = (self.x[i].sqrt(), self.x[i + 1].sqrt());
        let dt = self.t[i + 1] - self.t[i];
        let acc = if dt > 0.0 { (v1 - v0) / dt } else { 0.0 };
        let tau = t - self.t[i];
        let s = (self.s[i] + v0 * tau + 0.5 * acc * tau * tau).min(self.s[i + 1]);
        (s, v0 + acc * tau)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rounded_corner_is_passed_without_stopping_and_within_the_limits() {
        let path = Blended::new(&[vec![0.0, 0.0], vec![1.0, 0.0], vec![1.0, 1.0]], 0.1);
        let (v, a) = ([1.0, 0.8], [2.0, 3.0]);
        let p = parameterize(&path, &v, &a, 0.002).unwrap();
        // Moving everywhere but at the ends.
        assert!(p.x[1..p.x.len() - 1].iter().all(|&x| x > 0.0));
        // Faster than stopping at the corner: two rest-to-rest segments.
        let stop = |len: f64, v: f64, a: f64| len / v + v / a;
        assert!(p.duration() < stop(1.0, 1.0, 2.0) + stop(1.0, 0.8, 3.0));
        // Limits hold at 1 ms samples (finite differences), within 3 %.
        let dt = 1e-3;
        let q = |t: f64| path.at(p.at(t).0).0;
        let steps = (p.duration() / dt) as usize;
        for k in 1..steps {
            let t = k as f64 * dt;
            let (q0, q1, q2) = (q(t - dt), q(t), q(t + dt));
            for j in 0..2 {
                let vel = (q2[j] - q0[j]) / (2.0 * dt);
                let acc = (q2[j] - 2.0 * q1[j] + q0[j]) / (dt * dt);
                assert!(vel.abs() <= v[j] * 1.03, "t {t} joint {j} v {vel}");
                assert!(acc.abs() <= a[j] * 1.03 + 0.05, "t {t} joint {j} a {acc}");
            }
        }
    }

    #[test]
    fn a_sharp_corner_is_a_stop() {
        let path = Blended::new(&[vec![0.0], vec![1.0], vec![0.0]], 0.1);
        let p = parameterize(&path, &[1.0], &[2.0], 0.001).unwrap();
        let i = p.s.iter().position(|&s| (s - 1.0).abs() < 1e-9).unwrap();
        assert_eq!(p.x[i], 0.0);
        assert!((p.duration() - 3.0).abs() < 0.02, "{}", p.duration());
    }
}
