//! `tsukami model inspect|fk|ik|compose|grasp-types|allowed-collisions`: the
//! body library (and the planner kit's grasp-type derivation) on the command
//! line.
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
    /// Proposes the paper's grasp types (reference postures and GRC boxes) for
    /// a robot's first hand from its kinematics and writes a grasp-type file
    /// to review (`docs/grasp-types.md`).
    GraspTypes {
        /// The robot's folder (holding `description.toml`) or its description file.
        robot: PathBuf,
        /// Where to write the file (default: standard output).
        #[arg(long, short)]
        out: Option<PathBuf>,
        #[command(flatten)]
        load: LoadArgs,
    },
    /// Proposes a robot description's `allowed_collisions` from random
    /// postures: link pairs in contact in every posture or in none (as MoveIt's
    /// setup assistant does), printed as TOML with the reason per pair.
    AllowedCollisions {
        /// The robot's folder (holding `description.toml`) or its description file;
        /// pairs it already allows are not proposed again.
        robot: PathBuf,
        /// Random postures to sample.
        #[arg(long, default_value_t = 2000)]
        samples: usize,
        /// Seed of the postures (same seed, same proposal).
        #[arg(long, default_value_t = 0)]
        seed: u64,
        #[command(flatten)]
        load: LoadArgs,
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
    /// Inserts an empty link of this name above the hand's root, at
    /// `--palm-xyz`/`--palm-rpy` in the root's frame: a palm frame with the
    /// planner's axes (+z palm normal, +x toward the fingertips) for a hand
    /// whose own palm link has other axes; name it as `palm_link` in the
    /// robot description.
    #[arg(long, value_name = "NAME")]
    pub palm_frame: Option<String>,
    /// Position of the palm frame in the hand root's frame, `x,y,z` (m).
    #[arg(
        long,
        default_value = "0,0,0",
        allow_hyphen_values = true,
        requires = "palm_frame"
    )]
    pub palm_xyz: String,
    /// Orientation of the palm frame in the hand root's frame, `roll,pitch,yaw` (rad).
    #[arg(
        long,
        default_value = "0,0,0",
        allow_hyphen_values = true,
        requires = "palm_frame"
    )]
    pub palm_rpy: String,
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

/// `--palm-frame`: the frame link above the hand's root `root`, if asked for.
fn add_palm_frame(
    c: &ComposeArgs,
    robot: &mut tsukami_body::urdf_xml::RawRobot,
    root: &str,
) -> Result<()> {
    let Some(name) = &c.palm_frame else {
        return Ok(());
    };
    let frame = tsukami_body::compose::Frame {
        name: name.clone(),
        origin: tsukami_body::urdf_xml::RawPose {
            xyz: parse_vec3(&c.palm_xyz, "--palm-xyz")?,
            rpy: parse_vec3(&c.palm_rpy, "--palm-rpy")?,
        },
    };
    tsukami_body::compose::insert_frame(robot, root, &frame)?;
    Ok(())
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
        ..
    } = c;
    use tsukami_body::compose::{compose, read_raw, root_link, Attach};
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
    let hand_root = format!("{prefix}{}", root_link(&hand_raw)?);
    let mut robot = compose(
        arm_raw,
        hand_raw,
        &attach,
        (&folder(arm), &folder(hand), &out_dir),
    )?;
    add_palm_frame(c, &mut robot, &hand_root)?;
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

/// The description file of a robot folder or file, parsed, and its URDF's path.
fn read_description(
    robot: &Path,
) -> Result<(tsukami_planner_kit::description::Description, PathBuf)> {
    use tsukami_planner_kit::description::{Description, FILE_NAME};
    let file = if robot.is_dir() {
        robot.join(FILE_NAME)
    } else {
        robot.to_path_buf()
    };
    let text =
        std::fs::read_to_string(&file).with_context(|| format!("reading {}", file.display()))?;
    let description = Description::parse(&text, &file.display().to_string())?;
    let urdf = file
        .parent()
        .unwrap_or(Path::new("."))
        .join(&description.urdf);
    Ok((description, urdf))
}

/// `tsukami model allowed-collisions`: the robot's collision shapes with its
/// adjacent and already allowed pairs, then
/// `tsukami_body::collision_matrix::propose_allowed` over random postures.
fn allowed_collisions(robot: &Path, samples: usize, seed: u64, args: &LoadArgs) -> Result<()> {
    use tsukami_body::collision_matrix::{propose_allowed, to_toml};
    anyhow::ensure!(samples > 0, "--samples must be at least 1");
    let (description, urdf) = read_description(robot)?;
    let options = tsukami_body::urdf::LoadOptions {
        strict: args.strict,
        packages: tsukami_body::packages::PackagePath::default()
            .with_env()
            .with_dirs(args.package_dirs.iter().cloned()),
        ..Default::default()
    };
    let model = tsukami_body::urdf::load_urdf_with(&urdf, &options)?.model;
    let mut collision = tsukami_body::collision::RobotCollision::new(&model)?;
    for (k, [a, b]) in description.allowed_collisions.iter().enumerate() {
        let id = |n: &str| {
            model
                .link_id(n)
                .with_context(|| format!("allowed_collisions[{k}]: link `{n}` is not in the URDF"))
        };
        collision.allow(id(a)?, id(b)?);
    }
    let proposal = propose_allowed(&model, &collision, samples, seed);
    println!(
        "# tsukami model allowed-collisions {} --samples {samples} --seed {seed}",
        robot.display()
    );
    print!("{}", to_toml(&model, &proposal));
    eprintln!(
        "{} pairs proposed, {} kept checked ({} already allowed in the description)",
        proposal.pairs.len(),
        proposal.sometimes.len(),
        description.allowed_collisions.len()
    );
    Ok(())
}

/// `tsukami model grasp-types`: the robot description and URDF read as
/// `inspect` reads them, the first hand resolved, its grasp types derived
/// (`tsukami_planner_kit::grasp_derive`), checked against the model and written.
fn grasp_types(robot: &Path, out: Option<&Path>, args: &LoadArgs) -> Result<()> {
    use tsukami_planner_kit::grasp_derive::{derive, to_toml, DeriveOptions};
    use tsukami_planner_kit::grasp_types::GraspTypeConfig;
    let (description, urdf) = read_description(robot)?;
    let model = load(&urdf, args)?;
    let spec = &description.hands[0];
    let empty = GraspTypeConfig {
        hand: Default::default(),
        grasp_types: Vec::new(),
    };
    let hand = tsukami_planner_kit::Hand::new(&model, spec, 0, empty)?;
    let derived = derive(&model, &hand, &DeriveOptions::default())?;
    let mut header = vec![
        format!(
            "Grasp types of hand `{}` of robot `{}`, proposed by",
            spec.name, model.name
        ),
        format!("  tsukami model grasp-types {}", robot.display()),
        "from the hand's kinematics (tsukami_planner_kit::grasp_derive); review and edit.".into(),
        "Format: docs/grasp-types.md. Palm frame: the description's palm_link.".into(),
        "Measured (m, palm frame):".into(),
    ];
    header.extend(derived.notes.iter().map(|n| format!("  {n}")));
    let toml_text = to_toml(&derived.config, &header);
    let again = GraspTypeConfig::parse(&toml_text, "the proposal")?;
    again.check_against(&model)?;
    for n in &derived.notes {
        eprintln!("{n}");
    }
    match out {
        Some(o) => {
            std::fs::write(o, &toml_text).with_context(|| format!("writing {}", o.display()))?
        }
        None => print!("{toml_text}"),
    }
    eprintln!(
        "{} grasp types for hand `{}`",
        derived.config.grasp_types.len(),
        spec.name
    );
    Ok(())
}

/// Runs one `tsukami model` subcommand.
pub fn run(command: &ModelCommand) -> Result<()> {
    match command {
        ModelCommand::Compose(c) => compose(c),
        ModelCommand::AllowedCollisions {
            robot,
            samples,
            seed,
            load: args,
        } => allowed_collisions(robot, *samples, *seed, args),
        ModelCommand::GraspTypes {
            robot,
            out,
            load: args,
        } => grasp_types(robot, out.as_deref(), args),
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
