//! Model files named over the bus: resolved inside configured roots, read
//! with bounds.
//!
//! What: [`ModelRoots`], a list of root folders. A request names a model file
//! by a path relative to a root (or an absolute path that lies inside one);
//! [`ModelRoots::resolve`] turns it into a [`ModelFile`], refusing `..`
//! escapes, absolute paths outside the roots and symlinks that lead outside.
//! [`ModelRoots::read`] then reads it with a size limit per [`FileKind`].
//!
//! Why: a bus client must never make the host open a file outside its model
//! folders, block on a FIFO or device, or grow without bound on a huge file;
//! and an error must never tell a client whether a path outside the roots
//! exists, nor quote a file's contents. Every refusal is therefore one
//! [`FileError::Refused`] with the same wording, whether the path is missing,
//! outside the roots or not a regular file.
//!
//! How: the candidate path is canonicalised (which resolves every symlink
//! and `..`) and must start with a canonicalised root. The file is opened
//! with `O_NONBLOCK | O_NOFOLLOW` (so a FIFO swapped in cannot block), its
//! metadata is checked before the open (by path) and after it (by handle):
//! regular file, same inode, size within the kind's limit. The read itself
//! takes at most `limit + 1` bytes, so a file that grows meanwhile is still
//! bounded. Paths in errors are relative to their root. [`redact`] and
//! [`toml_error`] turn parser messages into text with line/column and no
//! quoted file content.
//!
//! ```
//! use tsukami_body::files::{FileKind, ModelRoots};
//! let dir = std::env::temp_dir().join(format!("tsukami-files-doc-{}", std::process::id()));
//! std::fs::create_dir_all(dir.join("robots")).unwrap();
//! std::fs::write(dir.join("robots/a.toml"), "x = 1\n").unwrap();
//! let roots = ModelRoots::new([dir.clone()]);
//! let file = roots.resolve("robots/a.toml").unwrap();
//! assert_eq!(file.name(), "robots/a.toml");
//! assert_eq!(roots.read_string(&file, FileKind::Toml).unwrap(), "x = 1\n");
//! let refused = roots.resolve("../../etc/passwd").unwrap_err().to_string();
//! assert!(refused.contains("not a model file inside the model roots"));
//! assert_eq!(refused, roots.resolve("robots/missing.toml").unwrap_err().to_string()
//!     .replace("robots/missing.toml", "../../etc/passwd"));
//! std::fs::remove_dir_all(&dir).unwrap();
//! ```

use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// The longest request string an error repeats (longer ones are cut).
const MAX_ECHO: usize = 120;

/// What a file holds; each kind has its own size limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// A robot description (XML).
    Urdf,
    /// A TOML file (grasp types, object, scene).
    Toml,
    /// A triangle mesh (STL, OBJ, PLY, Collada).
    Mesh,
}

impl FileKind {
    /// The kind's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            FileKind::Urdf => "URDF",
            FileKind::Toml => "TOML",
            FileKind::Mesh => "mesh",
        }
    }
}

/// Byte limits per [`FileKind`], checked before reading.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SizeLimits {
    /// Largest URDF file.
    pub urdf: u64,
    /// Largest TOML file.
    pub toml: u64,
    /// Largest mesh file.
    pub mesh: u64,
}

impl Default for SizeLimits {
    /// URDF 4 MiB, TOML 1 MiB, mesh 64 MiB (a binary STL of about 1.3 M
    /// triangles; the mesh loader's triangle cap is lower).
    fn default() -> Self {
        Self {
            urdf: 4 << 20,
            toml: 1 << 20,
            mesh: 64 << 20,
        }
    }
}

impl SizeLimits {
    /// The limit for `kind`.
    pub fn of(&self, kind: FileKind) -> u64 {
        match kind {
            FileKind::Urdf => self.urdf,
            FileKind::Toml => self.toml,
            FileKind::Mesh => self.mesh,
        }
    }
}

/// Why a model file was not read. Messages name the request or the path
/// relative to its root, never an absolute root, never file contents.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FileError {
    /// The path is missing, outside the roots, escapes them through a
    /// symlink or `..`, or is not a regular file (one message for all, so a
    /// client learns nothing about files outside the roots).
    #[error("'{name}' is not a model file inside the model roots")]
    Refused {
        /// The path as the request gave it (cut to 120 characters).
        name: String,
    },
    /// The file is larger than its kind's limit.
    #[error("{name}: {kind} file is {size} bytes, more than the limit of {limit} bytes")]
    TooLarge {
        /// The path relative to its root.
        name: String,
        /// The kind's name.
        kind: &'static str,
        /// The file's size (or `limit + 1` if it grew while read).
        size: u64,
        /// The limit.
        limit: u64,
    },
    /// The file could not be read (the OS error's kind only).
    #[error("{name}: cannot read: {reason}")]
    Unreadable {
        /// The path relative to its root.
        name: String,
        /// The I/O error kind, e.g. `permission denied`.
        reason: String,
    },
    /// A text file is not UTF-8.
    #[error("{name}: not UTF-8 text")]
    NotText {
        /// The path relative to its root.
        name: String,
    },
}

/// A file inside one of the roots, as [`ModelRoots::resolve`] found it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModelFile {
    path: PathBuf,
    name: String,
}

impl ModelFile {
    /// The canonical absolute path (for the host's own use; never put it in
    /// a reply).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The path relative to its root, for messages.
    pub fn name(&self) -> &str {
        &self.name
    }
}

/// The folders models may be read from, with the size limits.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ModelRoots {
    roots: Vec<PathBuf>,
    limits: SizeLimits,
}

impl ModelRoots {
    /// Roots from folders; folders that do not exist (yet) are skipped, the
    /// others are canonicalised. Default size limits.
    pub fn new<P: AsRef<Path>>(roots: impl IntoIterator<Item = P>) -> Self {
        let roots = roots
            .into_iter()
            .filter_map(|r| std::fs::canonicalize(r.as_ref()).ok())
            .filter(|r| r.is_dir())
            .collect();
        Self {
            roots,
            limits: SizeLimits::default(),
        }
    }

    /// The same roots with other size limits.
    pub fn with_limits(mut self, limits: SizeLimits) -> Self {
        self.limits = limits;
        self
    }

    /// The canonical root folders, in search order.
    pub fn roots(&self) -> &[PathBuf] {
        &self.roots
    }

    /// The size limits.
    pub fn limits(&self) -> SizeLimits {
        self.limits
    }

    /// Resolves a request's path: relative paths are tried under each root
    /// in order; an absolute path must lie inside a root. Symlinks are
    /// followed and the target must still be inside a root and be a regular
    /// file.
    pub fn resolve(&self, request: &str) -> Result<ModelFile, FileError> {
        self.resolve_as(request, Self::inside)
    }

    /// Resolves a folder a request names (a `package://` search folder, say)
    /// with the rules of [`ModelRoots::resolve`], except that the target
    /// must be a folder inside a root. Returns its canonical path.
    pub fn resolve_dir(&self, request: &str) -> Result<PathBuf, FileError> {
        self.resolve_as(request, |roots, candidate| {
            let path = std::fs::canonicalize(candidate).ok()?;
            roots.roots.iter().find(|r| path.starts_with(r))?;
            std::fs::metadata(&path).ok()?.is_dir().then_some(path)
        })
    }

    /// The rules [`ModelRoots::resolve`] documents, with `accept` deciding
    /// what a candidate path resolves to.
    fn resolve_as<T>(
        &self,
        request: &str,
        accept: impl Fn(&Self, &Path) -> Option<T>,
    ) -> Result<T, FileError> {
        let refused = || FileError::Refused {
            name: echo(request),
        };
        if request.is_empty() || request.contains('\0') {
            return Err(refused());
        }
        let asked = Path::new(request);
        if asked.is_absolute() {
            return accept(self, asked).ok_or_else(refused);
        }
        if asked
            .components()
            .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
        {
            return Err(refused());
        }
        self.roots
            .iter()
            .find_map(|root| accept(self, &root.join(asked)))
            .ok_or_else(refused)
    }

    /// Resolves `relative` beside `base` (e.g. a mesh named by a URDF or an
    /// object TOML): `..` is allowed as long as the result stays inside a
    /// root. Absolute paths must lie inside a root.
    pub fn resolve_beside(&self, base: &ModelFile, relative: &str) -> Result<ModelFile, FileError> {
        let refused = || FileError::Refused {
            name: echo(relative),
        };
        if relative.is_empty() || relative.contains('\0') {
            return Err(refused());
        }
        let dir = base.path.parent().ok_or_else(refused)?;
        self.inside(&dir.join(relative)).ok_or_else(refused)
    }

    /// The canonical form of `candidate` if it is a regular file inside a
    /// root.
    fn inside(&self, candidate: &Path) -> Option<ModelFile> {
        let path = std::fs::canonicalize(candidate).ok()?;
        let root = self.roots.iter().find(|r| path.starts_with(r))?;
        if !std::fs::metadata(&path).ok()?.is_file() {
            return None;
        }
        let name = path.strip_prefix(root).ok()?.to_string_lossy().into_owned();
        Some(ModelFile { path, name })
    }

    /// Reads a resolved file: regular file only, at most the kind's limit.
    pub fn read(&self, file: &ModelFile, kind: FileKind) -> Result<Vec<u8>, FileError> {
        read_bounded(file, self.limits.of(kind), kind.name())
    }

    /// [`ModelRoots::read`] for text files (must be UTF-8).
    pub fn read_string(&self, file: &ModelFile, kind: FileKind) -> Result<String, FileError> {
        String::from_utf8(self.read(file, kind)?).map_err(|_| FileError::NotText {
            name: file.name.clone(),
        })
    }
}

/// The request string as errors repeat it: at most 120 characters.
fn echo(request: &str) -> String {
    if request.chars().count() <= MAX_ECHO {
        return request.to_string();
    }
    let cut: String = request.chars().take(MAX_ECHO).collect();
    format!("{cut}…")
}

/// Opens `file` without following a final symlink and without blocking,
/// checks it is the regular file that was resolved and within `limit`, and
/// reads at most `limit + 1` bytes.
fn read_bounded(file: &ModelFile, limit: u64, kind: &'static str) -> Result<Vec<u8>, FileError> {
    let refused = || FileError::Refused {
        name: file.name.clone(),
    };
    let before = std::fs::symlink_metadata(&file.path).map_err(|_| refused())?;
    if !before.is_file() {
        return Err(refused());
    }
    let too_large = |size| FileError::TooLarge {
        name: file.name.clone(),
        kind,
        size,
        limit,
    };
    if before.len() > limit {
        return Err(too_large(before.len()));
    }
    let handle = open_nonblocking(&file.path).map_err(|_| refused())?;
    let after = handle.metadata().map_err(|_| refused())?;
    if !after.is_file() || !same_file(&before, &after) {
        return Err(refused());
    }
    if after.len() > limit {
        return Err(too_large(after.len()));
    }
    let mut bytes = Vec::with_capacity(after.len() as usize);
    handle
        .take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| FileError::Unreadable {
            name: file.name.clone(),
            reason: e.kind().to_string(),
        })?;
    if bytes.len() as u64 > limit {
        return Err(too_large(limit + 1));
    }
    Ok(bytes)
}

#[cfg(unix)]
fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_NOFOLLOW)
        .open(path)
}

#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    std::fs::File::open(path)
}

#[cfg(unix)]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

#[cfg(not(unix))]
fn same_file(_: &std::fs::Metadata, _: &std::fs::Metadata) -> bool {
    true
}

/// A parser message made safe to send: its first line only, every quoted
/// or back-ticked token that is not a short identifier replaced by `…`, cut
/// to 200 characters. Use it on any parser message whose input came from a
/// file.
pub fn redact(message: &str) -> String {
    let line = message.lines().next().unwrap_or("");
    let mut out = String::new();
    let mut rest = line;
    while let Some(start) = rest.find(['`', '"', '\'']) {
        let quote = rest[start..].chars().next().unwrap_or('"');
        out.push_str(&rest[..start]);
        let after = &rest[start + 1..];
        let Some(end) = after.find(quote) else {
            out.push('…');
            rest = "";
            break;
        };
        let token = &after[..end];
        let safe = token.len() <= 40
            && token
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        out.push(quote);
        out.push_str(if safe { token } else { "…" });
        out.push(quote);
        rest = &after[end + 1..];
    }
    out.push_str(rest);
    echo_long(out, 200)
}

fn echo_long(s: String, max: usize) -> String {
    if s.chars().count() <= max {
        return s;
    }
    let cut: String = s.chars().take(max).collect();
    format!("{cut}…")
}

/// A TOML parse error as `line L, column C: <redacted message>`, never the
/// source line the `toml` crate quotes.
pub fn toml_error(error: &toml::de::Error, text: &str) -> String {
    let message = redact(error.message());
    match error.span() {
        Some(span) => {
            let (line, column) = line_column(text, span.start);
            format!("line {line}, column {column}: {message}")
        }
        None => message,
    }
}

/// 1-based line and column (in characters) of byte `offset` in `text`.
pub fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Dir(PathBuf);
    impl Drop for Dir {
        fn drop(&mut self) {
            std::fs::remove_dir_all(&self.0).ok();
        }
    }

    fn setup(tag: &str) -> (Dir, Dir, ModelRoots) {
        let base = std::env::temp_dir().join(format!("tsukami-files-{tag}-{}", std::process::id()));
        let root = base.join("root");
        let outside = base.join("outside");
        std::fs::create_dir_all(root.join("robots")).unwrap();
        std::fs::create_dir_all(&outside).unwrap();
        std::fs::write(root.join("robots/hand.toml"), "a = 1\n").unwrap();
        std::fs::write(outside.join("secret.toml"), "SECRET = 'planted'\n").unwrap();
        let roots = ModelRoots::new([&root]);
        (Dir(base), Dir(outside), roots)
    }

    #[test]
    fn resolves_inside_and_refuses_outside_alike() {
        let (base, outside, roots) = setup("resolve");
        let f = roots.resolve("robots/hand.toml").unwrap();
        assert_eq!(f.name(), "robots/hand.toml");
        assert!(roots.resolve("./robots/hand.toml").is_ok());
        let abs = f.path().to_string_lossy().into_owned();
        assert_eq!(roots.resolve(&abs).unwrap().name(), "robots/hand.toml");
        let secret = outside.0.join("secret.toml");
        for bad in [
            "../outside/secret.toml".to_string(),
            "robots/../../outside/secret.toml".to_string(),
            secret.to_string_lossy().into_owned(),
            "/proc/self/environ".into(),
            "/etc/passwd".into(),
            "robots/none.toml".into(),
            "robots".into(),
            String::new(),
        ] {
            let e = roots.resolve(&bad).unwrap_err();
            assert!(matches!(e, FileError::Refused { .. }), "{bad}: {e}");
            // The request is echoed (the client wrote it), the root never is.
            assert!(
                !e.to_string()
                    .contains(&*base.0.join("root").to_string_lossy()),
                "{e}"
            );
        }
    }

    #[cfg(unix)]
    #[test]
    fn symlinks_out_and_special_files_are_refused() {
        let (base, outside, roots) = setup("links");
        let root = base.0.join("root");
        std::os::unix::fs::symlink(outside.0.join("secret.toml"), root.join("s.toml")).unwrap();
        std::os::unix::fs::symlink("/dev/zero", root.join("zero.stl")).unwrap();
        std::os::unix::fs::symlink("robots/hand.toml", root.join("ok.toml")).unwrap();
        for bad in ["s.toml", "zero.stl"] {
            assert!(
                matches!(roots.resolve(bad), Err(FileError::Refused { .. })),
                "{bad}"
            );
        }
        assert_eq!(roots.resolve("ok.toml").unwrap().name(), "robots/hand.toml");
        let fifo = root.join("fifo.toml");
        let c = std::ffi::CString::new(fifo.to_string_lossy().as_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path; mkfifo only creates a node.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        assert!(matches!(
            roots.resolve("fifo.toml"),
            Err(FileError::Refused { .. })
        ));
        let beside = roots.resolve("robots/hand.toml").unwrap();
        assert!(roots.resolve_beside(&beside, "../ok.toml").is_ok());
        assert!(roots
            .resolve_beside(&beside, "../../outside/secret.toml")
            .is_err());
    }

    #[test]
    fn reads_are_bounded_by_kind() {
        let (base, _outside, roots) = setup("bounded");
        let root = base.0.join("root");
        std::fs::write(root.join("big.toml"), vec![b'#'; 2000]).unwrap();
        let roots = roots.with_limits(SizeLimits {
            urdf: 10,
            toml: 1000,
            mesh: 5000,
        });
        let f = roots.resolve("big.toml").unwrap();
        let e = roots.read(&f, FileKind::Toml).unwrap_err();
        assert!(
            e.to_string().contains("big.toml: TOML file is 2000 bytes"),
            "{e}"
        );
        assert_eq!(roots.read(&f, FileKind::Mesh).unwrap().len(), 2000);
        std::fs::write(root.join("bin.toml"), [0xff, 0xfe]).unwrap();
        let f = roots.resolve("bin.toml").unwrap();
        assert!(matches!(
            roots.read_string(&f, FileKind::Toml),
            Err(FileError::NotText { .. })
        ));
    }

    #[test]
    fn toml_errors_carry_no_content() {
        let text = "a = 1\nb = 2\npassword = \"hunter2-$6$abc/def\"\nc = [\n";
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct S {
            a: u8,
            password: u32,
        }
        let err = toml::from_str::<S>(text).unwrap_err();
        let m = toml_error(&err, text);
        assert!(m.starts_with("line "), "{m}");
        assert!(!m.contains("hunter2"), "{m}");
        assert_eq!(
            redact("unknown field `foo`, expected `bar`"),
            "unknown field `foo`, expected `bar`"
        );
        assert_eq!(
            redact("invalid type: string \"root:$6$x:0\", expected u32"),
            "invalid type: string \"…\", expected u32"
        );
        assert_eq!(line_column("ab\ncd", 4), (2, 2));
    }
}
