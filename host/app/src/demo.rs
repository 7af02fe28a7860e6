//! `tsukami demo`: the main job. Starts a private host with the workspace's plugins on
//! a free loopback port, then runs each of the paper's scenes through the bus with
//! SetRobot / SetObject / SetEnv / Plan like any client would, and prints a table
//! (or JSON). The exit status is non-zero if any scene's outcome differs from the
//! paper's.

use crate::bus::{free_loopback_port, BusConfig};
use crate::client::BusClient;
use crate::config::{default_models_dir, HostConfig};
use crate::scenes::{run_scene, SceneOutcome};
use crate::server::RunningHost;
use anyhow::{bail, Result};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tsukami_scenes::PAPER_SCENES;

/// Options of `tsukami demo`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct DemoArgs {
    /// Run only this scene (`can_breast`, `can_waist`, `heavy_low`, `fridge_pet`, `vase_table`).
    #[arg(long)]
    pub scene: Option<String>,
    /// Random seed of the planner.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Print a JSON array of `{"scene", "expected", "ok", "result"}` instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Folder of the report: `report.md`, and per scene a picture (`SCENE.png`)
    /// and a glTF binary (`SCENE.glb`). Default: `target/demo-report`.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Where the report goes without `--out`.
pub const DEFAULT_REPORT_DIR: &str = "target/demo-report";

/// Runs the demo.
pub fn run(args: &DemoArgs) -> Result<ExitCode> {
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

    let port = free_loopback_port()?;
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let mut config = HostConfig::default_config()?;
    config.namespace = format!("tsukami-demo-{port}");
    config.bus = BusConfig::listening(&endpoint);
    let models = default_models_dir();

    let started = Instant::now();
    let host = RunningHost::start(&config)?;
    let client = BusClient::connect(&BusConfig::connecting(&endpoint), &config.namespace)?;
    let listing = client.wait_for_host(Duration::from_secs(10))?;
    let ready_ms = started.elapsed().as_secs_f64() * 1e3;

    let outcomes: Vec<SceneOutcome> = scenes
        .iter()
        .map(|scene| run_scene(&client, &models, scene, args.seed, Duration::from_secs(60)))
        .collect();

    if args.json {
        println!("{}", serde_json::to_string_pretty(&outcomes)?);
    } else {
        println!(
            "Tsukami host on {endpoint}, namespace `{}`, ready in {ready_ms:.0} ms; plugins:",
            config.namespace
        );
        for plugin in &listing.plugins {
            println!(
                "  {:<20} {} {}",
                plugin.roles.join(","),
                plugin.name,
                plugin.version
            );
        }
        println!();
        print_table(&outcomes);
    }
    client.close();
    host.shutdown();
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_REPORT_DIR));
    let report = crate::demo_report::write_report(&out, &models, &outcomes, args.seed)?;
    if !args.json {
        println!("\nReport, pictures and .glb files: {}", report.display());
    }
    let all_ok = outcomes.iter().all(|o| o.ok);
    Ok(if all_ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// One scene's table cells: grasp type, OCP region and face, whole-body
/// joints, margin, and the independent check's verdict with the weight.
pub(crate) fn cells(o: &SceneOutcome) -> [String; 5] {
    let Some(r) = &o.result else {
        return ["-", "-", "-", "-", "-"].map(str::to_owned);
    };
    let face = serde_json::to_value(r.face)
        .ok()
        .and_then(|v| v.as_str().map(str::to_owned))
        .unwrap_or_default();
    let joints = if r.joints_used.is_empty() {
        "arm only".to_owned()
    } else {
        r.joints_used.join(",")
    };
    // Recomputed by the independent check, never the planner's flag.
    let exact = match o.weight_scale {
        Some(s) if s >= 1.0 => "holds",
        Some(_) => "FAILS",
        None => "-",
    };
    [
        r.grasp_type.name.clone(),
        format!("{}:{face}", r.ocp_region),
        joints,
        format!("{:.3}", r.force_closure.margin),
        exact.to_owned(),
    ]
}

fn print_table(outcomes: &[SceneOutcome]) {
    println!(
        "{:<11} {:<16} {:<6} {:<31} {:>7} {:>6} {:>9}  paper",
        "scene", "grasp type", "face", "whole-body joints", "margin", "exact", "plan ms"
    );
    for o in outcomes {
        let [grasp, face, joints, margin, exact] = cells(o);
        let verdict = if o.ok { "ok" } else { "DIFFERS" };
        println!(
            "{:<11} {:<16} {:<6} {:<31} {:>7} {:>6} {:>9.1}  {verdict}: {}",
            o.scene, grasp, face, joints, margin, exact, o.plan_ms, o.expected
        );
        if let Some(arm_only) = &o.arm_only {
            println!("{:<11} arm alone: {arm_only}", "");
        }
        if let Some(problem) = &o.problem {
            println!("{:<11} problem: {problem}", "");
        }
    }
}
