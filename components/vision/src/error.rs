//! The error type of the vision component.
//!
//! Every failure caused by input (a depth image, intrinsics, a camera pose, an
//! object name, a scene file) is a [`VisionError`] naming what was wrong, so a
//! caller can fix the input without reading the source. Nothing here panics on
//! bad input, and no message quotes the contents of a file.

use std::path::PathBuf;

use tsukami_body::BodyError;

/// Errors of the vision library.
#[derive(Debug, thiserror::Error)]
pub enum VisionError {
    /// A value of the input is out of range or inconsistent (NaN intrinsics,
    /// a data length that does not match the image size, ...).
    #[error("{field}: {message}")]
    Invalid {
        /// The field, e.g. `intrinsics.fx` or `image.data`.
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// An image could not be decoded (malformed PNG, wrong pixel format).
    #[error("{source_name}: cannot decode the depth image: {message}")]
    Decode {
        /// Where the image came from (a file name or `request.image`).
        source_name: String,
        /// The decoder's message.
        message: String,
    },
    /// A file could not be read or written.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// An object model is unknown or unusable.
    #[error("object '{object}': {message}")]
    Model {
        /// The object name.
        object: String,
        /// What is wrong.
        message: String,
    },
    /// A model, mesh or scene file failed to load.
    #[error(transparent)]
    Body(#[from] BodyError),
}

/// Result with a [`VisionError`].
pub type Result<T> = std::result::Result<T, VisionError>;

/// Shorthand for [`VisionError::Invalid`].
pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> VisionError {
    VisionError::Invalid {
        field: field.into(),
        message: message.into(),
    }
}
