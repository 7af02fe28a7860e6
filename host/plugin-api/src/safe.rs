//! The plain-Rust side of the interface: what a plugin author implements and uses.

use crate::ffi::{FfiCallError, FfiHostBox, FfiPluginInfo, FfiSubscriptionBox};
use abi_stable::std_types::{RResult, RSlice, RStr, RString, RVec};
use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// What a plugin says about itself.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PluginInfo {
    /// The plugin's name.
    pub name: String,
    /// The plugin's own version.
    pub version: String,
    /// Roles it can fill.
    pub roles: Vec<String>,
    /// One-line description.
    pub description: String,
    /// What the plugin declares it can do: [`PluginInfo::WORLD`],
    /// [`PluginInfo::CONCURRENT`].
    pub capabilities: Vec<String>,
}

impl PluginInfo {
    /// Capability: the plugin shares the host's world (it answers
    /// `world_prepare`, `world_commit`, `world_abort`; see `docs/plugins.md`).
    pub const WORLD: &'static str = "world";
    /// Capability: the host may run several calls of the plugin at once.
    pub const CONCURRENT: &'static str = "concurrent";

    /// The same info declaring `capabilities`.
    pub fn with_capabilities(mut self, capabilities: &[&str]) -> Self {
        self.capabilities = capabilities.iter().map(|c| (*c).to_owned()).collect();
        self
    }

    /// True if the plugin declares `capability`.
    pub fn has(&self, capability: &str) -> bool {
        self.capabilities.iter().any(|c| c == capability)
    }

    /// Builds the info from plain strings.
    pub fn new(name: &str, version: &str, roles: &[&str], description: &str) -> Self {
        PluginInfo {
            name: name.to_owned(),
            version: version.to_owned(),
            roles: roles.iter().map(|r| (*r).to_owned()).collect(),
            description: description.to_owned(),
            capabilities: Vec::new(),
        }
    }

    pub(crate) fn to_ffi(&self) -> FfiPluginInfo {
        FfiPluginInfo {
            name: self.name.as_str().into(),
            version: self.version.as_str().into(),
            roles: self
                .roles
                .iter()
                .map(|r| RString::from(r.as_str()))
                .collect(),
            description: self.description.as_str().into(),
            capabilities: self
                .capabilities
                .iter()
                .map(|c| RString::from(c.as_str()))
                .collect(),
        }
    }

    pub(crate) fn from_ffi(info: &FfiPluginInfo) -> Self {
        PluginInfo {
            name: info.name.to_string(),
            version: info.version.to_string(),
            roles: info.roles.iter().map(|r| r.to_string()).collect(),
            description: info.description.to_string(),
            capabilities: info.capabilities.iter().map(|c| c.to_string()).collect(),
        }
    }
}

/// An error from a plugin call: a machine-readable code (the wire names of
/// `tsukami_msgs::ErrorCode`), a message for people and optional JSON details.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CallError {
    /// Machine-readable code, e.g. `invalid_value`.
    pub code: String,
    /// What went wrong, naming the field or file.
    pub message: String,
    /// Extra details as JSON text, or empty.
    pub details_json: String,
}

impl CallError {
    /// Code of an error made from a caught panic.
    pub const PANICKED: &'static str = "plugin_panicked";
    /// Code of an unknown command.
    pub const UNKNOWN_COMMAND: &'static str = "unknown_command";
    /// Code of a cancelled call.
    pub const CANCELLED: &'static str = "cancelled";

    /// An error with a code and message.
    pub fn new(code: &str, message: impl Into<String>) -> Self {
        CallError {
            code: code.to_owned(),
            message: message.into(),
            details_json: String::new(),
        }
    }

    /// The error for a command the plugin does not know.
    pub fn unknown_command(command: &str) -> Self {
        CallError::new(
            CallError::UNKNOWN_COMMAND,
            format!("unknown command `{command}`"),
        )
    }

    /// The error for a call stopped through its cancel flag.
    pub fn cancelled(command: &str) -> Self {
        CallError::new(CallError::CANCELLED, format!("`{command}` was stopped"))
    }

    pub(crate) fn to_ffi(&self) -> FfiCallError {
        FfiCallError {
            code: self.code.as_str().into(),
            message: self.message.as_str().into(),
            details_json: self.details_json.as_str().into(),
        }
    }

    pub(crate) fn from_ffi(err: FfiCallError) -> Self {
        CallError {
            code: err.code.into_string(),
            message: err.message.into_string(),
            details_json: err.details_json.into_string(),
        }
    }
}

impl fmt::Display for CallError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.code, self.message)
    }
}

impl std::error::Error for CallError {}

/// Log levels a plugin may write at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[repr(u8)]
pub enum LogLevel {
    /// Something failed.
    Error = 0,
    /// Something looks wrong.
    Warn = 1,
    /// Normal operation.
    Info = 2,
    /// Details for developers.
    Debug = 3,
    /// Very fine details.
    Trace = 4,
}

impl LogLevel {
    /// Decodes the FFI byte; unknown values are treated as `Trace`.
    pub fn from_u8(level: u8) -> LogLevel {
        match level {
            0 => LogLevel::Error,
            1 => LogLevel::Warn,
            2 => LogLevel::Info,
            3 => LogLevel::Debug,
            _ => LogLevel::Trace,
        }
    }
}

/// The plugin's handle on the host: the bus, logging and progress.
///
/// Cheap to clone; every clone talks to the same host. Keys are relative to the
/// host's namespace (`planner/progress`, `vision/detect`, …).
#[derive(Clone)]
pub struct Host {
    inner: FfiHostBox,
}

impl Host {
    /// Wraps the FFI host object (the host side builds it; plugins receive it in `new`).
    pub fn from_ffi(inner: FfiHostBox) -> Self {
        Host { inner }
    }

    /// Publishes `payload` on `<ns>/<key>`.
    pub fn publish(&self, key: &str, payload: &[u8]) -> Result<(), String> {
        self.inner
            .publish(RStr::from(key), RSlice::from(payload))
            .into_result()
            .map_err(RString::into_string)
    }

    /// Queries `<ns>/<key>` and waits at most `timeout` for the reply bytes; an
    /// error reply from the other side comes back as its [`CallError`].
    pub fn request(
        &self,
        key: &str,
        payload: &[u8],
        timeout: Duration,
    ) -> Result<Vec<u8>, CallError> {
        let timeout_ms = u64::try_from(timeout.as_millis()).unwrap_or(u64::MAX);
        self.inner
            .request(RStr::from(key), RSlice::from(payload), timeout_ms)
            .into_result()
            .map(RVec::into_vec)
            .map_err(CallError::from_ffi)
    }

    /// Subscribes to `<ns>/<key>` (wildcards allowed).
    pub fn subscribe(&self, key: &str) -> Result<Subscription, String> {
        self.inner
            .subscribe(RStr::from(key))
            .into_result()
            .map(|inner| Subscription { inner })
            .map_err(RString::into_string)
    }

    /// Writes a log line through the host's logger.
    pub fn log(&self, level: LogLevel, message: &str) {
        self.inner.log(level as u8, RStr::from(message));
    }

    /// Publishes a progress event (JSON bytes) on the progress key of the plugin's role.
    pub fn progress(&self, payload: &[u8]) {
        self.inner.progress(RSlice::from(payload));
    }
}

/// A live subscription; dropping it ends it.
pub struct Subscription {
    inner: FfiSubscriptionBox,
}

impl Subscription {
    /// Waits at most `timeout` for the next sample: `(key, payload)`.
    pub fn recv_timeout(&mut self, timeout: Duration) -> Option<(String, Vec<u8>)> {
        let timeout_ms = u64::try_from(timeout.as_millis()).unwrap_or(u64::MAX);
        self.inner
            .recv_timeout(timeout_ms)
            .into_option()
            .map(|s| (s.key.into_string(), s.payload.into_vec()))
    }
}

/// What a call sees besides its payload: the cancel flag and the host.
pub struct CallContext<'a> {
    cancel: &'a AtomicBool,
    host: &'a Host,
}

impl<'a> CallContext<'a> {
    /// Builds a context (the export adapter does this; tests of a plugin may too).
    pub fn new(cancel: &'a AtomicBool, host: &'a Host) -> Self {
        CallContext { cancel, host }
    }

    /// True once the host has asked this call to stop. Long calls poll it often
    /// (the planner every few milliseconds) and return [`CallError::cancelled`].
    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// The raw flag, to hand to algorithm code that knows nothing of plugins.
    pub fn cancel_flag(&self) -> &'a AtomicBool {
        self.cancel
    }

    /// The host handle.
    pub fn host(&self) -> &'a Host {
        self.host
    }
}

/// A plugin, written in plain Rust. Export it with [`crate::export_plugin!`].
///
/// `call` takes `&self`: a plugin keeps changing state behind its own lock (or
/// atomics). The host runs one call at a time unless the plugin declares
/// [`PluginInfo::CONCURRENT`] and the host config gives it several workers.
pub trait Plugin: Send + Sync + Sized + 'static {
    /// Name, version, roles and description; called before `new`.
    fn info() -> PluginInfo;

    /// Creates the plugin. `config` is the plugin's config table from the host
    /// config, as TOML text (empty when there is none).
    fn new(host: Host, config: &str) -> Result<Self, String>;

    /// Runs one command. `payload` is the request's JSON bytes; the reply is JSON bytes.
    fn call(
        &self,
        command: &str,
        payload: &[u8],
        ctx: &CallContext<'_>,
    ) -> Result<Vec<u8>, CallError>;
}

pub(crate) fn into_ffi_result(
    result: Result<Vec<u8>, CallError>,
) -> RResult<RVec<u8>, FfiCallError> {
    match result {
        Ok(bytes) => RResult::ROk(RVec::from(bytes)),
        Err(err) => RResult::RErr(err.to_ffi()),
    }
}
