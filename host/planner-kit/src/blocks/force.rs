//! The forces a hand can make: the largest normal force a finger can press
//! with (`τ = Jᵀ f`), and the joint torque limits of a whole contact set
//! ([`hand_torques`]) that the hold test of `crate::verify` applies.
//!
//! ```
//! // A finger whose Jacobian is missing presses with nothing: 0 N, not the cap.
//! # use tsukami_planner_kit::blocks::force::cap;
//! assert_eq!(cap(None, 100.0), 0.0);
//! assert_eq!(cap(Some(250.0), 100.0), 100.0);
//! ```

use nalgebra::{DVector, Matrix3xX, Point3, Vector3};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::model::{JointId, LinkId, RobotModel};
use tsukami_grasp::finger_force::max_finger_force;
use tsukami_grasp::joint_torques::JointTorques;

/// The force credited to a finger: its computed limit capped at `max`, and 0
/// when it could not be computed (the one rule for every planner).
pub fn cap(force: Option<f64>, max: f64) -> f64 {
    force
        .filter(|f| f.is_finite() && *f > 0.0)
        .map_or(0.0, |f| f.min(max))
}

/// The largest normal force `joints` can apply at `point` (world) on `link`
/// along `normal` (into the object), from their efforts and the translational
/// Jacobian, capped at `max` (N); 0 when it cannot be computed.
pub fn finger_force(
    model: &RobotModel,
    fk: &FkState,
    joints: &[JointId],
    link: LinkId,
    point: &Point3<f64>,
    normal: &Vector3<f64>,
    max: f64,
) -> f64 {
    let Ok(sel) = JointSelection::new(model, joints) else {
        return 0.0;
    };
    let local = fk.pose(link).inverse() * point;
    let j6 = model.jacobian(fk, link, &local, &sel);
    let j = Matrix3xX::from_fn(sel.len(), |r, k| j6[(r, k)]);
    let efforts = DVector::from_iterator(
        sel.len(),
        sel.joints
            .iter()
            .map(|&jid| model.joints[jid].limits.effort),
    );
    cap(
        max_finger_force(&j, &efforts, normal).ok().map(|f| f.force),
        max,
    )
}

/// The torque limits of a contact set at posture `fk`: per contact
/// `(link, world point)`, its translational Jacobian over the hand's
/// independent joints `joints` (mimic joints folded into their leaders, the
/// columns of joints not above the link zero: a palm contact loads none),
/// and the joints' efforts. `None` when `joints` is not a valid selection.
pub fn hand_torques(
    model: &RobotModel,
    fk: &FkState,
    joints: &[JointId],
    contacts: &[(LinkId, Point3<f64>)],
) -> Option<JointTorques> {
    let sel = JointSelection::new(model, joints).ok()?;
    let jacobians = contacts
        .iter()
        .map(|(link, point)| {
            let local = fk.pose(*link).inverse() * point;
            let j6 = model.jacobian(fk, *link, &local, &sel);
            Matrix3xX::from_fn(sel.len(), |r, k| j6[(r, k)])
        })
        .collect();
    let efforts = sel
        .joints
        .iter()
        .map(|&j| model.joints[j].limits.effort)
        .collect();
    JointTorques::new(jacobians, efforts).ok()
}
