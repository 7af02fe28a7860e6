//! `tsukami demo`: the main job. Starts a private host with the workspace's plugins on
//! a free loopback port, talks to it over the bus like any client would, and prints
//! what it did.

use crate::bus::{free_loopback_port, BusConfig};
use crate::client::BusClient;
use crate::config::HostConfig;
use crate::server::RunningHost;
use anyhow::Result;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Options of `tsukami demo`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct DemoArgs {
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Runs the demo; the exit status is non-zero if anything did not work.
pub fn run(args: &DemoArgs) -> Result<ExitCode> {
    let port = free_loopback_port()?;
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let mut config = HostConfig::default_config()?;
    config.namespace = format!("tsukami-demo-{port}");
    config.bus = BusConfig::listening(&endpoint);

    let started = Instant::now();
    let host = RunningHost::start(&config)?;
    let client = BusClient::connect(&BusConfig::connecting(&endpoint), &config.namespace)?;
    let listing = client.wait_for_host(Duration::from_secs(10))?;
    let ready = started.elapsed();

    if args.json {
        println!("{}", serde_json::to_string_pretty(&listing)?);
    } else {
        println!("Tsukami host on {endpoint} (namespace `{}`), ready in {:.0} ms", config.namespace, ready.as_secs_f64() * 1e3);
        println!("plugin interface {}", listing.interface_version);
        println!("{:<20} {:<28} {:<8} {}", "role", "plugin", "version", "file");
        for plugin in &listing.plugins {
            println!("{:<20} {:<28} {:<8} {}", plugin.roles.join(","), plugin.name, plugin.version, plugin.path);
        }
    }
    client.close();
    host.shutdown();
    Ok(ExitCode::SUCCESS)
}
