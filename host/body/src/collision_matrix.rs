//! Proposed `allowed_collisions`: the link pairs that random postures show
//! need no self-collision check.
//!
//! What: [`propose_allowed`] poses the robot in `samples` random postures
//! (every independent joint uniform within its limits, mimics following) and
//! counts, per link pair the robot's collision shapes check (not adjacent, not
//! already allowed), the postures in which the pair overlaps. A pair that
//! overlaps in every posture is [`Reason::Always`] (built to overlap, e.g. a
//! joint housing inside the link beside it); one that never does is
//! [`Reason::Never`] (cannot touch within the joint limits, as far as the
//! samples show). Pairs that sometimes overlap are real self-collisions and
//! are not proposed.
//!
//! Why: a robot description lists the pairs never checked
//! (`allowed_collisions`, SRDF's `disable_collisions`). Choosing them by hand
//! either misses pairs that always overlap — every posture is then refused —
//! or silences real collisions. MoveIt's setup assistant proposes them from
//! random postures the same way; the proposal is the author's to review.
//!
//! How: one ChaCha8 generator seeded with `seed` draws the postures in joint
//! order, so the same model, samples and seed give the same proposal; the
//! overlap test is [`RobotCollision::self_collisions`] with margin 0. Joints
//! without finite limits are drawn within ±π (revolute) or ±1 m (prismatic).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::collision::RobotCollision;
use crate::kinematics::FkState;
use crate::model::{LinkId, RobotModel};

/// Why a pair needs no check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reason {
    /// The pair overlapped in every sampled posture.
    Always,
    /// The pair overlapped in no sampled posture.
    Never,
}

/// One proposed pair.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ProposedPair {
    /// The first link (lower id).
    pub a: LinkId,
    /// The second link.
    pub b: LinkId,
    /// Why it needs no check.
    pub reason: Reason,
}

/// The proposal: the pairs and what the samples saw.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Proposal {
    /// Proposed pairs, in link-id order.
    pub pairs: Vec<ProposedPair>,
    /// Pairs checked that overlap in some postures only (kept checked).
    pub sometimes: Vec<(LinkId, LinkId, usize)>,
    /// Postures sampled.
    pub samples: usize,
}

/// One random posture of `model` drawn from `rng` (see the module docs).
pub fn random_posture(model: &RobotModel, rng: &mut ChaCha8Rng) -> Vec<f64> {
    let mut q = model.rest_positions();
    for (j, joint) in model.joints.iter().enumerate() {
        if !joint.is_movable() || !joint.is_independent() {
            continue;
        }
        let span = if joint.kind == crate::model::JointKind::Prismatic {
            1.0
        } else {
            std::f64::consts::PI
        };
        let lo = joint.limits.lower.max(-span);
        let hi = joint.limits.upper.min(span);
        q[j] = if hi > lo {
            rng.random_range(lo..=hi)
        } else {
            lo
        };
    }
    model.apply_mimics(&mut q);
    q
}

/// Proposes the pairs `collision` checks that need no check, from `samples`
/// random postures drawn with `seed` (see the module docs).
pub fn propose_allowed(
    model: &RobotModel,
    collision: &RobotCollision,
    samples: usize,
    seed: u64,
) -> Proposal {
    let pairs = collision.self_pairs();
    let mut hits = vec![0usize; pairs.len()];
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut fk = FkState::new(model);
    for _ in 0..samples {
        let q = random_posture(model, &mut rng);
        model.forward_kinematics(&q, &mut fk);
        for pair in collision.self_collisions(&fk, 0.0) {
            let k = pairs.binary_search(&pair).expect("a checked pair");
            hits[k] += 1;
        }
    }
    let mut out = Proposal {
        pairs: Vec::new(),
        sometimes: Vec::new(),
        samples,
    };
    for (&(a, b), &n) in pairs.iter().zip(&hits) {
        let reason = match n {
            0 => Reason::Never,
            n if n == samples => Reason::Always,
            n => {
                out.sometimes.push((a, b, n));
                continue;
            }
        };
        out.pairs.push(ProposedPair { a, b, reason });
    }
    out
}

/// The proposal as the TOML a robot description takes: an
/// `allowed_collisions` list, one pair a line with its reason as a comment.
pub fn to_toml(model: &RobotModel, proposal: &Proposal) -> String {
    let name = |l: LinkId| model.links[l].name.as_str();
    let mut out = format!(
        "# Proposed from {} random postures: review before use.\nallowed_collisions = [\n",
        proposal.samples
    );
    for p in &proposal.pairs {
        let why = match p.reason {
            Reason::Always => format!("in contact in all {} postures", proposal.samples),
            Reason::Never => format!("never in contact in {} postures", proposal.samples),
        };
        out += &format!("  [\"{}\", \"{}\"],  # {why}\n", name(p.a), name(p.b));
    }
    out += "]\n";
    for &(a, b, n) in &proposal.sometimes {
        out += &format!(
            "# checked: [\"{}\", \"{}\"] in contact in {n} of {} postures\n",
            name(a),
            name(b),
            proposal.samples
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::urdf::parse_urdf;

    /// A planar toy: `arm1` and `tip` turn about the base's axis; `arm2` and
    /// `housing` turn about one axis at the end of `arm1`.
    const TOY: &str = r#"<robot name="toy">
      <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="arm1"/>
        <axis xyz="0 0 1"/><limit lower="-3.14" upper="3.14" effort="1" velocity="1"/></joint>
      <link name="arm1"><collision><origin xyz="0.35 0 0"/><geometry><box size="0.5 0.04 0.04"/></geometry></collision></link>
      <joint name="j2" type="revolute"><parent link="arm1"/><child link="arm2"/><origin xyz="0.6 0 0"/>
        <axis xyz="0 0 1"/><limit lower="-3.14" upper="3.14" effort="1" velocity="1"/></joint>
      <link name="arm2"><collision><origin xyz="0.15 0 0"/><geometry><box size="0.3 0.04 0.04"/></geometry></collision>
        <collision><geometry><sphere radius="0.03"/></geometry></collision></link>
      <joint name="j3" type="revolute"><parent link="arm1"/><child link="housing"/><origin xyz="0.6 0 0"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <link name="housing"><collision><geometry><sphere radius="0.05"/></geometry></collision></link>
      <joint name="j4" type="revolute"><parent link="base"/><child link="tip"/>
        <axis xyz="0 0 1"/><limit lower="-3.14" upper="3.14" effort="1" velocity="1"/></joint>
      <link name="tip"><collision><origin xyz="0.35 0 0"/><geometry><box size="0.5 0.04 0.04"/></geometry></collision></link>
    </robot>"#;

    fn toy() -> (RobotModel, RobotCollision) {
        let model = parse_urdf(TOY, "toy.urdf".as_ref()).unwrap();
        let collision = RobotCollision::new(&model).unwrap();
        (model, collision)
    }

    #[test]
    fn always_and_never_pairs_are_proposed_and_real_collisions_kept() {
        let (model, collision) = toy();
        let id = |n: &str| model.link_id(n).unwrap();
        let p = propose_allowed(&model, &collision, 300, 7);
        let reason = |a: &str, b: &str| {
            let (a, b) = (id(a).min(id(b)), id(a).max(id(b)));
            p.pairs
                .iter()
                .find(|x| (x.a, x.b) == (a, b))
                .map(|x| x.reason)
        };
        assert_eq!(reason("arm2", "housing"), Some(Reason::Always));
        assert_eq!(reason("base", "arm2"), Some(Reason::Never));
        assert_eq!(reason("base", "housing"), Some(Reason::Never));
        // arm1 and tip cross when j1 and j4 agree: a real collision, kept.
        assert_eq!(reason("arm1", "tip"), None);
        let (a, t) = (id("arm1"), id("tip"));
        let kept = p
            .sometimes
            .iter()
            .find(|s| (s.0, s.1) == (a.min(t), a.max(t)));
        assert!(
            kept.is_some_and(|s| s.2 > 0 && s.2 < 300),
            "{:?}",
            p.sometimes
        );
        // Adjacent pairs are never checked, so never proposed.
        assert_eq!(reason("base", "arm1"), None);
        let toml = to_toml(&model, &p);
        assert!(
            toml.contains("[\"arm2\", \"housing\"],  # in contact in all 300 postures"),
            "{toml}"
        );
        assert!(
            toml.contains("[\"base\", \"arm2\"],  # never in contact in 300 postures"),
            "{toml}"
        );
        let parsed: toml::Table = toml::from_str(&toml).unwrap();
        assert_eq!(
            parsed["allowed_collisions"].as_array().unwrap().len(),
            p.pairs.len()
        );
    }

    #[test]
    fn the_same_seed_gives_the_same_proposal_and_postures_stay_in_limits() {
        let (model, collision) = toy();
        assert_eq!(
            propose_allowed(&model, &collision, 100, 3),
            propose_allowed(&model, &collision, 100, 3)
        );
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..100 {
            let q = random_posture(&model, &mut rng);
            for (j, joint) in model.joints.iter().enumerate() {
                assert!((joint.limits.lower..=joint.limits.upper).contains(&q[j]));
            }
        }
    }
}
