//! A phase's corners rounded as far as the obstacles allow, eased outward
//! where they touch the clearance.
//!
//! What: [`timed_phase`] times one phase's waypoints with their corners rounded
//! ([`crate::blend`], [`crate::timing`]) and returns the samples the controller
//! follows, every one checked against the phase's world.
//!
//! Why: a rounded corner cuts inside its waypoint. Shortcutting pulls a path
//! taut against the obstacles, so its corners often lie on the clearance's
//! edge, and any cut collides. Unrounded, the motion must stop there: a real
//! arm would halt for a moment at every such corner (issue #23: motions must not
//! stop inside a phase).
//!
//! How: the sampled polyline is checked; the corner nearest the first
//! collision rounds a quarter as much, down to `deviation / 64`. A corner still
//! blocked then is eased once: the waypoint moves outward along its angle's
//! bisector (away from the inside, where the obstacle is) by `deviation / 16`,
//! within the joints' limits, when both new segments are clear; it is then
//! rounded again from `deviation / 16`. A corner that cannot be eased is not
//! rounded (the motion stops there). Unrounded, the samples lie on the checked
//! path.
//!
//! ```
//! use tsukami_trajectory_planner::rounding::eased;
//! // A right-angle corner at (1, 0), eased outward (away from the inside).
//! let q = eased(&[0.0, 0.0], &[1.0, 0.0], &[1.0, 1.0], 0.1).unwrap();
//! assert!(q[0] > 1.0 && q[1] < 0.0);
//! assert!(((q[0] - 1.0).hypot(q[1]) - 0.1).abs() < 1e-12);
//! ```

use tsukami_planner_kit::motion_check::checker::RobotWorld;
use tsukami_planner_kit::motion_check::phases::{first_blocked, PhaseScene};

use crate::timing;

/// How many times a phase's rounding is tightened (or a corner eased) before
/// it stops at its waypoints.
const ROUNDING_TRIES: usize = 32;

/// One phase timed with its corners rounded by `deviation` where the phase's
/// `world` allows (module header).
pub fn timed_phase(
    s: &mut PhaseScene<'_>,
    mut world: RobotWorld<'_>,
    path: &[Vec<f64>],
    limits: &timing::Limits,
    deviation: f64,
) -> Vec<timing::TimedPoint> {
    let bounds: Vec<(f64, f64)> = s
        .joints
        .iter()
        .map(|&j| {
            let l = &s.model().joints[j].limits;
            (l.lower, l.upper)
        })
        .collect();
    let mut path = path.to_vec();
    let mut dev = vec![deviation; path.len()];
    let mut eased_once = vec![false; path.len()];
    for _ in 0..ROUNDING_TRIES {
        let points = timing::time_path_with(&path, limits, &dev);
        let polyline: Vec<Vec<f64>> = points.iter().map(|p| p.positions.clone()).collect();
        let blocked = first_blocked(&mut world, &polyline);
        s.checks += world.checks();
        let Err((k, _)) = blocked else {
            return points;
        };
        let (a, b) = (&polyline[k], &polyline[(k + 1).min(polyline.len() - 1)]);
        let Some(c) = nearest_corner(&path, a, b) else {
            break;
        };
        if dev[c] > deviation / 64.0 {
            dev[c] /= 4.0;
            continue;
        }
        let step = deviation / 16.0;
        let moved = (!eased_once[c])
            .then(|| eased(&path[c - 1], &path[c], &path[c + 1], step))
            .flatten()
            .filter(|q| within(q, &bounds))
            .filter(|q| {
                let clear = first_blocked(
                    &mut world,
                    &[path[c - 1].clone(), q.clone(), path[c + 1].clone()],
                );
                s.checks += world.checks();
                clear.is_ok()
            });
        eased_once[c] = true;
        match moved {
            Some(q) => {
                path[c] = q;
                dev[c] = step;
            }
            None => dev[c] = 0.0,
        }
    }
    timing::time_path(&path, limits, 0.0)
}

/// The corner `w` (between `prev` and `next`) moved by `step` along its
/// angle's bisector, away from the inside of the corner; `None` when the
/// corner is straight or a waypoint repeats.
pub fn eased(prev: &[f64], w: &[f64], next: &[f64], step: f64) -> Option<Vec<f64>> {
    let unit = |a: &[f64]| -> Option<Vec<f64>> {
        let d: Vec<f64> = a.iter().zip(w).map(|(x, y)| x - y).collect();
        let n = d.iter().map(|x| x * x).sum::<f64>().sqrt();
        (n > 1e-12).then(|| d.iter().map(|x| x / n).collect())
    };
    let (u1, u2) = (unit(prev)?, unit(next)?);
    let inside: Vec<f64> = u1.iter().zip(&u2).map(|(a, b)| a + b).collect();
    let n = inside.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n < 1e-9 {
        return None;
    }
    Some(
        w.iter()
            .zip(&inside)
            .map(|(x, d)| x - step * d / n)
            .collect(),
    )
}

fn within(q: &[f64], bounds: &[(f64, f64)]) -> bool {
    q.iter()
        .zip(bounds)
        .all(|(x, (lo, hi))| *x >= *lo && *x <= *hi)
}

/// The interior waypoint of `path` nearest the segment `a`–`b`'s midpoint.
fn nearest_corner(path: &[Vec<f64>], a: &[f64], b: &[f64]) -> Option<usize> {
    let mid: Vec<f64> = a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect();
    let d = |q: &[f64]| {
        q.iter()
            .zip(&mid)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
    };
    (1..path.len().saturating_sub(1)).min_by(|&i, &j| d(&path[i]).total_cmp(&d(&path[j])))
}
