//! One plan's bookkeeping: stop checks, samples, rejections, progress, timing.
//!
//! What: [`Run`] is handed to `GraspPlanner::plan`. A planner calls
//! [`Run::sample`] once per sample (it counts the sample and checks the cancel
//! flag and, only when the request asked for one, the deadline),
//! [`Run::reject`] with a short reason when a sample fails, [`Run::phase`] when
//! it moves to another phase (which times the phases and publishes a progress
//! event), and [`Run::margin`] with each ellipsoid margin it computes.
//!
//! Why: the same counts, stop rules and progress events for every planner; the
//! kit turns them into the reply and into the message of a failed plan.
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
//! assert_eq!(run.samples(), 1);
//! assert!(run.summary().contains("ik 1"));
//! ```

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use tsukami_msgs::planner::{PhaseTiming, PlanPhase, ProgressEvent};

use crate::Stop;

/// The bookkeeping of one plan.
pub struct Run<'a> {
    cancel: &'a AtomicBool,
    deadline: Option<(Instant, u64)>,
    progress: &'a mut dyn FnMut(&ProgressEvent),
    start: Instant,
    samples: u32,
    rejections: BTreeMap<&'static str, u32>,
    best_margin: Option<f64>,
    timing: PhaseTiming,
    phase: (PlanPhase, Instant),
    grasp_type: Option<String>,
    joints_used: Vec<String>,
    tried: Vec<String>,
}

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
            best_margin: None,
            timing: PhaseTiming::default(),
            phase: (PlanPhase::Selection, start),
            grasp_type: None,
            joints_used: Vec::new(),
            tried: Vec::new(),
        }
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
    pub fn rejected(&mut self, why: &'static str, n: u32) {
        if n > 0 {
            *self.rejections.entry(why).or_default() += n;
        }
    }

    /// Samples drawn so far.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Records why a sample was rejected.
    pub fn reject(&mut self, why: &'static str) {
        *self.rejections.entry(why).or_default() += 1;
    }

    /// Rejection counts per reason.
    pub fn rejections(&self) -> &BTreeMap<&'static str, u32> {
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
        format!(
            "{} samples, best margin {}; rejections: {}",
            self.samples,
            self.best_margin
                .map_or("none".into(), |m| format!("{m:.3}")),
            if rejections.is_empty() {
                "none".into()
            } else {
                rejections.join(", ")
            }
        )
    }

    /// Ends the run: the phase times, total included, and the types tried.
    pub fn finish(mut self) -> (PhaseTiming, Vec<String>, u32) {
        self.phase(PlanPhase::Done, None, &[]);
        self.timing.total = ms(self.start.elapsed());
        (self.timing, self.tried, self.samples)
    }
}
