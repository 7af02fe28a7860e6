//! Pictures of a scene and its planned grasp, for `tsukami view` and the
//! demo's report: a PNG from the software renderer of `tsukami-render` (the
//! host library the result-viewer plugin draws with too) and, optionally, the
//! same drawing as a glTF binary.

use std::path::Path;

use anyhow::{Context, Result};
use nalgebra::{Point3, Vector3};
use tsukami_msgs::planner::PlanReply;
use tsukami_render::drawing::Drawing;
use tsukami_render::glb::to_glb;
use tsukami_render::grasp_view::{self, contact_marks, posture, GraspView};
use tsukami_render::render::{render, Camera};
use tsukami_scenes::World;

/// The drawing of `world` with the robot at `reply`'s posture and its
/// contacts, or at rest without a reply.
pub fn scene_drawing(world: &World, reply: Option<&PlanReply>) -> Result<Drawing> {
    let q = match reply {
        Some(r) => posture(&world.robot.model, r).map_err(|e| anyhow::anyhow!("result: {e}"))?,
        None => world.robot.model.rest_positions(),
    };
    let contacts = reply.map(contact_marks).unwrap_or_default();
    Ok(GraspView {
        model: &world.robot.model,
        collision: &world.robot.collision,
        q: &q,
        hand_links: &world.robot.hand_links,
        object: Some((&world.object.mesh, world.object.pose)),
        obstacles: &world.obstacles,
        contacts: &contacts,
    }
    .drawing())
}

/// What the camera looks at: midway between the object's box centre and the
/// contacts' centroid (the object's box centre without a grasp).
fn look_at(world: &World, reply: Option<&PlanReply>) -> Point3<f64> {
    let contacts = reply.map(contact_marks).unwrap_or_default();
    grasp_view::look_at(&world.object.mesh, &world.object.pose, &contacts)
}

/// Draws `world` (and `reply`) to a `size` PNG at `png` seen from `eye`
/// relative to the grasp (see `look_at`), and to `glb` when given. Returns the triangles drawn.
pub fn write_pictures(
    world: &World,
    reply: Option<&PlanReply>,
    png: &Path,
    glb: Option<&Path>,
    size: (u32, u32),
    eye: Vector3<f64>,
) -> Result<usize> {
    let drawing = scene_drawing(world, reply)?;
    let target = look_at(world, reply);
    let camera = Camera::offset_from(target, eye);
    let picture = render(&drawing, &camera, size.0, size.1).to_png()?;
    std::fs::write(png, picture).with_context(|| format!("writing {}", png.display()))?;
    if let Some(path) = glb {
        std::fs::write(path, to_glb(&drawing))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(drawing.triangle_count())
}
