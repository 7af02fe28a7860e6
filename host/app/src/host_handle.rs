//! The host object a plugin reaches the bus through.
//!
//! Plugins do not link zenoh: they call these methods across the FFI boundary with
//! keys relative to the namespace and JSON bytes, and the host does the zenoh work
//! on its own session.

use abi_stable::sabi_trait::TD_Opaque;
use abi_stable::std_types::{RArc, RBox, ROption, RResult, RSlice, RStr, RString, RVec};
use std::time::Duration;
use tsukami_bus::RequestError;
use tsukami_msgs::{ErrorCode, ErrorReply, KeySpace};
use tsukami_plugin_api::ffi::{
    FfiCallError, FfiHost, FfiHostBox, FfiHost_TO, FfiSample, FfiSubscription, FfiSubscriptionBox,
    FfiSubscription_TO,
};
use zenoh::bytes::Encoding;
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;
use zenoh::Wait;

/// One plugin's view of the host.
#[derive(Clone)]
pub struct BusHost {
    session: zenoh::Session,
    keys: KeySpace,
    progress_key: String,
    plugin: String,
}

impl BusHost {
    /// The handle for `plugin`, whose progress goes to `progress_key`.
    pub fn new(
        session: zenoh::Session,
        keys: KeySpace,
        progress_key: String,
        plugin: String,
    ) -> Self {
        BusHost {
            session,
            keys,
            progress_key,
            plugin,
        }
    }

    /// Boxes it behind the stable vtable for the plugin's `new`.
    pub fn into_ffi(self) -> FfiHostBox {
        FfiHost_TO::from_ptr(RArc::new(self), TD_Opaque)
    }
}

/// The FFI error of an error object, keeping its code and details.
fn call_error(reply: ErrorReply) -> FfiCallError {
    FfiCallError {
        code: reply.error.code.as_str().into(),
        message: reply.error.message.as_str().into(),
        details_json: reply
            .error
            .details
            .map(|d| d.to_string())
            .unwrap_or_default()
            .into(),
    }
}

fn ffi_error(code: ErrorCode, message: String) -> FfiCallError {
    FfiCallError {
        code: code.as_str().into(),
        message: message.into(),
        details_json: RString::new(),
    }
}

impl FfiHost for BusHost {
    fn publish(&self, key: RStr<'_>, payload: RSlice<'_, u8>) -> RResult<(), RString> {
        let key = self.keys.key(key.as_str());
        self.session
            .put(&key, payload.as_slice().to_vec())
            .encoding(Encoding::APPLICATION_JSON)
            .wait()
            .map_err(|e| RString::from(format!("publishing on {key}: {e}")))
            .into()
    }

    fn request(
        &self,
        key: RStr<'_>,
        payload: RSlice<'_, u8>,
        timeout_ms: u64,
    ) -> RResult<RVec<u8>, FfiCallError> {
        let key = self.keys.key(key.as_str());
        let timeout = Duration::from_millis(timeout_ms);
        match tsukami_bus::client::query(&self.session, &key, payload.as_slice(), timeout) {
            Ok(bytes) => RResult::ROk(RVec::from(bytes)),
            Err(RequestError::Reply(reply) | RequestError::Conflict(reply)) => {
                RResult::RErr(call_error(reply))
            }
            Err(RequestError::Timeout { .. }) => RResult::RErr(ffi_error(
                ErrorCode::Timeout,
                format!("no reply from {key} within {timeout_ms} ms"),
            )),
            Err(RequestError::Bus { message, .. }) => RResult::RErr(ffi_error(
                ErrorCode::Internal,
                format!("querying {key}: {message}"),
            )),
        }
    }

    fn subscribe(&self, key: RStr<'_>) -> RResult<FfiSubscriptionBox, RString> {
        let key = self.keys.key(key.as_str());
        match self.session.declare_subscriber(&key).wait() {
            Ok(subscriber) => RResult::ROk(FfiSubscription_TO::from_ptr(
                RBox::new(BusSubscription { subscriber }),
                TD_Opaque,
            )),
            Err(e) => RResult::RErr(RString::from(format!("subscribing to {key}: {e}"))),
        }
    }

    fn log(&self, level: u8, message: RStr<'_>) {
        let plugin = self.plugin.as_str();
        let message = message.as_str();
        match tsukami_plugin_api::LogLevel::from_u8(level) {
            tsukami_plugin_api::LogLevel::Error => tracing::error!(plugin, "{message}"),
            tsukami_plugin_api::LogLevel::Warn => tracing::warn!(plugin, "{message}"),
            tsukami_plugin_api::LogLevel::Info => tracing::info!(plugin, "{message}"),
            tsukami_plugin_api::LogLevel::Debug => tracing::debug!(plugin, "{message}"),
            tsukami_plugin_api::LogLevel::Trace => tracing::trace!(plugin, "{message}"),
        }
    }

    fn progress(&self, payload: RSlice<'_, u8>) {
        let published = self
            .session
            .put(&self.progress_key, payload.as_slice().to_vec())
            .encoding(Encoding::APPLICATION_JSON)
            .wait();
        if let Err(e) = published {
            tracing::warn!(plugin = self.plugin.as_str(), "progress not published: {e}");
        }
    }
}

/// A zenoh subscriber behind the FFI subscription trait.
struct BusSubscription {
    subscriber: Subscriber<FifoChannelHandler<Sample>>,
}

impl FfiSubscription for BusSubscription {
    fn recv_timeout(&mut self, timeout_ms: u64) -> ROption<FfiSample> {
        match self
            .subscriber
            .recv_timeout(Duration::from_millis(timeout_ms))
        {
            Ok(Some(sample)) => ROption::RSome(FfiSample {
                key: sample.key_expr().as_str().into(),
                payload: RVec::from(sample.payload().to_bytes().into_owned()),
            }),
            _ => ROption::RNone,
        }
    }
}
