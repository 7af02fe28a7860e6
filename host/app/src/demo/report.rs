//! The demo's report: a Markdown page with one row and one picture per scene.
//!
//! What: [`write_report`] writes `report.md` beside each scene's picture
//! (`SCENE.png`) and glTF binary (`SCENE.glb`); the components' logs are in
//! `logs/` beside them.
//!
//! Why: the terminal table scrolls away; the report keeps the same cells with
//! a picture of every grasp, for a person to look at later.
//!
//! How: the cells come from the table's functions (the same as printed); each
//! scene's world is loaded again from its scene file and drawn with
//! `tsukami-render` through [`crate::picture`].

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use nalgebra::Vector3;

use tsukami_render::grasp_view::DEFAULT_EYE;
use tsukami_scenes::{scene_requests, World};

use super::outcome::{DemoScene, PlanOn};
use super::table::{notes, plan_cells, step_cells};
use crate::picture::write_pictures;

/// Picture size of the report (pixels).
const PICTURE: (u32, u32) = (800, 600);

/// Writes the report of `scenes` into `dir` (created if needed); returns the
/// Markdown file's path.
pub fn write_report(dir: &Path, models: &Path, scenes: &[DemoScene], seed: u64) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let planned_on = if scenes.iter().any(|s| s.planned_on == PlanOn::Vision) {
        "where the vision saw the object (on the scene file's pose where it did not find it)"
    } else {
        "on the scene file's pose"
    };
    let mut md = format!(
        "# Tsukami demo report\n\nThe paper's scenes run over the bus (seed {seed}): the \
         vision component looks for the object — head aimed at it, arms and body out of the \
         view, other views where one does not see it — and finds it (error against the scene \
         file's pose, and the view it was found in), the grasp planner plans {planned_on}, the trajectory planner plans rest → grasp → \
         lift, the controller executes it. \"exact\" is the independent check's verdict \
         (force closure with the object's weight, recomputed from the reply's contacts); \
         \"executed\" is ok when the controller's published state at the end of `close` \
         is the planned grasp posture and at the end of the lift the trajectory's last \
         point (within 1e-6).\n\n\
         | scene | grasp type | region:face | whole-body joints | margin | exact | vision error | plan ms | motion ms | motion s | executed | paper |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n"
    );
    let mut pictures = String::new();
    for scene in scenes {
        let o = &scene.plan;
        let [grasp, face, joints, margin, exact] = plan_cells(o);
        let [vision, motion_ms, motion_s, executed] = step_cells(scene);
        let verdict = if o.ok { "ok" } else { "DIFFERS" };
        writeln!(
            md,
            "| {} | {grasp} | {face} | {joints} | {margin} | {exact} | {vision} | {:.1} | {motion_ms} | {motion_s} | {executed} | {verdict}: {} |",
            o.scene, o.plan_ms, o.expected
        )?;
        let file = models.join("scenes").join(format!("{}.toml", o.scene));
        let req = scene_requests(&file).map_err(|e| anyhow::anyhow!("{e}"))?;
        let world = World::from_requests(models, &req.robot, &req.object, &req.env)
            .map_err(|e| anyhow::anyhow!("scene {}: {e}", o.scene))?;
        let (png, glb) = (format!("{}.png", o.scene), format!("{}.glb", o.scene));
        write_pictures(
            &world,
            o.result.as_ref(),
            &dir.join(&png),
            Some(&dir.join(&glb)),
            PICTURE,
            Vector3::from(DEFAULT_EYE),
        )?;
        writeln!(pictures, "## {}\n", o.scene)?;
        let mut lines = notes(scene);
        if scene.planned_on == PlanOn::Vision {
            lines.insert(0, "planned on the pose the vision saw".to_owned());
        }
        for line in &lines {
            writeln!(pictures, "- {line}")?;
        }
        if !lines.is_empty() {
            pictures.push('\n');
        }
        writeln!(
            pictures,
            "![{}]({png})\n\n3D: [{glb}]({glb}); the components' output: \
             [vision](logs/vision-{}.log), [controller](logs/controller-{}.log)\n",
            o.scene, o.scene, o.scene
        )?;
    }
    md.push('\n');
    md.push_str(&pictures);
    let path = dir.join("report.md");
    std::fs::write(&path, md).with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}
