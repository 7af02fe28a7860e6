//! Model files named in requests, found inside the model roots only.
//!
//! What: [`Models`] turns the names of `set_robot` and `set_object` (a robot or
//! object name, or a path inside a model root) into files, and reads them
//! through `tsukami_body::files` with its size limits.
//!
//! Why: a bus request must never make the host open a file outside the
//! configured roots, block on a FIFO or read without bound; errors name paths
//! relative to a root and never quote contents. Keeping every file the kit
//! opens behind this one type makes that checkable in one place.
//!
//! How: names resolve as `robots/<name>/description.toml` and
//! `objects/<name>/object.toml`; a path resolves as given
//! ([`tsukami_body::files::ModelRoots::resolve`]). A `.urdf` path stands for the
//! description beside it.

use std::path::PathBuf;

use tsukami_body::files::{FileKind, ModelFile, ModelRoots};

use crate::KitError;

/// The model roots of a planner.
#[derive(Debug, Clone)]
pub struct Models {
    roots: ModelRoots,
}

/// A model name: letters, digits, `_`, `-`, `.`; no path separators, not `..`.
pub fn plain_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 128
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
        && !name.contains("..")
}

impl Models {
    /// Models under `roots` (folders that do not exist are skipped).
    pub fn new(roots: impl IntoIterator<Item = PathBuf>) -> Self {
        Self {
            roots: ModelRoots::new(roots),
        }
    }

    /// Models under `roots` with other file size limits.
    pub fn with_limits(
        roots: impl IntoIterator<Item = PathBuf>,
        sizes: tsukami_body::files::SizeLimits,
    ) -> Self {
        Self {
            roots: ModelRoots::new(roots).with_limits(sizes),
        }
    }

    /// The roots.
    pub fn roots(&self) -> &ModelRoots {
        &self.roots
    }

    fn resolve(&self, request: &str, field: &str) -> Result<ModelFile, KitError> {
        self.roots
            .resolve(request)
            .map_err(|e| KitError::model(field, e.to_string()))
    }

    /// The description file of `robot` (a name, a description path or a URDF path).
    pub fn robot_description(&self, robot: &str) -> Result<ModelFile, KitError> {
        if plain_name(robot) && !robot.ends_with(".urdf") && !robot.ends_with(".toml") {
            return self.resolve(
                &format!("robots/{robot}/{}", crate::description::FILE_NAME),
                "robot",
            );
        }
        let file = self.resolve(robot, "robot")?;
        if robot.ends_with(".urdf") {
            return self.beside(&file, crate::description::FILE_NAME, "robot");
        }
        Ok(file)
    }

    /// The `object.toml` of object model `name`.
    pub fn object(&self, name: &str) -> Result<ModelFile, KitError> {
        if !plain_name(name) {
            return Err(KitError::model(
                "shape.model.name",
                format!("`{name}` is not a model name (letters, digits, _ - .)"),
            ));
        }
        self.resolve(&format!("objects/{name}/object.toml"), "shape.model.name")
    }

    /// A mesh file named by path.
    pub fn mesh(&self, path: &str, field: &str) -> Result<ModelFile, KitError> {
        let file = self.resolve(path, field)?;
        self.check_size(&file, FileKind::Mesh, field)?;
        Ok(file)
    }

    /// A file named relative to another one (e.g. the URDF beside a description).
    pub fn beside(&self, base: &ModelFile, rel: &str, field: &str) -> Result<ModelFile, KitError> {
        self.roots
            .resolve_beside(base, rel)
            .map_err(|e| KitError::model(field, e.to_string()))
    }

    /// Reads a text file of `kind` (bounded).
    pub fn read(&self, file: &ModelFile, kind: FileKind, field: &str) -> Result<String, KitError> {
        self.roots
            .read_string(file, kind)
            .map_err(|e| KitError::model(field, e.to_string()))
    }

    /// Refuses a file larger than its kind's limit before a loader opens it.
    pub fn check_size(
        &self,
        file: &ModelFile,
        kind: FileKind,
        field: &str,
    ) -> Result<(), KitError> {
        let limit = self.roots.limits().of(kind);
        let size = std::fs::metadata(file.path())
            .map(|m| m.len())
            .unwrap_or(u64::MAX);
        if size > limit {
            return Err(KitError::model(
                field,
                format!(
                    "{}: {} file is {size} bytes, more than the limit of {limit} bytes",
                    file.name(),
                    kind.name()
                ),
            ));
        }
        Ok(())
    }
}

/// A loader's error message with the file's absolute path replaced by its name
/// relative to the root, and anything quoted from the file removed.
pub fn relative_error(file: &ModelFile, error: &dyn std::fmt::Display) -> String {
    let text = error.to_string();
    let abs = file.path().display().to_string();
    let dir = file
        .path()
        .parent()
        .map(|p| p.display().to_string())
        .unwrap_or_default();
    let named = text.replace(&abs, file.name());
    let named = if dir.is_empty() {
        named
    } else {
        named.replace(&dir, "<model root>")
    };
    tsukami_body::files::redact(&named)
}
