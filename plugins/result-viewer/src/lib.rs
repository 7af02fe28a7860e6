//! Tsukami's result viewer: the `result-viewer` plugin.
//!
//! What: the plugin ([`plugin`]) shares the host's world ([`world`]), follows
//! plan and motion results on the bus ([`follow`], into [`latest`]), answers
//! `render` (PNG) and `glb` from them ([`viewer`]) and serves a live three.js
//! view of them on loopback ([`web`], with the page's JSON from [`scene`]).
//!
//! Why: a person judges a grasp by looking at it (Choreonoid shows the result
//! in its graphics window); a headless robot PC needs the same from a browser,
//! a picture or a file, without slowing the planners (the viewer only
//! listens).
//!
//! How: the drawing itself — tessellation, the software renderer, the glTF
//! writer, the grasp scene — is the host library `tsukami-render`
//! (`host/render`), which `tsukami view` and the demo's report use too; this
//! crate holds only what makes it a plugin: the bus, the web server and the
//! FFI export.
//!
//! ```
//! use tsukami_result_viewer::latest::{Board, Outcome};
//! let board = Board::default();
//! let g = board.generation();
//! board.update(|l| l.plan = Some(Outcome::Failed("infeasible: no grasp".into()).into()));
//! assert_eq!(board.generation(), g + 1);
//! ```

pub mod follow;
pub mod latest;
pub mod plugin;
pub mod scene;
mod unread;
pub mod viewer;
pub mod web;
pub mod world;
