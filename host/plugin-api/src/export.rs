//! The plugin side of the boundary: adapts a [`Plugin`] to the FFI traits and catches
//! its panics before they reach the `extern "C"` boundary (where they would abort).

use crate::ffi::{
    FfiCallError, FfiHostBox, FfiPlugin, FfiPluginBox, FfiPluginInfo, FfiPlugin_TO, PluginModule,
    PluginModuleRef,
};
use crate::safe::{into_ffi_result, CallContext, CallError, Host, Plugin, PluginInfo};
use abi_stable::prefix_type::PrefixTypeTrait;
use abi_stable::sabi_trait::TD_Opaque;
use abi_stable::std_types::{RResult, RSlice, RStr, RString, RVec};
use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::AtomicBool;

/// Wraps a plugin and its host handle behind the FFI plugin trait.
pub struct PluginAdapter<P: Plugin> {
    plugin: P,
    host: Host,
}

fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_owned()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "non-string panic payload".to_owned()
    }
}

impl<P: Plugin> FfiPlugin for PluginAdapter<P> {
    fn call(
        &self,
        command: RStr<'_>,
        payload: RSlice<'_, u8>,
        cancel: &AtomicBool,
    ) -> RResult<RVec<u8>, FfiCallError> {
        let command = command.as_str();
        let result = catch_unwind(AssertUnwindSafe(|| {
            let ctx = CallContext::new(cancel, &self.host);
            self.plugin.call(command, payload.as_slice(), &ctx)
        }))
        .unwrap_or_else(|panic| {
            Err(CallError::new(
                CallError::PANICKED,
                format!(
                    "plugin `{}` panicked in `{command}`: {}",
                    P::info().name,
                    panic_message(panic.as_ref())
                ),
            ))
        });
        into_ffi_result(result)
    }
}

extern "C" fn info_of<P: Plugin>() -> FfiPluginInfo {
    catch_unwind(P::info)
        .unwrap_or_else(|_| PluginInfo::new("<panicked in info()>", "0.0.0", &[], ""))
        .to_ffi()
}

extern "C" fn new_of<P: Plugin>(
    host: FfiHostBox,
    config: RStr<'_>,
) -> RResult<FfiPluginBox, RString> {
    let host = Host::from_ffi(host);
    let created = catch_unwind(AssertUnwindSafe(|| P::new(host.clone(), config.as_str())))
        .unwrap_or_else(|panic| {
            Err(format!(
                "panicked in new(): {}",
                panic_message(panic.as_ref())
            ))
        });
    match created {
        Ok(plugin) => RResult::ROk(FfiPlugin_TO::from_value(
            PluginAdapter { plugin, host },
            TD_Opaque,
        )),
        Err(message) => RResult::RErr(RString::from(message)),
    }
}

/// Builds the root module of plugin type `P` (called by [`crate::export_plugin!`]).
pub fn plugin_module<P: Plugin>() -> PluginModuleRef {
    PluginModule {
        info: info_of::<P>,
        new: new_of::<P>,
    }
    .leak_into_prefix()
}

/// Exports a [`Plugin`] type as this library's root module.
///
/// The crate must have `crate-type = ["cdylib", "rlib"]` and depend on `abi_stable`.
#[macro_export]
macro_rules! export_plugin {
    ($plugin:ty) => {
        // A private module keeps the exported static out of the crate's public docs.
        mod __tsukami_plugin_export {
            #[allow(unused_imports)]
            use super::*;

            /// The root module abi_stable looks for when the host loads this library.
            #[::abi_stable::export_root_module]
            pub fn tsukami_plugin_root_module() -> $crate::ffi::PluginModuleRef {
                $crate::__private::plugin_module::<$plugin>()
            }
        }
    };
}
