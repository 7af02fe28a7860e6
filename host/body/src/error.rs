//! The error type of the body crate.
//!
//! Every failure caused by user input (a model file, a mesh, a scene, a joint
//! name given on the command line) is a [`BodyError`] that names the file and
//! the element or field that was wrong, so a user can fix the input without
//! reading the source. Nothing in this crate panics on bad input.

use std::path::PathBuf;

/// Errors raised while loading or querying robot, object and scene models.
#[derive(Debug, thiserror::Error)]
pub enum BodyError {
    /// A file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The file.
        file: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The URDF is not well-formed XML or does not follow the URDF schema.
    #[error("{file}: malformed URDF: {message}")]
    Urdf {
        /// The URDF file.
        file: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A model element is invalid (a non-finite number, a bad limit, a
    /// negative size, ...).
    #[error("{file}: {element}: {message}")]
    Invalid {
        /// The file holding the element.
        file: PathBuf,
        /// The element, e.g. `joint 'r_elbow' origin xyz`.
        element: String,
        /// What is wrong with it.
        message: String,
    },
    /// A joint names a parent or child link that the model does not have.
    #[error("{file}: joint '{joint}' names {role} link '{link}', which does not exist")]
    UnknownLinkInJoint {
        /// The URDF file.
        file: PathBuf,
        /// The joint.
        joint: String,
        /// `parent` or `child`.
        role: &'static str,
        /// The missing link.
        link: String,
    },
    /// The links do not form a tree: a link has two parents, there is a
    /// cycle, or there is no unique root.
    #[error("{file}: kinematic loop: {message}")]
    Loop {
        /// The URDF file.
        file: PathBuf,
        /// Which links and joints form the loop.
        message: String,
    },
    /// A mimic joint names a joint that does not exist, or mimic couplings
    /// form a cycle.
    #[error("{file}: joint '{joint}': bad mimic: {message}")]
    Mimic {
        /// The URDF file.
        file: PathBuf,
        /// The mimic joint.
        joint: String,
        /// What is wrong.
        message: String,
    },
    /// A mesh file referenced by a model does not exist.
    #[error("{file}: {element}: mesh file '{mesh}' not found")]
    MissingMesh {
        /// The model file that references the mesh.
        file: PathBuf,
        /// The referencing element, e.g. `link 'r_palm' collision 0`.
        element: String,
        /// The resolved mesh path.
        mesh: PathBuf,
    },
    /// A mesh file cannot be parsed or is geometrically invalid (no
    /// triangles, non-finite vertices, degenerate triangles, bad indices).
    #[error("{file}: bad mesh: {message}")]
    Mesh {
        /// The mesh file.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A scene or object TOML file is malformed.
    #[error("{file}: {message}")]
    Toml {
        /// The TOML file.
        file: PathBuf,
        /// The parser's message (names the offending key).
        message: String,
    },
    /// A link name that the model does not have.
    #[error("unknown link '{0}'")]
    UnknownLink(String),
    /// A joint name that the model does not have.
    #[error("unknown joint '{0}'")]
    UnknownJoint(String),
    /// A query or request is not valid for this model (e.g. setting a mimic
    /// joint directly, a joint list with a fixed joint, a bad target).
    #[error("{0}")]
    Request(String),
}

/// Result alias of the body crate.
pub type Result<T, E = BodyError> = std::result::Result<T, E>;
