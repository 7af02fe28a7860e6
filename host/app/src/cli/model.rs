//! `tsukami model inspect|fk|ik`: the body library on the command line.
//!
//! Output field names are a contract external tools rely on (see
//! [`super::model_report`], which defines them); `--batch FILE` runs thousands of
//! configurations in one process.

use super::model_report::{self as report, IkRequest};
use anyhow::{Context, Result};
use clap::Subcommand;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Subcommands of `tsukami model`.
#[derive(Subcommand, Debug)]
pub enum ModelCommand {
    /// Links (name, mass) and joints (type, parent, child, limits, mimic) of a URDF.
    Inspect {
        /// The URDF file.
        file: PathBuf,
        #[command(flatten)]
        load: LoadArgs,
    },
    /// Forward kinematics: every link's pose in the root frame.
    Fk {
        /// The URDF file.
        file: PathBuf,
        #[command(flatten)]
        load: LoadArgs,
        /// `NAME=VALUE` (radians or metres); joints not given are 0.
        #[arg(long = "joint")]
        joints: Vec<String>,
        /// A JSON array of `{joint: value}` maps; answers an array.
        #[arg(long, conflicts_with = "joints")]
        batch: Option<PathBuf>,
    },
    /// Inverse kinematics of one link over a chosen joint list.
    Ik {
        /// The URDF file.
        file: PathBuf,
        #[command(flatten)]
        load: LoadArgs,
        /// The link to place.
        #[arg(long)]
        link: Option<String>,
        /// `x,y,z` or `x,y,z,qx,qy,qz,qw` in the root frame.
        #[arg(long, allow_hyphen_values = true)]
        target: Option<String>,
        /// Comma-separated joints that may move (default: the chain to the link).
        #[arg(long, value_delimiter = ',')]
        joints: Option<Vec<String>>,
        /// Seed of the random restarts.
        #[arg(long)]
        seed: Option<u64>,
        /// A JSON array of `{"link", "target", "joints"?, "seed"?}`; `--link` is the
        /// default link of items without one. Answers an array.
        #[arg(long, conflicts_with = "target")]
        batch: Option<PathBuf>,
    },
}

/// How `tsukami model` loads a URDF (shared by its subcommands).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct LoadArgs {
    /// A folder holding ROS packages (or a package folder, or `PKG=DIR`) for
    /// `package://` URIs; repeatable. Searched after ROS_PACKAGE_PATH and
    /// AMENT_PREFIX_PATH, before the URDF's own ancestors.
    #[arg(long = "package-dir", value_name = "DIR")]
    pub package_dirs: Vec<PathBuf>,
    /// Refuse every quirk that the default lenient reading only warns about.
    #[arg(long)]
    pub strict: bool,
}

/// Loads a URDF for kinematics (meshes that fail are skipped with a warning
/// on stderr), with the package path from the environment and `--package-dir`.
fn load(file: &Path, args: &LoadArgs) -> Result<tsukami_body::RobotModel> {
    let options = tsukami_body::urdf::LoadOptions {
        strict: args.strict,
        packages: tsukami_body::packages::PackagePath::default()
            .with_env()
            .with_dirs(args.package_dirs.iter().cloned()),
        ..tsukami_body::urdf::LoadOptions::kinematics_only()
    };
    let loaded = tsukami_body::urdf::load_urdf_with(file, &options)?;
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    Ok(loaded.model)
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))
}

fn print<T: serde::Serialize>(value: &T) -> Result<()> {
    println!("{}", serde_json::to_string_pretty(value)?);
    Ok(())
}

/// Runs one `tsukami model` subcommand.
pub fn run(command: &ModelCommand) -> Result<()> {
    match command {
        ModelCommand::Inspect { file, load: args } => {
            let model = load(file, args)?;
            print(&report::inspect(&model))
        }
        ModelCommand::Fk {
            file,
            load: args,
            joints,
            batch,
        } => {
            let model = load(file, args)?;
            match batch {
                Some(path) => {
                    let configurations: Vec<BTreeMap<String, f64>> = read_json(path)?;
                    print(&report::fk_batch(&model, &configurations)?)
                }
                None => {
                    let assignments = joints
                        .iter()
                        .map(|j| report::parse_joint_assignment(j))
                        .collect::<Result<Vec<_>, _>>()?;
                    print(&report::fk(
                        &model,
                        assignments.iter().map(|(n, v)| (n.as_str(), *v)),
                    )?)
                }
            }
        }
        ModelCommand::Ik {
            file,
            link,
            target,
            joints,
            seed,
            batch,
            load: args,
        } => {
            let model = load(file, args)?;
            match batch {
                Some(path) => {
                    let mut requests: Vec<IkRequest> = read_json(path)?;
                    for request in &mut requests {
                        if request.link.is_none() {
                            request.link = link.clone();
                        }
                    }
                    print(&report::ik_batch(&model, &requests)?)
                }
                None => {
                    let target = target
                        .as_deref()
                        .context("--target x,y,z[,qx,qy,qz,qw] is required without --batch")?;
                    let request = IkRequest {
                        link: link.clone(),
                        target: report::parse_target(target)?,
                        joints: joints.clone(),
                        seed: *seed,
                    };
                    print(&report::ik(&model, &request)?)
                }
            }
        }
    }
}
