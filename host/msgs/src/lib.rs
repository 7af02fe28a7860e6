//! Message types of the Tsukami bus, shared by the host, the plugins and the components.
//!
//! Every payload on the bus is JSON (`application/json`) made from these types, so any
//! zenoh client (Rust, Python's `eclipse-zenoh`, the C client) can drive the system, and
//! the same bytes cross the plugin boundary in-process. Every reply is either the
//! result type of its request or an [`ErrorReply`] with a machine-readable
//! [`ErrorCode`].
//!
//! - [`keys`]: the key expressions, built from a namespace ([`keys::KeySpace`]).
//! - [`error`]: the common error object.
//! - [`common`]: poses and joint maps used by several messages.
//! - [`planner`], [`motion`], [`controller`], [`vision`], [`host`]: one module per
//!   component of the key table in `docs/protocol.md`; [`component`]: what every
//!   component process answers about itself.
//! - [`schema`]: the JSON Schema of every payload, written to `docs/schema/` by
//!   `tsukami schema --out docs/schema`.

pub mod common;
pub mod component;
pub mod controller;
pub mod error;
pub mod host;
pub mod keys;
pub mod motion;
pub mod planner;
pub mod schema;
pub mod vision;

pub use common::Pose;
pub use error::{ErrorCode, ErrorReply};
pub use keys::KeySpace;
