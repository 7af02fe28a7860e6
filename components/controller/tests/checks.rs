//! The controller's checks and execution on the project's humanoid, period by
//! period, without a bus: what is refused (with its reason), and that a run follows
//! the trajectory at every sample time.

use std::path::Path;
use tsukami_controller::{Executor, JointTable};
use tsukami_msgs::controller::ExecutionOutcome;
use tsukami_msgs::motion::{JointTrajectory, TrajectoryPoint};

fn humanoid() -> JointTable {
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
    JointTable::load("tsukami_humanoid", &models).expect("the humanoid loads")
}

fn point(time: f64, positions: &[f64]) -> TrajectoryPoint {
    TrajectoryPoint {
        time,
        positions: positions.to_vec(),
        velocities: vec![],
        phase: String::new(),
        command: vec![],
    }
}

fn trajectory(joints: &[&str], points: Vec<TrajectoryPoint>) -> JointTrajectory {
    JointTrajectory {
        joint_names: joints.iter().map(|j| j.to_string()).collect(),
        points,
    }
}

/// Rest pose of the humanoid at 100 Hz.
fn executor() -> Executor {
    Executor::new(humanoid(), 100.0, None).unwrap()
}

fn refused(traj: &JointTrajectory) -> String {
    let mut ex = executor();
    let before = ex.state();
    let reason = ex.start(traj, 0.01).expect_err("must be refused");
    assert_eq!(ex.state(), before, "a refused trajectory changed the state");
    assert!(!ex.is_running());
    reason
}

#[test]
fn limit_violations_are_refused_with_their_reason() {
    // r_elbow is limited to [-2.6, 0].
    let reason = refused(&trajectory(
        &["r_elbow"],
        vec![point(0.0, &[0.0]), point(2.0, &[0.3])],
    ));
    assert!(
        reason.contains("r_elbow") && reason.contains("outside its limits"),
        "{reason}"
    );
    // 3 rad/s at most: 1.5 rad in 0.4 s is 3.75 rad/s.
    let reason = refused(&trajectory(
        &["r_elbow"],
        vec![point(0.0, &[0.0]), point(0.4, &[-1.5])],
    ));
    assert!(
        reason.contains("r_elbow") && reason.contains("velocity limit 3"),
        "{reason}"
    );
    // Within the limits at both waypoints, but the cubic overshoots the upper limit 0.
    let mut overshoot = trajectory(&["r_elbow"], vec![point(0.0, &[0.0]), point(1.0, &[-0.1])]);
    overshoot.points[0].velocities = vec![1.0];
    overshoot.points[1].velocities = vec![0.0];
    let reason = refused(&overshoot);
    assert!(reason.contains("would pass"), "{reason}");
}

#[test]
fn bad_times_joints_and_starts_are_refused() {
    let times = refused(&trajectory(
        &["r_elbow"],
        vec![point(0.0, &[0.0]), point(1.0, &[-0.5]), point(1.0, &[-0.6])],
    ));
    assert!(
        times.contains("point 2") && times.contains("strictly increase"),
        "{times}"
    );
    let unknown = refused(&trajectory(
        &["r_elbow", "l_elbow"],
        vec![point(0.0, &[0.0, 0.0]), point(1.0, &[-0.5, 0.0])],
    ));
    assert!(unknown.contains("unknown joint `l_elbow`"), "{unknown}");
    let mimic = refused(&trajectory(
        &["r_index_j4"],
        vec![point(0.0, &[0.0]), point(1.0, &[0.5])],
    ));
    assert!(mimic.contains("mimics `r_index_j3`"), "{mimic}");
    let far = refused(&trajectory(
        &["r_shoulder_pitch"],
        vec![point(0.0, &[-0.5]), point(1.0, &[-0.6])],
    ));
    assert!(
        far.contains("starts at -0.5") && far.contains("tolerance"),
        "{far}"
    );
    let late = refused(&trajectory(
        &["r_elbow"],
        vec![point(0.5, &[0.0]), point(1.0, &[-0.5])],
    ));
    assert!(late.contains("time must be 0"), "{late}");
    let nan = refused(&trajectory(
        &["r_elbow"],
        vec![point(0.0, &[0.0]), point(1.0, &[f64::NAN])],
    ));
    assert!(nan.contains("not a finite number"), "{nan}");
    let short = refused(&trajectory(&["r_elbow"], vec![point(0.0, &[0.0])]));
    assert!(short.contains("at least 2 points"), "{short}");
}

/// Linear interpolation written out independently of the controller's segments.
fn expected_linear(points: &[(f64, f64)], t: f64) -> f64 {
    for pair in points.windows(2) {
        let ((t0, q0), (t1, q1)) = (pair[0], pair[1]);
        if t <= t1 {
            return q0 + (q1 - q0) * (t - t0) / (t1 - t0);
        }
    }
    points.last().unwrap().1
}

#[test]
fn a_run_follows_the_trajectory_at_every_sample_time() {
    let mut ex = executor();
    let elbow = [(0.0, 0.0), (0.35, -0.6), (1.005, -1.2), (1.5, -1.0)];
    let wrist = [(0.0, 0.0), (0.35, 0.1), (1.005, 0.5), (1.5, 0.5)];
    let points = (0..4)
        .map(|k| point(elbow[k].0, &[elbow[k].1, wrist[k].1]))
        .collect();
    let traj = trajectory(&["r_elbow", "r_wrist_yaw"], points);
    ex.start(&traj, 0.01).unwrap();
    let (ie, iw) = (index(&ex, "r_elbow"), index(&ex, "r_wrist_yaw"));
    let mut samples = 0;
    let outcome = loop {
        let ended = ex.step();
        let state = ex.state();
        let t = state.trajectory_time.unwrap();
        samples += 1;
        assert!(
            (t - (samples as f64 * 0.01).min(1.5)).abs() < 1e-12,
            "t = {t}"
        );
        assert!((state.positions[ie] - expected_linear(&elbow, t)).abs() < 1e-6);
        assert!((state.positions[iw] - expected_linear(&wrist, t)).abs() < 1e-6);
        if let Some(outcome) = ended {
            break outcome;
        }
    };
    assert_eq!(outcome, ExecutionOutcome::Done);
    assert_eq!(samples, 150, "1.5 s at 100 Hz");
    assert_eq!(ex.state().status, "done");
    // Only the commanded joints moved.
    let rest = humanoid().rest_positions();
    for (i, (&q, &r)) in ex.positions().iter().zip(&rest).enumerate() {
        if i != ie && i != iw {
            assert_eq!(q, r);
        }
    }
}

#[test]
fn hermite_runs_follow_the_cubic() {
    let mut ex = executor();
    let mut traj = trajectory(&["r_elbow"], vec![point(0.0, &[0.0]), point(1.0, &[-1.0])]);
    traj.points[0].velocities = vec![0.0];
    traj.points[1].velocities = vec![0.0];
    ex.start(&traj, 0.01).unwrap();
    let ie = index(&ex, "r_elbow");
    while ex.step().is_none() {
        let s = ex.state().trajectory_time.unwrap();
        // From rest to rest: q = -(3 s^2 - 2 s^3), q' = -(6 s - 6 s^2).
        assert!((ex.positions()[ie] + 3.0 * s * s - 2.0 * s * s * s).abs() < 1e-6);
        assert!((ex.state().velocities[ie] + 6.0 * s - 6.0 * s * s).abs() < 1e-6);
    }
    assert!((ex.positions()[ie] + 1.0).abs() < 1e-12);
}

#[test]
fn the_state_is_held_between_trajectories() {
    let mut ex = executor();
    let first = trajectory(&["r_elbow"], vec![point(0.0, &[0.0]), point(0.5, &[-1.0])]);
    ex.start(&first, 0.01).unwrap();
    while ex.step().is_none() {}
    for _ in 0..10 {
        ex.step(); // idle periods: nothing moves
    }
    assert_eq!(ex.positions()[index(&ex, "r_elbow")], -1.0);
    // Starting again from 0 is now far from the state; continuing from -1 is fine.
    let reason = ex.start(&first, 0.01).unwrap_err();
    assert!(reason.contains("the robot is at -1"), "{reason}");
    let second = trajectory(&["r_elbow"], vec![point(0.0, &[-1.0]), point(0.5, &[-0.5])]);
    ex.start(&second, 0.01).unwrap();
    assert!(ex.start(&second, 0.01).unwrap_err().contains("busy"));
    while ex.step().is_none() {}
    assert_eq!(ex.positions()[index(&ex, "r_elbow")], -0.5);
}

#[test]
fn cancel_ends_the_run_in_one_period_where_it_is() {
    let mut ex = executor();
    let traj = trajectory(&["r_elbow"], vec![point(0.0, &[0.0]), point(1.0, &[-2.0])]);
    ex.start(&traj, 0.01).unwrap();
    for _ in 0..30 {
        assert!(ex.step().is_none());
    }
    let (tick, q) = (ex.tick(), ex.positions()[index(&ex, "r_elbow")]);
    assert_eq!(ex.cancel(), Some(ExecutionOutcome::Cancelled));
    assert_eq!(ex.tick(), tick + 1);
    assert_eq!(ex.positions()[index(&ex, "r_elbow")], q);
    assert!((q + 0.6).abs() < 1e-12, "{q}");
    assert_eq!(ex.state().status, "cancelled");
    assert!(ex.state().velocities.iter().all(|&v| v == 0.0));
    assert_eq!(ex.cancel(), None, "nothing left to cancel");
}

fn index(ex: &Executor, joint: &str) -> usize {
    ex.table().names().iter().position(|n| n == joint).unwrap()
}

/// `r_index_j2` closes from 0 to 0.8 (contact) over [0, 1] s and is commanded
/// to 1.1 (the squeeze) from then on; the lift point holds it.
fn squeeze_trajectory() -> JointTrajectory {
    let mut t = trajectory(
        &["r_elbow", "r_index_j2"],
        vec![
            point(0.0, &[0.0, 0.0]),
            point(0.5, &[0.0, 0.4]),
            point(1.0, &[0.0, 0.8]),
            point(1.5, &[-0.2, 0.8]),
        ],
    );
    t.points[2].command = vec![0.0, 1.1];
    t.points[3].command = vec![-0.2, 1.1];
    t
}

/// Asserts that the refusal of `t` says every one of `parts`.
fn refused_saying(t: &JointTrajectory, parts: &[&str]) {
    let reason = refused(t);
    assert!(parts.iter().all(|p| reason.contains(p)), "{reason}");
}

#[test]
fn bad_commands_are_refused_naming_the_point_and_joint() {
    let mut t = squeeze_trajectory();
    t.points[2].command = vec![1.1];
    refused_saying(&t, &["point 2", "1 commands for 2 joints"]);
    let mut t = squeeze_trajectory();
    t.points[3].command[1] = f64::INFINITY;
    refused_saying(&t, &["point 3", "r_index_j2", "not a finite number"]);
    // r_index_j2 is limited to [0, 1.6].
    let mut t = squeeze_trajectory();
    t.points[3].command[1] = 1.7;
    refused_saying(
        &t,
        &["point 3", "`r_index_j2` command 1.7", "outside its limits"],
    );
    // A cubic command path that overshoots the limit between valid points.
    let mut t = squeeze_trajectory();
    for (p, v) in t.points.iter_mut().zip([0.0, 0.0, 3.0, 0.0]) {
        p.velocities = vec![0.0, v];
    }
    t.points[2].command = vec![0.0, 1.6];
    t.points[3].command = vec![-0.2, 1.6];
    refused_saying(&t, &["points 2-3", "r_index_j2", "would be commanded"]);
}

#[test]
fn commands_are_interpolated_reported_and_held() {
    let mut ex = executor();
    let t = squeeze_trajectory();
    ex.start(&t, 0.01).unwrap();
    let (ie, ii) = (index(&ex, "r_elbow"), index(&ex, "r_index_j2"));
    // Commanded: the positions up to 0.5 s, then ramped from 0.4 to 1.1 by 1 s.
    let commanded = [(0.0, 0.0), (0.5, 0.4), (1.0, 1.1), (1.5, 1.1)];
    let finger = [(0.0, 0.0), (0.5, 0.4), (1.0, 0.8), (1.5, 0.8)];
    let elbow = [(0.0, 0.0), (1.0, 0.0), (1.5, -0.2)];
    loop {
        let ended = ex.step();
        let state = ex.state();
        let s = state.trajectory_time.unwrap();
        assert!((state.positions[ii] - expected_linear(&finger, s)).abs() < 1e-9);
        assert!((state.commanded[ii] - expected_linear(&commanded, s)).abs() < 1e-9);
        assert!((state.commanded[ie] - expected_linear(&elbow, s)).abs() < 1e-9);
        assert_eq!(state.commanded[ie], state.positions[ie], "t = {s}");
        if ended.is_some() {
            break;
        }
    }
    for _ in 0..5 {
        ex.step(); // idle: the squeeze stays commanded
    }
    let state = ex.state();
    assert_eq!(state.status, "done");
    assert_eq!((state.positions[ii], state.commanded[ii]), (0.8, 1.1));
    // Every other joint is commanded where it is.
    for (i, (q, c)) in state.positions.iter().zip(&state.commanded).enumerate() {
        if i != ii {
            assert_eq!(q, c, "joint {i}");
        }
    }
    // The next trajectory starts from the positions, and commands its own.
    let release = trajectory(
        &["r_index_j2"],
        vec![point(0.0, &[0.8]), point(0.5, &[0.0])],
    );
    ex.start(&release, 0.01).unwrap();
    while ex.step().is_none() {}
    assert_eq!(ex.commanded()[ii], 0.0);
}

#[test]
fn without_commands_the_positions_are_commanded() {
    let mut ex = executor();
    assert_eq!(ex.state().commanded, ex.state().positions);
    let mut t = squeeze_trajectory();
    t.points.iter_mut().for_each(|p| p.command.clear());
    ex.start(&t, 0.01).unwrap();
    while ex.step().is_none() {
        assert_eq!(ex.state().commanded, ex.state().positions);
    }
    assert_eq!(ex.state().commanded, ex.state().positions);
}
