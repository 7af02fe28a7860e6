//! One plan's bookkeeping: stop checks, samples, rejections, progress, timing.
//!
//! What: [`Run`] is handed to `GraspPlanner::plan`. A planner calls
//! [`Run::sample`] once per sample (it counts the sample and checks the cancel
//! flag and, only when the request asked for one, the deadline),
//! [`Run::reject`] with a short reason when a sample fails ([`Run::blocked`]
//! with what blocked it, e.g. `"r_thumb_link2 vs table"`), [`Run::phase`] when
//! it moves to another phase (which times the phases and publishes a progress
//! event), and [`Run::margin`] with each ellipsoid margin it computes.
//!
//! Why: the same counts, stop rules and progress events for every planner; the
//! kit turns them into the reply and into the message and `details` of a failed
//! plan (`rejections`, `blockers`, `blocked_by`).
//!
//! How: reasons are owned strings, so a planner may name links and obstacles;
//! each table keeps at most [`MAX_REASONS`] names of at most [`MAX_REASON_LEN`]
//! bytes, and counts the rest under [`OTHERS`], so no input makes it grow
//! without bound.
//!
//! ```
//! use std::sync::atomic::AtomicBool;
//! use tsukami_planner_kit::Run;
//! let cancel = AtomicBool::new(false);
//! let mut events = 0;
//! let mut progress = |_: &tsukami_msgs::planner::ProgressEvent| events += 1;
//! let mut run = Run::new(&cancel, None, &mut progress);
//! run.sample().unwrap();
//! run.reject("ik");
//! run.blocked("r_thumb_link2 vs table", 2);
//! assert_eq!(run.samples(), 1);
//! assert!(run.summary().contains("ik 1"));
//! assert_eq!(run.blocked_by()["table"], 2);
//! ```

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use tsukami_msgs::planner::{HoldRequest, PhaseTiming, PlanPhase, PoseRobustness, ProgressEvent};

use crate::motion_check::phases::Blocked;
use crate::planner::{GraspPlanner, World};
use crate::{Grasp, Stop};

/// Most distinct names kept in each rejection table.
pub const MAX_REASONS: usize = 32;
/// Longest name kept (bytes; longer names are cut at a character boundary).
pub const MAX_REASON_LEN: usize = 96;
/// The name the counts beyond [`MAX_REASONS`] are kept under.
pub const OTHERS: &str = "(others)";

/// Adds `n` to `name` in a bounded table (see the module documentation).
fn count(table: &mut BTreeMap<String, u32>, name: &str, n: u32) {
    if n == 0 {
        return;
    }
    let mut end = name.len().min(MAX_REASON_LEN);
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    let name = &name[..end];
    // One slot stays free for OTHERS: at most MAX_REASONS entries in all.
    let key = if table.contains_key(name) || table.len() + 1 < MAX_REASONS {
        name
    } else {
        OTHERS
    };
    let slot = table.entry(key.to_owned()).or_default();
    *slot = slot.saturating_add(n);
}

/// The bookkeeping of one plan.
pub struct Run<'a> {
    cancel: &'a AtomicBool,
    deadline: Option<(Instant, u64)>,
    progress: &'a mut dyn FnMut(&ProgressEvent),
    start: Instant,
    samples: u32,
    rejections: BTreeMap<String, u32>,
    blockers: BTreeMap<String, u32>,
    best_margin: Option<f64>,
    timing: PhaseTiming,
    phase: (PlanPhase, Instant),
    grasp_type: Option<String>,
    joints_used: Vec<String>,
    tried: Vec<String>,
    /// The last pose-robustness answer and what it was asked of.
    robust_memo: Option<RobustMemo>,
    /// The last motion-phase answer and the grasp it was asked of.
    phase_memo: Option<(Grasp, Result<(), Blocked>)>,
}

/// A grasp, the request and seed it was re-checked under, and the answer.
type RobustMemo = (Grasp, HoldRequest, u64, PoseRobustness);

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

impl<'a> Run<'a> {
    /// A run polling `cancel`, with a wall-clock budget only if `budget_ms` is set.
    pub fn new(
        cancel: &'a AtomicBool,
        budget_ms: Option<u64>,
        progress: &'a mut dyn FnMut(&ProgressEvent),
    ) -> Self {
        let start = Instant::now();
        Run {
            cancel,
            deadline: budget_ms.map(|b| (start + Duration::from_millis(b), b)),
            progress,
            start,
            samples: 0,
            rejections: BTreeMap::new(),
            blockers: BTreeMap::new(),
            best_margin: None,
            timing: PhaseTiming::default(),
            phase: (PlanPhase::Selection, start),
            grasp_type: None,
            joints_used: Vec::new(),
            tried: Vec::new(),
            robust_memo: None,
            phase_memo: None,
        }
    }

    /// The exact hold margin of `grasp` under `req`, `None` when it does not
    /// hold ([`crate::verify::hold_margin`]).
    pub fn hold_margin<P: GraspPlanner>(
        &self,
        world: &World<'_, P>,
        grasp: &Grasp,
        req: &HoldRequest,
    ) -> Option<f64> {
        crate::verify::hold_margin(world, grasp, req)
    }

    /// [`Run::hold_margin`] clipped at `cap` ([`crate::verify::hold_margin_up_to`]):
    /// enough to compare with a preferred margin, for fewer programs.
    pub fn hold_margin_up_to<P: GraspPlanner>(
        &self,
        world: &World<'_, P>,
        grasp: &Grasp,
        req: &HoldRequest,
        cap: f64,
    ) -> Option<f64> {
        crate::verify::hold_margin_up_to(world, grasp, req, cap)
    }

    /// How many of the request's object pose errors `grasp` still holds
    /// under ([`crate::verify::robustness`], the kit's re-check). The last
    /// answer is kept, so the verification of the grasp a planner chose on it
    /// does not repeat the work.
    pub fn pose_robustness<P: GraspPlanner>(
        &mut self,
        world: &World<'_, P>,
        grasp: &Grasp,
        req: &HoldRequest,
        seed: u64,
    ) -> PoseRobustness {
        if let Some((g, r, s, answer)) = &self.robust_memo {
            if g == grasp && r == req && *s == seed {
                return *answer;
            }
        }
        let answer = crate::verify::robustness(world, grasp, req, seed);
        self.robust_memo = Some((grasp.clone(), *req, seed, answer));
        answer
    }

    /// Whether the approach, closing and lift `grasp` implies are free
    /// ([`crate::verify::motion_phases`]). The last answer is kept, so the
    /// session's check of the grasp a planner chose on it does not repeat the
    /// work.
    pub fn motion_phases<P: GraspPlanner>(
        &mut self,
        world: &World<'_, P>,
        grasp: &Grasp,
    ) -> Result<(), Blocked> {
        if let Some((g, answer)) = &self.phase_memo {
            if g == grasp {
                return answer.clone();
            }
        }
        let answer = crate::verify::motion_phases(world, grasp);
        self.phase_memo = Some((grasp.clone(), answer.clone()));
        answer
    }

    /// `Err` once the plan must stop: cancelled, or past the request's deadline.
    pub fn check(&self) -> Result<(), Stop> {
        if self.cancel.load(Ordering::Relaxed) {
            return Err(Stop::Cancelled);
        }
        match self.deadline {
            Some((at, budget)) if Instant::now() >= at => Err(Stop::OutOfTime(budget)),
            _ => Ok(()),
        }
    }

    /// Counts one sample after [`Run::check`].
    pub fn sample(&mut self) -> Result<(), Stop> {
        self.check()?;
        self.samples += 1;
        Ok(())
    }

    /// The raw cancel flag, for algorithm code that polls it itself.
    pub fn cancel_flag(&self) -> &'a AtomicBool {
        self.cancel
    }

    /// The request's deadline, if it asked for one.
    pub fn deadline(&self) -> Option<Instant> {
        self.deadline.map(|d| d.0)
    }

    /// Takes the counts of a planner that counts samples itself: the total
    /// drawn so far and its best margin.
    pub fn record(&mut self, samples: u32, best_margin: Option<f64>) {
        self.samples = self.samples.max(samples);
        if let Some(m) = best_margin {
            self.margin(m);
        }
    }

    /// Records `n` rejections for one reason at once (0 records nothing).
    pub fn rejected(&mut self, why: &str, n: u32) {
        count(&mut self.rejections, why, n);
    }

    /// Records that `what` blocked `n` samples, named `"<link> vs <obstacle>"`
    /// (or `"<link> into <obstacle>"`): the obstacle is the text after the last
    /// `" vs "` / `" into "` ([`Run::blocked_by`]).
    pub fn blocked(&mut self, what: &str, n: u32) {
        count(&mut self.blockers, what, n);
    }

    /// What blocked samples, per link and obstacle.
    pub fn blockers(&self) -> &BTreeMap<String, u32> {
        &self.blockers
    }

    /// Blocked samples per obstacle (or `the object`, or a link for
    /// self-collision), summed over the links of [`Run::blockers`].
    pub fn blocked_by(&self) -> BTreeMap<String, u32> {
        let mut out = BTreeMap::new();
        for (what, &n) in &self.blockers {
            let by = [" vs ", " into "]
                .iter()
                .filter_map(|sep| what.rfind(sep).map(|i| &what[i + sep.len()..]))
                .next()
                .unwrap_or(what);
            count(&mut out, by, n);
        }
        out
    }

    /// Samples drawn so far.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Records why a sample was rejected.
    pub fn reject(&mut self, why: &str) {
        count(&mut self.rejections, why, 1);
    }

    /// Rejection counts per reason.
    pub fn rejections(&self) -> &BTreeMap<String, u32> {
        &self.rejections
    }

    /// Records an ellipsoid margin; keeps the best.
    pub fn margin(&mut self, margin: f64) {
        if margin.is_finite() && self.best_margin.is_none_or(|b| margin > b) {
            self.best_margin = Some(margin);
        }
    }

    /// Best margin so far.
    pub fn best_margin(&self) -> Option<f64> {
        self.best_margin
    }

    /// Records a grasp type tried (the reply's `candidates_tried`).
    pub fn tried(&mut self, grasp_type: &str) {
        self.tried.push(grasp_type.to_owned());
    }

    /// Moves to `phase` (timing the phase left) with the grasp type and extra
    /// joints being tried, and publishes a progress event.
    pub fn phase(&mut self, phase: PlanPhase, grasp_type: Option<&str>, joints_used: &[String]) {
        let now = Instant::now();
        let spent = ms(now - self.phase.1);
        let t = &mut self.timing;
        match self.phase.0 {
            PlanPhase::Selection => t.selection += spent,
            PlanPhase::NominalPose => t.nominal_pose += spent,
            PlanPhase::Search => t.search += spent,
            PlanPhase::Verification | PlanPhase::Done => t.verification += spent,
        }
        self.phase = (phase, now);
        self.grasp_type = grasp_type.map(str::to_owned);
        self.joints_used = joints_used.to_vec();
        self.report();
    }

    /// Publishes a progress event for the current phase.
    pub fn report(&mut self) {
        let event = ProgressEvent {
            phase: self.phase.0,
            grasp_type: self.grasp_type.clone(),
            joints_used: self.joints_used.clone(),
            samples: self.samples,
            best_margin: self.best_margin,
            elapsed_ms: ms(self.start.elapsed()),
        };
        (self.progress)(&event);
    }

    /// Counts, best margin and rejections as text for an error message.
    pub fn summary(&self) -> String {
        let rejections: Vec<String> = self
            .rejections
            .iter()
            .map(|(why, n)| format!("{why} {n}"))
            .collect();
        let mut blocked: Vec<(String, u32)> = self.blocked_by().into_iter().collect();
        blocked.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        let blocked: Vec<String> = blocked
            .iter()
            .take(5)
            .map(|(by, n)| format!("{by} {n}"))
            .collect();
        let mut s = format!(
            "{} samples, best margin {}; rejections: {}",
            self.samples,
            self.best_margin
                .map_or("none".into(), |m| format!("{m:.3}")),
            if rejections.is_empty() {
                "none".into()
            } else {
                rejections.join(", ")
            }
        );
        if !blocked.is_empty() {
            s.push_str("; blocked by: ");
            s.push_str(&blocked.join(", "));
        }
        s
    }

    /// Ends the run: the phase times, total included, and the types tried.
    pub fn finish(mut self) -> (PhaseTiming, Vec<String>, u32) {
        self.phase(PlanPhase::Done, None, &[]);
        self.timing.total = ms(self.start.elapsed());
        (self.timing, self.tried, self.samples)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_stay_bounded_and_name_obstacles() {
        let cancel = AtomicBool::new(false);
        let mut progress = |_: &ProgressEvent| {};
        let mut run = Run::new(&cancel, None, &mut progress);
        for k in 0..1000 {
            run.reject(&format!("reason {k} {}", "x".repeat(k)));
            run.blocked(&format!("link{k} vs shelf"), 1);
        }
        run.blocked("r_thumb vs table", 3);
        run.blocked("r_index into the object", 2);
        assert_eq!(run.rejections().len(), MAX_REASONS);
        assert_eq!(run.rejections()[OTHERS], 1000 - (MAX_REASONS as u32 - 1));
        assert!(run.rejections().keys().all(|k| k.len() <= MAX_REASON_LEN));
        let by = run.blocked_by();
        assert_eq!(by["shelf"], 31);
        assert_eq!(by[OTHERS], 1000 - 31 + 3 + 2);
        assert!(run.summary().contains("blocked by: "), "{}", run.summary());
    }
}
