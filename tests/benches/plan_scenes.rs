//! Time to plan each of the paper's scenes, p50 over seeds, in-process (the plugin
//! file cargo built, loaded into this process and called through its FFI with a
//! recording host: no bus) and over the bus (a client → the host → the same plugin
//! file), in the same run, with the ratio. The in-process side calls the plugin
//! file, not the planner's library, so both sides run the same code through the
//! same boundary and the ratio is the bus's cost alone. (Linking the library
//! is possible since the host's pictures moved to `host/render`: the host links
//! no plugin crate, so only the planner's root-module export would be in the
//! binary; see `docs/plugins.md`, "A plugin is loaded, never linked".)
//!
//! Run: `cargo bench -p tsukami-e2e --bench plan_scenes`. Targets (issue #5): can at
//! breast height p50 < 10 ms in-process; fridge scene p50 < 100 ms.

use abi_stable::sabi_trait::TD_Opaque;
use abi_stable::std_types::RArc;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};
use tsukami_e2e::{models_dir, planner_entry, plugin_file, test_config, TestBus};
use tsukami_msgs::keys::{planner, ROLE_GRASP_PLANNER};
use tsukami_msgs::planner::PlanOptions;
use tsukami_plugin_api::ffi::FfiHost_TO;
use tsukami_plugin_api::loader::{LoadedLibrary, PluginInstance};
use tsukami_plugin_api::offline::OfflineHost;
use tsukami_scenes::{scene_requests, PAPER_SCENES};

const SEEDS: u64 = 32;
const T: Duration = Duration::from_secs(60);

fn median_ms(mut times: Vec<Duration>) -> f64 {
    times.sort();
    times[times.len() / 2].as_secs_f64() * 1e3
}

/// The planner's plugin file, loaded here with the repository's models.
fn in_process_planner() -> PluginInstance {
    let library = LoadedLibrary::load(&plugin_file("tsukami_grasp_planner")).expect("loads");
    let config = format!("models_dir = {:?}\n", models_dir().display().to_string());
    let host = FfiHost_TO::from_ptr(RArc::new(OfflineHost::new()), TD_Opaque);
    library.create(host, &config).expect("the planner starts")
}

fn main() {
    let bus = TestBus::start(test_config(vec![planner_entry()]));
    let local = in_process_planner();
    let send = |command: &str, body: Vec<u8>| {
        bus.client
            .command(ROLE_GRASP_PLANNER, command, &body, T)
            .expect(command)
    };

    println!("plan time per scene, p50 over {SEEDS} seeds (release):");
    println!(
        "{:<11} {:>14} {:>14} {:>8}",
        "scene", "in-process ms", "over bus ms", "bus/in"
    );
    for scene in PAPER_SCENES {
        let req = scene_requests(
            &models_dir()
                .join("scenes")
                .join(format!("{}.toml", scene.name)),
        )
        .unwrap();

        let call = |command: &str, body: Vec<u8>| {
            local
                .call(command, &body, &AtomicBool::new(false))
                .unwrap_or_else(|e| panic!("{command}: {e:?}"))
        };
        call(planner::SET_ROBOT, serde_json::to_vec(&req.robot).unwrap());
        call(
            planner::SET_OBJECT,
            serde_json::to_vec(&req.object).unwrap(),
        );
        call(planner::SET_ENV, serde_json::to_vec(&req.env).unwrap());
        let in_process: Vec<Duration> = (0..SEEDS)
            .map(|seed| {
                let body = serde_json::to_vec(&PlanOptions {
                    seed,
                    ..PlanOptions::default()
                })
                .unwrap();
                let start = Instant::now();
                call(planner::PLAN, body);
                start.elapsed()
            })
            .collect();

        send(planner::SET_ROBOT, serde_json::to_vec(&req.robot).unwrap());
        send(
            planner::SET_OBJECT,
            serde_json::to_vec(&req.object).unwrap(),
        );
        send(planner::SET_ENV, serde_json::to_vec(&req.env).unwrap());
        let over_bus: Vec<Duration> = (0..SEEDS)
            .map(|seed| {
                let body = serde_json::to_vec(&PlanOptions {
                    seed,
                    ..PlanOptions::default()
                })
                .unwrap();
                let start = Instant::now();
                send(planner::PLAN, body);
                start.elapsed()
            })
            .collect();

        let (a, b) = (median_ms(in_process), median_ms(over_bus));
        println!("{:<11} {:>14.2} {:>14.2} {:>7.2}x", scene.name, a, b, b / a);
    }
}
