//! Bounds on what a model file may ask of the loader.
//!
//! What: [`ParseLimits`] (XML depth, links, joints, mesh triangles and file
//! sizes) and the two checks that enforce them before any recursive or large
//! work happens: [`check_xml_depth`] on raw XML text and
//! [`read_bounded`] for every file the loader opens.
//!
//! Why: a hostile or broken file must not overflow a stack (a URDF or Collada
//! file nested 10,000 elements deep), block (a FIFO or device), or grow the
//! process without bound (a 100k-link URDF, a 1 GB mesh). The loader's memory
//! is bounded by these numbers: roughly `max_urdf_bytes × 8` for the XML tree
//! plus `max_mesh_triangles × 100` bytes per mesh being cleaned.
//!
//! How: the depth check is one linear scan over the text that counts open and
//! close tags (skipping comments, CDATA, processing instructions and quoted
//! attribute values), with no recursion. Reads refuse anything but a regular
//! file, check the size before reading and never take more than the limit.
//!
//! ```
//! use tsukami_body::limits::check_xml_depth;
//! assert_eq!(check_xml_depth("<a><b/><c>x</c></a>", 8), Ok(2));
//! let deep = "<a>".repeat(100);
//! assert!(check_xml_depth(&deep, 64).unwrap_err().contains("deeper than 64"));
//! ```

use std::io::Read;
use std::path::Path;

use crate::error::{BodyError, Result};

/// Limits applied while loading robots and meshes. The defaults accept every
/// public robot description we know of and scans of up to 2M triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParseLimits {
    /// Deepest element nesting in a URDF or Collada file.
    pub max_xml_depth: usize,
    /// Most links in a robot (joints are at most one fewer).
    pub max_links: usize,
    /// Most triangles in one mesh file, before cleaning.
    pub max_mesh_triangles: usize,
    /// Largest URDF file (bytes).
    pub max_urdf_bytes: u64,
    /// Largest mesh file (bytes).
    pub max_mesh_bytes: u64,
}

impl Default for ParseLimits {
    fn default() -> Self {
        Self {
            max_xml_depth: 256,
            max_links: 10_000,
            max_mesh_triangles: 2_000_000,
            max_urdf_bytes: 16 << 20,
            max_mesh_bytes: 256 << 20,
        }
    }
}

/// The deepest element nesting in `xml`, or a message when it exceeds
/// `limit`. Malformed XML is not judged here (the parser does that); the scan
/// only has to be linear and never recurse.
pub fn check_xml_depth(xml: &str, limit: usize) -> std::result::Result<usize, String> {
    let bytes = xml.as_bytes();
    let (mut i, mut depth, mut deepest) = (0usize, 0usize, 0usize);
    while let Some(off) = memchr(b'<', &bytes[i..]) {
        i += off;
        let rest = &bytes[i..];
        if rest.starts_with(b"<!--") {
            i = skip_past(bytes, i, b"-->");
        } else if rest.starts_with(b"<![CDATA[") {
            i = skip_past(bytes, i, b"]]>");
        } else if rest.starts_with(b"<?") {
            i = skip_past(bytes, i, b"?>");
        } else if rest.starts_with(b"<!") {
            i = skip_past(bytes, i, b">");
        } else if rest.starts_with(b"</") {
            depth = depth.saturating_sub(1);
            i = skip_past(bytes, i, b">");
        } else {
            let (end, self_closing) = tag_end(bytes, i + 1);
            if !self_closing {
                depth += 1;
                deepest = deepest.max(depth);
                if depth > limit {
                    return Err(format!("elements are nested deeper than {limit} levels"));
                }
            } else {
                deepest = deepest.max(depth + 1);
            }
            i = end;
        }
    }
    Ok(deepest)
}

fn memchr(needle: u8, hay: &[u8]) -> Option<usize> {
    hay.iter().position(|&b| b == needle)
}

/// Index just past the first `pat` at or after `from` (or the end).
fn skip_past(bytes: &[u8], from: usize, pat: &[u8]) -> usize {
    bytes[from..]
        .windows(pat.len())
        .position(|w| w == pat)
        .map_or(bytes.len(), |p| from + p + pat.len())
}

/// End of a start tag beginning at `from` (just after `<`), honouring quoted
/// attribute values; and whether it is self-closing.
fn tag_end(bytes: &[u8], from: usize) -> (usize, bool) {
    let mut quote: Option<u8> = None;
    let mut prev = 0u8;
    for (k, &b) in bytes[from..].iter().enumerate() {
        match quote {
            Some(q) if b == q => quote = None,
            Some(_) => {}
            None if b == b'"' || b == b'\'' => quote = Some(b),
            None if b == b'>' => return (from + k + 1, prev == b'/'),
            None => {}
        }
        prev = b;
    }
    (bytes.len(), false)
}

/// Reads a regular file of at most `limit` bytes. `what` names the kind of
/// file in errors ("URDF", "mesh"). Devices, FIFOs and folders are refused
/// before opening; a file that grows while being read is cut at the limit and
/// refused.
pub fn read_bounded(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>> {
    let io = |source| BodyError::Io {
        file: path.to_path_buf(),
        source,
    };
    let too_big = |size: u64| BodyError::TooLarge {
        file: path.to_path_buf(),
        message: format!("the {what} file has {size} bytes, more than the limit of {limit}"),
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(io(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file",
        )));
    }
    if meta.len() > limit {
        return Err(too_big(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let mut out = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1).read_to_end(&mut out).map_err(io)?;
    if out.len() as u64 > limit {
        return Err(too_big(out.len() as u64));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_scan_skips_comments_cdata_and_quotes() {
        let xml =
            r#"<?xml version="1.0"?><!-- <a><a><a> --><r a=">x<y>"><![CDATA[<q><q>]]><s/></r>"#;
        assert_eq!(check_xml_depth(xml, 4), Ok(2));
        assert_eq!(check_xml_depth("", 4), Ok(0));
        assert_eq!(check_xml_depth("<a", 4), Ok(1));
    }

    #[test]
    fn deep_nesting_is_refused_without_recursion() {
        let deep = "<link>".repeat(1_000_000);
        assert!(check_xml_depth(&deep, 256).is_err());
        let ok = format!("{}{}", "<a>".repeat(200), "</a>".repeat(200));
        assert_eq!(check_xml_depth(&ok, 256), Ok(200));
    }

    #[test]
    fn reads_are_bounded_and_regular_only() {
        let dir = std::env::temp_dir().join(format!("tsukami-limits-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("a.urdf");
        std::fs::write(&f, vec![b'x'; 100]).unwrap();
        assert_eq!(read_bounded(&f, 100, "URDF").unwrap().len(), 100);
        let e = read_bounded(&f, 99, "URDF").unwrap_err().to_string();
        assert!(e.contains("a.urdf") && e.contains("limit of 99"), "{e}");
        assert!(read_bounded(&dir, 100, "URDF").is_err());
        assert!(read_bounded(Path::new("/dev/zero"), 100, "mesh").is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
