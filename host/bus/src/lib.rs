//! # tsukami-bus
//!
//! How Tsukami's processes join the zenoh bus. The host (`tsukami run`), its
//! clients, the components (`tsukami-vision`, `tsukami-controller`) and the test
//! mocks all link this crate, so they share one set of defaults:
//!
//! - [`config`]: the built-in zenoh config — loopback only, multicast and gossip
//!   scouting off, `peer` mode unless told otherwise; a zenoh json5 file
//!   (`--zenoh-config`) replaces it entirely for routers, TLS and other machines.
//! - [`client`]: a small blocking client ([`BusClient`]): a request gets a reply, an
//!   error object or a timeout, never a hang.
//! - [`component`]: the options every component takes ([`ComponentArgs`]) and
//!   [`Component`], which answers `<ns>/<name>/info` and lists its keys there.
//! - [`serve`]: request checks (size, JSON, shape) and reply helpers.
//! - [`shutdown`]: clean shutdown on SIGINT/SIGTERM.
//! - [`logging`]: the `tracing` subscriber of the component binaries.

pub mod client;
pub mod component;
pub mod config;
pub mod logging;
pub mod serve;
pub mod shutdown;

pub use client::{BusClient, RequestError};
pub use component::{Component, ComponentArgs};
pub use config::{
    check_loopback, default_endpoint, free_loopback_port, reassembly_cap, BusConfig, BusMode,
    DEFAULT_PORT, DEFAULT_ROUTER_PORT,
};
pub use logging::init_logging;
pub use serve::MAX_PAYLOAD_BYTES;
pub use shutdown::Shutdown;
