//! The plugin interface of Tsukami: the one crate both the host and every plugin link.
//!
//! # What
//! A Tsukami plugin is a `cdylib` that fills one or more *roles* (`grasp-planner`,
//! `trajectory-planner`, `result-viewer`, or a third-party role). The host loads it,
//! routes the bus commands of its roles to it, and gives it a [`Host`] handle to reach
//! the bus. This crate is the contract between the two.
//!
//! # Why it looks like this
//! The surface that crosses the library boundary is tiny and frozen ([`ffi`]): a
//! root module with `info()` and `new(host, config)`, a plugin object with one
//! `call(command, payload, cancel)` method, and a host object with `publish`,
//! `request`, `subscribe`, `log` and `progress`. Only command names and serialized
//! JSON bytes cross it (`RStr`, `RSlice<u8>`, `RVec<u8>`): no nalgebra, parry or
//! zenoh type, no `Arc<dyn …>`. The same bytes travel over zenoh, so one schema
//! (`tsukami-msgs`) serves in-process and cross-process traffic. abi_stable checks
//! the layout of everything that crosses at load time and the host refuses a plugin
//! built against an incompatible interface version ([`loader`]).
//!
//! # How to write a plugin
//! Implement [`Plugin`] in plain Rust and export it with [`export_plugin!`]; the
//! crate needs `crate-type = ["cdylib", "rlib"]` and `abi_stable` as a dependency
//! (the export macro expands to abi_stable's root-module export).
//!
//! ```no_run
//! use tsukami_plugin_api::{export_plugin, CallContext, CallError, Host, Plugin, PluginInfo};
//!
//! pub struct Echo;
//!
//! impl Plugin for Echo {
//!     fn info() -> PluginInfo {
//!         PluginInfo::new("echo", env!("CARGO_PKG_VERSION"), &["echo"], "replies with its input")
//!     }
//!     fn new(_host: Host, _config: &str) -> Result<Self, String> {
//!         Ok(Echo)
//!     }
//!     fn call(&self, command: &str, payload: &[u8], _ctx: &CallContext<'_>) -> Result<Vec<u8>, CallError> {
//!         match command {
//!             "echo" => Ok(payload.to_vec()),
//!             other => Err(CallError::unknown_command(other)),
//!         }
//!     }
//! }
//!
//! export_plugin!(Echo);
//! # fn main() {}
//! ```
//!
//! # Lifecycle
//! `load` (version and layout checked) → `info()` → `new(host, config)` → any number of
//! `call`s, **one at a time** unless the plugin declares the `concurrent` capability
//! (then the host may run as many at once as its config gives the plugin workers;
//! `call` takes `&self` either way) → dropped when the host shuts down. Libraries are never
//! unloaded. A panic inside `info`, `new` or `call` is caught inside the plugin's own
//! library and returned as an error ([`CallError::PANICKED`]); the host keeps serving.
//! A running call is cancelled by the host setting the call's cancel flag, which the
//! plugin polls through [`CallContext::is_cancelled`].

mod export;
pub mod ffi;
pub mod loader;
pub mod offline;
mod safe;

pub use safe::{CallContext, CallError, Host, LogLevel, Plugin, PluginInfo, Subscription};

/// The interface version this crate defines; a plugin must be built against a
/// compatible one (same minor version while the major is 0).
pub const INTERFACE_VERSION: &str = env!("CARGO_PKG_VERSION");

#[doc(hidden)]
pub mod __private {
    pub use crate::export::{plugin_module, PluginAdapter};
    pub use abi_stable;
}
