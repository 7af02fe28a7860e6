//! The hand: which fingers pinch, their pre-shapes, and closing them onto the
//! object with the body crate's distance query.
//!
//! What: [`Hand`] names the thumb and the two opposing fingers (index and
//! middle) of the project's humanoid hand, the links to keep clear of the
//! object, and a table of [`Preshape`]s — one reference pinch posture scaled
//! from open to closed, with the thumb-tip and finger-tip positions in the palm
//! frame and the gap between their pads. [`close_finger`] flexes one finger
//! from a pre-shape until one of its links touches the object.
//!
//! Why: an antipodal planner needs only two things from the hand: "which palm
//! pose puts the thumb tip on point A and the finger tips on point B", answered
//! by a pre-shape whose gap is a little wider than the object there, and
//! "where do the fingers really touch", answered by closing them (the paper's
//! section 3.5 closes the fingers the same way).
//!
//! How: [`Hand::new`] reads finger links and joints from the robot model by
//! name (`r_thumb_*`, `r_index_*`, `r_middle_*`, `r_ring_*`); a robot without
//! them is a model error naming the missing joint or link.

use nalgebra::{DVector, Matrix3xX, Point3, Vector3};
use tsukami_body::collision::{CollisionObject, RobotCollision};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::model::{Geometry, JointId, LinkId, RobotModel};
use tsukami_grasp::finger_force::max_finger_force;

/// Reference pinch posture (thumb opposed to index + middle), scaled by the
/// pre-shape parameter `s`; measured on the project's hand (see
/// `models/robots/tsukami_humanoid/grasp_types.toml`, `fingertip3`).
const PINCH_POSTURE: [(&str, f64); 5] = [
    ("r_index_j2", 0.9),
    ("r_middle_j2", 0.9),
    ("r_thumb_j2", 0.7),
    ("r_thumb_j3", 0.3),
    ("r_thumb_j4", 0.3),
];
/// Thumb rotation toward the fingers (kept at this value in every pre-shape).
const THUMB_OPPOSITION: (&str, f64) = ("r_thumb_j1", -0.5);
/// Pre-shape parameters tabulated: `s = k · PRESHAPE_STEP` for `k = 0..=PRESHAPE_COUNT`.
const PRESHAPE_STEP: f64 = 0.05;
const PRESHAPE_COUNT: usize = 40;
/// Largest normal force credited to one finger (N), whatever its Jacobian says.
pub const MAX_FINGER_FORCE: f64 = 20.0;

/// One finger: its links and joints.
#[derive(Debug, Clone)]
pub struct Finger {
    /// Short name (`thumb`, `index`, …).
    pub name: String,
    /// Its links, base to tip.
    pub links: Vec<LinkId>,
    /// Independent joints (abduction first), for force limits.
    pub joints: Vec<JointId>,
    /// Flexion joints closed by [`close_finger`].
    pub flex: Vec<JointId>,
    /// Centre of the fingertip pad in the distal link's frame.
    pub tip_point: Point3<f64>,
    /// Radius of the fingertip pad (m).
    pub tip_radius: f64,
}

impl Finger {
    fn new(model: &RobotModel, prefix: &str) -> Result<Self, String> {
        let links: Vec<LinkId> = (0..model.links.len())
            .filter(|&l| model.links[l].name.starts_with(&format!("{prefix}_l")))
            .collect();
        let joints: Vec<JointId> = (0..model.joints.len())
            .filter(|&j| {
                model.joints[j].name.starts_with(&format!("{prefix}_j"))
                    && model.joints[j].is_independent()
            })
            .collect();
        if links.is_empty() || joints.len() < 2 {
            return Err(format!(
                "robot `{}` has no finger `{prefix}` (links {prefix}_l*, joints {prefix}_j*)",
                model.name
            ));
        }
        let tip = *links.last().unwrap_or(&0);
        let (tip_point, tip_radius) = model.links[tip]
            .collisions
            .first()
            .map(|c| {
                let r = match c.geometry {
                    Geometry::Capsule { radius, .. } | Geometry::Sphere { radius } => radius,
                    _ => 0.008,
                };
                (Point3::from(c.origin.translation.vector), r)
            })
            .ok_or_else(|| format!("link `{}` has no collision geometry", model.links[tip].name))?;
        Ok(Self {
            name: prefix.trim_start_matches("r_").to_owned(),
            flex: joints[1..].to_vec(),
            links,
            joints,
            tip_point,
            tip_radius,
        })
    }

    /// The distal link.
    pub fn tip_link(&self) -> LinkId {
        *self.links.last().unwrap_or(&0)
    }
}

/// One pre-shape of the pinch family.
#[derive(Debug, Clone)]
pub struct Preshape {
    /// Scale of the reference posture (0 = open hand).
    pub s: f64,
    /// Hand joint values of this pre-shape.
    pub q: Vec<(JointId, f64)>,
    /// Thumb pad centre in the palm frame.
    pub thumb_tip: Point3<f64>,
    /// Midpoint of the index and middle pad centres in the palm frame.
    pub finger_tip: Point3<f64>,
    /// Free gap between the thumb pad and the finger pads (m).
    pub gap: f64,
}

/// The pinching hand.
#[derive(Debug, Clone)]
pub struct Hand {
    /// The opposing thumb.
    pub thumb: Finger,
    /// Index and middle fingers, side by side against the thumb.
    pub fingers: Vec<Finger>,
    /// The ring finger, kept straight below the object.
    pub idle: Finger,
    /// Pre-shapes, open first.
    pub preshapes: Vec<Preshape>,
}

impl Hand {
    /// Reads the fingers from `model` and tabulates the pre-shapes (palm frame).
    pub fn new(model: &RobotModel, palm: LinkId) -> Result<Self, String> {
        let thumb = Finger::new(model, "r_thumb")?;
        let fingers = vec![
            Finger::new(model, "r_index")?,
            Finger::new(model, "r_middle")?,
        ];
        let idle = Finger::new(model, "r_ring")?;
        let mut posture = Vec::new();
        for (name, v) in PINCH_POSTURE {
            posture.push((model.joint_id(name).map_err(|e| e.to_string())?, v));
        }
        let opposition = (
            model
                .joint_id(THUMB_OPPOSITION.0)
                .map_err(|e| e.to_string())?,
            THUMB_OPPOSITION.1,
        );
        let mut fk = FkState::new(model);
        let mut preshapes = Vec::new();
        for k in 0..=PRESHAPE_COUNT {
            let s = k as f64 * PRESHAPE_STEP;
            let mut q = model.rest_positions();
            let mut values = vec![opposition];
            for &(j, v) in &posture {
                let lim = model.joints[j].limits;
                values.push((j, (v * s).clamp(lim.lower, lim.upper)));
            }
            for &(j, v) in &values {
                q[j] = v;
            }
            model.apply_mimics(&mut q);
            model.forward_kinematics(&q, &mut fk);
            let to_palm = fk.pose(palm).inverse();
            let pad = |f: &Finger| to_palm * (fk.pose(f.tip_link()) * f.tip_point);
            let thumb_tip = pad(&thumb);
            let finger_tip = nalgebra::center(&pad(&fingers[0]), &pad(&fingers[1]));
            let gap = (finger_tip - thumb_tip).norm() - thumb.tip_radius - fingers[0].tip_radius;
            preshapes.push(Preshape {
                s,
                q: values,
                thumb_tip,
                finger_tip,
                gap,
            });
        }
        Ok(Self {
            thumb,
            fingers,
            idle,
            preshapes,
        })
    }

    /// The most closed pre-shape whose gap is at least `width` (the hand
    /// opens just enough); `None` when even the open hand is too narrow.
    pub fn preshape_for(&self, width: f64) -> Option<&Preshape> {
        self.preshapes
            .iter()
            .filter(|p| p.gap >= width)
            .max_by(|a, b| a.s.total_cmp(&b.s))
    }

    /// Widest gap any pre-shape opens (m).
    pub fn max_gap(&self) -> f64 {
        self.preshapes.iter().map(|p| p.gap).fold(0.0, f64::max)
    }

    /// Every independent hand joint (thumb, fingers, idle finger).
    pub fn joints(&self) -> Vec<JointId> {
        let mut all: Vec<JointId> = std::iter::once(&self.thumb)
            .chain(&self.fingers)
            .chain(std::iter::once(&self.idle))
            .flat_map(|f| f.joints.iter().copied())
            .collect();
        all.sort_unstable();
        all
    }

    /// The contacting fingers: the thumb first, then index and middle.
    pub fn pinching(&self) -> impl Iterator<Item = &Finger> {
        std::iter::once(&self.thumb).chain(&self.fingers)
    }
}

/// Where a finger touches the object.
#[derive(Debug, Clone)]
pub struct FingerContact {
    /// The touching link.
    pub link: LinkId,
    /// Contact point on the object (world frame).
    pub position: Point3<f64>,
    /// Unit normal into the object.
    pub normal: Vector3<f64>,
    /// Largest normal force the finger can apply there (N).
    pub f_max: f64,
}

/// Closing settings.
#[derive(Debug, Clone, Copy)]
pub struct Closing {
    /// Joint step while closing (rad).
    pub step: f64,
    /// A link this close to the object (m) touches it.
    pub contact_distance: f64,
}

impl Default for Closing {
    fn default() -> Self {
        Self {
            step: 0.04,
            contact_distance: 0.002,
        }
    }
}

/// The closest link of `finger` to the object: `(link, proximity)`.
fn nearest(
    collision: &RobotCollision,
    fk: &FkState,
    finger: &Finger,
    object: &CollisionObject,
) -> Option<(LinkId, tsukami_body::collision::Proximity)> {
    finger
        .links
        .iter()
        .filter_map(|&l| {
            collision
                .link_object_proximity(fk, l, object, 0.1)
                .map(|p| (l, p))
        })
        .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance))
}

/// Flexes `finger` from the configuration `q` (changed in place; `fk` holds
/// its link poses afterwards) until one of its links is within
/// `contact_distance` of the object; `None` when it reaches its joint limits
/// without touching or touches already at the start (penetration).
pub fn close_finger(
    model: &RobotModel,
    collision: &RobotCollision,
    finger: &Finger,
    q: &mut [f64],
    fk: &mut FkState,
    object: &CollisionObject,
    closing: &Closing,
) -> Option<FingerContact> {
    let start: Vec<f64> = finger.flex.iter().map(|&j| q[j]).collect();
    let set = |q: &mut [f64], delta: f64| {
        for (&j, &q0) in finger.flex.iter().zip(&start) {
            let lim = model.joints[j].limits;
            q[j] = (q0 + delta).clamp(lim.lower, lim.upper);
        }
        model.apply_mimics(q);
    };
    let span = finger
        .flex
        .iter()
        .zip(&start)
        .map(|(&j, &q0)| model.joints[j].limits.upper - q0)
        .fold(0.0, f64::max);
    let distance_at = |q: &mut [f64], fk: &mut FkState, delta: f64| {
        set(q, delta);
        model.forward_kinematics(q, fk);
        nearest(collision, fk, finger, object)
    };
    let (mut lo, mut hi) = (0.0, None);
    let first = distance_at(q, fk, 0.0)?;
    if first.1.distance < 0.0 {
        return None;
    }
    let mut delta = 0.0;
    let mut touch = (first.1.distance < closing.contact_distance).then_some(first);
    while touch.is_none() && delta < span {
        delta = (delta + closing.step).min(span);
        let (l, p) = distance_at(q, fk, delta)?;
        if p.distance < 0.0 {
            hi = Some(delta);
            break;
        }
        if p.distance < closing.contact_distance {
            touch = Some((l, p));
        } else {
            lo = delta;
        }
    }
    // Bisect between the last free and the first penetrating step.
    if let Some(mut h) = hi {
        for _ in 0..12 {
            let mid = 0.5 * (lo + h);
            let (l, p) = distance_at(q, fk, mid)?;
            if p.distance < 0.0 {
                h = mid;
            } else if p.distance < closing.contact_distance {
                touch = Some((l, p));
                break;
            } else {
                lo = mid;
            }
        }
    }
    let (link, prox) = touch?;
    let normal = -prox.normal.into_inner();
    let f_max = finger_force(model, fk, finger, link, &prox.point_on_object, &normal);
    (f_max > 0.0).then_some(FingerContact {
        link,
        position: prox.point_on_object,
        normal,
        f_max,
    })
}

/// Largest normal force the finger presses with at `point` along `normal`,
/// from its joint efforts and translational Jacobian (`τ = Jᵀ f`).
fn finger_force(
    model: &RobotModel,
    fk: &FkState,
    finger: &Finger,
    link: LinkId,
    point: &Point3<f64>,
    normal: &Vector3<f64>,
) -> f64 {
    let Ok(sel) = JointSelection::new(model, &finger.joints) else {
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
    max_finger_force(&j, &efforts, normal).map_or(0.0, |f| f.force.min(MAX_FINGER_FORCE))
}
