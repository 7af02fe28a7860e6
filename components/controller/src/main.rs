//! `tsukami-controller`: the robot-controller component.
//!
//! ```sh
//! tsukami-controller --robot tsukami_humanoid --models-dir models      # real time, default host bus
//! tsukami-controller --speed 20 --connect tcp/127.0.0.1:7448          # 20x faster than real time
//! ```
//!
//! It serves until SIGINT or SIGTERM, then ends a running trajectory as a fault,
//! answers its caller and leaves the bus.

use anyhow::{Context, Result};
use clap::Parser;
use std::path::PathBuf;
use std::process::ExitCode;
use tsukami_bus::{ComponentArgs, Shutdown};
use tsukami_controller::{Executor, JointTable, NodeOptions};

/// The robot controller: executes joint trajectories and publishes the joint state.
#[derive(Parser, Debug)]
#[command(name = "tsukami-controller", version, about)]
struct Cli {
    #[command(flatten)]
    bus: ComponentArgs,
    /// The robot: a model name (`<models-dir>/robots/<name>/<name>.urdf`) or a .urdf file.
    #[arg(long, default_value = "tsukami_humanoid")]
    robot: String,
    /// Folder of the robot models.
    #[arg(long, default_value = "models")]
    models_dir: PathBuf,
    /// Control rate, Hz: one state is published per period (100 to 10000).
    #[arg(long, default_value_t = 100.0)]
    rate_hz: f64,
    /// Controller time per wall-clock time while executing: 1 is real time, 10 is ten
    /// times faster, `inf` as fast as possible.
    #[arg(long, default_value_t = 1.0)]
    speed: f64,
    /// How far (rad or m) a trajectory's first point may be from the current state.
    #[arg(long, default_value_t = 0.01)]
    start_tolerance: f64,
    /// Initial joint positions as JSON, e.g. '{"r_elbow": -1.0}'; the other joints
    /// start at rest (0 clamped into their limits).
    #[arg(long)]
    initial: Option<String>,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    tsukami_bus::init_logging("tsukami_controller");
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tsukami-controller: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    anyhow::ensure!(
        (100.0..=10_000.0).contains(&cli.rate_hz),
        "--rate-hz {} must be between 100 and 10000",
        cli.rate_hz
    );
    let shutdown = Shutdown::on_signals()?;
    let table = JointTable::load(&cli.robot, &cli.models_dir)?;
    let initial = match &cli.initial {
        Some(text) => {
            let map = serde_json::from_str(text)
                .context("--initial is not a JSON object of joint values")?;
            Some(table.positions_from_map(&map).map_err(anyhow::Error::msg)?)
        }
        None => None,
    };
    let robot = table.robot().to_owned();
    let joints = table.len();
    let executor = Executor::new(table, cli.rate_hz, initial).map_err(anyhow::Error::msg)?;
    let options = NodeOptions {
        speed: cli.speed,
        start_tolerance: cli.start_tolerance,
    };
    let node = tsukami_controller::start(&cli.bus, executor, options)?;
    tracing::info!(
        robot,
        joints,
        rate_hz = cli.rate_hz,
        speed = cli.speed,
        namespace = cli.bus.namespace,
        "controller serving; Ctrl-C to stop"
    );
    shutdown.wait();
    node.shutdown();
    Ok(())
}
