//! A small blocking bus client: the `tsukami-bus` crate's
//! [`client`](tsukami_bus::client), re-exported so `tsukami::client::…` paths keep
//! working; the components use the same client.

pub use tsukami_bus::client::*;
