//! Test fixture: a plugin that panics on the `panic` command.
//!
//! The host must turn the panic into an error reply and keep serving: `count`
//! answers how many calls the plugin has seen, proving its state survived.

use std::sync::atomic::{AtomicU64, Ordering};
use tsukami_plugin_api::{export_plugin, CallContext, CallError, Host, Plugin, PluginInfo};

/// Panics on `panic`, echoes on `echo`, counts calls on `count`.
pub struct Panicky {
    calls: AtomicU64,
}

impl Plugin for Panicky {
    fn info() -> PluginInfo {
        PluginInfo::new(
            "test-panicky",
            env!("CARGO_PKG_VERSION"),
            &["test-panicky"],
            "test fixture that panics on demand",
        )
    }

    fn new(_host: Host, _config: &str) -> Result<Self, String> {
        Ok(Panicky {
            calls: AtomicU64::new(0),
        })
    }

    fn call(
        &self,
        command: &str,
        payload: &[u8],
        _ctx: &CallContext<'_>,
    ) -> Result<Vec<u8>, CallError> {
        let calls = self.calls.fetch_add(1, Ordering::Relaxed) + 1;
        match command {
            "panic" => panic!("asked to panic (call {calls})"),
            "echo" => Ok(payload.to_vec()),
            "count" => Ok(format!("{{\"calls\":{calls}}}").into_bytes()),
            other => Err(CallError::unknown_command(other)),
        }
    }
}

export_plugin!(Panicky);
