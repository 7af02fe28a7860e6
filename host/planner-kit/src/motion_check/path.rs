//! What a motion's collision test answers, as two one-method traits.
//!
//! What: [`Validity`] (is this configuration free?) and [`SegmentSteps`] (how
//! many checks does this straight segment need?), and [`lerp_into`], the
//! points of a straight segment.
//!
//! Why: the trajectory planner's trees and shortcuts and the grasp's phase checks
//! ([`super::phases`]) ask the same two questions of the same checker
//! ([`super::checker::RobotWorld`]); a planner with its own test implements
//! them.
//!
//! How: a segment from `a` to `b` is checked at `steps(a, b)` equal steps
//! ([`super::resolution`] bounds how far any link point moves in one), each
//! point written by [`lerp_into`].
//!
//! ```
//! use tsukami_planner_kit::motion_check::path::lerp_into;
//! let mut q = [0.0; 2];
//! lerp_into(&[0.0, 1.0], &[1.0, 3.0], 0.25, &mut q);
//! assert_eq!(q, [0.25, 1.5]);
//! ```

/// Is a configuration free (no collision, within limits)?
pub trait Validity {
    /// True when `q` may be occupied.
    fn is_valid(&mut self, q: &[f64]) -> bool;
}

/// How many equal steps a straight segment needs so that checking the step ends
/// cannot miss an obstacle (see [`super::resolution`]).
pub trait SegmentSteps {
    /// Number of steps (≥ 1) from `a` to `b`; `usize::MAX` when no finite
    /// number is enough.
    fn steps(&self, a: &[f64], b: &[f64]) -> usize;
}

/// `out = a + t (b − a)`.
pub fn lerp_into(a: &[f64], b: &[f64], t: f64, out: &mut [f64]) {
    for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
        *o = x + t * (y - x);
    }
}
