//! The robot as rigid bodies for one planning problem: the broad phase of its
//! self-collision and obstacle checks.
//!
//! What: [`Bodies`] splits the links with geometry into moving bodies — links
//! past the same last planned joint, which the planned joints move as one rigid
//! piece (a hand the reach carries with its fingers fixed) — and static links,
//! which the planned joints never move. It sorts the self-collision pairs whose
//! links move relative to each other into blocks, one per pair of bodies (or of
//! a body and a static link), and keeps each moving body's AABB for the
//! configuration placed last.
//!
//! Why: a reach moves a hand of eighteen links past a torso; testing each of
//! their pairs' AABBs at every configuration costs more than the narrow phase
//! they spare. One AABB test per block skips every pair of a block whose two
//! sides are apart; one per body skips every link of a body far from an
//! obstacle. Pairs of links inside one body, or both static, keep the relative
//! pose the first check saw and are not tested again.
//!
//! How: [`Bodies::update`] unions the placed links' AABBs per body
//! ([`Placement::link_bounds`]); [`Bodies::first_self_collision`] tests a
//! block's pairs only when its sides' boxes come within the margin, and
//! [`Bodies::near`] lists the moving links of bodies whose box reaches an
//! obstacle's. Both only skip what cannot collide: the answer is the exact
//! tests'.

use std::ops::Range;

use nalgebra::Point3;
use tsukami_body::collision::{CollisionObject, Placement, RobotCollision};
use tsukami_body::model::{JointId, LinkId, RobotModel};

/// A world axis-aligned box (min, max corners).
type Bounds = (Point3<f64>, Point3<f64>);

/// One side of a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Side {
    /// A moving body (index into `Bodies::members`).
    Body(usize),
    /// A static link.
    Link(LinkId),
}

/// The self-collision pairs between two sides.
#[derive(Debug, Clone)]
struct Block {
    a: Side,
    b: Side,
    pairs: Range<usize>,
}

/// The moving bodies and static links of a planning problem (see the module).
#[derive(Debug, Clone)]
pub struct Bodies {
    /// Per moving body: its links with geometry.
    members: Vec<Vec<LinkId>>,
    /// Per moving body: its box at the configuration placed last.
    bounds: Vec<Bounds>,
    /// Self-collision pairs with relative motion, block by block.
    pairs: Vec<(LinkId, LinkId)>,
    blocks: Vec<Block>,
}

/// Do two boxes come within `margin` of each other?
fn overlap(a: &Bounds, b: &Bounds, margin: f64) -> bool {
    (0..3).all(|i| a.0[i] <= b.1[i] + margin && b.0[i] <= a.1[i] + margin)
}

/// Per link: the last joint on its path from the root that a planned joint
/// drives (the joint itself, or a mimic of it), if any. Links with the same
/// value move as one rigid body: their relative pose never changes.
pub fn moving_bodies(model: &RobotModel, joints: &[JointId]) -> Vec<Option<JointId>> {
    let mut body = vec![None; model.links.len()];
    // Links are stored parents first: a link moves with its parent unless its
    // own joint is planned or mimics a planned joint.
    for l in 1..model.links.len() {
        let Some(j) = model.links[l].parent_joint else {
            continue;
        };
        let joint = &model.joints[j];
        let driven = joints.contains(&j)
            || joint
                .mimic
                .as_ref()
                .is_some_and(|m| joints.contains(&m.master));
        body[l] = if driven { Some(j) } else { body[joint.parent] };
    }
    body
}

impl Bodies {
    /// The bodies of `links` (those with geometry) when `joints` are planned.
    pub fn new(
        model: &RobotModel,
        collision: &RobotCollision,
        links: &[LinkId],
        joints: &[JointId],
    ) -> Self {
        let driven = moving_bodies(model, joints);
        let mut keys: Vec<JointId> = Vec::new();
        let mut members: Vec<Vec<LinkId>> = Vec::new();
        let mut side = vec![None; model.links.len()];
        for &l in links {
            side[l] = Some(match driven[l] {
                None => Side::Link(l),
                Some(j) => {
                    let i = keys.iter().position(|&k| k == j).unwrap_or_else(|| {
                        keys.push(j);
                        members.push(Vec::new());
                        keys.len() - 1
                    });
                    members[i].push(l);
                    Side::Body(i)
                }
            });
        }
        let key = |l: LinkId| side[l].expect("self pairs are links with geometry");
        let mut pairs: Vec<((Side, Side), (LinkId, LinkId))> = collision
            .self_pairs()
            .into_iter()
            .filter(|&(a, b)| driven[a] != driven[b])
            .map(|(a, b)| {
                let (x, y) = (key(a), key(b));
                ((x.min(y), x.max(y)), (a, b))
            })
            .collect();
        // Stable: within a block the pairs keep the body crate's order.
        pairs.sort_by_key(|p| p.0);
        let mut blocks: Vec<Block> = Vec::new();
        for (i, &((a, b), _)) in pairs.iter().enumerate() {
            match blocks.last_mut() {
                Some(last) if last.a == a && last.b == b => last.pairs.end = i + 1,
                _ => blocks.push(Block {
                    a,
                    b,
                    pairs: i..i + 1,
                }),
            }
        }
        let empty = (Point3::origin(), Point3::origin());
        Bodies {
            bounds: vec![empty; members.len()],
            members,
            pairs: pairs.into_iter().map(|p| p.1).collect(),
            blocks,
        }
    }

    /// Every link of every moving body.
    pub fn moving_links(&self) -> Vec<LinkId> {
        self.members.iter().flatten().copied().collect()
    }

    /// Recomputes the moving bodies' boxes; every moving link must be placed.
    pub fn update(&mut self, placement: &Placement) {
        for (b, links) in self.bounds.iter_mut().zip(&self.members) {
            let inf = Point3::from([f64::INFINITY; 3]);
            *b = links.iter().fold((inf, -inf), |(lo, hi), &l| {
                let (a, z) = placement.link_bounds(l);
                (lo.inf(&a), hi.sup(&z))
            });
        }
    }

    fn bounds_of(&self, side: Side, placement: &Placement) -> Bounds {
        match side {
            Side::Body(i) => self.bounds[i],
            Side::Link(l) => placement.link_bounds(l),
        }
    }

    /// The first pair of links that move relative to each other and come
    /// closer than `margin` (after [`Self::update`] with the same placement).
    pub fn first_self_collision(
        &self,
        collision: &RobotCollision,
        placement: &Placement,
        margin: f64,
    ) -> Option<(LinkId, LinkId)> {
        self.blocks.iter().find_map(|block| {
            let a = self.bounds_of(block.a, placement);
            let b = self.bounds_of(block.b, placement);
            if !overlap(&a, &b, margin) {
                return None;
            }
            collision.placed_self_collision(placement, &self.pairs[block.pairs.clone()], margin)
        })
    }

    /// Writes into `out` the moving links of the bodies whose box comes within
    /// `margin` of `object`'s.
    pub fn near(&self, object: &CollisionObject, margin: f64, out: &mut Vec<LinkId>) {
        out.clear();
        let o = object.bounds();
        for (b, links) in self.bounds.iter().zip(&self.members) {
            if overlap(b, &o, margin) {
                out.extend_from_slice(links);
            }
        }
    }
}
