//! The controller's state and its control periods, with no bus and no clock.
//!
//! What: [`Executor`] — the joint state the controller holds, the trajectory it is
//! running, and [`Executor::step`], one control period: the tick advances by one and
//! the running trajectory is sampled at `(tick − start) · dt` from its start.
//!
//! Why: what the robot does is decided here, deterministically, by counting
//! periods; the bus node ([`crate::node`]) only paces the periods (real time or
//! faster) and carries requests and states. Tests drive it period by period.
//!
//! How: a run starts at the current tick (its time 0 is the state already held); each
//! step samples the [`Plan`]; the step that reaches the last point ends the run with
//! [`ExecutionOutcome::Done`]. [`Executor::cancel`] is a period that ends it where it
//! is. Between runs
//! the state is held, so the next trajectory continues from where the last ended.
//!
//! Each period also samples what the trajectory commands ([`Plan::sample_command`]:
//! its points' `command`, else their positions) into the state's `commanded`;
//! after a run it holds, so a squeeze applied at the end of `close` stays
//! commanded until the next trajectory (whose points command their own).
//!
//! ```
//! use tsukami_controller::{executor::Executor, joints::JointTable};
//! use tsukami_msgs::motion::{JointTrajectory, TrajectoryPoint};
//! let urdf = r#"<robot name="r"><link name="a"/><link name="b"/>
//!   <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
//!   <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#;
//! let table = JointTable::from_model(&tsukami_body::RobotModel::from_urdf_str(urdf, ".".as_ref()).unwrap());
//! let mut ex = Executor::new(table, 100.0, None).unwrap();
//! let point = |time: f64, q: f64| TrajectoryPoint { time, positions: vec![q], velocities: vec![], phase: String::new(), command: vec![] };
//! ex.start(&JointTrajectory { joint_names: vec!["j".into()], points: vec![point(0.0, 0.0), point(0.5, 0.25)] }, 0.01).unwrap();
//! let mut steps = 0;
//! while ex.step().is_none() { steps += 1; }
//! assert_eq!(steps + 1, 50); // 0.5 s at 100 Hz
//! assert!((ex.positions()[0] - 0.25).abs() < 1e-12);
//! ```

use crate::joints::JointTable;
use crate::trajectory::Plan;
use tsukami_msgs::controller::{ControllerState, ExecutionOutcome};
use tsukami_msgs::motion::JointTrajectory;

/// The controller's state between and during runs.
#[derive(Debug, Clone)]
pub struct Executor {
    table: JointTable,
    dt: f64,
    tick: u64,
    positions: Vec<f64>,
    velocities: Vec<f64>,
    /// What is commanded, table order: the positions, or a running (or the
    /// last) trajectory's `command` where it squeezes.
    commanded: Vec<f64>,
    status: &'static str,
    run: Option<Run>,
    /// Time from the running trajectory's start of the last sample; kept for the
    /// period that ends a run, cleared on the next.
    trajectory_time: Option<f64>,
}

#[derive(Debug, Clone)]
struct Run {
    plan: Plan,
    start_tick: u64,
    /// Scratch for one sample, in plan order.
    q: Vec<f64>,
    v: Vec<f64>,
    c: Vec<f64>,
}

impl Executor {
    /// An idle controller at `initial` (table order; the rest pose when `None`),
    /// running `rate_hz` control periods per second of controller time.
    pub fn new(
        table: JointTable,
        rate_hz: f64,
        initial: Option<Vec<f64>>,
    ) -> Result<Executor, String> {
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(format!(
                "control rate {rate_hz} Hz is not a positive number"
            ));
        }
        let positions = match initial {
            Some(q) => check_initial(&table, q)?,
            None => table.rest_positions(),
        };
        Ok(Executor {
            dt: 1.0 / rate_hz,
            tick: 0,
            velocities: vec![0.0; positions.len()],
            commanded: positions.clone(),
            positions,
            status: "idle",
            run: None,
            trajectory_time: None,
            table,
        })
    }

    /// The control period, seconds.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Control periods so far.
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// The joint table.
    pub fn table(&self) -> &JointTable {
        &self.table
    }

    /// Current positions, table order.
    pub fn positions(&self) -> &[f64] {
        &self.positions
    }

    /// What is commanded now, table order (see [`ControllerState::commanded`]).
    pub fn commanded(&self) -> &[f64] {
        &self.commanded
    }

    /// Whether a trajectory is running.
    pub fn is_running(&self) -> bool {
        self.run.is_some()
    }

    /// Checks `trajectory` against the robot and the current state and, when it
    /// passes, starts it at the current tick. A refused trajectory changes nothing.
    pub fn start(&mut self, trajectory: &JointTrajectory, tolerance: f64) -> Result<(), String> {
        if self.run.is_some() {
            return Err("busy: a trajectory is running; stop it first (`controller/stop`)".into());
        }
        let plan = Plan::check(trajectory, &self.table, &self.positions, tolerance)?;
        self.begin(plan);
        Ok(())
    }

    /// Starts a plan already checked against the robot ([`Plan::for_robot`]) when
    /// nothing runs and its first point is within `tolerance` of the current state.
    /// A refused plan changes nothing.
    pub fn start_plan(&mut self, plan: Plan, tolerance: f64) -> Result<(), String> {
        if self.run.is_some() {
            return Err("busy: a trajectory is running; stop it first (`controller/stop`)".into());
        }
        plan.check_start(&self.table, &self.positions, tolerance)?;
        self.begin(plan);
        Ok(())
    }

    fn begin(&mut self, plan: Plan) {
        let n = plan.joints().len();
        self.run = Some(Run {
            plan,
            start_tick: self.tick,
            q: vec![0.0; n],
            v: vec![0.0; n],
            c: vec![0.0; n],
        });
        self.status = "executing";
        self.trajectory_time = Some(0.0);
    }

    /// One control period. Returns the outcome when this period ended the run.
    pub fn step(&mut self) -> Option<ExecutionOutcome> {
        self.tick += 1;
        let Some(run) = self.run.as_mut() else {
            self.trajectory_time = None;
            return None;
        };
        let t = ((self.tick - run.start_tick) as f64 * self.dt).min(run.plan.duration());
        let done = t >= run.plan.duration();
        run.plan.sample(t, &mut run.q, &mut run.v);
        run.plan.sample_command(t, &mut run.c);
        self.trajectory_time = Some(t);
        for (j, &i) in run.plan.joints().iter().enumerate() {
            self.positions[i] = run.q[j];
            self.velocities[i] = if done { 0.0 } else { run.v[j] };
            self.commanded[i] = run.c[j];
        }
        if done {
            return Some(self.finish(ExecutionOutcome::Done));
        }
        None
    }

    /// One control period in which the running trajectory ends where it is: the
    /// positions hold, the velocities go to zero. `None` (and no period) when idle.
    pub fn cancel(&mut self) -> Option<ExecutionOutcome> {
        self.run.as_ref()?;
        self.tick += 1;
        Some(self.finish(ExecutionOutcome::Cancelled))
    }

    /// Ends the running trajectory as a fault (e.g. the controller is shutting down).
    pub fn fault(&mut self) -> Option<ExecutionOutcome> {
        self.run.as_ref()?;
        Some(self.finish(ExecutionOutcome::Fault))
    }

    fn finish(&mut self, outcome: ExecutionOutcome) -> ExecutionOutcome {
        self.velocities.iter_mut().for_each(|v| *v = 0.0);
        self.status = match outcome {
            ExecutionOutcome::Done => "done",
            ExecutionOutcome::Cancelled => "cancelled",
            ExecutionOutcome::Fault => "error",
        };
        self.run = None;
        outcome
    }

    /// The state to publish.
    pub fn state(&self) -> ControllerState {
        ControllerState {
            joint_names: self.table.names(),
            positions: self.positions.clone(),
            commanded: self.commanded.clone(),
            status: self.status.to_owned(),
            time: self.tick as f64 * self.dt,
            velocities: self.velocities.clone(),
            tick: self.tick,
            trajectory_time: self.trajectory_time,
        }
    }
}

/// Checks an initial state: one finite value per joint, within the limits.
fn check_initial(table: &JointTable, q: Vec<f64>) -> Result<Vec<f64>, String> {
    if q.len() != table.len() {
        return Err(format!(
            "initial state has {} values for {} joints",
            q.len(),
            table.len()
        ));
    }
    for (i, &value) in q.iter().enumerate() {
        if !value.is_finite() || !table.within_position_limits(i, value) {
            let spec = table.joint(i);
            return Err(format!(
                "initial position {value} of joint `{}` is outside its limits [{}, {}]",
                spec.name, spec.lower, spec.upper
            ));
        }
    }
    Ok(q)
}
