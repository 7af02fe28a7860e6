//! The demo's report: a Markdown page with one row and one picture per scene,
//! beside each scene's picture (`SCENE.png`) and glTF binary (`SCENE.glb`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use nalgebra::Vector3;
use tsukami_scenes::{scene_requests, World};

use crate::demo::cells;
use crate::picture::{write_pictures, DEFAULT_EYE};
use crate::scenes::SceneOutcome;

/// Picture size of the report (pixels).
const PICTURE: (u32, u32) = (800, 600);

/// Writes the report of `outcomes` into `dir` (created if needed); returns the
/// Markdown file's path.
pub fn write_report(
    dir: &Path,
    models: &Path,
    outcomes: &[SceneOutcome],
    seed: u64,
) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut md = format!(
        "# Tsukami demo report\n\nThe paper's scenes planned over the bus (seed {seed}). \
         \"exact\" is the independent check's verdict (force closure with the object's \
         weight, recomputed from the reply's contacts).\n\n\
         | scene | grasp type | region:face | whole-body joints | margin | exact | plan ms | paper |\n\
         |---|---|---|---|---|---|---|---|\n"
    );
    let mut pictures = String::new();
    for o in outcomes {
        let [grasp, face, joints, margin, exact] = cells(o);
        let verdict = if o.ok { "ok" } else { "DIFFERS" };
        writeln!(
            md,
            "| {} | {grasp} | {face} | {joints} | {margin} | {exact} | {:.1} | {verdict}: {} |",
            o.scene, o.plan_ms, o.expected
        )?;
        let scene = models.join("scenes").join(format!("{}.toml", o.scene));
        let req = scene_requests(&scene).map_err(|e| anyhow::anyhow!("{e}"))?;
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
        writeln!(
            pictures,
            "## {}\n\n![{}]({png})\n\n3D: [{glb}]({glb})\n",
            o.scene, o.scene
        )?;
    }
    md.push('\n');
    md.push_str(&pictures);
    let path = dir.join("report.md");
    std::fs::write(&path, md).with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}
