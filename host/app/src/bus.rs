//! zenoh configuration for the host and its clients: the `tsukami-bus` crate's
//! [`config`](tsukami_bus::config), re-exported so `tsukami::bus::…` paths keep
//! working. The host, its clients and the components (vision, controller) share it:
//! loopback only, multicast and gossip scouting off, unless a zenoh config file
//! (`--zenoh-config`) replaces it.

pub use tsukami_bus::config::*;
