//! `tsukami view`: a scene and a planned grasp as a picture (PNG) and a glTF
//! binary (`.glb`), headless — no GPU, no display, no browser.
//!
//! The scene file (`models/scenes/*.toml`) gives the robot, the object and the
//! obstacles; the result is a Plan reply (`tsukami plan … > reply.json`). The
//! picture comes from the software renderer of `tsukami-render`.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use nalgebra::Vector3;
use tsukami::picture::write_pictures;
use tsukami_msgs::planner::PlanReply;
use tsukami_render::grasp_view::DEFAULT_EYE;
use tsukami_scenes::{scene_requests, World};

/// Largest picture edge (pixels).
const MAX_EDGE: u32 = 8192;

/// `tsukami view` arguments.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// Scene file (robot, object, obstacles), under a `models/scenes/` folder.
    #[arg(long)]
    scene: PathBuf,
    /// Plan reply (JSON file); without it the robot is drawn at rest.
    #[arg(long)]
    result: Option<PathBuf>,
    /// Output picture (PNG).
    #[arg(long)]
    out: PathBuf,
    /// Also write the scene and grasp as glTF 2.0 binary here.
    #[arg(long)]
    glb: Option<PathBuf>,
    /// Picture size, `WIDTHxHEIGHT`.
    #[arg(long, default_value = "800x600")]
    size: String,
    /// Camera position relative to the object (m, world frame), `x,y,z`; it
    /// looks at the object. Default: to the robot's right, in front, above
    /// (`tsukami_render::grasp_view::DEFAULT_EYE`).
    #[arg(long, allow_hyphen_values = true)]
    eye: Option<String>,
}

/// Runs `tsukami view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    let (width, height) = size(&args.size)?;
    let eye = match &args.eye {
        Some(text) => eye(text)?,
        None => Vector3::from(DEFAULT_EYE),
    };
    let scene = std::fs::canonicalize(&args.scene)
        .with_context(|| format!("scene {}", args.scene.display()))?;
    let models = scene
        .parent()
        .and_then(Path::parent)
        .context("the scene must be in a models/scenes/ folder")?;
    let req = scene_requests(&scene).map_err(|e| anyhow::anyhow!("{e}"))?;
    let world = World::from_requests(models, &req.robot, &req.object, &req.env)
        .map_err(|e| anyhow::anyhow!("scene {}: {e}", scene.display()))?;
    let reply: Option<PlanReply> = match &args.result {
        Some(path) => {
            let text = std::fs::read(path).with_context(|| format!("result {}", path.display()))?;
            Some(
                serde_json::from_slice(&text)
                    .with_context(|| format!("result {}: not a Plan reply", path.display()))?,
            )
        }
        None => None,
    };
    let triangles = write_pictures(
        &world,
        reply.as_ref(),
        &args.out,
        args.glb.as_deref(),
        (width, height),
        eye,
    )?;
    eprintln!(
        "tsukami: {triangles} triangles drawn to {}",
        args.out.display()
    );
    Ok(())
}

fn size(text: &str) -> Result<(u32, u32)> {
    let parsed = text
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if (1..=MAX_EDGE).contains(&w) && (1..=MAX_EDGE).contains(&h) => Ok((w, h)),
        _ => bail!("--size {text:?}: expected WIDTHxHEIGHT, each 1 to {MAX_EDGE}"),
    }
}

fn eye(text: &str) -> Result<Vector3<f64>> {
    let v: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| anyhow::anyhow!("--eye {text:?}: expected x,y,z in metres"))?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) && (x, y, z) != (0.0, 0.0, 0.0) => {
            Ok(Vector3::new(x, y, z))
        }
        _ => bail!("--eye {text:?}: expected three finite numbers, not all zero"),
    }
}
