//! `tsukami demo`: the main job — the paper's experiments end to end, through the bus.
//!
//! What: starts a private host with its plugins (grasp planner, trajectory
//! planner) on a free loopback port, and for each of the paper's scenes the vision
//! and controller components as child processes on the same bus; then, per scene,
//! like any client would:
//! 1. **vision**: `<ns>/vision/look` finds the object with the simulated head
//!    camera rendering the scene — the head aimed at it, the body and arms out of
//!    the view, other views (crouched, leaning, turned) where one does not see
//!    it; its pose is compared with the scene file's;
//! 2. **grasp**: SetRobot / SetObject / SetEnv / Plan with the pose the vision saw
//!    (the default, `--plan-on vision`; the scene file's where it did not find
//!    the object) or, with `--plan-on scene`, the scene file's object pose (the
//!    truth); judged against the paper on the scene file's object either way;
//! 3. **motion**: `<ns>/motion/plan` from the controller's state (rest) to the
//!    grasp and on to the lift;
//! 4. **execution**: the controller runs it; the state it publishes at the end of
//!    `close` must be the planned grasp posture, and at the end of the lift the
//!    trajectory's last point.
//!
//! It prints one table row per scene (or JSON), writes a report, and exits
//! non-zero if any scene's outcome differs from the paper's or its motion fails
//! to plan or execute. A component binary missing beside `tsukami` is said once,
//! and its steps are marked "not run".
//!
//! How: the host runs in this process; the demo's client listens on a port of its
//! own so that the components, connecting to the host's and the client's ports,
//! reach both (zenoh peers do not forward for each other). Components are started
//! afresh for each scene (the vision's camera renders one scene file; the
//! controller starts at rest) and killed when it ends ([`children`]). Every
//! request has a timeout. The files of the demo import downwards only: this
//! root uses [`outcome`], `table`, [`report`] and the steps' files; none of
//! them imports this file (`host/app/tests/module_cycles.rs` checks).

pub mod children;
pub mod motion;
pub mod outcome;
pub mod report;
mod status;
pub mod step;
mod table;
pub mod vision;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use tsukami_msgs::host::PluginsReply;
use tsukami_msgs::keys::{ROLE_RESULT_VIEWER, ROLE_TRAJECTORY_PLANNER};
use tsukami_msgs::planner::ObjectShape;
use tsukami_scenes::{scene_requests, PaperScene, PAPER_SCENES};

use crate::bus::{free_loopback_port, BusConfig};
use crate::client::BusClient;
use crate::config::{default_models_dir, HostConfig};
use crate::scenes::{run_scene_at, SceneOutcome};
use crate::server::RunningHost;
use children::{locate, ComponentProcess, Supervisor};
use motion::{ExecutionRun, MotionCheck};
pub use outcome::{DemoScene, PlanOn};
use status::Status;
use step::{Step, StepStatus};
use vision::VisionCheck;

/// Options of `tsukami demo`.
#[derive(clap::Args, Debug, Clone)]
pub struct DemoArgs {
    /// Run only this scene (`can_breast`, `can_waist`, `heavy_low`, `fridge_pet`, `vase_table`).
    #[arg(long)]
    pub scene: Option<String>,
    /// Random seed of the planners and of the camera's noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Print a JSON array, one object per scene: the grasp (`scene`, `expected`,
    /// `ok`, `result`, …) and the `vision`, `motion` and `execution` steps.
    #[arg(long)]
    pub json: bool,
    /// Folder of the report: `report.md`, per scene a picture (`SCENE.png`) and a
    /// glTF binary (`SCENE.glb`), and the components' logs (`logs/`).
    /// Default: `target/demo-report`.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// How much faster than real time the controller executes (1 = real time).
    #[arg(long, default_value_t = 10.0)]
    pub speed: f64,
    /// The object pose the grasp is planned on: where the vision component saw
    /// it (`vision`; the scene file's when it did not find it, said in the
    /// table), or the scene file's (`scene`). Either way the grasp is judged on
    /// the scene file's object.
    #[arg(long, value_enum, default_value_t = PlanOn::Vision)]
    pub plan_on: PlanOn,
    /// Folder holding the component binaries (`tsukami-vision`,
    /// `tsukami-controller`). Default: the `tsukami` binary's own folder.
    #[arg(long)]
    pub components_dir: Option<PathBuf>,
}

impl Default for DemoArgs {
    fn default() -> Self {
        DemoArgs {
            scene: None,
            seed: 0,
            json: false,
            out: None,
            speed: 10.0,
            plan_on: PlanOn::Vision,
            components_dir: None,
        }
    }
}

/// Where the report goes without `--out`.
pub const DEFAULT_REPORT_DIR: &str = "target/demo-report";

/// Timeout of every request but `execute` (whose own is the motion's duration
/// plus a margin).
const REQUEST_TIMEOUT: Duration = Duration::from_secs(120);

/// How long the trajectory planner waits for the controller's state.
const CONTROLLER_STATE_TIMEOUT: Duration = Duration::from_secs(5);

/// How long a component may take to answer on the bus after it was started.
const COMPONENT_READY: Duration = Duration::from_secs(60);

/// Runs the demo.
pub fn run(args: &DemoArgs) -> Result<ExitCode> {
    let scenes = selected(args)?;
    if !(args.speed.is_finite() && args.speed > 0.0) {
        bail!("--speed {}: must be a positive number", args.speed);
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_REPORT_DIR));
    let logs = out.join("logs");
    std::fs::create_dir_all(&logs).with_context(|| format!("creating {}", logs.display()))?;
    let supervisor = Supervisor::new();
    if let Err(e) = supervisor.kill_on_signals() {
        tracing::warn!("the demo's components may outlive an interrupt: {e:#}");
    }

    let started = Instant::now();
    let (host, config) = start_host()?;
    let host_endpoint = config.bus.listen[0].clone();
    let client_endpoint = format!("tcp/127.0.0.1:{}", free_loopback_port()?);
    let client_bus = BusConfig {
        connect: vec![host_endpoint.clone()],
        ..BusConfig::listening(&client_endpoint)
    };
    let client = BusClient::connect(&client_bus, &config.namespace)?;
    let listing = client.wait_for_host(Duration::from_secs(30))?;
    let demo = Demo {
        args,
        namespace: config.namespace.clone(),
        connect: vec![host_endpoint.clone(), client_endpoint],
        models: default_models_dir(),
        logs,
        vision_exe: locate(args.components_dir.as_deref(), "tsukami-vision"),
        controller_exe: locate(args.components_dir.as_deref(), "tsukami-controller"),
        supervisor,
        status: Status::on_stderr(),
        client,
    };
    if !args.json {
        let ready_ms = started.elapsed().as_secs_f64() * 1e3;
        println!(
            "Tsukami host on {host_endpoint}, namespace `{}`, ready in {ready_ms:.0} ms; plugins:",
            config.namespace
        );
        demo.print_header(&listing);
    }
    let mut results = Vec::new();
    for scene in scenes {
        let result = demo.scene(scene);
        demo.status.clear();
        if !args.json {
            println!("{}", table::row(&result));
            for note in table::notes(&result) {
                println!("{:<11} {note}", "");
            }
        }
        results.push(result);
    }
    demo.status.clear();
    if args.json {
        println!("{}", serde_json::to_string_pretty(&results)?);
    }
    demo.client.close();
    host.shutdown();
    let report = report::write_report(&out, &demo.models, &results, args.seed)?;
    if !args.json {
        println!(
            "\nReport, pictures, .glb files and the components' logs: {}",
            report.display()
        );
    }
    Ok(if results.iter().all(DemoScene::passed) {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

fn selected(args: &DemoArgs) -> Result<Vec<&'static PaperScene>> {
    let scenes: Vec<_> = PAPER_SCENES
        .iter()
        .filter(|s| args.scene.as_deref().is_none_or(|n| n == s.name))
        .collect();
    if scenes.is_empty() {
        let names: Vec<_> = PAPER_SCENES.iter().map(|s| s.name).collect();
        bail!(
            "no scene `{}`; the scenes are {names:?}",
            args.scene.as_deref().unwrap_or_default()
        );
    }
    Ok(scenes)
}

/// The default host config (grasp and trajectory planner) on a free loopback
/// port, under a namespace of its own, started.
fn start_host() -> Result<(RunningHost, HostConfig)> {
    let port = free_loopback_port()?;
    let mut config = HostConfig::default_config()?;
    // The motion starts from the controller's state: give a loaded machine time
    // to answer (the plugin's default, 200 ms, falls back to rest after it).
    for entry in &mut config.plugins {
        if entry.role == ROLE_TRAJECTORY_PLANNER {
            let table = entry.config.get_or_insert_with(toml::Table::new);
            let ms = CONTROLLER_STATE_TIMEOUT.as_millis() as i64;
            table.insert("controller_timeout_ms".into(), ms.into());
        }
    }
    config.namespace = format!("tsukami-demo-{port}");
    config.bus = BusConfig::listening(&format!("tcp/127.0.0.1:{port}"));
    let host = RunningHost::start(&config)?;
    Ok((host, config))
}

/// A component of a scene: running, or why not.
enum Started {
    Running(ComponentProcess),
    /// Its binary is not there: the steps needing it are not run.
    Missing(String),
    /// It could not be started: the steps needing it fail.
    Failed(String),
}

/// The running demo: its bus client, and how to start the components.
struct Demo<'a> {
    args: &'a DemoArgs,
    client: BusClient,
    namespace: String,
    /// What the components connect to: the host's and the client's endpoints.
    connect: Vec<String>,
    models: PathBuf,
    logs: PathBuf,
    vision_exe: Result<PathBuf, String>,
    controller_exe: Result<PathBuf, String>,
    supervisor: Supervisor,
    status: Status,
}

impl Demo<'_> {
    /// The plugins, the components, and the table's header.
    fn print_header(&self, listing: &PluginsReply) {
        for plugin in &listing.plugins {
            let roles = plugin.roles.join(",");
            println!("  {roles:<20} {} {}", plugin.name, plugin.version);
        }
        if let Some(url) = self.live_view(listing) {
            println!(
                "Live view: {url} (the result viewer follows each grasp and the robot as it moves; \
                 --speed 1 to watch in real time)"
            );
        }
        println!("Components, started for each scene on the same bus:");
        let rows = [
            ("vision", &self.vision_exe, "simulated head camera"),
            ("controller", &self.controller_exe, "speed"),
        ];
        for (name, exe, what) in rows {
            match exe {
                Ok(path) if what == "speed" => println!(
                    "  {name:<20} {} ({}x real time)",
                    path.display(),
                    self.args.speed
                ),
                Ok(path) => println!("  {name:<20} {} ({what})", path.display()),
                Err(why) => println!("  {name:<20} NOT RUN: {why}"),
            }
        }
        println!("{}", match self.args.plan_on {
            PlanOn::Scene => "Grasps are planned on each scene file's object pose; the vision error is measured against it.",
            PlanOn::Vision => "The vision looks for each object (head aimed, arms and body out of the view, other views where one does not see it); grasps are planned where it saw the object (on the scene file's pose where it did not find it); judged on the scene file's.",
        });
        println!("\n{}", table::header());
    }

    /// The result viewer's web page, when the host has the viewer and it serves one.
    fn live_view(&self, listing: &PluginsReply) -> Option<String> {
        listing
            .plugins
            .iter()
            .any(|p| p.roles.iter().any(|r| r == ROLE_RESULT_VIEWER))
            .then_some(())?;
        let timeout = Duration::from_secs(5);
        let reply = self
            .client
            .command(ROLE_RESULT_VIEWER, "state", b"{}", timeout)
            .ok()?;
        let state: serde_json::Value = serde_json::from_slice(&reply).ok()?;
        state["web"]["url"].as_str().map(str::to_owned)
    }

    /// Starts component `name` for `scene` with `args` after the bus options.
    fn start(
        &self,
        name: &str,
        exe: &Result<PathBuf, String>,
        args: &[&str],
        scene: &str,
    ) -> Started {
        let exe = match exe {
            Ok(exe) => exe,
            Err(why) => return Started::Missing(why.clone()),
        };
        let mut all: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        all.extend(["--namespace".to_owned(), self.namespace.clone()]);
        for endpoint in &self.connect {
            all.extend(["--connect".to_owned(), endpoint.clone()]);
        }
        let log = self.logs.join(format!("{name}-{scene}.log"));
        match self.supervisor.spawn(name, exe, &all, &log) {
            Ok(process) => Started::Running(process),
            Err(e) => Started::Failed(e),
        }
    }

    /// Waits for a started component; a step of the ones needing it when it is
    /// not there.
    fn ready<T>(&self, started: &Started) -> Result<(), Step<T>> {
        match started {
            Started::Missing(why) => Err(Step::not_run(why.clone())),
            Started::Failed(why) => Err(Step::failed(why.clone(), None)),
            Started::Running(process) => process
                .wait_ready(&self.client, COMPONENT_READY)
                .map_err(|e| Step::failed(e, None)),
        }
    }

    /// Runs one scene: vision, grasp, motion, execution.
    fn scene(&self, scene: &PaperScene) -> DemoScene {
        let name = scene.name;
        let file = self.models.join("scenes").join(format!("{name}.toml"));
        self.status
            .step(name, "starting the vision and controller components");
        let (models, file_arg) = (
            self.models.display().to_string(),
            file.display().to_string(),
        );
        let speed = self.args.speed.to_string();
        let vision_args = ["serve", "--models", &models, "--scene", &file_arg];
        let vision_process = self.start("vision", &self.vision_exe, &vision_args, name);
        let controller_args = ["--models-dir", &models, "--speed", &speed];
        let controller = self.start("controller", &self.controller_exe, &controller_args, name);

        let vision = self.vision(name, &file, &vision_process);
        drop(vision_process);
        let seen = match (&vision.data, vision.status, self.args.plan_on) {
            (Some(v), StepStatus::Ok, PlanOn::Vision) => Some(v.plan_pose),
            _ => None,
        };
        let planned_on = if seen.is_some() {
            PlanOn::Vision
        } else {
            PlanOn::Scene
        };
        self.status.step(name, "planning the grasp");
        let (seed, models) = (self.args.seed, &self.models);
        let plan = run_scene_at(&self.client, models, scene, seed, REQUEST_TIMEOUT, seen);
        let (motion, execution) = self.motion(&plan, &controller);
        DemoScene {
            plan,
            plan_on: self.args.plan_on,
            planned_on,
            vision,
            motion,
            execution,
        }
    }

    fn vision(&self, scene: &str, file: &Path, process: &Started) -> Step<VisionCheck> {
        self.status.step(scene, "waiting for the vision component");
        if let Err(step) = self.ready(process) {
            return step;
        }
        let requests = match scene_requests(file) {
            Ok(r) => r,
            Err(e) => return Step::failed(e.to_string(), None),
        };
        let ObjectShape::Model { name: object } = &requests.object.shape else {
            return Step::not_run("the scene's object is not a model the vision knows");
        };
        self.status.step(scene, "vision: looking for the object");
        let truth = &requests.object.pose;
        Step::from_result(vision::detect(
            &self.client,
            object,
            truth,
            self.args.seed,
            REQUEST_TIMEOUT,
        ))
    }

    fn motion(
        &self,
        plan: &SceneOutcome,
        controller: &Started,
    ) -> (Step<MotionCheck>, Step<ExecutionRun>) {
        let scene = plan.scene.as_str();
        let Some(grasp) = &plan.result else {
            return (Step::not_run("no grasp"), Step::not_run("no grasp"));
        };
        // The motion starts from the controller's state: wait for it first.
        self.status.step(scene, "waiting for the controller");
        let controller_ready = self.ready::<ExecutionRun>(controller);
        self.status.step(scene, "planning the motion");
        let (motion, trajectory) =
            match motion::plan(&self.client, grasp, self.args.seed, REQUEST_TIMEOUT) {
                Ok((check, trajectory)) => (Step::ok(check), trajectory),
                Err(e) => return (Step::failed(e, None), Step::not_run("no motion")),
            };
        if let Err(step) = controller_ready {
            return (motion, step);
        }
        let duration = motion.data.as_ref().map_or(0.0, |m| m.duration_s);
        self.status.step(
            scene,
            &format!(
                "executing {duration:.1} s of motion at {}x real time",
                self.args.speed
            ),
        );
        let execution = motion::execute(&self.client, &trajectory, grasp, self.args.speed);
        (motion, execution)
    }
}
