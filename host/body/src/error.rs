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
    /// A `package://` URI names a package found in none of the places
    /// searched.
    #[error("{file}: {element}: package '{package}' not found; searched {}", searched_list(.searched))]
    UnresolvedPackage {
        /// The model file that references the mesh.
        file: PathBuf,
        /// The referencing element, e.g. `link 'base' visual 0`.
        element: String,
        /// The package name.
        package: String,
        /// Every folder searched, in order.
        searched: Vec<PathBuf>,
    },
    /// A file or model exceeds a parse limit ([`crate::limits::ParseLimits`]).
    #[error("{file}: too large: {message}")]
    TooLarge {
        /// The file.
        file: PathBuf,
        /// Which limit, and by how much.
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

fn searched_list(searched: &[PathBuf]) -> String {
    if searched.is_empty() {
        return "nothing (no package path is set: use ROS_PACKAGE_PATH, AMENT_PREFIX_PATH \
                or --package-dir)"
            .into();
    }
    let names: Vec<String> = searched.iter().map(|p| p.display().to_string()).collect();
    names.join(", ")
}

/// What a [`LoadWarning`] is about, so callers can decide which ones they
/// accept (a planner may refuse a robot whose collision geometry is
/// incomplete).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WarningKind {
    /// A quirk that reference parsers accept; the model is as they read it.
    Quirk,
    /// A visual element was skipped (no effect on kinematics or collision).
    VisualSkipped,
    /// A collision element was skipped: collision checks of that link are
    /// incomplete.
    CollisionSkipped,
    /// A mesh was cleaned (duplicate vertices merged, degenerate or
    /// non-finite triangles dropped).
    MeshCleaned,
}

/// Something the lenient loader accepted that `--strict` refuses, or an
/// element it skipped. Displays as `file: element: message`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoadWarning {
    /// The kind of warning.
    pub kind: WarningKind,
    /// The model or mesh file.
    pub file: PathBuf,
    /// The element, e.g. `joint 'r_elbow' limit`.
    pub element: String,
    /// What was wrong and what the loader did about it.
    pub message: String,
}

impl std::fmt::Display for LoadWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {}: {}",
            self.file.display(),
            self.element,
            self.message
        )
    }
}

/// Result alias of the body crate.
pub type Result<T, E = BodyError> = std::result::Result<T, E>;
