//! Test fixture: a plugin with a slow command, to test cancellation and timeouts.
//!
//! `work` `{"ms": N}` busy-waits up to N milliseconds in 1 ms steps, polling the
//! cancel flag between steps like a real planner; `echo` answers at once (the
//! round-trip benchmark uses it); `progress` publishes a progress event first.

use std::time::{Duration, Instant};
use tsukami_plugin_api::{export_plugin, CallContext, CallError, Host, Plugin, PluginInfo};

/// The slow fixture plugin.
pub struct Slow;

fn requested_ms(payload: &[u8]) -> Result<u64, CallError> {
    let text = std::str::from_utf8(payload)
        .map_err(|_| CallError::new("invalid_request", "payload is not UTF-8"))?;
    // The fixture avoids a JSON dependency: it reads the number after `"ms":`.
    let digits: String = text
        .split("\"ms\"")
        .nth(1)
        .unwrap_or("")
        .chars()
        .skip_while(|c| !c.is_ascii_digit())
        .take_while(|c| c.is_ascii_digit())
        .collect();
    digits
        .parse()
        .map_err(|_| CallError::new("invalid_request", "expected {\"ms\": <integer>}"))
}

impl Plugin for Slow {
    fn info() -> PluginInfo {
        PluginInfo::new(
            "test-slow",
            env!("CARGO_PKG_VERSION"),
            &["test-slow"],
            "test fixture with a slow, cancellable command",
        )
    }

    fn new(_host: Host, _config: &str) -> Result<Self, String> {
        Ok(Slow)
    }

    fn call(
        &self,
        command: &str,
        payload: &[u8],
        ctx: &CallContext<'_>,
    ) -> Result<Vec<u8>, CallError> {
        match command {
            "echo" => Ok(payload.to_vec()),
            "work" | "progress" => {
                let ms = requested_ms(payload)?;
                if command == "progress" {
                    ctx.host()
                        .progress(b"{\"phase\":\"work\",\"fraction\":0.0}");
                }
                let start = Instant::now();
                while start.elapsed() < Duration::from_millis(ms) {
                    if ctx.is_cancelled() {
                        return Err(CallError::cancelled(command));
                    }
                    std::thread::sleep(Duration::from_millis(1));
                }
                Ok(format!("{{\"worked_ms\":{}}}", start.elapsed().as_millis()).into_bytes())
            }
            other => Err(CallError::unknown_command(other)),
        }
    }
}

export_plugin!(Slow);
