//! Joint-space interpolation between timed waypoints.
//!
//! What: [`Segment`] — one joint between two waypoints, linear or cubic Hermite —
//! with its value and rate at a time, and the extremes the checks need (largest
//! speed, range of positions over the segment).
//!
//! Why: the controller samples the trajectory every control period, and it must
//! know before it starts that no sample will leave the joint's limits — with cubic
//! segments the path can overshoot the waypoints.
//!
//! How: linear segments move at `(q1 − q0) / h`. Hermite segments use the standard
//! basis `q(s) = h00 q0 + h10 h v0 + h01 q1 + h11 h v1`, `s = (t − t0) / h`; its
//! derivative `dq/ds = a s² + b s + c` is a quadratic, so the position extremes are
//! its roots in (0, 1) and the speed extremes are at the ends or its vertex.
//!
//! ```
//! use tsukami_controller::interpolate::Segment;
//! let lin = Segment::linear(0.0, 1.0, 2.0); // from 0 to 1 in 2 s
//! assert_eq!(lin.at(1.0), (0.5, 0.5));
//! assert_eq!(lin.max_speed(), 0.5);
//! // A Hermite segment that starts and ends at rest moves fastest in the middle: 1.5 × the mean speed.
//! let cubic = Segment::hermite(0.0, 0.0, 1.0, 0.0, 1.0);
//! assert!((cubic.max_speed() - 1.5).abs() < 1e-12);
//! assert!((cubic.at(0.5).0 - 0.5).abs() < 1e-12);
//! ```

/// One joint's motion between two waypoints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    q0: f64,
    q1: f64,
    /// Velocities at the ends; `None` for a linear segment.
    v: Option<(f64, f64)>,
    /// Duration, seconds (> 0).
    h: f64,
}

impl Segment {
    /// Straight from `q0` to `q1` in `h` seconds.
    pub fn linear(q0: f64, q1: f64, h: f64) -> Segment {
        Segment { q0, q1, v: None, h }
    }

    /// Cubic Hermite from `(q0, v0)` to `(q1, v1)` in `h` seconds.
    pub fn hermite(q0: f64, v0: f64, q1: f64, v1: f64, h: f64) -> Segment {
        Segment {
            q0,
            q1,
            v: Some((v0, v1)),
            h,
        }
    }

    /// Position and velocity at `tau` seconds into the segment (clamped to `[0, h]`).
    pub fn at(&self, tau: f64) -> (f64, f64) {
        let s = (tau / self.h).clamp(0.0, 1.0);
        match self.v {
            None => (
                self.q0 + (self.q1 - self.q0) * s,
                (self.q1 - self.q0) / self.h,
            ),
            Some((v0, v1)) => {
                let (s2, s3) = (s * s, s * s * s);
                let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
                let h10 = s3 - 2.0 * s2 + s;
                let h01 = -2.0 * s3 + 3.0 * s2;
                let h11 = s3 - s2;
                let q = h00 * self.q0 + h10 * self.h * v0 + h01 * self.q1 + h11 * self.h * v1;
                let (a, b, c) = self.derivative_coefficients();
                (q, (a * s2 + b * s + c) / self.h)
            }
        }
    }

    /// `dq/ds = a s² + b s + c` of a Hermite segment (`(0, 0, q1 − q0)` when linear).
    fn derivative_coefficients(&self) -> (f64, f64, f64) {
        let Some((v0, v1)) = self.v else {
            return (0.0, 0.0, self.q1 - self.q0);
        };
        let (q0, q1, h) = (self.q0, self.q1, self.h);
        let a = 6.0 * q0 + 3.0 * h * v0 - 6.0 * q1 + 3.0 * h * v1;
        let b = -6.0 * q0 - 4.0 * h * v0 + 6.0 * q1 - 2.0 * h * v1;
        let c = h * v0;
        (a, b, c)
    }

    /// The largest speed `|dq/dt|` over the segment.
    pub fn max_speed(&self) -> f64 {
        let (a, b, c) = self.derivative_coefficients();
        let rate = |s: f64| ((a * s * s + b * s + c) / self.h).abs();
        let mut best = rate(0.0).max(rate(1.0));
        if a != 0.0 {
            let vertex = -b / (2.0 * a);
            if (0.0..=1.0).contains(&vertex) {
                best = best.max(rate(vertex));
            }
        }
        best
    }

    /// The smallest and largest position over the segment.
    pub fn position_range(&self) -> (f64, f64) {
        let mut lo = self.q0.min(self.q1);
        let mut hi = self.q0.max(self.q1);
        let (a, b, c) = self.derivative_coefficients();
        for s in quadratic_roots(a, b, c) {
            if s > 0.0 && s < 1.0 {
                let q = self.at(s * self.h).0;
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
        (lo, hi)
    }
}

/// Real roots of `a x² + b x + c` (none, one or two; a linear equation when `a = 0`).
fn quadratic_roots(a: f64, b: f64, c: f64) -> Vec<f64> {
    if a == 0.0 {
        return if b == 0.0 { vec![] } else { vec![-c / b] };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return vec![];
    }
    let sq = disc.sqrt();
    vec![(-b - sq) / (2.0 * a), (-b + sq) / (2.0 * a)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_meets_its_end_conditions() {
        let seg = Segment::hermite(0.2, 0.5, -0.4, -1.0, 0.8);
        let (q0, v0) = seg.at(0.0);
        let (q1, v1) = seg.at(0.8);
        assert!((q0 - 0.2).abs() < 1e-12 && (v0 - 0.5).abs() < 1e-12);
        assert!((q1 + 0.4).abs() < 1e-12 && (v1 + 1.0).abs() < 1e-12);
    }

    #[test]
    fn extremes_match_dense_sampling() {
        let seg = Segment::hermite(0.0, 3.0, 0.1, 3.0, 1.0);
        let (mut lo, mut hi, mut fastest) = (f64::MAX, f64::MIN, 0.0f64);
        for k in 0..=100_000 {
            let (q, v) = seg.at(k as f64 / 100_000.0);
            lo = lo.min(q);
            hi = hi.max(q);
            fastest = fastest.max(v.abs());
        }
        let (rlo, rhi) = seg.position_range();
        assert!(
            (rlo - lo).abs() < 1e-9 && (rhi - hi).abs() < 1e-9,
            "{rlo} {lo} {rhi} {hi}"
        );
        assert!((seg.max_speed() - fastest).abs() < 1e-6);
        // It overshoots the waypoints: the range is wider than [0, 0.1].
        assert!(rhi > 0.1 && rlo < 0.0);
    }
}
