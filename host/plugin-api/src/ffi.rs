//! The frozen FFI surface: everything here crosses the library boundary.
//!
//! Change nothing here without bumping the crate version: abi_stable compares the
//! layouts of these types at load time and refuses a mismatch, but only a version
//! bump gives the user a message that says "rebuild the plugin". New methods go at
//! the end, after the `last_prefix_field`, so older plugins keep loading.

// sabi_trait's generated impls trip this lint (abi_stable issue); it is harmless.
#![allow(non_local_definitions)]

use abi_stable::{
    declare_root_module_statics,
    library::RootModule,
    sabi_trait,
    sabi_types::VersionStrings,
    std_types::{RArc, RBox, ROption, RResult, RSlice, RStr, RString, RVec},
    StableAbi,
};
use std::sync::atomic::AtomicBool;

/// What a plugin says about itself before it is created.
#[repr(C)]
#[derive(StableAbi, Debug, Clone)]
pub struct FfiPluginInfo {
    /// The plugin's name, e.g. `tsukami-grasp-planner`.
    pub name: RString,
    /// The plugin's own version.
    pub version: RString,
    /// Roles it can fill.
    pub roles: RVec<RString>,
    /// One-line description.
    pub description: RString,
    /// What the plugin declares it can do (`world`, `concurrent`).
    pub capabilities: RVec<RString>,
}

/// An error returned by a plugin: a machine-readable code, a message for people and
/// optional details as JSON text (empty when there are none).
#[repr(C)]
#[derive(StableAbi, Debug, Clone)]
pub struct FfiCallError {
    /// Machine-readable code (the wire names of `tsukami_msgs::ErrorCode`).
    pub code: RString,
    /// What went wrong, naming the field or file.
    pub message: RString,
    /// Extra details as JSON text, or empty.
    pub details_json: RString,
}

/// One message received on a subscription.
#[repr(C)]
#[derive(StableAbi, Debug, Clone)]
pub struct FfiSample {
    /// The full key it was published on.
    pub key: RString,
    /// The payload bytes.
    pub payload: RVec<u8>,
}

/// The plugin object the host drives. Shared: the host may call a plugin that
/// declares `concurrent` from several threads at once.
#[sabi_trait]
pub trait FfiPlugin: Send + Sync {
    /// Runs `command` with a serialized request; returns serialized reply bytes.
    /// The host sets `cancel` from another thread to stop a running call.
    #[sabi(last_prefix_field)]
    fn call(
        &self,
        command: RStr<'_>,
        payload: RSlice<'_, u8>,
        cancel: &AtomicBool,
    ) -> RResult<RVec<u8>, FfiCallError>;
}

/// The plugin object, boxed behind the stable vtable.
pub type FfiPluginBox = FfiPlugin_TO<'static, RBox<()>>;

/// What the host offers a plugin: the bus, logging and progress reports.
/// Keys are relative to the host's namespace.
#[sabi_trait]
pub trait FfiHost: Send + Sync + Clone {
    /// Publishes `payload` on `<ns>/<key>`.
    fn publish(&self, key: RStr<'_>, payload: RSlice<'_, u8>) -> RResult<(), RString>;
    /// Queries `<ns>/<key>` and waits at most `timeout_ms` for the reply (every
    /// responder is heard: two answering is `conflicting_responders`).
    fn request(
        &self,
        key: RStr<'_>,
        payload: RSlice<'_, u8>,
        timeout_ms: u64,
    ) -> RResult<RVec<u8>, FfiCallError>;
    /// Subscribes to `<ns>/<key>` (wildcards allowed).
    fn subscribe(&self, key: RStr<'_>) -> RResult<FfiSubscriptionBox, RString>;
    /// Writes a log line at `level` (0 error, 1 warn, 2 info, 3 debug, 4 trace).
    fn log(&self, level: u8, message: RStr<'_>);
    /// Publishes a progress event (JSON) on the progress key of the plugin's role.
    #[sabi(last_prefix_field)]
    fn progress(&self, payload: RSlice<'_, u8>);
}

/// The host object, shared behind the stable vtable.
pub type FfiHostBox = FfiHost_TO<'static, RArc<()>>;

/// A live subscription; dropping it undeclares it.
#[sabi_trait]
pub trait FfiSubscription: Send {
    /// Waits at most `timeout_ms` for the next sample.
    #[sabi(last_prefix_field)]
    fn recv_timeout(&mut self, timeout_ms: u64) -> ROption<FfiSample>;
}

/// A subscription, boxed behind the stable vtable.
pub type FfiSubscriptionBox = FfiSubscription_TO<'static, RBox<()>>;

/// The root module every plugin library exports.
#[repr(C)]
#[derive(StableAbi)]
#[sabi(kind(Prefix(prefix_ref = PluginModuleRef)))]
#[sabi(missing_field(panic))]
pub struct PluginModule {
    /// Describes the plugin (never fails).
    pub info: extern "C" fn() -> FfiPluginInfo,
    /// Creates the plugin with its host handle and its config (TOML text, may be empty).
    #[sabi(last_prefix_field)]
    pub new: extern "C" fn(FfiHostBox, RStr<'_>) -> RResult<FfiPluginBox, RString>,
}

impl RootModule for PluginModuleRef {
    declare_root_module_statics! {PluginModuleRef}
    const BASE_NAME: &'static str = "tsukami_plugin";
    const NAME: &'static str = "tsukami_plugin";
    const VERSION_STRINGS: VersionStrings = VersionStrings::new(crate::INTERFACE_VERSION);
}
