//! A host with no bus, for testing a plugin in-process.
//!
//! A plugin's unit tests create it with [`OfflineHost::new`], hand
//! [`OfflineHost::host`] to the plugin's `new`, call the plugin through the [`Plugin`]
//! trait, and read back what the plugin published and reported. Requests to other
//! components fail with `no_plugin` and subscriptions are refused: there is nobody to
//! answer. No abi_stable type appears in a test written against it.
//!
//! ```
//! use tsukami_plugin_api::{offline::OfflineHost, LogLevel};
//! let offline = OfflineHost::new();
//! let host = offline.host();
//! host.progress(br#"{"phase":"search"}"#);
//! host.log(LogLevel::Info, "hello");
//! assert_eq!(offline.progress(), vec![br#"{"phase":"search"}"#.to_vec()]);
//! assert!(host.request("vision/detect", b"{}", std::time::Duration::from_millis(10)).is_err());
//! ```
//!
//! [`Plugin`]: crate::Plugin

use crate::ffi::{FfiCallError, FfiHost, FfiHost_TO, FfiSubscriptionBox};
use crate::safe::{Host, LogLevel};
use abi_stable::sabi_trait::TD_Opaque;
use abi_stable::std_types::{RArc, RResult, RSlice, RStr, RString, RVec};
use std::sync::{Arc, Mutex, MutexGuard};

/// What a plugin sent to an [`OfflineHost`].
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Recorded {
    /// Progress events, in order.
    pub progress: Vec<Vec<u8>>,
    /// Publications: (key relative to the namespace, payload), in order.
    pub published: Vec<(String, Vec<u8>)>,
    /// Log lines, in order.
    pub logs: Vec<(LogLevel, String)>,
}

/// A host with no bus that records what the plugin sends. Clones share the record.
#[derive(Debug, Clone, Default)]
pub struct OfflineHost {
    // Shared with the `Host` handed to the plugin, which may call from any thread.
    recorded: Arc<Mutex<Recorded>>,
}

impl OfflineHost {
    /// A host with an empty record.
    pub fn new() -> Self {
        OfflineHost::default()
    }

    /// The handle to give the plugin's `new` (and a test's `CallContext`).
    pub fn host(&self) -> Host {
        Host::from_ffi(FfiHost_TO::from_ptr(RArc::new(self.clone()), TD_Opaque))
    }

    fn record(&self) -> MutexGuard<'_, Recorded> {
        self.recorded
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Everything recorded so far.
    pub fn recorded(&self) -> Recorded {
        self.record().clone()
    }

    /// The progress events recorded so far.
    pub fn progress(&self) -> Vec<Vec<u8>> {
        self.record().progress.clone()
    }
}

impl FfiHost for OfflineHost {
    fn publish(&self, key: RStr<'_>, payload: RSlice<'_, u8>) -> RResult<(), RString> {
        self.record()
            .published
            .push((key.to_string(), payload.to_vec()));
        RResult::ROk(())
    }

    fn request(
        &self,
        key: RStr<'_>,
        _payload: RSlice<'_, u8>,
        _timeout_ms: u64,
    ) -> RResult<RVec<u8>, FfiCallError> {
        RResult::RErr(FfiCallError {
            code: "no_plugin".into(),
            message: format!("offline host: nobody answers `{key}`")
                .as_str()
                .into(),
            details_json: RString::new(),
        })
    }

    fn subscribe(&self, key: RStr<'_>) -> RResult<FfiSubscriptionBox, RString> {
        RResult::RErr(
            format!("offline host: cannot subscribe to `{key}`")
                .as_str()
                .into(),
        )
    }

    fn log(&self, level: u8, message: RStr<'_>) {
        self.record()
            .logs
            .push((LogLevel::from_u8(level), message.to_string()));
    }

    fn progress(&self, payload: RSlice<'_, u8>) {
        self.record().progress.push(payload.to_vec());
    }
}
