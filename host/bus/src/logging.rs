//! Logs of the component processes: `tracing` to standard error.
//!
//! Every component logs the same way as the host: `RUST_LOG` (an `EnvFilter`) picks
//! what is shown, with a default of warnings plus the component's own `info` events;
//! events carry their values as fields (`key=value`), so the logs can be filtered
//! and parsed.

/// Installs the global `tracing` subscriber for a component binary. `crate_target`
/// is the component crate's log target (e.g. `tsukami_controller`), shown at `info`.
/// Does nothing when a subscriber is already installed (tests).
pub fn init_logging(crate_target: &str) {
    let default = format!("warn,{crate_target}=info,tsukami_bus=info,zenoh::net::routing=error");
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(default));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .try_init();
}
