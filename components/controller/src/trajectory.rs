//! Checking a joint trajectory against the robot and turning it into a [`Plan`].
//!
//! What: [`Plan::check`] — everything `<ns>/controller/execute` refuses, each with a
//! reason naming the point and joint: no joints or too few points, unknown, mimic,
//! fixed or repeated joints, wrong lengths, non-finite numbers, a first time other
//! than 0, times that do not strictly increase, positions outside the limits
//! (anywhere along the interpolated path), speeds over the limits, and a start away
//! from the current state by more than the tolerance. A point's `command` (what is
//! commanded there when it differs from the physical `positions`: a squeeze) must
//! be empty or one finite value per joint, within the joint's limits along the
//! interpolated command path too; its speed is not limited: the command that
//! first appears at the end of `close` is a setpoint step of the squeeze, ramped
//! in over the segment that ends there (its positions, the fingers' motion up to
//! contact, are what the velocity limits apply to).
//!
//! Why: validate everything, then move: a refused trajectory leaves the robot and the
//! controller's state untouched.
//!
//! How: one pass per rule; the checked plan keeps the segments the executor samples
//! ([`crate::interpolate::Segment`]), so what was checked is exactly what runs. The
//! commands are interpolated as the positions are (same kind of segment, the
//! points' velocities); a point with no `command` commands its positions.
//!
//! ```
//! use tsukami_controller::{joints::JointTable, trajectory::Plan};
//! use tsukami_msgs::motion::{JointTrajectory, TrajectoryPoint};
//! let urdf = r#"<robot name="r"><link name="a"/><link name="b"/>
//!   <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
//!   <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#;
//! let table = JointTable::from_model(&tsukami_body::RobotModel::from_urdf_str(urdf, ".".as_ref()).unwrap());
//! let point = |time: f64, q: f64| TrajectoryPoint { time, positions: vec![q], velocities: vec![], phase: String::new(), command: vec![] };
//! let too_fast = JointTrajectory { joint_names: vec!["j".into()], points: vec![point(0.0, 0.0), point(0.5, 1.0)] };
//! let reason = Plan::check(&too_fast, &table, &[0.0], 0.01).unwrap_err();
//! assert!(reason.contains("velocity"), "{reason}");
//! let ok = JointTrajectory { joint_names: vec!["j".into()], points: vec![point(0.0, 0.0), point(1.0, 1.0)] };
//! assert_eq!(Plan::check(&ok, &table, &[0.0], 0.01).unwrap().duration(), 1.0);
//! ```

use crate::interpolate::Segment;
use crate::joints::{JointLookup, JointTable, LIMIT_SLACK};
use tsukami_msgs::motion::{JointTrajectory, TrajectoryPoint};

/// The most waypoints one trajectory may have.
pub const MAX_POINTS: usize = 100_000;
/// The longest trajectory, seconds.
pub const MAX_DURATION: f64 = 3600.0;

/// A checked trajectory: which table joints it drives, and their segments.
#[derive(Debug, Clone)]
pub struct Plan {
    joints: Vec<usize>,
    times: Vec<f64>,
    /// `segments[k][j]`: joint `j` between points `k` and `k + 1`.
    segments: Vec<Vec<Segment>>,
    /// The commanded path, the same way; `None` when no point has a `command`
    /// (the positions are the command).
    commands: Option<Vec<Vec<Segment>>>,
    start: Vec<f64>,
}

impl Plan {
    /// Checks `trajectory` for a robot with `table` at `current` (table order);
    /// `tolerance` is how far the first point may be from `current`.
    pub fn check(
        trajectory: &JointTrajectory,
        table: &JointTable,
        current: &[f64],
        tolerance: f64,
    ) -> Result<Plan, String> {
        let plan = Plan::for_robot(trajectory, table)?;
        plan.check_start(table, current, tolerance)?;
        Ok(plan)
    }

    /// The checks that need the robot model only, not its state: every rule of
    /// [`Plan::check`] but the start. The controller runs them off its control
    /// thread, so a flood of bad trajectories costs the control periods nothing.
    pub fn for_robot(trajectory: &JointTrajectory, table: &JointTable) -> Result<Plan, String> {
        let joints = resolve_joints(&trajectory.joint_names, table)?;
        check_points(trajectory)?;
        check_commands(trajectory)?;
        let plan = build(trajectory, joints);
        plan.check_limits(trajectory, table)?;
        Ok(plan)
    }

    /// The table indices of the joints this plan drives, in trajectory order.
    pub fn joints(&self) -> &[usize] {
        &self.joints
    }

    /// Duration, seconds (the last point's time).
    pub fn duration(&self) -> f64 {
        *self.times.last().unwrap_or(&0.0)
    }

    /// Positions and velocities of the plan's joints at `t` seconds from its start
    /// (clamped to `[0, duration]`).
    pub fn sample(&self, t: f64, positions: &mut [f64], velocities: &mut [f64]) {
        let Some((k, tau)) = self.segment_at(t) else {
            positions.copy_from_slice(&self.start);
            velocities.iter_mut().for_each(|v| *v = 0.0);
            return;
        };
        for (j, segment) in self.segments[k].iter().enumerate() {
            (positions[j], velocities[j]) = segment.at(tau);
        }
    }

    /// Whether any point has a `command`.
    pub fn has_commands(&self) -> bool {
        self.commands.is_some()
    }

    /// What is commanded to the plan's joints at `t` seconds from its start
    /// (clamped to `[0, duration]`): the interpolated `command`s, a point
    /// without one commanding its positions; the positions when no point has one.
    pub fn sample_command(&self, t: f64, command: &mut [f64]) {
        let Some((k, tau)) = self.segment_at(t) else {
            command.copy_from_slice(&self.start);
            return;
        };
        let row = self.commands.as_ref().unwrap_or(&self.segments);
        for (j, segment) in row[k].iter().enumerate() {
            command[j] = segment.at(tau).0;
        }
    }

    /// The segment sampled at `t` (the last one starting at or before it, `t`
    /// clamped to `[0, duration]`) and the time into it; `None` without segments.
    fn segment_at(&self, t: f64) -> Option<(usize, f64)> {
        if self.segments.is_empty() {
            return None;
        }
        let t = t.clamp(0.0, self.duration());
        let k = self
            .times
            .partition_point(|&tk| tk <= t)
            .saturating_sub(1)
            .min(self.segments.len() - 1);
        Some((k, t - self.times[k]))
    }

    fn check_limits(&self, trajectory: &JointTrajectory, table: &JointTable) -> Result<(), String> {
        for (k, point) in trajectory.points.iter().enumerate() {
            for (j, &i) in self.joints.iter().enumerate() {
                let spec = table.joint(i);
                within_limits(k, table, i, "position", point.positions[j])?;
                if let Some(&q) = point.command.get(j) {
                    within_limits(k, table, i, "command", q)?;
                }
                if let Some(&v) = point.velocities.get(j) {
                    if v.abs() > spec.velocity + LIMIT_SLACK {
                        return Err(format!(
                            "point {k}: joint `{}` velocity {v} is over its limit {}",
                            spec.name, spec.velocity
                        ));
                    }
                }
            }
        }
        for (k, segment) in self.segments.iter().enumerate() {
            for (j, seg) in segment.iter().enumerate() {
                check_segment(k, seg, table.joint(self.joints[j]))?;
            }
        }
        for (k, segment) in self.commands.iter().flatten().enumerate() {
            for (j, seg) in segment.iter().enumerate() {
                check_range(k, seg, table.joint(self.joints[j]), "be commanded")?;
            }
        }
        Ok(())
    }

    /// Whether the plan's first point is within `tolerance` of `current` (table
    /// order) for every joint it drives.
    pub fn check_start(
        &self,
        table: &JointTable,
        current: &[f64],
        tolerance: f64,
    ) -> Result<(), String> {
        let first = &self.start;
        for (j, &i) in self.joints.iter().enumerate() {
            let gap = (first[j] - current[i]).abs();
            if gap > tolerance {
                return Err(format!(
                    "point 0: joint `{}` starts at {} but the robot is at {} (off by {gap:.6}, tolerance {tolerance})",
                    table.joint(i).name,
                    first[j],
                    current[i]
                ));
            }
        }
        Ok(())
    }
}

fn check_segment(k: usize, seg: &Segment, spec: &crate::joints::JointSpec) -> Result<(), String> {
    let speed = seg.max_speed();
    if speed > spec.velocity + LIMIT_SLACK {
        return Err(format!(
            "points {k}-{}: joint `{}` would move at {speed:.6}, over its velocity limit {} (slow the trajectory down)",
            k + 1,
            spec.name,
            spec.velocity
        ));
    }
    check_range(k, seg, spec, "pass")
}

/// Whether segment `k` stays within the joint's limits; `what` the segment does
/// (`pass`: the positions, `be commanded`: the commands).
fn check_range(
    k: usize,
    seg: &Segment,
    spec: &crate::joints::JointSpec,
    what: &str,
) -> Result<(), String> {
    let (lo, hi) = seg.position_range();
    if lo < spec.lower - LIMIT_SLACK || hi > spec.upper + LIMIT_SLACK {
        return Err(format!(
            "points {k}-{}: joint `{}` would {what} {:.6}, outside its limits [{}, {}]",
            k + 1,
            spec.name,
            if lo < spec.lower { lo } else { hi },
            spec.lower,
            spec.upper
        ));
    }
    Ok(())
}

/// Whether point `k`'s `what` (`position`, `command`) `q` of table joint `i` is
/// within the joint's limits.
fn within_limits(k: usize, table: &JointTable, i: usize, what: &str, q: f64) -> Result<(), String> {
    if table.within_position_limits(i, q) {
        return Ok(());
    }
    let spec = table.joint(i);
    Err(format!(
        "point {k}: joint `{}` {what} {q} is outside its limits [{}, {}]",
        spec.name, spec.lower, spec.upper
    ))
}

/// The table index of every named joint, refusing unknown, mimic, fixed and
/// repeated names.
fn resolve_joints(names: &[String], table: &JointTable) -> Result<Vec<usize>, String> {
    if names.is_empty() {
        return Err("`joint_names` is empty".into());
    }
    let mut joints = Vec::with_capacity(names.len());
    for name in names {
        let i = match table.lookup(name) {
            JointLookup::Commandable(i) => i,
            JointLookup::Mimic(master) => {
                return Err(format!(
                    "joint `{name}` mimics `{master}` and cannot be commanded; command `{master}`"
                ))
            }
            JointLookup::Fixed => return Err(format!("joint `{name}` is fixed")),
            JointLookup::Unknown => {
                return Err(format!(
                    "unknown joint `{name}`: robot `{}` has no such joint",
                    table.robot()
                ))
            }
        };
        if joints.contains(&i) {
            return Err(format!("joint `{name}` is named twice"));
        }
        joints.push(i);
    }
    Ok(joints)
}

/// Shapes, numbers and times of the points.
fn check_points(trajectory: &JointTrajectory) -> Result<(), String> {
    let points = &trajectory.points;
    let n = trajectory.joint_names.len();
    if points.len() < 2 {
        return Err(format!(
            "a trajectory needs at least 2 points (the start and a goal), got {}",
            points.len()
        ));
    }
    if points.len() > MAX_POINTS {
        return Err(format!(
            "{} points is over the limit of {MAX_POINTS}",
            points.len()
        ));
    }
    let with_velocities = !points[0].velocities.is_empty();
    for (k, point) in points.iter().enumerate() {
        if point.positions.len() != n {
            return Err(format!(
                "point {k}: {} positions for {n} joints",
                point.positions.len()
            ));
        }
        if point.velocities.is_empty() == with_velocities {
            return Err(format!(
                "point {k}: velocities must be given for every point or for none"
            ));
        }
        if with_velocities && point.velocities.len() != n {
            return Err(format!(
                "point {k}: {} velocities for {n} joints",
                point.velocities.len()
            ));
        }
        if let Some(bad) = point
            .positions
            .iter()
            .chain(&point.velocities)
            .find(|v| !v.is_finite())
        {
            return Err(format!("point {k}: {bad} is not a finite number"));
        }
        check_time(k, point.time, (k > 0).then(|| points[k - 1].time))?;
    }
    Ok(())
}

/// Each point's `command`: empty, or one finite value per joint.
fn check_commands(trajectory: &JointTrajectory) -> Result<(), String> {
    let n = trajectory.joint_names.len();
    for (k, point) in trajectory.points.iter().enumerate() {
        if !point.command.is_empty() && point.command.len() != n {
            return Err(format!(
                "point {k}: {} commands for {n} joints (give one per joint, or none to command the positions)",
                point.command.len()
            ));
        }
        let bad = point.command.iter().position(|v| !v.is_finite());
        if let Some(j) = bad {
            return Err(format!(
                "point {k}: joint `{}` command {} is not a finite number",
                trajectory.joint_names[j], point.command[j]
            ));
        }
    }
    Ok(())
}

fn check_time(k: usize, time: f64, previous: Option<f64>) -> Result<(), String> {
    if !time.is_finite() {
        return Err(format!("point {k}: time {time} is not a finite number"));
    }
    match previous {
        None if time != 0.0 => Err(format!(
            "point 0: time must be 0 (the trajectory starts now), got {time}"
        )),
        Some(prev) if time <= prev => Err(format!(
            "point {k}: time {time} is not after point {}'s time {prev}; times must strictly increase",
            k - 1
        )),
        _ if time > MAX_DURATION => Err(format!(
            "point {k}: time {time} s is over the longest trajectory, {MAX_DURATION} s"
        )),
        _ => Ok(()),
    }
}

/// The segments of a trajectory whose points passed [`check_points`] and
/// [`check_commands`].
fn build(trajectory: &JointTrajectory, joints: Vec<usize>) -> Plan {
    let points = &trajectory.points;
    let n = joints.len();
    let commanded = points.iter().any(|p| !p.command.is_empty());
    Plan {
        segments: segments(points, n, |p| &p.positions),
        commands: commanded.then(|| segments(points, n, commanded_values)),
        joints,
        times: points.iter().map(|p| p.time).collect(),
        start: points[0].positions.clone(),
    }
}

/// What a point commands: its `command`, else its positions.
fn commanded_values(p: &TrajectoryPoint) -> &Vec<f64> {
    if p.command.is_empty() {
        &p.positions
    } else {
        &p.command
    }
}

/// `n` joints' segments between consecutive points through `values`: cubic
/// Hermite with the points' velocities when both give them, else linear.
fn segments(
    points: &[TrajectoryPoint],
    n: usize,
    values: impl Fn(&TrajectoryPoint) -> &Vec<f64>,
) -> Vec<Vec<Segment>> {
    points
        .windows(2)
        .map(|pair| {
            let (a, b) = (&pair[0], &pair[1]);
            let (qa, qb) = (values(a), values(b));
            let h = b.time - a.time;
            (0..n)
                .map(|j| match (a.velocities.get(j), b.velocities.get(j)) {
                    (Some(&v0), Some(&v1)) => Segment::hermite(qa[j], v0, qb[j], v1, h),
                    _ => Segment::linear(qa[j], qb[j], h),
                })
                .collect()
        })
        .collect()
}
