//! A joint-space polyline with its corners rounded, so that a robot can follow
//! it without stopping.
//!
//! What: [`Blended::new`] turns waypoints into a path of straight pieces and
//! circular arcs tangent to them (each corner replaced by an arc that stays
//! within `deviation` of it), parameterised by arc length `s`;
//! [`Blended::at`] gives `q(s)`, `q'(s)` and `q''(s)`, the path's position,
//! unit tangent and curvature vector, which a time scaling needs
//! ([`crate::topp`]).
//!
//! Why: a polyline has a corner at every waypoint, where the direction of
//! motion jumps; a robot can only pass it at rest. Rounding the corners gives a
//! path with a continuous tangent, along which the velocity never has to drop
//! to zero (T. Kunz and M. Stilman, "Time-optimal trajectory generation for
//! path following with bounded acceleration and velocity", RSS 2012, section
//! IV, whose blends these are).
//!
//! How: at waypoint `w` with incoming unit direction `y1`, outgoing `y2` and
//! angle `α` between them, the arc starts `ℓ` before `w` and ends `ℓ` after it,
//! `ℓ = min(|a|/2, |b|/2, δ sin(α/2) / (1 − cos(α/2)))` (`a`, `b` the two
//! segments, `δ` the deviation), radius `r = ℓ / tan(α/2)`; its midpoint is
//! then at most `δ` from `w`. A corner whose arc would be degenerate (a
//! reversal, or `δ = 0`) stays a corner: [`Blended::stops`] lists it, and the
//! time scaling brings the motion to rest there.
//!
//! ```
//! use tsukami_trajectory_planner::blend::Blended;
//! let path = Blended::new(&[vec![0.0, 0.0], vec![1.0, 0.0], vec![1.0, 1.0]], 0.05);
//! assert!(path.stops().is_empty());
//! // Shorter than the polyline (2), and within 0.05 of the corner.
//! assert!(path.length() < 2.0 && path.length() > 1.9);
//! let (q, dq, _) = path.at(path.length() / 2.0);
//! assert!((q[0] - 1.0).hypot(q[1]) <= 0.05 + 1e-9);
//! assert!((dq[0].hypot(dq[1]) - 1.0).abs() < 1e-9);
//! ```

/// Angles below this are straight (no arc).
const STRAIGHT: f64 = 1e-9;

/// One piece of the path.
#[derive(Debug, Clone, PartialEq)]
enum Piece {
    /// `q = start + s · dir` for `s ∈ [0, length]`.
    Line {
        start: Vec<f64>,
        dir: Vec<f64>,
        length: f64,
    },
    /// `q = c − r n cos θ + r y sin θ`, `θ = s / r ∈ [0, angle]`.
    Arc {
        center: Vec<f64>,
        /// Unit vector from the arc's start toward the centre.
        n: Vec<f64>,
        /// Unit tangent at the arc's start.
        y: Vec<f64>,
        radius: f64,
        angle: f64,
    },
}

impl Piece {
    fn length(&self) -> f64 {
        match self {
            Piece::Line { length, .. } => *length,
            Piece::Arc { radius, angle, .. } => radius * angle,
        }
    }

    fn at(&self, s: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        match self {
            Piece::Line { start, dir, .. } => (
                start.iter().zip(dir).map(|(a, d)| a + s * d).collect(),
                dir.clone(),
                vec![0.0; dir.len()],
            ),
            Piece::Arc {
                center,
                n,
                y,
                radius,
                ..
            } => {
                let (sin, cos) = (s / radius).sin_cos();
                let q = (0..n.len())
                    .map(|j| center[j] - radius * n[j] * cos + radius * y[j] * sin)
                    .collect();
                let dq = (0..n.len()).map(|j| n[j] * sin + y[j] * cos).collect();
                let ddq = (0..n.len())
                    .map(|j| (n[j] * cos - y[j] * sin) / radius)
                    .collect();
                (q, dq, ddq)
            }
        }
    }
}

/// What becomes of an interior waypoint.
enum Corner {
    /// The directions agree: nothing to round.
    Straight,
    /// Rounded by an arc of this tangent length.
    Round(f64, Piece),
    /// Left sharp: the motion stops there.
    Stop,
}

/// A polyline with rounded corners, parameterised by arc length.
#[derive(Debug, Clone, PartialEq)]
pub struct Blended {
    pieces: Vec<Piece>,
    /// Arc length at each piece's start, and the total last.
    starts: Vec<f64>,
    stops: Vec<f64>,
    first: Vec<f64>,
}

fn sub(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn scaled(v: &[f64], k: f64) -> Vec<f64> {
    v.iter().map(|x| x * k).collect()
}

fn along(p: &[f64], d: &[f64], k: f64) -> Vec<f64> {
    p.iter().zip(d).map(|(a, b)| a + k * b).collect()
}

/// The arc rounding the corner at `w` between unit directions `y1`, `y2`
/// with tangent length `l`, or `None` when it would be degenerate.
fn arc(w: &[f64], y1: &[f64], y2: &[f64], l: f64) -> Option<Piece> {
    let cos = y1
        .iter()
        .zip(y2)
        .map(|(a, b)| a * b)
        .sum::<f64>()
        .clamp(-1.0, 1.0);
    let angle = cos.acos();
    let half_tan = (angle / 2.0).tan();
    if !(STRAIGHT..std::f64::consts::PI - 1e-6).contains(&angle) || l <= 0.0 {
        return None;
    }
    let radius = l / half_tan;
    let perp = sub(y2, &scaled(y1, cos));
    let pn = norm(&perp);
    if radius < 1e-9 || pn < 1e-12 {
        return None;
    }
    let n = scaled(&perp, 1.0 / pn);
    let start = along(w, y1, -l);
    Some(Piece::Arc {
        center: along(&start, &n, radius),
        n,
        y: y1.to_vec(),
        radius,
        angle,
    })
}

impl Blended {
    /// The polyline through `waypoints` (repeated points dropped), each
    /// corner rounded within `deviation` of it (joint units; 0: no rounding).
    pub fn new(waypoints: &[Vec<f64>], deviation: f64) -> Blended {
        Blended::with_deviations(waypoints, &vec![deviation; waypoints.len()])
    }

    /// [`Blended::new`] with a deviation per waypoint (`deviations[i]` for
    /// the corner at `waypoints[i]`; the ends' are not used).
    pub fn with_deviations(waypoints: &[Vec<f64>], deviations: &[f64]) -> Blended {
        let mut w: Vec<&Vec<f64>> = Vec::with_capacity(waypoints.len());
        let mut dev: Vec<f64> = Vec::with_capacity(waypoints.len());
        for (p, &d) in waypoints.iter().zip(deviations) {
            match w.last() {
                Some(l) if norm(&sub(p, l)) <= 1e-12 => {
                    // A repeated point: its corner keeps the smaller deviation.
                    let last = dev.last_mut().expect("one per point");
                    *last = last.min(d);
                }
                _ => {
                    w.push(p);
                    dev.push(d);
                }
            }
        }
        let first = waypoints.first().cloned().unwrap_or_default();
        let segs: Vec<(Vec<f64>, f64)> = w
            .windows(2)
            .map(|s| {
                let d = sub(s[1], s[0]);
                let len = norm(&d);
                (scaled(&d, 1.0 / len), len)
            })
            .collect();
        // Each interior corner: straight on, rounded (tangent length, arc) or a stop.
        let mut corners: Vec<Corner> = Vec::new();
        for i in 1..segs.len() {
            let (y1, a) = &segs[i - 1];
            let (y2, b) = &segs[i];
            let cos = y1
                .iter()
                .zip(y2)
                .map(|(p, q)| p * q)
                .sum::<f64>()
                .clamp(-1.0, 1.0);
            let half = cos.acos() / 2.0;
            if half < STRAIGHT / 2.0 {
                corners.push(Corner::Straight);
                continue;
            }
            let l = (dev[i] * half.sin() / (1.0 - half.cos()))
                .min(a / 2.0)
                .min(b / 2.0);
            corners.push(match arc(w[i], y1, y2, l) {
                Some(piece) if dev[i] > 0.0 => Corner::Round(l, piece),
                _ => Corner::Stop,
            });
        }
        let mut out = Blended {
            pieces: Vec::new(),
            starts: vec![0.0],
            stops: Vec::new(),
            first,
        };
        for (i, (dir, len)) in segs.iter().enumerate() {
            let cut = |c: Option<&Corner>| match c {
                Some(Corner::Round(l, _)) => *l,
                _ => 0.0,
            };
            let (cut_in, cut_out) = (
                cut(i.checked_sub(1).map(|k| &corners[k])),
                cut(corners.get(i)),
            );
            out.push(Piece::Line {
                start: along(w[i], dir, cut_in),
                dir: dir.clone(),
                length: (len - cut_in - cut_out).max(0.0),
            });
            match corners.get(i) {
                Some(Corner::Round(_, a)) => out.push(a.clone()),
                Some(Corner::Stop) => out.stops.push(out.length()),
                Some(Corner::Straight) | None => {}
            }
        }
        out
    }

    fn push(&mut self, p: Piece) {
        let total = self.starts.last().copied().unwrap_or(0.0) + p.length();
        self.pieces.push(p);
        self.starts.push(total);
    }

    /// Total arc length (joint units).
    pub fn length(&self) -> f64 {
        self.starts.last().copied().unwrap_or(0.0)
    }

    /// Arc lengths of the corners left sharp, where the motion must be at rest.
    pub fn stops(&self) -> &[f64] {
        &self.stops
    }

    /// Arc lengths where one piece ends and the next begins (interior ones).
    pub fn breaks(&self) -> &[f64] {
        let n = self.starts.len();
        if n <= 2 {
            &[]
        } else {
            &self.starts[1..n - 1]
        }
    }

    /// Position, unit tangent and curvature vector at arc length `s`
    /// (clamped to the path); `side` picks, at a break, the piece before
    /// (`false`) or after (`true`) it.
    pub fn at_side(&self, s: f64, side: bool) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        if self.pieces.is_empty() {
            let z = vec![0.0; self.first.len()];
            return (self.first.clone(), z.clone(), z);
        }
        let s = s.clamp(0.0, self.length());
        let i = match side {
            true => self.starts[1..].partition_point(|&e| e <= s),
            false => self.starts[1..].partition_point(|&e| e < s),
        }
        .min(self.pieces.len() - 1);
        self.pieces[i].at(s - self.starts[i])
    }

    /// [`Blended::at_side`] after a break.
    pub fn at(&self, s: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        self.at_side(s, true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_path_is_continuous_and_tangent_continuous_and_ends_at_the_last_waypoint() {
        let w = vec![
            vec![0.0, 0.0, 0.0],
            vec![1.0, 0.2, 0.0],
            vec![1.1, 1.0, 0.5],
            vec![-0.5, 1.0, 0.4],
        ];
        let p = Blended::new(&w, 0.1);
        assert!(p.stops().is_empty());
        for &b in p.breaks() {
            let (q0, d0, _) = p.at_side(b, false);
            let (q1, d1, _) = p.at_side(b, true);
            assert!(norm(&sub(&q0, &q1)) < 1e-9, "position jumps at {b}");
            assert!(norm(&sub(&d0, &d1)) < 1e-9, "tangent jumps at {b}");
        }
        let (end, _, _) = p.at(p.length());
        assert!(norm(&sub(&end, &w[3])) < 1e-9);
        let (start, _, _) = p.at(0.0);
        assert!(norm(&start) < 1e-12);
        // Every corner within the deviation of the path.
        for c in &w[1..3] {
            let closest = (0..=2000)
                .map(|i| norm(&sub(&p.at(p.length() * i as f64 / 2000.0).0, c)))
                .fold(f64::INFINITY, f64::min);
            assert!(closest <= 0.1 + 1e-3, "{closest}");
        }
    }

    #[test]
    fn without_rounding_or_on_a_reversal_the_corner_is_a_stop() {
        let w = vec![vec![0.0], vec![1.0], vec![0.5]];
        let p = Blended::new(&w, 0.1);
        assert_eq!(p.stops(), &[1.0]);
        let sharp = Blended::new(&[vec![0.0, 0.0], vec![1.0, 0.0], vec![1.0, 1.0]], 0.0);
        assert_eq!(sharp.stops(), &[1.0]);
        assert!((sharp.length() - 2.0).abs() < 1e-12);
    }
}
