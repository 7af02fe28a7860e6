//! The host side of the boundary: loads plugin files and drives plugin objects.
//!
//! Each file is loaded with `lib_header_from_path` + `init_root_module`, not
//! `RootModule::load_from_file`, because the latter caches one library per
//! root-module type and would hand back the first plugin for every later file.
//! A library whose interface version or type layouts differ from this crate's is
//! refused with a [`LoadError`] that names the file and both versions — never
//! loaded with a warning. Libraries are never unloaded (abi_stable leaks them on
//! purpose: a vtable may outlive any handle).

use crate::ffi::{FfiHostBox, FfiPluginBox, PluginModuleRef};
use crate::safe::{CallError, PluginInfo};
use crate::INTERFACE_VERSION;
use abi_stable::library::{lib_header_from_path, LibraryError};
use abi_stable::std_types::{RSlice, RStr};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// Why a plugin file could not be loaded or created.
#[derive(Debug)]
pub enum LoadError {
    /// The file does not exist.
    NotFound {
        /// The file.
        path: PathBuf,
    },
    /// The file was built against an incompatible plugin interface version.
    IncompatibleVersion {
        /// The file.
        path: PathBuf,
        /// The interface version the plugin was built against.
        plugin_interface: String,
        /// The interface version this host speaks.
        host_interface: String,
    },
    /// The interface version matches but the types' layouts differ.
    IncompatibleLayout {
        /// The file.
        path: PathBuf,
        /// abi_stable's description of the difference.
        detail: String,
    },
    /// The file could not be opened as a library, or exports no Tsukami root module.
    NotAPlugin {
        /// The file.
        path: PathBuf,
        /// The loader's message.
        detail: String,
    },
    /// The plugin's `new` returned an error.
    CreateFailed {
        /// The plugin's name.
        plugin: String,
        /// Its message.
        message: String,
    },
}

impl std::fmt::Display for LoadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LoadError::NotFound { path } => write!(f, "plugin file {} does not exist", path.display()),
            LoadError::IncompatibleVersion { path, plugin_interface, host_interface } => write!(
                f,
                "refusing plugin `{}` ({}): built against plugin interface {plugin_interface}, \
                 but this host speaks {host_interface}; rebuild it against tsukami-plugin-api {host_interface}",
                plugin_stem(path),
                path.display()
            ),
            LoadError::IncompatibleLayout { path, detail } => write!(
                f,
                "refusing plugin `{}` ({}): its interface types differ from this host's \
                 (interface {INTERFACE_VERSION}); rebuild it. abi_stable says: {detail}",
                plugin_stem(path),
                path.display()
            ),
            LoadError::NotAPlugin { path, detail } => {
                write!(f, "{} is not a Tsukami plugin: {detail}", path.display())
            }
            LoadError::CreateFailed { plugin, message } => {
                write!(f, "plugin `{plugin}` failed to start: {message}")
            }
        }
    }
}

impl std::error::Error for LoadError {}

/// The name a plugin file goes by before its `info()` can be trusted: the file stem
/// without the platform's `lib` prefix.
pub fn plugin_stem(path: &Path) -> String {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("?");
    stem.strip_prefix("lib").unwrap_or(stem).to_owned()
}

/// The platform's file name for a library called `name`: `libname.so`,
/// `libname.dylib` or `name.dll`.
pub fn library_file_name(name: &str) -> String {
    format!(
        "{}{name}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    )
}

/// A loaded, checked plugin library, not yet created.
pub struct LoadedLibrary {
    path: PathBuf,
    module: PluginModuleRef,
    info: PluginInfo,
}

impl LoadedLibrary {
    /// Loads `path` and checks its interface version and layouts.
    pub fn load(path: &Path) -> Result<LoadedLibrary, LoadError> {
        if !path.is_file() {
            return Err(LoadError::NotFound {
                path: path.to_owned(),
            });
        }
        let header = lib_header_from_path(path).map_err(|e| LoadError::NotAPlugin {
            path: path.to_owned(),
            detail: e.to_string(),
        })?;
        let module = header
            .init_root_module::<PluginModuleRef>()
            .map_err(|e| match e {
                LibraryError::IncompatibleVersionNumber {
                    expected_version,
                    actual_version,
                    ..
                } => LoadError::IncompatibleVersion {
                    path: path.to_owned(),
                    plugin_interface: actual_version.to_string(),
                    host_interface: expected_version.to_string(),
                },
                LibraryError::AbiInstability(detail) => LoadError::IncompatibleLayout {
                    path: path.to_owned(),
                    detail: detail.to_string(),
                },
                other => LoadError::NotAPlugin {
                    path: path.to_owned(),
                    detail: other.to_string(),
                },
            })?;
        let info = PluginInfo::from_ffi(&(module.info())());
        Ok(LoadedLibrary {
            path: path.to_owned(),
            module,
            info,
        })
    }

    /// The file it came from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// What the plugin says about itself.
    pub fn info(&self) -> &PluginInfo {
        &self.info
    }

    /// Creates a plugin instance with its host handle and config (TOML text).
    pub fn create(&self, host: FfiHostBox, config: &str) -> Result<PluginInstance, LoadError> {
        (self.module.new())(host, RStr::from(config))
            .into_result()
            .map(|inner| PluginInstance { inner })
            .map_err(|message| LoadError::CreateFailed {
                plugin: self.info.name.clone(),
                message: message.into_string(),
            })
    }
}

/// A created plugin. `Sync`: the host shares it between its workers (one
/// unless the plugin declares `concurrent`).
pub struct PluginInstance {
    inner: FfiPluginBox,
}

impl PluginInstance {
    /// Runs one command; `cancel` may be set from another thread to stop it.
    pub fn call(
        &self,
        command: &str,
        payload: &[u8],
        cancel: &AtomicBool,
    ) -> Result<Vec<u8>, CallError> {
        self.inner
            .call(RStr::from(command), RSlice::from(payload), cancel)
            .into_result()
            .map(|bytes| bytes.into_vec())
            .map_err(CallError::from_ffi)
    }
}
