//! The Tsukami host and its command-line client, as a library.
//!
//! The `tsukami` binary is a thin layer over this crate; tests and embedders start a
//! host in-process with [`server::RunningHost::start`] and talk to it with
//! [`client::BusClient`], over a real zenoh bus on loopback.
//!
//! - [`config`]: the host config (TOML): namespace, bus, plugins and their roles.
//! - [`bus`]: the zenoh configuration — loopback only, no multicast, unless the user
//!   hands in a zenoh config file of their own.
//! - [`server`]: loads the plugins, owns the one zenoh session, routes each role's
//!   queries to its plugin on a worker thread, answers `stop` and `host/plugins`.
//! - `reply`: answering a query (JSON reply, error object, payload check),
//!   shared by the server and the world hub.
//! - [`world`]: the one world every world-aware plugin shares.
//! - [`host_handle`]: what a plugin reaches the bus through.
//! - [`demo`]: `tsukami demo`, the main job.
//! - [`scenes`]: the paper's scenes run over the bus and judged.
//! - [`client`]: a small blocking client for the bus (CLI, demo, tests, benches).
//! - [`inline`]: a mesh file of the client's disk sent inline in `set_object`.
//! - [`picture`]: `tsukami view`'s and the report's pictures, drawn by `tsukami-render`.
//!
//! No file here imports a file that imports it back (`tests/module_cycles.rs`
//! checks every `use crate::…` and `super::…` path).

pub mod bus;
pub mod client;
pub mod config;
pub mod demo;
pub mod host_handle;
pub mod inline;
pub mod picture;
mod reply;
pub mod scenes;
pub mod server;
pub mod world;
