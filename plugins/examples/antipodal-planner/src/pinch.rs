//! The pinch: which fingers oppose, and the hand's pre-shapes from open to
//! closed, derived once per robot from its fingertip grasp type.
//!
//! What: [`Pinch::new`] takes the hand's first `fingertip3` grasp type: its
//! first contact's finger is the thumb, the others press against it. Its
//! posture with the flexion scaled by `s ∈ [0, 2]` (kit block `posture`) gives
//! a family of [`Preshape`]s, each with the thumb-pad and finger-pad positions
//! in the palm frame and the gap between them. [`Pinch::preshape_for`] picks the
//! most closed one that still opens wider than the object.
//!
//! Why: "which palm pose puts the thumb on point A and the fingers on point B"
//! is answered by a pre-shape whose gap fits; all names come from the robot
//! description and the grasp types, so any described hand works.

use nalgebra::Point3;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::JointId;
use tsukami_msgs::planner::GraspStyle;
use tsukami_planner_kit::blocks::posture::posture;
use tsukami_planner_kit::{KitError, Robot};

/// One pre-shape.
#[derive(Debug, Clone)]
pub struct Preshape {
    /// Hand joint values.
    pub q: Vec<(JointId, f64)>,
    /// Thumb pad centre, palm frame.
    pub thumb: Point3<f64>,
    /// Midpoint of the opposing pads, palm frame.
    pub fingers: Point3<f64>,
    /// Free gap between the pads, m.
    pub gap: f64,
}

/// The pinching fingers (thumb first; indices into the hand's fingers) and
/// the pre-shapes, open first.
#[derive(Debug, Clone)]
pub struct Pinch {
    /// The thumb, then the opposing fingers.
    pub fingers: Vec<usize>,
    /// Pre-shapes.
    pub preshapes: Vec<Preshape>,
}

impl Pinch {
    /// Derives the pinch of `robot`'s hand.
    pub fn new(robot: &Robot) -> Result<Self, KitError> {
        let (model, hand) = (&robot.model, robot.hand());
        let no = |m: &str| KitError::model("robot", format!("antipodal planner: {m}"));
        let gt = (hand.grasp_types.grasp_types.iter())
            .find(|g| g.style == GraspStyle::Fingertip3)
            .ok_or_else(|| no("the hand has no fingertip3 grasp type"))?;
        let finger_of = |link: &str| {
            let l = model.link_id(link).ok()?;
            hand.fingers.iter().position(|f| f.links.contains(&l))
        };
        let fingers: Vec<usize> = (gt.contacts.iter())
            .map(|c| finger_of(&c.link).ok_or_else(|| no(&format!("`{}` is on no finger", c.link))))
            .collect::<Result<_, _>>()?;
        if fingers.len() < 2 {
            return Err(no(
                "the fingertip3 type needs a thumb and an opposing finger",
            ));
        }
        let mut fk = FkState::new(model);
        let mut preshape = |s: f64| {
            let values = posture(robot, hand, gt, s);
            let mut q = model.rest_positions();
            values.iter().for_each(|&(j, v)| q[j] = v);
            model.apply_mimics(&mut q);
            model.forward_kinematics(&q, &mut fk);
            let to_palm = fk.pose(hand.palm).inverse();
            let pad = |i: usize| {
                let f = &hand.fingers[fingers[i]];
                to_palm * (fk.pose(f.tip) * f.pad.0)
            };
            let n = fingers.len() - 1;
            let centre = (1..=n).fold(Point3::origin(), |c, i| c + pad(i).coords / n as f64);
            let thumb = pad(0);
            let radii = hand.fingers[fingers[0]].pad.1 + hand.fingers[fingers[1]].pad.1;
            Preshape {
                gap: (centre - thumb).norm() - radii,
                q: values,
                thumb,
                fingers: centre,
            }
        };
        let preshapes = (0..=40).map(|k| preshape(k as f64 * 0.05)).collect();
        Ok(Pinch { fingers, preshapes })
    }

    /// The most closed pre-shape whose gap is at least `width`.
    pub fn preshape_for(&self, width: f64) -> Option<&Preshape> {
        self.preshapes.iter().rev().find(|p| p.gap >= width)
    }
}
