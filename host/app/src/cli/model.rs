//! `tsukami model inspect|fk|ik|compose`: the body library on the command line.
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
    /// Attaches a hand's URDF to a link of an arm's (or humanoid's) URDF with a
    /// fixed joint and writes the composed URDF; neither input is changed.
    Compose(ComposeArgs),
}

/// Arguments of `tsukami model compose`.
#[derive(clap::Args, Debug, Clone)]
pub struct ComposeArgs {
    /// The arm's (or humanoid's) URDF.
    pub arm: PathBuf,
    /// The hand's URDF (one root link: its palm or base).
    pub hand: PathBuf,
    /// The arm's link the hand is fixed to (its flange or wrist).
    #[arg(long)]
    pub at: String,
    /// Position of the hand's root in that link's frame, `x,y,z` (m).
    #[arg(long, default_value = "0,0,0", allow_hyphen_values = true)]
    pub xyz: String,
    /// Orientation of the hand's root in that link's frame, `roll,pitch,yaw` (rad).
    #[arg(long, default_value = "0,0,0", allow_hyphen_values = true)]
    pub rpy: String,
    /// Prepended to every hand link and joint name (needed when names clash).
    #[arg(long, default_value = "")]
    pub prefix: String,
    /// The composed robot's name (default `<arm>_<hand>`).
    #[arg(long)]
    pub name: Option<String>,
    /// Where to write the composed URDF (default: standard output).
    #[arg(long, short)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub load: LoadArgs,
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

/// `a,b,c` as three finite numbers; `what` names the option in errors.
fn parse_vec3(text: &str, what: &str) -> Result<[f64; 3]> {
    let v: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("{what} `{text}`: expected three numbers a,b,c"))?;
    match v.as_slice() {
        [a, b, c] if v.iter().all(|x| x.is_finite()) => Ok([*a, *b, *c]),
        _ => anyhow::bail!("{what} `{text}`: expected three finite numbers a,b,c"),
    }
}

/// `tsukami model compose`: reads both files, composes, writes the URDF, and
/// loads the result for kinematics to prove it is a valid robot.
fn compose(c: &ComposeArgs) -> Result<()> {
    let ComposeArgs {
        arm,
        hand,
        at,
        xyz,
        rpy,
        prefix,
        name,
        out,
        load: args,
    } = c;
    use tsukami_body::compose::{compose, read_raw, Attach};
    let mut raw = Vec::new();
    for file in [arm, hand] {
        let (robot, warnings) = read_raw(file, args.strict)?;
        warnings.iter().for_each(|w| eprintln!("warning: {w}"));
        raw.push(robot);
    }
    let attach = Attach {
        parent_link: at.clone(),
        origin: tsukami_body::urdf_xml::RawPose {
            xyz: parse_vec3(xyz, "--xyz")?,
            rpy: parse_vec3(rpy, "--rpy")?,
        },
        prefix: prefix.clone(),
        name: name.clone(),
    };
    let out_dir = match out {
        Some(o) => o.parent().map(Path::to_path_buf).unwrap_or_default(),
        None => std::env::current_dir()?,
    };
    let folder = |p: &Path| p.parent().map(Path::to_path_buf).unwrap_or_default();
    let hand_raw = raw.pop().expect("two files read");
    let arm_raw = raw.pop().expect("two files read");
    let robot = compose(
        arm_raw,
        hand_raw,
        &attach,
        (&folder(arm), &folder(hand), &out_dir),
    )?;
    let text = tsukami_body::urdf_write::write_urdf(&robot);
    let as_file = out.clone().unwrap_or_else(|| out_dir.join("composed.urdf"));
    let model = tsukami_body::urdf::parse_urdf_with(
        &text,
        &as_file,
        &tsukami_body::urdf::LoadOptions {
            packages: tsukami_body::packages::PackagePath::default()
                .with_env()
                .with_dirs(args.package_dirs.iter().cloned()),
            ..tsukami_body::urdf::LoadOptions::kinematics_only()
        },
    )
    .context("the composed robot does not load")?
    .model;
    match out {
        Some(o) => std::fs::write(o, &text).with_context(|| format!("writing {}", o.display()))?,
        None => print!("{text}"),
    }
    eprintln!(
        "composed '{}': {} links, {} joints ({} movable)",
        model.name,
        model.links.len(),
        model.joints.len(),
        model.joints.iter().filter(|j| j.is_movable()).count()
    );
    Ok(())
}

/// Runs one `tsukami model` subcommand.
pub fn run(command: &ModelCommand) -> Result<()> {
    match command {
        ModelCommand::Compose(c) => compose(c),
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
