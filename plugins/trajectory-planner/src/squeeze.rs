//! The grasp's squeeze as the trajectory's `command`.
//!
//! What: [`targets`] checks the request's `grasp.squeeze` against the hand (each
//! entry an independent hand joint, named once, finite numbers, its `target`
//! within the joint's limits); [`apply`] gives the trajectory's last `close`
//! point and every `lift` (and `retreat`) point a `command`: the point's positions with each
//! squeezed joint at its target (a mimic joint of the trajectory at its leader's
//! target through the URDF's multiplier and offset, clamped into its limits).
//!
//! Why: a position-controlled hand presses with the planned forces only when it
//! is commanded beyond contact, and it must keep being commanded there while the
//! object is lifted, or it relaxes and drops it. The positions stay the physical
//! posture (the fingers are stopped by the object there), so every check of the
//! motion — the planner's, an independent checker's, the controller's limits —
//! keeps running on what the robot really does; only the command differs.
//!
//! ```
//! use tsukami_msgs::motion::{JointTrajectory, TrajectoryPoint};
//! use tsukami_trajectory_planner::squeeze::apply_overrides;
//! let point = |time: f64, q: f64, phase: &str| TrajectoryPoint {
//!     time, positions: vec![0.0, q], velocities: vec![], phase: phase.into(), command: vec![],
//! };
//! let mut t = JointTrajectory {
//!     joint_names: vec!["arm".into(), "finger".into()],
//!     points: vec![point(0.0, 0.0, "close"), point(1.0, 0.5, "close"), point(1.5, 0.5, "lift")],
//! };
//! apply_overrides(&mut t, &[(1, 0.7)]);
//! assert!(t.points[0].command.is_empty());
//! assert_eq!(t.points[1].command, vec![0.0, 0.7]);
//! assert_eq!(t.points[2].command, vec![0.0, 0.7]);
//! ```

use tsukami_body::model::{JointId, RobotModel};
use tsukami_msgs::motion::JointTrajectory;
use tsukami_msgs::planner::JointSqueeze;

use crate::error::MotionError;

/// How far a target may be outside its joint's limits and count as on them
/// (rounding); it is clamped onto them.
const LIMIT_SLACK: f64 = 1e-6;

/// The squeezed joints and their targets, checked: each entry of `squeeze`
/// (the request's `grasp.squeeze`) names one of `hand`'s independent joints
/// once, its numbers are finite and its target within the joint's limits.
pub fn targets(
    model: &RobotModel,
    hand: &[JointId],
    squeeze: &[JointSqueeze],
) -> Result<Vec<(JointId, f64)>, MotionError> {
    let mut out: Vec<(JointId, f64)> = Vec::with_capacity(squeeze.len());
    for (i, s) in squeeze.iter().enumerate() {
        let field = format!("grasp.squeeze[{i}]");
        let j = hand_joint(model, hand, &s.joint, &field)?;
        if out.iter().any(|&(k, _)| k == j) {
            return Err(MotionError::invalid(
                format!("{field}.joint"),
                format!("joint `{}` is squeezed twice", s.joint),
            ));
        }
        let numbers = [
            ("position", s.position),
            ("torque", s.torque),
            ("stiffness", s.stiffness),
            ("target", s.target),
        ];
        if let Some((name, v)) = numbers.into_iter().find(|(_, v)| !v.is_finite()) {
            return Err(MotionError::invalid(
                format!("{field}.{name}"),
                format!("{v} (joint `{}`) is not a finite number", s.joint),
            ));
        }
        let lim = model.joints[j].limits;
        if s.target < lim.lower - LIMIT_SLACK || s.target > lim.upper + LIMIT_SLACK {
            return Err(MotionError::invalid(
                format!("{field}.target"),
                format!(
                    "{} is outside the limits [{}, {}] of joint `{}`",
                    s.target, lim.lower, lim.upper, s.joint
                ),
            ));
        }
        out.push((j, s.target.clamp(lim.lower, lim.upper)));
    }
    Ok(out)
}

/// The id of `name` when it is one of `hand`'s joints; else why not, naming it.
fn hand_joint(
    model: &RobotModel,
    hand: &[JointId],
    name: &str,
    field: &str,
) -> Result<JointId, MotionError> {
    let field = format!("{field}.joint");
    let Ok(j) = model.joint_id(name) else {
        return Err(MotionError::invalid(
            field,
            format!("robot `{}` has no joint `{name}`", model.name),
        ));
    };
    if hand.contains(&j) {
        return Ok(j);
    }
    let why = match &model.joints[j].mimic {
        Some(m) => format!(
            "joint `{name}` mimics `{}`; squeeze `{}` (its mimics follow it)",
            m.joint_name, model.joints[m.master].name
        ),
        None => format!("joint `{name}` is not one of the hand's independent joints"),
    };
    Err(MotionError::invalid(field, why))
}

/// Where the squeeze changes the command: (index in `joints`, commanded value)
/// for each squeezed joint of `joints` and each mimic of one (its leader's
/// target through the multiplier and offset, clamped into its limits).
pub fn overrides(
    model: &RobotModel,
    joints: &[JointId],
    targets: &[(JointId, f64)],
) -> Vec<(usize, f64)> {
    let target_of = |j: JointId| targets.iter().find(|&&(k, _)| k == j).map(|&(_, t)| t);
    joints
        .iter()
        .enumerate()
        .filter_map(|(i, &j)| {
            let joint = &model.joints[j];
            let value = match &joint.mimic {
                None => target_of(j)?,
                Some(m) => {
                    let t = target_of(m.master)?;
                    (m.master_multiplier * t + m.master_offset)
                        .clamp(joint.limits.lower, joint.limits.upper)
                }
            };
            Some((i, value))
        })
        .collect()
}

/// Gives the last `close` point and every `lift` point of `trajectory` a
/// `command`: its positions with `overrides` (index, value) written over them.
/// Nothing changes when `overrides` is empty.
pub fn apply_overrides(trajectory: &mut JointTrajectory, overrides: &[(usize, f64)]) {
    if overrides.is_empty() {
        return;
    }
    let last_close = trajectory.points.iter().rposition(|p| p.phase == "close");
    for (k, p) in trajectory.points.iter_mut().enumerate() {
        if Some(k) != last_close && p.phase != "lift" && p.phase != "retreat" {
            continue;
        }
        p.command.clone_from(&p.positions);
        for &(i, v) in overrides {
            p.command[i] = v;
        }
    }
}

/// [`apply_overrides`] of the squeeze `targets` on `trajectory`, whose joints
/// are `joints`.
pub fn apply(
    model: &RobotModel,
    joints: &[JointId],
    targets: &[(JointId, f64)],
    trajectory: &mut JointTrajectory,
) {
    apply_overrides(trajectory, &overrides(model, joints, targets));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An arm joint, a finger joint `f1` ([0, 1.5]) and `f2` mimicking it
    /// (2 × f1 + 0.1, limited to [0, 2]).
    fn model() -> RobotModel {
        let joint = |name: &str, parent: &str, child: &str, upper: f64, mimic: &str| {
            format!(
                r#"<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>
                <axis xyz="0 0 1"/><limit lower="0" upper="{upper}" effort="1" velocity="1"/>{mimic}</joint>"#
            )
        };
        let urdf = format!(
            r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>{}{}{}</robot>"#,
            joint("arm", "a", "b", 1.0, ""),
            joint("f1", "b", "c", 1.5, ""),
            joint(
                "f2",
                "c",
                "d",
                2.0,
                r#"<mimic joint="f1" multiplier="2" offset="0.1"/>"#
            ),
        );
        RobotModel::from_urdf_str(&urdf, ".".as_ref()).unwrap()
    }

    fn entry(joint: &str, target: f64) -> JointSqueeze {
        JointSqueeze {
            joint: joint.into(),
            position: 0.5,
            torque: 0.2,
            stiffness: 5.0,
            target,
        }
    }

    fn refused(squeeze: &[JointSqueeze]) -> (String, String) {
        let m = model();
        let hand = [m.joint_id("f1").unwrap()];
        match targets(&m, &hand, squeeze) {
            Err(MotionError::Invalid { field, message }) => (field, message),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn bad_entries_name_the_field_and_the_joint() {
        let (field, message) = refused(&[entry("f1", 0.6), entry("nope", 0.6)]);
        assert_eq!(field, "grasp.squeeze[1].joint");
        assert!(message.contains("no joint `nope`"), "{message}");
        let (field, message) = refused(&[entry("arm", 0.6)]);
        assert_eq!(field, "grasp.squeeze[0].joint");
        assert!(
            message.contains("`arm` is not one of the hand's"),
            "{message}"
        );
        let (_, message) = refused(&[entry("f2", 0.6)]);
        assert!(message.contains("mimics `f1`"), "{message}");
        let (field, message) = refused(&[entry("f1", 0.6), entry("f1", 0.7)]);
        assert_eq!(field, "grasp.squeeze[1].joint");
        assert!(message.contains("twice"), "{message}");
        let mut nan = entry("f1", 0.6);
        nan.torque = f64::NAN;
        let (field, message) = refused(&[nan]);
        assert_eq!(field, "grasp.squeeze[0].torque");
        assert!(message.contains("not a finite number"), "{message}");
        let (field, message) = refused(&[entry("f1", f64::INFINITY)]);
        assert_eq!(field, "grasp.squeeze[0].target");
        assert!(message.contains("not a finite number"), "{message}");
        let (field, message) = refused(&[entry("f1", 1.6)]);
        assert_eq!(field, "grasp.squeeze[0].target");
        assert!(
            message.contains("outside the limits [0, 1.5] of joint `f1`"),
            "{message}"
        );
    }

    #[test]
    fn mimics_follow_their_leader_within_their_limits() {
        let m = model();
        let ids: Vec<JointId> = ["arm", "f1", "f2"]
            .iter()
            .map(|n| m.joint_id(n).unwrap())
            .collect();
        let t = targets(&m, &ids[1..2], &[entry("f1", 0.6)]).unwrap();
        assert_eq!(t, vec![(ids[1], 0.6)]);
        let o = overrides(&m, &ids, &t);
        assert_eq!(o.len(), 2);
        assert_eq!(o[0], (1, 0.6));
        assert_eq!(o[1].0, 2);
        assert!((o[1].1 - 1.3).abs() < 1e-12, "{o:?}");
        // 2 × 1.5 + 0.1 is over f2's upper limit 2: clamped onto it.
        let t = targets(&m, &ids[1..2], &[entry("f1", 1.5)]).unwrap();
        assert_eq!(overrides(&m, &ids, &t)[1], (2, 2.0));
        // A trajectory without the mimic: only the leader.
        assert_eq!(overrides(&m, &ids[..2], &t), vec![(1, 1.5)]);
    }
}
