//! How finely a straight joint-space segment must be checked for collision.
//!
//! What: [`SweepBound`] bounds how far any point of any link can travel when the
//! joints move from `a` to `b` along the straight segment, and
//! [`SweepBound::steps`] turns that into the number of checks that keep every
//! point's travel between two checks under a stated distance.
//!
//! Why: a collision check every few degrees can jump over a thin shelf board with
//! a long forearm. If no point moves more than `d` between checks, an obstacle
//! thicker than `d` cannot be crossed unseen: a point that passes through it
//! travels at least its thickness inside it, so at least one check finds it there.
//! The planner's default `d` is 5 mm, so a 1 cm obstacle is never skipped.
//!
//! How: a point at distance `r` from a revolute joint's axis moves `r·|Δq|` when
//! that joint turns by `Δq`, and a prismatic joint moves every point downstream by
//! `|Δq|`; by the triangle inequality a point's path length is at most
//! `Σ_j R_j |Δq_j|`, where `R_j` bounds the distance from joint `j` to any collision
//! geometry downstream of it, over all configurations: the lengths of the joint
//! offsets between them, the travel of prismatic joints between them, and each
//! link's geometry radius. An attached object (after the hand closes) adds its
//! radius to the hand link.
//!
//! ```
//! use tsukami_body::model::RobotModel;
//! use tsukami_planner_kit::motion_check::resolution::SweepBound;
//! let urdf = r#"<robot name="r">
//!   <link name="base"/>
//!   <link name="arm"><collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.1"/></geometry></collision></link>
//!   <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
//!     <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
//! </robot>"#;
//! let model = RobotModel::from_urdf_str(urdf, std::path::Path::new(".")).unwrap();
//! let bound = SweepBound::new(&model);
//! // The sphere's far side is 0.6 m from the axis: 0.1 rad moves it 6 cm.
//! assert!((bound.travel(&[0.0], &[0.1]) - 0.06).abs() < 1e-12);
//! assert_eq!(bound.steps(&[0.0], &[0.1], 0.005), 12);
//! ```

use tsukami_body::model::{Geometry, JointKind, LinkId, RobotModel};

/// Bounds on how far link points travel per unit of joint motion.
#[derive(Debug, Clone)]
pub struct SweepBound {
    /// Per joint: metres of travel per radian (revolute) or per metre (prismatic);
    /// 0 for fixed joints.
    per_unit: Vec<f64>,
}

/// The largest distance from a link's frame origin to any of its collision shapes.
pub fn link_radius(model: &RobotModel, link: LinkId) -> f64 {
    model.links[link]
        .collisions
        .iter()
        .map(|e| e.origin.translation.vector.norm() + geometry_radius(&e.geometry))
        .fold(0.0, f64::max)
}

/// The largest distance from a shape's own origin to any of its points.
pub fn geometry_radius(geometry: &Geometry) -> f64 {
    match geometry {
        Geometry::Box { size } => (size / 2.0).norm(),
        Geometry::Cylinder { radius, length } => radius.hypot(length / 2.0),
        Geometry::Capsule { radius, length } => radius + length / 2.0,
        Geometry::Sphere { radius } => *radius,
        Geometry::Mesh { mesh, .. } => mesh
            .vertices
            .iter()
            .map(|v| v.coords.norm())
            .fold(0.0, f64::max),
    }
}

impl SweepBound {
    /// The bound for `model`'s own links.
    pub fn new(model: &RobotModel) -> Self {
        Self::with_attached(model, &[])
    }

    /// The bound with extra radii on some links, e.g. a grasped object's radius
    /// (measured from the hand link's frame origin) on the hand link.
    pub fn with_attached(model: &RobotModel, attached: &[(LinkId, f64)]) -> Self {
        let n = model.links.len();
        let mut radius: Vec<f64> = (0..n).map(|l| link_radius(model, l)).collect();
        for &(link, r) in attached {
            radius[link] = radius[link].max(r);
        }
        // reach[l]: the farthest any geometry of l's subtree can be from l's frame
        // origin. Links are stored parents first, so walk them backwards.
        let mut reach = radius.clone();
        for l in (1..n).rev() {
            let Some(j) = model.links[l].parent_joint else {
                continue;
            };
            let joint = &model.joints[j];
            let mut offset = joint.origin.translation.vector.norm();
            if joint.kind == JointKind::Prismatic {
                offset += prismatic_travel(joint.limits.lower, joint.limits.upper);
            }
            let parent = joint.parent;
            reach[parent] = reach[parent].max(offset + reach[l]);
        }
        let per_unit = model
            .joints
            .iter()
            .map(|joint| match joint.kind {
                JointKind::Fixed => 0.0,
                JointKind::Prismatic => 1.0,
                // The joint frame is the child link's frame.
                JointKind::Revolute | JointKind::Continuous => reach[joint.child],
            })
            .collect();
        SweepBound { per_unit }
    }

    /// Upper bound on the path length of any link point along the straight
    /// segment from `a` to `b` (full joint vectors, mimic joints already applied).
    pub fn travel(&self, a: &[f64], b: &[f64]) -> f64 {
        self.per_unit
            .iter()
            .zip(a.iter().zip(b))
            .map(|(w, (x, y))| w * (y - x).abs())
            .sum()
    }

    /// How many equal steps split `a → b` so that no link point moves more than
    /// `max_travel` per step (at least 1).
    pub fn steps(&self, a: &[f64], b: &[f64], max_travel: f64) -> usize {
        let t = self.travel(a, b) / max_travel;
        if t.is_finite() {
            (t.ceil() as usize).max(1)
        } else {
            usize::MAX
        }
    }

    /// Metres of travel per unit of each joint's motion.
    pub fn per_unit(&self) -> &[f64] {
        &self.per_unit
    }
}

fn prismatic_travel(lower: f64, upper: f64) -> f64 {
    let m = lower.abs().max(upper.abs());
    if m.is_finite() {
        m
    } else {
        0.0
    }
}
