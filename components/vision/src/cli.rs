//! The command line of `tsukami-vision`.
//!
//! - `serve`: the component on the bus (answers `<ns>/vision/detect` and
//!   `<ns>/vision/look`, publishes `<ns>/vision/pose/<object>`), with the
//!   simulated head camera of `--scene` when requests carry no image.
//! - `render`: a simulated depth frame of a scene to files (a 16-bit PNG in
//!   millimetres, or float32 for any other extension, and the camera as JSON),
//!   seen from the first view of a look at the object.
//! - `detect`: the pose of an object in a depth file, printed as JSON.

use std::path::{Path, PathBuf};
use std::time::Duration;

use clap::{Parser, Subcommand};
use tsukami_body::files::ModelRoots;
use tsukami_msgs::vision::{CameraInfo, DetectRequest};

use crate::convert::{camera_from_msg, camera_to_msg, frame_to_msg};
use crate::depth::{encoding_of, DepthImage};
use crate::detect::DetectParams;
use crate::service::{serve, VisionService};
use crate::sim::noise::NoiseModel;
use crate::sim::scene_camera::SceneCamera;

#[derive(Parser)]
#[command(
    name = "tsukami-vision",
    version,
    about = "Tsukami vision component: object poses from depth images"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Args, Clone)]
struct Models {
    /// Model root holding `objects/<name>/object.toml` (default: ./models, else the source tree's).
    #[arg(long)]
    models: Option<PathBuf>,
}

impl Models {
    fn root(&self) -> PathBuf {
        self.models.clone().unwrap_or_else(default_models)
    }
}

fn default_models() -> PathBuf {
    let local = PathBuf::from("models");
    if local.join("objects").is_dir() {
        local
    } else {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models")
    }
}

#[derive(Subcommand)]
enum Command {
    /// Run the component on the bus.
    Serve {
        #[command(flatten)]
        bus: tsukami_bus::ComponentArgs,
        #[command(flatten)]
        models: Models,
        /// Scene file the simulated head camera renders when a request has no
        /// image (default: <models>/scenes/can_breast.toml).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// No simulated camera: requests must carry an image.
        #[arg(long, conflicts_with = "scene")]
        no_camera: bool,
        /// Seconds to wait for the world to accept a `set_object`.
        #[arg(long, default_value_t = 5.0)]
        set_object_timeout: f64,
    },
    /// Render a simulated frame of a scene.
    Render {
        /// The scene file.
        #[arg(long)]
        scene: PathBuf,
        /// Look at this object (model or scene name; default: the first), from
        /// the first view of a look: head aimed, body and arms out of the view.
        #[arg(long, default_value = "")]
        object: String,
        /// Noise seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Depth noise sigma (m).
        #[arg(long, default_value_t = 0.001)]
        sigma: f64,
        /// Output depth file (.png: 16-bit mm; otherwise float32 metres).
        #[arg(long)]
        out: PathBuf,
        /// Output camera file (JSON: intrinsics and camera_pose).
        #[arg(long)]
        camera_out: PathBuf,
    },
    /// Detect an object in a depth file.
    Detect {
        /// Object model name.
        #[arg(long)]
        object: String,
        /// Depth file (.png: 16-bit mm; otherwise float32 metres).
        #[arg(long)]
        depth: PathBuf,
        /// Camera file (JSON: intrinsics and camera_pose).
        #[arg(long)]
        camera: PathBuf,
        /// Least confidence to report a pose.
        #[arg(long)]
        min_confidence: Option<f64>,
        #[command(flatten)]
        models: Models,
    },
}

/// Runs the command line; returns the exit code.
pub fn main() -> i32 {
    let cli = Cli::parse();
    match run(cli.command) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("tsukami-vision: {e:#}");
            2
        }
    }
}

fn run(command: Command) -> anyhow::Result<i32> {
    match command {
        Command::Serve {
            bus,
            models,
            scene,
            no_camera,
            set_object_timeout,
        } => {
            tsukami_bus::init_logging("tsukami_vision");
            let shutdown = tsukami_bus::Shutdown::on_signals()?;
            let root = models.root();
            let camera = if no_camera {
                None
            } else {
                let path = scene.unwrap_or_else(|| root.join("scenes/can_breast.toml"));
                Some(SceneCamera::load(&path, NoiseModel::default())?)
            };
            let service =
                VisionService::new(ModelRoots::new([root]), DetectParams::default(), camera);
            let component = tsukami_bus::Component::start(
                "vision",
                env!("CARGO_PKG_VERSION"),
                "object poses from depth images (RANSAC plane, clusters, principal axes, point-to-plane ICP)",
                &bus,
            )?;
            let timeout = Duration::from_secs_f64(set_object_timeout.clamp(0.1, 600.0));
            let (queryables, worker) = serve(&component, service, timeout)?;
            shutdown.wait();
            tracing::info!("shutting down");
            drop(queryables);
            component.close();
            let _ = worker.join();
            Ok(0)
        }
        Command::Render {
            scene,
            object,
            seed,
            sigma,
            out,
            camera_out,
        } => {
            let noise = NoiseModel {
                sigma,
                ..NoiseModel::default()
            };
            let cam = SceneCamera::load(&scene, noise)?;
            let (image, camera) = cam.frame(&object, seed)?;
            image.save(&out)?;
            let text = serde_json::to_string_pretty(&camera_to_msg(&camera))?;
            std::fs::write(&camera_out, text + "\n")?;
            println!(
                "{} x {} depth frame of '{}' to {}",
                image.width(),
                image.height(),
                cam.name(),
                out.display()
            );
            Ok(0)
        }
        Command::Detect {
            object,
            depth,
            camera,
            min_confidence,
            models,
        } => {
            let info: CameraInfo = read_json(&camera)?;
            let cam = camera_from_msg(&info)?;
            let image = DepthImage::load(&depth, cam.intrinsics.width, cam.intrinsics.height)?;
            let frame = frame_to_msg(&image, &cam, encoding_of(Path::new("x.f32")))?;
            let mut service = VisionService::new(
                ModelRoots::new([models.root()]),
                DetectParams::default(),
                None,
            );
            let req = DetectRequest {
                object,
                image: Some(frame),
                set_object: false,
                min_confidence,
                seed: None,
            };
            match service.handle(&req) {
                Ok(h) => {
                    print_out(&serde_json::to_string_pretty(&h.pose)?);
                    Ok(0)
                }
                Err(e) => {
                    print_out(&serde_json::to_string_pretty(&e)?);
                    Ok(1)
                }
            }
        }
    }
}

/// Prints a line; a closed stdout (`| head`) is not an error.
fn print_out(text: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stdout(), "{text}");
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> anyhow::Result<T> {
    let text =
        std::fs::read_to_string(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}
