//! Turning a nominal palm pose away from the support: lift it until the open
//! hand clears the obstacles.
//!
//! What: [`clear_nominal`] solves the IK of a nominal palm pose (section 3.2)
//! and, when the open hand or arm at that pose touches an obstacle (the table
//! under a lying bottle, the board under a plate), raises the palm in steps of
//! [`LIFT_STEP`] along the world vertical, up to [`max_lift`] of the OCP,
//! until it is clear; at the highest lift, a finger still on an obstacle is
//! flexed instead ([`PRE_FLEX`]: its Δa_i joints, toward their upper limits).
//! A finger that rests on the object itself in the reference posture is
//! opened instead ([`PRE_OPEN`]: its closing joint, toward its lower limit).
//! It returns the first clear pose, or the unlifted one marked blocked.
//!
//! Why: the paper centres GRCdes on the OCP, which on a low or lying object
//! puts the open fingers and the thumb below the support's top, so every
//! sample of Algorithm 1 around that pose is rejected. Holding the object a
//! little higher — the contacts move up its sides, which still close (the
//! exact test decides) — is what a person does with a plate or a lying can.
//!
//! How: only obstacle contacts trigger a lift; an arm against the robot
//! itself (the upper arm in the chest) or against the object triggers the IK
//! again from other arm postures ([`ARM_STARTS`]), which a lift would not
//! change; a hand link on the object triggers neither (the palm pose places
//! the hand, whatever the arm does) but, when it is a closing finger's, that
//! finger opens (the Allegro's fingertip posture is narrower than a ring's
//! tube with the fingertips' thickness). A lift whose IK fails is skipped. The
//! unlifted pose and the usual IK start are tried first, so a scene whose
//! nominal is already clear is unchanged.
//!
//! ```
//! use nalgebra::{Matrix3, Point3, Rotation3, Vector3};
//! use tsukami_grasp_planner::{clearance::max_lift, ocp::Ocp};
//! let lying_can = Ocp {
//!     region: 0,
//!     center: Point3::new(0.4, -0.2, 0.75),
//!     rotation: Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
//!         Vector3::y(), Vector3::x(), -Vector3::z(),
//!     ])),
//!     extents: Vector3::new(0.12, 0.06, 0.06),
//!     blocked: [None; 6],
//! };
//! assert!((max_lift(&lying_can) - 0.3 * 0.06).abs() < 1e-12);
//! ```

use nalgebra::{Isometry3, Translation3, Vector3};
use tsukami_body::collision::CollisionObject;
use tsukami_body::ik::IkSolver;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::LinkId;

use crate::hand::{HandModel, ResolvedContact};
use crate::link_sets::{Against, LinkSets};
use crate::ocp::Ocp;

/// Height step of a lift (m).
pub const LIFT_STEP: f64 = 0.003;
/// Largest lift as a fraction of the OCP's vertical extent.
pub const LIFT_FRACTION: f64 = 0.3;

/// The largest lift for a nominal on `ocp` (m): [`LIFT_FRACTION`] of its
/// extent along the world vertical.
pub fn max_lift(ocp: &Ocp) -> f64 {
    let m = ocp.rotation.matrix();
    let vertical: f64 = (0..3).map(|k| m[(2, k)].abs() * ocp.extents[k]).sum();
    LIFT_FRACTION * vertical
}

/// A nominal palm pose with its IK solution.
pub struct Cleared {
    /// Palm pose (world).
    pub palm: Isometry3<f64>,
    /// IK solution with the grasp type's posture.
    pub q: Vec<f64>,
    /// Still blocked at every lift tried.
    pub blocked: bool,
}

/// What the open hand must clear: the object and the obstacles.
pub struct Surroundings<'a> {
    /// The object.
    pub object: &'a CollisionObject,
    /// Obstacles.
    pub env: &'a [&'a CollisionObject],
}

/// How a posture stands against its surroundings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Verdict {
    /// Nothing touched that may not be.
    Clear,
    /// A link touches an obstacle (a lift may help).
    Obstacle,
    /// A hand link touches the object where it may not: the hand is where
    /// the palm pose puts it whatever the arm does, so neither another arm
    /// posture nor a lift is tried.
    HandOnObject,
    /// The arm touches the robot itself or the object (another arm posture
    /// may help).
    Other,
}

fn verdict(hand: &HandModel, links: &LinkSets, fk: &FkState, around: &Surroundings<'_>) -> Verdict {
    match links.blocked_by(hand, fk, around.object, around.env, true) {
        None => Verdict::Clear,
        Some(b) if b.against == Against::Obstacle => Verdict::Obstacle,
        Some(b) if b.against == Against::Object && hand.hand_links.contains(&b.link) => {
            Verdict::HandOnObject
        }
        Some(_) => Verdict::Other,
    }
}

/// The arm's other starts: every arm joint that is not a wrist joint at
/// these fractions of its range, tried in turn when the first IK solution
/// puts the arm against the robot itself.
pub const ARM_STARTS: [f64; 2] = [0.3, 0.7];

/// The IK solution of `palm` and its verdict: from `q0` first, then (if the
/// arm touches the robot or the object) from the [`ARM_STARTS`]; the first
/// clear one, else the first one. `None` when `q0` gives no IK solution.
fn solve(
    ik: &mut IkSolver,
    hand: &HandModel,
    links: &LinkSets,
    palm: &Isometry3<f64>,
    (q0, q_init): (&[f64], &[f64]),
    around: &Surroundings<'_>,
    fk: &mut FkState,
) -> Option<(Vec<f64>, Verdict)> {
    let mut first: Option<(Vec<f64>, Verdict)> = None;
    for start in std::iter::once(None).chain(ARM_STARTS.iter().map(Some)) {
        let mut q_start = q0.to_vec();
        if let Some(&f) = start {
            for &j in hand.arm.iter().filter(|j| !hand.wrist.contains(j)) {
                let l = &hand.robot.joints[j].limits;
                q_start[j] = l.lower + f * (l.upper - l.lower);
            }
        }
        let rest = if start.is_some() {
            &q_start[..]
        } else {
            q_init
        };
        let sol = ik.solve(palm, true, &q_start, Some(rest));
        if !sol.ok {
            // Without a solution from the usual start there is no nominal
            // here, as in the paper.
            start?;
            continue;
        }
        hand.robot.forward_kinematics(&sol.q, fk);
        let v = verdict(hand, links, fk, around);
        if v == Verdict::Clear {
            return Some((sol.q, v));
        }
        let other = v == Verdict::Other;
        first.get_or_insert((sol.q, v));
        if !other {
            break;
        }
    }
    first
}

/// How far a finger that rests on an obstacle is flexed before sampling:
/// fractions of the way from the pre-shape to its flexing joints' upper
/// limits, tried in turn.
pub const PRE_FLEX: [f64; 3] = [0.3, 0.6, 0.9];

/// How far a finger that touches the object in the pre-shape is opened
/// before sampling: fractions of the way from its closing joint's value to
/// the joint's lower limit, tried in turn.
pub const PRE_OPEN: [f64; 3] = [0.25, 0.5, 0.75];

/// The pre-shape of grasp type `t` at a nominal palm pose, and what its
/// fingers may be moved away from.
struct PreShape<'a> {
    hand: &'a HandModel,
    links: &'a LinkSets,
    t: usize,
    around: &'a Surroundings<'a>,
}

impl PreShape<'_> {
    /// The contact whose finger moves `link` when it closes.
    fn finger_of(&self, link: LinkId) -> Option<&ResolvedContact> {
        let hand = self.hand;
        hand.types[self.t]
            .contacts
            .iter()
            .find(|c| crate::finger_closing::moved_links(hand, c.joint, c.link).contains(&link))
    }

    /// Whether `q` (with its mimics applied) clears everything.
    fn clear(&self, q: &mut [f64], fk: &mut FkState) -> bool {
        self.hand.robot.apply_mimics(q);
        self.hand.robot.forward_kinematics(q, fk);
        verdict(self.hand, self.links, fk, self.around) == Verdict::Clear
    }

    /// `q` with the finger that touches an obstacle flexed (its contact's
    /// `perturb` joints, the ones Δa_i moves) by the first [`PRE_FLEX`]
    /// fraction that clears everything; `None` if none does, or if no finger
    /// is the one touching.
    fn flex(&self, q: &[f64], fk: &mut FkState) -> Option<Vec<f64>> {
        let robot = &self.hand.robot;
        robot.forward_kinematics(q, fk);
        let hit =
            self.hand
                .collision
                .first_collision(fk, &self.links.moving, self.around.env, 0.0)?;
        let finger = self.finger_of(hit.link)?;
        PRE_FLEX.iter().find_map(|f| {
            let mut flexed = q.to_vec();
            for &j in &finger.perturb {
                let upper = robot.joints[j].limits.upper;
                if upper.is_finite() && upper > q[j] {
                    flexed[j] = q[j] + f * (upper - q[j]);
                }
            }
            self.clear(&mut flexed, fk).then_some(flexed)
        })
    }

    /// `q` with every finger that touches the object opened (its contact's
    /// closing joint turned back by the first [`PRE_OPEN`] fraction that
    /// frees it), so that the closing starts outside the object: a wider
    /// hand than the reference posture, as a person opens the hand more for
    /// a thick part. `None` if a link other than a closing finger's touches
    /// or no fraction frees the finger.
    fn open(&self, q: &[f64], fk: &mut FkState) -> Option<Vec<f64>> {
        let (hand, links, around) = (self.hand, self.links, self.around);
        let on_object = |fk: &FkState| links.blocked_by(hand, fk, around.object, around.env, true);
        let mut q = q.to_vec();
        // Each finger at most once.
        for _ in 0..hand.types[self.t].contacts.len() {
            hand.robot.forward_kinematics(&q, fk);
            let hit = match on_object(fk) {
                None => return Some(q),
                Some(b) if b.against == Against::Object => b.link,
                Some(_) => return None,
            };
            let j = self.finger_of(hit)?.joint;
            let lower = hand.robot.joints[j].limits.lower;
            if !lower.is_finite() || lower >= q[j] {
                return None;
            }
            q = PRE_OPEN.iter().find_map(|f| {
                let mut opened = q.clone();
                opened[j] = q[j] - f * (q[j] - lower);
                hand.robot.apply_mimics(&mut opened);
                hand.robot.forward_kinematics(&opened, fk);
                let still = on_object(fk).is_some_and(|b| b.link == hit);
                (!still).then_some(opened)
            })?;
        }
        self.clear(&mut q, fk).then_some(q)
    }
}

/// The nominal `palm`, lifted as little as [`LIFT_STEP`] steps up to `lift`
/// allow so that `links` clear `around` (see the module docs); `None` when
/// the unlifted pose has no IK solution. `q0` holds the grasp type's posture.
#[allow(clippy::too_many_arguments)]
pub fn clear_nominal(
    ik: &mut IkSolver,
    hand: &HandModel,
    links: &LinkSets,
    palm: &Isometry3<f64>,
    (q0, q_init): (&[f64], &[f64]),
    around: &Surroundings<'_>,
    (t, lift): (usize, f64),
    fk: &mut FkState,
) -> Option<Cleared> {
    let steps = (lift / LIFT_STEP).floor() as usize;
    let shape = PreShape {
        hand,
        links,
        t,
        around,
    };
    let mut first: Option<Cleared> = None;
    let mut highest: Option<(Isometry3<f64>, Vec<f64>)> = None;
    for k in 0..=steps {
        let up = Vector3::z() * (k as f64 * LIFT_STEP);
        let p = Isometry3::from_parts(
            Translation3::from(palm.translation.vector + up),
            palm.rotation,
        );
        let Some((q, v)) = solve(ik, hand, links, &p, (q0, q_init), around, fk) else {
            if k == 0 {
                return None;
            }
            continue;
        };
        let blocked = v != Verdict::Clear;
        if !blocked {
            return Some(Cleared {
                palm: p,
                q,
                blocked,
            });
        }
        first.get_or_insert(Cleared {
            palm: p,
            q: q.clone(),
            blocked,
        });
        if v == Verdict::HandOnObject {
            // A finger on the object: open it rather than move the hand.
            if let Some(q) = shape.open(&q, fk) {
                return Some(Cleared {
                    palm: p,
                    q,
                    blocked: false,
                });
            }
            return first;
        }
        if v == Verdict::Other {
            return first;
        }
        highest = Some((p, q));
    }
    // Lifted as far as allowed and a finger still on an obstacle: flex it.
    if let Some((p, q)) = highest {
        if let Some(q) = shape.flex(&q, fk) {
            return Some(Cleared {
                palm: p,
                q,
                blocked: false,
            });
        }
    }
    first
}
