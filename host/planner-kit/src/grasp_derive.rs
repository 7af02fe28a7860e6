//! Grasp types derived from a hand's kinematics (issue 11, item 4).
//!
//! What: [`derive`] proposes the paper's reference postures (section 3.1) for
//! a hand the project did not design — 3- and 4-finger fingertip and 4-finger
//! envelope, each for a small, mid and large reference object — with their
//! GRCmax / GRCmin / GRCdes boxes, approach vector, contact links, closing and
//! perturbed joints; [`to_toml`] writes them as a grasp-type file
//! (`docs/grasp-types.md`) for a person to review.
//!
//! Why: writing `grasp_types.toml` by hand needs the hand's geometry in the
//! palm frame and a dozen measured numbers per type; a new hand should get a
//! working proposal from its URDF and robot description alone.
//!
//! How: everything is measured in the palm frame (+z palm normal, +x toward
//! the fingertips: the description's `palm_link`). The finger named `thumb`
//! opposes the others; a fingertip pad is the centre and radius of the tip
//! link's first collision shape (the kit's [`Finger::pad`]).
//! * **Fingertip** (a reference cylinder of diameter `D` with its axis along
//!   palm y): the fingers' flex joints close from open (0, clamped) toward the
//!   limit that lifts the pad off the palm (+z) — the proximal ones by `s`,
//!   the distal one by `t`, most open first. At the first closing where the
//!   pads are `D/2 + 2·clearance` above the palm, the thumb (damped least
//!   squares on its pad, within limits, from five starts) reaches the point
//!   opposite the finger row at the opening `D + 2·clearance`, every contact
//!   can still close three steps, no other finger link lies in the cylinder
//!   and closing every contact fully would squeeze below `D`, that is the
//!   posture (failing that: one clearance for the opening, then for the lift,
//!   then both, then half a clearance for the opening). GRCmax's x edge is
//!   the measured opening, GRCmin's the opening after every closing joint
//!   reaches its upper limit (at least `D − 2·clearance`), its y edge the
//!   measured width of the finger row; the boxes are centred between thumb
//!   and fingers. A capsule fingertip touches with its far end cap.
//! * **Envelope**: fingers nearly open (5 % closed); the object of size `D`
//!   lies on the proximal phalanges (x: the middle of the first flex link,
//!   z: `D/2 + clearance`) and the thumb is solved to its far side (one
//!   clearance away, else a quarter of `D` lower or higher, else two or four
//!   clearances away). Contacts: the thumb tip, each finger's proximal link
//!   (closed by its first flex joint) and its tip (closed by its last); the
//!   other finger links and the palm may touch.
//! * **Closing joint** of a contact: the most distal independent joint of the
//!   finger whose positive turn moves the pad toward the box centre at least
//!   half as fast as the best one (the planner closes toward upper limits);
//!   the finger's other joints are perturbed (Δa of Algorithm 1).
//!
//! Styles a hand cannot do are left out with a note: fingertip3 needs a thumb
//! and two fingers, fingertip4 and envelope4 a thumb and three.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use nalgebra::{DMatrix, DVector, Point3, Vector3};
use tsukami_body::kinematics::{FkState, JointSelection};
use tsukami_body::model::{Geometry, JointId, LinkId, RobotModel};
use tsukami_msgs::planner::{GraspSize, GraspStyle};

use crate::grasp_types::{ContactSpec, GraspType, GraspTypeConfig, GrcBox};
use crate::robot::{Finger, Hand};

/// The reference objects and conventions of a derivation.
#[derive(Debug, Clone, PartialEq)]
pub struct DeriveOptions {
    /// Reference object sizes of the fingertip types, small / mid / large (m).
    pub fingertip_sizes: [f64; 3],
    /// Reference object sizes of the envelope types (m).
    pub envelope_sizes: [f64; 3],
    /// Free space left on each side of the reference object (m).
    pub clearance: f64,
    /// The closing step written to every type (rad).
    pub closing_step: f64,
    /// GRCdes's y edge is the finger row's width times this.
    pub row_factor: f64,
    /// Mass ranges (kg) of fingertip3, fingertip4 and envelope4.
    pub mass: [[f64; 2]; 3],
}

impl Default for DeriveOptions {
    /// The sizes and masses of the project's humanoid hand
    /// (`models/robots/tsukami_humanoid/grasp_types.toml`).
    fn default() -> Self {
        Self {
            fingertip_sizes: [0.03, 0.066, 0.085],
            envelope_sizes: [0.045, 0.07, 0.095],
            clearance: 0.01,
            closing_step: 0.04,
            row_factor: 1.6,
            mass: [[0.0, 0.25], [0.0, 0.3], [0.2, 2.0]],
        }
    }
}

/// What a derivation proposes.
#[derive(Debug, Clone)]
pub struct Derived {
    /// The grasp types.
    pub config: GraspTypeConfig,
    /// One line per type (measured values) and per type left out (why).
    pub notes: Vec<String>,
}

/// Why no grasp type can be derived.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DeriveError {
    /// The description has no finger named `thumb`, or too few fingers.
    #[error("hand `{hand}`: {message}")]
    Hand {
        /// The hand's name.
        hand: String,
        /// What is missing.
        message: String,
    },
    /// No style and size could be derived.
    #[error("hand `{hand}`: no grasp type could be derived: {notes:?}")]
    Nothing {
        /// The hand's name.
        hand: String,
        /// Why each was left out.
        notes: Vec<String>,
    },
}

/// The hand's kinematics in the palm frame.
struct Kin<'a> {
    model: &'a RobotModel,
    hand: &'a Hand,
    fk: FkState,
    /// Hand joints at their open value (0 clamped), the rest at rest.
    open: Vec<f64>,
}

/// A measured posture.
struct Posture {
    q: Vec<f64>,
    /// Thumb pad (palm frame), finger pads.
    thumb: Point3<f64>,
    pads: Vec<Point3<f64>>,
}

impl<'a> Kin<'a> {
    fn new(model: &'a RobotModel, hand: &'a Hand) -> Self {
        Kin {
            model,
            hand,
            fk: FkState::new(model),
            open: model.rest_positions(),
        }
    }

    /// Pad centre of finger `f` in the palm frame at `q`.
    fn pad(&mut self, f: &Finger, q: &[f64]) -> Point3<f64> {
        self.model.forward_kinematics(q, &mut self.fk);
        let palm = self.fk.pose(self.hand.palm).inverse();
        palm * self.fk.pose(f.tip) * tip_point(self.model, f)
    }

    /// Origin of `link` in the palm frame at `q`.
    fn origin(&mut self, link: LinkId, q: &[f64]) -> Point3<f64> {
        self.model.forward_kinematics(q, &mut self.fk);
        self.fk.pose(self.hand.palm).inverse() * self.fk.pose(link) * Point3::origin()
    }

    fn set(&self, q: &mut [f64], j: JointId, v: f64) {
        let l = &self.model.joints[j].limits;
        q[j] = v.clamp(l.lower, l.upper);
    }

    /// The flex joints' closed values: the limit toward which the pad rises
    /// off the palm (+z) from the open posture.
    fn closed(&mut self, f: &Finger) -> Vec<f64> {
        let q0 = self.open.clone();
        let z0 = self.pad(f, &q0).z;
        f.flex
            .iter()
            .map(|&j| {
                let mut q = q0.clone();
                q[j] += 1e-4;
                self.model.apply_mimics(&mut q);
                let l = &self.model.joints[j].limits;
                if self.pad(f, &q).z >= z0 {
                    l.upper
                } else {
                    l.lower
                }
            })
            .collect()
    }

    /// Closes finger `f`'s flex joints the fraction `s` of the way, its last
    /// (distal) one the fraction `t` (`s` too when it has only one).
    fn close(&mut self, f: &Finger, closed: &[f64], (s, t): (f64, f64), q: &mut [f64]) {
        let n = f.flex.len();
        for (i, (&j, &c)) in f.flex.iter().zip(closed).enumerate() {
            let o = self.open[j];
            let a = if i + 1 == n && n > 1 { t } else { s };
            self.set(q, j, o + a * (c - o));
        }
        self.model.apply_mimics(q);
    }

    /// Damped least squares on finger `f`'s pad toward `target` over its
    /// independent joints, within limits; returns the remaining distance.
    fn reach(&mut self, f: &Finger, target: &Point3<f64>, q: &mut [f64]) -> f64 {
        let Ok(sel) = JointSelection::new(self.model, &f.joints) else {
            return f64::INFINITY;
        };
        let local = tip_point(self.model, f);
        let mut last = f64::INFINITY;
        for _ in 0..100 {
            let err = target - self.pad(f, q);
            // Converged, or no longer improving by a tenth of a millimetre.
            if err.norm() < 1e-5 || last - err.norm() < 1e-7 {
                break;
            }
            last = err.norm();
            let to_palm = self.fk.pose(self.hand.palm).rotation.inverse();
            let j6 = self.model.jacobian(&self.fk, f.tip, &local, &sel);
            let jac = DMatrix::from_fn(3, sel.len(), |r, c| {
                (to_palm * Vector3::new(j6[(0, c)], j6[(1, c)], j6[(2, c)]))[r]
            });
            let jt = jac.transpose();
            let a = &jac * &jt + DMatrix::identity(3, 3) * 1e-4;
            let Some(x) = a.lu().solve(&DVector::from_column_slice(err.as_slice())) else {
                break;
            };
            let dq = jt * x;
            for (c, &j) in f.joints.iter().enumerate() {
                let v = q[j] + dq[c].clamp(-0.2, 0.2);
                self.set(q, j, v);
            }
            self.model.apply_mimics(q);
        }
        (target - self.pad(f, q)).norm()
    }

    /// The thumb's postures reaching `target` within 1 mm from five starts
    /// (its joints at 1/2, 1/4, 0, 3/4, 1 of their ranges), or the closest miss.
    fn reach_thumb(
        &mut self,
        thumb: &Finger,
        target: &Point3<f64>,
        q: &[f64],
    ) -> Result<Vec<Vec<f64>>, f64> {
        let (mut found, mut miss) = (Vec::new(), f64::INFINITY);
        for s in [0.5, 0.25, 0.0, 0.75, 1.0] {
            let mut start = q.to_vec();
            for &j in &thumb.joints {
                let l = &self.model.joints[j].limits;
                let (lo, hi) = (l.lower.max(-3.0), l.upper.min(3.0));
                self.set(&mut start, j, lo + s * (hi - lo));
            }
            self.model.apply_mimics(&mut start);
            let d = self.reach(thumb, target, &mut start);
            if d < 1e-3 {
                found.push(start);
            }
            miss = miss.min(d);
        }
        if found.is_empty() {
            Err(miss)
        } else {
            Ok(found)
        }
    }

    /// The first finger link, other than a fingertip, that lies in the
    /// reference object at `q`: a cylinder around `centre` (palm frame) with
    /// its axis along palm y, radius `half.x`, half length `half.y`. Each link
    /// is taken as the segment from its joint to the next joint of its
    /// finger, 10 mm thick, sampled at five points.
    fn intruder(&mut self, q: &[f64], centre: &Point3<f64>, half: &Vector3<f64>) -> Option<String> {
        let hand = self.hand;
        for f in &hand.fingers {
            for pair in f.links.windows(2) {
                let (a, b) = (self.origin(pair[0], q), self.origin(pair[1], q));
                let inside = (0..5).any(|k| {
                    let p = a + (b - a) * (k as f64 / 4.0) - centre;
                    p.x.hypot(p.z) < half.x + 0.005 && p.y.abs() < half.y + 0.005
                });
                if inside {
                    return Some(self.model.links[pair[0]].name.clone());
                }
            }
        }
        None
    }

    /// True when every contact's closing joint can still turn three closing
    /// steps toward its upper limit (the planner closes that way).
    fn room(&self, contacts: &[ContactSpec], q: &[f64], step: f64) -> bool {
        contacts.iter().all(|c| {
            self.model
                .joint_id(&c.joint)
                .is_ok_and(|j| self.model.joints[j].limits.upper - q[j] >= 3.0 * step)
        })
    }
}

/// The point of finger `f`'s tip link that touches in a fingertip grasp, in
/// the link's frame: the centre of its first collision shape, or for a
/// capsule the centre of the end cap farther from the link's joint.
fn tip_point(model: &RobotModel, f: &Finger) -> Point3<f64> {
    let Some(e) = model.links[f.tip].collisions.first() else {
        return f.pad.0;
    };
    match e.geometry {
        Geometry::Capsule { length, .. } => {
            let half = e.origin.rotation * Vector3::z() * (0.5 * length);
            let c = Point3::from(e.origin.translation.vector);
            let (a, b) = (c + half, c - half);
            if a.coords.norm() >= b.coords.norm() {
                a
            } else {
                b
            }
        }
        _ => f.pad.0,
    }
}

/// The thumb's index and the other fingers' indices.
fn split_fingers(hand: &Hand) -> Result<(usize, Vec<usize>), DeriveError> {
    let thumb = hand
        .fingers
        .iter()
        .position(|f| f.name == "thumb")
        .ok_or_else(|| DeriveError::Hand {
            hand: hand.name.clone(),
            message: "the description names no finger `thumb` (the finger opposing the others)"
                .into(),
        })?;
    let others = (0..hand.fingers.len()).filter(|&k| k != thumb).collect();
    Ok((thumb, others))
}

/// Front of the finger row (its pads' smallest x minus radius), its y extent
/// and mean height.
fn row(hand: &Hand, members: &[usize], pads: &[Point3<f64>]) -> (f64, [f64; 2], f64) {
    let r = |k: usize| hand.fingers[members[k]].pad.1;
    let front = (0..pads.len())
        .map(|k| pads[k].x - r(k))
        .fold(f64::MAX, f64::min);
    let lo = (0..pads.len())
        .map(|k| pads[k].y - r(k))
        .fold(f64::MAX, f64::min);
    let hi = (0..pads.len())
        .map(|k| pads[k].y + r(k))
        .fold(f64::MIN, f64::max);
    let z = pads.iter().map(|p| p.z).sum::<f64>() / pads.len() as f64;
    (front, [lo, hi], z)
}

/// A fingertip posture, its box centre, contacts and smallest opening.
struct Fingertip {
    p: Posture,
    centre: Point3<f64>,
    contacts: Vec<ContactSpec>,
    min_x: f64,
}

/// The finger closings tried, most open first: proximal joints by `s`, the
/// distal one by `t`, in 5 % and 10 % steps.
fn closings() -> impl Iterator<Item = (f64, f64)> {
    (0..=20).flat_map(|s| (0..=10).map(move |t| (s as f64 / 20.0, t as f64 / 10.0)))
}

/// The fingertip posture for reference size `d`, or why there is none: the
/// fingers close from open until the pads are `D/2 + 2·clearance` above the
/// palm and the thumb reaches the point opposite the row at the opening
/// `D + 2·clearance`, with room to close every contact, and closing them all
/// would squeeze an object smaller than `D`; failing that, with one
/// clearance instead of two for the opening, then for the lift, then both,
/// then half a clearance for the opening.
fn fingertip_posture(
    kin: &mut Kin<'_>,
    thumb: usize,
    members: &[usize],
    d: f64,
    opts: &DeriveOptions,
) -> Result<Fingertip, String> {
    let hand = kin.hand;
    let closed: Vec<Vec<f64>> = members
        .iter()
        .map(|&k| kin.closed(&hand.fingers[k]))
        .collect();
    let c = opts.clearance;
    let mut why = format!("the fingers never lift {:.3} m off the palm", 0.5 * d + c);
    let mut closest = f64::INFINITY;
    let tries = [
        (2.0 * c, 2.0 * c),
        (c, 2.0 * c),
        (2.0 * c, c),
        (c, c),
        (0.5 * c, c),
    ];
    for (opening, lift) in tries.map(|(o, l)| (d + o, 0.5 * d + l)) {
        for (s, t) in closings() {
            let mut q = kin.open.clone();
            for (i, &k) in members.iter().enumerate() {
                kin.close(&hand.fingers[k], &closed[i], (s, t), &mut q);
            }
            let pads: Vec<Point3<f64>> = members
                .iter()
                .map(|&k| kin.pad(&hand.fingers[k], &q))
                .collect();
            let (front, y, z) = row(hand, members, &pads);
            if z < lift {
                continue;
            }
            let t_pad = &hand.fingers[thumb];
            let target = Point3::new(front - opening - t_pad.pad.1, 0.5 * (y[0] + y[1]), z);
            match kin.reach_thumb(t_pad, &target, &q) {
                Ok(found) => {
                    for q in found {
                        match fingertip_checks(kin, (thumb, members), q, &pads, d, opts) {
                            Ok(f) => return Ok(f),
                            Err(e) => why = e,
                        }
                    }
                }
                Err(miss) if miss < closest => {
                    closest = miss;
                    why = format!("the thumb cannot oppose the fingers at an opening of {opening:.3} m (closest {miss:.3} m off)");
                }
                Err(_) => {}
            }
        }
    }
    Err(why)
}

/// The contacts of a fingertip posture `q` whose thumb reached, if each can
/// close and closing them all gets below the reference size `d`.
fn fingertip_checks(
    kin: &mut Kin<'_>,
    (thumb, members): (usize, &[usize]),
    q: Vec<f64>,
    pads: &[Point3<f64>],
    d: f64,
    opts: &DeriveOptions,
) -> Result<Fingertip, String> {
    let hand = kin.hand;
    let t_pad = &hand.fingers[thumb];
    let (front, y, z) = row(hand, members, pads);
    let thumb_pad = kin.pad(t_pad, &q);
    let centre = Point3::new(
        0.5 * (front + thumb_pad.x + t_pad.pad.1),
        0.5 * (y[0] + y[1]),
        z,
    );
    let contacts = std::iter::once(thumb)
        .chain(members.iter().copied())
        .map(|k| contact(kin, &hand.fingers[k], &q, &centre))
        .collect::<Result<Vec<_>, _>>()?;
    if !kin.room(&contacts, &q, opts.closing_step) {
        return Err("a closing joint is at its upper limit".into());
    }
    let half = Vector3::new(0.5 * d, 0.5 * (y[1] - y[0]) * opts.row_factor, 0.5 * d);
    if let Some(name) = kin.intruder(&q, &centre, &half) {
        return Err(format!("link `{name}` lies in the reference object"));
    }
    let mut shut = q.clone();
    for c in &contacts {
        let j = kin.model.joint_id(&c.joint).map_err(|e| e.to_string())?;
        // At most one turn, as the planner's closing.
        let v = shut[j] + std::f64::consts::TAU;
        kin.set(&mut shut, j, v);
    }
    kin.model.apply_mimics(&mut shut);
    let min_x = opening(kin, thumb, members, &shut)
        .max(d - 2.0 * opts.clearance)
        .max(0.005);
    if min_x > d {
        return Err(format!(
            "closing stops at an opening of {min_x:.3} m, above {d} m"
        ));
    }
    let p = Posture {
        q,
        thumb: thumb_pad,
        pads: pads.to_vec(),
    };
    Ok(Fingertip {
        p,
        centre,
        contacts,
        min_x,
    })
}

/// The closing joint of finger `f` toward `centre` and the joints perturbed.
fn closing_joint(
    kin: &mut Kin<'_>,
    f: &Finger,
    q: &[f64],
    centre: &Point3<f64>,
) -> Option<(JointId, Vec<JointId>)> {
    let p = kin.pad(f, q);
    let toward = (centre - p).normalize();
    let speeds: Vec<f64> = f
        .joints
        .iter()
        .map(|&j| {
            let mut qh = q.to_vec();
            qh[j] += 1e-6;
            kin.model.apply_mimics(&mut qh);
            (kin.pad(f, &qh) - p).dot(&toward) / 1e-6
        })
        .collect();
    let best = speeds.iter().copied().fold(0.0, f64::max);
    if best <= 0.0 {
        return None;
    }
    let c = (0..speeds.len()).rev().find(|&c| speeds[c] >= 0.5 * best)?;
    let perturb = f
        .joints
        .iter()
        .copied()
        .filter(|&j| j != f.joints[c])
        .collect();
    Some((f.joints[c], perturb))
}

/// The thumb and finger pads' opening along palm x at posture `q`.
fn opening(kin: &mut Kin<'_>, thumb: usize, members: &[usize], q: &[f64]) -> f64 {
    let hand = kin.hand;
    let pads: Vec<Point3<f64>> = members
        .iter()
        .map(|&k| kin.pad(&hand.fingers[k], q))
        .collect();
    let (front, _, _) = row(hand, members, &pads);
    front - (kin.pad(&hand.fingers[thumb], q).x + hand.fingers[thumb].pad.1)
}

fn names(model: &RobotModel, joints: &[JointId]) -> Vec<String> {
    joints
        .iter()
        .map(|&j| model.joints[j].name.clone())
        .collect()
}

/// The contact of `f`'s tip and the joint that closes it toward `centre`.
fn contact(
    kin: &mut Kin<'_>,
    f: &Finger,
    q: &[f64],
    centre: &Point3<f64>,
) -> Result<ContactSpec, String> {
    let (joint, perturb) = closing_joint(kin, f, q, centre).ok_or_else(|| {
        format!(
            "no joint of finger `{}` closes it toward the object",
            f.name
        )
    })?;
    Ok(ContactSpec {
        link: kin.model.links[f.tip].name.clone(),
        joint: kin.model.joints[joint].name.clone(),
        perturb: names(kin.model, &perturb),
    })
}

/// The hand joints' angles of `q` (independent joints only), by name.
fn posture_map(kin: &Kin<'_>, q: &[f64]) -> BTreeMap<String, f64> {
    kin.hand
        .joints
        .iter()
        .map(|&j| {
            let v = (q[j] * 1e4).round() / 1e4;
            (
                kin.model.joints[j].name.clone(),
                if v == 0.0 { 0.0 } else { v },
            )
        })
        .collect()
}

fn rounded(v: [f64; 3]) -> [f64; 3] {
    v.map(|x| {
        let r = (x * 1e4).round() / 1e4;
        if r == 0.0 {
            0.0
        } else {
            r
        }
    })
}

fn grc(centre: &Point3<f64>, size: [f64; 3]) -> GrcBox {
    GrcBox {
        position: rounded([centre.x, centre.y, centre.z]),
        rpy: [0.0; 3],
        size: rounded(size),
    }
}

const SIZES: [(GraspSize, &str); 3] = [
    (GraspSize::Small, "small"),
    (GraspSize::Mid, "mid"),
    (GraspSize::Large, "large"),
];

/// One fingertip grasp type of `style` for size class `size` (index 0..3).
fn fingertip(
    kin: &mut Kin<'_>,
    (thumb, members): (usize, &[usize]),
    style: GraspStyle,
    size: usize,
    opts: &DeriveOptions,
) -> Result<(GraspType, String), String> {
    let d = opts.fingertip_sizes[size];
    let Fingertip {
        p,
        centre,
        contacts,
        min_x,
    } = fingertip_posture(kin, thumb, members, d, opts)?;
    let hand = kin.hand;
    let (front, y, _) = row(hand, members, &p.pads);
    let back = p.thumb.x + hand.fingers[thumb].pad.1;
    let open_x = front - back;
    let width = y[1] - y[0];
    let mass = opts.mass[if style == GraspStyle::Fingertip3 {
        0
    } else {
        1
    }];
    let note = format!(
        "opening {open_x:.3} (min {min_x:.3}), finger row {width:.3}, centre [{:.3}, {:.3}, {:.3}]",
        centre.x, centre.y, centre.z
    );
    let g = GraspType {
        name: format!("{}_{}", style.as_str(), SIZES[size].1),
        style,
        size: SIZES[size].0,
        mass,
        approach: [0.0, 0.0, 1.0],
        closing_step: opts.closing_step,
        posture: posture_map(kin, &p.q),
        contacts,
        touch_allowed: Vec::new(),
        palm_contact: false,
        grc_max: grc(&centre, [open_x, 0.3, 0.3]),
        grc_min: grc(&centre, [min_x, width, 0.01]),
        grc_des: grc(&centre, [d, width * opts.row_factor, d]),
    };
    Ok((g, note))
}

/// The envelope's thumb on the object's far side, one clearance away at the
/// centre's height, else a quarter of the object lower or higher, else two or
/// four clearances away: the first posture whose closing joint has room, and
/// its contact.
fn envelope_thumb(
    kin: &mut Kin<'_>,
    t: &Finger,
    centre: &Point3<f64>,
    d: f64,
    opts: &DeriveOptions,
    q: &[f64],
) -> Result<(Vec<f64>, ContactSpec), String> {
    let mut why = "the thumb cannot reach the envelope's far side".to_string();
    let gaps = [1.0, 2.0, 4.0].map(|k| k * opts.clearance);
    let heights = [0.0, -0.25 * d, 0.25 * d];
    for (gap, dz) in gaps.into_iter().flat_map(|g| heights.map(|h| (g, h))) {
        let x = centre.x - 0.5 * d - gap - t.pad.1;
        let target = Point3::new(x, centre.y, centre.z + dz);
        match kin.reach_thumb(t, &target, q) {
            Ok(found) => {
                for q in found {
                    let c = contact(kin, t, &q, centre)?;
                    if kin.room(std::slice::from_ref(&c), &q, opts.closing_step) {
                        return Ok((q, c));
                    }
                    why = "the thumb's closing joint is at its upper limit".into();
                }
            }
            Err(miss) => {
                why = format!("the thumb cannot reach the envelope's far side ({miss:.3} m off)")
            }
        }
    }
    Err(why)
}

/// The envelope's contacts (the thumb's, then each finger's proximal link
/// closed by its first flex joint and its tip closed by its last) and the
/// links that may touch (the palm's and the fingers' other links).
fn envelope_contacts(
    kin: &Kin<'_>,
    thumb_contact: ContactSpec,
    thumb: usize,
    members: &[usize],
) -> (Vec<ContactSpec>, Vec<LinkId>) {
    let hand = kin.hand;
    let name = |j: JointId| kin.model.joints[j].name.clone();
    let mut contacts = vec![thumb_contact];
    let mut touch: Vec<LinkId> = hand
        .links
        .iter()
        .copied()
        .filter(|l| !hand.fingers.iter().any(|f| f.links.contains(l)))
        .collect();
    for &k in members {
        let f = &hand.fingers[k];
        let (first, last) = (f.flex[0], f.flex[f.flex.len() - 1]);
        let proximal = kin.model.joints[first].child;
        contacts.push(ContactSpec {
            link: kin.model.links[proximal].name.clone(),
            joint: name(first),
            perturb: vec![name(first)],
        });
        contacts.push(ContactSpec {
            link: kin.model.links[f.tip].name.clone(),
            joint: name(last),
            perturb: Vec::new(),
        });
        touch.extend(
            f.links
                .iter()
                .copied()
                .filter(|&l| l != proximal && l != f.tip),
        );
    }
    let t = &hand.fingers[thumb];
    touch.extend(t.links.iter().copied().filter(|&l| l != t.tip));
    touch.retain(|&l| !kin.model.links[l].collisions.is_empty());
    (contacts, touch)
}

/// One envelope grasp type for size class `size`.
fn envelope(
    kin: &mut Kin<'_>,
    (thumb, members): (usize, &[usize]),
    size: usize,
    opts: &DeriveOptions,
) -> Result<(GraspType, String), String> {
    let d = opts.envelope_sizes[size];
    let hand = kin.hand;
    let mut q = kin.open.clone();
    let mut mids = Vec::new();
    for &k in members {
        let f = &hand.fingers[k];
        let closed = kin.closed(f);
        kin.close(f, &closed, (0.05, 0.05), &mut q);
        let [first, second, ..] = f.flex[..] else {
            return Err(format!("finger `{}` needs two flex joints", f.name));
        };
        let (a, b) = (
            kin.model.joints[first].child,
            kin.model.joints[second].child,
        );
        mids.push(nalgebra::center(&kin.origin(a, &q), &kin.origin(b, &q)));
    }
    let pads: Vec<Point3<f64>> = members
        .iter()
        .map(|&k| kin.pad(&hand.fingers[k], &q))
        .collect();
    let (_, y, _) = row(hand, members, &pads);
    let x = mids.iter().map(|m| m.x).sum::<f64>() / mids.len() as f64;
    let centre = Point3::new(x, 0.5 * (y[0] + y[1]), 0.5 * d + opts.clearance);
    let rt = hand.fingers[thumb].pad.1;
    let t = &hand.fingers[thumb];
    let (q, thumb_contact) = envelope_thumb(kin, t, &centre, d, opts, &q)?;
    let (contacts, touch) = envelope_contacts(kin, thumb_contact, thumb, members);
    let width = y[1] - y[0];
    let open_x = 2.0 * (x - (kin.pad(t, &q).x + rt));
    let min_x = (d - 1.5 * opts.clearance).max(0.005);
    let note = format!(
        "opening {open_x:.3} (min {min_x:.3}), finger row {width:.3}, centre [{:.3}, {:.3}, {:.3}]",
        centre.x, centre.y, centre.z
    );
    let g = GraspType {
        name: format!("envelope4_{}", SIZES[size].1),
        style: GraspStyle::Envelope4,
        size: SIZES[size].0,
        mass: opts.mass[2],
        approach: [0.0, 0.0, 1.0],
        closing_step: opts.closing_step,
        posture: posture_map(kin, &q),
        contacts,
        touch_allowed: touch
            .iter()
            .map(|&l| kin.model.links[l].name.clone())
            .collect(),
        palm_contact: false,
        grc_max: grc(&centre, [open_x.max(d), 0.3, 0.3]),
        grc_min: grc(&centre, [min_x, width, 0.01]),
        grc_des: grc(&centre, [d, width * opts.row_factor, d]),
    };
    Ok((g, note))
}

/// Derives the grasp types of `hand` (see the module documentation).
pub fn derive(
    model: &RobotModel,
    hand: &Hand,
    opts: &DeriveOptions,
) -> Result<Derived, DeriveError> {
    let (thumb, others) = split_fingers(hand)?;
    if others.len() < 2 {
        return Err(DeriveError::Hand {
            hand: hand.name.clone(),
            message: format!(
                "{} finger(s) besides the thumb: the planner's styles need at least two",
                others.len()
            ),
        });
    }
    let mut kin = Kin::new(model, hand);
    let mut types = Vec::new();
    let mut notes = Vec::new();
    let styles = [
        (GraspStyle::Fingertip3, 2),
        (GraspStyle::Fingertip4, 3),
        (GraspStyle::Envelope4, 3),
    ];
    for (style, n) in styles {
        for (size, (_, label)) in SIZES.iter().enumerate() {
            let name = format!("{}_{label}", style.as_str());
            if others.len() < n {
                notes.push(format!("{name}: left out: needs a thumb and {n} fingers"));
                continue;
            }
            let fingers = (thumb, &others[..n]);
            let made = match style {
                GraspStyle::Envelope4 => envelope(&mut kin, fingers, size, opts),
                _ => fingertip(&mut kin, fingers, style, size, opts),
            };
            match made {
                Ok((g, note)) => {
                    notes.push(format!("{name}: {note}"));
                    types.push(g);
                }
                Err(why) => notes.push(format!("{name}: left out: {why}")),
            }
        }
    }
    let config = GraspTypeConfig {
        hand: Default::default(),
        grasp_types: types,
    };
    if config.grasp_types.is_empty() {
        return Err(DeriveError::Nothing {
            hand: hand.name.clone(),
            notes,
        });
    }
    config.validate().map_err(|e| DeriveError::Hand {
        hand: hand.name.clone(),
        message: format!("derived types do not check: {e}"),
    })?;
    Ok(Derived { config, notes })
}

fn vec3(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", v[0], v[1], v[2])
}

fn grc_line(key: &str, b: &GrcBox) -> String {
    format!(
        "{key} = {{ position = {}, size = {} }}\n",
        vec3(b.position),
        vec3(b.size)
    )
}

fn strings(v: &[String]) -> String {
    let quoted: Vec<String> = v.iter().map(|s| format!("{s:?}")).collect();
    format!("[{}]", quoted.join(", "))
}

/// The grasp types as a grasp-type file in the layout of the hand-written
/// ones (one inline table per box and contact), headed by `header` lines as
/// comments.
pub fn to_toml(config: &GraspTypeConfig, header: &[String]) -> String {
    let mut out = String::new();
    for line in header {
        let _ = writeln!(out, "# {line}");
    }
    for g in &config.grasp_types {
        let _ = writeln!(out, "\n[[grasp_type]]");
        let _ = writeln!(out, "name = {:?}", g.name);
        let _ = writeln!(out, "style = {:?}", g.style.as_str());
        let _ = writeln!(out, "size = {:?}", g.size.as_str());
        let _ = writeln!(out, "mass = [{}, {}]", g.mass[0], g.mass[1]);
        let _ = writeln!(out, "approach = {}", vec3(g.approach));
        let _ = writeln!(out, "closing_step = {}", g.closing_step);
        let posture: Vec<String> = g
            .posture
            .iter()
            .map(|(j, v)| format!("{:?} = {v}", j))
            .collect();
        let _ = writeln!(out, "posture = {{ {} }}", posture.join(", "));
        let _ = writeln!(out, "contacts = [");
        for c in &g.contacts {
            let _ = writeln!(
                out,
                "  {{ link = {:?}, joint = {:?}, perturb = {} }},",
                c.link,
                c.joint,
                strings(&c.perturb)
            );
        }
        let _ = writeln!(out, "]");
        if !g.touch_allowed.is_empty() {
            let _ = writeln!(out, "touch_allowed = {}", strings(&g.touch_allowed));
        }
        out.push_str(&grc_line("grc_max", &g.grc_max));
        out.push_str(&grc_line("grc_min", &g.grc_min));
        out.push_str(&grc_line("grc_des", &g.grc_des));
    }
    out
}
