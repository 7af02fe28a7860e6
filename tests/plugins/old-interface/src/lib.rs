//! Test fixture: a plugin built against an *older* plugin interface.
//!
//! It carries its own copy of the interface as it stood at version 0.1.0 (a root
//! module with only `info`), exactly what a plugin compiled against that old
//! `tsukami-plugin-api` would export. The host (interface 0.3.x) must refuse it with
//! a message naming the plugin and both versions.

#![allow(non_local_definitions)]

use abi_stable::{
    declare_root_module_statics, export_root_module, library::RootModule,
    prefix_type::PrefixTypeTrait, sabi_types::VersionStrings, std_types::RString, StableAbi,
};

/// The 0.1.0 root module.
#[repr(C)]
#[derive(StableAbi)]
#[sabi(kind(Prefix(prefix_ref = OldPluginModuleRef)))]
#[sabi(missing_field(panic))]
pub struct OldPluginModule {
    /// The plugin's name.
    #[sabi(last_prefix_field)]
    pub info: extern "C" fn() -> RString,
}

impl RootModule for OldPluginModuleRef {
    declare_root_module_statics! {OldPluginModuleRef}
    const BASE_NAME: &'static str = "tsukami_plugin";
    const NAME: &'static str = "tsukami_plugin";
    const VERSION_STRINGS: VersionStrings = VersionStrings::new("0.1.0");
}

extern "C" fn info() -> RString {
    RString::from("test-old-interface")
}

mod export {
    use super::*;

    /// The root module, as the 0.1.0 export macro produced it.
    #[export_root_module]
    pub fn tsukami_plugin_root_module() -> OldPluginModuleRef {
        OldPluginModule { info }.leak_into_prefix()
    }
}
