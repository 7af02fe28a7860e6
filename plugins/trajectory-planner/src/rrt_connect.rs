//! RRT-Connect: a collision-free joint-space path between two configurations.
//!
//! What: [`plan`] grows one tree from the start and one from the goal and tries to
//! connect them (J. J. Kuffner and S. M. LaValle, "RRT-Connect: An efficient
//! approach to single-query path planning", ICRA 2000). The path it returns is a
//! list of configurations whose straight segments are all collision-free.
//!
//! Why: the reach from the rest posture to a grasp is a high-dimensional query
//! (7 arm joints, plus waist and squat) answered once; a bidirectional tree
//! answers such queries fast, and its greedy connect step suits the mostly free
//! space around a humanoid's arm.
//!
//! How: the collision test is the caller's, behind two one-method traits —
//! [`Validity`] (is this configuration free?) and [`SegmentSteps`] (how many
//! checks does this straight segment need?). Samples come from a ChaCha stream
//! seeded by the caller and the budget counts samples, so the same problem and
//! seed give the same path on any machine. Nearest neighbours are found by a linear
//! scan, which is fast enough for the few thousand nodes a budget allows.
//!
//! Edges are checked lazily (as in Lazy PRM: R. Bohlin and L. E. Kavraki, "Path
//! planning using lazy PRM", ICRA 2000): growing a tree checks each new edge
//! coarsely — its end and every [`GROWTH_STRIDE`]-th of its points, the head of
//! its [`coarse_to_fine`] order; when the trees meet, the edges of the joined path
//! get the rest of their points checked, each edge once. A blocked edge cuts its
//! node and everything grown from it off its tree, and sampling goes on. Most tree
//! edges never lie on a joined path, so most are never checked finely; every
//! point of every edge of the returned path has been.
//!
//! ```
//! use tsukami_trajectory_planner::rrt_connect::{plan, Problem, RrtParams, Validity, SegmentSteps};
//! // A unit square with a wall at x = 0.5 that has a gap at y > 0.8.
//! struct Wall;
//! impl Validity for Wall {
//!     fn is_valid(&mut self, q: &[f64]) -> bool { (q[0] - 0.5).abs() > 0.05 || q[1] > 0.8 }
//! }
//! struct Fine;
//! impl SegmentSteps for Fine {
//!     fn steps(&self, a: &[f64], b: &[f64]) -> usize { ((a[0]-b[0]).hypot(a[1]-b[1]) / 0.01).ceil().max(1.0) as usize }
//! }
//! let problem = Problem { lower: &[0.0, 0.0], upper: &[1.0, 1.0], start: &[0.1, 0.1], goal: &[0.9, 0.1] };
//! let path = plan(&problem, &RrtParams::default(), &mut Wall, &Fine, &|| false).unwrap();
//! assert_eq!(path.first().unwrap(), &vec![0.1, 0.1]);
//! assert_eq!(path.last().unwrap(), &vec![0.9, 0.1]);
//! ```

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub use tsukami_planner_kit::motion_check::path::{lerp_into, SegmentSteps, Validity};

/// A query: bounds of the space, start and goal.
#[derive(Debug, Clone, Copy)]
pub struct Problem<'a> {
    /// Lower bound per dimension.
    pub lower: &'a [f64],
    /// Upper bound per dimension.
    pub upper: &'a [f64],
    /// Start configuration.
    pub start: &'a [f64],
    /// Goal configuration.
    pub goal: &'a [f64],
}

/// Tuning of [`plan`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RrtParams {
    /// Largest number of random samples drawn before giving up.
    pub max_samples: usize,
    /// Longest extension of a tree per step (Euclidean, joint units).
    pub step: f64,
    /// Seed of the sample stream.
    pub seed: u64,
}

impl Default for RrtParams {
    fn default() -> Self {
        RrtParams {
            max_samples: 5000,
            step: 0.15,
            seed: 0,
        }
    }
}

/// Why no path was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RrtError {
    /// The start configuration is in collision or out of bounds.
    #[error("the start configuration is in collision or out of its limits")]
    StartInvalid,
    /// The goal configuration is in collision or out of bounds.
    #[error("the goal configuration is in collision or out of its limits")]
    GoalInvalid,
    /// The sample budget ran out.
    #[error("no collision-free path found within {samples} samples")]
    Exhausted {
        /// Samples drawn.
        samples: usize,
    },
    /// The caller's cancel check said stop.
    #[error("cancelled")]
    Cancelled,
}

/// Checks the straight segment `a → b`, excluding `a` itself (assumed checked):
/// every one of its `steps` points, coarse to fine ([`coarse_to_fine`]), so a
/// blocked segment is usually found blocked after a few checks.
pub fn segment_valid(
    validity: &mut impl Validity,
    steps: &impl SegmentSteps,
    a: &[f64],
    b: &[f64],
) -> bool {
    let n = steps.steps(a, b);
    if n == usize::MAX {
        return false;
    }
    points_valid(validity, a, b, n, coarse_to_fine(n))
}

/// Checks the points `order` (indices into `1..=n`) of `a → b` split in `n` steps.
fn points_valid(
    validity: &mut impl Validity,
    a: &[f64],
    b: &[f64],
    n: usize,
    mut order: impl Iterator<Item = usize>,
) -> bool {
    let mut q = vec![0.0; a.len()];
    order.all(|i| {
        let t = i as f64 / n as f64;
        lerp_into(a, b, t, &mut q);
        validity.is_valid(&q)
    })
}

/// Growing a tree checks every `GROWTH_STRIDE`-th point of a new edge (and its
/// end); the others wait until the edge lies on a joined path.
pub const GROWTH_STRIDE: usize = 8;

/// How many of [`coarse_to_fine`]`(n)` come first and are `n` or multiples of
/// `GROWTH_STRIDE` (a power of two): the points a growing tree checks.
fn growth_points(n: usize) -> usize {
    1 + (n - 1) / GROWTH_STRIDE
}

/// The indices `1..=n`, each once: `n` first, then bisection order — the
/// midpoint, the quarter points, and so on (`i = odd · 2^k` for falling `k`).
///
/// ```
/// use tsukami_trajectory_planner::rrt_connect::coarse_to_fine;
/// assert_eq!(coarse_to_fine(6).collect::<Vec<_>>(), [6, 4, 2, 1, 3, 5]);
/// let mut all: Vec<usize> = coarse_to_fine(1000).collect();
/// all.sort();
/// assert_eq!(all, (1..=1000).collect::<Vec<_>>());
/// ```
pub fn coarse_to_fine(n: usize) -> impl Iterator<Item = usize> {
    let top = n
        .checked_next_power_of_two()
        .unwrap_or(1 << (usize::BITS - 1));
    let strides = std::iter::successors(Some(top), |&s| (s > 1).then_some(s / 2));
    std::iter::once(n)
        .filter(|&n| n > 0)
        .chain(strides.flat_map(move |s| (s..n).step_by(2 * s)))
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// One tree: nodes, the index of each node's parent, the steps of the edge to
/// the parent (0 once it is checked at every point), and whether the node has
/// been cut off.
struct Tree {
    nodes: Vec<Vec<f64>>,
    parent: Vec<usize>,
    unchecked: Vec<usize>,
    cut: Vec<bool>,
}

#[derive(PartialEq)]
enum Extend {
    Trapped,
    Advanced,
    Reached,
}

impl Tree {
    fn new(root: &[f64]) -> Self {
        Tree {
            nodes: vec![root.to_vec()],
            parent: vec![0],
            unchecked: vec![0],
            cut: vec![false],
        }
    }

    fn nearest(&self, q: &[f64]) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, n) in self.nodes.iter().enumerate() {
            if self.cut[i] {
                continue;
            }
            let d = distance(n, q);
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    /// One RRT extension towards `target`; the new edge is checked coarsely
    /// ([`growth_points`]), its end not when it is `target` and `target_free`
    /// says `target` was checked already.
    fn extend<V: Validity, S: SegmentSteps>(
        &mut self,
        target: &[f64],
        target_free: bool,
        step: f64,
        validity: &mut V,
        steps: &S,
    ) -> Extend {
        let near = self.nearest(target);
        let from = &self.nodes[near];
        let d = distance(from, target);
        let (new, reached) = if d <= step {
            (target.to_vec(), true)
        } else {
            let mut q = vec![0.0; target.len()];
            lerp_into(from, target, step / d, &mut q);
            (q, false)
        };
        let n = steps.steps(from, &new);
        if n == usize::MAX {
            return Extend::Trapped;
        }
        let coarse = coarse_to_fine(n)
            .take(growth_points(n))
            .skip(usize::from(reached && target_free));
        if !points_valid(validity, from, &new, n, coarse) {
            return Extend::Trapped;
        }
        self.nodes.push(new);
        self.parent.push(near);
        self.unchecked.push(n);
        self.cut.push(false);
        if reached {
            Extend::Reached
        } else {
            Extend::Advanced
        }
    }

    /// Checks the points left unchecked on the edges between node `i` and the
    /// root, from `i` on; the first blocked edge cuts its lower node and that
    /// node's descendants off. True when the whole path is free.
    fn verify<V: Validity>(&mut self, mut i: usize, validity: &mut V) -> bool {
        while i != 0 {
            let (p, n) = (self.parent[i], self.unchecked[i]);
            if n > 0 {
                let rest = coarse_to_fine(n).skip(growth_points(n));
                if !points_valid(validity, &self.nodes[p], &self.nodes[i], n, rest) {
                    self.cut_off(i);
                    return false;
                }
                self.unchecked[i] = 0;
            }
            i = p;
        }
        true
    }

    /// Cuts node `i` and its descendants (stored after it) off the tree.
    fn cut_off(&mut self, i: usize) {
        self.cut[i] = true;
        for k in i + 1..self.nodes.len() {
            if self.cut[self.parent[k]] {
                self.cut[k] = true;
            }
        }
    }

    /// Root-to-node path.
    fn path_to(&self, mut i: usize) -> Vec<Vec<f64>> {
        let mut path = vec![self.nodes[i].clone()];
        while i != 0 {
            i = self.parent[i];
            path.push(self.nodes[i].clone());
        }
        path.reverse();
        path
    }
}

/// Plans a path from `problem.start` to `problem.goal`; both ends are included.
/// `cancelled` is polled once per sample.
pub fn plan<V: Validity, S: SegmentSteps>(
    problem: &Problem<'_>,
    params: &RrtParams,
    validity: &mut V,
    steps: &S,
    cancelled: &dyn Fn() -> bool,
) -> Result<Vec<Vec<f64>>, RrtError> {
    plan_counted(problem, params, validity, steps, cancelled).map(|(path, _)| path)
}

/// [`plan`], also returning the number of samples drawn (0 when the straight
/// segment was free).
pub fn plan_counted<V: Validity, S: SegmentSteps>(
    problem: &Problem<'_>,
    params: &RrtParams,
    validity: &mut V,
    steps: &S,
    cancelled: &dyn Fn() -> bool,
) -> Result<(Vec<Vec<f64>>, usize), RrtError> {
    let in_bounds = |q: &[f64]| {
        q.iter()
            .zip(problem.lower.iter().zip(problem.upper))
            .all(|(x, (lo, hi))| x >= lo && x <= hi)
    };
    if !in_bounds(problem.start) || !validity.is_valid(problem.start) {
        return Err(RrtError::StartInvalid);
    }
    if !in_bounds(problem.goal) || !validity.is_valid(problem.goal) {
        return Err(RrtError::GoalInvalid);
    }
    if segment_valid(validity, steps, problem.start, problem.goal) {
        return Ok((vec![problem.start.to_vec(), problem.goal.to_vec()], 0));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let mut trees = [Tree::new(problem.start), Tree::new(problem.goal)];
    let mut sample = vec![0.0; problem.start.len()];
    for k in 0..params.max_samples {
        if cancelled() {
            return Err(RrtError::Cancelled);
        }
        for (s, (lo, hi)) in sample
            .iter_mut()
            .zip(problem.lower.iter().zip(problem.upper))
        {
            *s = if hi > lo {
                rng.random_range(*lo..=*hi)
            } else {
                *lo
            };
        }
        let a = k % 2;
        let [ta, tb] = if a == 0 {
            let [x, y] = &mut trees;
            [x, y]
        } else {
            let [x, y] = &mut trees;
            [y, x]
        };
        if ta.extend(&sample, false, params.step, validity, steps) == Extend::Trapped {
            continue;
        }
        let newest = ta.nodes.len() - 1;
        let target = ta.nodes[newest].clone();
        let mut outcome = Extend::Advanced;
        while outcome == Extend::Advanced {
            outcome = tb.extend(&target, true, params.step, validity, steps);
        }
        let joined = tb.nodes.len() - 1;
        if outcome == Extend::Reached && ta.verify(newest, validity) && tb.verify(joined, validity)
        {
            let mut from_a = ta.path_to(newest);
            let mut from_b = tb.path_to(joined);
            from_b.reverse();
            from_b.remove(0); // the connecting node appears in both
            from_a.extend(from_b);
            if a == 1 {
                from_a.reverse();
            }
            return Ok((from_a, k + 1));
        }
    }
    Err(RrtError::Exhausted {
        samples: params.max_samples,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2-D world with a wall at x ∈ [0.45, 0.55] below y = 0.8.
    struct Wall {
        checks: usize,
    }
    impl Validity for Wall {
        fn is_valid(&mut self, q: &[f64]) -> bool {
            self.checks += 1;
            !((0.45..=0.55).contains(&q[0]) && q[1] < 0.8)
        }
    }
    struct Res(f64);
    impl SegmentSteps for Res {
        fn steps(&self, a: &[f64], b: &[f64]) -> usize {
            ((distance(a, b) / self.0).ceil() as usize).max(1)
        }
    }

    fn problem() -> Problem<'static> {
        Problem {
            lower: &[0.0, 0.0],
            upper: &[1.0, 1.0],
            start: &[0.1, 0.1],
            goal: &[0.9, 0.1],
        }
    }

    #[test]
    fn path_goes_around_the_wall_and_every_segment_is_free() {
        let path = plan(
            &problem(),
            &RrtParams::default(),
            &mut Wall { checks: 0 },
            &Res(0.01),
            &|| false,
        )
        .unwrap();
        assert!(
            path.iter().any(|q| q[1] >= 0.8),
            "the path must pass the gap"
        );
        for w in path.windows(2) {
            let mut fine = Wall { checks: 0 };
            assert!(segment_valid(&mut fine, &Res(0.001), &w[0], &w[1]));
        }
    }

    #[test]
    fn a_wall_thinner_than_the_growth_stride_is_caught_on_the_joined_path() {
        // 3 cm thick: growing trees check every 8th point of 1 cm steps and can
        // jump it; the joined path's edges are checked at every point.
        struct Thin;
        impl Validity for Thin {
            fn is_valid(&mut self, q: &[f64]) -> bool {
                !((0.485..=0.515).contains(&q[0]) && q[1] < 0.8)
            }
        }
        for seed in 0..20 {
            let params = RrtParams {
                seed,
                step: 0.3,
                ..RrtParams::default()
            };
            let path = plan(&problem(), &params, &mut Thin, &Res(0.01), &|| false).unwrap();
            for w in path.windows(2) {
                assert!(
                    segment_valid(&mut Thin, &Res(0.001), &w[0], &w[1]),
                    "seed {seed}: {w:?} crosses the wall"
                );
            }
        }
    }

    #[test]
    fn same_seed_same_path_other_seed_other_path() {
        let p = |seed| {
            let params = RrtParams {
                seed,
                ..RrtParams::default()
            };
            plan(
                &problem(),
                &params,
                &mut Wall { checks: 0 },
                &Res(0.01),
                &|| false,
            )
            .unwrap()
        };
        assert_eq!(p(3), p(3));
        assert_ne!(p(3), p(4));
    }

    #[test]
    fn invalid_ends_and_exhaustion_are_reported() {
        let mut pr = problem();
        pr.start = &[0.5, 0.1];
        assert_eq!(
            plan(
                &pr,
                &RrtParams::default(),
                &mut Wall { checks: 0 },
                &Res(0.01),
                &|| false
            ),
            Err(RrtError::StartInvalid)
        );
        let mut pr = problem();
        pr.goal = &[0.5, 0.5];
        assert_eq!(
            plan(
                &pr,
                &RrtParams::default(),
                &mut Wall { checks: 0 },
                &Res(0.01),
                &|| false
            ),
            Err(RrtError::GoalInvalid)
        );
        // A wall with no gap: nothing connects.
        struct Closed;
        impl Validity for Closed {
            fn is_valid(&mut self, q: &[f64]) -> bool {
                !(0.45..=0.55).contains(&q[0])
            }
        }
        let params = RrtParams {
            max_samples: 300,
            ..RrtParams::default()
        };
        assert_eq!(
            plan(&problem(), &params, &mut Closed, &Res(0.01), &|| false),
            Err(RrtError::Exhausted { samples: 300 })
        );
        assert_eq!(
            plan(&problem(), &params, &mut Closed, &Res(0.01), &|| true),
            Err(RrtError::Cancelled)
        );
    }
}
