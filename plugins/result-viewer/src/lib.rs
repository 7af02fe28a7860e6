//! Tsukami's result viewer: what a planned grasp looks like.
//!
//! What: a [`drawing::Drawing`] — coloured triangle groups (robot links at the
//! planned posture, the object, the obstacles, contact markers and friction
//! cones) — built by [`grasp_view::GraspView`], and two ways out of it: a PNG
//! picture from a software z-buffer renderer ([`render`]) and a glTF 2.0
//! binary (`.glb`, [`glb`]) that opens in any 3D tool.
//!
//! Why: a person judges a grasp by looking at it (Choreonoid shows the result
//! in its graphics window). A robot PC is often headless: the picture needs no
//! browser, no GPU and no display; the `.glb` carries the same scene to a
//! desktop.
//!
//! How: shapes are tessellated once into world-frame triangles with a flat
//! colour per group; the renderer projects them through a pinhole
//! [`render::Camera`] into a depth buffer with Lambert shading; the glTF
//! writer puts one mesh and one node per group into a single binary buffer.
//!
//! As the `result-viewer` plugin ([`plugin`]) it shares the host's world,
//! follows plan and motion results on the bus ([`follow`]) and serves a live
//! three.js view of them on loopback ([`web`]).
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_result_viewer::drawing::{Drawing, Rgba};
//! use tsukami_result_viewer::render::{render, Camera};
//! let mut d = Drawing::default();
//! d.marker("contact", Rgba::CONTACT, &Point3::new(0.0, 0.0, 0.0), 0.01);
//! let camera = Camera::looking_at(Point3::new(0.3, 0.0, 0.1), Point3::origin(), Vector3::z());
//! let picture = render(&d, &camera, 64, 48);
//! assert_ne!(picture.pixel(32, 24), picture.background);
//! assert!(picture.to_png().unwrap().starts_with(b"\x89PNG"));
//! ```

pub mod drawing;
pub mod follow;
pub mod glb;
pub mod grasp_view;
pub mod latest;
pub mod plugin;
pub mod render;
pub mod scene;
mod unread;
pub mod viewer;
pub mod web;
pub mod world;
