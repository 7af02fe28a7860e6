//! What the robot's own body hides of a target in the head camera's image.
//!
//! What: [`Looker::hidden`] counts, of the pixels where a sphere around the
//! target is seen, those where one of the robot's links is in front, per
//! link ([`Hidden`]).
//!
//! Why: a look must keep the robot's arms and body out of the object's part
//! of the image. The depth camera measures nothing nearer than 0.3 m, so a
//! link close in front of the object is a hole, which the detector cannot
//! tell from the object's absence (the chest below a head tilted to its
//! limit cut the can of `can_waist` in half). The robot's own body is also
//! the one thing known before the image is taken.
//!
//! How: the links at the configuration and the sphere are ray cast
//! ([`trace`]) over the sphere's pixel box, in a camera of a quarter of the
//! head camera's resolution (enough to tell a link from the object, 16 times
//! fewer rays): once with the sphere alone (the pixels it covers), once with
//! the links too (which of them a link covers first). The links around the
//! camera are left out, as in the rendered frame.

use nalgebra::Isometry3;
use parry3d_f64::shape::SharedShape;
use tsukami_body::convert::to_pose;
use tsukami_body::model::LinkId;

use super::{Looker, Target};
use crate::camera::{Camera, Intrinsics};
use crate::sim::render::{pixel_box, trace, Region};
use crate::sim::world::{SimBody, SimShape, SimWorld};

/// The sight check's image is the head camera's divided by this, a side.
pub const SIGHT_SCALE: u32 = 4;

/// What the robot's links hide of a target's sphere in the image.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Hidden {
    /// Pixels of the sphere (of the sight check's image).
    pub pixels: usize,
    /// Of those, the pixels a link covers.
    pub hidden: usize,
    /// The links covering them, with their pixel counts, most first.
    pub by_link: Vec<(LinkId, usize)>,
}

impl Hidden {
    /// The hidden fraction of the sphere's pixels (1 when none is in the image).
    pub fn fraction(&self) -> f64 {
        if self.pixels == 0 {
            1.0
        } else {
            self.hidden as f64 / self.pixels as f64
        }
    }
}

/// `k` with `SIGHT_SCALE` times fewer pixels a side, looking the same way.
fn coarse(k: &Intrinsics) -> Intrinsics {
    let s = SIGHT_SCALE as f64;
    Intrinsics {
        width: (k.width / SIGHT_SCALE).max(1),
        height: (k.height / SIGHT_SCALE).max(1),
        fx: k.fx / s,
        fy: k.fy / s,
        cx: (k.cx + 0.5) / s - 0.5,
        cy: (k.cy + 0.5) / s - 0.5,
    }
}

impl Looker {
    /// What the robot's links hide, at `q`, of the sphere of `target`
    /// (base frame) grown by [`super::MARGIN`]: the object with the surface
    /// around it that the detector needs (its supporting plane, what is
    /// behind it).
    pub fn hidden(&self, q: &[f64], target: &Target) -> Hidden {
        let head = self.head.camera(q);
        let camera = Camera {
            intrinsics: coarse(&head.intrinsics),
            pose: head.pose,
        };
        let mut world = SimWorld::default();
        let links = world.add_robot_shapes(
            &self.head.robot,
            &self.collision,
            q,
            &Isometry3::identity(),
            &camera.centre(),
        );
        let c = target.centre;
        let pose = to_pose(&Isometry3::translation(c.x, c.y, c.z));
        let shape = SharedShape::ball(target.radius * super::MARGIN);
        let aabb = shape.compute_aabb(&pose);
        let sphere = world.bodies.len();
        world.bodies.push(SimBody {
            name: "target".into(),
            shapes: vec![SimShape { pose, shape, aabb }],
        });
        let k = &camera.intrinsics;
        let b = pixel_box(&camera, aabb.mins, aabb.maxs);
        let clamp = |x: f64, hi: u32| x.clamp(0.0, hi as f64) as u32;
        let region: Region = [
            clamp(b[0].floor(), k.width),
            clamp(b[1].floor(), k.height),
            clamp(b[2].ceil() + 1.0, k.width),
            clamp(b[3].ceil() + 1.0, k.height),
        ];
        let alone = trace(&world, &camera, region, &|b| b == sphere);
        let first = trace(&world, &camera, region, &|_| true);
        let mut out = Hidden::default();
        let mut counts = vec![0usize; links.len()];
        for (a, f) in alone.iter().zip(&first) {
            if a.is_none() {
                continue;
            }
            out.pixels += 1;
            if let Some(hit) = f.filter(|h| h.body != sphere) {
                out.hidden += 1;
                counts[hit.body] += 1;
            }
        }
        out.by_link = links
            .into_iter()
            .zip(counts)
            .filter(|&(_, n)| n > 0)
            .collect();
        out.by_link
            .sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        out
    }
}
