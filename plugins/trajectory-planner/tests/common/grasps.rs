//! A paper scene's world and its grasp, for the in-process tests and benches.
//!
//! The grasp comes from the paper's planner loaded from its plugin file (cargo
//! builds it as a dev-dependency), not linked: two plugin libraries linked into one
//! binary would both define the plugin export symbol.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use abi_stable::sabi_trait::TD_Opaque;
use abi_stable::std_types::RArc;
use tsukami_msgs::motion::MotionGrasp;
use tsukami_planner_kit::Session;
use tsukami_plugin_api::ffi::FfiHost_TO;
use tsukami_plugin_api::loader::{library_file_name, LoadedLibrary};
use tsukami_plugin_api::offline::OfflineHost;
use tsukami_scenes::scene_requests;
use tsukami_trajectory_planner::world::SharedWorld;

/// The repository's `models/`.
pub fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

/// The grasp planner's plugin file cargo built beside the test, bench or
/// example binary.
pub fn grasp_planner_file() -> PathBuf {
    let exe = std::env::current_exe().expect("current_exe");
    let deps = exe.parent().expect("the binary's folder");
    let file = library_file_name("tsukami_grasp_planner");
    [deps.to_owned(), deps.join(".."), deps.join("../deps")]
        .into_iter()
        .map(|d| d.join(&file))
        .find(|p| p.is_file())
        .unwrap_or_else(|| panic!("{file} was not built beside {}", deps.display()))
}

/// The motion world of `scene` and the paper planner's grasp (seed `seed`).
pub fn scene(scene: &str, seed: u64) -> (Session<SharedWorld>, MotionGrasp) {
    let req = scene_requests(&models().join("scenes").join(format!("{scene}.toml"))).unwrap();
    let world = Session::<SharedWorld>::new(models());
    world.set_robot(&req.robot).unwrap();
    world.set_object(&req.object).unwrap();
    world.set_env(&req.env).unwrap();
    let library = LoadedLibrary::load(&grasp_planner_file()).expect("the grasp planner loads");
    let host = FfiHost_TO::from_ptr(RArc::new(OfflineHost::new()), TD_Opaque);
    let config = format!("models_dir = {:?}", models().display().to_string());
    let planner = library
        .create(host, &config)
        .expect("the grasp planner starts");
    let cancel = AtomicBool::new(false);
    let call = |command: &str, payload: Vec<u8>| {
        planner
            .call(command, &payload, &cancel)
            .unwrap_or_else(|e| panic!("{scene}: {command}: {} {}", e.code, e.message))
    };
    call("set_robot", serde_json::to_vec(&req.robot).unwrap());
    call("set_object", serde_json::to_vec(&req.object).unwrap());
    call("set_env", serde_json::to_vec(&req.env).unwrap());
    let reply = call("plan", format!("{{\"seed\": {seed}}}").into_bytes());
    (world, serde_json::from_slice(&reply).expect("a Plan reply"))
}
