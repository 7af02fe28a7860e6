//! Command-line interface (clap derive): the host, the bus client, the demo, and the
//! offline tools.

mod fc;
mod fc_problem;
mod fc_solve;
mod model;
mod model_report;
mod view;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use std::io::Read;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;
use tsukami::bus::{default_endpoint, BusConfig};
use tsukami::client::{BusClient, RequestError};
use tsukami::config::HostConfig;
use tsukami::server::RunningHost;
use tsukami_msgs::keys::{self, ROLE_GRASP_PLANNER};

/// Tsukami: grasp planning for humanoid robots with multi-fingered hands.
#[derive(Parser, Debug)]
#[command(name = "tsukami", version, about)]
struct Cli {
    #[command(flatten)]
    bus: BusArgs,
    #[command(subcommand)]
    command: Command,
}

/// How the client subcommands reach the bus.
#[derive(Args, Debug)]
struct BusArgs {
    /// Key-expression namespace.
    #[arg(long, global = true, default_value = keys::DEFAULT_NAMESPACE)]
    namespace: String,
    /// Endpoint of the host to connect to (loopback only without --zenoh-config).
    #[arg(long, global = true)]
    connect: Option<String>,
    /// A zenoh json5 config file; replaces the built-in loopback-only config.
    #[arg(long, global = true)]
    zenoh_config: Option<PathBuf>,
    /// How long to wait for a reply, milliseconds.
    #[arg(long, global = true, default_value_t = 30_000)]
    timeout_ms: u64,
}

impl BusArgs {
    fn client_bus(&self) -> BusConfig {
        let mut bus = BusConfig::connecting(self.connect.as_deref().unwrap_or(&default_endpoint()));
        bus.zenoh_config = self.zenoh_config.clone();
        bus
    }

    fn timeout(&self) -> Duration {
        Duration::from_millis(self.timeout_ms)
    }
}

/// A request payload: inline JSON, `--file F`, or `-` for standard input.
#[derive(Args, Debug)]
struct Payload {
    /// The request as JSON text, or `-` to read it from standard input.
    json: Option<String>,
    /// Read the request from this file.
    #[arg(long, conflicts_with = "json")]
    file: Option<PathBuf>,
}

impl Payload {
    fn bytes(&self) -> Result<Vec<u8>> {
        match (&self.json, &self.file) {
            (_, Some(file)) => {
                std::fs::read(file).with_context(|| format!("reading {}", file.display()))
            }
            (Some(text), None) if text == "-" => {
                let mut buf = Vec::new();
                std::io::stdin()
                    .read_to_end(&mut buf)
                    .context("reading standard input")?;
                Ok(buf)
            }
            (Some(text), None) => Ok(text.clone().into_bytes()),
            (None, None) => Ok(b"{}".to_vec()),
        }
    }
}

/// `set-object`: the request, and whether to send its mesh file inline.
#[derive(Args, Debug)]
struct SetObjectArgs {
    #[command(flatten)]
    payload: Payload,
    /// Send the file named by `shape.mesh.path` (on this machine) inline, as
    /// base64 in the request, for a host on another machine (`.stl`, `.obj`, `.ply`;
    /// the host refuses one over its `max_mesh_bytes` or `max_payload_bytes`).
    #[arg(long)]
    inline: bool,
}

impl SetObjectArgs {
    fn bytes(&self) -> Result<Vec<u8>> {
        let bytes = self.payload.bytes()?;
        if !self.inline {
            return Ok(bytes);
        }
        let mut req: tsukami_msgs::planner::SetObject = serde_json::from_slice(&bytes)
            .context("--inline: the payload is not a set_object request")?;
        let max = tsukami_body::files::SizeLimits::default().mesh;
        tsukami::inline::inline_local_mesh(&mut req, max)?;
        let out = serde_json::to_vec(&req)?;
        if out.len() > tsukami_bus::MAX_PAYLOAD_BYTES {
            eprintln!(
                "tsukami: the request is {} bytes; a host with the default max_payload_bytes ({}) refuses it",
                out.len(),
                tsukami_bus::MAX_PAYLOAD_BYTES
            );
        }
        Ok(out)
    }
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Serve the configured plugins on the bus until interrupted.
    Run {
        /// Host config file (TOML); without it, the built-in default.
        #[arg(long)]
        config: Option<PathBuf>,
        /// Override the listen endpoint(s) of the config.
        #[arg(long)]
        listen: Vec<String>,
    },
    /// List the host's plugins, versions and roles.
    Plugins,
    /// SetRobot: send the robot model and grasp-type config to the planner.
    SetRobot(Payload),
    /// SetObject: send the object to grasp.
    SetObject(SetObjectArgs),
    /// SetEnv: add or replace environment obstacles.
    SetEnv(Payload),
    /// RemoveEnv: remove environment obstacles.
    RemoveEnv(Payload),
    /// Plan: plan a grasp.
    Plan(Payload),
    /// Stop: cancel the planner's running call.
    Stop,
    /// Motion: plan a trajectory from the start to a grasp (`<ns>/motion/plan`;
    /// `{"grasp": <a Plan reply>, "seed"?, "start"?, "lift_height"?}`).
    Motion(Payload),
    /// Run a zenoh router on loopback until interrupted: the host, the components and
    /// the clients connect to it (`mode: "client"`) instead of to each other.
    Router {
        /// Endpoint to listen on (loopback only without --zenoh-config).
        #[arg(long, default_value_t = format!("tcp/127.0.0.1:{}", tsukami_bus::DEFAULT_ROUTER_PORT))]
        listen: String,
    },
    /// Write the JSON Schema of every bus payload.
    Schema {
        /// Output folder.
        #[arg(long, default_value = "docs/schema")]
        out: PathBuf,
    },
    /// Run the main job: the paper's scenes end to end (vision, grasp, motion,
    /// execution) on a private host with its plugins and the components.
    Demo(tsukami::demo::DemoArgs),
    /// Robot models: inspect, forward and inverse kinematics.
    Model {
        #[command(subcommand)]
        command: model::ModelCommand,
    },
    /// Force-closure tests and grasp quality of contact sets (JSON in, JSON out).
    Fc(fc::FcArgs),
    /// Draw a scene and a planned grasp: a PNG picture and optionally a glTF
    /// binary, headless (`--scene models/scenes/can_breast.toml --result reply.json`).
    View(view::ViewArgs),
}

/// Runs the CLI and maps errors to a message and exit status 1.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    if cli.command.prints_and_exits() {
        die_quietly_on_closed_stdout();
    }
    // The demo prints its own progress; the host's info lines would only clutter it,
    // as would zenoh's note that its (disabled) scouting found nobody.
    let default_filter = match cli.command {
        Command::Demo(_) => {
            "warn,zenoh::net::routing=error,zenoh::net::runtime::orchestrator=error"
        }
        _ => "warn,tsukami=info,zenoh::net::routing=error",
    };
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(default_filter)),
        )
        .with_writer(std::io::stderr)
        .init();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("tsukami: {e:#}");
            ExitCode::FAILURE
        }
    }
}

impl Command {
    /// A client command that prints its answer and ends (not the host, the
    /// router, the demo or the viewer, which serve or supervise).
    fn prints_and_exits(&self) -> bool {
        !matches!(
            self,
            Command::Run { .. } | Command::Router { .. } | Command::Demo(_) | Command::View(_)
        )
    }
}

/// `tsukami plan … | head` closes stdout early: end as `cat` does (the default
/// SIGPIPE action) instead of Rust's "failed printing to stdout" panic.
fn die_quietly_on_closed_stdout() {
    // SAFETY: setting a signal's disposition to its default before any other
    // thread exists; no handler runs.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn run(cli: Cli) -> Result<ExitCode> {
    let planner = |command: &str, payload: &Payload| -> Result<ExitCode> {
        send(&cli.bus, ROLE_GRASP_PLANNER, command, &payload.bytes()?)
    };
    match &cli.command {
        Command::Run { config, listen } => serve(config.as_deref(), listen, &cli.bus),
        Command::Plugins => {
            let client = BusClient::connect(&cli.bus.client_bus(), &cli.bus.namespace)?;
            let key = client.keys().host_plugins();
            print_reply(client.request_key(&key, b"", cli.bus.timeout()))
        }
        Command::SetRobot(p) => planner(keys::planner::SET_ROBOT, p),
        Command::SetObject(a) => send(
            &cli.bus,
            ROLE_GRASP_PLANNER,
            keys::planner::SET_OBJECT,
            &a.bytes()?,
        ),
        Command::SetEnv(p) => planner(keys::planner::SET_ENV, p),
        Command::RemoveEnv(p) => planner(keys::planner::REMOVE_ENV, p),
        Command::Plan(p) => planner(keys::planner::PLAN, p),
        Command::Stop => send(&cli.bus, ROLE_GRASP_PLANNER, keys::STOP, b""),
        Command::Motion(p) => send(&cli.bus, keys::ROLE_TRAJECTORY_PLANNER, "plan", &p.bytes()?),
        Command::Router { listen } => route(listen, &cli.bus),
        Command::Schema { out } => write_schema(out),
        Command::Demo(args) => tsukami::demo::run(args),
        Command::Model { command } => model::run(command).map(|()| ExitCode::SUCCESS),
        Command::Fc(args) => fc::run(args).map(|()| ExitCode::SUCCESS),
        Command::View(args) => view::run(args).map(|()| ExitCode::SUCCESS),
    }
}

fn serve(config: Option<&std::path::Path>, listen: &[String], bus: &BusArgs) -> Result<ExitCode> {
    let mut config = match config {
        Some(path) => HostConfig::from_file(path)?,
        None => HostConfig::default_config()?,
    };
    config.namespace = bus.namespace.clone();
    if !listen.is_empty() {
        config.bus.listen = listen.to_vec();
    }
    if bus.zenoh_config.is_some() {
        config.bus.zenoh_config = bus.zenoh_config.clone();
    }
    let host = RunningHost::start(&config)?;
    eprintln!(
        "tsukami: serving {} plugin(s) under `{}` on {:?}; Ctrl-C to stop",
        host.plugins().plugins.len(),
        config.namespace,
        config.bus.listen
    );
    for plugin in &host.plugins().plugins {
        eprintln!(
            "  {:<20} {} {}",
            plugin.roles.join(","),
            plugin.name,
            plugin.version
        );
    }
    // Serve until the process is interrupted: the workers and zenoh run on their own
    // threads; this one only waits.
    loop {
        std::thread::park();
    }
}

fn route(listen: &str, bus: &BusArgs) -> Result<ExitCode> {
    let mut config = BusConfig::router(listen);
    config.zenoh_config = bus.zenoh_config.clone();
    let shutdown = tsukami_bus::Shutdown::on_signals()?;
    let session = config.open()?;
    eprintln!("tsukami: zenoh router on {listen}; Ctrl-C to stop");
    shutdown.wait();
    use zenoh::Wait;
    session
        .close()
        .wait()
        .map_err(|e| anyhow::anyhow!("closing the router: {e}"))?;
    Ok(ExitCode::SUCCESS)
}

fn send(bus: &BusArgs, role: &str, command: &str, payload: &[u8]) -> Result<ExitCode> {
    let client = BusClient::connect(&bus.client_bus(), &bus.namespace)?;
    match client.command(role, command, payload, bus.timeout()) {
        Err(RequestError::Timeout { key, timeout }) => Err(timed_out(&client, bus, &key, timeout)),
        reply => print_reply(reply),
    }
}

/// How long the CLI asks `<ns>/host/plugins` whether a host is there, after a
/// request timed out.
const HOST_PROBE: Duration = Duration::from_secs(2);

/// What a timeout means: a host that is there but did not answer in time, or
/// no host on the bus at all (asked on `<ns>/host/plugins`).
fn timed_out(client: &BusClient, bus: &BusArgs, key: &str, timeout: Duration) -> anyhow::Error {
    let endpoint = bus.connect.clone().unwrap_or_else(default_endpoint);
    let ms = timeout.as_millis();
    match client.request_key(&client.keys().host_plugins(), b"", HOST_PROBE) {
        Ok(_) => anyhow::anyhow!(
            "the host on {endpoint} (namespace `{}`) is running but did not answer `{key}` within \
             {ms} ms (--timeout-ms); a plan can take longer: raise --timeout-ms, or bound the \
             plan with options.time_budget_ms",
            bus.namespace
        ),
        Err(_) => anyhow::anyhow!(
            "no host answered on {endpoint} (namespace `{}`): nothing replied to `{key}` within \
             {ms} ms, and nothing answers `{}`; is `tsukami run` serving there?",
            bus.namespace,
            client.keys().host_plugins()
        ),
    }
}

fn print_reply(reply: Result<Vec<u8>, RequestError>) -> Result<ExitCode> {
    match reply {
        Ok(bytes) => {
            println!("{}", pretty(&bytes));
            Ok(ExitCode::SUCCESS)
        }
        Err(RequestError::Reply(error) | RequestError::Conflict(error)) => {
            println!("{}", serde_json::to_string_pretty(&error)?);
            eprintln!("tsukami: {error}");
            Ok(ExitCode::FAILURE)
        }
        Err(other) => Err(other.into()),
    }
}

fn pretty(bytes: &[u8]) -> String {
    serde_json::from_slice::<serde_json::Value>(bytes)
        .and_then(|v| serde_json::to_string_pretty(&v))
        .unwrap_or_else(|_| String::from_utf8_lossy(bytes).into_owned())
}

fn write_schema(out: &std::path::Path) -> Result<ExitCode> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    for schema in tsukami_msgs::schema::all() {
        let path = out.join(format!("{}.schema.json", schema.name));
        std::fs::write(&path, schema.json)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    eprintln!(
        "tsukami: wrote {} schemas to {}",
        tsukami_msgs::schema::all().len(),
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}
